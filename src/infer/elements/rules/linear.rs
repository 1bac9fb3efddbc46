//! Linear sequences (the paper's §5.3 and Fig. 5): chains whose transform
//! changes by a constant amount per repetition, one rule
//! `P(m) -> [A] T(t0 + tΔ·m) P(m - 1)`.
//!
//! Owns: finding such chains and fitting t0 and tΔ to all their instances.
//! Two searches, each a subspace of the transformation space in which the
//! edges of one chain cluster, and a change along consecutive edges that is
//! the same at every step:
//!
//! - *turning*: the turn before and/or after the step changes (Fig. 5). Edges
//!   cluster by scale alone, and the whole turn θ = α + β changes by a
//!   constant step; both hold whatever point of the element the frames take
//!   as origin. The point the turtle turned about (the element's base) is
//!   then found from the chain: in frames with their origin there, the step
//!   d is the same for every transform, and |F_{k+1}(q) − F_k(q)| = d is a
//!   linear system in (|q|², q, d²). The element is drawn from the turtle at
//!   that point (`place`), so t0 and tΔ are the generator's.
//! - *growing*: the step d and/or the scale s change (α and β do not). Edges
//!   cluster by (α, β) and d and s change by a constant step.
//!
//! Each chain's t0 and tΔ (and base point) are fitted by least squares to all
//! its instances (`fit`); other chains join when the same t0 and tΔ draw them
//! within the tolerance, and the rule is fitted to all of them. A chain that
//! a fit does not draw back within the tolerance is dropped. Must not choose
//! among candidates of other kinds.

use super::fit::{Fit, Member, Solution, nice, nice_angle, solve_linear};
use super::regular::Regular;
use super::{
    Budget, Candidate, Edge, Index, Inst, LINEAR_STEP_MAX, Plan, Tolerance, TooMuchWork, close,
    point, seq_candidate,
};
use crate::infer::elements::shape::{Frame, wrap};
use crate::infer::elements::space::{Point, Tr, cluster};
use glam::DVec2;
use rayon::prelude::*;
use std::collections::{BTreeMap, HashSet};

/// Which numbers of the transform change along a chain.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Vary {
    /// α and/or β (θ = α + β changes).
    Turn,
    /// d and/or s.
    Grow,
}

/// Edges of one kind's space that the turning search links all with all
/// (they cluster by scale alone); more, and it clusters by step and scale,
/// taking the frames' origins as the turtle's.
const TURN_ANY_ORIGIN: usize = 4000;

/// Edges out of an instance that a link may continue with, nearest first:
/// a turning chain may curl back past its neighbours (Fig. 5); a growing
/// one goes on to the nearest instance in the same direction.
fn links_out(vary: Vary) -> usize {
    match vary {
        Vary::Turn => 8,
        Vary::Grow => 2,
    }
}

/// Delta clusters tried per search.
const TRIES: usize = 3;

// The parameters p: t0 = (α, d, s, θ = α + β) at 0..4, tΔ = (α, d, s, β)
// at 4..8, the base point q at 8..10.

fn identity() -> Frame {
    Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    }
}

/// The transform for counter `m`.
fn at(p: &[f64], m: f64) -> Tr {
    Tr {
        alpha: wrap(p[0] + p[4] * m),
        d: p[1] + p[5] * m,
        s: p[2] + p[6] * m,
        beta: wrap(p[3] - p[0] + p[7] * m),
    }
}

/// Where the element is drawn from the turtle: at −q.
fn offset(p: &[f64]) -> Frame {
    Frame {
        pos: -DVec2::new(p[8], p[9]),
        rot: 0.0,
        scale: 1.0,
    }
}

/// The frames of chains of lengths `lens` drawn with `p`, each from the
/// identity: member k of a chain of n follows k transforms, for m = n − 1
/// down to n − k.
fn model(p: &[f64], lens: &[usize], out: &mut Vec<Frame>) {
    out.clear();
    let o = offset(p);
    for &n in lens {
        let mut g = identity();
        for k in 0..n {
            out.push(g.then(&o));
            if k + 1 < n {
                g = at(p, (n - 1 - k) as f64).apply(&g);
            }
        }
    }
}

