//! Rule generation: placed instances become sequence, branching and pair rules,
//! level by level, until one instance is left (the axiom).
//!
//! Owns: the paper's loop (§5). Each round compares every live instance with
//! its nearest neighbours (transforms in one space per pair of kinds), clusters
//! each space, and proposes candidates: *sequences* (chains of one kind linked
//! by the same transform, rule r1/r2), *linear sequences* (chains whose
//! transform changes by a constant amount per step, t(m) = t0 + tΔ·m: `linear`),
//! *branchings* (complete binary trees whose two child transforms come from two
//! clusters, r3/r4) and, when nothing repeats, *pairs* (r1 with m = 1). The
//! candidate with the largest importance w = w_n·n + w_h·h + w_φ·φ + w_l·l is
//! made a rule; its instances are replaced by one new instance each, in the
//! frame fitted to all its members, and the round repeats. A chain is cut where
//! redrawing it with the rule's averaged transform would leave the tolerance,
//! so what is drawn back stays on the input. With `--symmetrize`
//! (`Tolerance::regular`) chains also grow at both ends, and a chosen rule is
//! refitted and made round (`regular`, on the least squares of `fit`).
//! Branchings are found in `branch`, linear sequences in `linear`. Must not
//! print or build syntax.

mod branch;
mod fit;
mod linear;
mod regular;

use super::shape::{Frame, wrap};
use super::space::{CellMap, Point, Tr, cluster};
use super::{Budget, TooMuchWork};
use crate::geometry::index::PointGrid;
use branch::{Children, Outs, branching};
use glam::DVec2;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

/// A symbol of the inferred grammar: an element kind, or a rule with its count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    Element(usize),
    Rule(usize, u32),
}

/// What a rule draws.
#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    /// `P(m) : m > 0 -> [a] T(t(m)) P(m - 1); P(m) : m == 0 -> [tip]` with
    /// t(m) = t + delta·m (delta only for linear sequences); `a` is drawn
    /// from the turtle moved by `place` (when its frame's origin is not where
    /// the turtle turns); `tip` is `a` unless the sequence ends in something
    /// else (the paper's Fig. 5 ends its leaves with a bud).
    Seq {
        a: Sym,
        t: Tr,
        delta: Option<Tr>,
        place: Option<Tr>,
        tip: Option<Sym>,
    },
    /// `R(m) : m > 0 -> [a] [T R(m - 1)] [U R(m - 1)]…; R(m) : m == 0 ->
    /// [tip]`, one bracket per transform of `ts` (two or three); `tip` is
    /// `a` unless the tips are something else.
    Branch {
        a: Sym,
        ts: Vec<Tr>,
        tip: Option<Sym>,
        /// The tip's frame relative to where a child would be, when not
        /// there (`m == 0 -> [T tip]`).
        tip_at: Option<Frame>,
    },
    /// `Q -> [a] T [b]`; `swap`: the drawing paints `b` first (a flag's
    /// field before its stars), so the program draws it first.
    Pair { a: Sym, t: Tr, b: Sym, swap: bool },
}

#[derive(Clone, Debug)]
pub struct Rule {
    pub body: Body,
    /// The counts it is used with.
    pub counts: BTreeSet<u32>,
}

impl Rule {
    /// Whether it repeats something a count of times: a sequence longer
    /// than a pair, or a branching.
    pub fn repeats(&self) -> bool {
        match self.body {
            Body::Seq { .. } => !self.counts.iter().all(|&m| m == 1),
            Body::Branch { .. } => true,
            Body::Pair { .. } => false,
        }
    }
}

/// The weights of the cluster importance w = w_n·n + w_h·h + w_φ·φ + w_l·l.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    pub n: f64,
    pub h: f64,
    pub phi: f64,
    pub l: f64,
}

impl Default for Weights {
    fn default() -> Weights {
        Weights {
            n: 1.0,
            h: 1.0,
            phi: 0.5,
            l: 1.0,
        }
    }
}

/// How different two transforms may be and still be one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Angles, radians.
    pub angle: f64,
    /// Distances, relative (0.01 is 1 %).
    pub distance: f64,
    /// Scales, relative.
    pub scale: f64,
    /// Whether a chosen rule is made regular (`--symmetrize`): refitted to
    /// all its instances and its numbers snapped to round values (`regular`).
    pub regular: bool,
}

impl Tolerance {
    pub const EXACT: Tolerance = Tolerance {
        angle: 0.5 * std::f64::consts::PI / 180.0,
        distance: 0.005,
        scale: 0.005,
        regular: false,
    };
    pub const RELAXED: Tolerance = Tolerance {
        angle: 10.0 * std::f64::consts::PI / 180.0,
        distance: 0.15,
        scale: 0.03,
        regular: true,
    };
}

/// A placed thing: an element or an instance of a rule.
#[derive(Clone, Debug)]
pub struct Inst {
    pub sym: Sym,
    pub frame: Frame,
    pub min: DVec2,
    pub max: DVec2,
    alive: bool,
    /// Standard error of the frame's rotation where a fit placed it
    /// (radians; 0 for an element of the drawing), and of a coordinate of
    /// its position.
    rot_se: f64,
    pos_se: f64,
    /// The mean position of the elements it draws, and their number.
    mass: DVec2,
    count: f64,
    /// The variance of its elements' positions about the fits that placed
    /// them (per coordinate; 0 for an element of the drawing).
    noise: f64,
    /// Per element kind it draws: the sum of its elements' rotations less
    /// those they are drawn with, and their number.
    tilt: Vec<(usize, f64, f64)>,
    /// The place in the drawing of the first element it draws: structures
    /// read in the drawing's order where the geometry leaves a choice.
    order: usize,
    /// An element's rotational symmetry (1 for none, k for k-fold, 0 for
    /// round) and its centroid: its frame could as well be turned about
    /// the centroid by a k-th of a turn.
    turns: usize,
    centroid: DVec2,
}

impl Inst {
    pub fn new(sym: Sym, frame: Frame, min: DVec2, max: DVec2) -> Inst {
        Inst {
            sym,
            frame,
            min,
            max,
            alive: true,
            rot_se: 0.0,
            pos_se: 0.0,
            mass: frame.pos,
            count: 1.0,
            noise: 0.0,
            tilt: match sym {
                Sym::Element(k) => vec![(k, 0.0, 1.0)],
                Sym::Rule(..) => Vec::new(),
            },
            order: usize::MAX,
            turns: 1,
            centroid: frame.pos,
        }
    }

    /// The element is symmetric: `turns`-fold (0: round) about `centroid`.
    pub fn symmetric(mut self, turns: usize, centroid: DVec2) -> Inst {
        self.turns = turns;
        self.centroid = centroid;
        self
    }

