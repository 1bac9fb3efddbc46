//! Grammar synthesis against the stroke graph: a D0L system is guessed one
//! symbol at a time while it is derived and drawn, and every drawn step must
//! be an unused edge of the drawing.
//!
//! The drawing is a set of unit edges (`graph`), so the order, direction and
//! splitting of its paths do not matter. A search starts at a vertex, along
//! one of its edges, for a depth n. The axiom and the successors start empty
//! and open; the derivation runs depth first, as a turtle draws, and where it
//! needs a symbol that is not known yet it chooses one (close the successor,
//! a drawing letter, a turn, a bracket) and goes on. A drawing letter is
//! first written unnamed: at the last derivation step every drawing letter
//! draws the same step, so its name is chosen only when it must be rewritten
//! (an existing letter or a new one). Every choice is checked by the steps it
//! draws, so a wrong one fails within a few steps and the search backs up to
//! the latest choice with alternatives left. A search ends when every edge
//! is drawn exactly once: the grammar draws the drawing, whatever order its
//! paths came in.
//!
//! Owns: the search and its work limits. Must not read SVG or write
//! programs; the found grammar goes through the same checks as every other
//! candidate (`grammar::matches`, the library's redraw).

use super::graph::Graph;
use super::levels::Drawing as _;
use super::{blocks, euler, levels, turtle};
use glam::DVec2;
use std::ops::RangeInclusive;
use std::time::Instant;

/// A symbol of a successor being guessed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sym {
    /// Drawing letter `k`.
    Letter(u8),
    /// A drawing letter not named yet.
    Unnamed,
    /// A turn of `t` times δ₀ (left when positive).
    Turn(i32),
    Push,
    Pop,
}

/// A successor (or the axiom) and whether it is complete.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rule {
    pub syms: Vec<Sym>,
    pub closed: bool,
}

/// A grammar found: the axiom, each drawing letter's successor, the depth,
/// δ₀ (degrees) the turns count, and the start.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    pub axiom: Vec<Sym>,
    pub rules: Vec<Vec<Sym>>,
    pub depth: u32,
    pub delta: f64,
    /// The drawing's polylines in the order the grammar draws them.
    pub walk: Vec<Vec<DVec2>>,
}

impl Found {
    /// Symbols in the axiom and all successors.
    pub fn size(&self) -> usize {
        self.axiom.len() + self.rules.iter().map(Vec::len).sum::<usize>()
    }

    /// Two letters that are each rewritten only to the other (`F -> G--G`,
    /// `G -> F+F`), derived an even number of times from an axiom of one of
    /// them, are one letter's grammar twice over: written as that
    /// (`F -> F+F--F+F`) at half the depth, which draws the same and has
    /// one letter, as a person writes it.
    pub fn squared(self) -> Found {
        if self.rules.len() != 2 || !self.depth.is_multiple_of(2) {
            return self;
        }
        let only = |r: &[Sym], k: u8| {
            r.iter()
                .all(|s| !matches!(s, Sym::Unnamed) && !matches!(s, Sym::Letter(j) if *j != k))
        };
        let Some(k) = (0..2u8).find(|&k| only(&self.axiom, k)) else {
            return self;
        };
        if !(only(&self.rules[0], 1) && only(&self.rules[1], 0)) {
            return self;
        }
        let other = &self.rules[1 - k as usize];
        let mut rule: Vec<Sym> = Vec::new();
        for s in &self.rules[k as usize] {
            let part: &[Sym] = if matches!(s, Sym::Letter(_)) {
                other
            } else {
                std::slice::from_ref(s)
            };
            for &t in part {
                let t = if matches!(t, Sym::Letter(_)) {
                    Sym::Letter(0)
                } else {
                    t
                };
                match (rule.last_mut(), t) {
                    (Some(Sym::Turn(a)), Sym::Turn(b)) => {
                        *a += b;
                        if *a == 0 {
                            rule.pop();
                        }
                    }
                    _ => rule.push(t),
                }
            }
        }
        let axiom = self
            .axiom
            .iter()
            .map(|s| {
                if matches!(s, Sym::Letter(_)) {
                    Sym::Letter(0)
                } else {
                    *s
                }
            })
            .collect();
        Found {
            axiom,
            rules: vec![rule],
            depth: self.depth / 2,
            ..self
        }
    }
}

impl Found {
    /// A letter that only the axiom names (`F -> G+` with axiom `FFFF`)
    /// is rewritten there once: the axiom becomes its first derivation
    /// (`G+G+G+G+`) at one step less, which draws the same with one letter
    /// less, as a person writes it.
    pub fn unfolded(mut self) -> Found {
        let named_in_rules =
            |rules: &[Vec<Sym>], k: u8| rules.iter().flatten().any(|s| *s == Sym::Letter(k));
        while self.depth > 1 && self.rules.len() > 1 {
            let axiom_only = (0..self.rules.len() as u8)
                .find(|&k| self.axiom.contains(&Sym::Letter(k)) && !named_in_rules(&self.rules, k));
            let Some(k) = axiom_only else {
                break;
            };
            if self.axiom.contains(&Sym::Unnamed)
                || self.rules.iter().flatten().any(|s| *s == Sym::Unnamed)
            {
                break;
            }
            let mut axiom = Vec::new();
            for s in &self.axiom {
                match s {
                    Sym::Letter(j) => axiom.extend_from_slice(&self.rules[*j as usize]),
                    other => axiom.push(*other),
                }
            }
            if axiom.contains(&Sym::Letter(k)) {
                break;
            }
            // Letter k is gone: the letters after it move down one.
            let down = |s: &Sym| match *s {
                Sym::Letter(j) if j > k => Sym::Letter(j - 1),
                other => other,
            };
            // Turns after the axiom's last letter draw nothing.
            while matches!(axiom.last(), Some(Sym::Turn(_))) {
                axiom.pop();
            }
            self.axiom = axiom.iter().map(down).collect();
            self.rules.remove(k as usize);
            self.rules = self
                .rules
                .iter()
                .map(|r| r.iter().map(down).collect())
                .collect();
            self.depth -= 1;
        }
        self
    }
}

/// How far a search goes.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Drawing letters at most.
    pub letters: usize,
    /// Symbols in a successor at most.
    pub rule: usize,
    /// Symbols in the axiom at most.
    pub axiom: usize,
    /// Derivation symbols read and choices made per start and depth.
    pub work: u64,
    /// Derivation symbols read and choices made over all searches: the
    /// search ends there (a count, so the same drawing always gets the same
    /// answer).
    pub total: u64,
    /// Whether successors may branch (`[`, `]`).
    pub brackets: bool,
    pub deadline: Option<Instant>,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            letters: 3,
            rule: 24,
            axiom: 12,
            work: 200_000,
            total: 8_000_000,
            brackets: false,
            deadline: None,
        }
    }
}

const AXIOM: u8 = u8::MAX;

#[derive(Clone, Copy, Debug)]
struct Frame {
    rule: u8,
    at: u16,
    depth: u8,
}

