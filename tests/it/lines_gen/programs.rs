//! Random D0L programs by class, for testing line-drawing inference on
//! programs nobody tuned it to.
//!
//! Each class draws candidates from its own recipe (below) and keeps the
//! first that passes every filter; the filters leave out programs whose
//! drawing cannot identify them (see `Reject`), and each rejection is
//! counted so that the figures can say how the classes were sampled.

use super::draw;
use super::rng::Rng;
use std::collections::HashSet;

/// δ of the edge-rewriting and node-rewriting classes, degrees.
pub const EDGE_ANGLES: [f64; 8] = [90.0, 60.0, 45.0, 120.0, 72.0, 36.0, 30.0, 22.5];
/// δ of the moves class, degrees: those at which a successor of 3–8
/// steps and moves ends on its own line often enough (at 72°, 36° and
/// 22.5° one in hundreds of thousands does, or none).
pub const MOVES_ANGLES: [f64; 5] = [90.0, 60.0, 45.0, 120.0, 30.0];
/// δ of the bracketed plants, degrees.
pub const PLANT_ANGLES: [f64; 6] = [20.0, 22.5, 25.0, 25.7, 30.0, 45.0];
/// The drawing at the chosen depth has this many unit steps, or more …
pub const MIN_STEPS: u64 = 100;
/// … and no more than this.
pub const MAX_STEPS: u64 = 3000;
/// The string one level further has no more letters than this.
pub const MAX_LETTERS: u64 = 400_000;
/// Candidates drawn before `generate` gives up.
const MAX_TRIES: usize = 100_000;

/// A declared class of programs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// One drawing letter `F`, edge rewriting: `F -> F+F-F-F+F`.
    Edge1,
    /// Two drawing letters F, G (the Sierpiński triangle's `F-G-G`).
    Edge2,
    /// Three drawing letters F, G, H.
    Edge3,
    /// Node rewriting: X (and Y) draw nothing (Hilbert, Peano).
    Node,
    /// Bracketed plants, by edge or node rewriting (a node X that draws
    /// nothing, or an apex G that draws a step at every tip).
    Bracketed,
    /// Edge rewriting with moves `f` (islands and lakes).
    Moves,
}

impl Class {
    pub const ALL: [Class; 6] = [
        Class::Edge1,
        Class::Edge2,
        Class::Edge3,
        Class::Node,
        Class::Bracketed,
        Class::Moves,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Class::Edge1 => "edge-1",
            Class::Edge2 => "edge-2",
            Class::Edge3 => "edge-3",
            Class::Node => "node",
            Class::Bracketed => "bracketed",
            Class::Moves => "moves",
        }
    }

    /// (The bench's `--class`.)
    #[allow(dead_code)]
    pub fn parse(s: &str) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.name() == s)
    }
}

/// A D0L program over `F G H` (drawing letters), `X Y` (drawing nothing),
/// `f` (a move), `+ - [ ]`, with the depth it is drawn at.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// δ, degrees.
    pub angle: f64,
    pub axiom: String,
    /// Successors; a letter without one is left as it is.
    pub rules: Vec<(char, String)>,
    /// The letters that draw a step.
    pub draws: Vec<char>,
    /// The depth drawn (the next level is drawn at `depth + 1`).
    pub depth: u32,
}

impl Program {
    pub fn successor(&self, c: char) -> Option<&str> {
        self.rules
            .iter()
            .find(|(p, _)| *p == c)
            .map(|(_, s)| s.as_str())
    }

