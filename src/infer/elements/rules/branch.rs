//! Branchings (the paper's r3/r4): complete trees of one kind whose children
//! come from two or three clusters of edges, one per transform.
//!
//! Owns: each cluster as a transform with a child per node (`Children`), the
//! depth of the complete tree below each node, the trees a set of clusters
//! draws (largest first, node-disjoint, each node where the averaged
//! transforms put it) and the tips of another kind at their leaves. A round
//! tries dozens of sets over every instance, so the per-node state lives in
//! arrays indexed by instance (no hashing, nothing allocated per root) and a
//! tree walk stops at its first node out of place. Must not choose among
//! candidates.

use super::{Candidate, Edge, Index, Inst, Plan, Tolerance, close, supported_mean};
use crate::infer::elements::shape::Frame;
use crate::infer::elements::space::Tr;
use std::collections::{HashMap, HashSet};

/// An empty slot of a per-instance array. Slots hold a number plus one, so
/// that the arrays start zeroed: the allocator hands out zeroed pages, and a
/// set of small clusters touches only the few it uses (a round tries
/// dozens of sets, and a drawing without repeats has dozens of rounds).
const NONE: u32 = 0;

/// One cluster of edges as a transform of branchings: each node's child by
/// it (the edge of lowest index out of the node), and the transform.
pub(super) struct Children {
    /// Per instance, its child plus one (`NONE`: it has none) and the edge to it.
    to: Vec<u32>,
    edge: Vec<u32>,
    /// The instances with a child, in increasing order.
    from: Vec<usize>,
    t: Tr,
}

impl Children {
    /// The children of `group` (edge indices) among `n` instances.
    pub(super) fn of(n: usize, edges: &[Edge], group: &[usize], tol: Tolerance) -> Children {
        let mut to = vec![NONE; n];
        let mut edge = vec![0u32; n];
        let mut sorted = group.to_vec();
        sorted.sort_unstable();
        let mut from = Vec::with_capacity(group.len());
        for k in sorted {
            let e = &edges[k];
            if to[e.from] == NONE {
                to[e.from] = e.to as u32 + 1;
                edge[e.from] = k as u32;
                from.push(e.from);
            }
        }
        from.sort_unstable();
        let ts: Vec<Tr> = group.iter().map(|&k| edges[k].t).collect();
        Children {
            to,
            edge,
            from,
            t: supported_mean(&ts, tol),
        }
    }

    /// The child of `v`, if it has one.
    fn child(&self, v: usize) -> Option<usize> {
        match self.to[v] {
            NONE => None,
            c => Some(c as usize - 1),
        }
    }
}

/// The edges out of each instance, in increasing order: the edges of
/// instance `v` are `list[start[v]..start[v + 1]]`.
pub(super) struct Outs {
    start: Vec<usize>,
    list: Vec<u32>,
}

impl Outs {
    pub(super) fn of(n: usize, edges: &[Edge]) -> Outs {
        let mut start = vec![0usize; n + 1];
        for e in edges {
            start[e.from + 1] += 1;
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; edges.len()];
        for (k, e) in edges.iter().enumerate() {
            list[fill[e.from]] = k as u32;
            fill[e.from] += 1;
        }
        Outs { start, list }
    }

    fn of_instance(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.list[self.start[v]..self.start[v + 1]]
            .iter()
            .map(|&k| k as usize)
    }
}

/// The depth of the complete tree below `v` whose children are the ends of
/// `groups[i]`'s edges (one per transform; 0 for a leaf), memoised in `memo`
/// plus one (`NONE`: not known yet). A node met again while its own depth is being
/// found (`open`: a cycle) counts as a leaf. Iterative, so that a long chain
/// cannot overflow the stack: each frame is one step of the recursive
/// definition `depth(v) = 1 + min_i depth(child_i(v))`.
fn depth_of(v: usize, groups: &[&Children], memo: &mut [u32], open: &mut [bool]) -> u32 {
    enum Step {
        /// Find the depth of this node.
        Enter(usize),
        /// Child `i` of the node is found; the least depth of its children so far.
        After(usize, usize, u32),
    }
    let child = |i: usize, v: usize| groups[i].child(v);
    let mut calls = vec![Step::Enter(v)];
    let mut found = 0;
    while let Some(step) = calls.pop() {
        match step {
            Step::Enter(v) => {
                if memo[v] != NONE {
                    found = memo[v] - 1;
                    continue;
                }
                let mut kids = [0usize; 3];
                let mut all = true;
                for (i, kid) in kids.iter_mut().enumerate().take(groups.len()) {
                    match child(i, v) {
                        Some(c) => *kid = c,
                        None => all = false,
                    }
                }
                let k = &kids[..groups.len()];
                let distinct = all && k.iter().enumerate().all(|(i, a)| !k[..i].contains(a));
                if distinct && !open[v] {
                    open[v] = true;
                    calls.push(Step::After(v, 0, u32::MAX));
                    calls.push(Step::Enter(k[0]));
                } else {
                    memo[v] = 1;
                    found = 0;
                }
            }
            Step::After(v, i, least) => {
                let least = least.min(found);
                let next = if i + 1 < groups.len() {
                    child(i + 1, v)
                } else {
                    None
                };
                match next {
                    Some(c) => {
                        calls.push(Step::After(v, i + 1, least));
                        calls.push(Step::Enter(c));
                    }
                    None => {
                        let d = least.saturating_add(1);
                        open[v] = false;
                        memo[v] = d.saturating_add(1);
                        found = d;
                    }
                }
            }
        }
    }
    found
}

