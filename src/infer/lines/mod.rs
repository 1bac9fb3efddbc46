//! `lsyc infer ART.svg` on a line drawing: the D0L system that draws it.
//!
//! A line drawing (every visible shape stroked, unfilled, straight segments:
//! the turtle's trace of a Koch curve, a dragon, a bracketed plant) is read
//! as turtle steps (`read`, `turtle`): equal steps, turns by multiples of one
//! angle δ, branches where a polyline starts on an earlier point, gaps of
//! whole steps as moves. The search (`search`) proposes D0L systems from the
//! drawing's self-similarity; each candidate is derived and drawn step by
//! step against the drawing (`grammar`), and the first, smallest one that
//! draws it exactly is derived again by the library and compared with the
//! drawing (`verify`) before it is written (`emit`).
//!
//! Owns: the pipeline, its options and its outcome (a program, not a line
//! drawing, or a line drawing no grammar explains within the budget). Must
//! not print or write files (the CLI does), and must not panic on any input.

pub mod blocks;
pub mod emit;
pub mod euler;
pub mod frame;
pub mod grammar;
pub mod graph;
pub mod ideal;
pub mod levels;
pub mod read;
pub mod root;
pub mod search;
pub mod synth;
pub mod turtle;
pub mod verify;
pub mod walk;

use crate::ast::{Expr, Module};
use crate::infer::program::{nice, sym};
use glam::DVec2;
use grammar::{Grammar, Outcome};
use read::{NotLines, Reading};
use std::time::{Duration, Instant};

/// Options of the line-drawing search.
#[derive(Clone, Debug)]
pub struct Options {
    /// How long the search may take.
    pub budget: Duration,
    /// Search limits.
    pub limits: search::Limits,
    /// Limits of the search on the stroke graph (`synth`); its work is a
    /// count, so the same drawing gets the same answer on any machine.
    pub graph: synth::Limits,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            budget: Duration::from_millis(DEFAULT_BUDGET_MS),
            limits: search::Limits::default(),
            graph: synth::Limits::default(),
        }
    }
}

/// The most candidates per reading that the library derives and draws
/// again (each as large as the drawing).
const MAX_REDRAWS: usize = 3;

/// The default time budget of the search, milliseconds.
pub const DEFAULT_BUDGET_MS: u64 = 4000;

/// What the search did, for `--stats`.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Stats {
    /// Drawn steps read.
    pub steps: usize,
    /// δ, degrees.
    pub angle: f64,
    /// Candidates proposed.
    pub candidates: usize,
    /// Candidates derived and compared.
    pub compared: usize,
    /// Rules of the program (rewriting rules, not `interpret`).
    pub rules: usize,
    /// Symbols in their successors.
    pub rule_symbols: usize,
    pub depth: u32,
    pub read_ms: f64,
    pub search_ms: f64,
    pub verify_ms: f64,
}

/// A line drawing and its program.
pub struct Inferred {
    pub grammar: Grammar,
    pub file: crate::ast::File,
    pub text: String,
    pub redraw: verify::Redraw,
    pub stats: Stats,
}

