//! Node rewriting with two letters that draw nothing, X and Y (Hilbert's
//! `X -> +YF-XFX-FY+`, `Y -> -XF+YFY+FX-`; Peano's; Moore's), for drawings
//! that are one path.
//!
//! The counts of steps follow f_c(j) = β_c·k^(j−1) + Σ_d a_cd·f_d(j−1)
//! (c, d ∈ {X, Y}, `F -> F^k`). For each solution whose f_X(n) is the
//! drawing's steps, the drawing is cut top-down into runs of k^(n−1) steps
//! and copies of X and Y one step down — the first copy of a letter says its
//! shape, later ones must have it — which gives X's successor as letters; a
//! copy of X cut one level lower must give the same letters, and a copy of Y
//! gives Y's. The copies are then followed down to a copy of X and one of Y
//! two steps down, whose pieces' turns give the successors' turns, less the
//! turns a copy one step down starts and ends with: those the drawing does
//! not show, so they are tried over the turn range and each candidate is
//! matched against the drawing before it is proposed.
//!
//! An axiom of several copies of X and runs of F (Moore's `LFL+F+LFL`) is
//! cut first, for each copy length the drawing draws again from its start
//! (the Z-function of its turns); f_X(n) is then that length. Axioms that
//! mix copies of X and Y are not searched yet.

use super::{Limits, Proposals, Sink, turn_range};
use crate::infer::lines::grammar::{Action, Grammar, Letter, Outcome, Sym, matches, turn_syms};
use crate::infer::lines::turtle::{Angles, Kind, Node, ROOT, Tree};

const X: usize = 0;
const Y: usize = 1;

/// Deepest derivation tried.
const MAX_DEPTH: u32 = 24;

/// Most cuts kept of one copy.
const MAX_CUTS: usize = 4;

/// Most choices a cut tries before it gives up.
const CUT_WORK: usize = 20_000;

/// Most grammars proposed for one count hypothesis.
const PER_HYPOTHESIS: usize = 16;

/// A piece of a copy: a run of F, or a copy of X or Y one step down.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    F,
    Copy(usize),
}

/// Counts of each successor (`beta` F's, `a[c][d]` copies of letter d in
/// c's successor), F's successor `F^k`, the depth, and the steps each
/// letter draws at every depth up to it.
struct Hypothesis {
    k: usize,
    beta: [usize; 2],
    a: [[usize; 2]; 2],
    depth: u32,
    steps: Vec<[usize; 2]>,
}

impl Hypothesis {
    /// Steps of a piece of a copy at depth `j`.
    fn len(&self, p: Part, j: u32) -> usize {
        match p {
            Part::F => self.k.saturating_pow(j - 1),
            Part::Copy(d) => self.steps[j as usize - 1][d],
        }
    }
}

/// Proposes grammars of two node letters for `tree`, each already matched
/// against it.
pub(super) fn node_pairs(
    tree: &Tree,
    angles: &Angles,
    limits: &Limits,
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let nodes = &tree.nodes;
    if !is_path(nodes) {
        return;
    }
    let shifts = shifts(angles);
    let table = growths(nodes.len(), limits);
    let single = hypotheses(nodes.len(), &table, limits);
    let axiom = [Part::Copy(X)];
    for h in single {
        if limits.late() {
            out.timed_out = true;
            return;
        }
        propose_matched(tree, &h, &axiom, angles, limits, &shifts, sink, out);
    }
    // An axiom of several copies of X and runs of F (`LFL+F+LFL`): cut
    // for each length of a run and of a copy that the drawing repeats from
    // its start, then the hypotheses of that many steps.
    let z = z_function(nodes);
    let runs = straight_runs(nodes);
    // Lengths of the drawing's start that it draws again further on.
    let mut repeats = vec![false; nodes.len() + 1];
    let mut best = 0;
    for len in (1..nodes.len()).rev() {
        best = best.max(z[len]);
        repeats[len] = best + 1 >= len;
    }
    let total = nodes.len();
    let mut lengths: Vec<usize> = (1..=3usize)
        .flat_map(|k| (1..=MAX_DEPTH).map(move |n| k.saturating_pow(n)))
        .filter(|&r| r < total)
        .collect();
    lengths.sort_unstable();
    lengths.dedup();
    let mut by_len = std::collections::HashMap::new();
    for r in lengths {
        for (len, _) in repeats
            .iter()
            .enumerate()
            .take(total)
            .skip(2)
            .filter(|r| *r.1)
        {
            let cuts = axiom_cuts(&z, &runs, r, len);
            if cuts.is_empty() {
                continue;
            }
            let hs = by_len
                .entry(len)
                .or_insert_with(|| hypotheses(len, &table, limits));
            for h in hs.iter() {
                if h.len(Part::F, h.depth + 1) != r {
                    continue;
                }
                for axiom in &cuts {
                    if limits.late() {
                        out.timed_out = true;
                        return;
                    }
                    propose_matched(tree, h, axiom, angles, limits, &shifts, sink, out);
                }
            }
        }
    }
}