    /// The frames it could as well have: turned about its centroid by its
    /// symmetry (for a round one, the one turned to `rot`).
    fn variants(&self, rot: f64) -> Vec<Frame> {
        let f = self.frame;
        let turn = |a: f64| Frame {
            pos: self.centroid + crate::infer::elements::shape::rotate(f.pos - self.centroid, a),
            rot: wrap(f.rot + a),
            scale: f.scale,
        };
        match self.turns {
            0 => vec![turn(wrap(rot - f.rot))],
            k => (0..k)
                .map(|j| turn(std::f64::consts::TAU * j as f64 / k as f64))
                .collect(),
        }
    }

    fn centre(&self) -> DVec2 {
        (self.min + self.max) * 0.5
    }

    fn size(&self) -> f64 {
        (self.max - self.min).length().max(1e-12)
    }
}

/// The inferred grammar.
#[derive(Clone, Debug)]
pub struct Grammar {
    pub rules: Vec<Rule>,
    /// The last instance: where it is and what it is.
    pub axiom: Option<(Frame, Sym)>,
    /// Rounds of the loop.
    pub rounds: usize,
    /// Clusters met, over all rounds.
    pub clusters: usize,
    /// With `--symmetrize`, per element kind: the mean rotation of its
    /// elements relative to how the grammar draws them (radians), so that
    /// the kind's outline is drawn turned by it: the representative is one
    /// noisy sample, the mean of all is not.
    pub tilt: Vec<(usize, f64)>,
}

struct Edge {
    from: usize,
    to: usize,
    t: Tr,
    /// Gap between the two boxes, relative to the drawing's diagonal.
    gap: f64,
}

#[derive(Debug)]
enum Plan {
    Seq {
        chains: Vec<Vec<usize>>,
        t: Tr,
        delta: Option<Tr>,
        place: Option<Tr>,
        /// Where a fit placed the chains, when one did.
        fitted: Option<regular::Regular>,
    },
    Branch {
        trees: Vec<(usize, u32)>,
        /// Per transform, each node's child by it.
        child: Vec<HashMap<usize, usize>>,
        ts: Vec<Tr>,
        /// Where tips sit relative to where a child would be (when not
        /// there), and each tip's frame as a child's.
        tip_at: Option<(Frame, Vec<(usize, Frame)>)>,
    },
    Pair {
        pairs: Vec<(usize, usize)>,
        t: Tr,
    },
}

struct Candidate {
    plan: Plan,
    /// Pairs of instances it codes.
    pairs: usize,
    /// Mean number of instances per chain (or per root-to-leaf path).
    length: f64,
    /// Mean proximity, 1 − gap.
    h: f64,
    /// Similarity of the two kinds.
    phi: f64,
    /// A constant sequence refitted as a linear change: chosen only in the
    /// sequence's place (`hidden_change`).
    hidden: bool,
}

/// Edges by their two ends.
type Index = CellMap<(usize, usize), usize>;

/// The largest change of a turn per step of a linear sequence, radians.
const LINEAR_STEP_MAX: f64 = 30.0 * std::f64::consts::PI / 180.0;

/// Constant sequences of a kind (the most pairs first) refitted as linear
/// changes per round, with `--symmetrize`.
const REFITS: usize = 3;

/// Neighbours compared per instance.
const NEIGHBOURS: usize = 8;

/// The work limit of the loop, in transform-space points clustered over all
/// rounds (each round clusters about 16 points per live instance, and linear
/// sequences up to 16 times more for the steps between them), plus one per
/// live instance and round. A drawing of a thousand elements needs well
/// under a million; a chain of 30,000 strokes about four million (some
/// five seconds).
pub const MAX_WORK: u64 = 4_000_000;

/// Runs the loop over `insts`; `progress` is told how many are left. Stops
/// with `TooMuchWork` rather than run for minutes.
pub fn infer(
    mut insts: Vec<Inst>,
    weights: Weights,
    tol: Tolerance,
    progress: &mut dyn FnMut(usize),
) -> Result<Grammar, TooMuchWork> {
    let mut budget = Budget::new("transform-space points clustered", MAX_WORK);
    let (lo, hi) = insts.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), i| (lo.min(i.min), hi.max(i.max)),
    );
    let diagonal = (hi - lo).length().max(1e-12);
    let elements = insts.len() as u64;
    for (i, inst) in insts.iter_mut().enumerate() {
        inst.order = inst.order.min(i);
    }
    let mut g = Grammar {
        rules: Vec::new(),
        axiom: None,
        rounds: 0,
        clusters: 0,
        tilt: Vec::new(),
    };
    loop {
        let live: Vec<usize> = (0..insts.len()).filter(|&i| insts[i].alive).collect();
        progress(live.len());
        if live.len() <= 1 {
            g.axiom = live.first().map(|&i| {
                let inst = &insts[i];
                if !tol.regular {
                    return (inst.frame, inst.sym);
                }
                let pos_se = (inst.noise / inst.count).sqrt();
                let straight = match (inst.sym, &g.rules) {
                    (Sym::Rule(r, _), rules) => match rules[r].body {
                        Body::Seq { t, delta: None, .. }
                            if t.d > 0.0 && t.alpha + t.beta == 0.0 =>
                        {
                            Some(t.alpha)
                        }
                        _ => None,
                    },
                    _ => None,
                };
                let frame =
                    regular::axiom(inst.frame, straight, inst.rot_se, inst.mass, pos_se, tol);
                let turn = wrap(frame.rot - inst.frame.rot);
                g.tilt = inst
                    .tilt
                    .iter()
                    .map(|&(k, sum, n)| (k, wrap(sum / n.max(1.0) - turn)))
                    .filter(|t| t.1 != 0.0)
                    .collect();
                (frame, inst.sym)
            });
            debug_assert_eq!(
                g.axiom.map_or(0, |(_, s)| g.covered(s)),
                elements,
                "every element is drawn exactly once"
            );
            return Ok(g);
        }
        g.rounds += 1;
        budget.spend(live.len())?;
        let edges = edges(&insts, &live, diagonal);
        let (mut candidates, clusters) = candidates(&insts, &edges, tol, &mut budget)?;
        g.clusters += clusters;
        let best = choose(&insts, &mut candidates, weights, tol);
        match best {
            Some(c) if c.pairs >= 2 => apply(&mut g, &mut insts, c.plan, tol),
            _ => pair_up(&mut g, &mut insts, &edges, tol),
        }
    }
}