/// What became of a drawing.
pub enum Lines {
    /// A D0L system draws it.
    Found(Box<Inferred>),
    /// Not a line drawing (what it has instead).
    NotLines(&'static str),
    /// A line drawing no D0L system explains (why), within the search's
    /// limits; `timed_out` when the budget ended the search.
    Unexplained {
        why: String,
        steps: usize,
        timed_out: bool,
        stats: Stats,
    },
}

fn ms(t: Instant) -> f64 {
    (t.elapsed().as_secs_f64() * 1e5).round() / 100.0
}

/// Infers the D0L system of the line drawing in `data` (named `name`).
pub fn from_svg(data: &[u8], name: &str, opts: &Options) -> Lines {
    let start = Instant::now();
    // No deadline for a budget beyond what a clock can count. The stroke
    // graph's search comes after it, bounded by its count of work.
    let deadline = start.checked_add(opts.budget);
    let late = || deadline.is_some_and(|d| Instant::now() >= d);
    if data.len() > super::MAX_SVG_BYTES {
        return Lines::NotLines("too large");
    }
    let lines = match read::polylines(data) {
        Ok(l) => l,
        Err(NotLines::Shapes(what)) => return Lines::NotLines(what),
        Err(NotLines::Steps(why)) => {
            return Lines::Unexplained {
                why,
                steps: 0,
                timed_out: false,
                stats: Stats::default(),
            };
        }
    };
    let read_ms = ms(start);
    let mut tried = Tried {
        stats: Stats {
            read_ms,
            ..Stats::default()
        },
        ..Tried::default()
    };
    // A grammar whose axiom says more than its rules explains little of
    // the drawing: held while the stroke graph's search looks for a
    // smaller one.
    let held = match by_reading(&lines, name, opts, deadline, None, None, &mut tried) {
        Some(found) if !axiom_heavy(&found.grammar) => return Lines::Found(found),
        held => held,
    };
    let graph = graph::build(&lines, 1).ok();
    // A branching drawing whose steps came in any order: read again as the
    // walks a turtle could have drawn it in, from its likeliest roots; a
    // noisy one as the turtle meant it, checked against it as it is.
    // Each with its noise when checked against the drawing as it is, and
    // whether it is a redrawing on the lattice.
    let mut again: Vec<(Vec<Vec<DVec2>>, Option<f64>, bool)> = Vec::new();
    let ideal = graph.as_ref().map(ideal::redrawn).unwrap_or_default();
    if let Some(g) = &graph {
        again.extend(walk::trees(g).into_iter().map(|w| (w, None, false)));
        // A path saved as several paths (a single one was read above).
        if lines.len() > 1 {
            again.extend(walk::paths(g).into_iter().map(|w| (w, None, false)));
        }
        again.extend(ideal.iter().cloned().map(|w| (w, None, true)));
    }
    let as_drawn: Vec<(DVec2, DVec2)> = lines
        .iter()
        .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
        .collect();
    // Together they may take half the budget, each an equal share.
    let share = opts.budget / (2 * again.len().max(1)) as u32;
    for (walk, noise, redrawn) in again {
        if held.is_some() {
            break;
        }
        if late() {
            tried.timed_out = true;
            break;
        }
        let mut more = Tried {
            stats: tried.stats.clone(),
            ..Tried::default()
        };
        let truth = noise.map(|n| (&as_drawn[..], n));
        let until = Instant::now()
            .checked_add(share)
            .map_or(deadline, |t| Some(deadline.map_or(t, |d| d.min(t))));
        let drawn = redrawn.then_some(&as_drawn[..]);
        if let Some(found) = by_reading(&walk, name, opts, until, truth, drawn, &mut more) {
            return Lines::Found(found);
        }
        tried.stats = more.stats;
        tried.timed_out |= more.timed_out;
    }
    let Tried {
        mut why,
        steps,
        mut timed_out,
        mut stats,
    } = tried;
    // The drawing as a set of segments: a grammar that draws each once,
    // whatever the order, direction and splitting of its paths.
    // A noisy drawing as the turtle meant it first (its stroke graph is
    // clean), then as it is.
    // One count of work for all of them (each redrawing, the drawing as
    // it is): more redrawings do not make a failing drawing slower.
    let t = Instant::now();
    let mut left = opts.graph.total;
    let by_graph = ideal
        .iter()
        .find_map(|w| {
            let drawn = Some(&as_drawn[..]);
            from_graph(w, drawn, name, &opts.graph, &mut left, &mut stats).ok()
        })
        .map_or_else(
            || from_graph(&lines, None, name, &opts.graph, &mut left, &mut stats),
            Ok,
        );
    stats.search_ms += ms(t);
    match (by_graph, held) {
        (Ok(found), Some(h)) if description(&h.grammar) <= description(&found.grammar) => {
            return Lines::Found(h);
        }
        (Ok(found), _) => return Lines::Found(found),
        (Err(_), Some(h)) => return Lines::Found(h),
        (Err(late), None) => timed_out |= late,
    }
    // Read as steps but unexplained: say that, not why another reading failed.
    if why.is_empty() || steps > 0 {
        why = "no D0L system of the classes it searches (one to three drawing letters, node letters, branches, moves) draws it".into();
    }
    Lines::Unexplained {
        why,
        steps,
        timed_out,
        stats,
    }
}

/// What the readings of a drawing came to when no grammar explained it.
#[derive(Default)]
struct Tried {
    why: String,
    /// Drawn steps at the first reading (0: no reading).
    steps: usize,
    timed_out: bool,
    stats: Stats,
}

/// The drawing read as turtle steps in its paths' order (steps as long as
/// the shortest segment, then half as long) and the grammars the search
/// proposes for it, each matched step by step and redrawn: against `lines`,
/// or against `truth` (the drawing as it is, and its noise in steps) when
/// `lines` is its redrawing. `drawn`: the drawing as it is when `lines` is
/// its redrawing on the lattice (for the angle a person writes).
#[allow(clippy::too_many_arguments)]
fn by_reading(
    lines: &[Vec<DVec2>],
    name: &str,
    opts: &Options,
    deadline: Option<Instant>,
    truth: Option<(&[(DVec2, DVec2)], f64)>,
    drawn: Option<&[(DVec2, DVec2)]>,
    tried: &mut Tried,
) -> Option<Box<Inferred>> {
    let late = || deadline.is_some_and(|d| Instant::now() >= d);
    // The size of the drawing's own turtle string (at the first reading).
    let mut drawing_size = 0;
    // Steps as long as the shortest segment, or half as long (a drawing
    // whose steps all come in pairs, such as F -> FF plants).
    for split in [1, 2] {
        if late() {
            tried.timed_out = true;
            break;
        }
        let mut reading = match read::reading(lines, split) {
            Ok(r) => r,
            Err(e) => {
                if tried.why.is_empty() {
                    tried.why = match e {
                        NotLines::Steps(w) => w,
                        NotLines::Shapes(w) => w.to_string(),
                    };
                }
                continue;
            }
        };
        if tried.steps == 0 {
            tried.steps = reading.steps;
            drawing_size = drawing_symbols(&reading);
        }
        let noise = truth.map_or(0.0, |(segments, noise)| {
            reading.segments = segments.to_vec();
            noise
        });
        tried.stats.steps = reading.steps;
        tried.stats.angle = reading.angles.delta;
        let t = Instant::now();
        let limits = search::Limits {
            deadline,
            ..opts.limits
        };
        let proposals = search::propose(&reading.tree, &reading.angles, &limits);
        tried.timed_out |= proposals.timed_out;
        tried.stats.candidates += proposals.grammars.len();
        let work = 64 * reading.tree.nodes.len() as u64 + 100_000;
        let mut verified = 0;
        for g in proposals.grammars {
            if late() {
                tried.timed_out = true;
                break;
            }
            if !explains(&g, drawing_size) {
                continue;
            }
            tried.stats.compared += 1;
            if grammar::matches(&g, &reading.tree, &reading.angles, work, deadline) != Outcome::Same
            {
                continue;
            }
            let g = deepest(g, &reading, work, deadline);
            // The library's redraw is the costly check: a few per reading.
            verified += 1;
            if verified > MAX_REDRAWS {
                break;
            }
            tried.stats.search_ms += ms(t);
            let tv = Instant::now();
            let (g, angles) = grammar::aligned(&g, &reading.angles);
            let reading = in_angles(&reading, angles);
            if let Some(found) = finish(&g, &reading, name, work, noise, drawn) {
                tried.stats.verify_ms = ms(tv);
                tried.stats.rules = g.letters.iter().filter(|l| l.rule.is_some()).count();
                tried.stats.rule_symbols = g.rule_size();
                tried.stats.depth = g.depth;
                let (file, text, redraw) = found;
                return Some(Box::new(Inferred {
                    grammar: g,
                    file,
                    text,
                    redraw,
                    stats: tried.stats.clone(),
                }));
            }
        }
        tried.stats.search_ms += ms(t);
    }
    None
}

/// A grammar that draws every segment of the drawing's stroke graph once
/// (`synth`), checked as every candidate is: its walk read as steps, the
/// grammar matched against them and redrawn by the library. `Err(true)`
/// when the budget ended the search. The searches spend from `left`.
fn from_graph(
    lines: &[Vec<DVec2>],
    drawn: Option<&[(DVec2, DVec2)]>,
    name: &str,
    opts: &synth::Limits,
    left: &mut u64,
    stats: &mut Stats,
) -> Result<Box<Inferred>, bool> {
    let deadline = opts.deadline;
    let late = || deadline.is_some_and(|d| Instant::now() >= d);
    let mut noisy = false;
    for split in [1, 2] {
        if late() {
            return Err(true);
        }
        let Ok(g) = graph::build(lines, split) else {
            continue;
        };
        let branches =
            g.adj.iter().any(|a| a.len() > 2) || g.adj.iter().filter(|a| a.len() == 1).count() > 2;
        // Half steps of a noisy drawing are noise.
        if split == 1 {
            noisy = g.noise >= ideal::NOISY;
        } else if noisy {
            continue;
        }
        if *left == 0 {
            return Err(true);
        }
        let limits = synth::Limits {
            brackets: branches,
            total: *left,
            ..*opts
        };
        let mut spent = 0;
        let found = synth::search_counted(&g, &limits, &mut spent);
        *left = left.saturating_sub(spent);
        let Some(found) = found.map(|f| f.squared().unfolded()) else {
            continue;
        };
        stats.candidates += 1;
        let reading = match read::reading(&found.walk, 1) {
            Ok(r) => r,
            Err(_) => continue,
        };
        let Some(gr) = to_grammar(&found, &reading.angles) else {
            continue;
        };
        if !explains(&gr, drawing_symbols(&reading)) {
            continue;
        }
        stats.compared += 1;
        stats.steps = reading.steps;
        stats.angle = reading.angles.delta;
        let work = 64 * reading.tree.nodes.len() as u64 + 100_000;
        if grammar::matches(&gr, &reading.tree, &reading.angles, work, deadline) != Outcome::Same {
            continue;
        }
        let gr = deepest(gr, &reading, work, deadline);
        // The walk may run from the drawing's end: the same curve drawn
        // from where its paths start, when the reversed grammar draws it
        // and the grammar found does not.
        let draws = |g: &Grammar, r: &Reading| {
            r.angles.period == reading.angles.period
                && (r.angles.delta - reading.angles.delta).abs() < 1e-6
                && grammar::matches(g, &r.tree, &r.angles, work, deadline) == Outcome::Same
        };
        let (gr, reading) = match (
            root::reversed(&gr, &reading.angles),
            read::reading(lines, split),
        ) {
            (Some(back), Ok(as_drawn)) if !draws(&gr, &as_drawn) && draws(&back, &as_drawn) => {
                (back, as_drawn)
            }
            _ => (gr, reading),
        };
        let tv = Instant::now();
        let (gr, angles) = grammar::aligned(&gr, &reading.angles);
        let reading = in_angles(&reading, angles);
        if let Some((file, text, redraw)) = finish(&gr, &reading, name, work, g.noise, drawn) {
            stats.verify_ms = ms(tv);
            stats.rules = gr.letters.iter().filter(|l| l.rule.is_some()).count();
            stats.rule_symbols = gr.rule_size();
            stats.depth = gr.depth;
            return Ok(Box::new(Inferred {
                grammar: gr,
                file,
                text,
                redraw,
                stats: stats.clone(),
            }));
        }
    }
    Err(late())
}

/// `g`, or the deepest of its roots (`root`) that draws the reading too.
fn deepest(mut g: Grammar, r: &Reading, work: u64, deadline: Option<Instant>) -> Grammar {
    // A root's root: a power of a power (at most a few times over).
    for _ in 0..4 {
        let root = root::deeper(&g, &r.angles)
            .into_iter()
            .find(|d| grammar::matches(d, &r.tree, &r.angles, work, deadline) == Outcome::Same);
        match root {
            Some(d) => g = d,
            None => break,
        }
    }
    g
}

/// `r` counted in `angles` (δ or a whole fraction of it, see
/// `grammar::aligned`).
fn in_angles(r: &Reading, angles: turtle::Angles) -> std::borrow::Cow<'_, Reading> {
    if angles == r.angles {
        return std::borrow::Cow::Borrowed(r);
    }
    let k = r.angles.delta / angles.delta;
    let mut out = r.clone();
    out.angles = angles;
    out.delta_error /= k;
    std::borrow::Cow::Owned(out)
}

