//! The tips of a noisy branching drawing read as its other tips like them.
//!
//! A walk on the lattice pins an inner vertex down by everything drawn
//! after it, but a tip only by itself: under a fifth of a step of noise a
//! last step at 20° is read one δ off now and then (its two candidate ends
//! lie a third of a step apart), and one wrong tip among hundreds hides the
//! grammar from a search that matches step by step. The drawing's other
//! tips say which way it goes: a tree a D0L system draws repeats its
//! subtrees, so the wrong tip makes its parent's subtree (and its
//! ancestors') one of a kind. A small subtree at the drawing's ends (a tip,
//! a fork, a stalk of a few steps; or the first step from an end) is turned
//! by one δ, its steps placed again nearest the drawing, when that makes
//! the tree's distinct subtrees (its size as a DAG) fewer by more than the
//! move costs in the drawing's offsets from the walk and in its turns (all
//! in bits: a subtree said once, an offset as a normal spread of the walk's
//! own offsets, a turn as often as the tree turns it). The step into a
//! large subtree whose tree holds few steps besides (a short stalk at the
//! drawing's start) is weighed the other way round: the subtree stays and
//! the few steps move with the step's start. A step that one drawn segment
//! holds with its neighbour is not turned alone.
//!
//! Owns: the tips' second reading. Must not search grammars.

use super::{Graph, Lattice, Walked};
use glam::DVec2;
use std::collections::HashMap;

/// Chain steps (tip to root) the comparisons may take in all: a drawing
/// of deep chains and many tips is left as it was walked.
const WORK: usize = 4_000_000;

/// The most steps of a subtree at the drawing's ends read again as a
/// whole (a tip, a fork of two tips, a tip on a stalk).
const SMALL: usize = 8;

/// Passes over the tips (a turned tip can make another worth turning).
const PASSES: usize = 3;

/// `w` with the small subtrees at its ends turned where the drawing's
/// other subtrees agree (see the module's text); `w` as it is when the
/// drawing has a cycle or a vertex the walk did not place.
pub(super) fn agreed(g: &Graph, paths: &[Vec<u32>], lattice: &Lattice, w: Walked) -> Walked {
    let Some(mut f) = Forest::new(g, paths, lattice, &w.at) else {
        return w;
    };
    let Some(mut weigh) = Weigh::new(g, lattice, &w, &f) else {
        return w;
    };
    let mut at = w.at.clone();
    let ends = ends(g, &f);
    for _ in 0..PASSES {
        // The likeliest turns first, each weighed again when its turn
        // comes (a turn before it may have made it worthless: twin
        // subtrees, one misread, agree whichever of them turns).
        let mut gains: Vec<(f64, u32)> = ends
            .iter()
            .filter_map(|&v| Some((weigh.best(&mut f, &at, v)?.0, v)))
            .collect();
        gains.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut turned = false;
        for (_, v) in gains {
            let Some((_, mv)) = weigh.best(&mut f, &at, v) else {
                continue;
            };
            f.apply(&mv);
            for &(u, there) in &mv.points {
                if let Some(now) = at[u as usize] {
                    f.moved(now, there);
                }
                at[u as usize] = Some(there);
            }
            turned = true;
        }
        if !turned {
            break;
        }
    }
    Walked { at, ..w }
}