/// Linear candidates of one kind's space `ks`: the best of each search.
pub(super) fn linear(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    ks: &[usize],
    tol: Tolerance,
    budget: &mut Budget,
) -> Result<Option<Candidate>, TooMuchWork> {
    let mut best: Option<Candidate> = None;
    // Turning chains are looked for twice: among edges of one scale, whatever
    // the frames' origin, and among edges of one step and scale, the frames'
    // origins taken as the turtle's (given frames, or a chain whose edges of
    // one scale happen to change alike out of order).
    let searches = [
        (Vary::Turn, ks.len() <= TURN_ANY_ORIGIN),
        (Vary::Turn, false),
        (Vary::Grow, false),
    ];
    // The searches run in parallel, each on a copy of the budget; what they
    // spent is then charged in their order, so the limit is met exactly when
    // one search after the other would meet it.
    let runs: Vec<_> = searches
        .par_iter()
        .enumerate()
        .filter(|&(i, _)| i != 1 || searches[0].1)
        .map(|(_, &(vary, any_origin))| {
            let mut own = budget.copy();
            let found = search(insts, edges, index, ks, tol, &mut own, vary, any_origin);
            (found, budget.left - own.left)
        })
        .collect();
    for (found, spent) in runs {
        budget.spend_u64(spent)?;
        for cand in found? {
            if best.as_ref().is_none_or(|b| better(&cand, b)) {
                best = Some(cand);
            }
        }
    }
    Ok(best)
}

/// Linear rules for the chains of a constant sequence (`chains`, longest
/// first, each of four instances at least), turning and growing: a
/// relaxed reading (`--symmetrize`) links a chain whose turn or step
/// changes by less per step than its tolerance, and whose changes vary with
/// the drawing's noise more than the search for linear chains allows; a
/// fit to the whole chain still finds the change (`hidden_change` in the
/// choice says which wins).
pub(super) fn refit(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    chains: &[Vec<usize>],
    tol: Tolerance,
) -> Vec<Candidate> {
    let long: Vec<Vec<usize>> = chains.iter().filter(|c| c.len() >= 4).cloned().collect();
    if long.is_empty() {
        return Vec::new();
    }
    [Vary::Turn, Vary::Grow]
        .into_iter()
        .filter_map(|vary| rule(insts, edges, index, long.clone(), tol, vary))
        .collect()
}

/// More pairs; at a tie, chains that follow the drawing's order.
fn better(a: &Candidate, b: &Candidate) -> bool {
    let forward = |c: &Candidate| match &c.plan {
        Plan::Seq { chains, .. } => chains.iter().filter(|ch| ch.first() < ch.last()).count(),
        _ => 0,
    };
    a.pairs > b.pairs || (a.pairs == b.pairs && forward(a) > forward(b))
}

/// The coordinates edges of one chain share.
fn fixed(t: &Tr, tol: Tolerance, vary: Vary, any_origin: bool) -> Point {
    let p = point(t, tol);
    match vary {
        Vary::Turn if any_origin => [0.0, 0.0, p[2], 0.0],
        Vary::Turn => [0.0, p[1], p[2], 0.0],
        Vary::Grow => [p[0], 0.0, 0.0, p[3]],
    }
}

/// How a transform changes from edge `a` to edge `b`, in tolerance units
/// (steps and scales relative to the group's mean `unit` step and scale: a
/// linear change is the same amount at every step, not the same ratio).
fn change(a: &Tr, b: &Tr, tol: Tolerance, vary: Vary, unit: (f64, f64)) -> Point {
    match vary {
        Vary::Turn => [
            wrap((b.alpha + b.beta) - (a.alpha + a.beta)) / tol.angle,
            0.0,
            0.0,
            0.0,
        ],
        Vary::Grow => [
            0.0,
            (b.d - a.d) / unit.0 / tol.distance,
            (b.s - a.s) / unit.1 / tol.scale,
            0.0,
        ],
    }
}