/// Directed edges between each live instance and its nearest neighbours,
/// by their two ends (the lower live index first), each pair both ways.
fn edges(insts: &[Inst], live: &[usize], diagonal: f64) -> Vec<Edge> {
    let centres: Vec<DVec2> = live.iter().map(|&i| insts[i].centre()).collect();
    let grid = PointGrid::new(&centres);
    let mut pairs: Vec<(usize, usize)> = centres
        .par_iter()
        .enumerate()
        .flat_map_iter(|(a, c)| {
            grid.nearest(*c, NEIGHBOURS + 1)
                .into_iter()
                .filter(move |&b| a != b)
                .map(move |b| (a.min(b), a.max(b)))
        })
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
        .par_iter()
        .flat_map_iter(|&(a, b)| {
            let (i, j) = (live[a], live[b]);
            let gap = {
                let (p, q) = (&insts[i], &insts[j]);
                let dx = (q.min.x - p.max.x).max(p.min.x - q.max.x).max(0.0);
                let dy = (q.min.y - p.max.y).max(p.min.y - q.max.y).max(0.0);
                (dx * dx + dy * dy).sqrt() / diagonal
            };
            [(i, j), (j, i)].map(|(from, to)| {
                let size = insts[from].size() / insts[from].frame.scale;
                Edge {
                    from,
                    to,
                    t: Tr::between(&insts[from].frame, &insts[to].frame, size),
                    gap,
                }
            })
        })
        .collect()
}

fn point(t: &Tr, tol: Tolerance) -> Point {
    [
        t.alpha / tol.angle,
        t.d.max(1e-12).ln() / tol.distance,
        t.s.ln() / tol.scale,
        t.beta / tol.angle,
    ]
}

/// The mean of transforms (angles averaged around the first).
fn mean(ts: &[Tr]) -> Tr {
    let n = ts.len().max(1) as f64;
    let first = ts.first().copied().unwrap_or(Tr::IDENTITY);
    let mut m = Tr {
        alpha: 0.0,
        d: 0.0,
        s: 0.0,
        beta: 0.0,
    };
    for t in ts {
        m.alpha += wrap(t.alpha - first.alpha);
        m.d += t.d;
        m.s += t.s;
        m.beta += wrap(t.beta - first.beta);
    }
    Tr {
        alpha: wrap(first.alpha + m.alpha / n),
        d: m.d / n,
        s: m.s / n,
        beta: wrap(first.beta + m.beta / n),
    }
}

