//! Edge-rewriting grammars read level by level off a curve drawn in one
//! stroke, with one to three drawing letters whose successors may have
//! different numbers of steps.
//!
//! A D0L system's drawing at depth n is its string one level up with each
//! letter replaced by its successor's steps. So the curve's steps cut into
//! blocks, each block turning inside exactly as one successor does; the
//! blocks are the letters of the level above, and the turns between them
//! are that level's turns plus the successors' trailing and leading turns.
//! That level cuts the same way, its blocks now checked letter by letter
//! too, and so on down to the axiom.
//!
//! The parse runs all levels at once, deepest first, so that a wrong cut
//! of the drawing (a successor taken too long, a block given to the wrong
//! letter) fails within a few blocks of the level below. Successors are
//! learned where they are first needed: their steps and inner turns where
//! the drawing first shows one, their letters where the level above first
//! does, and the sum of a trailing and a leading turn where two letters
//! first meet inside a block. Every choice is backed up when a later block
//! contradicts it, within a count of work.
//!
//! The curve is a `Drawing` the parse walks step by step: the turns of a
//! stroke drawn in order (`parse`), or a walk over a stroke graph whose
//! steps came in any order (`parse_drawing`), where a curve that touches
//! itself leaves a choice of turns at each vertex it passes twice. The
//! parse takes those choices with its own: a wrong one fails as a wrong cut
//! does.
//!
//! Owns: the level parse. Must not read the drawing (`synth` gives it the
//! turns, `euler` the walk) or accept a grammar (it goes through the same
//! checks as every other candidate).

use super::synth::Sym;

/// How far a parse goes.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Drawing letters at most (1–3).
    pub letters: usize,
    /// Steps in a successor at most.
    pub block: usize,
    /// Letters in the axiom at most.
    pub axiom: usize,
    /// Blocks parsed and choices made at most.
    pub work: u64,
    /// Whether a successor may have one step (`F -> G`, `F -> F-`): such
    /// a block fits anywhere, so the cuts with none are tried first.
    pub single: bool,
    /// Only grammars of fewer symbols than this are wanted.
    pub bound: usize,
}

/// A grammar read off the curve: axiom, each letter's successor, depth, in
/// turns of δ₀ (or the work spent failing).
#[derive(Clone, Debug, PartialEq)]
pub struct Parsed {
    pub axiom: Vec<Sym>,
    pub rules: Vec<Vec<Sym>>,
    pub depth: u32,
    /// The turns (0..m) of the walk the grammar draws, between its steps.
    pub turns: Vec<i32>,
    /// Work spent.
    pub work: u64,
}

/// A curve the parse walks, step by step.
pub trait Drawing {
    /// Steps in all.
    fn steps(&self) -> usize;
    /// Steps drawn so far.
    fn drawn(&self) -> usize;
    /// The turns (0..m) the next step may take after the last one drawn
    /// (the first step has one, 0), into `out`.
    fn choices(&mut self, out: &mut Vec<i32>);
    /// Draws the next step turning by `t` (ignored for the first); `false`
    /// when none may.
    fn take(&mut self, t: i32) -> bool;
    /// Undraws every step after the first `n`.
    fn back(&mut self, n: usize);
    /// Work done beyond the steps drawn since last asked (looks ahead).
    fn spent(&mut self) -> u64 {
        0
    }
}

/// The turns of a curve drawn in one stroke, in order.
struct Fixed<'a> {
    turns: &'a [i32],
    drawn: usize,
}

impl Drawing for Fixed<'_> {
    fn steps(&self) -> usize {
        self.turns.len() + 1
    }

    fn drawn(&self) -> usize {
        self.drawn
    }

    fn choices(&mut self, out: &mut Vec<i32>) {
        match self.drawn {
            0 => out.push(0),
            n if n < self.steps() => out.push(self.turns[n - 1]),
            _ => {}
        }
    }

    fn take(&mut self, t: i32) -> bool {
        let n = self.drawn;
        let ok = n == 0 || (n < self.steps() && self.turns[n - 1] == t);
        self.drawn += ok as usize;
        ok
    }

    fn back(&mut self, n: usize) {
        self.drawn = n.min(self.drawn);
    }
}