/// A found grammar in the symbols of the candidates, its turns counted in
/// the reading's δ (which may be a multiple of the graph's δ₀).
fn to_grammar(f: &synth::Found, angles: &turtle::Angles) -> Option<Grammar> {
    let ratio = f.delta / angles.delta;
    let syms = |v: &[synth::Sym]| -> Option<Vec<grammar::Sym>> {
        let mut out = Vec::new();
        for s in v {
            match *s {
                synth::Sym::Letter(k) => out.push(grammar::Sym::Letter(k)),
                synth::Sym::Unnamed => out.push(grammar::Sym::Letter(0)),
                synth::Sym::Push => out.push(grammar::Sym::Push),
                synth::Sym::Pop => out.push(grammar::Sym::Pop),
                synth::Sym::Turn(t) => {
                    let k = f64::from(t) * ratio;
                    if (k - k.round()).abs() > 1e-6 {
                        return None;
                    }
                    out.extend(grammar::turn_syms(k.round() as i32, angles));
                }
            }
        }
        Some(out)
    };
    const NAMES: [char; 3] = ['F', 'G', 'H'];
    let mut letters = Vec::new();
    for (k, r) in f.rules.iter().enumerate() {
        letters.push(grammar::Letter {
            name: *NAMES.get(k)?,
            action: grammar::Action::Draw,
            rule: Some(syms(r)?),
        });
    }
    Some(Grammar {
        letters,
        axiom: syms(&f.axiom)?,
        depth: f.depth,
    })
}