    /// Every letter of the program (not `+ - [ ]`), sorted.
    pub fn letters(&self) -> Vec<char> {
        let mut out: Vec<char> = self
            .axiom
            .chars()
            .chain(
                self.rules
                    .iter()
                    .flat_map(|(p, s)| std::iter::once(*p).chain(s.chars())),
            )
            .filter(|c| c.is_ascii_alphabetic())
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The program as `.lsy` text (letters other than `F` draw through
    /// `interpret`).
    pub fn text(&self) -> String {
        let mut out = format!(
            "lsystem Random {{\n    angle {};\n    derive {};\n    axiom {};\n",
            self.angle, self.depth, self.axiom
        );
        for (p, s) in &self.rules {
            out.push_str(&format!("    {p} -> {s};\n"));
        }
        for &d in &self.draws {
            if d != 'F' {
                out.push_str(&format!("    interpret {d} -> F;\n"));
            }
        }
        out.push_str("}\n");
        out
    }

    /// One line: axiom, rules, depth.
    pub fn describe(&self) -> String {
        let mut out = format!("angle {}; axiom {}", self.angle, self.axiom);
        for (p, s) in &self.rules {
            out.push_str(&format!("; {p} -> {s}"));
        }
        if self.draws.iter().any(|&d| d != 'F') {
            let d: String = self.draws.iter().collect();
            out.push_str(&format!("; drawing {d}"));
        }
        out.push_str(&format!("; derive {}", self.depth));
        out
    }
}

/// Why a candidate was left out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Reject {
    /// No rule draws a bend: each rewritten letter's successor, and its
    /// successor's successor, draws all its steps on one line (`F -> FFF`,
    /// `F -> +FF-`, `F -> Ff--f++F` at 90° whose moves come back,
    /// `X -> XX-X` that never draws), so that the drawing is straight runs
    /// turning only where the axiom turns, which `F -> F^k` explains as
    /// well; or the drawing at depth n is one straight line.
    Straight,
    /// (Edge rewriting, every letter rewritten) Another conjugate is the
    /// one inference writes: every successor's leading turn less c·δ and
    /// its trailing turn more c·δ (`F -> ++F--FF` and `F -> F+FF-` at
    /// 120°) draws the same level n from another start heading, and its
    /// next level is this one's turned by c·δ, so level n cannot tell
    /// which is meant. Inference writes the conjugate whose successors
    /// each end straight ahead of where they start (`F -> +F--F+`, Lévy's
    /// C curve, as the Koch construction draws a generator over its
    /// edge) when one exists, at δ or else at δ/2 or δ/3, and the
    /// smallest otherwise.
    Conjugate,
    /// Two letters have the same successor and the same action: one letter
    /// would do, so the program is not the smallest that draws its drawing.
    Twins,
    /// (moves) The successor of F does not end on its own line, a whole
    /// number k ≥ 2 of steps on, heading as it started: `f -> f^k` would
    /// not keep the gaps in scale with the edges.
    OffLine,
    /// No depth n ≥ 2 draws between `MIN_STEPS` and `MAX_STEPS` steps
    /// with no more than `MAX_LETTERS` letters at depth n + 1 (node
    /// letters that multiply without drawing).
    Size,
    /// A letter does not occur at depth n − 1, so its rule is never used
    /// to draw level n.
    Unused,
    /// The drawing at depth n draws some unit segment twice (a drawing
    /// cannot show how often a segment was drawn).
    Overlap,
    /// The same at depth n + 1 (the next level, which inference predicts).
    OverlapNext,
    /// (Edge rewriting) Two letters each rewritten only to the other
    /// (`F -> G+G`, `G -> F-F`), drawn an even number of times from one of
    /// them: one letter's program at half the depth (`F -> F-F+F-F`) draws
    /// the same level n, and inference writes that one (fewer letters).
    /// The same from an axiom of both when two steps rewrite each alike
    /// (`F -> G`, `G -> F--FF`: `F -> F--FF` from `G+G+F`).
    Square,
    /// The drawing grows polynomially with n, not exponentially: no
    /// letter's successor holds two or more letters that derive it again
    /// (`F -> F-` with `G -> F+G++F--F`, `G -> G` with `F -> G++GG--F`).
    /// Such a program draws a hundred steps only at a depth of 20 to 40,
    /// and smaller programs of other depths draw the same level n while
    /// predicting another next level: level n does not say which is meant.
    Slow,
}

impl Reject {
    pub const ALL: [Reject; 10] = [
        Reject::Straight,
        Reject::Conjugate,
        Reject::Twins,
        Reject::OffLine,
        Reject::Size,
        Reject::Unused,
        Reject::Overlap,
        Reject::OverlapNext,
        Reject::Square,
        Reject::Slow,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Reject::Straight => "straight",
            Reject::Conjugate => "conjugate",
            Reject::Twins => "twins",
            Reject::OffLine => "off-line",
            Reject::Size => "size",
            Reject::Unused => "unused",
            Reject::Overlap => "overlap",
            Reject::OverlapNext => "overlap-next",
            Reject::Square => "square",
            Reject::Slow => "slow",
        }
    }
}

