//! `lsyc infer ART.svg` when it is not a line drawing's grammar (see
//! `infer::from_svg`): a drawing of repeated elements to an L-system that
//! draws it back, after Šťava, Beneš, Měch, Aliaga & Krištof, *Inverse
//! Procedural Modeling by Automatic Generation of L-systems* (CGF 2010).
//!
//! Owns: the pipeline and its options and statistics: elements (`read`),
//! kinds and frames (`shape`), the kinds' origins (`origin`) and local frames
//! (`pivot`) where the drawing gives none, transformation spaces and
//! clustering (`space`), rules level by level (`rules`) and the program
//! (`emit`). Must not write files or print (the CLI does), and must not panic
//! on any input.

pub mod choose;
pub mod emit;
pub mod origin;
pub mod pivot;
pub mod read;
pub mod rules;
pub mod shape;
pub mod space;

use super::{InferError, MAX_SVG_BYTES};
use crate::ast::File;
use rules::{Body, Grammar, Inst, Sym, Tolerance, Weights};
use shape::{Facing, Frame, Instancing};
use std::time::Instant;

/// The most elements a drawing may have.
pub const MAX_ELEMENTS: usize = 200_000;

/// The most elements a drawing may have for its round kinds to be read
/// turned as well (`choose`): each reading infers the rules again.
pub const MAX_REREAD: usize = 20_000;

/// A phase would do more work than its limit: `what` it counts, and the limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooMuchWork {
    pub what: &'static str,
    pub limit: u64,
}

/// The work a phase has left before its limit, counted in `what`.
pub(crate) struct Budget {
    what: &'static str,
    limit: u64,
    left: u64,
}

impl Budget {
    pub(crate) fn new(what: &'static str, limit: u64) -> Budget {
        Budget {
            what,
            limit,
            left: limit,
        }
    }

    /// A copy with the same work left, for work done in parallel: what the
    /// copy spent is charged to this budget afterwards (`spend_u64`).
    pub(crate) fn copy(&self) -> Budget {
        Budget {
            what: self.what,
            limit: self.limit,
            left: self.left,
        }
    }

    /// Spends `n`, or says the limit is reached.
    pub(crate) fn spend(&mut self, n: usize) -> Result<(), TooMuchWork> {
        self.spend_u64(n as u64)
    }

    /// Spends `n`, or says the limit is reached.
    pub(crate) fn spend_u64(&mut self, n: u64) -> Result<(), TooMuchWork> {
        match self.left.checked_sub(n) {
            Some(left) => {
                self.left = left;
                Ok(())
            }
            None => Err(TooMuchWork {
                what: self.what,
                limit: self.limit,
            }),
        }
    }
}

/// Options of `lsyc infer ART.svg`.
#[derive(Clone, Debug)]
pub struct Options {
    /// Importance weights of clusters.
    pub weights: Weights,
    /// Relaxed tolerances: a noisy drawing comes out regular.
    pub symmetrize: bool,
    /// Largest mean misfit of alike elements, relative to their size.
    pub similarity: f64,
    /// Random variation of repeated transforms (see `emit::Settings::jitter`).
    pub jitter: Option<f64>,
    /// Mirror images of a kind become its mirror kind, drawn from one outline.
    pub reflect: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            weights: Weights::default(),
            symmetrize: false,
            similarity: 0.02,
            jitter: None,
            reflect: false,
        }
    }
}

/// What inference found and how long each phase took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Stats {
    pub elements: usize,
    pub skipped: usize,
    pub kinds: usize,
    pub clusters: usize,
    pub rules: usize,
    pub rounds: usize,
    pub read_ms: f64,
    pub instancing_ms: f64,
    pub rules_ms: f64,
    pub emit_ms: f64,
    /// Bytes of the drawing read.
    pub svg_bytes: usize,
    /// Bytes of the emitted program (its canonical text).
    pub program_bytes: usize,
    /// `program_bytes / svg_bytes`: below 1 the program is the smaller description.
    pub size_ratio: f64,
}

/// A drawing and the program inferred from it.
pub struct Inferred {
    pub file: File,
    pub text: String,
    /// Things of the drawing that were skipped, one line each.
    pub skipped: Vec<String>,
    pub stats: Stats,
}

fn ms(t: Instant) -> f64 {
    (t.elapsed().as_secs_f64() * 1e5).round() / 100.0
}

