//! Roots: a grammar that is another applied twice or three times over, and
//! an axiom that is a successor's image.
//!
//! A successor of one step (`H -> F-`, `G -> F`) fits anywhere in a
//! drawing, so the level parse tries cuts with none first, and what it
//! finds for a system with one is that system applied twice or three times
//! over: its rules longer, its depth a half or a third (`F -> F-G+H;
//! G -> GH-; H -> FG+H` at depth 7 for `F -> HG; G -> H+G; H -> F-` at
//! depth 14). Both draw the drawing; only the root draws the next level.
//! So a grammar found is offered its roots: σ with σᵏ = τ (k = 2, 3), in
//! letters and in turns, at k times the depth. Likewise an axiom that is
//! the successors' image of a shorter word is that word one level up.
//! Each is smaller than what it came from, and each goes through the same
//! check against the drawing as every candidate.
//!
//! The letters of a root come from a search over successors written one
//! letter at a time, each choice checked against the prefix of τ it
//! derives. The turns are unknowns (each successor's leading, inner and
//! trailing turns), solved from linear equations modulo the full turn:
//! σᵏ's inner turns are τ's, and the sum of one letter's trailing and the
//! next one's leading turn is τ's for every pair of letters that meet.
//!
//! Also the grammar that draws a curve from its other end (`reversed`).
//!
//! Owns: roots and reversals of edge-rewriting grammars (every letter
//! draws, no branches, δ a whole fraction of a full turn). Must not check a
//! candidate against the drawing (`grammar::matches` does).

use super::grammar::{Action, Grammar, Sym};
use super::levels::signed;
use super::turtle::Angles;

/// Work (letters derived, values tried) for one grammar's roots at most.
const WORK: u64 = 200_000;
/// Levels an axiom is taken up at most (a letter whose successor is one
/// letter is its own image's preimage level after level).
const MAX_UP: u32 = 8;
/// Letter roots kept per power at most.
const MOST_ROOTS: usize = 8;

/// A successor (or an axiom) as turns around letters: `lead`, the letters
/// with `inner[i]` between letters `i` and `i + 1`, `trail`.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Succ {
    lead: i32,
    letters: Vec<u8>,
    inner: Vec<i32>,
    trail: i32,
}

impl Succ {
    /// `None` for branches or a word with no letter.
    fn of(syms: &[Sym]) -> Option<Succ> {
        let mut s = Succ {
            lead: 0,
            letters: Vec::new(),
            inner: Vec::new(),
            trail: 0,
        };
        let mut turn = 0;
        for sym in syms {
            match sym {
                Sym::Plus => turn += 1,
                Sym::Minus => turn -= 1,
                Sym::Push | Sym::Pop => return None,
                Sym::Letter(k) => {
                    if s.letters.is_empty() {
                        s.lead = turn;
                    } else {
                        s.inner.push(turn);
                    }
                    s.letters.push(*k);
                    turn = 0;
                }
            }
        }
        s.trail = turn;
        (!s.letters.is_empty()).then_some(s)
    }

    fn syms(&self, angles: &Angles) -> Vec<Sym> {
        let turn = |t: i32, out: &mut Vec<Sym>| {
            out.extend(super::grammar::turn_syms(t, angles));
        };
        let mut out = Vec::new();
        turn(self.lead, &mut out);
        for (i, &y) in self.letters.iter().enumerate() {
            if i > 0 {
                turn(self.inner[i - 1], &mut out);
            }
            out.push(Sym::Letter(y));
        }
        turn(self.trail, &mut out);
        out
    }
}

/// The successors of an edge-rewriting grammar (a letter with none
/// rewrites to itself); `None` for any other grammar.
fn successors(g: &Grammar) -> Option<Vec<Succ>> {
    if g.letters.is_empty() || g.letters.len() > 4 {
        return None;
    }
    g.letters
        .iter()
        .enumerate()
        .map(|(k, l)| {
            if l.action != Action::Draw {
                return None;
            }
            match &l.rule {
                Some(r) => Succ::of(r),
                None => Some(Succ {
                    lead: 0,
                    letters: vec![k as u8],
                    inner: Vec::new(),
                    trail: 0,
                }),
            }
        })
        .collect()
}