#[derive(Clone, Debug)]
struct Turtle {
    at: u32,
    heading: i32,
    saved: Vec<(u32, i32)>,
}

/// What a choice may be.
#[derive(Clone, Copy, Debug)]
enum Choice {
    /// The successor `rule` (or the axiom) is read to its end: close it or
    /// add a symbol.
    End { rule: u8 },
    /// The unnamed letter at `rule[at]` must be rewritten: name it.
    Name { rule: u8, at: u16 },
}

/// An edit to the grammar, undone when the search backs up.
#[derive(Clone, Copy, Debug)]
enum Edit {
    Added(u8),
    Closed(u8),
    Named(u8, u16),
    NewLetter,
}

struct Point {
    choice: Choice,
    next: usize,
    frames: Vec<Frame>,
    turtle: Turtle,
    h0: Option<f64>,
    used: usize,
    edits: usize,
}

enum Step {
    Need(Choice),
    Fail,
    Done,
}

struct Search<'a> {
    g: &'a Graph,
    limits: Limits,
    delta: f64,
    turns: Vec<i32>,
    axiom: Rule,
    rules: Vec<Rule>,
    frames: Vec<Frame>,
    turtle: Turtle,
    /// Radians of heading 0, fixed by the first drawn step.
    h0: Option<f64>,
    start: (u32, u32),
    used: &'a mut [bool],
    /// Drawn edges and the vertex each was drawn from, in order.
    trail: Vec<(u32, u32)>,
    edits: Vec<Edit>,
    cos_tol: f64,
    /// The drawing's orientation (radians) when δ₀ divides the turn: every
    /// step's direction is the phase plus a multiple of δ₀, so the first
    /// step's heading is snapped to it rather than taken as drawn.
    phase: Option<f64>,
    work: u64,
    /// Symbols in the axiom and all successors at most.
    bound: usize,
    /// The depth n.
    depth: u8,
    /// The steps in the order the drawing's paths draw them, when the
    /// search must follow it.
    order: Option<&'a [(u32, u32)]>,
}

impl<'a> Search<'a> {
    fn rule(&self, r: u8) -> &Rule {
        if r == AXIOM {
            &self.axiom
        } else {
            &self.rules[r as usize]
        }
    }

    fn rule_mut(&mut self, r: u8) -> &mut Rule {
        if r == AXIOM {
            &mut self.axiom
        } else {
            &mut self.rules[r as usize]
        }
    }

    /// Whether the axiom could still draw no more steps than the drawing
    /// has: a lower bound of what it draws, from what is known of the
    /// successors (an unnamed letter or an open successor draws at least
    /// what its known part does, and at least one step).
    fn feasible(&self) -> bool {
        let n = self.depth;
        let mut memo = [[None::<u64>; 16]; 4];
        let mut total = 0u64;
        for s in &self.axiom.syms {
            total = total.saturating_add(self.least(*s, n, &mut memo));
        }
        total <= self.all() as u64 && self.most() >= self.all() as u64
    }

    /// The most steps the axiom could draw at depth n: every symbol the
    /// bound leaves (in any open successor, or the axiom) a letter, every
    /// unnamed letter the one that draws most.
    fn most(&self) -> u64 {
        let size = self.axiom.syms.len() + self.rules.iter().map(|r| r.syms.len()).sum::<usize>();
        let spare = self.bound.saturating_sub(size) as u64;
        let new_letters = self.rules.len() < self.limits.letters;
        // most[k] and any (the most of any letter) at the depth below.
        let mut below = [1u64; 4];
        let mut any_below = 1u64;
        for _ in 1..=self.depth {
            let mut here = [0u64; 4];
            let mut any = if new_letters {
                spare.saturating_mul(any_below).max(1)
            } else {
                0
            };
            for (k, r) in self.rules.iter().enumerate().take(4) {
                let mut t = 0u64;
                for s in &r.syms {
                    let c = match *s {
                        Sym::Letter(j) => below.get(j as usize).copied().unwrap_or(any_below),
                        Sym::Unnamed => any_below,
                        _ => 0,
                    };
                    t = t.saturating_add(c);
                }
                if !r.closed {
                    t = t.saturating_add(spare.saturating_mul(any_below));
                }
                here[k] = t.max(1);
                any = any.max(here[k]);
            }
            below = here;
            any_below = any;
        }
        let mut total = 0u64;
        for s in &self.axiom.syms {
            let c = match *s {
                Sym::Letter(j) => below.get(j as usize).copied().unwrap_or(any_below),
                Sym::Unnamed => any_below,
                _ => 0,
            };
            total = total.saturating_add(c);
        }
        if !self.axiom.closed {
            total = total.saturating_add(spare.saturating_mul(any_below));
        }
        total
    }

    /// The fewest steps symbol `s` at depth `d` draws.
    fn least(&self, s: Sym, d: u8, memo: &mut [[Option<u64>; 16]; 4]) -> u64 {
        match s {
            Sym::Turn(_) | Sym::Push | Sym::Pop => 0,
            _ if d == 0 => 1,
            Sym::Letter(k) => self.least_letter(k, d, memo),
            Sym::Unnamed => {
                let mut m = if self.rules.len() < self.limits.letters {
                    1
                } else {
                    u64::MAX
                };
                for j in 0..self.rules.len() as u8 {
                    m = m.min(self.least_letter(j, d, memo));
                }
                m
            }
        }
    }

    fn least_letter(&self, k: u8, d: u8, memo: &mut [[Option<u64>; 16]; 4]) -> u64 {
        if let Some(v) = memo
            .get(k as usize)
            .and_then(|r| r.get(d as usize))
            .copied()
            .flatten()
        {
            return v;
        }
        let Some(r) = self.rules.get(k as usize) else {
            return 1;
        };
        let mut t = 0u64;
        for s in &r.syms {
            t = t.saturating_add(self.least(*s, d - 1, memo));
        }
        let t = t.max(1);
        if let Some(cell) = memo.get_mut(k as usize).and_then(|r| r.get_mut(d as usize)) {
            *cell = Some(t);
        }
        t
    }

    /// Whether more axiom letters could draw the steps left: once every
    /// successor is known, the letters needed are at least the steps left
    /// over the most one letter draws.
    fn axiom_can_grow(&self, letters: usize) -> bool {
        let depth = self.frames.first().map_or(0, |f| f.depth);
        let mut most = 0u64;
        for k in 0..self.rules.len() as u8 {
            match self.count(k, depth) {
                Some(c) => most = most.max(c),
                None => return true,
            }
        }
        let left = self.left();
        let need = left.div_ceil(most.max(1)) as usize;
        letters + need <= self.limits.axiom
    }

    /// How many steps letter `k` draws at depth `d`, when every successor
    /// it reaches is complete and named.
    fn count(&self, k: u8, d: u8) -> Option<u64> {
        let mut memo = [[None::<Option<u64>>; 16]; 4];
        self.count_in(k, d, &mut memo)
    }