/// The small subtrees at the drawing's ends, each read again as a whole;
/// a first step that starts at an end; and the step into a large subtree
/// whose tree holds little else (a short stalk from the drawing's start,
/// read one δ off, moves the rest of the drawing with it: the stalk moves
/// instead). Not a step that one drawn segment holds with the step before
/// it or after it (the steps of a segment go its one way).
fn ends(g: &Graph, f: &Forest) -> Vec<u32> {
    let piece = |a: u32, b: u32| g.edge(a, b).map(|e| g.piece[e as usize]);
    let one = |a: u32, b: u32, c: u32| piece(a, b).is_some_and(|x| piece(b, c) == Some(x));
    let (sizes, trees) = f.sizes();
    (0..g.points.len() as u32)
        .filter(|&v| {
            let p = f.parent[v as usize];
            if p == NONE {
                let [c] = f.children[v as usize][..] else {
                    return false;
                };
                return !f.children[c as usize].iter().any(|&d| one(v, c, d));
            }
            let pp = f.parent[p as usize];
            if pp != NONE && one(pp, p, v) {
                return false;
            }
            let size = sizes[v as usize];
            if size <= SMALL {
                return true;
            }
            let rest = trees[v as usize] - size;
            rest <= SMALL && !f.children[v as usize].iter().any(|&c| one(p, v, c))
        })
        .collect()
}

/// What a move costs and gains, in bits.
struct Weigh<'a> {
    g: &'a Graph,
    lattice: &'a Lattice,
    w: &'a Walked,
    /// The offsets' variance per coordinate, as the walk's own spread.
    var: f64,
    /// A subtree said once: its children's turns and subtrees.
    node_bits: f64,
    /// How far an inner vertex, pinned by what is drawn after it, already
    /// is from the drawing: no moved vertex goes farther.
    worst: f64,
    /// Each turn's bits, as often as the forest turns it.
    turn_bits: Vec<f64>,
    /// Chain steps spent so far (see `WORK`).
    work: usize,
}