/// The mean of `ts` with each number made as round as the transforms
/// support: the roundest value within three standard errors of the mean (at
/// most the tolerance). A drawing written with rounded coordinates gives
/// back `f(28)`, not `f(27.998)`.
fn supported_mean(ts: &[Tr], tol: Tolerance) -> Tr {
    let m = mean(ts);
    let n = ts.len() as f64;
    if ts.len() < 2 {
        return m;
    }
    let se = |dev: &dyn Fn(&Tr) -> f64| {
        (ts.iter().map(|t| dev(t).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt() * 3.0
    };
    let a = se(&|t| wrap(t.alpha - m.alpha)).min(tol.angle);
    let d = se(&|t| t.d - m.d).min(tol.distance * m.d.abs());
    let sc = se(&|t| t.s - m.s).min(tol.scale * m.s.abs());
    let b = se(&|t| wrap(t.beta - m.beta)).min(tol.angle);
    Tr {
        alpha: fit::nice_angle(m.alpha, a),
        d: fit::nice(m.d, d),
        s: fit::nice(m.s, sc),
        beta: fit::nice_angle(m.beta, b),
    }
}

/// Whether `f` is where `want` is, within the tolerance (relative to `step`,
/// the distance moved to get there, and the frame's scale).
fn close(f: &Frame, want: &Frame, step: f64, size: f64, tol: Tolerance) -> bool {
    f.pos.distance(want.pos) <= tol.distance * step.max(size * 0.05) * 2.0 + size * 1e-6
        && wrap(f.rot - want.rot).abs() <= tol.angle * 2.0
        && (f.scale / want.scale).ln().abs() <= tol.scale * 2.0
}

/// All candidates of a round, and the number of clusters.
fn candidates(
    insts: &[Inst],
    edges: &[Edge],
    tol: Tolerance,
    budget: &mut Budget,
) -> Result<(Vec<Candidate>, usize), TooMuchWork> {
    let mut spaces: BTreeMap<(Sym, Sym), Vec<usize>> = BTreeMap::new();
    for (k, e) in edges.iter().enumerate() {
        spaces
            .entry((insts[e.from].sym, insts[e.to].sym))
            .or_default()
            .push(k);
    }
    let turn = std::f64::consts::TAU / tol.angle;
    let index: Index = edges
        .iter()
        .enumerate()
        .map(|(k, e)| ((e.from, e.to), k))
        .collect();
    let mut out = Vec::new();
    let mut count = 0;
    let mut outs = None;
    let mut spots = None;
    for ((a, b), ks) in &spaces {
        let points: Vec<Point> = ks.iter().map(|&k| point(&edges[k].t, tol)).collect();
        budget.spend(points.len())?;
        let (label, centres) = cluster(&points, turn);
        count += centres.len();
        let mut groups: Vec<Vec<usize>> = vec![Vec::new(); centres.len()];
        for (i, &k) in ks.iter().enumerate() {
            groups[label[i]].push(k);
        }
        let phi = if a == b { 1.0 } else { 0.5 };
        let near = (tol.regular && a == b).then(|| Near::new(insts, *a));
        let found: Vec<Option<Candidate>> = groups
            .par_iter()
            .map(|group| sequence(insts, edges, &index, group, a == b, tol, phi, near.as_ref()))
            .collect();
        if tol.regular && a == b {
            // The longest constant sequences, fitted as linear changes too.
            let mut seqs: Vec<&Candidate> = found
                .iter()
                .flatten()
                .filter(|c| matches!(c.plan, Plan::Seq { delta: None, .. }))
                .collect();
            seqs.sort_by_key(|c| std::cmp::Reverse(c.pairs));
            seqs.truncate(REFITS);
            let refits: Vec<Candidate> = seqs
                .par_iter()
                .flat_map_iter(|c| match (&c.plan, near.as_ref()) {
                    (Plan::Seq { chains, .. }, Some(near)) => {
                        let chains = extend_changing(insts, chains.clone(), near, tol);
                        linear::refit(insts, edges, &index, &chains, tol)
                    }
                    _ => Vec::new(),
                })
                .map(|c| Candidate { hidden: true, ..c })
                .collect();
            out.extend(refits);
        }
        out.extend(found.into_iter().flatten());
        if a == b {
            // Branchings: two or three clusters of one kind, each node with
            // a child in each.
            // A kind of at most four instances may be one tree's root and
            // its children (a tree of two levels of stems and buds at the
            // tips): its clusters of one edge count too, and such a tree
            // must have tips.
            let few = ks
                .iter()
                .map(|&k| edges[k].from)
                .collect::<BTreeSet<_>>()
                .len()
                <= 4;
            let least = if few { 1 } else { 2 };
            let mut big: Vec<&Vec<usize>> = groups.iter().filter(|g| g.len() >= least).collect();
            big.sort_by_key(|g| std::cmp::Reverse(g.len()));
            big.truncate(8);
            let n = big.len();
            let pairs = (0..n).flat_map(|x| (x + 1..n).map(move |y| vec![x, y]));
            let triples = (0..n)
                .flat_map(|x| (x + 1..n).flat_map(move |y| (y + 1..n).map(move |z| vec![x, y, z])));
            let sets: Vec<Vec<usize>> = pairs.chain(triples).collect();
            // Each cluster's child map and transform, once for all the sets
            // it is in; the sets are tried in parallel, kept in their order.
            let children: Vec<Children> = big
                .par_iter()
                .map(|g| Children::of(insts.len(), edges, g, tol))
                .collect();
            let outs = outs.get_or_insert_with(|| Outs::of(insts.len(), edges));
            let spots = spots.get_or_insert_with(|| {
                insts
                    .iter()
                    .map(|i| (i.frame, i.size()))
                    .collect::<Vec<_>>()
            });
            let found: Vec<Option<Candidate>> = sets
                .par_iter()
                .map(|set| {
                    let groups: Vec<&Children> = set.iter().map(|&g| &children[g]).collect();
                    let tips = set.iter().any(|&g| big[g].len() < 2);
                    branching(insts, edges, &index, outs, spots, &groups, tips, tol)
                })
                .collect();
            out.extend(found.into_iter().flatten());
            out.extend(linear::linear(insts, edges, &index, ks, tol, budget)?);
        }
    }
    Ok((out, count))
}

/// Chains (or pairs, across kinds) of one cluster.
#[allow(clippy::too_many_arguments)]
fn sequence(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    group: &[usize],
    same: bool,
    tol: Tolerance,
    phi: f64,
    near: Option<&Near>,
) -> Option<Candidate> {
    let ts: Vec<Tr> = group.iter().map(|&k| edges[k].t).collect();
    let centre = mean(&ts);
    // Edges nearest the centre first (each edge's distance found once, not
    // per comparison; edges differ in their ends, so the order is total).
    let c = point(&centre, tol);
    let mut keyed: Vec<(f64, usize, usize, usize)> = group
        .iter()
        .map(|&k| {
            let p = point(&edges[k].t, tol);
            let dev = (0..4).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>();
            (dev, edges[k].from, edges[k].to, k)
        })
        .collect();
    keyed.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let order: Vec<usize> = keyed.into_iter().map(|x| x.3).collect();
    let mut next: CellMap<usize, usize> = CellMap::default();
    let mut prev: CellMap<usize, usize> = CellMap::default();
    let mut root: CellMap<usize, usize> = CellMap::default();
    fn find(root: &mut CellMap<usize, usize>, i: usize) -> usize {
        let mut r = i;
        while let Some(&up) = root.get(&r) {
            if up == r {
                break;
            }
            r = up;
        }
        // Every node on the way points at the root: a long chain is walked once.
        let mut at = i;
        while at != r {
            let up = root[&at];
            root.insert(at, r);
            at = up;
        }
        r
    }
    for k in order {
        let e = &edges[k];
        if next.contains_key(&e.from) || prev.contains_key(&e.to) {
            continue;
        }
        if !same && (prev.contains_key(&e.from) || next.contains_key(&e.to)) {
            continue;
        }
        let (ra, rb) = (find(&mut root, e.from), find(&mut root, e.to));
        if ra == rb {
            continue;
        }
        root.insert(ra.max(rb), ra.min(rb));
        root.entry(ra.min(rb)).or_insert(ra.min(rb));
        next.insert(e.from, e.to);
        prev.insert(e.to, e.from);
    }
    let mut starts: Vec<usize> = next
        .keys()
        .copied()
        .filter(|s| !prev.contains_key(s))
        .collect();
    starts.sort_unstable();
    // The cluster's edges, sorted: whether a ring's closing edge is one of
    // them is a search, not a scan per chain.
    let mut sorted = group.to_vec();
    sorted.sort_unstable();
    let mut chains: Vec<Vec<usize>> = Vec::new();
    for s in starts {
        let mut chain = vec![s];
        let mut at = s;
        while let Some(&n) = next.get(&at) {
            chain.push(n);
            at = n;
        }
        // A closed ring (its closing edge is in the cluster) starts at the
        // element turned least, so that equal rings get equal frames.
        let closed = chain.len() > 2
            && index
                .get(&(at, s))
                .is_some_and(|k| sorted.binary_search(k).is_ok());
        if closed {
            let first = (0..chain.len())
                .min_by(|&x, &y| {
                    let (fx, fy) = (&insts[chain[x]].frame, &insts[chain[y]].frame);
                    let key = |f: &Frame| (wrap(f.rot).abs() * 1e6).round();
                    key(fx).total_cmp(&key(fy)).then(x.cmp(&y))
                })
                .unwrap_or(0);
            chain.rotate_left(first);
        }
        chains.push(chain);
    }
    // The transform from the edges used, then chains cut where it drifts.
    let used: Vec<Tr> = chains
        .iter()
        .flat_map(|c| c.windows(2))
        .filter_map(|w| index.get(&(w[0], w[1])).map(|&k| edges[k].t))
        .collect();
    let t = supported_mean(&used, tol);
    let mut chains = cut_drift(insts, chains, |_, _| t, tol);
    if let Some(near) = near {
        chains = extend(insts, chains, &t, near, tol);
    }
    let mut cand = seq_candidate(edges, index, chains, t, None, phi)?;
    if !same {
        // Across two kinds the chains are pairs: A T B.
        if let Plan::Seq { chains, t, .. } = cand.plan {
            cand.plan = Plan::Pair {
                pairs: chains.iter().map(|c| (c[0], c[1])).collect(),
                t,
            };
        }
    }
    Some(cand)
}

/// Splits chains where redrawing with `step(chain position, chain length)`
/// leaves the tolerance; drops pieces of one instance.
fn cut_drift(
    insts: &[Inst],
    chains: Vec<Vec<usize>>,
    step: impl Fn(usize, usize) -> Tr,
    tol: Tolerance,
) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    for chain in chains {
        let mut piece = vec![chain[0]];
        let mut at = insts[chain[0]].frame;
        for (q, &i) in chain.iter().enumerate().skip(1) {
            let t = step(piece.len() - 1, chain.len() - q + piece.len() - 1);
            let want = t.apply(&at);
            let f = insts[i].frame;
            let size = insts[i].size();
            if close(&want, &f, t.d * at.scale, size, tol) {
                piece.push(i);
                at = want;
            } else {
                if piece.len() >= 2 {
                    out.push(std::mem::take(&mut piece));
                }
                piece = vec![i];
                at = f;
            }
        }
        if piece.len() >= 2 {
            out.push(piece);
        }
    }
    out
}

/// The live instances of one symbol, for finding one near a point.
struct Near {
    ids: Vec<usize>,
    grid: PointGrid,
}

impl Near {
    fn new(insts: &[Inst], sym: Sym) -> Near {
        let ids: Vec<usize> = (0..insts.len())
            .filter(|&i| insts[i].alive && insts[i].sym == sym)
            .collect();
        let points: Vec<DVec2> = ids.iter().map(|&i| insts[i].frame.pos).collect();
        Near {
            grid: PointGrid::new(&points),
            ids,
        }
    }

    /// The instance nearest to where `want` is, if it is there within the tolerance.
    fn at(&self, insts: &[Inst], want: &Frame, step: f64, tol: Tolerance) -> Option<usize> {
        let j = *self.ids.get(*self.grid.nearest(want.pos, 1).first()?)?;
        close(&insts[j].frame, want, step, insts[j].size(), tol).then_some(j)
    }
}

/// Chains of three or more grown at both ends while an instance no chain
/// holds is where the change between their last (first) two transforms,
/// continued, puts the next (`--symmetrize`): a constant sequence that
/// stood for a changing one was cut where the change outgrew it, and its
/// linear refit takes the copies back.
fn extend_changing(
    insts: &[Inst],
    mut chains: Vec<Vec<usize>>,
    near: &Near,
    tol: Tolerance,
) -> Vec<Vec<usize>> {
    fill_gaps(insts, &mut chains, near, tol);
    let mut used: HashSet<usize> = chains.iter().flatten().copied().collect();
    let between = |a: usize, b: usize| {
        let f = &insts[a].frame;
        Tr::between(f, &insts[b].frame, insts[a].size() / f.scale)
    };
    // The transform after `a` then `b`, each number changed by as much again.
    let continued = |a: &Tr, b: &Tr| Tr {
        alpha: wrap(b.alpha + wrap(b.alpha - a.alpha)),
        d: 2.0 * b.d - a.d,
        s: 2.0 * b.s - a.s,
        beta: wrap(b.beta + wrap(b.beta - a.beta)),
    };
    for chain in chains.iter_mut().filter(|c| c.len() >= 3) {
        loop {
            let n = chain.len();
            let t = continued(
                &between(chain[n - 3], chain[n - 2]),
                &between(chain[n - 2], chain[n - 1]),
            );
            let f = insts[chain[n - 1]].frame;
            if t.d <= 0.0 || t.s <= 0.0 {
                break;
            }
            match near.at(insts, &t.apply(&f), t.d * f.scale, tol) {
                Some(j) if used.insert(j) => chain.push(j),
                _ => break,
            }
        }
        loop {
            let t = continued(&between(chain[1], chain[2]), &between(chain[0], chain[1]));
            if t.d <= 0.0 || t.s <= 0.0 {
                break;
            }
            let want = insts[chain[0]]
                .frame
                .then(&t.apply(&Frame::IDENTITY).inverse());
            match near.at(insts, &want, t.d * want.scale, tol) {
                Some(j) if used.insert(j) => chain.insert(0, j),
                _ => break,
            }
        }
    }
    chains
}

/// Instances on the way between two neighbours of a chain of three or
/// more (a detour of at most a third of the distance tolerance, each part
/// at least a fifth of the way), taken into it from wherever they were: a
/// constant sequence that stood for a row whose steps change skips a short
/// step where two of them add up to a step of its own length. A chain
/// left with one copy is dropped (its copy is free to be grown into).
fn fill_gaps(insts: &[Inst], chains: &mut Vec<Vec<usize>>, near: &Near, tol: Tolerance) {
    let mut owner: HashMap<usize, usize> = HashMap::new();
    for (c, chain) in chains.iter().enumerate() {
        for &i in chain {
            owner.insert(i, c);
        }
    }
    for c in 0..chains.len() {
        if chains[c].len() < 3 {
            continue;
        }
        let mut k = 0;
        while k + 1 < chains[c].len() {
            let (a, b) = (
                insts[chains[c][k]].frame.pos,
                insts[chains[c][k + 1]].frame.pos,
            );
            let d = a.distance(b);
            let on_way = near
                .grid
                .within((a + b) / 2.0, d / 2.0)
                .into_iter()
                .map(|g| near.ids[g])
                .filter(|&j| owner.get(&j) != Some(&c))
                .filter(|&j| {
                    let p = insts[j].frame.pos;
                    let (x, y) = (a.distance(p), p.distance(b));
                    x + y <= d * (1.0 + tol.distance / 3.0) && x.min(y) >= d / 5.0
                })
                .min_by(|&x, &y| {
                    a.distance(insts[x].frame.pos)
                        .total_cmp(&a.distance(insts[y].frame.pos))
                });
            match on_way {
                Some(j) => {
                    if let Some(&o) = owner.get(&j) {
                        chains[o].retain(|&i| i != j);
                    }
                    owner.insert(j, c);
                    chains[c].insert(k + 1, j);
                }
                None => k += 1,
            }
        }
    }
    // What a chain lost may leave one copy, which is no chain.
    chains.retain(|c| c.len() >= 2);
}

/// Chains grown at both ends while the next instance `t` leads to (or the
/// one it comes from) is where it should be, joining chains that meet: a
/// noisy row or ring whose transforms fell into two clusters comes out whole
/// (`--symmetrize`).
fn extend(
    insts: &[Inst],
    mut chains: Vec<Vec<usize>>,
    t: &Tr,
    near: &Near,
    tol: Tolerance,
) -> Vec<Vec<usize>> {
    let origin = Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    };
    let back = t.apply(&origin).inverse();
    // Which chain each instance is in, and whether it starts or ends it.
    let mut owner: HashMap<usize, usize> = HashMap::new();
    for (c, chain) in chains.iter().enumerate() {
        for &i in chain {
            owner.insert(i, c);
        }
    }
    let mut gone = vec![false; chains.len()];
    for c in 0..chains.len() {
        if gone[c] {
            continue;
        }
        // Forward: append free instances, or a chain that starts there.
        while let Some(&last) = chains[c].last() {
            let f = insts[last].frame;
            let want = t.apply(&f);
            let Some(j) = near.at(insts, &want, t.d * f.scale, tol) else {
                break;
            };
            match owner.get(&j).copied() {
                None => {
                    chains[c].push(j);
                    owner.insert(j, c);
                }
                Some(o) if o != c && !gone[o] && chains[o].first() == Some(&j) => {
                    let tail = std::mem::take(&mut chains[o]);
                    for &i in &tail {
                        owner.insert(i, c);
                    }
                    chains[c].extend(tail);
                    gone[o] = true;
                }
                _ => break,
            }
        }
        // Backward: prepend free instances, or a chain that ends there.
        while let Some(&first) = chains[c].first() {
            let want = insts[first].frame.then(&back);
            let Some(j) = near.at(insts, &want, t.d * want.scale, tol) else {
                break;
            };
            match owner.get(&j).copied() {
                None => {
                    chains[c].insert(0, j);
                    owner.insert(j, c);
                }
                Some(o) if o != c && !gone[o] && chains[o].last() == Some(&j) => {
                    let mut head = std::mem::take(&mut chains[o]);
                    for &i in &head {
                        owner.insert(i, c);
                    }
                    head.append(&mut chains[c]);
                    chains[c] = head;
                    gone[o] = true;
                }
                _ => break,
            }
        }
    }
    chains
        .into_iter()
        .zip(gone)
        .filter(|(c, gone)| !gone && c.len() >= 2)
        .map(|(c, _)| c)
        .collect()
}