impl Parsed {
    /// Symbols in the axiom and the successors.
    pub fn size(&self) -> usize {
        self.axiom.len() + self.rules.iter().map(Vec::len).sum::<usize>()
    }
}

/// Letters at most (the sums table is this square).
const MAX_LETTERS: usize = 3;
/// The most steps of δ in a full turn parsed (a sum is guessed among them,
/// and the leading and trailing turns split over m^letters ways).
const MAX_TURNS: i32 = 36;
/// Paths offered as new successors at one cut at most (a walk that
/// touches itself often branches at every vertex).
const MOST_PATHS: usize = 512;
/// Levels at most (a successor of one step only delays its letter, so a
/// linear system can be deep).
const MAX_LEVELS: usize = 64;

/// A successor as the drawing shows it.
#[derive(Clone, Debug)]
struct Shape {
    /// Turns between its steps (`size - 1` of them).
    inner: Vec<i32>,
    /// Its letters, once a level above shows them.
    letters: Option<Vec<u8>>,
}

/// A turn between two letters of a level: `raw` less the sum of the left
/// letter's trailing and the right letter's leading turn (none on the
/// drawing itself).
#[derive(Clone, Copy, Debug)]
struct Turn {
    raw: i32,
    pair: Option<(u8, u8)>,
}

#[derive(Clone, Debug, Default)]
struct Level {
    letters: Vec<u8>,
    /// `turns[i]` is between letters `i` and `i + 1`.
    turns: Vec<Turn>,
    /// Letters cut into blocks so far.
    done: usize,
    /// This level is the axiom.
    frozen: bool,
}

#[derive(Clone, Copy, Debug)]
enum Alt {
    /// The next block is the successor of this letter.
    Block(u8),
    /// The drawing's next block is this letter's successor, after this
    /// turn.
    Cut(u8, i32),
    /// The drawing's next block is a new letter's successor, drawn as this
    /// path of the walk (`Parse::paths`) goes.
    New(u32),
    /// This level is the axiom.
    Freeze,
    /// The sum of the pair's trailing and leading turns.
    Sum((u8, u8), i32),
}

/// Where a level stands on the undo stack.
#[derive(Clone, Copy, Debug)]
struct Mark {
    letters: usize,
    turns: usize,
    done: usize,
    frozen: bool,
}

/// A step of a path the walk may take from where it is: the one before
/// (`u32::MAX` for the first), the turn to it, and how many steps in.
#[derive(Clone, Copy, Debug)]
struct Node {
    parent: u32,
    turn: i32,
    len: u32,
}

#[derive(Clone, Debug)]
struct Saved {
    levels: Vec<Mark>,
    shapes: usize,
    paths: usize,
    known: Vec<bool>,
    sums: [[Option<i32>; MAX_LETTERS]; MAX_LETTERS],
}

struct Point {
    saved: Saved,
    level: usize,
    alts: Vec<Alt>,
    next: usize,
}

enum Task {
    Choose(usize, Vec<Alt>),
    Fail,
    Done,
}

struct Parse<'a, D: Drawing> {
    d: &'a mut D,
    /// Turns of the drawing between its steps drawn so far.
    turns: Vec<i32>,
    /// The paths offered as new successors, as trees of steps.
    paths: Vec<Node>,
    m: i32,
    limits: Limits,
    shapes: Vec<Shape>,
    sums: [[Option<i32>; MAX_LETTERS]; MAX_LETTERS],
    /// Levels above the drawing: `levels[0]` is the string one derivation
    /// step up.
    levels: Vec<Level>,
    /// Steps of the drawing cut into blocks.
    done: usize,
    work: u64,
    /// Grammars of this many symbols or more are not wanted.
    bound: usize,
}