impl<'a> Weigh<'a> {
    fn new(g: &'a Graph, lattice: &'a Lattice, w: &'a Walked, f: &Forest) -> Option<Weigh<'a>> {
        let offsets: Vec<f64> = (0..g.points.len())
            .filter_map(|v| Some(w.frame.apply(g.points[v]).distance_squared(w.at[v]?)))
            .collect();
        if offsets.is_empty() {
            return None;
        }
        let m = lattice.units.len() as f64;
        Some(Weigh {
            g,
            lattice,
            w,
            var: (offsets.iter().sum::<f64>() / (2.0 * offsets.len() as f64)).max(1e-6),
            node_bits: (f.live.max(2) as f64).log2() + m.log2(),
            worst: (0..g.points.len())
                .filter(|&v| g.adj[v].len() > 1)
                .filter_map(|v| Some(w.frame.apply(g.points[v]).distance(w.at[v]?)))
                .fold(0.0, f64::max),
            turn_bits: f.turn_bits(),
            work: 0,
        })
    }

    fn seen(&self, u: u32) -> DVec2 {
        self.w.frame.apply(self.g.points[u as usize])
    }

    /// The best turn of the step into or out of end `v` now (a subtree
    /// placed again where the drawing has it): its gain in bits and what
    /// moves; none when no turn gains or the work is spent.
    fn best(&mut self, f: &mut Forest, at: &[Option<DVec2>], v: u32) -> Option<(f64, Move)> {
        let mut best: Option<(f64, Move)> = None;
        for dk in [-1, 1] {
            let mv = f.turned(v, dk, at, |u| self.seen(u), self.lattice)?;
            let mut cost = 0.0;
            for &(u, there) in &mv.points {
                let seen = self.seen(u);
                if seen.distance(there) > self.worst || f.taken_by_other(there, &mv.points, at) {
                    cost = f64::INFINITY;
                }
                cost += seen.distance_squared(there) - seen.distance_squared(at[u as usize]?);
            }
            if !cost.is_finite() {
                continue;
            }
            self.work += f.depth(v) + mv.ways.len();
            if self.work > WORK {
                return None;
            }
            let cost = cost / (2.0 * self.var) / std::f64::consts::LN_2
                + f.turns_cost(&mv, &self.turn_bits);
            let gain = f.fewer_if(&mv) as f64 * self.node_bits - cost;
            if gain > 0.0 && best.as_ref().is_none_or(|b| gain > b.0) {
                best = Some((gain, mv));
            }
        }
        best
    }
}

/// A part of the walk read again: the vertices whose way in changes
/// (parents before children) and those that move.
struct Move {
    ways: Vec<(u32, i64)>,
    points: Vec<(u32, DVec2)>,
}

const NONE: u32 = u32::MAX;

/// The drawing as a rooted forest on the lattice, each vertex's subtree
/// interned as a class (its children's turns and classes).
struct Forest {
    parent: Vec<u32>,
    children: Vec<Vec<u32>>,
    /// Each vertex's way in from its parent (a multiple of δ; roots: 0).
    way: Vec<i64>,
    class: Vec<u32>,
    classes: HashMap<Vec<(i64, u32)>, u32>,
    /// Vertices of each class.
    count: Vec<u32>,
    /// Classes with a vertex.
    live: usize,
    m: i64,
    /// Lattice points taken, rounded.
    points: HashMap<[i64; 2], u32>,
}

fn key(p: DVec2) -> [i64; 2] {
    [(p.x * 1e4).round() as i64, (p.y * 1e4).round() as i64]
}

impl Forest {
    fn new(
        g: &Graph,
        paths: &[Vec<u32>],
        lattice: &Lattice,
        at: &[Option<DVec2>],
    ) -> Option<Forest> {
        let n = g.points.len();
        let m = lattice.units.len() as i64;
        let mut parent = vec![NONE; n];
        let mut seen = vec![false; n];
        let mut children = vec![Vec::new(); n];
        let mut way = vec![0i64; n];
        let mut order = Vec::with_capacity(n);
        for root in paths.iter().filter_map(|p| p.first().copied()) {
            if seen[root as usize] {
                continue;
            }
            seen[root as usize] = true;
            let mut stack = vec![root];
            while let Some(v) = stack.pop() {
                order.push(v);
                for &(u, _) in &g.adj[v as usize] {
                    if u == parent[v as usize] {
                        continue;
                    }
                    if seen[u as usize] {
                        return None;
                    }
                    seen[u as usize] = true;
                    parent[u as usize] = v;
                    children[v as usize].push(u);
                    way[u as usize] = lattice
                        .nearest(at[u as usize]? - at[v as usize]?)
                        .rem_euclid(m);
                    stack.push(u);
                }
            }
        }
        let mut points = HashMap::new();
        for p in at.iter().flatten() {
            *points.entry(key(*p)).or_insert(0) += 1;
        }
        let mut f = Forest {
            parent,
            children,
            way,
            class: vec![0; n],
            classes: HashMap::new(),
            count: Vec::new(),
            live: 0,
            m,
            points,
        };
        for &v in order.iter().rev() {
            let c = f.intern(f.shape(v, &HashMap::new(), &HashMap::new()));
            f.class[v as usize] = c;
            f.add(c, 1);
        }
        Some(f)
    }

    /// The subtree of `v` as its children's turns and classes (`ways`,
    /// `classes`: some vertices' taken as others).
    fn shape(
        &self,
        v: u32,
        ways: &HashMap<u32, i64>,
        classes: &HashMap<u32, u32>,
    ) -> Vec<(i64, u32)> {
        let way = |u: u32| ways.get(&u).copied().unwrap_or(self.way[u as usize]);
        let from = if self.parent[v as usize] == NONE {
            0
        } else {
            way(v)
        };
        let mut s: Vec<(i64, u32)> = self.children[v as usize]
            .iter()
            .map(|&c| {
                let class = classes.get(&c).copied().unwrap_or(self.class[c as usize]);
                ((way(c) - from).rem_euclid(self.m), class)
            })
            .collect();
        s.sort_unstable();
        s
    }

    fn intern(&mut self, shape: Vec<(i64, u32)>) -> u32 {
        let next = self.classes.len() as u32;
        let c = *self.classes.entry(shape).or_insert(next);
        if c as usize >= self.count.len() {
            self.count.push(0);
        }
        c
    }