/// Grammars smaller than `g` that draw what it draws, deepest first: its
/// cube and square roots with a successor of one letter (each with its
/// axiom taken up as far as it goes). A root with none is not offered:
/// the level parse would have found it first, and where it gives a power
/// instead (`F -> F-F++F-F` is `F -> F-F+++` twice over) that is what a
/// person draws, level n cannot tell the two apart.
pub fn deeper(g: &Grammar, angles: &Angles) -> Vec<Grammar> {
    let (Some(m), Some(tau), Some(axiom)) = (angles.period, successors(g), Succ::of(&g.axiom))
    else {
        return Vec::new();
    };
    let n = tau.len();
    let known = |s: &Succ| s.letters.iter().all(|&y| (y as usize) < n);
    if m < 2 || !tau.iter().all(known) || !known(&axiom) {
        return Vec::new();
    }
    let mut out = Vec::new();
    for k in [3u32, 2] {
        let mut work = 0;
        let t: Vec<Vec<u8>> = tau.iter().map(|s| s.letters.clone()).collect();
        for s in letter_roots(&t, k, &mut work) {
            if !s.iter().any(|w| w.len() == 1) {
                continue;
            }
            let Some(sigma) = turned(&s, &tau, &axiom, k, m, &mut work) else {
                continue;
            };
            let (ax, up) = taken_up(&sigma, &axiom, m);
            out.push(written(g, &sigma, &ax, k * g.depth + up, angles));
        }
    }
    out
}

/// The grammar that draws `g`'s curve from its other end: each successor
/// and the axiom written backwards, each turn the other way (`F -> F-G+H`
/// becomes `F -> H-G+F`). `None` unless `g` rewrites edges.
pub fn reversed(g: &Grammar, angles: &Angles) -> Option<Grammar> {
    let back = |s: &Succ| Succ {
        lead: -s.trail,
        letters: s.letters.iter().rev().copied().collect(),
        inner: s.inner.iter().rev().map(|t| -t).collect(),
        trail: -s.lead,
    };
    let rules: Vec<Succ> = successors(g)?.iter().map(back).collect();
    let axiom = back(&Succ::of(&g.axiom)?);
    Some(written(g, &rules, &axiom, g.depth, angles))
}

fn written(g: &Grammar, rules: &[Succ], axiom: &Succ, depth: u32, angles: &Angles) -> Grammar {
    let mut out = g.clone();
    for (l, s) in out.letters.iter_mut().zip(rules) {
        l.rule = Some(s.syms(angles));
    }
    out.axiom = axiom.syms(angles);
    out.depth = depth;
    out
}

/// Letter successors `s` (not `t` itself) with `s` applied `k` times
/// equal to `t`, at most `MOST_ROOTS`.
fn letter_roots(t: &[Vec<u8>], k: u32, work: &mut u64) -> Vec<Vec<Vec<u8>>> {
    let mut r = Roots {
        t,
        k,
        s: vec![Vec::new(); t.len()],
        closed: vec![false; t.len()],
        found: Vec::new(),
        work,
    };
    r.search();
    r.found
}

struct Roots<'a> {
    t: &'a [Vec<u8>],
    k: u32,
    s: Vec<Vec<u8>>,
    closed: Vec<bool>,
    found: Vec<Vec<Vec<u8>>>,
    work: &'a mut u64,
}

/// How far a letter's derivation agrees with its target.
enum Prefix {
    /// It differs, or is longer.
    Wrong,
    /// It agrees as far as it is known.
    Open,
    /// It is known and equal.
    Equal,
}