/// Complete trees whose children come from `groups` (clusters of edges, one
/// per transform); `outs` are the round's edges by the instance they leave.
/// With `tips`, only trees with buds at their tips count.
#[allow(clippy::too_many_arguments)]
pub(super) fn branching(
    insts: &[Inst],
    edges: &[Edge],
    index: &Index,
    outs: &Outs,
    spots: &[(Frame, f64)],
    groups: &[&Children],
    tips: bool,
    tol: Tolerance,
) -> Option<Candidate> {
    if groups.len() > 3 {
        return None;
    }
    let n = insts.len();
    let both: Vec<usize> = groups[0]
        .from
        .iter()
        .copied()
        .filter(|&v| groups[1..].iter().all(|c| c.to[v] != NONE))
        .collect();
    if both.is_empty() {
        return None;
    }
    // Depth of the complete tree below each node.
    let mut depth = vec![NONE; n];
    let mut open = vec![false; n];
    for &v in &both {
        depth_of(v, groups, &mut depth, &mut open);
    }
    let mut roots: Vec<(usize, u32)> = both
        .iter()
        .map(|&v| (v, depth[v].saturating_sub(1)))
        .filter(|&(_, d)| d >= 1)
        .collect();
    roots.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let ts: Vec<Tr> = groups.iter().map(|g| g.t).collect();
    let mut claimed = vec![false; n];
    // The tree (numbered from 1) a node was last met in.
    let mut met = vec![0u32; n];
    let mut trees = Vec::new();
    let mut leaves: Vec<(usize, Frame)> = Vec::new();
    // The trees' links: transform, parent, child.
    let mut links: Vec<(usize, usize, usize)> = Vec::new();
    let mut pairs = 0;
    let mut gap = 0.0;
    let (mut nodes, mut level, mut below, mut walked) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (tag, (r, d)) in roots.into_iter().enumerate() {
        if claimed[r] {
            continue;
        }
        let tag = tag as u32 + 1;
        // The tree's nodes, level by level, redrawn from the root; the walk
        // ends at the first node out of place.
        nodes.clear();
        level.clear();
        walked.clear();
        nodes.push(r);
        level.push((r, spots[r].0));
        met[r] = tag;
        let mut ok = true;
        'walk: for _ in 0..d {
            below.clear();
            for &(v, f) in &level {
                for (i, (g, tr)) in groups.iter().zip(&ts).enumerate() {
                    let Some(c) = g.child(v) else {
                        ok = false;
                        break 'walk;
                    };
                    let want = tr.apply(&f);
                    let (frame, size) = &spots[c];
                    if claimed[c]
                        || met[c] == tag
                        || !close(&want, frame, tr.d * f.scale, *size, tol)
                    {
                        ok = false;
                        break 'walk;
                    }
                    below.push((c, want));
                    nodes.push(c);
                    walked.push((i, v, c));
                    met[c] = tag;
                }
            }
            std::mem::swap(&mut level, &mut below);
        }
        if !ok {
            continue;
        }
        for &v in &nodes {
            claimed[v] = true;
        }
        pairs += nodes.len() - 1;
        // The gaps of its links, in the order the walk met them.
        gap += walked.iter().fold(0.0, |sum, &(i, v, _)| {
            sum + edges[groups[i].edge[v] as usize].gap
        });
        trees.push((r, d));
        leaves.extend(level.iter().copied());
        links.extend(walked.iter().copied());
    }
    if trees.is_empty() {
        return None;
    }
    // Each tree node's children, one map per transform.
    let mut child: Vec<HashMap<usize, usize>> = vec![HashMap::new(); groups.len()];
    for &(i, v, c) in &links {
        child[i].insert(v, c);
    }
    let mut tip_at = None;
    let found = tree_tips(insts, edges, outs, &leaves, &ts, &claimed, tol);
    if tips && found.is_none() {
        return None;
    }
    if let Some((tips, at)) = found {
        for (&(leaf, _), below) in leaves.iter().zip(tips) {
            for (map, &(c, _)) in child.iter_mut().zip(&below) {
                map.insert(leaf, c);
                gap += index.get(&(leaf, c)).map_or(1.0, |&k| edges[k].gap);
            }
            if let Some(at) = at {
                let frames = tip_at.get_or_insert_with(|| (at, Vec::new()));
                frames.1.extend(below.iter().copied());
            }
        }
        pairs += ts.len() * leaves.len();
        for tree in &mut trees {
            tree.1 += 1;
        }
    }
    let length = trees.iter().map(|t| t.1 as f64 + 1.0).sum::<f64>() / trees.len() as f64;
    Some(Candidate {
        h: 1.0 - gap / pairs as f64,
        phi: 1.0,
        length,
        pairs,
        plan: Plan::Branch {
            trees,
            child,
            ts,
            tip_at,
        },
        hidden: false,
    })
}

