//! The check: a drawing of a random program is inferred, and counts as
//! **exact** when inference gives a grammar (not the element fallback)
//! whose program, derived and drawn by the library, draws the same unit
//! segments as the drawing at its own depth and as the next level one
//! step further (within 0.2 of a step, in the world coordinates lsyc reads
//! both SVG files in). "Same grammar" (up to renaming letters) is the
//! secondary figure.

use super::draw::{self, Drawing, Transform, Variant};
use super::programs::{self, Class, Program, Rejections};
use super::rng::Rng;
use glam::{DVec2, DVec3};
use lsyc::infer::lines::{self, Lines};
use std::cell::OnceCell;
use std::collections::{BTreeMap, HashMap};
use std::time::{Duration, Instant};

/// Positions within this many steps are the same.
const TOLERANCE: f64 = 0.2;
/// Deriving or drawing an inferred program stops beyond this many modules.
const MAX_MODULES: usize = 5_000_000;

/// One random program and its drawings.
pub struct Case {
    pub class: Class,
    pub seed: u64,
    pub program: Program,
    /// Where the drawing is put in every variant but `clean`.
    pub transform: Transform,
    pub level: Drawing,
    pub next: Drawing,
    /// The truth as read by lsyc, clean and placed (`truth`).
    read: [OnceCell<Option<Truth>>; 2],
}

/// Level n and n + 1 as lsyc reads them (world coordinates), and the step.
struct Truth {
    level: Segs,
    next: Segs,
    step: f64,
}

impl Case {
    /// The program of `class` drawn from `seed`, and its drawings.
    pub fn new(class: Class, seed: u64, rejections: &mut Rejections) -> Option<Case> {
        let mut rng = Rng::of(&[class as u64, seed]);
        let program = programs::generate(class, &mut rng, rejections)?;
        let transform = Transform::random(&mut rng);
        let level = draw::draw(&program, &draw::derive(&program, program.depth));
        let next = draw::draw(&program, &draw::derive(&program, program.depth + 1));
        Some(Case {
            class,
            seed,
            program,
            transform,
            level,
            next,
            read: Default::default(),
        })
    }

    /// The level-n drawing as SVG in `variant`.
    pub fn svg(&self, variant: Variant) -> String {
        let mut rng = Rng::of(&[self.class as u64, self.seed, 1 + variant as u64]);
        draw::svg(&self.level, variant, &self.transform, &mut rng)
    }

    /// The drawings the prediction is compared with: level n and n + 1,
    /// placed as `variant` is but without its noise, written as SVG and
    /// read back by lsyc (`None` if they do not read).
    fn truth(&self, variant: Variant) -> Option<&Truth> {
        let (v, step) = match variant {
            Variant::Clean => (Variant::Clean, 1.0),
            _ => (Variant::Rotated, self.transform.scale),
        };
        self.read[usize::from(v != Variant::Clean)]
            .get_or_init(|| {
                let mut rng = Rng::new(0);
                let mut read = |d: &Drawing| {
                    let svg = draw::svg(d, v, &self.transform, &mut rng);
                    lines::read::polylines(svg.as_bytes())
                        .ok()
                        .map(|l| segments(&l))
                };
                Some(Truth {
                    level: read(&self.level)?,
                    next: read(&self.next)?,
                    step,
                })
            })
            .as_ref()
    }
}

/// Why a drawing does not count as exact.
#[derive(Clone, Debug, PartialEq)]
pub enum Fail {
    /// No grammar: inference gave up (its reason), and the element
    /// fallback would be used.
    Fallback(String),
    /// No grammar within the time budget.
    Timeout,
    /// A grammar whose program does not draw the drawing: half steps of
    /// the drawing it misses, and steps it draws that the drawing has not.
    AtN { missing: usize, extra: usize },
    /// A grammar that draws the drawing but not the next level.
    Next { missing: usize, extra: usize },
    /// A grammar that draws the drawing, and the next level once its
    /// drawing at level n is fitted onto the drawing (a similarity, least
    /// squares), but not the next level as written: the placement (start,
    /// heading, step, δ as written) is off by more than the tolerance at
    /// the next level.
    Frame { missing: usize, extra: usize },
    /// A panic, a program that does not run, an unreadable truth.
    Error(String),
}