/// Reads an edge-rewriting grammar off a curve drawn in one stroke whose
/// `turns[i]` (multiples of δ₀ = 360°/m) is between steps `i` and `i + 1`:
/// the smallest found, with at most `limits.letters` letters and fewer
/// symbols than `limits.bound`, looking a while past the first cut that
/// draws the curve; or the work spent finding none.
pub fn parse(turns: &[i32], m: i32, limits: &Limits) -> Result<Parsed, u64> {
    let turns: Vec<i32> = turns.iter().map(|t| t.rem_euclid(m.max(1))).collect();
    let mut d = Fixed {
        turns: &turns,
        drawn: 0,
    };
    parse_drawing(&mut d, m, limits)
}

/// The parse of a curve walked as `d` draws it, from its first step (none
/// drawn yet; its turns 0..m).
pub fn parse_drawing(d: &mut impl Drawing, m: i32, limits: &Limits) -> Result<Parsed, u64> {
    if !(2..=MAX_TURNS).contains(&m)
        || d.steps() < 2
        || d.drawn() != 0
        || limits.letters == 0
        || limits.letters > MAX_LETTERS
    {
        return Err(0);
    }
    let mut p = Parse {
        d,
        turns: Vec::new(),
        paths: Vec::new(),
        m,
        limits: *limits,
        shapes: Vec::new(),
        sums: [[None; MAX_LETTERS]; MAX_LETTERS],
        levels: Vec::new(),
        done: 0,
        work: 0,
        bound: limits.bound,
    };
    match p.run() {
        Some(mut parsed) => {
            parsed.work = p.work;
            Ok(parsed)
        }
        None => Err(p.work),
    }
}