/// Whether a change is a gradual one: more than the tolerance, less than a
/// different structure.
fn gradual(c: &Point, tol: Tolerance, vary: Vary) -> bool {
    match vary {
        Vary::Turn => c[0].abs() > 1.5 && c[0].abs() <= LINEAR_STEP_MAX / tol.angle,
        Vary::Grow => {
            let size = c[1].abs().max(c[2].abs());
            size > 1.5 && c[1].abs() * tol.distance <= 0.5 && c[2].abs() * tol.scale <= 0.5
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn search(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    ks: &[usize],
    tol: Tolerance,
    budget: &mut Budget,
    vary: Vary,
    any_origin: bool,
) -> Result<Vec<Candidate>, TooMuchWork> {
    // Changes are told apart at twice the exact tolerance at most: a
    // relaxed tolerance would take most steps of a gradual change for none.
    let det = Tolerance {
        angle: tol.angle.min(2.0 * Tolerance::EXACT.angle),
        distance: tol.distance.min(2.0 * Tolerance::EXACT.distance),
        scale: tol.scale.min(2.0 * Tolerance::EXACT.scale),
        ..tol
    };
    let points: Vec<Point> = ks
        .iter()
        .map(|&k| fixed(&edges[k].t, tol, vary, any_origin))
        .collect();
    budget.spend(points.len())?;
    // A growing chain's edges share their angles, which wrap (a step
    // straight back is α = ±π).
    let turn = match vary {
        Vary::Grow => std::f64::consts::TAU / tol.angle,
        Vary::Turn => 0.0,
    };
    let (label, centres) = cluster(&points, turn);
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); centres.len()];
    for (&k, &l) in ks.iter().zip(&label) {
        groups[l].push(k);
    }
    let mut out = Vec::new();
    for group in groups.iter().filter(|g| g.len() >= 3) {
        let (links, changes) = step_links(insts, edges, group, det, vary);
        if links.len() < 2 {
            continue;
        }
        budget.spend(changes.len())?;
        let (cl, cc) = cluster(&changes, 0.0);
        let mut sizes = vec![0usize; cc.len()];
        for &l in &cl {
            sizes[l] += 1;
        }
        let mut tops: Vec<usize> = (0..cc.len()).filter(|&i| sizes[i] >= 2).collect();
        tops.sort_by(|&x, &y| sizes[y].cmp(&sizes[x]).then(x.cmp(&y)));
        tops.truncate(TRIES);
        for top in tops {
            let chains = linear_chains(insts, edges, &links, &changes, &cl, (top, &cc[top]));
            budget.spend(chains.iter().map(Vec::len).sum())?;
            if let Some(cand) = rule(insts, edges, index, chains, tol, vary) {
                out.push(cand);
            }
        }
    }
    Ok(out)
}

/// The steps between consecutive edges of `group` (an edge into an
/// instance and one of the nearest edges out of it, not straight back) along
/// which the transform changes gradually: the links, and the changes.
fn step_links(
    insts: &[Inst],
    edges: &[Edge],
    group: &[usize],
    tol: Tolerance,
    vary: Vary,
) -> (Vec<(usize, usize)>, Vec<Point>) {
    let mut out_of: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for &k in group {
        out_of.entry(edges[k].from).or_default().push(k);
    }
    let length = |k: usize| edges[k].t.d * insts[edges[k].from].frame.scale;
    let n = group.len().max(1) as f64;
    let unit = (
        (group.iter().map(|&k| edges[k].t.d).sum::<f64>() / n).max(1e-12),
        (group.iter().map(|&k| edges[k].t.s).sum::<f64>() / n).max(1e-12),
    );
    for outs in out_of.values_mut() {
        outs.sort_by(|&a, &b| length(a).total_cmp(&length(b)).then(a.cmp(&b)));
        outs.truncate(links_out(vary));
    }
    let mut links = Vec::new();
    let mut changes = Vec::new();
    for &k in group {
        for &f in out_of.get(&edges[k].to).into_iter().flatten() {
            if edges[f].to == edges[k].from {
                continue;
            }
            // Only gradual changes are clustered: most links of a regular
            // drawing change nothing.
            let c = change(&edges[k].t, &edges[f].t, tol, vary, unit);
            if gradual(&c, tol, vary) {
                links.push((k, f));
                changes.push(c);
            }
        }
    }
    (links, changes)
}

/// The chains of instances linked by edges whose changes (`changes`, with
/// a cluster label each in `labels`) are in cluster `top` (label, centre),
/// node-disjoint, longest first. Links nearest the centre link first: a
/// chain's own links agree, links that skip an instance only roughly.
fn linear_chains(
    insts: &[Inst],
    edges: &[Edge],
    links: &[(usize, usize)],
    changes: &[Point],
    labels: &[usize],
    top: (usize, &Point),
) -> Vec<Vec<usize>> {
    let off = |i: usize| -> f64 { (0..4).map(|c| (changes[i][c] - top.1[c]).powi(2)).sum() };
    // A chain read backwards changes alike: among the links that agree within
    // the tolerance, those that follow the drawing's order link first.
    let backward = |i: usize| {
        let (k, f) = links[i];
        [k, f]
            .iter()
            .filter(|&&e| insts[edges[e].from].order > insts[edges[e].to].order)
            .count()
    };
    let mut order: Vec<usize> = (0..links.len()).filter(|&i| labels[i] == top.0).collect();
    order.sort_by(|&x, &y| {
        (off(x) > 1.0)
            .cmp(&(off(y) > 1.0))
            .then(backward(x).cmp(&backward(y)))
            .then(off(x).total_cmp(&off(y)))
            .then(x.cmp(&y))
    });
    let mut next: BTreeMap<usize, usize> = BTreeMap::new();
    let mut has_prev: HashSet<usize> = HashSet::new();
    for i in order {
        let (k, f) = links[i];
        if next.contains_key(&k) || has_prev.contains(&f) {
            continue;
        }
        next.insert(k, f);
        has_prev.insert(f);
    }
    let mut used: HashSet<usize> = HashSet::new();
    let mut chains: Vec<Vec<usize>> = Vec::new();
    let starts: Vec<usize> = next
        .keys()
        .copied()
        .filter(|k| !has_prev.contains(k))
        .collect();
    for s in starts {
        let mut nodes = vec![edges[s].from];
        let mut seen: HashSet<usize> = HashSet::from([edges[s].from]);
        let mut k = s;
        loop {
            let to = edges[k].to;
            if used.contains(&to) || !seen.insert(to) {
                break;
            }
            nodes.push(to);
            match next.get(&k) {
                Some(&f) => k = f,
                None => break,
            }
        }
        // Three transforms at least: two changes that agree.
        if nodes.len() >= 4 && !used.contains(&nodes[0]) {
            used.extend(nodes.iter().copied());
            chains.push(nodes);
        }
    }
    chains.sort_by(|a, b| b.len().cmp(&a.len()).then(a[0].cmp(&b[0])));
    chains
}

/// The point of the elements' frame (local units) the turtle turned about:
/// where consecutive frames are one step d apart. `None` when the frames do
/// not say (fewer than four transforms, or no turning).
fn pivot(frames: &[Frame]) -> Option<DVec2> {
    // |v + M q| = s d with v the step between origins and M = s' R(θ') − s R(θ):
    // |q − p|² = d² (s / |M|)², p = −M⁻¹ v; linear in (|q|², q, d²).
    let mut ata = vec![vec![0.0; 4]; 4];
    let mut atb = vec![0.0; 4];
    let mut rows = 0;
    for w in frames.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let m = DVec2::from_angle(b.rot) * b.scale - DVec2::from_angle(a.rot) * a.scale;
        let mm = m.length_squared();
        if mm < 1e-12 * a.scale * a.scale {
            continue;
        }
        let v = b.pos - a.pos;
        // p = −v / m as complex numbers.
        let p = -DVec2::new(v.x * m.x + v.y * m.y, v.y * m.x - v.x * m.y) / mm;
        let e = a.scale * a.scale / mm;
        let row = [1.0, -2.0 * p.x, -2.0 * p.y, -e];
        let rhs = -p.length_squared();
        for i in 0..4 {
            for j in 0..4 {
                ata[i][j] += row[i] * row[j];
            }
            atb[i] += row[i] * rhs;
        }
        rows += 1;
    }
    if rows < 4 {
        return None;
    }
    let x = solve_linear(ata, atb)?;
    let q = DVec2::new(x[1], x[2]);
    (x[3] > 0.0 && q.is_finite()).then_some(q)
}