impl Fail {
    /// The kind, for tables.
    pub fn kind(&self) -> &'static str {
        match self {
            Fail::Fallback(_) => "fallback",
            Fail::Timeout => "timeout",
            Fail::AtN { .. } => "wrong at n",
            Fail::Next { .. } => "wrong next",
            Fail::Frame { .. } => "frame",
            Fail::Error(_) => "error",
        }
    }

    pub fn detail(&self) -> String {
        match self {
            Fail::Fallback(why) => why.clone(),
            Fail::Timeout => "the search's budget ended".into(),
            Fail::AtN { missing, extra }
            | Fail::Next { missing, extra }
            | Fail::Frame { missing, extra } => {
                format!("{missing} half steps missing, {extra} extra")
            }
            Fail::Error(e) => e.clone(),
        }
    }
}

/// What one inference gave.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub exact: bool,
    /// The same grammar as the program's, up to renaming letters.
    pub same: bool,
    pub fail: Option<Fail>,
    /// Milliseconds of the inference (reading, search and its own check).
    pub ms: f64,
    /// The inferred grammar in one line, if any.
    pub found: Option<String>,
    /// The inferred program, if any (the bench's `--show`).
    #[allow(dead_code)]
    pub text: Option<String>,
}

// ------------------------------------------------------------ the adapter

/// An inferred grammar, in this module's terms.
pub struct Found {
    /// The program's text.
    pub text: String,
    pub grammar: Grammar,
    pub describe: String,
}

/// What inference made of a drawing.
pub enum Inference {
    Found(Found),
    Unexplained { why: String, timed_out: bool },
    NotLines(String),
}

/// The work the stroke-graph search may do when a budget is given (the
/// debug-build property test): a thirty-second of its default, so that the
/// drawings it cannot explain cost about a quarter of a second each in a
/// debug build (the property test's 900 inferences stay within minutes).
const TEST_GRAPH_WORK: u64 = 250_000;

/// The one place this module calls inference: the library's line-drawing
/// inference with its default options, but for the time budget (and the
/// graph search's work, `TEST_GRAPH_WORK`) when `budget` is given.
pub fn infer(svg: &[u8], budget: Option<Duration>) -> Inference {
    let mut opts = lines::Options::default();
    if let Some(b) = budget {
        opts.budget = b;
        opts.graph.total = TEST_GRAPH_WORK;
    }
    match lines::from_svg(svg, "random.svg", &opts) {
        Lines::Found(f) => {
            let g = &f.grammar;
            let kind = |a: lines::grammar::Action| match a {
                lines::grammar::Action::Draw => Kind::Draw,
                lines::grammar::Action::Move => Kind::Move,
                lines::grammar::Action::Nothing => Kind::Nothing,
            };
            let grammar = Grammar {
                angle: f.stats.angle,
                axiom: g.text(&g.axiom),
                rules: g
                    .letters
                    .iter()
                    .filter_map(|l| l.rule.as_ref().map(|r| (l.name, g.text(r))))
                    .collect(),
                kinds: g.letters.iter().map(|l| (l.name, kind(l.action))).collect(),
                depth: g.depth,
            };
            Inference::Found(Found {
                text: f.text.clone(),
                describe: g.describe(),
                grammar,
            })
        }
        Lines::NotLines(what) => Inference::NotLines(what.to_string()),
        Lines::Unexplained { why, timed_out, .. } => Inference::Unexplained { why, timed_out },
    }
}

// ------------------------------------------------------------ the check