/// Proposes the grammars of hypothesis `h` and `axiom` that draw `tree`
/// (at most `PER_HYPOTHESIS`).
#[allow(clippy::too_many_arguments)]
fn propose_matched(
    tree: &Tree,
    h: &Hypothesis,
    axiom: &[Part],
    angles: &Angles,
    limits: &Limits,
    shifts: &[[i32; 4]],
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let work = 64 * tree.nodes.len() as u64 + 1_000;
    let mut found = 0;
    grammars(&tree.nodes, h, axiom, angles, limits, shifts, &mut |g| {
        if matches(&g, tree, angles, work, limits.deadline) == Outcome::Same {
            sink(g, out);
            found += 1;
        }
        found >= PER_HYPOTHESIS
    });
}

/// One path of drawn steps, each from the one before.
fn is_path(nodes: &[Node]) -> bool {
    nodes.first().is_some_and(|n| n.parent == ROOT)
        && nodes
            .iter()
            .enumerate()
            .all(|(i, n)| n.kind == Kind::Draw && (i == 0 || n.parent as usize == i - 1))
}

/// For each step p of a path, how many turns from step p + 1 on are those
/// from step 1 on (a copy of the first L steps starts at p iff z[p] ≥
/// L − 1), by the Z-function of its turns.
fn z_function(nodes: &[Node]) -> Vec<usize> {
    let t: Vec<i32> = nodes.iter().skip(1).map(|n| n.turn).collect();
    let m = t.len();
    let mut z = vec![0usize; nodes.len()];
    let (mut l, mut r) = (0usize, 0usize);
    for i in 1..m {
        if i < r {
            z[i] = (r - i).min(z[i - l]);
        }
        while i + z[i] < m && t[z[i]] == t[i + z[i]] {
            z[i] += 1;
        }
        if i + z[i] > r {
            (l, r) = (i, i + z[i]);
        }
    }
    if m > 0 {
        z[0] = m;
    }
    z
}

/// For each step p of a path, how many steps after it go straight on.
fn straight_runs(nodes: &[Node]) -> Vec<usize> {
    let mut out = vec![0usize; nodes.len()];
    for p in (0..nodes.len().saturating_sub(1)).rev() {
        if nodes[p + 1].turn == 0 {
            out[p] = out[p + 1] + 1;
        }
    }
    out
}

/// The ways (at most `MAX_CUTS`) to cut a path into an axiom of copies of
/// X (`len` steps, turning as its first `len` steps do) and runs of F
/// (`run` straight steps): X first, at least two pieces, at most
/// `AXIOM_COPIES` copies and one run more than copies.
fn axiom_cuts(z: &[usize], runs: &[usize], run: usize, len: usize) -> Vec<Vec<Part>> {
    let end = z.len();
    let mut found = Vec::new();
    let mut stack = vec![(vec![Part::Copy(X)], len, 1usize, 0usize)];
    let mut work = 0;
    while let Some((pat, at, copies, fs)) = stack.pop() {
        work += 1;
        if work > AXIOM_WORK || found.len() >= MAX_CUTS {
            break;
        }
        if at == end {
            if pat.len() > 1 {
                found.push(pat);
            }
            continue;
        }
        if fs <= copies && at + run <= end && runs[at] + 1 >= run {
            let mut next = pat.clone();
            next.push(Part::F);
            stack.push((next, at + run, copies, fs + 1));
        }
        if copies < AXIOM_COPIES && at + len <= end && z[at] + 1 >= len {
            let mut next = pat;
            next.push(Part::Copy(X));
            stack.push((next, at + len, copies + 1, fs));
        }
    }
    found
}