/// Candidates drawn and why they were left out.
#[derive(Clone, Debug, Default)]
pub struct Rejections {
    pub kept: usize,
    pub counts: [usize; Reject::ALL.len()],
}

impl Rejections {
    pub fn line(&self) -> String {
        let total = self.kept + self.counts.iter().sum::<usize>();
        let mut out = format!("{} kept of {total} candidates", self.kept);
        for (r, n) in Reject::ALL.iter().zip(self.counts) {
            if n > 0 {
                out.push_str(&format!(", {} {n}", r.name()));
            }
        }
        out
    }
}

/// A random program of `class` that passes every filter; `None` if none
/// did within `MAX_TRIES` candidates. δ (and for plants, edge or node
/// rewriting) is drawn first, uniformly, and kept while candidates are
/// drawn: each δ is as common among the programs as any other, however
/// many of its candidates the filters leave out.
pub fn generate(class: Class, rng: &mut Rng, rejections: &mut Rejections) -> Option<Program> {
    let angles: &[f64] = match class {
        Class::Bracketed => &PLANT_ANGLES,
        Class::Moves => &MOVES_ANGLES,
        _ => &EDGE_ANGLES,
    };
    let delta = rng.pick(angles);
    let edge_plants = rng.chance(0.5);
    // Node plants whose apex draws, half of them.
    let apices = class == Class::Bracketed && !edge_plants && rng.chance(0.5);
    for _ in 0..MAX_TRIES {
        let candidate = match class {
            Class::Edge1 => edge(rng, delta, 1),
            Class::Edge2 => edge(rng, delta, 2),
            Class::Edge3 => edge(rng, delta, 3),
            Class::Node => node(rng, delta),
            Class::Bracketed if edge_plants => edge_plant(rng, delta),
            Class::Bracketed if apices => apex_plant(rng, delta),
            Class::Bracketed => node_plant(rng, delta),
            Class::Moves => moves(rng, delta),
        };
        match candidate.and_then(|p| filter(p, rng)) {
            Ok(p) => {
                rejections.kept += 1;
                return Some(p);
            }
            Err(r) => rejections.counts[r as usize] += 1,
        }
    }
    None
}

// ------------------------------------------------------------ recipes

fn turn(k: i32) -> String {
    let c = if k > 0 { "+" } else { "-" };
    c.repeat(k.unsigned_abs() as usize)
}

/// A turn of 1..=max δ, either way.
fn nonzero(rng: &mut Rng, max: i32) -> i32 {
    let k = rng.range(1, max);
    if rng.chance(0.5) { k } else { -k }
}

/// `parts` with a random turn of −2..2 δ between each two, and sometimes
/// a leading and a trailing turn.
fn word(rng: &mut Rng, parts: &[String]) -> String {
    let mut out = String::new();
    if rng.chance(0.25) {
        out.push_str(&turn(nonzero(rng, 2)));
    }
    for (i, p) in parts.iter().enumerate() {
        if i > 0 {
            out.push_str(&turn(rng.range(-2, 2)));
        }
        out.push_str(p);
    }
    if rng.chance(0.25) {
        out.push_str(&turn(nonzero(rng, 2)));
    }
    out
}

/// A closed polygon of k edges turning by t·δ at each corner, k·t·δ =
/// 360 (k ≥ 3, t ≤ 4), its edges drawn by `edge`; one edge when no such
/// polygon exists.
fn polygon(rng: &mut Rng, delta: f64, edge: &mut dyn FnMut(&mut Rng) -> String) -> String {
    let options: Vec<(i32, usize)> = (1..=4)
        .filter_map(|t| {
            let k = 360.0 / (f64::from(t) * delta);
            (k >= 3.0 && (k - k.round()).abs() < 1e-9).then_some((t, k.round() as usize))
        })
        .collect();
    if options.is_empty() {
        return edge(rng);
    }
    let (t, k) = rng.pick(&options);
    let t = if rng.chance(0.5) { t } else { -t };
    let edges: Vec<String> = (0..k).map(|_| edge(rng)).collect();
    edges.join(&turn(t))
}

fn one(c: char) -> String {
    c.to_string()
}

