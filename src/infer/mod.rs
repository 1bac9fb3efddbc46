//! Inference: drawings become `.lsy` programs, one folder for each kind of
//! drawing read: `lsyc infer --skeleton`, a tree sketch to a recursive
//! L-system (`sketch`); `lsyc infer ART.svg`, repeated elements to sequence
//! and branching rules (`elements`), or, for a line drawing, the D0L system
//! that draws it (`lines`). `svg` reads drawings safely for all three.
//!
//! Owns: the errors of inference and the size limit of a drawing. Must not
//! write files or print: the CLI does that, and must not panic on any input.

pub mod elements;
pub mod lines;
pub mod program;
pub mod sketch;
pub mod svg;

use thiserror::Error;

/// The largest sketch read, in bytes.
pub const MAX_SVG_BYTES: usize = 64 * 1024 * 1024;

/// Why a sketch cannot be inferred. Each message names the file.
#[derive(Debug, Error, PartialEq)]
pub enum InferError {
    #[error("`{file}` is not an SVG drawing lsyc can read: {why}")]
    NotSvg { file: String, why: String },
    #[error(
        "`{file}` has no strokes: draw the trunk and the branches as paths, lines or polylines"
    )]
    NoStrokes { file: String },
    #[error(
        "{file}: {stroke} starts {distance:.1} units from every earlier stroke; a branch must start on its parent (within {limit:.1} units), and the first stroke is the trunk"
    )]
    Detached {
        file: String,
        stroke: String,
        distance: f64,
        limit: f64,
    },
    #[error("`{file}` is larger than {} MiB", MAX_SVG_BYTES >> 20)]
    TooLarge { file: String },
    #[error(
        "`{file}` has more than {} strokes; lsyc infers trees of up to {}",
        sketch::MAX_STROKES,
        sketch::MAX_STROKES
    )]
    TooManyStrokes { file: String },
    #[error(
        "`{file}`: inference from its {elements} elements would need more than {limit} {what}; lsyc stops there (infer a part of the drawing at a time, or fewer, more alike elements)"
    )]
    TooMuchWork {
        file: String,
        elements: usize,
        what: &'static str,
        limit: u64,
    },
    #[error("`{file}` is not read: {why}")]
    Refused { file: String, why: svg::Refusal },
    #[error(
        "`{file}` has nothing to infer from: no paths or shapes with an extent{}",
        if *skipped > 0 { format!(" ({skipped} text, image or empty shapes skipped)") } else { String::new() }
    )]
    NoElements { file: String, skipped: usize },
    #[error(
        "`{file}` has coordinates as large as {largest:.1e}; lsyc infers drawings whose coordinates stay within ±{:e} user units (scale the drawing down)",
        elements::read::MAX_COORDINATE
    )]
    Huge { file: String, largest: f64 },
    #[error(
        "`{file}` has {elements} elements; lsyc infers drawings of up to {}",
        elements::MAX_ELEMENTS
    )]
    TooManyElements { file: String, elements: usize },
}

impl InferError {
    /// The error for a document `svg` refused to read: usvg's own reasons
    /// keep their wording.
    pub fn refused(file: &str, why: svg::Refusal) -> InferError {
        match why {
            svg::Refusal::NotSvg(why) => InferError::NotSvg {
                file: file.into(),
                why,
            },
            why => InferError::Refused {
                file: file.into(),
                why,
            },
        }
    }
}