/// Most choices an axiom's cut tries before it gives up.
const AXIOM_WORK: usize = 1_000;

/// The most copies in an axiom of several.
const AXIOM_COPIES: usize = 16;

/// The count hypotheses under which X draws `total` steps at a depth of at
/// least 3, both letters' successors with at least one F (at most
/// `MAX_F`), Y's copies in X's successor, and the drawing growing
/// exponentially (else smaller programs of other depths draw it as well).
///
/// The steps are linear in the F counts: f(n) = S(n)·β with
/// S(n) = A·S(n−1) + k^(n−1)·I, so for each k, A and n the F counts are
/// solved for rather than enumerated.
fn hypotheses(total: usize, table: &[Growth], limits: &Limits) -> Vec<Hypothesis> {
    let total = total as u64;
    let max_f = limits.max_f.min(MAX_F) as u64;
    let mut out = Vec::new();
    for g in table {
        let [u, v] = g.x;
        if u + v > total {
            continue;
        }
        for bx in 1..=max_f {
            let Some(rest) = total.checked_sub(u * bx) else {
                break;
            };
            if rest % v != 0 || !(1..=max_f).contains(&(rest / v)) {
                continue;
            }
            let beta = [bx as usize, (rest / v) as usize];
            out.push(hypothesis(g.k, beta, g.a, g.depth, total as usize + 1));
        }
    }
    out
}

/// How X's steps grow under F -> F^k and copies `a`: at `depth` X draws
/// x[0]·β_X + x[1]·β_Y steps.
struct Growth {
    k: usize,
    a: [[u64; 2]; 2],
    depth: u32,
    x: [u64; 2],
}

/// Every growth (depth at least 3) under which X may draw no more than
/// `total` steps, computed once for a drawing and each of its parts.
fn growths(total: usize, limits: &Limits) -> Vec<Growth> {
    let total = total as u64;
    let mut out = Vec::new();
    for k in 1..=3u64 {
        for a in matrices(limits.max_x as u64) {
            if k == 1 && !grows(a) {
                continue;
            }
            let mut s = [[1u64, 0], [0, 1]];
            let mut run = 1u64;
            for depth in 1..=MAX_DEPTH {
                if depth > 1 {
                    run *= k;
                    s = [
                        [
                            a[X][X] * s[X][X] + a[X][Y] * s[Y][X] + run,
                            a[X][X] * s[X][Y] + a[X][Y] * s[Y][Y],
                        ],
                        [
                            a[Y][X] * s[X][X] + a[Y][Y] * s[Y][X],
                            a[Y][X] * s[X][Y] + a[Y][Y] * s[Y][Y] + run,
                        ],
                    ];
                }
                if s[X][X] + s[X][Y] > total {
                    break;
                }
                if depth >= 3 {
                    out.push(Growth {
                        k: k as usize,
                        a,
                        depth,
                        x: s[X],
                    });
                }
            }
        }
    }
    out
}

/// The most F's in a successor of the two-letter search.
const MAX_F: usize = 12;

/// Copies of X and Y in each successor, X's holding a Y, at most `max_x`
/// copies a successor.
fn matrices(max_x: u64) -> Vec<[[u64; 2]; 2]> {
    let mut out = Vec::new();
    for axx in 0..=max_x {
        for axy in 1..=max_x - axx {
            for ayx in 0..=max_x {
                for ayy in 0..=max_x - ayx {
                    out.push([[axx, axy], [ayx, ayy]]);
                }
            }
        }
    }
    out
}