impl Roots<'_> {
    fn search(&mut self) {
        if self.found.len() >= MOST_ROOTS || *self.work > WORK {
            return;
        }
        *self.work += 1;
        let Some(x) = self.closed.iter().position(|c| !c) else {
            if self.s != self.t {
                self.found.push(self.s.clone());
            }
            return;
        };
        // Close `x`'s successor, or write one more letter in it.
        if !self.s[x].is_empty() {
            self.closed[x] = true;
            if self.consistent() {
                self.search();
            }
            self.closed[x] = false;
        }
        if self.s[x].len() < self.t[x].len() {
            for y in 0..self.t.len() as u8 {
                self.s[x].push(y);
                if self.consistent() {
                    self.search();
                }
                self.s[x].pop();
            }
        }
    }

    /// The fewest letters `z` can derive in `level` steps, whatever its
    /// open successors get.
    fn least(&self, z: u8, level: u32) -> usize {
        if level == 0 {
            return 1;
        }
        let sum: usize = self.s[z as usize]
            .iter()
            .map(|&y| self.least(y, level - 1))
            .sum();
        sum.max(1)
    }

    /// Whether every letter's derivation agrees with its target so far.
    fn consistent(&mut self) -> bool {
        if (0..self.t.len()).any(|x| self.least(x as u8, self.k) > self.t[x].len()) {
            return false;
        }
        (0..self.t.len()).all(|x| {
            let mut out = Vec::new();
            let state = self.derive(x as u8, self.k, &mut out);
            *self.work += out.len() as u64;
            let target = &self.t[x];
            if out.len() > target.len() || out[..] != target[..out.len()] {
                return false;
            }
            match state {
                Prefix::Equal => out.len() == target.len(),
                Prefix::Open => true,
                Prefix::Wrong => false,
            }
        })
    }

    /// `z` derived `level` times into `out`, as far as its successors are
    /// known (stopping past the target's longest).
    fn derive(&self, z: u8, level: u32, out: &mut Vec<u8>) -> Prefix {
        if level == 0 {
            out.push(z);
            return Prefix::Equal;
        }
        let longest = self.t.iter().map(Vec::len).max().unwrap_or(0);
        for &y in &self.s[z as usize] {
            match self.derive(y, level - 1, out) {
                Prefix::Equal if out.len() <= longest => {}
                Prefix::Equal | Prefix::Wrong => return Prefix::Wrong,
                Prefix::Open => return Prefix::Open,
            }
        }
        if self.closed[z as usize] {
            Prefix::Equal
        } else {
            Prefix::Open
        }
    }
}

/// A linear form over the unknown turns: coefficients and a constant.
#[derive(Clone, Debug)]
struct Lin {
    c: Vec<i32>,
    k: i32,
}

impl Lin {
    fn zero(n: usize) -> Lin {
        Lin {
            c: vec![0; n],
            k: 0,
        }
    }

    fn var(n: usize, i: usize) -> Lin {
        let mut l = Lin::zero(n);
        l.c[i] = 1;
        l
    }

    fn add(&mut self, o: &Lin) {
        for (a, b) in self.c.iter_mut().zip(&o.c) {
            *a += b;
        }
        self.k += o.k;
    }
}

/// A successor in unknown turns: lead, letters, inner, trail.
#[derive(Clone, Debug)]
struct Form {
    lead: Lin,
    letters: Vec<u8>,
    inner: Vec<Lin>,
    trail: Lin,
}