/// Infers `case`'s level-n drawing in `variant` (with `budget`, or the
/// default one) and judges the result.
pub fn check(case: &Case, variant: Variant, budget: Option<Duration>) -> Outcome {
    let svg = case.svg(variant);
    let start = Instant::now();
    let inferred = std::panic::catch_unwind(|| infer(svg.as_bytes(), budget));
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let fail = |f: Fail, found: Option<(String, String)>| Outcome {
        exact: false,
        same: false,
        fail: Some(f),
        ms,
        text: found.as_ref().map(|f| f.1.clone()),
        found: found.map(|f| f.0),
    };
    let found = match inferred {
        Err(_) => return fail(Fail::Error("inference panicked".into()), None),
        Ok(Inference::NotLines(what)) => {
            return fail(Fail::Fallback(format!("not a line drawing: {what}")), None);
        }
        Ok(Inference::Unexplained {
            timed_out: true, ..
        }) => return fail(Fail::Timeout, None),
        Ok(Inference::Unexplained { why, .. }) => return fail(Fail::Fallback(why), None),
        Ok(Inference::Found(f)) => f,
    };
    let same = same_grammar(&Grammar::of(&case.program), &found.grammar);
    let described = Some((found.describe.clone(), found.text.clone()));
    let Some(Truth { level, next, step }) = case.truth(variant) else {
        return fail(Fail::Error("the truth does not read".into()), described);
    };
    let step = *step;
    let drawn = match redraw(&found.text) {
        Ok(d) => d,
        Err(e) => return fail(Fail::Error(e), described),
    };
    let (missing, extra) = compare(level, &drawn.0, step);
    if missing + extra > 0 {
        return Outcome {
            same,
            ..fail(Fail::AtN { missing, extra }, described)
        };
    }
    let (missing, extra) = compare(next, &drawn.1, step);
    // A drawing whose steps came in any order and direction no longer says
    // where it starts: a grammar that reads it from another end or corner
    // predicts the next level up to where that is drawn (a rigid motion,
    // or a mirror image, of it).
    let lost_start = variant == Variant::Shuffled;
    if missing + extra > 0 && !(lost_start && congruent(next, &drawn.1, step)) {
        // The next level, placed as the program's level n best fits the
        // drawing's.
        let (truth, ours) = (unit_steps(level, step), unit_steps(&drawn.0, step));
        let f = fit(&truth, &ours, step);
        let moved: Segs = drawn.1.iter().map(|&(a, b)| (f(a), f(b))).collect();
        let why = match compare(next, &moved, step) {
            (0, 0) => Fail::Frame { missing, extra },
            _ => Fail::Next { missing, extra },
        };
        return Outcome {
            same,
            ..fail(why, described)
        };
    }
    Outcome {
        exact: true,
        same,
        fail: None,
        ms,
        found: Some(found.describe),
        text: Some(found.text),
    }
}

/// Whether a rigid motion, or one with a mirror, puts `drawn` onto `truth`
/// as sets of steps: `drawn`'s first step onto any step of `truth`, either
/// way round, tried on a sample of steps first.
pub fn congruent(truth: &[(DVec2, DVec2)], drawn: &[(DVec2, DVec2)], step: f64) -> bool {
    let (a, b) = (unit_steps(truth, step), unit_steps(drawn, step));
    let Some(&(p, q)) = b.first() else {
        return false;
    };
    if a.len() != b.len() {
        return false;
    }
    // Steps of `a` by the cell of their midpoint.
    let key = |m: DVec2| ((m.x / step).floor() as i64, (m.y / step).floor() as i64);
    let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in a.iter().enumerate() {
        cells.entry(key((s.0 + s.1) / 2.0)).or_default().push(i);
    }
    let tol = TOLERANCE * step;
    let has = |x: DVec2, y: DVec2| {
        let (cx, cy) = key((x + y) / 2.0);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                cells.get(&(cx + dx, cy + dy)).is_some_and(|v| {
                    v.iter().any(|&i| {
                        let t = a[i];
                        (t.0.distance(x) <= tol && t.1.distance(y) <= tol)
                            || (t.0.distance(y) <= tol && t.1.distance(x) <= tol)
                    })
                })
            })
        })
    };
    let sample: Segs = b.iter().step_by((b.len() / 16).max(1)).copied().collect();
    let u = (q - p).normalize_or_zero();
    for &(s, t) in &a {
        for (s, t) in [(s, t), (t, s)] {
            let v = (t - s).normalize_or_zero();
            let (c, sn) = (u.dot(v), u.perp_dot(v));
            for mirror in [false, true] {
                // z ↦ s + R(z − p), R turning u onto v (after a mirror
                // about u's line).
                let motion = |z: DVec2| {
                    let d = z - p;
                    let d = if mirror { 2.0 * d.dot(u) * u - d } else { d };
                    s + DVec2::new(c * d.x - sn * d.y, sn * d.x + c * d.y)
                };
                let fits =
                    |segs: &[(DVec2, DVec2)]| segs.iter().all(|&(x, y)| has(motion(x), motion(y)));
                if fits(&sample) && fits(&b) {
                    return true;
                }
            }
        }
    }
    false
}

