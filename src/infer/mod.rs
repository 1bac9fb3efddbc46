//! Inference: drawings become `.lsy` programs.
//!
//! Owns: `lsyc infer --skeleton`, a tree sketch (SVG strokes) to a recursive
//! L-system after Hegde & Rathi, *Modeling Vegetation with L-systems Using an
//! Image*: strokes (`strokes`), the tree with Douglas–Peucker simplification
//! (`skeleton`), productions, pre-reduction, the reduction table and the reduced
//! productions (`productions`), and the program as an AST (`emit`), printed by
//! `fmt::format_file`; and `lsyc infer ART.svg`, repeated elements to sequence
//! and branching rules (`elements`), or, for a line drawing, the D0L system
//! that draws it (`lines`). Must not write files or print: the CLI does that, and
//! must not panic on any input.

pub mod elements;
pub mod emit;
pub mod lines;
pub mod productions;
pub mod skeleton;
pub mod strokes;
pub mod svg;

use crate::ast::File;
use productions::Analysis;
use skeleton::Skeleton;
use thiserror::Error;

/// The largest sketch read, in bytes.
pub const MAX_SVG_BYTES: usize = 64 * 1024 * 1024;
/// The most strokes a sketch may have (attaching them is quadratic).
pub const MAX_STROKES: usize = 10_000;

/// Options of `lsyc infer --skeleton`.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Douglas–Peucker tolerance in drawing units; relative to the drawing's
    /// size when `None`.
    pub epsilon: Option<f64>,
    /// Emit a 3D program.
    pub three_d: bool,
    /// Seed of the 3D perturbation.
    pub seed: u64,
}

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
        "`{file}` has more than {MAX_STROKES} strokes; lsyc infers trees of up to {MAX_STROKES}"
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

/// For a drawing's file name: the name the header gives (the file's own name)
/// and the lsystem's name (from its stem: `sketch-tree.svg` → `SketchTree`).
pub fn names(name: &str) -> (String, String) {
    let path = std::path::Path::new(name);
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let source = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| name.to_string());
    (source, emit::system_name(&stem))
}

/// A sketch and what was inferred from it.
pub struct Inferred {
    pub skeleton: Skeleton,
    pub analysis: Analysis,
    /// The program.
    pub file: File,
    /// The program in canonical text.
    pub text: String,
}

/// Infers a program from the bytes of an SVG sketch named `name` (a file name,
/// for messages and the header).
pub fn skeleton_from_svg(data: &[u8], name: &str, opts: &Options) -> Result<Inferred, InferError> {
    if data.len() > MAX_SVG_BYTES {
        return Err(InferError::TooLarge { file: name.into() });
    }
    let strokes = strokes::read(data, MAX_STROKES).map_err(|why| InferError::refused(name, why))?;
    if strokes.is_empty() {
        return Err(InferError::NoStrokes { file: name.into() });
    }
    if strokes.len() > MAX_STROKES {
        return Err(InferError::TooManyStrokes { file: name.into() });
    }
    let sk = skeleton::build(&strokes, opts.epsilon).map_err(|d| InferError::Detached {
        file: name.into(),
        stroke: d.stroke,
        distance: d.distance,
        limit: d.limit,
    })?;
    let analysis = Analysis::new(&sk.children());
    let (source, system) = names(name);
    let settings = emit::Settings {
        source: &source,
        name: system,
        strokes: strokes.len(),
        numbers: strokes.iter().map(|s| s.number).collect(),
        seed_3d: opts.three_d.then_some(opts.seed),
    };
    let file = emit::program(&sk, &analysis, &settings);
    let text = crate::fmt::format_file(&file);
    Ok(Inferred {
        skeleton: sk,
        analysis,
        file,
        text,
    })
}