impl<D: Drawing> Parse<'_, D> {
    fn steps(&self) -> usize {
        self.d.steps()
    }

    /// Draws the next step, turning by `t` after the last.
    fn draw(&mut self, t: i32) -> bool {
        let first = self.d.drawn() == 0;
        if !self.d.take(t) {
            return false;
        }
        if !first {
            self.turns.push(t);
        }
        true
    }

    /// Draws `y`'s successor after turning by `before`.
    fn follow(&mut self, before: i32, y: u8) -> bool {
        if !self.draw(before) {
            return false;
        }
        for k in 0..self.shapes[y as usize].inner.len() {
            let t = self.shapes[y as usize].inner[k];
            if !self.draw(t) {
                return false;
            }
        }
        true
    }

    /// Undraws every step after the first `n`.
    fn undraw(&mut self, n: usize) {
        self.d.back(n);
        self.turns.truncate(n.saturating_sub(1));
    }

    /// The turns before the drawing's next block after which the walk can
    /// draw `y`'s successor.
    fn cuts(&mut self, y: u8) -> Vec<i32> {
        let n = self.done;
        let mut choices = Vec::new();
        self.d.choices(&mut choices);
        choices.retain(|&c| {
            let ok = self.follow(c, y);
            self.undraw(n);
            ok
        });
        choices
    }

    /// Every path of 1..=`most` steps the walk can take from where it is
    /// (at most `MOST_PATHS`), as nodes of `paths`.
    fn paths_from_here(&mut self, most: usize) -> std::ops::Range<u32> {
        let first = self.paths.len();
        self.grow(u32::MAX, 0, most, first + MOST_PATHS);
        first as u32..self.paths.len() as u32
    }

    /// The paths on from node `parent`, `len` steps in, until `paths` has
    /// `full` nodes.
    fn grow(&mut self, parent: u32, len: usize, most: usize, full: usize) {
        if len == most {
            return;
        }
        let n = self.d.drawn();
        let mut choices = Vec::new();
        self.d.choices(&mut choices);
        for c in choices {
            if self.paths.len() >= full {
                return;
            }
            if !self.draw(c) {
                continue;
            }
            self.paths.push(Node {
                parent,
                turn: c,
                len: len as u32 + 1,
            });
            let node = self.paths.len() as u32 - 1;
            self.grow(node, len + 1, most, full);
            self.undraw(n);
        }
    }

    /// The turns of path node `i`, from the first.
    fn path(&self, i: u32) -> Vec<i32> {
        let mut path = Vec::new();
        let mut at = i;
        while at != u32::MAX {
            path.push(self.paths[at as usize].turn);
            at = self.paths[at as usize].parent;
        }
        path.reverse();
        path
    }

    /// Every cut within the work limit, keeping the smallest grammar
    /// (a cut that draws the drawing is not yet the grammar a person
    /// wrote: a longer successor at a shallower depth can draw it too).
    fn run(&mut self) -> Option<Parsed> {
        let mut best: Option<Parsed> = None;
        let mut points: Vec<Point> = Vec::new();
        loop {
            self.work += 1 + self.d.spent();
            if self.work > self.limits.work {
                return best;
            }
            match self.task() {
                Task::Done => {
                    let p = self.parsed();
                    if best.as_ref().is_none_or(|b| p.size() < b.size()) {
                        self.bound = p.size();
                        best = Some(p);
                    }
                    // A smaller one is looked for a while longer, not
                    // through every cut.
                    let more = self.work.saturating_mul(4).max(self.work + 20_000);
                    self.limits.work = self.limits.work.min(more);
                }
                Task::Fail => {}
                Task::Choose(level, alts) => points.push(Point {
                    saved: self.save(),
                    level,
                    alts,
                    next: 0,
                }),
            }
            // Take the next alternative of the latest choice that has one.
            loop {
                let Some(p) = points.last_mut() else {
                    return best;
                };
                if p.next >= p.alts.len() {
                    points.pop();
                    continue;
                }
                let alt = p.alts[p.next];
                p.next += 1;
                let (level, saved) = (p.level, p.saved.clone());
                self.restore(&saved);
                self.work += 1;
                let applied = self.apply(level, alt);
                self.work += self.d.spent();
                if applied {
                    break;
                }
                if self.work > self.limits.work {
                    return best;
                }
            }
        }
    }

    /// The fewest symbols the successors known so far write: their letters
    /// and turns inside.
    fn least_size(&self) -> usize {
        self.shapes
            .iter()
            .map(|s| 1 + s.inner.len() + s.inner.iter().filter(|&&t| t != 0).count())
            .sum()
    }

    fn save(&self) -> Saved {
        Saved {
            levels: self
                .levels
                .iter()
                .map(|l| Mark {
                    letters: l.letters.len(),
                    turns: l.turns.len(),
                    done: l.done,
                    frozen: l.frozen,
                })
                .collect(),
            shapes: self.shapes.len(),
            paths: self.paths.len(),
            known: self.shapes.iter().map(|s| s.letters.is_some()).collect(),
            sums: self.sums,
        }
    }

    fn restore(&mut self, s: &Saved) {
        self.levels.truncate(s.levels.len());
        for (l, m) in self.levels.iter_mut().zip(&s.levels) {
            l.letters.truncate(m.letters);
            l.turns.truncate(m.turns);
            l.done = m.done;
            l.frozen = m.frozen;
        }
        self.shapes.truncate(s.shapes);
        self.paths.truncate(s.paths);
        for (shape, &known) in self.shapes.iter_mut().zip(&s.known) {
            if !known {
                shape.letters = None;
            }
        }
        self.sums = s.sums;
        // The drawing's own cut is the first level's letters.
        self.done = self.levels.first().map_or(0, |l| {
            l.letters
                .iter()
                .map(|&y| self.shapes[y as usize].inner.len() + 1)
                .sum()
        });
        self.undraw(self.done);
    }

    /// What to do next: the deepest level that can cut its next block
    /// chooses how; the drawing last.
    fn task(&mut self) -> Task {
        let all_shapes = self.shapes.len() == self.limits.letters;
        let longest = self.shapes.iter().map(|s| s.inner.len() + 1).max();
        for i in (0..self.levels.len()).rev() {
            let l = &self.levels[i];
            if l.frozen || l.done == l.letters.len() {
                continue;
            }
            let complete = self.complete(i);
            let pending = l.letters.len() - l.done;
            if !complete && longest.is_none_or(|b| pending < b) {
                // More letters will come.
                continue;
            }
            // The level's turn before the next block must be known to hand
            // it down.
            if l.done > 0
                && let Some(pair) = l.turns[l.done - 1].pair
                && self.sum(pair).is_none()
            {
                return Task::Choose(i + 1, self.guesses(pair));
            }
            let mut alts: Vec<Alt> = self
                .longest_first()
                .into_iter()
                .filter(|&y| self.fits(i + 1, y))
                .map(Alt::Block)
                .collect();
            if alts.is_empty() && !complete && !all_shapes {
                // The successor that cuts here is one the drawing has not
                // shown yet.
                continue;
            }
            if l.done == 0 && i >= 1 {
                alts.push(Alt::Freeze);
            }
            if alts.is_empty() {
                return Task::Fail;
            }
            return Task::Choose(i + 1, alts);
        }
        if self.done < self.steps() {
            let pending = self.steps() - self.done;
            let mut alts = Vec::new();
            for y in self.longest_first() {
                alts.extend(self.cuts(y).into_iter().map(|c| Alt::Cut(y, c)));
            }
            if !all_shapes {
                // The last letter must make the levels shorter: not every
                // successor one step.
                let shrinks = self.shapes.len() + 1 < self.limits.letters || self.shrinks();
                // A new successor of b steps writes at least b symbols.
                let room = self.bound.saturating_sub(self.least_size() + 1);
                let most = self.limits.block.min(pending).min(room);
                let mut paths: Vec<u32> = self.paths_from_here(most).collect();
                paths.sort_by_key(|&i| self.paths[i as usize].len);
                // One step fits anywhere: the last thing tried.
                let (one, more): (Vec<u32>, Vec<u32>) = paths
                    .into_iter()
                    .partition(|&i| self.paths[i as usize].len == 1);
                alts.extend(more.into_iter().map(Alt::New));
                if shrinks && self.limits.single {
                    alts.extend(one.into_iter().map(Alt::New));
                }
            }
            return if alts.is_empty() {
                Task::Fail
            } else {
                Task::Choose(0, alts)
            };
        }
        // Everything is cut: the deepest level is the axiom, at depth 2 or
        // more.
        match self.levels.last() {
            Some(l) if l.frozen && self.levels.len() >= 2 => Task::Done,
            _ => Task::Fail,
        }
    }

    /// The successors known so far, longest first (a short one fits in
    /// more places, so it is the likelier wrong cut).
    fn longest_first(&self) -> Vec<u8> {
        let mut ys: Vec<u8> = (0..self.shapes.len() as u8).collect();
        ys.sort_by_key(|&y| std::cmp::Reverse(self.shapes[y as usize].inner.len()));
        ys
    }

    /// Whether every letter of `levels[i]` is there: the levels below it
    /// are cut to their ends.
    fn complete(&self, i: usize) -> bool {
        self.done == self.steps() && self.levels[..i].iter().all(|l| l.done == l.letters.len())
    }

    /// The sum of `a`'s trailing and `b`'s leading turn, known or implied
    /// by three known sums (`s(a,b) = s(a,b') + s(a',b) − s(a',b')`).
    fn sum(&self, (a, b): (u8, u8)) -> Option<i32> {
        let (a, b) = (a as usize, b as usize);
        if let Some(v) = self.sums[a][b] {
            return Some(v);
        }
        for a2 in 0..MAX_LETTERS {
            for b2 in 0..MAX_LETTERS {
                if let (Some(x), Some(y), Some(z)) =
                    (self.sums[a][b2], self.sums[a2][b], self.sums[a2][b2])
                {
                    return Some((x + y - z).rem_euclid(self.m));
                }
            }
        }
        None
    }

    /// Sets a sum, or `false` when the known sums contradict it.
    fn learn(&mut self, pair: (u8, u8), v: i32) -> bool {
        let v = v.rem_euclid(self.m);
        if let Some(known) = self.sum(pair) {
            return known == v;
        }
        self.sums[pair.0 as usize][pair.1 as usize] = Some(v);
        true
    }

    /// Every value a sum could have, small turns first.
    fn guesses(&self, pair: (u8, u8)) -> Vec<Alt> {
        let mut v = vec![Alt::Sum(pair, 0)];
        for k in 1..=self.m / 2 {
            v.push(Alt::Sum(pair, k));
            if 2 * k != self.m {
                v.push(Alt::Sum(pair, -k));
            }
        }
        v
    }

    /// The value of a level's turn, when its sum is known.
    fn value(&self, t: Turn) -> Option<i32> {
        match t.pair {
            None => Some(t.raw),
            Some(pair) => self.sum(pair).map(|s| (t.raw - s).rem_euclid(self.m)),
        }
    }

    /// Whether the next block of level `at` (k ≥ 1: `levels[k-1]`) could be
    /// letter `y`'s successor (a cheap look; `apply` checks it all).
    fn fits(&self, at: usize, y: u8) -> bool {
        let shape = &self.shapes[y as usize];
        let size = shape.inner.len() + 1;
        let l = &self.levels[at - 1];
        let p = l.done;
        if p + size > l.letters.len() {
            return false;
        }
        match &shape.letters {
            Some(letters) if letters[..] != l.letters[p..p + size] => return false,
            None if l.letters[p..p + size] == [y] && !self.shrinks() => return false,
            _ => {}
        }
        shape
            .inner
            .iter()
            .zip(&l.turns[p..])
            .all(|(&want, &t)| self.value(t).is_none_or(|v| v == want))
    }

    /// Whether some successor has more than one step (so that a level is
    /// shorter than the one below it).
    fn shrinks(&self) -> bool {
        self.shapes.iter().any(|s| !s.inner.is_empty())
    }

    fn apply(&mut self, at: usize, alt: Alt) -> bool {
        match alt {
            Alt::Sum(pair, v) => self.learn(pair, v),
            Alt::Freeze => {
                let room = self.bound.saturating_sub(self.least_size() + 1);
                let l = &mut self.levels[at - 1];
                l.frozen = true;
                l.letters.len() <= self.limits.axiom.min(room)
            }
            Alt::New(node) => {
                let path = self.path(node);
                self.shapes.push(Shape {
                    inner: path[1..].to_vec(),
                    letters: None,
                });
                self.block(0, self.shapes.len() as u8 - 1, path[0])
            }
            Alt::Cut(y, before) => self.block(0, y, before),
            Alt::Block(y) => self.block(at, y, 0),
        }
    }

    /// Cuts the next block of level `at` as `y`'s successor (on the
    /// drawing, after turning by `before`) and hands `y` down to the level
    /// above.
    fn block(&mut self, at: usize, y: u8, before: i32) -> bool {
        let size = self.shapes[y as usize].inner.len() + 1;
        self.work += size as u64;
        let p;
        if at == 0 {
            p = self.done;
            if !self.follow(before, y) {
                return false;
            }
            self.done += size;
        } else {
            let l = &self.levels[at - 1];
            p = l.done;
            if p + size > l.letters.len() {
                return false;
            }
            let letters = l.letters[p..p + size].to_vec();
            let turns = l.turns[p..p + size - 1].to_vec();
            match &self.shapes[y as usize].letters {
                Some(known) if *known != letters => return false,
                Some(_) => {}
                // A letter whose successor is itself (turned: `F -> F-`,
                // or left as it is) needs another whose successor is
                // longer, or no level would be shorter than the last.
                None if letters == [y] && !self.shrinks() => return false,
                None => self.shapes[y as usize].letters = Some(letters),
            }
            for (k, t) in turns.into_iter().enumerate() {
                let want = self.shapes[y as usize].inner[k];
                let ok = match t.pair {
                    None => t.raw == want,
                    Some(pair) => self.learn(pair, t.raw - want),
                };
                if !ok {
                    return false;
                }
            }
            self.levels[at - 1].done += size;
        }
        // The turn before this block, handed down.
        let before = if p == 0 {
            None
        } else if at == 0 {
            Some(self.turns[p - 1])
        } else {
            match self.value(self.levels[at - 1].turns[p - 1]) {
                Some(v) => Some(v),
                None => return false,
            }
        };
        if self.levels.len() == at {
            if at >= MAX_LEVELS {
                return false;
            }
            self.levels.push(Level::default());
        }
        // The axiom's letters count towards the grammar's symbols too.
        let axiom = self
            .limits
            .axiom
            .min(self.bound.saturating_sub(self.least_size() + 1));
        let up = &mut self.levels[at];
        if let (Some(raw), Some(&prev)) = (before, up.letters.last()) {
            up.turns.push(Turn {
                raw,
                pair: Some((prev, y)),
            });
        }
        up.letters.push(y);
        !(up.frozen && up.letters.len() > axiom)
    }

    /// The grammar: each successor's leading and trailing turns split from
    /// the sums as cheaply as they can be (the conjugate a person writes).
    fn parsed(&self) -> Parsed {
        let k = self.shapes.len();
        let (lead, trail) = self.split();
        let turn = |t: i32, out: &mut Vec<Sym>| {
            let t = signed(t, self.m);
            if t != 0 {
                out.push(Sym::Turn(t));
            }
        };
        let rules = (0..k)
            .map(|y| {
                let shape = &self.shapes[y];
                let letters = shape
                    .letters
                    .clone()
                    .unwrap_or_else(|| vec![y as u8; shape.inner.len() + 1]);
                let mut out = Vec::new();
                turn(lead[y], &mut out);
                for (i, &x) in letters.iter().enumerate() {
                    if i > 0 {
                        turn(shape.inner[i - 1], &mut out);
                    }
                    out.push(Sym::Letter(x));
                }
                turn(trail[y], &mut out);
                out
            })
            .collect();
        let top = self.levels.last().cloned().unwrap_or_default();
        let mut axiom = Vec::new();
        for (i, &x) in top.letters.iter().enumerate() {
            if i > 0 {
                let t = top.turns[i - 1];
                let v = match t.pair {
                    None => t.raw,
                    Some((a, b)) => t.raw - trail[a as usize] - lead[b as usize],
                };
                turn(v, &mut axiom);
            }
            axiom.push(Sym::Letter(x));
        }
        Parsed {
            axiom,
            rules,
            depth: self.levels.len() as u32,
            turns: self.turns.clone(),
            work: self.work,
        }
    }

    /// Leading and trailing turns that give every known sum, the fewest
    /// turn symbols in all.
    fn split(&self) -> (Vec<i32>, Vec<i32>) {
        let k = self.shapes.len();
        let m = self.m;
        let size = |t: i32| signed(t, m).abs();
        let mut best: Option<(i32, Vec<i32>, Vec<i32>)> = None;
        let combos = (m as usize).pow(k as u32);
        for code in 0..combos {
            let mut lead = vec![0; k];
            let mut c = code;
            for l in lead.iter_mut() {
                *l = (c % m as usize) as i32;
                c /= m as usize;
            }
            let mut ok = true;
            let trail: Vec<i32> = self.sums[..k]
                .iter()
                .map(|row| {
                    let mut t = None;
                    for (s, &l) in row.iter().zip(&lead) {
                        if let Some(s) = s {
                            let v = (s - l).rem_euclid(m);
                            ok &= t.is_none_or(|t| t == v);
                            t = Some(v);
                        }
                    }
                    t.unwrap_or(0)
                })
                .collect();
            if !ok {
                continue;
            }
            let cost: i32 = lead.iter().chain(&trail).map(|&t| size(t)).sum();
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, lead, trail));
            }
        }
        best.map_or_else(|| (vec![0; k], vec![0; k]), |(_, l, t)| (l, t))
    }
}