/// The successors `s` (letters) given turns: σᵏ's inner turns equal τ's,
/// and its trailing-plus-leading sums τ's for every pair of letters that
/// meet in τ's derivation of `axiom`; `None` when no turns do.
fn turned(
    s: &[Vec<u8>],
    tau: &[Succ],
    axiom: &Succ,
    k: u32,
    m: i32,
    work: &mut u64,
) -> Option<Vec<Succ>> {
    // Unknowns: each letter's lead, trail and inner turns.
    let mut index = Vec::new();
    let mut n = 0;
    for w in s {
        index.push(n);
        n += 2 + w.len() - 1;
    }
    let sigma: Vec<Form> = s
        .iter()
        .zip(&index)
        .map(|(w, &i)| Form {
            lead: Lin::var(n, i),
            letters: w.clone(),
            inner: (0..w.len() - 1).map(|j| Lin::var(n, i + 2 + j)).collect(),
            trail: Lin::var(n, i + 1),
        })
        .collect();
    let mut eqs: Vec<Lin> = Vec::new();
    let power: Vec<Form> = (0..s.len())
        .map(|x| {
            let mut f = Form {
                lead: Lin::zero(n),
                letters: vec![x as u8],
                inner: Vec::new(),
                trail: Lin::zero(n),
            };
            for _ in 0..k {
                f = applied(&f, &sigma, n);
            }
            f
        })
        .collect();
    for (p, t) in power.iter().zip(tau) {
        if p.letters != t.letters {
            return None;
        }
        for (l, &v) in p.inner.iter().zip(&t.inner) {
            let mut e = l.clone();
            e.k -= v;
            eqs.push(e);
        }
    }
    let t_letters: Vec<Vec<u8>> = tau.iter().map(|t| t.letters.clone()).collect();
    for (a, b) in meeting(&t_letters, &axiom.letters) {
        let (a, b) = (a as usize, b as usize);
        let mut e = power[a].trail.clone();
        e.add(&power[b].lead);
        e.k -= tau[a].trail + tau[b].lead;
        eqs.push(e);
    }
    let mut vals = vec![None; n];
    if !solve(&eqs, &mut vals, m, work) {
        return None;
    }
    let value = |l: &Lin| -> i32 {
        let v: i32 = l.c.iter().zip(&vals).map(|(c, v)| c * v.unwrap_or(0)).sum();
        signed(v + l.k, m)
    };
    Some(
        sigma
            .iter()
            .map(|f| Succ {
                lead: value(&f.lead),
                letters: f.letters.clone(),
                inner: f.inner.iter().map(value).collect(),
                trail: value(&f.trail),
            })
            .collect(),
    )
}

/// `f` with each letter replaced by its successor.
fn applied(f: &Form, sigma: &[Form], n: usize) -> Form {
    let mut out = Form {
        lead: f.lead.clone(),
        letters: Vec::new(),
        inner: Vec::new(),
        trail: Lin::zero(n),
    };
    // The turn pending before the next letter written.
    let mut pending = Lin::zero(n);
    for (i, &y) in f.letters.iter().enumerate() {
        if i > 0 {
            pending.add(&f.inner[i - 1]);
        }
        let s = &sigma[y as usize];
        pending.add(&s.lead);
        for (j, &z) in s.letters.iter().enumerate() {
            if j > 0 {
                pending = s.inner[j - 1].clone();
            }
            if out.letters.is_empty() {
                out.lead.add(&pending);
            } else {
                out.inner.push(pending.clone());
            }
            out.letters.push(z);
            pending = Lin::zero(n);
        }
        pending = s.trail.clone();
    }
    out.trail = pending;
    out.trail.add(&f.trail);
    out
}

/// The pairs of letters that meet (one right after the other) in some
/// word of `t`'s derivation of `axiom`.
fn meeting(t: &[Vec<u8>], axiom: &[u8]) -> Vec<(u8, u8)> {
    let mut seen = std::collections::BTreeSet::new();
    let mut todo: Vec<(u8, u8)> = axiom.windows(2).map(|w| (w[0], w[1])).collect();
    // Letters that occur: in the axiom, and in what they derive.
    let mut occurs = vec![false; t.len()];
    let mut stack: Vec<u8> = axiom.to_vec();
    while let Some(x) = stack.pop() {
        if !std::mem::replace(&mut occurs[x as usize], true) {
            stack.extend(&t[x as usize]);
        }
    }
    for (x, w) in t.iter().enumerate() {
        if occurs[x] {
            todo.extend(w.windows(2).map(|w| (w[0], w[1])));
        }
    }
    while let Some((a, b)) = todo.pop() {
        if seen.insert((a, b)) {
            let last = *t[a as usize].last().expect("a successor has a letter");
            todo.push((last, t[b as usize][0]));
        }
    }
    seen.into_iter().collect()
}