/// Infers a program from the bytes of an SVG drawing named `name`;
/// `progress` is told how many instances are left as rules are found.
pub fn from_svg(
    data: &[u8],
    name: &str,
    opts: &Options,
    progress: &mut dyn FnMut(usize),
) -> Result<Inferred, InferError> {
    if data.len() > MAX_SVG_BYTES {
        return Err(InferError::TooLarge { file: name.into() });
    }
    let t = Instant::now();
    let drawing = read::read(data).map_err(|why| InferError::refused(name, why))?;
    if drawing.largest > read::MAX_COORDINATE || !drawing.largest.is_finite() {
        return Err(InferError::Huge {
            file: name.into(),
            largest: drawing.largest,
        });
    }
    if drawing.elements.is_empty() {
        return Err(InferError::NoElements {
            file: name.into(),
            skipped: drawing.skipped.len(),
        });
    }
    if drawing.elements.len() > MAX_ELEMENTS {
        return Err(InferError::TooManyElements {
            file: name.into(),
            elements: drawing.elements.len(),
        });
    }
    let mut stats = Stats {
        elements: drawing.elements.len(),
        skipped: drawing.skipped.len(),
        read_ms: ms(t),
        ..Stats::default()
    };
    let t = Instant::now();
    let tol = if opts.symmetrize {
        Tolerance::RELAXED
    } else {
        Tolerance::EXACT
    };
    let similarity = if opts.symmetrize {
        opts.similarity * 3.0
    } else {
        opts.similarity
    };
    let too_much = |w: TooMuchWork| InferError::TooMuchWork {
        file: name.into(),
        elements: drawing.elements.len(),
        what: w.what,
        limit: w.limit,
    };
    let mut inst =
        shape::instancing(&drawing.elements, similarity, opts.reflect).map_err(too_much)?;
    let moved = origin::find(&mut inst, tol);
    pivot::choose(&mut inst, &moved, tol);
    stats.kinds = inst.kinds.len();
    stats.instancing_ms = ms(t);
    let t = Instant::now();
    let (source, system) = super::program::names(name);
    let settings = emit::Settings {
        source: &source,
        name: system,
        symmetrize: opts.symmetrize,
        jitter: opts.jitter,
    };
    let program = |mut inst: Instancing, progress: &mut dyn FnMut(usize)| {
        let mut grammar = rules::infer(insts(&drawing, &inst), opts.weights, tol, progress)?;
        frame_tips(&mut inst, &mut grammar);
        let t = Instant::now();
        let file = emit::program(&drawing.elements, &inst, &grammar, &settings);
        let text = crate::fmt::format_file(&file);
        Ok((grammar, file, text, ms(t)))
    };
    // Round kinds turned along their neighbours, out of their ring or along
    // the path through them, when there are any (in drawings of up to
    // `MAX_REREAD` elements: each reading costs the rules again): the
    // program with fewer numbers (not names' digits) wins if it puts the
    // elements where the first does (a spiral of discs steps alike at every
    // disc, a row keeps the drawing's axes). A reading that reaches a work
    // limit is left out.
    let turned: Vec<Instancing> = [Facing::Neighbour, Facing::Out, Facing::Path, Facing::Fork]
        .into_iter()
        .filter(|_| drawing.elements.len() <= MAX_REREAD)
        .filter_map(|f| inst.turned_round(f, if opts.symmetrize { 0.03 } else { 0.01 }))
        .collect();
    let (mut grammar, mut file, mut text, mut emit_ms) =
        program(inst, progress).map_err(too_much)?;
    if !turned.is_empty() {
        let places: Vec<glam::DVec2> = drawing
            .elements
            .iter()
            .filter_map(|e| choose::mean_point(e.subpaths.iter().flatten().copied()))
            .collect();
        // As near as the first, or (with `--symmetrize`) within the noise
        // of the drawing's placement.
        let first = choose::misfit(&text, &places).unwrap_or(f64::INFINITY);
        let mut sizes: Vec<f64> = drawing
            .elements
            .iter()
            .map(|e| (e.max - e.min).length())
            .collect();
        sizes.sort_by(f64::total_cmp);
        let size = sizes[sizes.len() / 2];
        let near = first * 1.5 + if opts.symmetrize { 0.1 } else { 1e-3 } * size;
        for turned in turned {
            let Ok(other) = program(turned, &mut |_| {}) else {
                continue;
            };
            emit_ms += other.3;
            let fits = choose::misfit(&other.2, &places).is_some_and(|m| m <= near);
            if fits && choose::numbers(&other.2) < choose::numbers(&text) {
                (grammar, file, text, _) = other;
            }
        }
    }
    stats.rules = grammar.rules.len();
    stats.rounds = grammar.rounds;
    stats.clusters = grammar.clusters;
    stats.emit_ms = emit_ms;
    stats.rules_ms = ms(t) - emit_ms;
    stats.svg_bytes = data.len();
    stats.program_bytes = text.len();
    stats.size_ratio = text.len() as f64 / data.len().max(1) as f64;
    Ok(Inferred {
        file,
        text,
        skipped: drawing.skipped,
        stats,
    })
}