/// edge-1, edge-2, edge-3: `letters` drawing letters (F, G, H).
fn edge(rng: &mut Rng, delta: f64, letters: usize) -> Result<Program, Reject> {
    let alphabet = &['F', 'G', 'H'][..letters];
    let mut rules = Vec::new();
    if letters == 1 {
        // 2–7 F's.
        let parts = vec![one('F'); rng.range(2, 7) as usize];
        rules.push(('F', word(rng, &parts)));
    } else {
        for &l in alphabet {
            let parts: Vec<String> = (0..rng.range(1, 6))
                .map(|_| one(rng.pick(alphabet)))
                .collect();
            rules.push((l, word(rng, &parts)));
        }
    }
    let axiom = if rng.chance(0.5) {
        one(rng.pick(alphabet))
    } else {
        polygon(rng, delta, &mut |r| one(r.pick(alphabet)))
    };
    Ok(Program {
        angle: delta,
        axiom,
        rules,
        draws: alphabet.to_vec(),
        depth: 0,
    })
}

/// node: X (and sometimes Y) rewritten over F, X, Y; `F -> F` or `F -> FF`.
fn node(rng: &mut Rng, delta: f64) -> Result<Program, Reject> {
    let with_y = rng.chance(0.5);
    let alphabet: &[char] = if with_y {
        &['F', 'X', 'Y']
    } else {
        &['F', 'X']
    };
    let mut rules = Vec::new();
    for l in ['X', 'Y'].into_iter().take(if with_y { 2 } else { 1 }) {
        let parts: Vec<String> = (0..rng.range(3, 9))
            .map(|_| one(rng.pick(alphabet)))
            .collect();
        rules.push((l, word(rng, &parts)));
    }
    if rng.chance(0.5) {
        rules.push(('F', "FF".to_string()));
    }
    let nodes = &alphabet[1..];
    let axiom = if rng.chance(0.6) {
        one('X')
    } else {
        polygon(rng, delta, &mut |r| format!("{}F", r.pick(nodes)))
    };
    Ok(Program {
        angle: delta,
        axiom,
        rules,
        draws: vec!['F'],
        depth: 0,
    })
}

/// bracketed, edge rewriting: a trunk of F's with 1–3 branches of 1–3
/// steps (`F -> F[+F]F[-F]F`, `F -> FF-[-F+F+F]+[+F-F-F]`).
fn edge_plant(rng: &mut Rng, delta: f64) -> Result<Program, Reject> {
    let mut w = "F".repeat(rng.range(1, 2) as usize);
    let branches = rng.range(1, 3);
    for b in 0..branches {
        if rng.chance(0.3) {
            w.push_str(&turn(nonzero(rng, 1)));
        }
        w.push('[');
        w.push_str(&turn(nonzero(rng, 2)));
        for s in 0..rng.range(1, 3) {
            if s > 0 {
                w.push_str(&turn(rng.range(-1, 1)));
            }
            w.push('F');
        }
        w.push(']');
        if b + 1 < branches || rng.chance(0.6) {
            w.push_str(&"F".repeat(rng.range(1, 2) as usize));
        }
    }
    Ok(Program {
        angle: delta,
        axiom: one('F'),
        rules: vec![('F', w)],
        draws: vec!['F'],
        depth: 0,
    })
}

/// A node plant's successor up to its last apex: 1–2 F's, then 1–3
/// branches `[±turns F? apex]` each followed by 0–2 F's.
fn trunk_with_branches(rng: &mut Rng, apex: char) -> String {
    let mut w = "F".repeat(rng.range(1, 2) as usize);
    for _ in 0..rng.range(1, 3) {
        w.push('[');
        w.push_str(&turn(nonzero(rng, 2)));
        w.push_str(&"F".repeat(rng.range(0, 1) as usize));
        w.push(apex);
        w.push(']');
        w.push_str(&"F".repeat(rng.range(0, 2) as usize));
    }
    w
}