    fn add(&mut self, c: u32, by: i32) {
        let n = &mut self.count[c as usize];
        let was = *n;
        *n = n.saturating_add_signed(by);
        match (was, *n) {
            (0, k) if k > 0 => self.live += 1,
            (k, 0) if k > 0 => self.live -= 1,
            _ => {}
        }
    }

    fn depth(&self, mut v: u32) -> usize {
        let mut d = 0;
        while self.parent[v as usize] != NONE {
            v = self.parent[v as usize];
            d += 1;
        }
        d
    }

    fn moved(&mut self, from: DVec2, to: DVec2) {
        if let Some(n) = self.points.get_mut(&key(from)) {
            *n = n.saturating_sub(1);
        }
        *self.points.entry(key(to)).or_insert(0) += 1;
    }

    /// The vertices of `v`'s subtree, `v` first, parents before children.
    fn subtree(&self, v: u32) -> Vec<u32> {
        let mut out = vec![v];
        let mut i = 0;
        while i < out.len() {
            out.extend(self.children[out[i] as usize].iter().copied());
            i += 1;
        }
        out
    }

    /// How many vertices `v`'s subtree has, counted up to `most`.
    /// Each vertex's subtree's size, and the size of its whole tree.
    fn sizes(&self) -> (Vec<usize>, Vec<usize>) {
        let mut order: Vec<u32> = (0..self.parent.len() as u32)
            .filter(|&v| self.parent[v as usize] == NONE)
            .collect();
        let mut i = 0;
        while i < order.len() {
            order.extend(self.children[order[i] as usize].iter().copied());
            i += 1;
        }
        let mut size = vec![1usize; self.parent.len()];
        for &v in order.iter().rev() {
            let p = self.parent[v as usize];
            if p != NONE {
                size[p as usize] += size[v as usize];
            }
        }
        let mut tree = size.clone();
        for &v in &order {
            let p = self.parent[v as usize];
            if p != NONE {
                tree[v as usize] = tree[p as usize];
            }
        }
        (size, tree)
    }

    /// The root of `v`'s tree.
    fn root(&self, mut v: u32) -> u32 {
        while self.parent[v as usize] != NONE {
            v = self.parent[v as usize];
        }
        v
    }

    fn size(&self, v: u32, most: usize) -> usize {
        let mut stack = vec![v];
        let mut n = 0;
        while let Some(u) = stack.pop() {
            n += 1;
            if n >= most {
                return n;
            }
            stack.extend(self.children[u as usize].iter().copied());
        }
        n
    }

    /// End `v` turned by `dk` δ: a subtree's first step (the subtree
    /// placed again, every later step along the way nearest the drawing's
    /// vertex from where its parent now is), or the first step of a walk
    /// that starts at an end (the start moves).
    fn turned(
        &self,
        v: u32,
        dk: i64,
        at: &[Option<DVec2>],
        seen: impl Fn(u32) -> DVec2,
        lattice: &Lattice,
    ) -> Option<Move> {
        let p = self.parent[v as usize];
        if p == NONE {
            let c = self.children[v as usize][0];
            let k = (self.way[c as usize] + dk).rem_euclid(self.m);
            return Some(Move {
                ways: vec![(c, k)],
                points: vec![(v, at[c as usize]? - lattice.units[k as usize])],
            });
        }
        if self.size(v, SMALL + 1) > SMALL {
            return self.turned_rest(v, dk, at, lattice);
        }
        let base = at[p as usize]?;
        let mut mv = Move {
            ways: Vec::new(),
            points: Vec::new(),
        };
        for u in self.subtree(v) {
            let from = match mv.points.iter().find(|o| o.0 == self.parent[u as usize]) {
                Some(o) => o.1,
                None => base,
            };
            let way = if u == v {
                (self.way[v as usize] + dk).rem_euclid(self.m)
            } else {
                lattice.nearest(seen(u) - from).rem_euclid(self.m)
            };
            mv.ways.push((u, way));
            mv.points.push((u, from + lattice.units[way as usize]));
        }
        Some(mv)
    }