/// The drawing's elements as instances of their kinds, for the rules.
fn insts(drawing: &read::Drawing, inst: &Instancing) -> Vec<Inst> {
    drawing
        .elements
        .iter()
        .zip(&inst.of)
        .zip(&inst.shapes)
        .map(|((e, (k, f)), sh)| {
            Inst::new(Sym::Element(*k), *f, e.min, e.max)
                .symmetric(inst.kinds[*k].symmetry, sh.centroid)
        })
        .collect()
}

/// A kind the drawing does not frame, drawn only at the tips of
/// branchings and there always at one place relative to where a child
/// would be, is framed at that place: the rules then end in `m == 0 -> B`,
/// its path written as it sits at a tip.
fn frame_tips(inst: &mut Instancing, g: &mut Grammar) {
    for k in 0..inst.kinds.len() {
        let me = Sym::Element(k);
        let mut at: Option<Frame> = None;
        let mut only_tips = !inst.kinds[k].given && g.axiom.is_none_or(|(_, s)| s != me);
        for rule in &g.rules {
            let (uses, tip) = match &rule.body {
                Body::Seq { a, tip, .. } => (*a == me || *tip == Some(me), None),
                Body::Pair { a, b, .. } => (*a == me || *b == me, None),
                Body::Branch { a, tip, tip_at, .. } => match (tip, tip_at) {
                    (Some(t), Some(rel)) if *t == me && *a != me => (false, Some(*rel)),
                    _ => (*a == me || *tip == Some(me), None),
                },
            };
            only_tips &= !uses;
            if let Some(rel) = tip {
                only_tips &= at.is_none_or(|f| f == rel);
                at = Some(rel);
            }
        }
        let Some(rel) = at.filter(|_| only_tips) else {
            continue;
        };
        inst.reframe(k, &rel);
        for rule in &mut g.rules {
            if let Body::Branch { tip, tip_at, .. } = &mut rule.body
                && *tip == Some(me)
            {
                *tip_at = None;
            }
        }
    }
}

/// Replaces the path of element `name` in `file` by the drawing in `svg` (all
/// its shapes as one path), centred where the element's outline is centred and
/// scaled to the same size, with the drawing's colours: `lsyc run
/// --element A=leaf.svg`. The error says what is wrong, for a message.
pub fn replace_element(file: &mut File, name: &str, svg: &[u8]) -> Result<(), String> {
    use crate::ast::{Item, PropValue};
    let element = file
        .items
        .stmts
        .iter_mut()
        .find_map(|i| match &mut i.node {
            Item::Element(e) if e.name.name == name => Some(e),
            _ => None,
        })
        .ok_or_else(|| format!("the program has no element `{name}`"))?;
    let old = element
        .props
        .stmts
        .iter()
        .find_map(|p| match (&p.node.key.name[..], &p.node.value) {
            ("path", PropValue::Str(d, _)) => Some(d.clone()),
            _ => None,
        })
        .unwrap_or_default();
    // The old outline, read like a drawing (its y flips, which keeps sizes).
    let wrapped = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="{}"/></svg>"#,
        crate::render::svg::xml(&old)
    );
    let size = |d: &read::Drawing| {
        let lines: Vec<Vec<glam::DVec2>> =
            d.elements.iter().flat_map(|e| e.outline.clone()).collect();
        shape::Shape::of(&lines).map(|s| (s.centroid, s.radius))
    };
    let old_size = read::read(wrapped.as_bytes())
        .ok()
        .and_then(|d| size(&d))
        .map_or(1.0, |(_, r)| r);
    let new = read::read(svg).map_err(|why| why.to_string())?;
    let (centre, radius) = size(&new)
        .ok_or_else(|| "the drawing has no paths or shapes with an extent".to_string())?;
    let k = old_size / radius;
    let mut subpaths = Vec::new();
    for e in &new.elements {
        for sub in &e.subpaths {
            subpaths.push(
                sub.iter()
                    .map(|s| shape::map_seg(s, |p| (p - centre) * k))
                    .collect::<Vec<_>>(),
            );
        }
    }
    let data = emit::path_data(&subpaths, glam::DVec2::ZERO, old_size);
    let style = new.elements[0].style.clone();
    for p in element.props.stmts.iter_mut() {
        let value = match &p.node.key.name[..] {
            "path" => Some(data.clone()),
            "fill" => Some(style.fill.clone().unwrap_or_else(|| "none".into())),
            "stroke" => style.stroke.clone(),
            _ => None,
        };
        if let (Some(v), PropValue::Str(s, _)) = (value, &mut p.node.value) {
            *s = v;
        }
    }
    Ok(())
}