fn segments(lines: &[Vec<DVec2>]) -> Vec<(DVec2, DVec2)> {
    lines
        .iter()
        .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
        .collect()
}

/// Collects drawn segments in the plane.
#[derive(Default)]
struct Segments(Vec<(DVec2, DVec2)>);

impl lsyc::turtle::Sink for Segments {
    fn segment(&mut self, a: DVec3, b: DVec3, _width: f64, _color: u32) {
        self.0.push((a.truncate(), b.truncate()));
    }
    fn polygon(&mut self, _points: &[DVec3], _color: u32) {}
    fn element(&mut self, _i: u16, _at: DVec3, _h: DVec3, _l: DVec3, _s: f64, _c: u32) {}
}

type Segs = Vec<(DVec2, DVec2)>;

/// The program `text` derived and drawn by the library (as `lsyc run` and
/// inference's own check do) at its `derive` and one step further.
pub fn redraw(text: &str) -> Result<(Segs, Segs), String> {
    let fe = lsyc::frontend::run(text, Vec::new(), &[]);
    if fe.has_errors() {
        return Err("the inferred program has errors".into());
    }
    let checked = fe.checked.as_ref().ok_or("not checked")?;
    let prog = lsyc::compile::compile(&fe.file, checked, None)
        .map_err(|_| "the inferred program does not compile".to_string())?;
    let limits = lsyc::derive::Limits {
        max_modules: MAX_MODULES,
        ..lsyc::derive::Limits::default()
    };
    let axiom = lsyc::derive::axiom(&prog, &vec![0.0; prog.params.len()], 0)
        .map_err(|e| format!("axiom: {e}"))?;
    let at = lsyc::derive::derive(&prog, axiom, prog.derive, 0, limits, &|_, _| {})
        .map_err(|e| format!("derive: {e}"))?;
    let draw = |s: &lsyc::derive::ModString| -> Result<Segs, String> {
        let mut sink = Segments::default();
        lsyc::turtle::interpret_limited(
            &prog,
            s,
            0,
            lsyc::turtle::State::default(),
            limits,
            &mut sink,
        )
        .map_err(|e| format!("draw: {e}"))?;
        Ok(sink.0)
    };
    let level = draw(&at)?;
    let next = lsyc::derive::derive(&prog, at, 1, 0, limits, &|_, _| {})
        .map_err(|e| format!("derive one more: {e}"))?;
    Ok((level, draw(&next)?))
}

/// Segments cut into half steps (`step / 2`: a program may draw a step
/// as two halves, `F -> FF` read at half the step).
fn unit_steps(segments: &[(DVec2, DVec2)], step: f64) -> Segs {
    let mut out = Vec::new();
    for &(a, b) in segments {
        let n = (2.0 * a.distance(b) / step).round().max(1.0) as usize;
        for k in 0..n {
            out.push((
                a.lerp(b, k as f64 / n as f64),
                a.lerp(b, (k + 1) as f64 / n as f64),
            ));
        }
    }
    out
}

/// How two drawings differ as sets of unit steps (counted in half
/// steps): steps of `truth` that `drawn` has not (within `TOLERANCE` steps
/// at both ends), and the other way round.
pub fn compare(truth: &[(DVec2, DVec2)], drawn: &[(DVec2, DVec2)], step: f64) -> (usize, usize) {
    compare_within(truth, drawn, step, TOLERANCE)
}

/// [`compare`] with ends within `tolerance` steps.
pub fn compare_within(
    truth: &[(DVec2, DVec2)],
    drawn: &[(DVec2, DVec2)],
    step: f64,
    tolerance: f64,
) -> (usize, usize) {
    let (a, b) = (unit_steps(truth, step), unit_steps(drawn, step));
    // A wrong grammar can draw far more: no need to count exactly.
    if b.len() > 8 * a.len() + 1000 {
        return (0, b.len());
    }
    let tol = tolerance * step;
    (unmatched(&a, &b, step, tol), unmatched(&b, &a, step, tol))
}