/// bracketed, node rewriting with an apex that draws: every G ends its
/// branch (`G -> F[+G]-G`, `F -> FF`: the binary tree;
/// `G -> F[-FG]F[+G]+G`).
fn apex_plant(rng: &mut Rng, delta: f64) -> Result<Program, Reject> {
    let mut w = trunk_with_branches(rng, 'G');
    w.push_str(&turn(rng.range(-2, 2)));
    w.push('G');
    let mut rules = vec![('G', w)];
    if rng.chance(0.7) {
        rules.push(('F', "FF".to_string()));
    }
    Ok(Program {
        angle: delta,
        axiom: one('G'),
        rules,
        draws: vec!['F', 'G'],
        depth: 0,
    })
}

/// bracketed, node rewriting: `X -> F[+X]F[-X]+X`, `F -> FF`-like.
fn node_plant(rng: &mut Rng, delta: f64) -> Result<Program, Reject> {
    let mut w = trunk_with_branches(rng, 'X');
    if rng.chance(0.6) {
        w.push_str(&turn(rng.range(-2, 2)));
        w.push('X');
    }
    let mut rules = vec![('X', w)];
    if rng.chance(0.7) {
        rules.push(('F', "FF".to_string()));
    }
    Ok(Program {
        angle: delta,
        axiom: one('X'),
        rules,
        draws: vec!['F'],
        depth: 0,
    })
}

/// moves: `F -> ` 3–8 steps and moves (at least two F, one f) ending on
/// its own line k steps on, `f -> f^k`.
fn moves(rng: &mut Rng, delta: f64) -> Result<Program, Reject> {
    let n = rng.range(3, 8) as usize;
    let mut parts: Vec<String> = (0..n)
        .map(|_| one(if rng.chance(0.3) { 'f' } else { 'F' }))
        .collect();
    // At least one move and two steps.
    let i = rng.below(n);
    parts[i] = one('f');
    while parts.iter().filter(|p| *p == "F").count() < 2 {
        let j = rng.below(n);
        if j != i {
            parts[j] = one('F');
        }
    }
    let w = word(rng, &parts);
    let k = draw::span(&w, delta).ok_or(Reject::OffLine)?;
    if k < 2 {
        return Err(Reject::OffLine);
    }
    let axiom = if rng.chance(0.5) {
        one('F')
    } else {
        polygon(rng, delta, &mut |_| one('F'))
    };
    Ok(Program {
        angle: delta,
        axiom,
        rules: vec![('F', w), ('f', "f".repeat(k))],
        draws: vec!['F'],
        depth: 0,
    })
}

// ------------------------------------------------------------ filters

/// Whether some rule draws a bend: the successor of one of the rewritten
/// letters, or its successor, drawn from that letter alone, does not draw
/// all its steps on one line.
fn bends(p: &Program) -> bool {
    p.rules.iter().any(|(l, _)| {
        let q = Program {
            axiom: l.to_string(),
            ..p.clone()
        };
        (1..=2).any(|k| !straight(&draw::draw(&q, &draw::derive(&q, k))))
    })
}