    /// The step into `v` turned by `dk` δ with `v`'s subtree where it is:
    /// the rest of its tree moves with the step's start, as it is.
    fn turned_rest(
        &self,
        v: u32,
        dk: i64,
        at: &[Option<DVec2>],
        lattice: &Lattice,
    ) -> Option<Move> {
        let p = self.parent[v as usize];
        let k = (self.way[v as usize] + dk).rem_euclid(self.m);
        let by = at[v as usize]? - lattice.units[k as usize] - at[p as usize]?;
        let mut points = Vec::new();
        let mut stack = vec![self.root(v)];
        while let Some(u) = stack.pop() {
            points.push((u, at[u as usize]? + by));
            if points.len() > SMALL {
                return None;
            }
            stack.extend(self.children[u as usize].iter().filter(|&&c| c != v));
        }
        Some(Move {
            ways: vec![(v, k)],
            points,
        })
    }

    /// Whether a vertex that does not move is at `p` (`at`: where each is
    /// now).
    fn taken_by_other(&self, p: DVec2, moving: &[(u32, DVec2)], at: &[Option<DVec2>]) -> bool {
        let own = moving
            .iter()
            .filter(|&&(u, _)| at[u as usize].is_some_and(|q| key(q) == key(p)))
            .count() as u32;
        self.points.get(&key(p)).is_some_and(|&n| n > own)
    }

    /// Bits of each turn (0..m) as often as the forest turns it.
    fn turn_bits(&self) -> Vec<f64> {
        let mut n = vec![0.5f64; self.m as usize];
        for (u, &p) in self.parent.iter().enumerate() {
            if p != NONE && self.parent[p as usize] != NONE {
                n[(self.way[u] - self.way[p as usize]).rem_euclid(self.m) as usize] += 1.0;
            }
        }
        let total: f64 = n.iter().sum();
        n.iter().map(|c| -(c / total).log2()).collect()
    }

    /// What `mv` changes in the bits of the forest's turns (those into and
    /// out of the vertices whose way changes).
    fn turns_cost(&self, mv: &Move, bits: &[f64]) -> f64 {
        let ways: HashMap<u32, i64> = mv.ways.iter().copied().collect();
        let mut touched: Vec<u32> = mv.ways.iter().map(|w| w.0).collect();
        for &(u, _) in &mv.ways {
            touched.extend(self.children[u as usize].iter().copied());
        }
        touched.sort_unstable();
        touched.dedup();
        let mut delta = 0.0;
        for u in touched {
            let p = self.parent[u as usize];
            if p == NONE || self.parent[p as usize] == NONE {
                continue;
            }
            let turn = |w: &dyn Fn(u32) -> i64| (w(u) - w(p)).rem_euclid(self.m) as usize;
            let old = turn(&|x| self.way[x as usize]);
            let new = turn(&|x| ways.get(&x).copied().unwrap_or(self.way[x as usize]));
            delta += bits[new] - bits[old];
        }
        delta
    }

    /// The classes of the vertices whose way `mv` changes (children first)
    /// and of the first one's ancestors, each with its class now and were
    /// `mv` done.
    fn reclassed(&mut self, mv: &Move) -> Vec<(u32, u32, u32)> {
        let ways: HashMap<u32, i64> = mv.ways.iter().copied().collect();
        let mut classes: HashMap<u32, u32> = HashMap::new();
        let mut out = Vec::new();
        for &(u, _) in mv.ways.iter().rev() {
            let c = self.intern(self.shape(u, &ways, &classes));
            classes.insert(u, c);
            out.push((u, self.class[u as usize], c));
        }
        let Some(&(top, _)) = mv.ways.first() else {
            return out;
        };
        let mut x = self.parent[top as usize];
        while x != NONE {
            let c = self.intern(self.shape(x, &ways, &classes));
            classes.insert(x, c);
            out.push((x, self.class[x as usize], c));
            x = self.parent[x as usize];
        }
        out
    }