/// Steps of `from` with no step of `to` at both ends.
fn unmatched(from: &[(DVec2, DVec2)], to: &[(DVec2, DVec2)], step: f64, tol: f64) -> usize {
    pairs_within(from, to, step, tol)
        .iter()
        .filter(|p| p.is_none())
        .count()
}

/// The step of `to` at both ends of each step of `from`, if any.
fn pairs(from: &[(DVec2, DVec2)], to: &[(DVec2, DVec2)], step: f64) -> Vec<Option<(DVec2, DVec2)>> {
    pairs_within(from, to, step, TOLERANCE * step)
}

/// [`pairs`] with ends within `tol` (user units).
fn pairs_within(
    from: &[(DVec2, DVec2)],
    to: &[(DVec2, DVec2)],
    step: f64,
    tol: f64,
) -> Vec<Option<(DVec2, DVec2)>> {
    let key = |p: DVec2| ((p.x / step).floor() as i64, (p.y / step).floor() as i64);
    let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in to.iter().enumerate() {
        cells.entry(key((s.0 + s.1) / 2.0)).or_default().push(i);
    }
    let mut out = Vec::with_capacity(from.len());
    for s in from {
        let (x, y) = key((s.0 + s.1) / 2.0);
        let mut hit = None;
        'look: for dx in -1..=1 {
            for dy in -1..=1 {
                for &i in cells.get(&(x + dx, y + dy)).into_iter().flatten() {
                    let t = to[i];
                    if t.0.distance(s.0) <= tol && t.1.distance(s.1) <= tol {
                        hit = Some(t);
                        break 'look;
                    }
                    if t.0.distance(s.1) <= tol && t.1.distance(s.0) <= tol {
                        hit = Some((t.1, t.0));
                        break 'look;
                    }
                }
            }
        }
        out.push(hit);
    }
    out
}

/// The similarity (least squares over the ends of matched steps) that
/// puts `drawn` onto `truth`.
fn fit(truth: &[(DVec2, DVec2)], drawn: &[(DVec2, DVec2)], step: f64) -> impl Fn(DVec2) -> DVec2 {
    let mut points = Vec::new();
    for (s, t) in drawn.iter().zip(pairs(drawn, truth, step)) {
        if let Some(t) = t {
            points.push((s.0, t.0));
            points.push((s.1, t.1));
        }
    }
    let n = points.len().max(1) as f64;
    let (cz, cw) = points
        .iter()
        .fold((DVec2::ZERO, DVec2::ZERO), |(a, b), (z, w)| {
            (a + *z, b + *w)
        });
    let (cz, cw) = (cz / n, cw / n);
    // w − cw = a·(z − cz), a complex: a = Σ w' conj(z') / Σ |z'|².
    let (mut num, mut den) = (DVec2::ZERO, 0.0);
    for (z, w) in &points {
        let (z, w) = (*z - cz, *w - cw);
        num += DVec2::new(w.x * z.x + w.y * z.y, w.y * z.x - w.x * z.y);
        den += z.length_squared();
    }
    let a = if den > 0.0 { num / den } else { DVec2::X };
    move |p: DVec2| {
        let z = p - cz;
        DVec2::new(a.x * z.x - a.y * z.y, a.x * z.y + a.y * z.x) + cw
    }
}

// ------------------------------------------------------------ same grammar

/// What a letter does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    Draw,
    Move,
    Nothing,
}

/// A grammar as compared: δ, axiom, rules (text over letters and
/// `+ - [ ]`), what each letter does, the depth.
#[derive(Clone, Debug)]
pub struct Grammar {
    pub angle: f64,
    pub axiom: String,
    pub rules: Vec<(char, String)>,
    pub kinds: Vec<(char, Kind)>,
    pub depth: u32,
}

impl Grammar {
    pub fn of(p: &Program) -> Grammar {
        let kinds = p
            .letters()
            .into_iter()
            .map(|c| {
                let k = if p.draws.contains(&c) {
                    Kind::Draw
                } else if c == 'f' {
                    Kind::Move
                } else {
                    Kind::Nothing
                };
                (c, k)
            })
            .collect();
        Grammar {
            angle: p.angle,
            axiom: p.axiom.clone(),
            rules: p.rules.clone(),
            kinds,
            depth: p.depth,
        }
    }
}