    fn count_in(&self, k: u8, d: u8, memo: &mut [[Option<Option<u64>>; 16]; 4]) -> Option<u64> {
        if d == 0 {
            return Some(1);
        }
        if let Some(m) = memo
            .get(k as usize)
            .and_then(|row| row.get(d as usize))
            .copied()
            .flatten()
        {
            return m;
        }
        let r = self.rules.get(k as usize)?;
        let mut total: Option<u64> = if r.closed { Some(0) } else { None };
        for s in &r.syms {
            let c = match *s {
                Sym::Letter(j) => self.count_in(j, d - 1, memo),
                Sym::Unnamed if d == 1 => Some(1),
                Sym::Unnamed => None,
                _ => Some(0),
            };
            total = match (total, c) {
                (Some(t), Some(c)) => Some(t.saturating_add(c)),
                _ => None,
            };
            if total.is_none() {
                break;
            }
        }
        if let Some(cell) = memo
            .get_mut(k as usize)
            .and_then(|row| row.get_mut(d as usize))
        {
            *cell = Some(total);
        }
        total
    }

    /// The letters some successor or the axiom names, as bits.
    fn named(&self) -> u32 {
        let mut bits = 0u32;
        for r in std::iter::once(&self.axiom).chain(&self.rules) {
            for s in &r.syms {
                if let Sym::Letter(k) = s {
                    bits |= 1 << k;
                }
            }
        }
        bits
    }

    /// Steps the grammar must draw.
    fn all(&self) -> usize {
        self.order.map_or(self.g.edges.len(), <[_]>::len)
    }

    /// Steps the drawing has that are not drawn yet.
    fn left(&self) -> u64 {
        self.all().saturating_sub(self.trail.len()) as u64
    }

    /// Draws the drawing's next step, which must leave the turtle's vertex
    /// along its heading (the search follows the paths' order).
    fn draw_next(&mut self, order: &[(u32, u32)]) -> bool {
        let Some(&(from, to)) = order.get(self.trail.len()) else {
            return false;
        };
        let Some(e) = self.g.edge(from, to) else {
            return false;
        };
        if from != self.turtle.at {
            return false;
        }
        let dir = self.g.direction(e, from);
        let turned = f64::from(self.turtle.heading) * self.delta.to_radians();
        match self.h0 {
            None => self.h0 = Some(self.snapped(dir) - turned),
            Some(h0) => {
                if (dir - h0 - turned).cos() < self.cos_tol {
                    return false;
                }
            }
        }
        self.take(e, from)
    }

    /// A direction (radians) moved to the nearest the drawing's phase
    /// allows.
    fn snapped(&self, dir: f64) -> f64 {
        let Some(phase) = self.phase else {
            return dir;
        };
        let d = self.delta.to_radians();
        phase + ((dir - phase) / d).round() * d
    }

    /// Draws one step from the turtle's vertex along its heading.
    fn draw(&mut self) -> bool {
        if let Some(order) = self.order {
            return self.draw_next(order);
        }
        let at = self.turtle.at;
        let h0 = match self.h0 {
            Some(h) => h,
            None => {
                // The first step: along the start edge.
                let (v, e) = self.start;
                if at != v || self.used[e as usize] {
                    return false;
                }
                let dir = self.g.direction(e, v);
                let turned = f64::from(self.turtle.heading) * self.delta.to_radians();
                self.h0 = Some(self.snapped(dir) - turned);
                return self.take(e, v);
            }
        };
        let a = h0 + f64::from(self.turtle.heading) * self.delta.to_radians();
        let u = DVec2::new(a.cos(), a.sin());
        let p = self.g.points[at as usize];
        let mut best: Option<(f64, u32)> = None;
        for &(nb, e) in &self.g.adj[at as usize] {
            if self.used[e as usize] {
                continue;
            }
            let d = self.g.points[nb as usize] - p;
            let c = d.dot(u) / d.length();
            if c >= self.cos_tol && best.is_none_or(|(bc, _)| c > bc) {
                best = Some((c, e));
            }
        }
        match best {
            Some((_, e)) => self.take(e, at),
            None => false,
        }
    }

    fn take(&mut self, e: u32, from: u32) -> bool {
        let [a, b] = self.g.edges[e as usize];
        self.used[e as usize] = true;
        self.trail.push((e, from));

        self.turtle.at = if a == from { b } else { a };
        true
    }

    /// Reads the derivation on to the next choice, failure or end.
    fn advance(&mut self) -> Step {
        loop {
            self.work += 1;
            if self.work > self.limits.work {
                return Step::Fail;
            }
            let Some(top) = self.frames.last().copied() else {
                return Step::Done;
            };
            let rule = self.rule(top.rule);
            if top.at as usize >= rule.syms.len() {
                if !rule.closed {
                    return Step::Need(Choice::End { rule: top.rule });
                }
                self.frames.pop();
                continue;
            }
            let sym = rule.syms[top.at as usize];
            match sym {
                Sym::Turn(t) => self.turtle.heading += t,
                Sym::Push => {
                    let s = (self.turtle.at, self.turtle.heading);
                    self.turtle.saved.push(s);
                }
                Sym::Pop => match self.turtle.saved.pop() {
                    Some((at, h)) => {
                        self.turtle.at = at;
                        self.turtle.heading = h;
                    }
                    None => return Step::Fail,
                },
                Sym::Unnamed if top.depth > 0 => {
                    return Step::Need(Choice::Name {
                        rule: top.rule,
                        at: top.at,
                    });
                }
                Sym::Unnamed | Sym::Letter(_) if top.depth == 0 => {
                    if !self.draw() {
                        return Step::Fail;
                    }
                }
                Sym::Letter(k) => {
                    // A letter that would draw more steps than are left.
                    if let Some(c) = self.count(k, top.depth)
                        && c > self.left()
                    {
                        return Step::Fail;
                    }
                    if let Some(f) = self.frames.last_mut() {
                        f.at += 1;
                    }
                    self.frames.push(Frame {
                        rule: k,
                        at: 0,
                        depth: top.depth - 1,
                    });
                    continue;
                }
                Sym::Unnamed => return Step::Fail,
            }
            if let Some(f) = self.frames.last_mut() {
                f.at += 1;
            }
        }
    }