/// A grammar's size as text: its axiom, and each rule its successor and
/// two symbols more (the letter it rewrites and the arrow).
fn description(g: &Grammar) -> usize {
    let rules = g.letters.iter().filter(|l| l.rule.is_some()).count();
    g.axiom.len() + g.rule_size() + 2 * rules
}

/// Whether a grammar's axiom is longer than its rules together.
fn axiom_heavy(g: &Grammar) -> bool {
    g.axiom.len() > g.rule_size()
}

/// Whether a grammar says more than the drawing itself: at most half its
/// size, and not only rules that lengthen steps (`F -> FF` with the
/// drawing as the axiom).
fn explains(g: &Grammar, drawing_size: usize) -> bool {
    let small = 2 * (g.rule_size() + g.axiom.len()) <= drawing_size;
    let lengthens = g.letters.iter().enumerate().all(|(k, l)| {
        l.rule
            .as_ref()
            .is_none_or(|r| r.iter().all(|s| *s == grammar::Sym::Letter(k as u8)))
    });
    small && !lengthens
}

/// Roughly how many symbols the drawing's own turtle string has: a grammar
/// must be shorter to explain anything.
fn drawing_symbols(r: &Reading) -> usize {
    let turns: usize = r
        .tree
        .nodes
        .iter()
        .map(|n| n.turn.unsigned_abs() as usize)
        .sum();
    let branches = r
        .tree
        .nodes
        .iter()
        .enumerate()
        .filter(|(i, n)| n.parent != turtle::ROOT && n.parent as usize + 1 != *i)
        .count();
    r.tree.nodes.len() + turns + 2 * branches
}