/// Values (modulo `m`) for the unknowns that make every equation zero:
/// an equation with one unknown left of coefficient ±1 sets it, and when
/// none has, an unknown is tried at each value, small turns first. Unknowns
/// no equation fixes stay `None` (zero).
fn solve(eqs: &[Lin], vals: &mut [Option<i32>], m: i32, work: &mut u64) -> bool {
    loop {
        *work += eqs.len() as u64;
        if *work > WORK {
            return false;
        }
        let mut progress = false;
        let mut open = None;
        for e in eqs {
            let mut rest = e.k;
            let mut unknown = Vec::new();
            for (i, (&c, v)) in e.c.iter().zip(vals.iter()).enumerate() {
                if c.rem_euclid(m) == 0 {
                    continue;
                }
                match v {
                    Some(v) => rest += c * v,
                    None => unknown.push(i),
                }
            }
            match unknown[..] {
                [] if rest.rem_euclid(m) != 0 => return false,
                [] => {}
                [i] if e.c[i].rem_euclid(m) == 1 || e.c[i].rem_euclid(m) == m - 1 => {
                    let c = if e.c[i].rem_euclid(m) == 1 { 1 } else { -1 };
                    vals[i] = Some((-rest * c).rem_euclid(m));
                    progress = true;
                }
                [i, ..] => open = open.or(Some(i)),
            }
        }
        if progress {
            continue;
        }
        let Some(i) = open else {
            return true;
        };
        for v in small_first(m) {
            let mut tried = vals.to_vec();
            tried[i] = Some(v);
            if solve(eqs, &mut tried, m, work) {
                vals.copy_from_slice(&tried);
                return true;
            }
            if *work > WORK {
                return false;
            }
        }
        return false;
    }
}

/// 0, 1, −1, 2, −2 … modulo `m`.
fn small_first(m: i32) -> Vec<i32> {
    let mut v = vec![0];
    for k in 1..=m / 2 {
        v.push(k);
        if 2 * k != m {
            v.push(m - k);
        }
    }
    v
}

/// `axiom` taken up the levels that make it shortest: while it is the
/// image of a word under `rules`, that word (up to `MAX_UP` levels); the
/// fewest letters, the fewest levels up among those, and the levels.
fn taken_up(rules: &[Succ], axiom: &Succ, m: i32) -> (Succ, u32) {
    let mut best = (axiom.clone(), 0);
    let mut a = axiom.clone();
    for up in 1..=MAX_UP {
        let Some(b) = preimage(rules, &a, m) else {
            break;
        };
        if b.letters.len() < best.0.letters.len() {
            best = (b.clone(), up);
        }
        a = b;
    }
    best
}

/// A word whose image under `rules` is `a`, turns and all (up to the turn
/// before its first step).
fn preimage(rules: &[Succ], a: &Succ, m: i32) -> Option<Succ> {
    let mut cut = Vec::new();
    let mut work = 0;
    if !cut_into(rules, a, m, 0, &mut cut, &mut work) {
        return None;
    }
    let mut inner = Vec::new();
    let mut at = 0;
    for w in cut.windows(2) {
        at += rules[w[0] as usize].letters.len();
        let between = a.inner[at - 1];
        inner.push(signed(
            between - rules[w[0] as usize].trail - rules[w[1] as usize].lead,
            m,
        ));
    }
    let first = &rules[cut[0] as usize];
    let last = &rules[*cut.last()? as usize];
    Some(Succ {
        lead: signed(a.lead - first.lead, m),
        letters: cut,
        inner,
        trail: signed(a.trail - last.trail, m),
    })
}