    /// The alternatives of a choice, in the order they are tried.
    fn alternatives(&self, c: Choice) -> Vec<Alt> {
        match c {
            Choice::Name { rule, .. } => {
                // A successor of one letter names another letter (a letter
                // that only becomes itself, turned, explains nothing).
                let single = rule != AXIOM
                    && self
                        .rule(rule)
                        .syms
                        .iter()
                        .filter(|s| matches!(s, Sym::Letter(_) | Sym::Unnamed))
                        .count()
                        == 1
                    && self.rule(rule).closed;
                // Letters are interchangeable: a letter nothing names yet is
                // any new letter, so only the first such is offered (and a
                // new one when every letter is named somewhere).
                let named = self.named();
                let fresh = (0..self.rules.len() as u8).find(|&k| named & (1 << k) == 0);
                let mut v: Vec<Alt> = (0..self.rules.len() as u8)
                    .filter(|&k| !(single && k == rule))
                    .filter(|&k| named & (1 << k) != 0 || Some(k) == fresh)
                    .map(Alt::Name)
                    .collect();
                if fresh.is_none() && self.rules.len() < self.limits.letters {
                    v.push(Alt::NewLetter);
                }
                v
            }
            Choice::End { rule } => {
                let r = self.rule(rule);
                let letters = r
                    .syms
                    .iter()
                    .filter(|s| matches!(s, Sym::Letter(_) | Sym::Unnamed))
                    .count();
                let open = r.syms.iter().fold(0i32, |d, s| match s {
                    Sym::Push => d + 1,
                    Sym::Pop => d - 1,
                    _ => d,
                });
                let last = r.syms.last().copied();
                let limit = if rule == AXIOM {
                    self.limits.axiom
                } else {
                    self.limits.rule
                };
                let mut v = Vec::new();
                // A successor that only copies its letter explains nothing
                // (one unnamed letter closed alone is named another letter:
                // `F -> G` delays F a step).
                let identity = rule != AXIOM && letters == 1 && r.syms.contains(&Sym::Letter(rule));
                if letters > 0 && open == 0 && !identity {
                    v.push(Alt::Close);
                }
                let size =
                    self.axiom.syms.len() + self.rules.iter().map(|r| r.syms.len()).sum::<usize>();
                if r.syms.len() >= limit || size >= self.bound {
                    return v;
                }
                if rule == AXIOM && !self.axiom_can_grow(letters) {
                    return v;
                }
                v.push(Alt::Add(Sym::Unnamed));
                let turn_ok =
                    !(matches!(last, Some(Sym::Turn(_))) || rule == AXIOM && r.syms.is_empty());
                if turn_ok {
                    for &t in &self.turns {
                        v.push(Alt::Add(Sym::Turn(t)));
                    }
                }
                if self.limits.brackets && rule != AXIOM {
                    if open < 2 {
                        v.push(Alt::Add(Sym::Push));
                    }
                    if open > 0 && !matches!(last, Some(Sym::Push) | Some(Sym::Turn(_))) {
                        v.push(Alt::Add(Sym::Pop));
                    }
                }
                v
            }
        }
    }

    fn apply(&mut self, c: Choice, alt: Alt) {
        match (c, alt) {
            (Choice::Name { rule, at }, Alt::Name(k)) => {
                self.rule_mut(rule).syms[at as usize] = Sym::Letter(k);
                self.edits.push(Edit::Named(rule, at));
            }
            (Choice::Name { rule, at }, Alt::NewLetter) => {
                self.rules.push(Rule::default());
                self.edits.push(Edit::NewLetter);
                let k = self.rules.len() as u8 - 1;
                self.rule_mut(rule).syms[at as usize] = Sym::Letter(k);
                self.edits.push(Edit::Named(rule, at));
            }
            (Choice::End { rule }, Alt::Close) => {
                self.rule_mut(rule).closed = true;
                self.edits.push(Edit::Closed(rule));
            }
            (Choice::End { rule }, Alt::Add(s)) => {
                self.rule_mut(rule).syms.push(s);
                self.edits.push(Edit::Added(rule));
            }
            _ => {}
        }
    }

    fn undo_to(&mut self, p: &Point) {
        while self.trail.len() > p.used {
            if let Some((e, _)) = self.trail.pop() {
                self.used[e as usize] = false;
            }
        }
        while self.edits.len() > p.edits {
            match self.edits.pop() {
                Some(Edit::Added(r)) => {
                    self.rule_mut(r).syms.pop();
                }
                Some(Edit::Closed(r)) => self.rule_mut(r).closed = false,
                Some(Edit::Named(r, at)) => self.rule_mut(r).syms[at as usize] = Sym::Unnamed,
                Some(Edit::NewLetter) => {
                    self.rules.pop();
                }
                None => break,
            }
        }
        self.frames.clone_from(&p.frames);
        self.turtle.clone_from(&p.turtle);
        self.h0 = p.h0;
    }

    /// Searches from the start; `true` when the grammar draws every edge.
    fn run(&mut self) -> bool {
        let mut points: Vec<Point> = Vec::new();
        loop {
            match self.advance() {
                Step::Done if self.left() == 0 => return true,
                Step::Need(c) => {
                    let p = Point {
                        choice: c,
                        next: 0,
                        frames: self.frames.clone(),
                        turtle: self.turtle.clone(),
                        h0: self.h0,
                        used: self.trail.len(),
                        edits: self.edits.len(),
                    };
                    points.push(p);
                    if !self.next(&mut points) {
                        return false;
                    }
                }
                Step::Done | Step::Fail => {
                    if !self.next(&mut points) {
                        return false;
                    }
                }
            }
            if self.work > self.limits.work {
                return false;
            }
        }
    }

    /// Takes the next alternative of the latest choice that has one.
    fn next(&mut self, points: &mut Vec<Point>) -> bool {
        while let Some(mut p) = points.pop() {
            self.undo_to(&p);
            let alts = self.alternatives(p.choice);
            if p.next < alts.len() {
                let alt = alts[p.next];
                p.next += 1;
                let c = p.choice;
                points.push(p);
                self.apply(c, alt);
                if !self.feasible() {
                    self.work += 1;
                    continue;
                }
                return true;
            }
            self.work += 1;
            if self.work > self.limits.work {
                return false;
            }
        }
        false
    }
}

#[derive(Clone, Copy, Debug)]
enum Alt {
    Close,
    Add(Sym),
    Name(u8),
    NewLetter,
}

/// Where searches start: vertices with one edge first (a curve's ends, a
/// plant's root), far from the drawing's centre first, then the others.
fn starts(g: &Graph) -> Vec<(u32, u32)> {
    let n = g.points.len().max(1) as f64;
    let centre = g.points.iter().fold(DVec2::ZERO, |s, p| s + *p) / n;
    let mut vs: Vec<u32> = (0..g.points.len() as u32)
        .filter(|&v| !g.adj[v as usize].is_empty())
        .collect();
    vs.sort_by(|&a, &b| {
        let (da, db) = (g.adj[a as usize].len(), g.adj[b as usize].len());
        (da != 1).cmp(&(db != 1)).then(
            g.points[b as usize]
                .distance_squared(centre)
                .total_cmp(&g.points[a as usize].distance_squared(centre)),
        )
    });
    vs.iter()
        .flat_map(|&v| g.adj[v as usize].iter().map(move |&(_, e)| (v, e)))
        .collect()
}