/// A turn of `deg` degrees: bare symbols when it is a few turns of δ.
fn turn(deg: f64, delta: f64) -> Vec<Module> {
    let k = (deg / delta).round();
    if (deg - k * delta).abs() <= 1e-6 * delta.max(1.0) && k.abs() <= 4.0 {
        let c = if k > 0.0 { '+' } else { '-' };
        return vec![sym(c, None); k.abs() as usize];
    }
    let d = nice(deg, 1e-4);
    if d == 0.0 {
        return Vec::new();
    }
    vec![sym(
        if d > 0.0 { '+' } else { '-' },
        Some(Expr::num(d.abs())),
    )]
}

/// Where the program puts the drawing: the heading of the first step
/// (degrees from +y) and where the turtle starts (user units).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frame {
    heading: f64,
    start: DVec2,
}

/// The settings of `g` drawn at a `decimal` δ in the frame that fits the
/// drawing as it is (`drawn`) best, and how they redraw it: the first
/// step's frame and step, moved and scaled by the similarity that brings
/// what it draws nearest the drawing (its turn either way round, the
/// closer). `(p_c, k_c)`: where the first step starts and its heading in δ
/// (`grammar::first_step`).
fn decimal_frame<'a>(
    g: &Grammar,
    r: &Reading,
    drawn: &[(DVec2, DVec2)],
    decimal: f64,
    step: f64,
    (p_c, k_c): (DVec2, i32),
    settings: &dyn Fn((f64, Frame, f64)) -> emit::Settings<'a>,
) -> Option<(emit::Settings<'a>, verify::Redraw)> {
    let heading = turtle::wrap_degrees(r.heading - f64::from(k_c) * decimal);
    let first = Frame {
        heading,
        start: place(r.start, p_c, heading, step),
    };
    let text = |f: Frame, step: f64| {
        let s = settings((decimal, f, step));
        (crate::fmt::format_file(&emit::program(g, &s)), s)
    };
    let (draft, _) = text(first, step);
    let fit = verify::similarity_fit(&verify::drawn(&draft, 0)?, drawn)?;
    let turned = fit.angle().to_degrees();
    // The step as precise as a drawing of a few hundred steps across needs
    // (five digits), not the fit's sixteen.
    let step = nice(step * fit.scale(), 2e-5 * step);
    [turned, -turned]
        .into_iter()
        .filter_map(|t| {
            let f = Frame {
                heading: turtle::wrap_degrees(heading + t),
                start: fit.apply(first.start),
            };
            let (draft, s) = text(f, step);
            verify::redraw(&draft, drawn, r.step).map(|d| (s, d))
        })
        .min_by(|a, b| a.1.chamfer.total_cmp(&b.1.chamfer))
}