/// Whether copies multiply: the matrix's largest eigenvalue exceeds 1.
fn grows(a: [[u64; 2]; 2]) -> bool {
    let [[p, q], [r, t]] = a.map(|row| row.map(|v| v as f64));
    let tr = p + t;
    let disc = (tr * tr - 4.0 * (p * t - q * r)).max(0.0);
    (tr + disc.sqrt()) / 2.0 > 1.0 + 1e-9
}

/// The hypothesis with its steps at every depth (no more than `most`:
/// more than a drawing holds).
fn hypothesis(k: usize, beta: [usize; 2], a: [[u64; 2]; 2], depth: u32, most: usize) -> Hypothesis {
    let a = a.map(|row| row.map(|v| v as usize));
    let mut steps = vec![[0usize; 2]];
    let mut run = 1usize;
    let count = |b: usize, run: usize, row: [usize; 2], f: [usize; 2]| {
        b.saturating_mul(run)
            .saturating_add(row[X].saturating_mul(f[X]))
            .saturating_add(row[Y].saturating_mul(f[Y]))
            .min(most)
    };
    for _ in 1..=depth {
        let f = steps[steps.len() - 1];
        steps.push([count(beta[X], run, a[X], f), count(beta[Y], run, a[Y], f)]);
        run = run.saturating_mul(k).min(most);
    }
    Hypothesis {
        k,
        beta,
        a,
        depth,
        steps,
    }
}

/// The grammars of hypothesis `h` and `axiom` (its pieces at depth n + 1:
/// runs of k^n steps and copies at depth n) whose cuts the drawing has,
/// before matching; `take` says when it has had enough.
fn grammars(
    nodes: &[Node],
    h: &Hypothesis,
    axiom: &[Part],
    angles: &Angles,
    limits: &Limits,
    shifts: &[[i32; 4]],
    take: &mut dyn FnMut(Grammar) -> bool,
) {
    let n = h.depth;
    let top = [X, Y].map(|d| first_copy(axiom, d, 0, n + 1, h));
    let Some(x0) = top[X] else {
        return;
    };
    for px in cuts(nodes, x0, X, n, h) {
        // A copy of X one step down has X's letters too.
        if let Some(x1) = first_copy(&px, X, x0, n, h)
            && !has_cut(nodes, x1, &px, n - 1, h)
        {
            continue;
        }
        // Y's letters from a copy in the axiom, or one step down.
        let ys = match (top[Y], first_copy(&px, Y, x0, n, h)) {
            (Some(y0), _) => cuts(nodes, y0, Y, n, h),
            (None, Some(y1)) => cuts(nodes, y1, Y, n - 1, h),
            (None, None) => continue,
        };
        for py in ys {
            if limits.late() {
                return;
            }
            let pats = [px.clone(), py];
            let [Some(x2), Some(y2)] = copies_at(&pats, h, top, 2) else {
                continue;
            };
            let cut = Cut {
                pats,
                axiom,
                top,
                twos: [x2, y2],
            };
            if with_turns(nodes, &cut, h, angles, shifts, take) {
                return;
            }
        }
    }
}

/// The drawing cut: each letter's pieces, the axiom's, where the axiom's
/// first copy of each letter starts, and where a copy of each starts two
/// steps down.
struct Cut<'a> {
    pats: [Vec<Part>; 2],
    axiom: &'a [Part],
    top: [Option<usize>; 2],
    twos: [usize; 2],
}

/// Where the first copy of letter `d` starts in a copy of `pat` at `start`
/// at depth `j`.
fn first_copy(pat: &[Part], d: usize, start: usize, j: u32, h: &Hypothesis) -> Option<usize> {
    let mut at = start;
    for &p in pat {
        if p == Part::Copy(d) {
            return Some(at);
        }
        at += h.len(p, j);
    }
    None
}

