//! Candidate grammars: bracketed D0L systems over a few letters, derived
//! lazily and drawn by a small turtle straight into the `turtle::Builder`,
//! so that a candidate is compared with the drawing step by step and given
//! up at the first step that differs.
//!
//! Owns: `Grammar` (letters, rules, axiom, depth), its size (rule symbols),
//! and `matches`. Must not search: `search` proposes, this module checks.

use super::turtle::{Angles, Builder, Tree};
use glam::DVec2;
use std::ops::ControlFlow;

/// A symbol of an axiom or a successor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    /// Letter `k` of the grammar.
    Letter(u8),
    Plus,
    Minus,
    Push,
    Pop,
}

/// What a letter does when the turtle meets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Action {
    Draw,
    Move,
    /// Nothing (a node letter such as `X`).
    Nothing,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Letter {
    pub name: char,
    pub action: Action,
    /// The successor; `None` for the identity.
    pub rule: Option<Vec<Sym>>,
}

/// A D0L system and the depth that draws the drawing.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Grammar {
    pub letters: Vec<Letter>,
    pub axiom: Vec<Sym>,
    pub depth: u32,
}

impl Grammar {
    /// Symbols in all successors.
    pub fn rule_size(&self) -> usize {
        self.letters
            .iter()
            .filter_map(|l| l.rule.as_ref())
            .map(Vec::len)
            .sum()
    }

    /// Whether the axiom or a successor opens a branch.
    pub fn pushes(&self) -> bool {
        self.axiom
            .iter()
            .chain(
                self.letters
                    .iter()
                    .filter_map(|l| l.rule.as_ref())
                    .flatten(),
            )
            .any(|s| *s == Sym::Push)
    }

    /// Whether a letter moves without drawing.
    pub fn moves(&self) -> bool {
        self.letters.iter().any(|l| l.action == Action::Move)
    }

    /// The order in which candidates are preferred: fewest symbols in the
    /// rules and the axiom together (a small rule with a long axiom explains
    /// little), then fewest rule symbols, then fewest rules, then the text.
    pub fn cost(&self) -> (usize, usize, usize, String) {
        let rules = self.letters.iter().filter(|l| l.rule.is_some()).count();
        (
            self.rule_size() + self.axiom.len(),
            self.rule_size(),
            rules,
            self.describe(),
        )
    }

    /// The symbols as text: `F-F-F-F; F -> FF-F`.
    pub fn text(&self, s: &[Sym]) -> String {
        s.iter()
            .map(|s| match *s {
                Sym::Letter(k) => self.letters.get(k as usize).map_or('?', |l| l.name),
                Sym::Plus => '+',
                Sym::Minus => '-',
                Sym::Push => '[',
                Sym::Pop => ']',
            })
            .collect()
    }

    /// One line: axiom, rules, depth.
    pub fn describe(&self) -> String {
        let mut out = format!("axiom {}", self.text(&self.axiom));
        for l in &self.letters {
            if let Some(r) = &l.rule {
                out.push_str(&format!("; {} -> {}", l.name, self.text(r)));
            }
        }
        out.push_str(&format!("; derive {}", self.depth));
        out
    }
}

/// Turns of δ as symbols: `+` left, `-` right; half a turn is written `--`.
pub fn turn_syms(k: i32, angles: &Angles) -> Vec<Sym> {
    let k = angles.norm(k);
    let k = match angles.period {
        Some(m) if m % 2 == 0 && k == m / 2 => -k,
        _ => k,
    };
    let sym = if k > 0 { Sym::Plus } else { Sym::Minus };
    vec![sym; k.unsigned_abs() as usize]
}

/// Unit vectors of headings `k` (turns of δ from +y).
struct Directions {
    delta: f64,
    period: Option<i32>,
    table: Vec<DVec2>,
}

impl Directions {
    fn new(angles: &Angles) -> Directions {
        let table = match angles.period {
            Some(m) if m > 0 => (0..m).map(|k| unit(angles.delta, k)).collect(),
            _ => Vec::new(),
        };
        Directions {
            delta: angles.delta,
            period: angles.period,
            table,
        }
    }

    fn get(&self, k: i32) -> DVec2 {
        match self.period {
            Some(m) if m > 0 => self.table[k.rem_euclid(m) as usize],
            _ => unit(self.delta, k),
        }
    }
}

fn unit(delta: f64, k: i32) -> DVec2 {
    let a = (90.0 + delta * f64::from(k)).to_radians();
    DVec2::new(a.cos(), a.sin())
}

/// How a candidate compared with the drawing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Every step matches.
    Same,
    /// It differs at step `at` (or draws more or fewer steps).
    Differs { at: usize },
    /// It derives more symbols than its budget before drawing the drawing.
    TooLong,
}