/// Where the turtle starts so that the first step, which starts at `p_c`
/// steps from it, starts at `first` once turned by `heading` degrees and
/// scaled by `step`.
fn place(first: DVec2, p_c: DVec2, heading: f64, step: f64) -> DVec2 {
    let rot = heading.to_radians();
    let rotated = DVec2::new(
        p_c.x * rot.cos() - p_c.y * rot.sin(),
        p_c.x * rot.sin() + p_c.y * rot.cos(),
    );
    first - rotated * step
}

/// The turns and moves that put the turtle at `f`'s start and heading.
fn frame_modules(f: &Frame, angle: f64, tol: f64) -> Vec<Module> {
    let mut out = Vec::new();
    if f.start.length() > tol {
        let r = f.start.length();
        let beta = nice(
            turtle::wrap_degrees(f.start.y.atan2(f.start.x).to_degrees() - 90.0),
            (tol / r).to_degrees().min(1e-3),
        );
        out.extend(turn(beta, angle));
        out.push(sym('f', Some(Expr::num(nice(r, tol)))));
        out.extend(turn(turtle::wrap_degrees(f.heading - beta), angle));
    } else {
        out.extend(turn(f.heading, angle));
    }
    out
}

/// The frame rounded as a person would have drawn it: the heading to a
/// multiple of δ or a whole degree, the start to the origin, when they are
/// that close.
fn rounded(f: &Frame, angle: f64, step: f64) -> Frame {
    let k = (f.heading / angle).round() * angle;
    let heading = if (f.heading - k).abs() <= 0.1 {
        k
    } else if (f.heading - f.heading.round()).abs() <= 0.1 {
        f.heading.round()
    } else {
        f.heading
    };
    let start = if f.start.length() <= 0.05 * step {
        DVec2::ZERO
    } else {
        f.start
    };
    Frame { heading, start }
}