fn seq_candidate(
    edges: &[Edge],
    index: &Index,
    chains: Vec<Vec<usize>>,
    t: Tr,
    delta: Option<Tr>,
    phi: f64,
) -> Option<Candidate> {
    if chains.is_empty() {
        return None;
    }
    let pairs: usize = chains.iter().map(|c| c.len() - 1).sum();
    let gap_sum: f64 = chains
        .iter()
        .flat_map(|c| c.windows(2))
        .map(|w| index.get(&(w[0], w[1])).map_or(1.0, |&k| edges[k].gap))
        .sum();
    Some(Candidate {
        length: (pairs + chains.len()) as f64 / chains.len() as f64,
        h: 1.0 - gap_sum / pairs as f64,
        phi,
        pairs,
        plan: Plan::Seq {
            chains,
            t,
            delta,
            place: None,
            fitted: None,
        },
        hidden: false,
    })
}

/// Importances closer than this are equal (the two directions of one chain
/// differ in proximity by the one link each leaves out).
const TIE: f64 = 0.005;

/// The most important candidate; between equals, the one whose links run
/// most in the drawing's order (a ring read as it was drawn, not backwards).
fn choose(
    insts: &[Inst],
    cands: &mut Vec<Candidate>,
    w: Weights,
    tol: Tolerance,
) -> Option<Candidate> {
    let (mut hidden, rest): (Vec<Candidate>, Vec<Candidate>) =
        std::mem::take(cands).into_iter().partition(|c| c.hidden);
    *cands = rest;
    let max_n = cands.iter().map(|c| c.pairs).max()? as f64;
    let max_l = cands.iter().map(|c| c.length).fold(0.0, f64::max);
    let score = |c: &Candidate| {
        w.n * c.pairs as f64 / max_n + w.h * c.h + w.phi * c.phi + w.l * c.length / max_l
    };
    let forward = |c: &Candidate| {
        let ahead = |a: usize, b: usize| usize::from(insts[a].order < insts[b].order);
        let (k, n) = match &c.plan {
            Plan::Seq { chains, .. } => chains
                .iter()
                .flat_map(|ch| ch.windows(2))
                .fold((0, 0), |(k, n), w| (k + ahead(w[0], w[1]), n + 1)),
            Plan::Pair { pairs, .. } => pairs
                .iter()
                .fold((0, 0), |(k, n), &(a, b)| (k + ahead(a, b), n + 1)),
            Plan::Branch { .. } => (1, 1),
        };
        k as f64 / n.max(1) as f64
    };
    // Each candidate's score and order once (not once per comparison).
    let scores: Vec<f64> = cands.par_iter().map(score).collect();
    let forwards: Vec<f64> = cands.par_iter().map(forward).collect();
    let mut best = 0;
    for i in 1..cands.len() {
        let (a, b) = (scores[i], scores[best]);
        let (fa, fb) = (forwards[i], forwards[best]);
        if (a > b + 1e-12 && !(a < b + TIE && fb > fa)) || (a > b - TIE && fa > fb) {
            best = i;
        }
    }
    // A sequence whose members pair up regularly with another kind's (A B
    // A B …, a leaflet on each side) is a period: the pairs first, then the
    // sequence of pairs, one rule over the period.
    if let Plan::Seq { chains, .. } = &cands[best].plan {
        let members: HashSet<usize> = chains.iter().flatten().copied().collect();
        let covers = |c: &Candidate| match &c.plan {
            Plan::Pair { pairs, .. } if pairs.len() >= 2 => {
                let k = pairs
                    .iter()
                    .filter(|(a, b)| members.contains(a) || members.contains(b))
                    .count();
                pairs.len() * 5 >= members.len() * 4 && k * 5 >= members.len() * 4
            }
            _ => false,
        };
        if let Some(p) = (0..cands.len())
            .filter(|&i| covers(&cands[i]))
            .max_by(|&x, &y| {
                let (a, b) = (scores[x], scores[y]);
                let tie = (a - b).abs() <= TIE;
                (if tie {
                    Ordering::Equal
                } else {
                    a.total_cmp(&b)
                })
                .then(forwards[x].total_cmp(&forwards[y]))
                .then(a.total_cmp(&b))
                .then(y.cmp(&x))
            })
        {
            best = p;
        }
    }
    let change = hidden_change(insts, &cands[best], &hidden, tol)
        .or_else(|| longer_change(insts, &cands[best], &hidden));
    if let Some(l) = change {
        return Some(hidden.swap_remove(l));
    }
    Some(cands.swap_remove(best))
}