/// A turn modulo m as the nearest signed one (half a turn counts as
/// positive).
pub(super) fn signed(t: i32, m: i32) -> i32 {
    let t = t.rem_euclid(m);
    if 2 * t > m { t - m } else { t }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The turns between the steps of `axiom` derived `n` times (every
    /// letter draws; `+`/`-` turn by one). (Also `blocks`'s tests'.)
    pub(in crate::infer::lines) fn turns(axiom: &str, rules: &[(char, &str)], n: u32) -> Vec<i32> {
        let mut w = axiom.to_string();
        for _ in 0..n {
            w = w
                .chars()
                .map(|c| {
                    rules
                        .iter()
                        .find(|(p, _)| *p == c)
                        .map_or_else(|| c.to_string(), |(_, s)| s.to_string())
                })
                .collect();
        }
        let mut out = Vec::new();
        let mut t = 0;
        let mut first = true;
        for c in w.chars() {
            match c {
                '+' => t += 1,
                '-' => t -= 1,
                _ => {
                    if !first {
                        out.push(t);
                    }
                    first = false;
                    t = 0;
                }
            }
        }
        out
    }

    fn limits(letters: usize) -> Limits {
        Limits {
            letters,
            block: 24,
            axiom: 32,
            work: 2_000_000,
            single: true,
            bound: usize::MAX,
        }
    }

    /// The parsed grammar as text over F, G, H.
    fn text(p: &Parsed) -> String {
        let word = |v: &[Sym]| -> String {
            v.iter()
                .map(|s| match s {
                    Sym::Letter(k) => ['F', 'G', 'H'][*k as usize].to_string(),
                    Sym::Turn(t) if *t > 0 => "+".repeat(*t as usize),
                    Sym::Turn(t) => "-".repeat(t.unsigned_abs() as usize),
                    _ => "?".into(),
                })
                .collect()
        };
        let mut out = format!("{} @{}", word(&p.axiom), p.depth);
        for (k, r) in p.rules.iter().enumerate() {
            out.push_str(&format!("; {} -> {}", ['F', 'G', 'H'][k], word(r)));
        }
        out
    }

    /// Parsed as the search does: one letter, then two …, each with no
    /// one-step successor first.
    fn parsed(axiom: &str, rules: &[(char, &str)], n: u32, m: i32, letters: usize) -> String {
        let t = turns(axiom, rules, n);
        let mut spent = 0;
        let mut best: Option<Parsed> = None;
        for k in 1..=letters {
            for single in [false, true] {
                let l = Limits {
                    single,
                    ..limits(k)
                };
                match parse(&t, m, &l) {
                    Ok(p) if best.as_ref().is_none_or(|b: &Parsed| p.size() < b.size()) => {
                        best = Some(p)
                    }
                    Ok(p) => spent += p.work,
                    Err(work) => spent += work,
                }
            }
        }
        best.map_or_else(|| format!("none after {spent}"), |p| text(&p))
    }

    #[test]
    fn one_letter_curves() {
        assert_eq!(
            parsed("F", &[('F', "F+F-F-F+F")], 4, 4, 3),
            "F @4; F -> F+F-F-F+F"
        );
        assert_eq!(
            parsed("F+F+F+F", &[('F', "F+F-F-FF+F+F-F")], 2, 4, 3),
            "F+F+F+F @2; F -> F+F-F-FF+F+F-F"
        );
    }

    /// The Koch curve's successor is another's square (`F -> F+F+++`
    /// twice is `F+F---F+F`, modulo a full turn): its drawing at depth 4 is
    /// that one's at depth 8, the smaller grammar, which the parse gives.
    #[test]
    fn a_successor_that_is_a_square_is_read_as_its_root() {
        assert_eq!(
            parsed("F", &[('F', "F+F--F+F")], 4, 6, 1),
            "F @8; F -> F+F+++"
        );
    }

    /// A fine angle (m > 36) or no turns at all is not parsed.
    #[test]
    fn fine_angles_are_not_parsed() {
        let t = turns("F", &[('F', "F+F-F-F+F")], 3);
        assert_eq!(parse(&t, 72, &limits(1)), Err(0));
        assert_eq!(parse(&[], 4, &limits(1)), Err(0));
        assert!(parse(&t, 4, &limits(1)).is_ok());
    }

    #[test]
    fn two_letters_of_different_lengths() {
        assert_eq!(
            parsed("G", &[('F', "F--G-F"), ('G', "F+F++GF-")], 5, 12, 2),
            "G @5; F -> F--G-F; G -> F+F++GF-"
        );
    }

    #[test]
    fn a_long_axiom() {
        assert_eq!(
            parsed(
                "F+G+F+F+G+F+G+G+G+F+F+F+G+F+G+F",
                &[('F', "G++G--F++FG--F"), ('G', "G-G--GG")],
                3,
                16,
                2
            ),
            "G+F+G+G+F+G+F+F+F+G+G+G+F+G+F+G @3; F -> F-F--FF; G -> F++F--G++GF--G"
        );
    }
}