/// The turns tried, in δ₀: small ones first.
fn turn_range(delta: f64) -> Vec<i32> {
    let m = (360.0 / delta).round();
    let span = if (360.0 / delta - m).abs() < 1e-6 && m <= 16.0 {
        (m as i32) / 2
    } else {
        4
    };
    let mut v = Vec::new();
    for k in 1..=span {
        v.push(k);
        if !(2 * k == m as i32 && (360.0 / delta - m).abs() < 1e-6) {
            v.push(-k);
        }
    }
    v
}

/// The drawing's orientation when δ₀ is 360/m: the mean of its unit edges'
/// directions, each taken m times round (so every multiple of δ₀ counts
/// alike), radians.
pub(super) fn phase(g: &Graph, delta: f64) -> Option<f64> {
    let m = 360.0 / delta;
    if (m - m.round()).abs() > 1e-9 || m < 2.0 {
        return None;
    }
    let mut z = DVec2::ZERO;
    for (e, [a, _]) in g.edges.iter().enumerate() {
        let t = g.direction(e as u32, *a) * m.round();
        z += DVec2::new(t.cos(), t.sin());
    }
    (z.length() > 1e-9 * g.edges.len() as f64).then(|| z.y.atan2(z.x) / m.round())
}

/// δ₀ as the search uses it: 360/m when that is within a percent.
pub(super) fn working_delta(delta: f64) -> f64 {
    let m = (360.0 / delta).round();
    if m >= 2.0 && (360.0 / m - delta).abs() <= 0.01 * delta {
        360.0 / m
    } else {
        delta
    }
}

/// One search: from a start edge, for a bound on the grammar's size and a
/// depth n, following the paths' order or not.
struct Attempt<'a> {
    start: (u32, u32),
    bound: usize,
    depth: u32,
    order: Option<&'a [(u32, u32)]>,
}

/// What the searches share: the graph, δ₀ and its turns, the tolerance of
/// directions, the work spent and the drawn-edges buffer.
struct Shared<'a> {
    g: &'a Graph,
    limits: Limits,
    delta: f64,
    turns: Vec<i32>,
    cos_tol: f64,
    phase: Option<f64>,
    spent: u64,
    /// Which edges are drawn: one buffer for every attempt, cleared by the
    /// attempt's own trail (an attempt costs its work, not the drawing's
    /// size).
    used: Vec<bool>,
}

impl Shared<'_> {
    fn exhausted(&self) -> bool {
        self.spent >= self.limits.total || self.limits.deadline.is_some_and(|d| Instant::now() >= d)
    }

    fn attempt(&mut self, a: &Attempt) -> Option<Found> {
        let (v, e) = a.start;
        let mut s = Search {
            g: self.g,
            limits: self.limits,
            delta: self.delta,
            turns: self.turns.clone(),
            axiom: Rule::default(),
            rules: vec![Rule::default()],
            frames: vec![Frame {
                rule: AXIOM,
                at: 0,
                depth: a.depth as u8,
            }],
            turtle: Turtle {
                at: v,
                heading: 0,
                saved: Vec::new(),
            },
            h0: None,
            start: (v, e),
            used: &mut self.used,
            trail: Vec::new(),
            edits: Vec::new(),
            cos_tol: if a.order.is_some() && self.phase.is_some() {
                // Following the paths' order, a step only has to say which
                // multiple of δ₀ it turns (a noisy drawing's steps stray).
                (0.45 * self.delta).to_radians().cos()
            } else {
                self.cos_tol
            },
            phase: self.phase,
            work: 0,
            bound: a.bound,
            depth: a.depth as u8,
            order: a.order,
        };
        s.limits.work = self.limits.work.min(self.limits.total - self.spent);
        let ok = s.run();
        self.spent += s.work.max(1);
        let found = ok.then(|| Found {
            axiom: s.axiom.syms.clone(),
            rules: s.rules.iter().map(|r| r.syms.clone()).collect(),
            depth: a.depth,
            delta: self.delta,
            walk: walk(self.g, &s.trail),
        });
        for &(e, _) in &s.trail {
            s.used[e as usize] = false;
        }
        found
    }

    /// The smallest grammar, with the fewest letters, that a start and a
    /// bound give at any of the depths, the deepest first.
    fn best_of(
        &mut self,
        start: (u32, u32),
        bound: usize,
        depths: RangeInclusive<u32>,
        order: Option<&[(u32, u32)]>,
    ) -> Option<Found> {
        let mut found: Vec<Found> = Vec::new();
        for depth in depths.rev() {
            if self.exhausted() {
                break;
            }
            let a = Attempt {
                start,
                bound,
                depth,
                order,
            };
            found.extend(self.attempt(&a));
        }
        found
            .into_iter()
            .min_by_key(|f| (f.size(), f.rules.len(), std::cmp::Reverse(f.depth)))
    }
}

/// Searches for a grammar that draws every edge of `g` exactly once: first
/// following the paths' order (forwards, then backwards), which a drawing
/// saved in the order a turtle drew it allows, then over the graph alone.
pub fn search(g: &Graph, limits: &Limits) -> Option<Found> {
    search_counted(g, limits, &mut 0)
}

/// `search`, adding the work it spent to `spent` (each of its two stages
/// may spend up to `limits.total`).
pub fn search_counted(g: &Graph, limits: &Limits, spent: &mut u64) -> Option<Found> {
    if g.edges.is_empty() || g.edges.len() > MAX_EDGES || g.order.len() > MAX_EDGES {
        return None;
    }
    let delta = working_delta(g.delta);
    // Directions within a third of δ₀ (tighter when the drawing is clean).
    let tol = (delta / 3.0).min(10.0 + (2.0 * g.noise).atan().to_degrees() * 2.0);
    let mut shared = Shared {
        g,
        limits: *limits,
        delta,
        turns: turn_range(delta),
        cos_tol: tol.to_radians().cos(),
        phase: phase(g, delta),
        spent: 0,
        used: vec![false; g.edges.len()],
    };
    let n_of = |steps: usize| ((steps as f64).log2().ceil() as u32 + 1).clamp(2, 14);
    let found = in_order(&mut shared, n_of(g.order.len()));
    *spent += shared.spent;
    if found.is_some() {
        return found;
    }
    // The search over the graph alone has a total of its own: a drawing
    // whose paths come in another order fails the first quickly, and one
    // that came in order but is not explained should not take the second's.
    shared.spent = 0;
    let found = over_all(&mut shared, n_of);
    *spent += shared.spent;
    found
}

