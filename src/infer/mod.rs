//! Inference: drawings become `.lsy` programs, one folder for each kind of
//! drawing read: `lsyc infer --skeleton`, a tree sketch to a recursive
//! L-system (`sketch`); `lsyc infer ART.svg`, a line drawing to the D0L
//! system that draws it (`lines`), or else repeated elements to sequence and
//! branching rules (`elements`). `svg` reads drawings safely for all three,
//! and each writes its program with the one kit of `program`.
//!
//! Owns: the one `Options` of inference, the choice between a line drawing's
//! grammar and the elements (`from_svg`), the errors and the size limit of a
//! drawing. Must not write files or print: the CLI does that, and must not
//! panic on any input.

pub mod elements;
pub mod lines;
pub mod program;
pub mod sketch;
pub mod svg;

use std::time::Duration;
use thiserror::Error;

/// The largest drawing read, in bytes.
pub const MAX_SVG_BYTES: usize = 64 * 1024 * 1024;

/// Why a drawing cannot be inferred. Each message names the file.
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

/// Options of inference, a part for each kind of drawing.
#[derive(Clone, Debug)]
pub struct Options {
    /// Tree sketches (`lsyc infer --skeleton`).
    pub sketch: sketch::Options,
    /// Drawings of repeated elements.
    pub elements: elements::Options,
    /// The search for a line drawing's D0L system, tried before the
    /// elements; `None` infers the elements at once.
    pub lines: Option<lines::Options>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            sketch: sketch::Options::default(),
            elements: elements::Options::default(),
            lines: Some(lines::Options::default()),
        }
    }
}

/// What `from_svg` made of a drawing.
pub enum Outcome {
    /// A line drawing, and the D0L system that draws it.
    Lines(Box<lines::Inferred>),
    /// The drawing's elements and the rules that place them, or why there
    /// are none.
    Elements {
        /// Why it is not a line drawing's grammar, when it is a line drawing.
        lines: Option<LinesGaveWay>,
        elements: Result<Box<elements::Inferred>, InferError>,
    },
}

/// A line drawing no D0L system was found for, so its elements are inferred
/// instead.
pub struct LinesGaveWay {
    /// What the search did.
    pub stats: lines::Stats,
    /// What to tell: `walk.svg: a line drawing of 400 steps, but …; inferring
    /// its elements instead`.
    pub note: String,
}

impl LinesGaveWay {
    fn new(
        file: &str,
        budget: Duration,
        why: String,
        steps: usize,
        timed_out: bool,
        stats: lines::Stats,
    ) -> LinesGaveWay {
        let what = if steps > 0 {
            format!("a line drawing of {steps} steps")
        } else {
            "a line drawing".to_string()
        };
        let how = if timed_out {
            format!(
                "no D0L system found within {} ms (--budget-ms)",
                budget.as_millis()
            )
        } else {
            why
        };
        LinesGaveWay {
            stats,
            note: format!("{file}: {what}, but {how}; inferring its elements instead"),
        }
    }
}

/// Infers a program from the bytes of an SVG drawing named `name` (a file
/// name, for messages and the header): the D0L system of a line drawing
/// when `opts.lines` finds one, else sequence and branching rules of its
/// elements; `progress` is told how many instances are left as the
/// elements' rules are found.
pub fn from_svg(
    data: &[u8],
    name: &str,
    opts: &Options,
    progress: &mut dyn FnMut(usize),
) -> Outcome {
    let mut gave_way = None;
    if let Some(search) = &opts.lines {
        match lines::from_svg(data, name, search) {
            lines::Lines::Found(found) => return Outcome::Lines(found),
            lines::Lines::Unexplained {
                why,
                steps,
                timed_out,
                stats,
            } => {
                gave_way = Some(LinesGaveWay::new(
                    name,
                    search.budget,
                    why,
                    steps,
                    timed_out,
                    stats,
                ));
            }
            lines::Lines::NotLines(_) => {}
        }
    }
    Outcome::Elements {
        lines: gave_way,
        elements: elements::from_svg(data, name, &opts.elements, progress).map(Box::new),
    }
}