/// Where a copy of X and one of Y `level` steps down start (when there
/// is one), following the letters of `pats` from the axiom's copies at
/// depth n (`top`).
fn copies_at(
    pats: &[Vec<Part>; 2],
    h: &Hypothesis,
    top: [Option<usize>; 2],
    level: u32,
) -> [Option<usize>; 2] {
    if level > h.depth {
        return [None, None];
    }
    let mut at = top;
    for j in (level + 1..=h.depth).rev() {
        let mut next = [None, None];
        for c in [X, Y] {
            let Some(s) = at[c] else { continue };
            for d in [X, Y] {
                if next[d].is_none() {
                    next[d] = first_copy(&pats[c], d, s, j, h);
                }
            }
        }
        at = next;
    }
    at
}

/// A cut under way: its pieces so far, where the next starts, the pieces
/// of each kind (F, X, Y) so far, and where the first copy of X and of Y
/// starts.
struct State {
    pat: Vec<Part>,
    at: usize,
    used: [usize; 3],
    firsts: [Option<usize>; 2],
}

/// The ways (at most `MAX_CUTS`) to cut the copy of letter `c` at depth `j`
/// that starts at `start` into the pieces its counts say: runs of F,
/// straight, and copies of X and Y, each of one shape.
fn cuts(nodes: &[Node], start: usize, c: usize, j: u32, h: &Hypothesis) -> Vec<Vec<Part>> {
    let want = [h.beta[c], h.a[c][X], h.a[c][Y]];
    let end = start + h.steps[j as usize][c];
    if end > nodes.len() {
        return Vec::new();
    }
    let lens = [
        h.len(Part::F, j),
        h.len(Part::Copy(X), j),
        h.len(Part::Copy(Y), j),
    ];
    let parts = [Part::F, Part::Copy(X), Part::Copy(Y)];
    let mut found = Vec::new();
    let mut stack = vec![State {
        pat: Vec::new(),
        at: start,
        used: [0; 3],
        firsts: [None; 2],
    }];
    let mut work = 0;
    while let Some(State {
        pat,
        at,
        used,
        firsts,
    }) = stack.pop()
    {
        work += 1;
        if work > CUT_WORK || found.len() >= MAX_CUTS {
            break;
        }
        if at == end {
            if used == want {
                found.push(pat);
            }
            continue;
        }
        // Pushed in reverse: copies of X are tried first, runs last.
        for kind in (0..3).rev() {
            let len = lens[kind];
            if used[kind] >= want[kind] || at + len > end || len == 0 {
                continue;
            }
            let fits = match parts[kind] {
                Part::F => straight(nodes, at, len),
                Part::Copy(d) => firsts[d].is_none_or(|f| same_turns(nodes, f, at, len)),
            };
            if !fits {
                continue;
            }
            let mut next = pat.clone();
            next.push(parts[kind]);
            let mut used = used;
            used[kind] += 1;
            let mut firsts = firsts;
            if let Part::Copy(d) = parts[kind] {
                firsts[d].get_or_insert(at);
            }
            stack.push(State {
                pat: next,
                at: at + len,
                used,
                firsts,
            });
        }
    }
    found
}

/// Whether the steps from `start` cut into the pieces `pat` at depth `j`:
/// runs straight, the copies of each letter turning alike.
fn has_cut(nodes: &[Node], start: usize, pat: &[Part], j: u32, h: &Hypothesis) -> bool {
    let mut firsts = [None; 2];
    let mut at = start;
    for &p in pat {
        let len = h.len(p, j);
        if len == 0 || at + len > nodes.len() {
            return false;
        }
        let fits = match p {
            Part::F => straight(nodes, at, len),
            Part::Copy(d) => same_turns(nodes, *firsts[d].get_or_insert(at), at, len),
        };
        if !fits {
            return false;
        }
        at += len;
    }
    true
}

/// Whether steps `at..at + len` of a path go straight on.
fn straight(nodes: &[Node], at: usize, len: usize) -> bool {
    nodes[at + 1..at + len].iter().all(|n| n.turn == 0)
}