/// The search over the graph alone: along a curve, or out from where its
/// paths touch, then from every start.
fn over_all(shared: &mut Shared, n_of: impl Fn(usize) -> u32) -> Option<Found> {
    let g = shared.g;
    let n_max = n_of(g.edges.len());
    if let Some((chain, closed)) = g.chain() {
        // One curve: its steps in order, from where its turns' blocks say
        // it starts.
        // An open curve drawn in one stroke was followed as drawn already.
        let followed = g.order.len() == chain.len() && g.order.windows(2).all(|w| w[0].1 == w[1].0);
        if let Some(found) = along_chain(shared, &chain, closed, n_max, followed) {
            return Some(found);
        }
        if shared.exhausted() {
            return None;
        }
    } else if let Some(found) = touching(shared) {
        return Some(found);
    }
    let starts = starts(g);
    // A curve's ends (a plant's root among its tips) are where a drawing
    // most likely starts: every bound is tried from each of them before
    // the other vertices, which are tried bound by bound.
    let ends = starts
        .iter()
        .take_while(|(v, _)| g.adj[*v as usize].len() == 1)
        .take(MAX_ENDS)
        .count();
    let mut plan: Vec<(usize, (u32, u32))> = Vec::new();
    for &start in &starts[..ends] {
        plan.extend(BOUNDS.iter().map(|&b| (b, start)));
    }
    for b in BOUNDS {
        plan.extend(starts[ends..].iter().map(|&start| (b, start)));
    }
    // A drawing one stroke can draw is tried as one first (brackets
    // multiply the choices), with half the work; then with brackets, when
    // the drawing branches, with the rest.
    let bracketed = shared.limits.brackets;
    if bracketed && g.one_stroke() {
        let total = shared.limits.total;
        shared.limits.brackets = false;
        shared.limits.total = total / 2;
        if let Some(found) = over_graph(shared, &plan, n_max) {
            return Some(found);
        }
        shared.limits.brackets = true;
        shared.limits.total = total;
    }
    over_graph(shared, &plan, n_max)
}

/// The search over the graph alone, with one drawing letter, then two,
/// then three (each more letter multiplies the choices), start by start
/// and bound by bound.
fn over_graph(shared: &mut Shared, plan: &[(usize, (u32, u32))], n_max: u32) -> Option<Found> {
    let most = shared.limits.letters;
    let mut found = None;
    'letters: for letters in 1..=most {
        shared.limits.letters = letters;
        for &(bound, start) in plan {
            if shared.exhausted() {
                break 'letters;
            }
            found = shared.best_of(start, bound, 2..=n_max, None);
            if found.is_some() {
                break 'letters;
            }
        }
    }
    shared.limits.letters = most;
    found
}

/// The search that follows the paths' order, forwards and backwards, bound
/// by bound.
fn in_order(shared: &mut Shared, n_max: u32) -> Option<Found> {
    let g = shared.g;
    // Steps that start away from everything drawn before: a turtle's
    // branches start where it has been, so only moves do; more than half
    // say that the paths came in another order.
    let mut seen = vec![false; g.points.len()];
    let mut strays = 0;
    for (i, &(a, b)) in g.order.iter().enumerate() {
        if i > 0 && !seen[a as usize] {
            strays += 1;
        }
        seen[a as usize] = true;
        seen[b as usize] = true;
    }
    if 2 * strays > g.order.len() {
        return None;
    }
    // A drawing in one stroke needs no branches.
    let saved = shared.limits.brackets;
    shared.limits.brackets &= g.order.windows(2).any(|w| w[0].1 != w[1].0);
    let found = in_order_from(shared, n_max);
    shared.limits.brackets = saved;
    found
}

fn in_order_from(shared: &mut Shared, n_max: u32) -> Option<Found> {
    let order = shared.g.order.clone();
    along(shared, 2..=n_max, &order)
}

/// The search that follows `order`, forwards and backwards, bound by bound.
fn along(shared: &mut Shared, depths: RangeInclusive<u32>, order: &[(u32, u32)]) -> Option<Found> {
    let g = shared.g;
    let forwards = order.to_vec();
    let backwards: Vec<(u32, u32)> = order.iter().rev().map(|&(a, b)| (b, a)).collect();
    // The level parse first; what it finds is the smallest of its cuts,
    // but a successor of one step (`F -> G`) it reaches less surely than
    // the search below, which then looks for a smaller grammar with a
    // quarter of the work.
    let parsed = [&forwards, &backwards]
        .into_iter()
        .filter_map(|order| by_levels(shared, order))
        .min_by_key(Found::size);
    let (total, spent) = (shared.limits.total, shared.spent);
    let limit = parsed.as_ref().map_or(usize::MAX, Found::size);
    if parsed.is_some() {
        shared.limits.total = spent + (total - spent.min(total)) / 4;
    }
    let most = shared.limits.letters;
    let mut found = None;
    'letters: for letters in 1..=most {
        shared.limits.letters = letters;
        for bound in BOUNDS.into_iter().filter(|&b| b < limit) {
            for order in [&forwards, &backwards] {
                let (Some(&(from, to)), false) = (order.first(), shared.exhausted()) else {
                    break 'letters;
                };
                let Some(e) = g.edge(from, to) else {
                    break 'letters;
                };
                found = shared
                    .best_of((from, e), bound, depths.clone(), Some(order))
                    .filter(|f| f.size() < limit);
                if found.is_some() {
                    break 'letters;
                }
            }
        }
    }
    shared.limits.letters = most;
    shared.limits.total = total;
    found.or(parsed)
}

/// An edge-rewriting grammar read level by level (`levels`) off a curve
/// drawn in one stroke in `order`: with one letter, then two, then three,
/// none with a successor of one step; then again with them (the passes
/// without them find such a program applied twice over, whose root
/// `root.rs` offers, and the passes with them spend the most).
fn by_levels(shared: &mut Shared, order: &[(u32, u32)]) -> Option<Found> {
    let letters = shared.limits.letters;
    let passes: Vec<(usize, bool)> = [false, true]
        .into_iter()
        .flat_map(|single| (1..=letters).map(move |k| (k, single)))
        .collect();
    // Four times the work for a drawing of up to `MORE_WORK_STEPS` steps
    // (a three-letter program's square takes that); a parse's work costs
    // more the larger the drawing, and a huge one that nothing explains
    // would spend it all.
    let work = if order.len() <= MORE_WORK_STEPS {
        4 * shared.limits.work
    } else {
        shared.limits.work
    };
    levels_with(shared, order, &passes, work)
}

/// The largest drawing (steps) whose level parse gets four times the work.
const MORE_WORK_STEPS: usize = 20_000;

/// The level parse of `order` in the passes given (letters, one-step
/// successors), each with at most `work`.
fn levels_with(
    shared: &mut Shared,
    order: &[(u32, u32)],
    passes: &[(usize, bool)],
    work: u64,
) -> Option<Found> {
    let (trail, turns) = stroke(shared, order)?;
    let p = parse_turns(shared, &turns, passes, work)?;
    Some(found_of(shared, p, &trail))
}

/// A curve's drawn edges (each with the vertex it is drawn from) and its
/// turns between steps in δ₀.
type Stroke = (Vec<(u32, u32)>, Vec<i32>);