/// A first guess of the parameters for one chain's frames and base point
/// `q`: each number of the transforms between the turtle's frames fitted by
/// a line in m.
fn guess(frames: &[Frame], q: DVec2, vary: Vary, size: f64) -> Vec<f64> {
    let base = Frame {
        pos: q,
        rot: 0.0,
        scale: 1.0,
    };
    let turtle: Vec<Frame> = frames.iter().map(|f| f.then(&base)).collect();
    let ts: Vec<Tr> = turtle
        .windows(2)
        .map(|w| Tr::between(&w[0], &w[1], size))
        .collect();
    let n = ts.len();
    // Angles unwrapped along the chain.
    let mut alpha: Vec<f64> = Vec::with_capacity(n);
    let mut beta: Vec<f64> = Vec::with_capacity(n);
    for (k, t) in ts.iter().enumerate() {
        if k == 0 {
            alpha.push(t.alpha);
            beta.push(t.beta);
        } else {
            alpha.push(alpha[k - 1] + wrap(t.alpha - alpha[k - 1]));
            beta.push(beta[k - 1] + wrap(t.beta - beta[k - 1]));
        }
    }
    let ms: Vec<f64> = (0..n).map(|k| (n - k) as f64).collect();
    let line = |ys: &[f64]| -> (f64, f64) {
        let mm = ms.iter().sum::<f64>() / n as f64;
        let my = ys.iter().sum::<f64>() / n as f64;
        let sxx: f64 = ms.iter().map(|m| (m - mm).powi(2)).sum();
        let sxy: f64 = ms.iter().zip(ys).map(|(m, y)| (m - mm) * (y - my)).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        (my - slope * mm, slope)
    };
    let (a0, ad) = line(&alpha);
    let (d0, dd) = line(&ts.iter().map(|t| t.d).collect::<Vec<_>>());
    let (s0, sd) = line(&ts.iter().map(|t| t.s).collect::<Vec<_>>());
    let (b0, bd) = line(&beta);
    let mut p = vec![a0, d0, s0, a0 + b0, ad, dd, sd, bd, q.x, q.y];
    match vary {
        Vary::Turn => {
            p[5] = 0.0;
            p[6] = 0.0;
            p[1] = ts.iter().map(|t| t.d).sum::<f64>() / n as f64;
            p[2] = ts.iter().map(|t| t.s).sum::<f64>() / n as f64;
        }
        Vary::Grow => {
            p[4] = 0.0;
            p[7] = 0.0;
            p[0] = alpha.iter().sum::<f64>() / n as f64;
            p[3] = p[0] + beta.iter().sum::<f64>() / n as f64;
        }
    }
    p
}