/// A linear candidate that draws most of a constant sequence's chain
/// (`best`) with a change the tolerance hides: its turn, step or scale
/// changes over the chain by more than the tolerance allows between two
/// copies, and it puts the copies nearer than the constant one does (the
/// mean square of how far and how much larger or smaller it draws them
/// under a ninth of the constant fit's). A relaxed reading (`--symmetrize`)
/// takes a turn that grows by 2° a step for a constant one; the change is
/// what the drawing shows, and a noisy row stays a row.
fn hidden_change(
    insts: &[Inst],
    best: &Candidate,
    cands: &[Candidate],
    tol: Tolerance,
) -> Option<usize> {
    let Plan::Seq {
        chains,
        t: constant,
        delta: None,
        ..
    } = &best.plan
    else {
        return None;
    };
    let members: HashSet<usize> = chains.iter().flatten().copied().collect();
    let shows = |c: &Candidate| {
        let Plan::Seq {
            chains,
            t,
            delta: Some(d),
            ..
        } = &c.plan
        else {
            return false;
        };
        let steps = chains
            .iter()
            .map(Vec::len)
            .max()
            .unwrap_or(1)
            .saturating_sub(1) as f64;
        let shared = chains
            .iter()
            .flatten()
            .filter(|i| members.contains(i))
            .count();
        shared * 5 >= members.len() * 4
            && c.pairs * 5 >= best.pairs * 4
            && ((d.alpha + d.beta).abs() * steps > tol.angle
                || d.d.abs() * steps > tol.distance * t.d.abs()
                || d.s.abs() * steps > tol.scale * t.s.abs())
    };
    let mut shown: Vec<usize> = (0..cands.len()).filter(|&i| shows(&cands[i])).collect();
    if shown.is_empty() {
        return None;
    }
    let misfit = |chains: &[Vec<usize>], r: &regular::Regular| misfit(insts, chains, r);
    let spread = regular::sequence(insts, chains, constant, tol)
        .map_or(f64::INFINITY, |r| misfit(chains, &r));
    shown.retain(|&i| match &cands[i].plan {
        Plan::Seq {
            chains,
            fitted: Some(r),
            ..
        } => misfit(chains, r) * 9.0 < spread,
        _ => false,
    });
    shown
        .into_iter()
        .max_by(|&x, &y| cands[x].pairs.cmp(&cands[y].pairs).then(y.cmp(&x)))
}