/// Cuts `a`'s letters from `from` on into successors whose letters and
/// inner turns they are, into `cut` (within `WORK` tries in all).
fn cut_into(
    rules: &[Succ],
    a: &Succ,
    m: i32,
    from: usize,
    cut: &mut Vec<u8>,
    work: &mut u64,
) -> bool {
    if from == a.letters.len() {
        return true;
    }
    *work += 1;
    if *work > WORK {
        return false;
    }
    for (y, r) in rules.iter().enumerate() {
        let len = r.letters.len();
        let fits = from + len <= a.letters.len()
            && a.letters[from..from + len] == r.letters[..]
            && r.inner
                .iter()
                .zip(&a.inner[from..])
                .all(|(x, y)| (x - y).rem_euclid(m) == 0);
        if fits {
            cut.push(y as u8);
            if cut_into(rules, a, m, from + len, cut, work) {
                return true;
            }
            cut.pop();
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::grammar::Letter;

    fn grammar(axiom: &str, rules: &[&str], depth: u32) -> Grammar {
        let names = ['F', 'G', 'H'];
        let syms = |w: &str| -> Vec<Sym> {
            w.chars()
                .map(|c| match c {
                    '+' => Sym::Plus,
                    '-' => Sym::Minus,
                    c => Sym::Letter(names.iter().position(|&n| n == c).expect("letter") as u8),
                })
                .collect()
        };
        Grammar {
            letters: rules
                .iter()
                .zip(names)
                .map(|(r, name)| Letter {
                    name,
                    action: Action::Draw,
                    rule: Some(syms(r)),
                })
                .collect(),
            axiom: syms(axiom),
            depth,
        }
    }

    fn described(gs: &[Grammar]) -> Vec<String> {
        gs.iter().map(Grammar::describe).collect()
    }

    fn right_angles() -> Angles {
        Angles::new(90.0, Some(4), 10.0)
    }

    #[test]
    fn a_square_gives_its_root_at_twice_the_depth() {
        // `F -> HG; G -> H+G; H -> F-` applied twice.
        let square = grammar("F", &["F-H+G", "F-+H+G", "HG-"], 7);
        let out = described(&deeper(&square, &right_angles()));
        assert!(
            out.contains(&"axiom F; F -> HG; G -> H+G; H -> F-; derive 14".to_string()),
            "{out:?}"
        );
    }

    #[test]
    fn a_cube_gives_its_root_at_three_times_the_depth() {
        // `F -> H+H-G; G -> F; H -> G` applied three times, from an axiom
        // that is `F` two levels down.
        let cube = grammar("G+G-F", &["F+F-H+H-G", "G+G-F", "H+H-G"], 4);
        let out = described(&deeper(&cube, &right_angles()));
        assert!(
            out.contains(&"axiom F; F -> H+H-G; G -> F; H -> G; derive 14".to_string()),
            "{out:?}"
        );
    }

    #[test]
    fn a_curve_drawn_backwards() {
        let g = grammar("F+G", &["G-H++G-F", "F", "G++G--G"], 4);
        let sixty = Angles::new(60.0, Some(6), 10.0);
        let back = reversed(&g, &sixty).expect("edges");
        assert_eq!(
            back.describe(),
            "axiom G-F; F -> F+G--H+G; G -> F; H -> G++G--G; derive 4"
        );
        assert_eq!(reversed(&back, &sixty), Some(g));
    }

    #[test]
    fn a_grammar_with_no_root_has_none() {
        let koch = grammar("F", &["F+F-F-F+F"], 3);
        assert!(deeper(&koch, &right_angles()).is_empty());
        // A root with no successor of one letter is not offered.
        let snowflake = grammar("F", &["F-F++F-F"], 3);
        let sixty = Angles::new(60.0, Some(6), 10.0);
        assert!(deeper(&snowflake, &sixty).is_empty());
        // Branches are out of scope.
        let mut plant = grammar("F", &["F+F-F"], 3);
        plant.letters[0].rule = Some(vec![Sym::Letter(0), Sym::Push, Sym::Letter(0), Sym::Pop]);
        assert!(deeper(&plant, &right_angles()).is_empty());
    }
}