/// A symbol with turns gathered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tok {
    Letter(char),
    Turn(i64),
    Push,
    Pop,
}

/// `w` as symbols, letters renamed by `rename`, each run of turns one
/// turn (modulo a full turn when 360/δ is whole, half a turn as −).
fn tokens(w: &str, delta: f64, rename: &HashMap<char, char>) -> Vec<Tok> {
    let m = 360.0 / delta;
    let period = ((m - m.round()).abs() < 1e-6).then_some(m.round() as i64);
    let mut out = Vec::new();
    let mut k = 0i64;
    let flush = |k: &mut i64, out: &mut Vec<Tok>| {
        let mut t = *k;
        if let Some(m) = period {
            t = t.rem_euclid(m);
            if 2 * t >= m {
                t -= m;
            }
        }
        if t != 0 {
            out.push(Tok::Turn(t));
        }
        *k = 0;
    };
    for c in w.chars() {
        match c {
            '+' => k += 1,
            '-' => k -= 1,
            _ => {
                flush(&mut k, &mut out);
                out.push(match c {
                    '[' => Tok::Push,
                    ']' => Tok::Pop,
                    c => Tok::Letter(*rename.get(&c).unwrap_or(&c)),
                });
            }
        }
    }
    flush(&mut k, &mut out);
    out
}

/// The axiom without its leading and trailing turns (where the drawing
/// starts heading is the frame's business).
fn axiom(w: &str, delta: f64, rename: &HashMap<char, char>) -> Vec<Tok> {
    let t = tokens(w, delta, rename);
    let first = t.iter().position(|t| !matches!(t, Tok::Turn(_)));
    let last = t.iter().rposition(|t| !matches!(t, Tok::Turn(_)));
    match (first, last) {
        (Some(a), Some(b)) => t[a..=b].to_vec(),
        _ => Vec::new(),
    }
}

/// Whether `b` is `a` up to renaming letters (of the same kind): the same
/// δ, depth, axiom (less turns at its ends) and rules (identity rules
/// left out).
pub fn same_grammar(a: &Grammar, b: &Grammar) -> bool {
    if (a.angle - b.angle).abs() > 1e-2 || a.depth != b.depth {
        return false;
    }
    let rules = |g: &Grammar, rename: &HashMap<char, char>| -> BTreeMap<char, Vec<Tok>> {
        g.rules
            .iter()
            .filter(|(p, w)| w.chars().ne(std::iter::once(*p)))
            .map(|(p, w)| (*rename.get(p).unwrap_or(p), tokens(w, a.angle, rename)))
            .collect()
    };
    let identity = HashMap::new();
    let want_rules = rules(a, &identity);
    let want_axiom = axiom(&a.axiom, a.angle, &identity);
    // Every renaming of b's letters onto a's, kind by kind.
    let letters = |g: &Grammar, k: Kind| -> Vec<char> {
        let mut v: Vec<char> = g
            .kinds
            .iter()
            .filter(|(_, x)| *x == k)
            .map(|(c, _)| *c)
            .collect();
        v.sort_unstable();
        v
    };
    let mut groups = Vec::new();
    for k in [Kind::Draw, Kind::Move, Kind::Nothing] {
        let (la, lb) = (letters(a, k), letters(b, k));
        if la.len() != lb.len() || la.len() > 5 {
            return false;
        }
        groups.push((lb, permutations(&la)));
    }
    let mut choice = vec![0; groups.len()];
    loop {
        let mut rename = HashMap::new();
        for (g, &c) in groups.iter().zip(&choice) {
            for (from, to) in g.0.iter().zip(&g.1[c]) {
                rename.insert(*from, *to);
            }
        }
        if axiom(&b.axiom, a.angle, &rename) == want_axiom && rules(b, &rename) == want_rules {
            return true;
        }
        // The next choice.
        let mut i = 0;
        loop {
            if i == groups.len() {
                return false;
            }
            choice[i] += 1;
            if choice[i] < groups[i].1.len() {
                break;
            }
            choice[i] = 0;
            i += 1;
        }
    }
}