/// How far a fit draws its members from where they are: the mean square
/// of the distance and of the size a wrong scale makes up (a row whose
/// steps shrink linearly fits a geometric sequence by shrinking copies the
/// drawing does not shrink).
fn misfit(insts: &[Inst], chains: &[Vec<usize>], r: &regular::Regular) -> f64 {
    let (sum, n) =
        chains
            .iter()
            .flatten()
            .zip(&r.drawn)
            .fold((0.0, 0usize), |(sum, n), (&i, d)| {
                let f = &insts[i].frame;
                let size = 0.5 * insts[i].size() * (f.scale / d.scale).ln();
                (sum + f.pos.distance_squared(d.pos) + size * size, n + 1)
            });
    sum / n.max(1) as f64
}

/// A linear candidate refitted from a constant sequence's grown chain
/// (`cands`) that holds every copy of the linear change `best` and more,
/// drawing them about as near (mean square at most four times `best`'s):
/// a change found on part of a hand-placed row, whose ends the search's
/// tolerance cut off (`--symmetrize`).
fn longer_change(insts: &[Inst], best: &Candidate, cands: &[Candidate]) -> Option<usize> {
    let Plan::Seq {
        chains,
        delta: Some(_),
        fitted: Some(fit),
        ..
    } = &best.plan
    else {
        return None;
    };
    let members: HashSet<usize> = chains.iter().flatten().copied().collect();
    let near = misfit(insts, chains, fit) * 4.0;
    (0..cands.len())
        .filter(|&i| cands[i].pairs > best.pairs)
        .filter(|&i| match &cands[i].plan {
            Plan::Seq {
                chains,
                delta: Some(_),
                fitted: Some(r),
                ..
            } => {
                let have: HashSet<usize> = chains.iter().flatten().copied().collect();
                members.is_subset(&have) && misfit(insts, chains, r) <= near
            }
            _ => false,
        })
        .max_by(|&x, &y| cands[x].pairs.cmp(&cands[y].pairs).then(y.cmp(&x)))
}

fn union_box(insts: &[Inst], ids: impl IntoIterator<Item = usize>) -> (DVec2, DVec2) {
    ids.into_iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), i| (lo.min(insts[i].min), hi.max(insts[i].max)),
    )
}

fn replace(insts: &mut Vec<Inst>, first: usize, members: &[usize], sym: Sym) {
    let frame = insts[first].frame;
    replace_at(insts, frame, members, sym, None);
}

/// How a regular fit placed a new instance: the standard error of its
/// rotation, where each member is drawn, and the variance about the fit.
struct Placed<'a> {
    rot_se: f64,
    pos_se: f64,
    drawn: &'a [Frame],
    sigma2: f64,
}

fn replace_at(
    insts: &mut Vec<Inst>,
    frame: Frame,
    members: &[usize],
    sym: Sym,
    placed: Option<Placed>,
) {
    let (min, max) = union_box(insts, members.iter().copied());
    let mut mass = DVec2::ZERO;
    let mut count = 0.0;
    let mut noise = 0.0;
    let mut tilt: Vec<(usize, f64, f64)> = Vec::new();
    for (k, &i) in members.iter().enumerate() {
        let m = &insts[i];
        // A member drawn elsewhere than it is carries its elements along.
        let (at, turn) = match placed.as_ref().and_then(|p| p.drawn.get(k)) {
            Some(d) => (
                d.apply(m.frame.inverse().apply(m.mass)),
                wrap(d.rot - m.frame.rot),
            ),
            None => (m.mass, 0.0),
        };
        mass += at * m.count;
        count += m.count;
        noise += m.noise * m.count;
        for &(kind, sum, n) in &m.tilt {
            match tilt.iter_mut().find(|t| t.0 == kind) {
                Some(t) => {
                    t.1 += sum - turn * n;
                    t.2 += n;
                }
                None => tilt.push((kind, sum - turn * n, n)),
            }
        }
    }
    let mut inst = Inst::new(sym, frame, min, max);
    inst.order = members
        .iter()
        .map(|&i| insts[i].order)
        .min()
        .unwrap_or(usize::MAX);
    inst.count = count.max(1.0);
    inst.mass = mass / inst.count;
    inst.noise = noise / inst.count;
    inst.tilt = tilt;
    if let Some(p) = placed {
        inst.rot_se = p.rot_se;
        inst.pos_se = p.pos_se;
        // Elements placed directly: the fit says how far they are off.
        if inst.noise == 0.0 && p.sigma2.is_finite() {
            inst.noise = p.sigma2;
        }
    }
    for &i in members {
        insts[i].alive = false;
    }
    insts.push(inst);
}

/// Where a chain drawn with `t` from one start frame fits its elements best:
/// the mean of the start frames each element implies (noise shrinks with the
/// chain's length; exact chains give their first frame).
fn fitted_start(insts: &[Inst], chain: &[usize], t: &Tr) -> Frame {
    let origin = Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    };
    let back = t.apply(&origin).inverse();
    let implied: Vec<Frame> = chain
        .iter()
        .enumerate()
        .map(|(k, &i)| (0..k).fold(insts[i].frame, |f, _| f.then(&back)))
        .collect();
    Frame::mean(&implied).unwrap_or(insts[chain[0]].frame)
}

/// The members of a complete binary tree, level by level.
fn tree_members(child: &[HashMap<usize, usize>], root: usize, depth: u32) -> Vec<usize> {
    let mut members = vec![root];
    let mut level = vec![root];
    for _ in 0..depth {
        level = level
            .iter()
            .flat_map(|v| child.iter().filter_map(move |c| c.get(v)))
            .copied()
            .collect();
        members.extend(level.iter().copied());
    }
    members
}