/// The parameters free in a search (`pivot`: the base point too). A
/// turning chain keeps its mean scale ratio: the steps would take up the
/// error of an origin that is nearly the base.
fn free(vary: Vary, pivot: bool) -> Vec<usize> {
    match vary {
        Vary::Turn if pivot => vec![0, 1, 3, 4, 7, 8, 9],
        Vary::Turn => vec![0, 1, 3, 4, 7],
        Vary::Grow => vec![0, 1, 2, 3, 5, 6],
    }
}

/// The members of chains for a fit (their rotations weigh at their radius).
fn members(insts: &[Inst], chains: &[Vec<usize>], turned: &Turned) -> Vec<Member> {
    chains
        .iter()
        .enumerate()
        .flat_map(|(g, c)| c.iter().map(move |&i| (g, i)))
        .map(|(g, i)| Member {
            group: g,
            frame: frame_of(insts, i, turned),
            lever: insts[i].size() / 2.5,
            rot_se: insts[i].rot_se,
            pos_se: insts[i].pos_se,
            tilted: false,
        })
        .collect()
}

/// Whether every member is drawn within the tolerance of where it is.
fn draws_back(
    insts: &[Inst],
    chains: &[Vec<usize>],
    p: &[f64],
    drawn: &[Frame],
    tol: Tolerance,
    turned: &Turned,
) -> bool {
    let mut k = 0;
    for c in chains {
        let n = c.len();
        for (q, &i) in c.iter().enumerate() {
            let Some(d) = drawn.get(k) else {
                return false;
            };
            // The step that led here (the first: the one that leaves it).
            let m = (n - 1 - q.saturating_sub(1)) as f64;
            let step = at(p, m).d.abs() * d.scale;
            if !close(d, &frame_of(insts, i, turned), step, insts[i].size(), tol) {
                return false;
            }
            k += 1;
        }
    }
    true
}