/// The stroke of a curve drawn in one stroke in `order`, when δ₀ divides
/// a full turn.
fn stroke(shared: &Shared, order: &[(u32, u32)]) -> Option<Stroke> {
    let g = shared.g;
    let m = (360.0 / shared.delta).round();
    let one_stroke = order.windows(2).all(|w| w[0].1 == w[1].0);
    if order.len() < 4 || !one_stroke || (360.0 / shared.delta - m).abs() > 1e-6 {
        return None;
    }
    let mut trail = Vec::with_capacity(order.len());
    for &(a, b) in order {
        trail.push((g.edge(a, b)?, a));
    }
    let turns = trail.windows(2).map(|w| turn(shared, w[0], w[1])).collect();
    Some((trail, turns))
}

/// The turn from drawn edge `a` to drawn edge `b`, in δ₀.
fn turn(shared: &Shared, a: (u32, u32), b: (u32, u32)) -> i32 {
    let g = shared.g;
    let d = g.direction(b.0, b.1) - g.direction(a.0, a.1);
    (turtle::wrap_degrees(d.to_degrees()) / shared.delta).round() as i32
}

/// The level parse of `turns` in the passes given: one letter, then two,
/// then three, each with no one-step successor first; the smallest grammar
/// of all (a later pass only looks for a smaller one).
fn parse_turns(
    shared: &mut Shared,
    turns: &[i32],
    passes: &[(usize, bool)],
    work: u64,
) -> Option<levels::Parsed> {
    let m = (360.0 / shared.delta).round() as i32;
    parse_passes(shared, passes, work, |l| levels::parse(turns, m, l))
}

/// The level parse's passes: one letter, then two, then three, each first
/// with no one-step successor.
fn passes(letters: usize) -> Vec<(usize, bool)> {
    (1..=letters)
        .flat_map(|k| [(k, false), (k, true)])
        .collect()
}

/// The level parse, as `parse` runs it with each pass's limits, in the
/// passes given.
fn parse_passes(
    shared: &mut Shared,
    passes: &[(usize, bool)],
    work: u64,
    mut parse: impl FnMut(&levels::Limits) -> Result<levels::Parsed, u64>,
) -> Option<levels::Parsed> {
    let mut best: Option<levels::Parsed> = None;
    for &(letters, single) in passes {
        if shared.exhausted() {
            break;
        }
        let limits = levels::Limits {
            letters,
            single,
            block: shared.limits.rule,
            // Letters, not symbols: a polygon of up to 32 sides.
            axiom: shared.limits.axiom.max(32),
            work: work.min(shared.limits.total - shared.spent),
            bound: best.as_ref().map_or(usize::MAX, levels::Parsed::size),
        };
        match parse(&limits) {
            Ok(p) => {
                shared.spent += p.work;
                best = Some(p);
            }
            Err(work) => shared.spent += work.max(1),
        }
    }
    best
}

/// A parse as a found grammar whose walk is `trail`.
fn found_of(shared: &Shared, p: levels::Parsed, trail: &[(u32, u32)]) -> Found {
    Found {
        axiom: p.axiom,
        rules: p.rules,
        depth: p.depth,
        delta: shared.delta,
        walk: walk(shared.g, trail),
    }
}

/// The search along a curve (every vertex on at most two edges) whose
/// steps came in any order: from the starts and at the depths its turns'
/// blocks give (`blocks`), each read forwards and backwards, with one
/// letter; an open curve is then read from each end at every depth, with
/// every letter the limits allow, unless it was `followed` so already (its
/// paths drew it in one stroke).
fn along_chain(
    shared: &mut Shared,
    chain: &[(u32, u32)],
    closed: bool,
    n_max: u32,
    followed: bool,
) -> Option<Found> {
    let g = shared.g;
    let delta = shared.delta;
    let dir = |&(a, b): &(u32, u32)| g.edge(a, b).map_or(0.0, |e| g.direction(e, a));
    let turns: Vec<i32> = (0..chain.len())
        .map(|i| {
            if i == 0 && !closed {
                return 0;
            }
            let prev = chain[(i + chain.len() - 1) % chain.len()];
            let d = (dir(&chain[i]) - dir(&prev)).to_degrees();
            (turtle::wrap_degrees(d) / delta).round() as i32
        })
        .collect();
    let max_block = shared.limits.rule;
    let starts = blocks::starts(&turns, closed, max_block, shared.limits.axiom);
    for s in &starts {
        if shared.exhausted() {
            return None;
        }
        let mut order = chain[s.at..].to_vec();
        order.extend_from_slice(&chain[..s.at]);
        let depth = s.depth.max(2);
        // Blocks that turn alike are one letter's successor.
        let letters = shared.limits.letters;
        shared.limits.letters = 1;
        let f = along(shared, depth..=depth, &order);
        shared.limits.letters = letters;
        if f.is_some() {
            return f;
        }
    }
    if closed {
        return around(shared, chain);
    }
    if followed {
        return None;
    }
    along(shared, 2..=n_max, chain)
}

/// A closed curve of two or three letters whose start is lost: the level
/// parse from every step in turn, both ways, with a little work each (a
/// wrong start fails within a few blocks), within half the work left.
fn around(shared: &mut Shared, chain: &[(u32, u32)]) -> Option<Found> {
    const EACH: u64 = 2_000;
    let passes: Vec<(usize, bool)> = (2..=shared.limits.letters).map(|k| (k, false)).collect();
    // The turns once, round the curve: `cyclic[i]` from step i to the next.
    let (trail, _) = stroke(shared, chain)?;
    let n = trail.len();
    let cyclic: Vec<i32> = (0..n)
        .map(|i| turn(shared, trail[i], trail[(i + 1) % n]))
        .collect();
    let total = shared.limits.total;
    shared.limits.total = shared.spent + (total - shared.spent.min(total)) / 2;
    let mut found = None;
    for at in 0..n {
        if shared.exhausted() {
            break;
        }
        // From step `at` on, and the same steps the other way round.
        let forwards: Vec<i32> = (0..n - 1).map(|j| cyclic[(at + j) % n]).collect();
        let backwards: Vec<i32> = forwards.iter().rev().map(|t| -t).collect();
        let order = |back: bool| -> Vec<(u32, u32)> {
            let mut o = chain[at..].to_vec();
            o.extend_from_slice(&chain[..at]);
            if back {
                o = o.iter().rev().map(|&(a, b)| (b, a)).collect();
            }
            o
        };
        for (turns, back) in [(&forwards, false), (&backwards, true)] {
            if let Some(p) = parse_turns(shared, turns, &passes, EACH) {
                found = stroke(shared, &order(back)).map(|(t, _)| found_of(shared, p, &t));
                break;
            }
        }
        if found.is_some() {
            break;
        }
    }
    shared.limits.total = total;
    found
}