/// The filters, and the depth: `p` as drawn, or why it is left out.
fn filter(mut p: Program, rng: &mut Rng) -> Result<Program, Reject> {
    if !bends(&p) {
        return Err(Reject::Straight);
    }
    if conjugate(&p) {
        return Err(Reject::Conjugate);
    }
    for (i, (a, wa)) in p.rules.iter().enumerate() {
        for (b, wb) in &p.rules[i + 1..] {
            if wa == wb && p.draws.contains(a) == p.draws.contains(b) {
                return Err(Reject::Twins);
            }
        }
    }
    // Letter counts by depth, without deriving.
    let letters = p.letters();
    let index = |c: char| letters.iter().position(|&l| l == c);
    let count = |w: &str| {
        let mut v = vec![0u64; letters.len()];
        for c in w.chars() {
            if let Some(i) = index(c) {
                v[i] += 1;
            }
        }
        v
    };
    let rows: Vec<Vec<u64>> = letters
        .iter()
        .map(|&l| count(p.successor(l).unwrap_or(&l.to_string())))
        .collect();
    if !exponential(&p, &letters, &rows) {
        return Err(Reject::Slow);
    }
    let drawn = |v: &[u64]| -> u64 {
        letters
            .iter()
            .zip(v)
            .filter(|(l, _)| p.draws.contains(l))
            .map(|(_, n)| *n)
            .sum()
    };
    let total = |v: &[u64]| v.iter().fold(0u64, |a, &b| a.saturating_add(b));
    let mut levels = vec![count(&p.axiom)];
    while levels.len() <= 41 {
        let last = levels.last().unwrap();
        if drawn(last) > MAX_STEPS || total(last) > MAX_LETTERS {
            break;
        }
        let mut next = vec![0u64; letters.len()];
        for (i, &m) in last.iter().enumerate() {
            for (j, &r) in rows[i].iter().enumerate() {
                next[j] = next[j].saturating_add(m.saturating_mul(r));
            }
        }
        levels.push(next);
    }
    // Depths n with the right number of steps and a string one level
    // further no longer than `MAX_LETTERS` letters.
    let depths: Vec<u32> = (2..levels.len().saturating_sub(1))
        .filter(|&d| {
            (MIN_STEPS..=MAX_STEPS).contains(&drawn(&levels[d]))
                && total(&levels[d + 1]) <= MAX_LETTERS
        })
        .map(|d| d as u32)
        .collect();
    if depths.is_empty() {
        return Err(Reject::Size);
    }
    p.depth = rng.pick(&depths);
    if levels[p.depth as usize - 1].contains(&0) {
        return Err(Reject::Unused);
    }
    if p.depth.is_multiple_of(2) && square(&p) {
        return Err(Reject::Square);
    }
    for (depth, why) in [
        (p.depth, Reject::Overlap),
        (p.depth + 1, Reject::OverlapNext),
    ] {
        let d = draw::draw(&p, &draw::derive(&p, depth));
        if depth == p.depth && straight(&d) {
            return Err(Reject::Straight);
        }
        let mut seen = HashSet::with_capacity(d.steps.len());
        for &(a, b) in &d.steps {
            if !seen.insert(draw::unit_key(a, b)) {
                return Err(why);
            }
        }
    }
    Ok(p)
}

/// Whether the drawing grows exponentially with the depth (see
/// `Reject::Slow`): some letter that draws, or derives a letter that
/// draws, has a successor holding two or more letters of its own strongly
/// connected component (letters that derive it and that it derives). A
/// nonnegative integer matrix that cannot be split has spectral radius 1
/// exactly when every row sums to 1; otherwise more than 1.
fn exponential(p: &Program, letters: &[char], rows: &[Vec<u64>]) -> bool {
    let n = letters.len();
    // reach[i][j]: letter j occurs in some derivation from letter i.
    let mut reach: Vec<Vec<bool>> = rows
        .iter()
        .map(|r| r.iter().map(|&c| c > 0).collect())
        .collect();
    for k in 0..n {
        for i in 0..n {
            for j in 0..n {
                if reach[i][k] && reach[k][j] {
                    reach[i][j] = true;
                }
            }
        }
    }
    let draws = |i: usize| p.draws.contains(&letters[i]);
    (0..n).any(|i| {
        let own: u64 = (0..n)
            .filter(|&j| reach[i][j] && reach[j][i])
            .map(|j| rows[i][j])
            .sum();
        own >= 2 && (draws(i) || (0..n).any(|j| reach[i][j] && draws(j)))
    })
}

/// Whether `p` has two drawing letters, each rewritten only to the other,
/// and an axiom of one of them (see `Reject::Square`).
fn square(p: &Program) -> bool {
    let letters = |w: &str| -> Vec<char> { w.chars().filter(|c| c.is_alphabetic()).collect() };
    let [(a, wa), (b, wb)] = p.rules.as_slice() else {
        return false;
    };
    let drawn = p.draws.contains(a) && p.draws.contains(b);
    let crossed = letters(wa).iter().all(|c| c == b) && letters(wb).iter().all(|c| c == a);
    let axiom = letters(&p.axiom);
    let one = axiom.iter().all(|c| c == a) || axiom.iter().all(|c| c == b);
    // Two steps of each, every letter written X: the same word makes the
    // squared program one letter's, whatever the axiom.
    let twice = |w: &str, other: &str| -> String {
        w.chars()
            .flat_map(|c| {
                if c.is_alphabetic() {
                    other.chars().collect::<Vec<_>>()
                } else {
                    vec![c]
                }
            })
            .map(|c| if c.is_alphabetic() { 'X' } else { c })
            .collect()
    };
    let twins = twice(wa, wb) == twice(wb, wa);
    drawn && crossed && (one || twins)
}