/// Whether the `len` steps of a path from `a` and from `b` turn alike
/// (their first steps aside).
fn same_turns(nodes: &[Node], a: usize, b: usize, len: usize) -> bool {
    a == b
        || nodes[a + 1..a + len]
            .iter()
            .zip(&nodes[b + 1..b + len])
            .all(|(p, q)| p.turn == q.turn)
}

/// Grammars of the letters `pats` with the turns of the copies of X and Y
/// two steps down at `twos`, over the turns a copy one step down starts
/// and ends with (fewest turns first), each given to `take` until it has
/// had enough (then `true`).
fn with_turns(
    nodes: &[Node],
    cut: &Cut<'_>,
    h: &Hypothesis,
    angles: &Angles,
    shifts: &[[i32; 4]],
    take: &mut dyn FnMut(Grammar) -> bool,
) -> bool {
    let (pats, twos) = (&cut.pats, cut.twos);
    // The turn before each piece of the copies two and three steps down,
    // and of the axiom.
    let turns = |start: Option<usize>, pat: &[Part], j: u32| {
        start.map_or(Some(Vec::new()), |s| piece_turns(nodes, s, pat, j, h))
    };
    let threes = copies_at(pats, h, cut.top, 3);
    let (Some(sx), Some(sy), Some(tx), Some(ty), Some(seen_axiom)) = (
        turns(Some(twos[X]), &pats[X], 2),
        turns(Some(twos[Y]), &pats[Y], 2),
        turns(threes[X], &pats[X], 3),
        turns(threes[Y], &pats[Y], 3),
        turns(Some(0), cut.axiom, h.depth + 1),
    ) else {
        return false;
    };
    let (seen, seen3) = ([sx, sy], [tx, ty]);
    let Some(three) = ThreeDown::new(pats, &seen, &seen3) else {
        return false;
    };
    for &[lx, ex, ly, ey] in shifts {
        let (lead, end) = ([lx, ly], [ex, ey]);
        let succ = |c: usize| successor(&pats[c], &seen[c], lead, end, lead[c], end[c], angles);
        if !three.holds([lx, ex, ly, ey], angles) {
            continue;
        }
        let (Some(sx), Some(sy)) = (succ(X), succ(Y)) else {
            continue;
        };
        let g = Grammar {
            letters: vec![
                Letter {
                    name: 'F',
                    action: Action::Draw,
                    rule: (h.k > 1).then(|| vec![Sym::Letter(0); h.k]),
                },
                Letter {
                    name: 'X',
                    action: Action::Nothing,
                    rule: Some(sx),
                },
                Letter {
                    name: 'Y',
                    action: Action::Nothing,
                    rule: Some(sy),
                },
            ],
            axiom: axiom_syms(cut, &seen, &seen_axiom, lead, end, h.depth, angles),
            depth: h.depth,
        };
        if take(g) {
            return true;
        }
    }
    false
}

/// The turn before each piece of a copy of `pat` at depth `j` that starts
/// at `start` (its first from the step before the copy).
fn piece_turns(
    nodes: &[Node],
    start: usize,
    pat: &[Part],
    j: u32,
    h: &Hypothesis,
) -> Option<Vec<i32>> {
    let mut at = start;
    let mut out = Vec::with_capacity(pat.len());
    for &p in pat {
        out.push(nodes.get(at)?.turn);
        at += h.len(p, j);
    }
    Some(out)
}

/// The symbol of a piece: F, or the letter X or Y.
fn sym(p: Part) -> Sym {
    match p {
        Part::F => Sym::Letter(0),
        Part::Copy(d) => Sym::Letter(1 + d as u8),
    }
}