/// Zeroes changes too small to matter over the longest chain (`n`
/// transforms): under half the tolerance from one end to the other.
fn settle(p: &mut [f64], free: &mut Vec<usize>, n: f64, tol: Tolerance) {
    let small = |j: usize, p: &[f64]| match j {
        4 | 7 => p[j].abs() * n < tol.angle * 0.5,
        5 => p[j].abs() * n < tol.distance * 0.5 * p[1].abs().max(1e-12),
        6 => p[j].abs() * n < tol.scale * 0.5 * p[2].abs().max(1e-12),
        _ => false,
    };
    for j in [4, 5, 6, 7] {
        if free.contains(&j) && small(j, p) {
            p[j] = 0.0;
            free.retain(|&f| f != j);
        }
    }
    // A scale that stays within the tolerance over the chain is 1.
    if !free.contains(&6) && (p[2] - 1.0).abs() * n < tol.scale * 0.5 {
        p[2] = 1.0;
        free.retain(|&f| f != 2);
    }
}

/// One rule for `chains` (longest first): fitted to the longest, joined by
/// the others it draws back, fitted to all; `None` when nothing is left.
fn rule(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    chains: Vec<Vec<usize>>,
    tol: Tolerance,
    vary: Vary,
) -> Option<Candidate> {
    let first = chains.first()?;
    let frames: Vec<Frame> = first.iter().map(|&i| insts[i].frame).collect();
    let size = first.iter().map(|&i| insts[i].size()).sum::<f64>() / first.len() as f64;
    let lens = [first.len()];
    let model1 = |p: &[f64], out: &mut Vec<Frame>| model(p, &lens, out);
    let ms = members(insts, std::slice::from_ref(first), &Turned::new());
    // The frames' own origin first (the kind's origin may be the base
    // already), then the point the chain says the turtle turned about.
    let attempt = |q: DVec2, moves: bool| {
        let mut p = guess(&frames, q, vary, size);
        let mut free = free(vary, moves);
        let mut fit = Fit::new(&ms, 1, &model1, None);
        fit.solve_robust(&mut p, &free);
        settle(&mut p, &mut free, (first.len() - 1) as f64, tol);
        // Still linear: something changes.
        if !free.iter().any(|j| (4..8).contains(j)) {
            return None;
        }
        fit.solve(&mut p, &free);
        let (sol, _) = fit.result(&p, &free);
        if !draws_back(
            insts,
            std::slice::from_ref(first),
            &p,
            &sol.drawn,
            tol,
            &Turned::new(),
        ) {
            return None;
        }
        let off: f64 = ms
            .iter()
            .zip(&sol.drawn)
            .map(|(m, d)| m.frame.pos.distance_squared(d.pos))
            .sum();
        Some((p, free, (off / ms.len() as f64).sqrt() / size))
    };
    let own = attempt(DVec2::ZERO, false);
    let (p, free, _) = match own {
        // Within a hundredth of the elements' size: the origin is the base.
        Some(a) if a.2 < 0.01 || vary == Vary::Grow => a,
        _ => {
            let moved = pivot(&frames).and_then(|q| attempt(q, true));
            match (own, moved) {
                (Some(a), Some(b)) => {
                    if b.2 < a.2 {
                        b
                    } else {
                        a
                    }
                }
                (a, b) => a.or(b)?,
            }
        }
    };
    // Other chains the same rule draws back (each from its own best start).
    let mut kept = vec![first.clone()];
    for c in chains.iter().skip(1) {
        let lens = [c.len()];
        let model_c = |p: &[f64], out: &mut Vec<Frame>| model(p, &lens, out);
        let ms = members(insts, std::slice::from_ref(c), &Turned::new());
        let fit = Fit::new(&ms, 1, &model_c, None);
        let (sol, _) = fit.result(&p, &[]);
        if draws_back(
            insts,
            std::slice::from_ref(c),
            &p,
            &sol.drawn,
            tol,
            &Turned::new(),
        ) {
            kept.push(c.clone());
        }
    }
    // A sequence that ends in something else (Fig. 5 ends its leaves with a
    // bud): the chains with their tips, counted one further, first.
    let with_tips = (offset(&p).pos.length() <= 1e-9 * size)
        .then(|| tips(insts, edges, &kept, &p, tol))
        .flatten()
        .map(|(tips, turned)| {
            let chains: Vec<Vec<usize>> = kept
                .iter()
                .zip(tips)
                .map(|(c, t)| c.iter().copied().chain([t]).collect())
                .collect();
            (chains, shifted(&p), turned)
        });
    let (kept, p, sol) = with_tips
        .and_then(|(chains, p, turned)| finish(insts, &turned, chains, p, free.clone(), tol, size))
        .or_else(|| finish(insts, &Turned::new(), kept, p, free, tol, size))?;
    let t = at(&p, 0.0);
    let delta = Tr {
        alpha: p[4],
        d: p[5],
        s: p[6],
        beta: p[7],
    };
    let o = offset(&p);
    let place = (o.pos.length() > 1e-9 * size).then(|| Tr::between(&identity(), &o, 1.0));
    let reg = Regular {
        t: vec![t, delta],
        starts: sol.starts,
        rot_se: sol.rot_se,
        pos_se: sol.pos_se,
        drawn: sol.drawn,
        sigma2: sol.sigma2,
    }
    .checked()?;
    if !p.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut cand = seq_candidate(edges, index, kept, t, Some(delta), 1.0)?;
    if let Plan::Seq {
        place: pl, fitted, ..
    } = &mut cand.plan
    {
        *pl = place;
        *fitted = Some(reg);
    }
    Some(cand)
}

