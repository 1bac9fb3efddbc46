//! `lsyc infer --skeleton SKETCH.svg`: a tree sketch (SVG strokes) to a
//! recursive L-system, after Hegde & Rathi, *Modeling Vegetation with
//! L-systems Using an Image*.
//!
//! Owns: the pipeline, its options and its limits: strokes (`strokes`), the
//! tree with Douglas–Peucker simplification (`skeleton`), productions,
//! pre-reduction, the reduction table and the reduced productions
//! (`productions`), and the program as an AST (`emit`), printed by
//! `fmt::format_file`. Must not write files or print (the CLI does), and must
//! not panic on any input.

pub mod emit;
pub mod productions;
pub mod skeleton;
pub mod strokes;

use super::{InferError, MAX_SVG_BYTES};
use crate::ast::File;
use productions::Analysis;
use skeleton::Skeleton;

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
pub fn from_svg(data: &[u8], name: &str, opts: &Options) -> Result<Inferred, InferError> {
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
    let (source, system) = super::program::names(name);
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