/// Whether every step of `d` is on one line.
fn straight(d: &draw::Drawing) -> bool {
    let Some(&(a, b)) = d.steps.first() else {
        return true;
    };
    let dir = b - a;
    d.steps
        .iter()
        .all(|&(p, q)| dir.perp_dot(q - p).abs() < 1e-6 && dir.perp_dot(p - a).abs() < 1e-6)
}

/// Turns of δ as a net turn.
fn net(turns: &str) -> i64 {
    turns.chars().map(|c| if c == '+' { 1 } else { -1 }).sum()
}

/// Whether inference writes another conjugate of `p` (see
/// `Reject::Conjugate`): the one whose successors end straight ahead, or
/// else one no larger than `p`. Only for edge rewriting, where every
/// letter is a drawing letter or a move (node letters sit between
/// unrewritten steps, whose turns a conjugate would change).
fn conjugate(p: &Program) -> bool {
    let letters = p.letters();
    if letters.iter().any(|c| !p.draws.contains(c) && *c != 'f') {
        return false;
    }
    let m = 360.0 / p.angle;
    let period = ((m - m.round()).abs() < 1e-9).then_some(m.round() as i64);
    // A letter left as it is would need a rule to turn.
    let rewritten = letters.iter().all(|&c| p.successor(c).is_some());
    if let Some(c) = straight_ahead(p, period).filter(|_| rewritten) {
        return c != 0;
    }
    // Ends straight ahead only at δ/2 or δ/3: inference writes that one.
    for k in [2, 3] {
        let finer = Program {
            angle: p.angle / k as f64,
            axiom: finer_turns(&p.axiom, k),
            rules: p
                .rules
                .iter()
                .map(|(c, w)| (*c, finer_turns(w, k)))
                .collect(),
            ..p.clone()
        };
        if rewritten && straight_ahead(&finer, period.map(|m| m * k)).is_some() {
            return true;
        }
    }
    // A turn's size in symbols (modulo a full turn; half a turn either way).
    let size = |k: i64| match period {
        Some(m) => {
            let t = k.rem_euclid(m);
            t.min(m - t)
        }
        None => k.abs(),
    };
    let ends: Vec<(i64, i64)> = letters
        .iter()
        .map(|&l| {
            let w = p.successor(l).unwrap_or("");
            let lead = w.len() - w.trim_start_matches(['+', '-']).len();
            let trail = w.len() - w.trim_end_matches(['+', '-']).len();
            (net(&w[..lead]), net(&w[w.len() - trail..]))
        })
        .collect();
    let cost = |c: i64| -> i64 { ends.iter().map(|&(a, b)| size(a - c) + size(b + c)).sum() };
    let others: Vec<i64> = match period {
        Some(m) => (1..m).collect(),
        None => (-4..=4).filter(|&c| c != 0).collect(),
    };
    others.into_iter().any(|c| cost(c) <= cost(0))
}

/// The c (turns of δ, modulo the period, or in −4..=4 without one) for
/// which every successor of `p` that ends away from its start ends
/// straight ahead once turned by −c·δ; `None` when no c does (or no
/// successor ends away from its start).
fn straight_ahead(p: &Program, period: Option<i64>) -> Option<i64> {
    let chords: Vec<glam::DVec2> = p
        .rules
        .iter()
        .map(|(_, w)| draw::chord(w, p.angle))
        .filter(|v| v.length() > 1e-6)
        .collect();
    if chords.is_empty() {
        return None;
    }
    let cs: Vec<i64> = match period {
        Some(m) => (0..m).collect(),
        None => (-4..=4).collect(),
    };
    cs.into_iter().find(|&c| {
        let a = (p.angle * c as f64).to_radians();
        let ahead = glam::DVec2::new(-a.sin(), a.cos());
        chords
            .iter()
            .all(|v| v.perp_dot(ahead).abs() < 1e-6 * v.length() && v.dot(ahead) > 0.0)
    })
}

/// `w` with every turn written `k` times.
fn finer_turns(w: &str, k: i64) -> String {
    w.chars()
        .flat_map(|c| {
            let n = if c == '+' || c == '-' { k as usize } else { 1 };
            std::iter::repeat_n(c, n)
        })
        .collect()
}