/// The rule fitted to all of `kept`, each number made as round as its
/// support allows (within the tolerance: the exact one unless
/// --symmetrize); `None` when it does not draw them all back.
fn finish(
    insts: &[Inst],
    turned: &Turned,
    kept: Vec<Vec<usize>>,
    mut p: Vec<f64>,
    mut free: Vec<usize>,
    tol: Tolerance,
    size: f64,
) -> Option<(Vec<Vec<usize>>, Vec<f64>, Solution)> {
    let lens: Vec<usize> = kept.iter().map(Vec::len).collect();
    let model_all = |p: &[f64], out: &mut Vec<Frame>| model(p, &lens, out);
    let ms = members(insts, &kept, turned);
    let mut fit = Fit::new(&ms, kept.len(), &model_all, None);
    if kept.len() > 1 {
        fit.solve_robust(&mut p, &free);
    } else {
        fit.solve(&mut p, &free);
    }
    round(&mut fit, &mut p, &mut free, tol, size);
    let (sol, _) = fit.result(&p, &free);
    draws_back(insts, &kept, &p, &sol.drawn, tol, turned).then_some((kept, p, sol))
}

/// Instances of symmetric kinds taken in another of their frames.
type Turned = BTreeMap<usize, Frame>;

fn frame_of(insts: &[Inst], i: usize, turned: &Turned) -> Frame {
    turned.get(&i).copied().unwrap_or(insts[i].frame)
}