/// A curve drawn in one stroke that touches or crosses itself, its steps
/// in any order: the level parse walks its graph (`euler`) from each of its
/// ends with every letter the limits allow, the smallest grammar of both;
/// a closed one from every step, with a little work each (a wrong start
/// fails within a few blocks), the first found. Within half the work left.
fn touching(shared: &mut Shared) -> Option<Found> {
    const EACH: u64 = 4_000;
    let g = shared.g;
    let delta = shared.delta;
    let m = (360.0 / delta).round() as i32;
    if (360.0 / delta - m as f64).abs() > 1e-6 || !g.one_stroke() {
        return None;
    }
    let odd: Vec<u32> = (0..g.points.len() as u32)
        .filter(|&v| g.adj[v as usize].len() % 2 == 1)
        .collect();
    let closed = odd.is_empty();
    let starts: Vec<(u32, u32)> = if closed {
        g.edges
            .iter()
            .enumerate()
            .flat_map(|(e, &[a, b])| [(a, e as u32), (b, e as u32)])
            .collect()
    } else {
        odd.iter()
            .flat_map(|&v| g.adj[v as usize].iter().map(move |&(_, e)| (v, e)))
            .collect()
    };
    // A closed curve's starts are tried with one letter each before any is
    // tried with two (a wrong start fails fastest with one); an open
    // curve's two ends with every pass.
    let passes = passes(shared.limits.letters);
    let rounds: Vec<&[(usize, bool)]> = if closed {
        passes.chunks(2).collect()
    } else {
        vec![&passes]
    };
    let each = if closed { EACH } else { shared.limits.work };
    let total = shared.limits.total;
    shared.limits.total = shared.spent + (total - shared.spent.min(total)) / 2;
    let mut best: Option<Found> = None;
    'rounds: for round in rounds {
        for &start in &starts {
            if shared.exhausted() {
                break 'rounds;
            }
            let parsed = parse_passes(shared, round, each, |l| {
                levels::parse_drawing(&mut euler::Walk::new(g, delta, start), m, l)
            });
            let Some(p) = parsed else { continue };
            let mut w = euler::Walk::new(g, delta, start);
            if !std::iter::once(0)
                .chain(p.turns.iter().copied())
                .all(|t| w.take(t))
            {
                continue;
            }
            let f = found_of(shared, p, w.trail());
            if best.as_ref().is_none_or(|b| f.size() < b.size()) {
                best = Some(f);
            }
            if closed {
                break 'rounds;
            }
        }
    }
    shared.limits.total = total;
    best
}

/// The most unit edges a drawing may have for this search (its work limit
/// would end it long before it drew one so large).
pub const MAX_EDGES: usize = 200_000;

/// The most start edges at a curve's ends tried with every bound first.
const MAX_ENDS: usize = 8;

/// The bounds on a grammar's symbols, tried in turn.
const BOUNDS: [usize; 10] = [4, 6, 8, 10, 12, 15, 18, 22, 26, 32];

/// The drawn edges, in the order drawn, as polylines: a new one wherever a
/// step does not start where the last ended.
fn walk(g: &Graph, trail: &[(u32, u32)]) -> Vec<Vec<DVec2>> {
    g.polylines(trail.iter().map(|&(e, from)| {
        let [a, b] = g.edges[e as usize];
        (from, if a == from { b } else { a })
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::graph;

    /// Draws a D0L system's string as unit segments (a turtle of this test).
    fn draw(axiom: &str, rules: &[(char, &str)], n: usize, delta: f64) -> Vec<Vec<DVec2>> {
        let mut s: String = axiom.into();
        for _ in 0..n {
            s = s
                .chars()
                .map(|c| {
                    rules
                        .iter()
                        .find(|r| r.0 == c)
                        .map_or(c.to_string(), |r| r.1.to_string())
                })
                .collect();
        }
        let (mut p, mut h) = (DVec2::ZERO, 90f64);
        let mut stack = Vec::new();
        let mut out = Vec::new();
        for c in s.chars() {
            match c {
                '+' => h += delta,
                '-' => h -= delta,
                '[' => stack.push((p, h)),
                ']' => (p, h) = stack.pop().expect("balanced"),
                c if c.is_ascii_uppercase() && c != 'X' && c != 'Y' => {
                    let q = p + DVec2::new(h.to_radians().cos(), h.to_radians().sin()) * 3.0;
                    out.push(vec![p, q]);
                    p = q;
                }
                _ => {}
            }
        }
        // Shuffle and reverse every other segment.
        let mut state = 12345u64;
        for i in (1..out.len()).rev() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let j = (state >> 33) as usize % (i + 1);
            out.swap(i, j);
        }
        for (i, l) in out.iter_mut().enumerate() {
            if i % 2 == 1 {
                l.reverse();
            }
        }
        out
    }

    fn found(lines: &[Vec<DVec2>], brackets: bool) -> Option<Found> {
        let g = graph::build(lines, 1).expect("graph");
        let limits = Limits {
            brackets,
            total: 12_000_000,
            ..Limits::default()
        };
        search(&g, &limits)
    }

    #[test]
    fn a_letter_only_the_axiom_names_is_unfolded() {
        use Sym::{Letter as L, Turn as T};
        let f = Found {
            axiom: vec![L(0), L(0), L(0), L(0)],
            rules: vec![vec![L(1), T(1)], vec![L(1), T(-1), L(1), L(1), T(1), L(1)]],
            depth: 4,
            delta: 90.0,
            walk: Vec::new(),
        }
        .unfolded();
        assert_eq!(f.depth, 3);
        assert_eq!(f.axiom, vec![L(0), T(1), L(0), T(1), L(0), T(1), L(0)]);
        assert_eq!(f.rules, vec![vec![L(0), T(-1), L(0), L(0), T(1), L(0)]]);
    }

    #[test]
    fn shuffled_curves_give_back_their_grammars() {
        // Drawn in another order, half the segments reversed: the
        // terdragon (δ = 120°, touching itself at every other vertex).
        let ter = found(&draw("F", &[('F', "F+F-F")], 4, 120.0), false).expect("the terdragon");
        assert_eq!(
            (ter.axiom.as_slice(), ter.rules.as_slice(), ter.depth),
            (
                &[Sym::Letter(0)][..],
                &[vec![
                    Sym::Letter(0),
                    Sym::Turn(1),
                    Sym::Letter(0),
                    Sym::Turn(-1),
                    Sym::Letter(0)
                ]][..],
                4
            )
        );
        // Its walk draws every segment once, in the grammar's order.
        let steps: usize = ter.walk.iter().map(|l| l.len() - 1).sum();
        assert_eq!(steps, 81);
    }

    #[test]
    fn a_random_walk_is_not_explained_within_the_work_limit() {
        let mut lines = Vec::new();
        let (mut p, mut state) = (DVec2::ZERO, 7u64);
        let mut seen = std::collections::HashSet::new();
        for _ in 0..400 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let d = [DVec2::X, DVec2::Y, -DVec2::X, -DVec2::Y][(state >> 33) as usize % 4];
            let q = p + d;
            let key = ((p + q) * 2.0).round().as_ivec2();
            if seen.insert((key.x, key.y)) {
                lines.push(vec![p, q]);
            }
            p = q;
        }
        let g = graph::build(&lines, 1).expect("graph");
        let limits = Limits {
            total: 200_000,
            ..Limits::default()
        };
        assert!(search(&g, &limits).is_none());
    }
}