/// A successor of letters `pat` whose pieces turn by `seen` two steps
/// down, where copies of X and Y start turned by `lead` and are left
/// turned by `end`; its own turns before its first F and after its last
/// are then `own_lead` and `own_end`.
fn successor(
    pat: &[Part],
    seen: &[i32],
    lead: [i32; 2],
    end: [i32; 2],
    own_lead: i32,
    own_end: i32,
    angles: &Angles,
) -> Option<Vec<Sym>> {
    let mut body = Vec::new();
    for (i, &p) in pat.iter().enumerate() {
        if i > 0 {
            let before = match p {
                Part::F => 0,
                Part::Copy(d) => lead[d],
            };
            let after = match pat[i - 1] {
                Part::F => 0,
                Part::Copy(d) => end[d],
            };
            body.extend(turn_syms(seen[i] - before - after, angles));
        }
        body.push(sym(p));
    }
    // One step down, copies draw nothing: the body's own outer turns.
    let first = body.iter().position(|s| *s == Sym::Letter(0))?;
    let last = body.iter().rposition(|s| *s == Sym::Letter(0))?;
    let count = |s: &[Sym]| {
        s.iter()
            .map(|s| match s {
                Sym::Plus => 1,
                Sym::Minus => -1,
                _ => 0,
            })
            .sum::<i32>()
    };
    let (before, after) = (count(&body[..first]), count(&body[last..]));
    let mut out = turn_syms(own_lead - before, angles);
    out.extend(body);
    out.extend(turn_syms(own_end - after, angles));
    Some(out)
}

/// The turn between pieces `i - 1` and `i` of letter `c`'s successor, from
/// the turn seen two steps down less the turns of copies one step down.
fn between(
    pats: &[Vec<Part>; 2],
    seen: &[Vec<i32>; 2],
    c: usize,
    i: usize,
    by: [[i32; 2]; 2],
) -> i32 {
    let [lead, end] = by;
    let before = match pats[c][i] {
        Part::F => 0,
        Part::Copy(d) => lead[d],
    };
    let after = match pats[c][i - 1] {
        Part::F => 0,
        Part::Copy(d) => end[d],
    };
    seen[c][i] - before - after
}

/// The turns a copy of X and of Y starts and ends with `level` steps down,
/// for successors written from `seen` where a copy one step down starts
/// turned by `lead` and is left turned by `end`: its successor's turns
/// before its first piece (its own lead less the turns between pieces
/// before its first F), and that piece's own if it is a copy; likewise at
/// its end.
fn ends_at(
    pats: &[Vec<Part>; 2],
    seen: &[Vec<i32>; 2],
    lead: [i32; 2],
    end: [i32; 2],
    level: u32,
) -> Option<([i32; 2], [i32; 2])> {
    let by = [lead, end];
    let (mut prefix, mut suffix) = ([0; 2], [0; 2]);
    for c in [X, Y] {
        let pat = &pats[c];
        let first = pat.iter().position(|p| *p == Part::F)?;
        let last = pat.iter().rposition(|p| *p == Part::F)?;
        let inner_before: i32 = (1..=first).map(|i| between(pats, seen, c, i, by)).sum();
        let inner_after: i32 = (last + 1..pat.len())
            .map(|i| between(pats, seen, c, i, by))
            .sum();
        prefix[c] = lead[c] - inner_before;
        suffix[c] = end[c] - inner_after;
    }
    let (mut l, mut e) = (lead, end);
    for _ in 2..=level {
        let (l0, e0) = (l, e);
        for c in [X, Y] {
            l[c] = prefix[c] + of(pats[c][0], l0);
            e[c] = suffix[c] + of(pats[c][pats[c].len() - 1], e0);
        }
    }
    Some((l, e))
}

/// A piece's value of `v`: 0 for a run of F.
fn of(p: Part, v: [i32; 2]) -> i32 {
    match p {
        Part::F => 0,
        Part::Copy(d) => v[d],
    }
}

/// Whether the successors written from `seen` turn as the copies three
/// steps down are seen to (`seen3`, empty for a letter with no copy there),
/// where a copy one step down starts turned by `lead` and is left turned
/// by `end` — in counts of turns, before any successor is written.
///
/// A piece of a copy three steps down turns as two steps down, plus how
/// much more its copy starts turned there (`lead2 − lead`) and its
/// predecessor's copy ends turned (`end2 − end`); those differences are
/// sums of turns, affine in the four shifts, so they are found once for
/// the cut and each shift is checked in a few additions.
struct ThreeDown {
    /// The differences (lead X, lead Y, end X, end Y) at no shift, and
    /// what each shift (lead X, end X, lead Y, end Y) adds.
    base: [i32; 4],
    by: [[i32; 4]; 4],
    /// Each piece boundary three steps down: the letter of the piece (if
    /// a copy), of the one before it, and the turn it must add.
    bounds: Vec<(Option<usize>, Option<usize>, i32)>,
}