/// The parameters counted one further: t'(m) = t(m − 1).
fn shifted(p: &[f64]) -> Vec<f64> {
    let mut q = p.to_vec();
    q[0] = p[0] - p[4];
    q[1] = p[1] - p[5];
    q[2] = p[2] - p[6];
    q[3] = p[3] - p[4] - p[7];
    q
}

/// The tip of each chain: where the rule would put a next member (after
/// the transform of counter 0, which the last member does not use), an instance of one other kind, the same for every chain; `None`
/// when a chain has none.
fn tips(
    insts: &[Inst],
    edges: &[Edge],
    chains: &[Vec<usize>],
    p: &[f64],
    tol: Tolerance,
) -> Option<(Vec<usize>, Turned)> {
    let a = insts[chains.first()?[0]].sym;
    let ends: BTreeMap<usize, usize> = chains
        .iter()
        .enumerate()
        .filter_map(|(c, ch)| Some((*ch.last()?, c)))
        .collect();
    let next = at(p, 0.0);
    let mut best: Vec<Option<(f64, usize, Frame)>> = vec![None; chains.len()];
    for e in edges {
        let Some(&c) = ends.get(&e.from) else {
            continue;
        };
        let b = &insts[e.to];
        if !b.alive || b.sym == a {
            continue;
        }
        let want = next.apply(&insts[e.from].frame);
        let step = next.d.abs() * want.scale;
        let Some(have) = b
            .variants(want.rot)
            .into_iter()
            .find(|f| close(&want, f, step, b.size(), tol))
        else {
            continue;
        };
        let off = want.pos.distance(have.pos);
        if best[c].is_none_or(|(o, _, _)| off < o) {
            best[c] = Some((off, e.to, have));
        }
    }
    let best: Vec<(f64, usize, Frame)> = best.into_iter().collect::<Option<_>>()?;
    let tips: Vec<usize> = best.iter().map(|b| b.1).collect();
    let turned: Turned = best.iter().map(|b| (b.1, b.2)).collect();
    let sym = insts[tips[0]].sym;
    let distinct: HashSet<usize> = tips.iter().copied().collect();
    (distinct.len() == tips.len() && tips.iter().all(|&i| insts[i].sym == sym))
        .then_some((tips, turned))
}

/// `--symmetrize`: each free number in turn snapped to the roundest value
/// within its support (three standard errors for angles, two for lengths
/// and scales, at most the tolerance), the rest refitted.
fn round(fit: &mut Fit, p: &mut [f64], free: &mut Vec<usize>, tol: Tolerance, size: f64) {
    for j in [7, 4, 6, 5, 3, 0, 2, 1] {
        let Some(k) = free.iter().position(|&f| f == j) else {
            continue;
        };
        let (_, se) = fit.result(p, free);
        let v = p[j];
        p[j] = match j {
            0 | 3 | 4 | 7 => nice_angle(v, (3.0 * se[k]).min(tol.angle)),
            2 | 6 => nice(v, (2.0 * se[k]).min(tol.scale * p[2].abs())),
            _ => nice(v, (2.0 * se[k]).min(tol.distance * p[1].abs().max(size))),
        };
        free.remove(k);
        fit.solve(p, free);
    }
}