    /// How many fewer classes the forest would have were `mv` done
    /// (negative: more).
    fn fewer_if(&mut self, mv: &Move) -> i64 {
        let changes = self.reclassed(mv);
        let before = self.live as i64;
        for &(_, old, new) in &changes {
            self.add(old, -1);
            self.add(new, 1);
        }
        let after = self.live as i64;
        for &(_, old, new) in &changes {
            self.add(new, -1);
            self.add(old, 1);
        }
        before - after
    }

    fn apply(&mut self, mv: &Move) {
        let changes = self.reclassed(mv);
        for &(u, k) in &mv.ways {
            self.way[u as usize] = k;
        }
        for (x, old, new) in changes {
            self.add(old, -1);
            self.add(new, 1);
            self.class[x as usize] = new;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Similarity, paths};
    use super::*;

    fn unit(deg: f64) -> DVec2 {
        DVec2::new(deg.to_radians().cos(), deg.to_radians().sin())
    }

    /// A stalk of two steps (one segment) along +x, then at its top a tree
    /// at 20° drawn step by step, a polyline per branch.
    fn drawing() -> Vec<Vec<DVec2>> {
        let mut lines = vec![vec![DVec2::ZERO, 2.0 * unit(0.0)]];
        let (mut at, mut heading) = (2.0 * unit(0.0), 20.0);
        let mut stack = Vec::new();
        lines.push(vec![at]);
        for c in "F[+F[+F]F[-F]F]F[-F[+F]F[-F]F]F[+F]F".chars() {
            match c {
                '+' => heading += 20.0,
                '-' => heading -= 20.0,
                '[' => {
                    stack.push((at, heading));
                    lines.push(vec![at]);
                }
                ']' => {
                    (at, heading) = stack.pop().expect("balanced");
                    lines.push(vec![at]);
                }
                _ => {
                    at += unit(heading);
                    lines.last_mut().expect("a line").push(at);
                }
            }
        }
        lines.retain(|l| l.len() > 1);
        lines
    }

    #[test]
    fn a_stalk_read_one_delta_off_moves_back_and_the_tree_above_it_stays() {
        let g = crate::infer::lines::graph::build(&drawing(), 1).expect("a stroke graph");
        let lattice = Lattice::new(18);
        let vertex = |p: DVec2| {
            (0..g.points.len())
                .min_by(|&a, &b| g.points[a].distance(p).total_cmp(&g.points[b].distance(p)))
                .expect("vertices")
        };
        let truth: Vec<Option<DVec2>> = g.points.iter().map(|&p| Some(p)).collect();
        // The stalk as if the step from its top into the tree were read at
        // 40°, not 20°: the tree where the drawing has it, the stalk off.
        let (top, first) = (
            vertex(2.0 * unit(0.0)),
            vertex(2.0 * unit(0.0) + unit(20.0)),
        );
        let by = g.points[first] - unit(40.0) - g.points[top];
        let mut at = truth.clone();
        for p in [DVec2::ZERO, unit(0.0), 2.0 * unit(0.0)] {
            at[vertex(p)] = Some(p + by);
        }
        let walked = Walked {
            at,
            frame: Similarity {
                from: DVec2::ZERO,
                turn: DVec2::new(1.0, 0.0),
                to: DVec2::ZERO,
            },
            bits: 0.0,
        };
        let agreed = agreed(&g, &paths(&g), &lattice, walked);
        for (v, (got, want)) in agreed.at.iter().zip(&truth).enumerate() {
            let (got, want) = (got.expect("placed"), want.expect("placed"));
            assert!(
                got.distance(want) < 1e-6,
                "vertex {v} at {got}, drawn at {want}"
            );
        }
    }
}