impl ThreeDown {
    fn new(pats: &[Vec<Part>; 2], seen: &[Vec<i32>; 2], seen3: &[Vec<i32>; 2]) -> Option<Self> {
        let diff = |shift: [i32; 4]| {
            let (lead, end) = ([shift[0], shift[2]], [shift[1], shift[3]]);
            let (lead2, end2) = ends_at(pats, seen, lead, end, 2)?;
            Some([
                lead2[X] - lead[X],
                lead2[Y] - lead[Y],
                end2[X] - end[X],
                end2[Y] - end[Y],
            ])
        };
        let base = diff([0; 4])?;
        let mut by = [[0; 4]; 4];
        for (k, col) in by.iter_mut().enumerate() {
            let mut unit = [0; 4];
            unit[k] = 1;
            let d = diff(unit)?;
            *col = [0, 1, 2, 3].map(|i| d[i] - base[i]);
        }
        let letter = |p: Part| match p {
            Part::F => None,
            Part::Copy(d) => Some(d),
        };
        let mut bounds = Vec::new();
        for c in [X, Y] {
            for i in 1..seen3[c].len() {
                bounds.push((
                    letter(pats[c][i]),
                    letter(pats[c][i - 1]),
                    seen3[c][i] - seen[c][i],
                ));
            }
        }
        Some(ThreeDown { base, by, bounds })
    }

    /// Whether the shift (lead X, end X, lead Y, end Y) turns as seen
    /// (plain loops: this runs for every shift of every cut).
    fn holds(&self, shift: [i32; 4], angles: &Angles) -> bool {
        let mut d = self.base;
        for (&v, col) in shift.iter().zip(&self.by) {
            if v != 0 {
                for (di, c) in d.iter_mut().zip(col) {
                    *di += v * c;
                }
            }
        }
        for &(p, q, want) in &self.bounds {
            let mut t = -want;
            if let Some(l) = p {
                t += d[l];
            }
            if let Some(l) = q {
                t += d[2 + l];
            }
            let off = match angles.period {
                Some(m) if m > 0 => t % m != 0,
                _ => t != 0,
            };
            if off {
                return false;
            }
        }
        true
    }
}

/// The axiom of `cut`: its pieces, the turns between them as drawn less
/// the turns a copy at depth n starts and ends with.
fn axiom_syms(
    cut: &Cut<'_>,
    seen: &[Vec<i32>; 2],
    seen_axiom: &[i32],
    lead: [i32; 2],
    end: [i32; 2],
    depth: u32,
    angles: &Angles,
) -> Vec<Sym> {
    if cut.axiom == [Part::Copy(X)] {
        return vec![Sym::Letter(1)];
    }
    let Some((lead_n, end_n)) = ends_at(&cut.pats, seen, lead, end, depth) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (i, &p) in cut.axiom.iter().enumerate() {
        if i > 0 {
            let t = seen_axiom[i] - of(p, lead_n) - of(cut.axiom[i - 1], end_n);
            out.extend(turn_syms(t, angles));
        }
        out.push(sym(p));
    }
    out
}

/// The turns a copy of X and of Y one step down may start and end with,
/// fewest turns first.
fn shifts(angles: &Angles) -> Vec<[i32; 4]> {
    let range = turn_range(angles);
    let mut out = Vec::new();
    for &lx in &range {
        for &ex in &range {
            for &ly in &range {
                for &ey in &range {
                    out.push([lx, ex, ly, ey]);
                }
            }
        }
    }
    out.sort_by_key(|s| (s.iter().map(|v| v.abs()).sum::<i32>(), *s));
    out
}