/// Derives `g` and draws it, step by step, against `tree`; `work` is the
/// most symbols it may read. The first drawn step of the candidate starts
/// where the drawing's does, so both are compared from their first step.
pub fn matches(
    g: &Grammar,
    tree: &Tree,
    angles: &Angles,
    work: u64,
    deadline: Option<std::time::Instant>,
) -> Outcome {
    let dirs = Directions::new(angles);
    let mut b = Builder::new();
    // A gap read as the drawing's are, with δ known.
    b.lattice = Some((angles.delta.to_radians(), angles.tolerance.to_radians()));
    let mut frames: Vec<(&[Sym], usize, u32)> = vec![(&g.axiom[..], 0, g.depth)];
    let mut heading = 0i32;
    let mut pos = DVec2::ZERO;
    let mut saved: Vec<(i32, DVec2)> = Vec::new();
    let mut read = 0u64;
    let mut checked = 0usize;
    let total = tree.nodes.len();
    while let Some(top) = frames.last_mut() {
        let (syms, i, depth) = (top.0, top.1, top.2);
        if i >= syms.len() {
            frames.pop();
            continue;
        }
        top.1 += 1;
        read += 1;
        if read > work {
            return Outcome::TooLong;
        }
        if read.is_multiple_of(4096) && deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            return Outcome::TooLong;
        }
        match syms[i] {
            Sym::Plus => heading += 1,
            Sym::Minus => heading -= 1,
            Sym::Push => saved.push((heading, pos)),
            Sym::Pop => {
                if let Some((h, p)) = saved.pop() {
                    heading = h;
                    pos = p;
                }
            }
            Sym::Letter(k) => {
                let Some(letter) = g.letters.get(k as usize) else {
                    return Outcome::Differs { at: checked };
                };
                if depth > 0
                    && let Some(rule) = &letter.rule
                {
                    frames.push((&rule[..], 0, depth - 1));
                    continue;
                }
                match letter.action {
                    Action::Nothing => {}
                    Action::Move => pos += dirs.get(heading),
                    Action::Draw => {
                        let next = pos + dirs.get(heading);
                        if b.push(pos, next).is_err() {
                            return Outcome::Differs { at: checked };
                        }
                        pos = next;
                        while checked < b.raw.len() {
                            if checked >= total {
                                return Outcome::Differs { at: checked };
                            }
                            let Ok(n) = b.node(checked, angles) else {
                                return Outcome::Differs { at: checked };
                            };
                            let want = tree.nodes[checked];
                            if n.parent != want.parent
                                || n.kind != want.kind
                                || (checked > 0 && n.turn != want.turn)
                                || !same_jump(&b, tree, checked as u32)
                            {
                                return Outcome::Differs { at: checked };
                            }
                            checked += 1;
                        }
                    }
                }
            }
        }
    }
    if checked == total && b.raw.len() == total {
        Outcome::Same
    } else {
        Outcome::Differs { at: checked }
    }
}

/// Whether node `i` jumps as far in both (or in neither).
fn same_jump(b: &Builder, tree: &Tree, i: u32) -> bool {
    let angle = b.raw[i as usize].angle;
    match (b.landing(i, angle), tree.jumps.get(&i)) {
        (None, None) => true,
        (Some(x), Some(y)) => x.distance(*y) <= super::turtle::TOUCH,
        _ => false,
    }
}

/// The first drawn step of `g`: where it starts (in steps, from the turtle's
/// start) and its heading (in δ from +y).
pub fn first_step(g: &Grammar, angles: &Angles, work: u64) -> Option<(DVec2, i32)> {
    let mut first = None;
    each_step(g, angles, work, |pos, heading| {
        first = Some((pos, heading));
        ControlFlow::Break(())
    })?;
    first
}

/// Derives `g` and walks it as its turtle does, from the origin heading +y,
/// handing each drawn step's start and heading (in δ from +y) to `step`
/// until it says to stop; `None` past `work` symbols read, or at a letter
/// or a `]` the grammar does not have.
pub fn each_step(
    g: &Grammar,
    angles: &Angles,
    work: u64,
    mut step: impl FnMut(DVec2, i32) -> ControlFlow<()>,
) -> Option<()> {
    let dirs = Directions::new(angles);
    let mut frames: Vec<(&[Sym], usize, u32)> = vec![(&g.axiom[..], 0, g.depth)];
    let mut heading = 0i32;
    let mut pos = DVec2::ZERO;
    let mut saved: Vec<(i32, DVec2)> = Vec::new();
    let mut read = 0u64;
    while let Some(top) = frames.last_mut() {
        let (syms, i, depth) = (top.0, top.1, top.2);
        if i >= syms.len() {
            frames.pop();
            continue;
        }
        top.1 += 1;
        read += 1;
        if read > work {
            return None;
        }
        match syms[i] {
            Sym::Plus => heading += 1,
            Sym::Minus => heading -= 1,
            Sym::Push => saved.push((heading, pos)),
            Sym::Pop => (heading, pos) = saved.pop()?,
            Sym::Letter(k) => {
                let letter = g.letters.get(k as usize)?;
                if depth > 0
                    && let Some(rule) = &letter.rule
                {
                    frames.push((&rule[..], 0, depth - 1));
                    continue;
                }
                match letter.action {
                    Action::Nothing => {}
                    Action::Move => pos += dirs.get(heading),
                    Action::Draw => {
                        if step(pos, heading).is_break() {
                            return Some(());
                        }
                        pos += dirs.get(heading);
                    }
                }
            }
        }
    }
    Some(())
}