/// Each leaf's tips, each with the frame it is drawn at, and the tips'
/// frame relative to where the transforms put a child (`None`: the same).
type Tips = (Vec<Vec<(usize, Frame)>>, Option<Frame>);

/// The tips of complete trees: where the transforms `tr` put the children
/// of every leaf (`leaves`, with their frames as the trees draw them), two
/// instances of one other kind that no tree claims (buds at the tips: the
/// `m == 0` rule draws them); `None` unless every leaf has both. A tip's
/// own frame may sit anywhere on it (a kind whose frame the drawing does
/// not give is framed at its centre): the tips count when every one sits
/// the same way relative to where a child would be, read from the first
/// leaf's first tip. Each leaf's edges are read in their order, so the
/// first of equally near ones wins.
fn tree_tips(
    insts: &[Inst],
    edges: &[Edge],
    outs: &Outs,
    leaves: &[(usize, Frame)],
    tr: &[Tr],
    claimed: &[bool],
    tol: Tolerance,
) -> Option<Tips> {
    let &(first, f) = leaves.first()?;
    let a = insts[first].sym;
    let bud = |k: usize| {
        let b = &insts[edges[k].to];
        b.alive && b.sym != a && !claimed[edges[k].to]
    };
    // Where the tips sit relative to a child: as a child, or as the first
    // leaf's candidates for its first tip sit.
    let want = tr.first()?.apply(&f);
    let mut relative = vec![Frame::IDENTITY];
    for k in outs.of_instance(first).filter(|&k| bud(k)) {
        for v in insts[edges[k].to].variants(want.rot) {
            relative.push(v.inverse().then(&want));
        }
    }
    relative.into_iter().find_map(|rel| {
        let tips = tips_at(insts, edges, outs, leaves, tr, &bud, &rel, tol)?;
        let sym = insts[tips[0][0].0].sym;
        let mut seen = HashSet::new();
        if !tips
            .iter()
            .flatten()
            .all(|&(i, ..)| insts[i].sym == sym && seen.insert(i))
        {
            return None;
        }
        // Where they sit, averaged over all tips (not one tip's noise).
        let rel = (rel != Frame::IDENTITY)
            .then(|| {
                let each: Vec<Frame> = tips
                    .iter()
                    .flatten()
                    .map(|(_, have, want)| have.inverse().then(want))
                    .collect();
                Frame::mean(&each)
            })
            .flatten();
        let at = rel.unwrap_or(Frame::IDENTITY);
        let tips = tips
            .into_iter()
            .map(|l| {
                l.into_iter()
                    .map(|(i, have, _)| (i, have.then(&at)))
                    .collect()
            })
            .collect();
        Some((tips, rel))
    })
}

/// Every leaf's tips when each sits at `rel` from where its child would be
/// (`None` if a leaf lacks one), each with its frame (the variant that fits)
/// and where its child would be from the leaf as drawn.
#[allow(clippy::too_many_arguments)]
fn tips_at(
    insts: &[Inst],
    edges: &[Edge],
    outs: &Outs,
    leaves: &[(usize, Frame)],
    tr: &[Tr],
    bud: &dyn Fn(usize) -> bool,
    rel: &Frame,
    tol: Tolerance,
) -> Option<Vec<Vec<(usize, Frame, Frame)>>> {
    let back = rel.inverse();
    let mut tips = Vec::with_capacity(leaves.len());
    for &(leaf, f) in leaves {
        // Every bud that sits where a side's child would: (offset, side,
        // bud, its frame, where the child would be from the leaf as drawn).
        let mut fits: Vec<(f64, usize, usize, Frame, Frame)> = Vec::new();
        for k in outs.of_instance(leaf).filter(|&k| bud(k)) {
            let b = &insts[edges[k].to];
            for (side, t) in tr.iter().enumerate() {
                let want = t.apply(&f);
                let step = t.d * f.scale;
                // The tip's frame where it would sit.
                let at = want.then(&back);
                let Some(have) = b
                    .variants(at.rot)
                    .into_iter()
                    .find(|v| close(&want, &v.then(rel), step, b.size(), tol))
                else {
                    continue;
                };
                let off = want.pos.distance(have.then(rel).pos);
                // Where the child would be from the leaf as drawn (the
                // tree's frames drift with depth).
                let near = t.apply(&insts[leaf].frame);
                fits.push((off, side, edges[k].to, have, near));
            }
        }
        // Nearest first, each bud on one side only (two like buds at one
        // place are one for each side, not one for both).
        fits.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Vec<Option<(usize, Frame, Frame)>> = vec![None; tr.len()];
        let mut used = Vec::new();
        for (_, side, i, have, near) in fits {
            if best[side].is_none() && !used.contains(&i) {
                best[side] = Some((i, have, near));
                used.push(i);
            }
        }
        // A leaf without both tips: no tree has tips.
        tips.push(best.into_iter().collect::<Option<Vec<_>>>()?);
    }
    Some(tips)
}