/// The program of a grammar that matched the drawing step by step: the
/// frame that puts it on the drawing, the text, and the library's redraw;
/// `None` if the redraw is not within 10⁻³ of the diagonal. The frame is
/// written rounded when that draws as close to the drawing.
fn finish(
    g: &Grammar,
    r: &Reading,
    name: &str,
    work: u64,
    noise: f64,
    drawn: Option<&[(DVec2, DVec2)]>,
) -> Option<(crate::ast::File, String, verify::Redraw)> {
    let angle = if r.angles.period.is_some() {
        nice(r.angles.delta, 1e-6)
    } else {
        nice(r.angles.delta, (3.0 * r.delta_error).max(1e-6))
    };
    // The step as precise as the drawing says it (a step rounded within
    // 10⁻⁴ draws level n but may drift by a step over a larger next level),
    // and rounded within 10⁻⁴, as a person would write it when it draws as
    // close (a drawing's coordinates, rounded, make its steps look shorter).
    let step = nice(r.step, (3.0 * r.step_error).max(1e-6 * r.step));
    let round_step = nice(r.step, (3.0 * r.step_error).max(1e-4 * r.step));
    let (p_c, k_c) = grammar::first_step(g, &r.angles, work)?;
    let tol = (3.0 * r.frame_error.1).max(2e-3 * step);
    // The frame for an angle: the first step's heading less its turns, and
    // where the turtle must start for its first step to start where the
    // drawing's does.
    let frame = |angle: f64, step: f64| {
        let phi = turtle::wrap_degrees(r.heading - f64::from(k_c) * angle);
        let heading = nice(phi, (3.0 * r.frame_error.0).max(1e-3));
        Frame {
            heading,
            start: place(r.start, p_c, heading, step),
        }
    };
    // As measured (by the whole drawing when the grammar's steps pair up
    // with it, precise enough for its far end: within a fiftieth of a step
    // there), and as a person would have written it: δ to a twentieth of a
    // degree, the heading to a multiple of δ or a whole degree, the start
    // at the origin, when they are that close.
    // Only for δ = 360/m, written exactly: a δ read from the turns is
    // itself a little off, and a frame fitted to it puts the error on the
    // root as well as on the tips.
    let fitted = r.angles.period.and_then(|_| frame::fit(g, angle, r, work));
    let precise = match fitted {
        Some(f) => {
            let far = 0.02 / f.extent;
            let heading = nice(turtle::wrap_degrees(f.heading), far.to_degrees().min(1e-3));
            let step = nice(f.step, far * f.step);
            let start = place(r.start, p_c, heading, step);
            // The start from the first step, unless the fit puts it closer
            // to every step.
            let start = if start.distance(f.start) <= 0.01 * step {
                start
            } else {
                f.start
            };
            (angle, Frame { heading, start }, step)
        }
        None => (angle, frame(angle, step), step),
    };
    let round_angle = if r.angles.period.is_some() {
        angle
    } else {
        nice(angle, 0.05)
    };
    let mut round = rounded(&frame(round_angle, round_step), round_angle, round_step);
    if !(round.start == DVec2::ZERO && p_c == DVec2::ZERO) {
        round.start = place(r.start, p_c, round.heading, round_step);
    }
    let (source, system) = super::program::names(name);
    let settings = |(angle, f, step): (f64, Frame, f64)| emit::Settings {
        source: &source,
        name: system.clone(),
        angle,
        step,
        frame: frame_modules(&f, angle, tol),
        redraw: verify::Redraw {
            matched: 0,
            steps: r.steps,
            drawn: 0,
            chamfer: 0.0,
            diagonal: 0.0,
        },
    };
    let check = |settings: &emit::Settings| {
        let draft = crate::fmt::format_file(&emit::program(g, settings));
        verify::redraw(&draft, &r.segments, r.step).filter(|d| {
            // Within 10⁻³ of the diagonal, or of the drawing's own noise
            // (its points' spread about their vertices, its steps' about
            // their length) when larger.
            let limit = (1e-3f64).max(2.0 * noise * r.step / d.diagonal.max(1e-300));
            d.drawn == d.steps && d.relative() <= limit
        })
    };
    let mut best = settings(precise);
    let mut redraw = check(&best);
    let person = settings((round_angle, round, round_step));
    if person.frame != best.frame || person.angle != best.angle || person.step != best.step {
        let other = check(&person);
        let better = match (&other, &redraw) {
            // As many steps matched, and as close: a heading rounded by a
            // tenth of a degree still matches level n's steps, but not the
            // next level's, which are further out.
            (Some(o), Some(p)) => {
                o.matched >= p.matched && o.relative() <= 1.25 * p.relative() + 1e-9
            }
            (Some(_), None) => true,
            _ => false,
        };
        if better {
            best = person;
            redraw = other;
        }
    }
    let mut redraw = redraw?;
    // A redrawing on the lattice says δ = 360/m; the drawing as it is may
    // allow the shorter decimal a person writes (25.7 rather than 360/14 =
    // 25.714286): the decimal, its frame fitted to the drawing as it is
    // (the lattice's frame is fitted to 360/m), chosen as `read` chooses
    // δ, when it fits about as well. (360/m's frame, fitted through the
    // redrawing to the noise, fits the noisy drawing better than the truth
    // does: bracketed seed 25 noisy, Chamfer 1.40 against the true
    // drawing's 1.49 and the decimal's 1.51.)
    if let Some(drawn) = drawn
        && r.angles.period.is_some()
        && let Some(decimal) = Some(nice(angle, 0.05)).filter(|d| *d != angle)
        && let Some((person, d)) =
            decimal_frame(g, r, drawn, decimal, best.step, (p_c, k_c), &settings)
    {
        let draft = crate::fmt::format_file(&emit::program(g, &best));
        if let Some(b) = verify::redraw(&draft, drawn, r.step)
            && d.drawn == b.drawn
            && d.chamfer <= 1.1 * b.chamfer
        {
            best = person;
            redraw = d;
        }
    }
    let mut settings = best;
    settings.redraw = redraw;
    let file = emit::program(g, &settings);
    let text = crate::fmt::format_file(&file);
    Some((file, text, redraw))
}