/// Where `w` ends, drawn from the origin heading +y, with steps of 1 for
/// letters that draw or move (branches come back where they started).
fn chord(g: &Grammar, w: &[Sym], dirs: &Directions) -> DVec2 {
    let (mut pos, mut heading) = (DVec2::ZERO, 0i32);
    let mut saved = Vec::new();
    for &s in w {
        match s {
            Sym::Plus => heading += 1,
            Sym::Minus => heading -= 1,
            Sym::Push => saved.push((pos, heading)),
            Sym::Pop => (pos, heading) = saved.pop().unwrap_or((pos, heading)),
            Sym::Letter(k) => {
                if g.letters
                    .get(k as usize)
                    .is_some_and(|l| l.action != Action::Nothing)
                {
                    pos += dirs.get(heading);
                }
            }
        }
    }
    pos
}

/// The turns `c` for which every successor that ends away from its start
/// ends `c` turns of δ to its left: modulo the period, or within a few
/// turns without one.
fn straight_ahead(g: &Grammar, angles: &Angles) -> Option<i32> {
    let dirs = Directions::new(angles);
    let chords: Vec<DVec2> = g
        .letters
        .iter()
        .filter_map(|l| l.rule.as_ref())
        .map(|w| chord(g, w, &dirs))
        .filter(|v| v.length() > 1e-6)
        .collect();
    if chords.is_empty() {
        return None;
    }
    let cs: Vec<i32> = match angles.period {
        Some(m) if m > 0 => (0..m).collect(),
        _ => (-4..=4).collect(),
    };
    cs.into_iter().find(|&c| {
        let ahead = dirs.get(c);
        chords
            .iter()
            .all(|v| v.perp_dot(ahead).abs() < 1e-6 * v.length() && v.dot(ahead) > 0.0)
    })
}

/// The conjugate a person writes of an edge-rewriting grammar (every
/// letter draws or moves and is rewritten), and its angles: every
/// successor's leading turns less c·δ and its trailing turns more c·δ draw
/// the same level n from a start turned by n·c·δ, so level n cannot tell
/// them apart. The one whose successors each end straight ahead of where
/// they start (as the Koch construction draws a generator over the edge it
/// replaces) is written when there is one, at δ or, when only a finer
/// angle has one, at δ/2 or δ/3: Lévy's C curve `F -> +F--F+` at 45° draws
/// every step at a multiple of 90° from its start, where the smallest
/// grammar is `F -> F-F+`. `g` as it is otherwise (the search's smallest).
/// The axiom is the same word: only the heading it starts at changes, which
/// the frame puts right.
pub fn aligned(g: &Grammar, angles: &Angles) -> (Grammar, Angles) {
    let edges = g
        .letters
        .iter()
        .all(|l| l.action != Action::Nothing && l.rule.is_some());
    if !edges {
        return (g.clone(), *angles);
    }
    for k in 1..=3 {
        let finer = Angles::new(
            angles.delta / f64::from(k),
            angles.period.map(|m| m * k),
            angles.tolerance / f64::from(k),
        );
        let gk = finer_turns(g, k as usize);
        match straight_ahead(&gk, &finer) {
            Some(0) => return (g.clone(), *angles),
            Some(c) => {
                if let Some(out) = conjugate(&gk, c, &finer) {
                    return (out, finer);
                }
            }
            None => {}
        }
    }
    (g.clone(), *angles)
}

/// `g` with every turn written as `k` turns (of δ/k).
fn finer_turns(g: &Grammar, k: usize) -> Grammar {
    let finer = |w: &[Sym]| -> Vec<Sym> {
        w.iter()
            .flat_map(|&s| match s {
                Sym::Plus | Sym::Minus => vec![s; k],
                _ => vec![s],
            })
            .collect()
    };
    let mut out = g.clone();
    out.axiom = finer(&g.axiom);
    for l in &mut out.letters {
        l.rule = l.rule.as_deref().map(finer);
    }
    out
}