fn apply(g: &mut Grammar, insts: &mut Vec<Inst>, plan: Plan, tol: Tolerance) {
    let r = g.rules.len();
    match plan {
        Plan::Seq {
            chains,
            t,
            delta,
            place,
            fitted,
        } => {
            let a = insts[chains[0][0]].sym;
            let tip = chains[0].last().map(|&i| insts[i].sym).filter(|&b| b != a);
            let reg = fitted.or_else(|| {
                (tol.regular && delta.is_none())
                    .then(|| regular::sequence(insts, &chains, &t, tol))
                    .flatten()
            });
            let mut counts = BTreeSet::new();
            let mut offset = 0;
            for (k, c) in chains.iter().enumerate() {
                let m = (c.len() - 1) as u32;
                counts.insert(m);
                let start = match (&reg, delta) {
                    (Some(reg), _) => reg.starts[k],
                    (None, None) => fitted_start(insts, c, &t),
                    (None, Some(_)) => insts[c[0]].frame,
                };
                let placed = reg.as_ref().map(|reg| Placed {
                    rot_se: reg.rot_se[k],
                    pos_se: reg.pos_se[k],
                    drawn: &reg.drawn[offset..offset + c.len()],
                    sigma2: reg.sigma2,
                });
                replace_at(insts, start, c, Sym::Rule(r, m), placed);
                offset += c.len();
            }
            let t = reg.map_or(t, |reg| reg.t[0]);
            g.rules.push(Rule {
                body: Body::Seq {
                    a,
                    t,
                    delta,
                    place,
                    tip,
                },
                counts,
            });
        }
        Plan::Branch {
            trees,
            child,
            ts,
            tip_at,
        } => {
            let a = insts[trees[0].0].sym;
            // Tips drawn as children: their frames where a child's would be.
            let tip_at = tip_at.map(|(rel, frames)| {
                for (i, f) in frames {
                    insts[i].frame = f;
                }
                rel
            });
            let tip = tree_members(&child, trees[0].0, trees[0].1)
                .last()
                .map(|&i| insts[i].sym)
                .filter(|&b| b != a);
            let reg = tol
                .regular
                .then(|| regular::branching(insts, &trees, &child, &ts, tol))
                .flatten();
            let mut counts = BTreeSet::new();
            let mut offset = 0;
            for (k, &(root, d)) in trees.iter().enumerate() {
                let members = tree_members(&child, root, d);
                counts.insert(d);
                match &reg {
                    Some(reg) => {
                        let placed = Placed {
                            rot_se: reg.rot_se[k],
                            pos_se: reg.pos_se[k],
                            drawn: &reg.drawn[offset..offset + members.len()],
                            sigma2: reg.sigma2,
                        };
                        replace_at(
                            insts,
                            reg.starts[k],
                            &members,
                            Sym::Rule(r, d),
                            Some(placed),
                        )
                    }
                    None => replace(insts, root, &members, Sym::Rule(r, d)),
                }
                offset += members.len();
            }
            let ts = reg.map_or(ts, |reg| reg.t);
            g.rules.push(Rule {
                body: Body::Branch {
                    a,
                    ts,
                    tip,
                    tip_at: tip_at.filter(|_| tip.is_some()),
                },
                counts,
            });
        }
        Plan::Pair { pairs, t } => {
            let (a, b) = (insts[pairs[0].0].sym, insts[pairs[0].1].sym);
            // Two of one sequence (two rows of a grid) are a sequence of
            // it, counted (`m` = 1), as a person extends a grid.
            let nested = a == b
                && matches!(a, Sym::Rule(q, _)
                    if g.rules[q].repeats() && matches!(g.rules[q].body, Body::Seq { .. }));
            let m = u32::from(nested);
            // Which part the drawing paints first, in most pairs.
            let later = pairs
                .iter()
                .filter(|&&(x, y)| insts[y].order < insts[x].order)
                .count();
            let swap = later * 2 > pairs.len();
            // Pairs of one cluster are a repeated structure; a lone pair is not.
            let reg = (tol.regular && pairs.len() >= 2)
                .then(|| {
                    let chains: Vec<Vec<usize>> = pairs.iter().map(|&(x, y)| vec![x, y]).collect();
                    regular::sequence(insts, &chains, &t, tol)
                })
                .flatten();
            for (k, &(x, y)) in pairs.iter().enumerate() {
                match &reg {
                    Some(reg) => {
                        let placed = Placed {
                            rot_se: reg.rot_se[k],
                            pos_se: reg.pos_se[k],
                            drawn: &reg.drawn[2 * k..2 * k + 2],
                            sigma2: reg.sigma2,
                        };
                        replace_at(insts, reg.starts[k], &[x, y], Sym::Rule(r, m), Some(placed))
                    }
                    None => replace(insts, x, &[x, y], Sym::Rule(r, m)),
                }
            }
            let t = reg.map_or(t, |reg| reg.t[0]);
            let body = if nested {
                Body::Seq {
                    a,
                    t,
                    delta: None,
                    place: None,
                    tip: None,
                }
            } else {
                Body::Pair { a, t, b, swap }
            };
            g.rules.push(Rule {
                body,
                counts: BTreeSet::from([m]),
            });
        }
    }
}

/// Nothing repeats: the closest pairs become pair rules, as many at once as
/// do not share an instance.
fn pair_up(g: &mut Grammar, insts: &mut Vec<Inst>, edges: &[Edge], tol: Tolerance) {
    let mut order: Vec<&Edge> = edges.iter().collect();
    order.sort_by(|a, b| {
        a.gap
            .total_cmp(&b.gap)
            .then(a.t.d.total_cmp(&b.t.d))
            .then(a.from.cmp(&b.from))
            .then(a.to.cmp(&b.to))
    });
    let mut taken: HashSet<usize> = HashSet::new();
    let mut any = false;
    for e in order {
        if taken.contains(&e.from) || taken.contains(&e.to) {
            continue;
        }
        // Read left to right: the pair starts at the earlier instance.
        if e.from > e.to {
            continue;
        }
        taken.insert(e.from);
        taken.insert(e.to);
        apply(
            g,
            insts,
            Plan::Pair {
                pairs: vec![(e.from, e.to)],
                t: e.t,
            },
            tol,
        );
        any = true;
    }
    if !any && let Some(e) = edges.first() {
        apply(
            g,
            insts,
            Plan::Pair {
                pairs: vec![(e.from, e.to)],
                t: e.t,
            },
            tol,
        );
    }
}

impl Grammar {
    /// How many elements `s` draws.
    pub fn covered(&self, s: Sym) -> u64 {
        match s {
            Sym::Element(_) => 1,
            Sym::Rule(r, m) => match &self.rules[r].body {
                Body::Seq { a, tip: None, .. } => (u64::from(m) + 1) * self.covered(*a),
                Body::Seq {
                    a, tip: Some(b), ..
                } => u64::from(m) * self.covered(*a) + self.covered(*b),
                Body::Branch { a, ts, tip, .. } => {
                    // k^m leaves below k^m − 1 … 1 nodes: (k^m − 1)/(k − 1).
                    let k = ts.len().max(2) as u64;
                    let leaves = k.saturating_pow(m);
                    let inner = (leaves - 1) / (k - 1);
                    match tip {
                        None => (inner + leaves).saturating_mul(self.covered(*a)),
                        Some(b) => inner
                            .saturating_mul(self.covered(*a))
                            .saturating_add(leaves.saturating_mul(self.covered(*b))),
                    }
                }
                Body::Pair { a, b, .. } => self.covered(*a) + self.covered(*b),
            },
        }
    }
}