fn permutations(xs: &[char]) -> Vec<Vec<char>> {
    if xs.len() <= 1 {
        return vec![xs.to_vec()];
    }
    let mut out = Vec::new();
    for i in 0..xs.len() {
        let mut rest = xs.to_vec();
        let x = rest.remove(i);
        for mut p in permutations(&rest) {
            p.insert(0, x);
            out.push(p);
        }
    }
    out
}

// ------------------------------------------------------------ the table

/// Counts of one class and variant.
#[derive(Clone, Debug, Default)]
pub struct Cell {
    pub total: usize,
    pub exact: usize,
    pub same: usize,
    pub ms: Vec<f64>,
    /// Failure kind → seeds (and details).
    pub fails: BTreeMap<&'static str, Vec<(u64, String)>>,
}

/// The results of a run.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub cells: BTreeMap<(Class, Variant), Cell>,
    pub rejections: BTreeMap<Class, Rejections>,
    /// Seeds for which no program was generated.
    pub ungenerated: BTreeMap<Class, usize>,
}

impl Table {
    pub fn add(&mut self, case: &Case, variant: Variant, o: &Outcome) {
        let c = self.cells.entry((case.class, variant)).or_default();
        c.total += 1;
        c.exact += usize::from(o.exact);
        c.same += usize::from(o.same);
        c.ms.push(o.ms);
        if let Some(f) = &o.fail {
            c.fails
                .entry(f.kind())
                .or_default()
                .push((case.seed, f.detail()));
        }
    }

    pub fn get(&self, class: Class, variant: Variant) -> Cell {
        self.cells
            .get(&(class, variant))
            .cloned()
            .unwrap_or_default()
    }

    /// The table: class × variant → exact/total (same grammar), then
    /// timings, failure kinds and how programs were sampled.
    pub fn render(&self) -> String {
        let classes: Vec<Class> = Class::ALL
            .into_iter()
            .filter(|c| self.cells.keys().any(|(k, _)| k == c))
            .collect();
        let variants: Vec<Variant> = Variant::ALL
            .into_iter()
            .filter(|v| self.cells.keys().any(|(_, k)| k == v))
            .collect();
        let mut out = String::from("exact/total (same grammar up to renaming)\n");
        out.push_str(&format!("{:<10}", "class"));
        for v in &variants {
            out.push_str(&format!("{:>20}", v.name()));
        }
        out.push('\n');
        for &c in &classes {
            out.push_str(&format!("{:<10}", c.name()));
            for &v in &variants {
                let cell = self.get(c, v);
                out.push_str(&format!(
                    "{:>20}",
                    format!("{}/{} ({})", cell.exact, cell.total, cell.same)
                ));
            }
            out.push('\n');
        }
        out.push_str("\nms per inference: median / max\n");
        for &c in &classes {
            out.push_str(&format!("{:<10}", c.name()));
            for &v in &variants {
                let mut ms = self.get(c, v).ms;
                ms.sort_by(f64::total_cmp);
                let med = ms.get(ms.len() / 2).copied().unwrap_or(0.0);
                let max = ms.last().copied().unwrap_or(0.0);
                out.push_str(&format!("{:>20}", format!("{med:.0} / {max:.0}")));
            }
            out.push('\n');
        }
        let all: f64 = self.cells.values().flat_map(|c| &c.ms).sum();
        out.push_str(&format!("inference: {:.1} s in all\n", all / 1e3));
        out.push_str("\nfailures by kind (first seeds)\n");
        for &c in &classes {
            for &v in &variants {
                for (kind, seeds) in &self.get(c, v).fails {
                    let first: Vec<String> =
                        seeds.iter().take(6).map(|s| s.0.to_string()).collect();
                    out.push_str(&format!(
                        "{:<10} {:<9} {:<11} {:>5}  seeds {}\n",
                        c.name(),
                        v.name(),
                        kind,
                        seeds.len(),
                        first.join(" ")
                    ));
                }
            }
        }
        out.push_str("\nprograms sampled\n");
        for (c, r) in &self.rejections {
            out.push_str(&format!("{:<10} {}", c.name(), r.line()));
            if let Some(n) = self.ungenerated.get(c) {
                out.push_str(&format!("; {n} seeds gave no program"));
            }
            out.push('\n');
        }
        out
    }
}