/// `g` with every successor's leading turns less `c` and its trailing
/// turns more `c`; `None` when a successor is only turns.
fn conjugate(g: &Grammar, c: i32, angles: &Angles) -> Option<Grammar> {
    let is_turn = |s: &Sym| matches!(s, Sym::Plus | Sym::Minus);
    let net = |t: &[Sym]| {
        t.iter()
            .map(|s| if *s == Sym::Plus { 1 } else { -1 })
            .sum::<i32>()
    };
    let mut out = g.clone();
    for l in &mut out.letters {
        let Some(w) = &l.rule else { continue };
        let lead = w.iter().take_while(|s| is_turn(s)).count();
        if lead == w.len() {
            return None;
        }
        let trail = w.iter().rev().take_while(|s| is_turn(s)).count();
        let mut v = turn_syms(net(&w[..lead]) - c, angles);
        v.extend_from_slice(&w[lead..w.len() - trail]);
        v.extend(turn_syms(net(&w[w.len() - trail..]) + c, angles));
        l.rule = Some(v);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::turtle::ROOT;

    fn koch() -> Grammar {
        use Sym::*;
        let f = Letter(0);
        Grammar {
            letters: vec![super::Letter {
                name: 'F',
                action: Action::Draw,
                rule: Some(vec![
                    f, Minus, f, Plus, f, Plus, f, f, Minus, f, Minus, f, Plus, f,
                ]),
            }],
            axiom: vec![f, Minus, f, Minus, f, Minus, f],
            depth: 1,
        }
    }

    #[test]
    fn a_grammar_matches_its_own_drawing_only() {
        let g = koch();
        let angles = Angles::new(90.0, Some(4), 1.0);
        // Draw it by hand: the generator four times, turning right between.
        let generator = [0, -1, 1, 1, 0, -1, -1, 1];
        let mut nodes = Vec::new();
        for side in 0..4 {
            for (k, &t) in generator.iter().enumerate() {
                let turn = if k == 0 {
                    if side == 0 { 0 } else { -1 }
                } else {
                    t
                };
                let parent = if nodes.is_empty() {
                    ROOT
                } else {
                    nodes.len() as u32 - 1
                };
                nodes.push(crate::infer::lines::turtle::Node {
                    parent,
                    turn,
                    kind: crate::infer::lines::turtle::Kind::Draw,
                });
            }
        }
        let tree = Tree::of(nodes);
        assert_eq!(matches(&g, &tree, &angles, 1000, None), Outcome::Same);
        let mut other = g.clone();
        other.depth = 2;
        assert!(matches!(
            matches(&other, &tree, &angles, 10_000, None),
            Outcome::Differs { .. }
        ));
        assert_eq!(matches(&other, &tree, &angles, 10, None), Outcome::TooLong);
        assert_eq!(g.rule_size(), 14);
        assert_eq!(g.describe(), "axiom F-F-F-F; F -> F-F+F+FF-F-F+F; derive 1");
        assert_eq!(first_step(&g, &angles, 100), Some((DVec2::ZERO, 0)));
    }

    #[test]
    fn the_conjugate_written_ends_straight_ahead() {
        use Sym::*;
        let f = Letter(0);
        // Lévy's C curve as the search's smallest finds it, F -> F--F++ at
        // 45°, is written F -> +F--F+.
        let mut g = Grammar {
            letters: vec![super::Letter {
                name: 'F',
                action: Action::Draw,
                rule: Some(vec![f, Minus, Minus, f, Plus, Plus]),
            }],
            axiom: vec![f],
            depth: 10,
        };
        let a = Angles::new(45.0, Some(8), 1.0);
        let (c, at) = aligned(&g, &a);
        assert_eq!(c.describe(), "axiom F; F -> +F--F+; derive 10");
        assert_eq!(at, a);
        // Drawn from a start turned by 45° per level, its steps all turn by
        // multiples of 90°, where the smallest grammar is F -> F-F+.
        g.letters[0].rule = Some(vec![f, Minus, f, Plus]);
        let (c, at) = aligned(&g, &Angles::new(90.0, Some(4), 1.0));
        assert_eq!(c.describe(), "axiom F; F -> +F--F+; derive 10");
        assert_eq!((at.delta, at.period), (45.0, Some(8)));
        // Already straight ahead: as it is.
        let koch = koch();
        let a = Angles::new(90.0, Some(4), 1.0);
        assert_eq!(aligned(&koch, &a), (koch, a));
    }

    #[test]
    fn half_turns_are_written_right() {
        let a = Angles::new(90.0, Some(4), 1.0);
        assert_eq!(turn_syms(2, &a), vec![Sym::Minus, Sym::Minus]);
        assert_eq!(turn_syms(3, &a), vec![Sym::Minus]);
        let b = Angles::new(25.7, None, 1.0);
        assert_eq!(turn_syms(2, &b), vec![Sym::Plus, Sym::Plus]);
    }
}
