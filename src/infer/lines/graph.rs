//! The stroke graph of a line drawing: its segments as a set, whatever the
//! order, direction or splitting of the paths that drew them.
//!
//! Every segment of every path is taken; endpoints closer than a tolerance
//! taken from the drawing's own scale (a fraction of its shortest segment)
//! are one vertex; a vertex that lies on another segment splits it (a
//! branch that starts mid-segment); every piece is cut into unit steps of
//! the drawing's step length, and the points between steps become vertices
//! too (so two strokes that cross or touch at a lattice point meet there).
//! The graph also says how noisy the drawing is (how far its points lie
//! from their vertices) and the smallest turn its rays make (δ₀).
//!
//! Owns: the graph, its unit edges and the lookups a search needs (the
//! vertex near a point, the edge between two vertices). Must not order the
//! drawing or search grammars.

use crate::geometry::index::PointGrid;
use glam::DVec2;
use std::collections::HashMap;

/// The most unit edges a graph is built with.
pub const MAX_EDGES: usize = 1_000_000;

/// How near (in shortest segments) two endpoints must be to be one vertex.
const SNAP: f64 = 0.3;

/// How far (in steps) a piece may be from a whole number of steps.
const WHOLE: f64 = 0.3;

/// A line drawing as a graph of unit steps.
pub struct Graph {
    /// The step length, user units.
    pub step: f64,
    /// Vertices, world coordinates.
    pub points: Vec<DVec2>,
    /// Unit edges, as vertex pairs.
    pub edges: Vec<[u32; 2]>,
    /// Each vertex's (neighbour, edge).
    pub adj: Vec<Vec<(u32, u32)>>,
    /// Each edge's piece: how many steps long the drawn segment it was cut
    /// from is (a long segment says its steps' direction more surely than
    /// a noisy one-step segment does).
    pub runs: Vec<u32>,
    /// Each edge's piece: which drawn segment (after cutting where others
    /// meet it) it was cut from. The steps of one piece go one way.
    pub piece: Vec<u32>,
    /// How far the drawing's points lie from their vertices: the root mean
    /// square, in steps.
    pub noise: f64,
    /// The smallest turn between rays, degrees (δ or a part of it).
    pub delta: f64,
    /// How near (user units) a point must be to a vertex to be it.
    pub tol: f64,
    /// Every unit step as the drawing's paths draw it, in their order and
    /// direction (a step drawn twice is here twice): what a search follows
    /// when the paths come in the order a turtle drew them.
    pub order: Vec<(u32, u32)>,
    grid: PointGrid,
    edge_of: HashMap<(u32, u32), u32>,
}

impl std::fmt::Debug for Graph {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Graph")
            .field("step", &self.step)
            .field("vertices", &self.points.len())
            .field("edges", &self.edges.len())
            .field("noise", &self.noise)
            .field("delta", &self.delta)
            .finish()
    }
}

impl Graph {
    /// The vertex nearest `p` within the tolerance.
    pub fn vertex_at(&self, p: DVec2) -> Option<u32> {
        self.grid
            .within(p, self.tol)
            .into_iter()
            .min_by(|&a, &b| {
                p.distance_squared(self.points[a])
                    .total_cmp(&p.distance_squared(self.points[b]))
            })
            .map(|v| v as u32)
    }

    /// The edge between vertices `a` and `b`.
    pub fn edge(&self, a: u32, b: u32) -> Option<u32> {
        self.edge_of.get(&(a.min(b), a.max(b))).copied()
    }

    /// The direction of edge `e` leaving vertex `from`, radians.
    pub fn direction(&self, e: u32, from: u32) -> f64 {
        let [a, b] = self.edges[e as usize];
        let to = if a == from { b } else { a };
        let d = self.points[to as usize] - self.points[from as usize];
        d.y.atan2(d.x)
    }

    /// The one walk that draws every edge once, when the drawing is one
    /// curve (every vertex on at most two edges, all of them connected): from
    /// one of its ends, or round it when it is closed (`true`), from the
    /// lowest vertex. A drawing whose steps came in any order and direction
    /// is read back as the curve it is.
    pub fn chain(&self) -> Option<(Vec<(u32, u32)>, bool)> {
        if self.adj.iter().any(|a| a.len() > 2) || self.edges.is_empty() {
            return None;
        }
        let ends = self.adj.iter().filter(|a| a.len() == 1).count();
        let first = self
            .adj
            .iter()
            .position(|a| a.len() == 1)
            .or_else(|| self.adj.iter().position(|a| !a.is_empty()))?;
        let mut used = vec![false; self.edges.len()];
        let mut walk = Vec::with_capacity(self.edges.len());
        let mut at = first as u32;
        while let Some(&(to, e)) = self.adj[at as usize]
            .iter()
            .find(|(_, e)| !used[*e as usize])
        {
            used[e as usize] = true;
            walk.push((at, to));
            at = to;
        }
        (walk.len() == self.edges.len()).then_some((walk, ends == 0))
    }

    /// Whether one stroke can draw every edge once (an Euler trail): the
    /// edges are connected and at most two vertices have an odd number.
    pub fn one_stroke(&self) -> bool {
        let odd = self.adj.iter().filter(|a| a.len() % 2 == 1).count();
        odd <= 2 && self.connected()
    }

    /// Whether every edge can be reached from every other.
    pub fn connected(&self) -> bool {
        let Some(first) = self.adj.iter().position(|a| !a.is_empty()) else {
            return false;
        };
        let mut seen = vec![false; self.points.len()];
        let mut stack = vec![first];
        seen[first] = true;
        let mut reached = 0;
        while let Some(v) = stack.pop() {
            reached += self.adj[v].len();
            for &(nb, _) in &self.adj[v] {
                if !seen[nb as usize] {
                    seen[nb as usize] = true;
                    stack.push(nb as usize);
                }
            }
        }
        reached == 2 * self.edges.len()
    }

    /// Steps (from, to) in order as polylines: a new one wherever a step
    /// does not start where the last ended.
    pub fn polylines(&self, steps: impl Iterator<Item = (u32, u32)>) -> Vec<Vec<DVec2>> {
        let mut out: Vec<Vec<DVec2>> = Vec::new();
        let mut at = u32::MAX;
        for (a, b) in steps {
            if a != at {
                out.push(vec![self.points[a as usize]]);
            }
            if let Some(l) = out.last_mut() {
                l.push(self.points[b as usize]);
            }
            at = b;
        }
        out
    }

    /// The drawing's diagonal, user units.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.points.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        if self.points.is_empty() {
            0.0
        } else {
            lo.distance(hi)
        }
    }
}

/// Union–find over indices.
struct Sets(Vec<u32>);

impl Sets {
    fn new(n: usize) -> Sets {
        Sets((0..n as u32).collect())
    }
    fn find(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let up = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = up;
            i = up;
        }
        i
    }
    fn join(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
    }
}

/// Points within `tol` of each other (transitively) as one: each point's
/// cluster and the clusters' mean positions.
fn cluster(points: &[DVec2], tol: f64) -> (Vec<u32>, Vec<DVec2>) {
    let grid = PointGrid::with_cell(points, tol);
    let mut sets = Sets::new(points.len());
    for (i, p) in points.iter().enumerate() {
        for j in grid.within(*p, tol) {
            if j > i {
                sets.join(i as u32, j as u32);
            }
        }
    }
    let mut index: HashMap<u32, u32> = HashMap::new();
    let mut sums: Vec<(DVec2, f64)> = Vec::new();
    let mut of = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let root = sets.find(i as u32);
        let k = *index.entry(root).or_insert_with(|| {
            sums.push((DVec2::ZERO, 0.0));
            sums.len() as u32 - 1
        });
        sums[k as usize].0 += *p;
        sums[k as usize].1 += 1.0;
        of.push(k);
    }
    let means = sums.into_iter().map(|(s, n)| s / n).collect();
    (of, means)
}

/// How near two endpoints must be to be one vertex, from the drawing's own
/// noise: endpoints that stand for one point lie closer to each other than
/// any two distinct points of the drawing, so the distances from each
/// endpoint to its nearest other endpoint fall in two groups with a jump
/// between them; the tolerance lies in that jump (at most `SNAP` steps, at
/// least a twentieth of a step for drawings whose points are never shared).
fn snap_tolerance(ends: &[DVec2], unit: f64) -> f64 {
    let grid = PointGrid::new(ends);
    let mut near: Vec<f64> = ends
        .iter()
        .filter_map(|p| grid.nearest(*p, 2).get(1).map(|&j| p.distance(ends[j])))
        .filter(|&d| d < 0.35 * unit)
        .collect();
    near.sort_by(f64::total_cmp);
    if near.is_empty() {
        return 0.05 * unit;
    }
    let floor = 1e-4 * unit;
    let mut best: Option<(f64, f64)> = None;
    for w in near.windows(2) {
        let ratio = w[1].max(floor) / w[0].max(floor);
        if ratio > 8.0 && best.is_none_or(|(r, _)| ratio > r) {
            best = Some((ratio, (w[0].max(floor) * w[1]).sqrt()));
        }
    }
    let tol = match best {
        Some((_, t)) => t,
        // One group: all noise (a jittered drawing) or all distinct points.
        None => 1.5 * near[near.len() - 1],
    };
    tol.clamp(1e-6 * unit, SNAP * unit)
}

/// The length of one step as the short segments show it: the median of
/// the segments no longer than 1.4 times the twentieth-shortest (noise
/// makes the very shortest shorter than a step).
fn unit_length(ends: &[DVec2]) -> f64 {
    let lengths: Vec<f64> = ends.chunks(2).map(|c| c[0].distance(c[1])).collect();
    unit_length_of(&lengths)
}

fn unit_length_of(lengths: &[f64]) -> f64 {
    let mut l: Vec<f64> = lengths.to_vec();
    l.sort_by(f64::total_cmp);
    let Some(&low) = l.get(l.len() / 20) else {
        return 0.0;
    };
    let short: Vec<f64> = l.iter().copied().take_while(|&x| x <= 1.4 * low).collect();
    short.get(short.len() / 2).copied().unwrap_or(low)
}

/// The step length of pieces of `lengths`: every piece a whole number of
/// steps. First from `unit` (one step as the short pieces show it), then
/// from ever longer pieces (a long piece pins the step down better once its
/// count of steps is known), then the step near that which puts the pieces
/// nearest whole numbers of steps when the drawing is noisy (its short
/// pieces are poor witnesses, its long ones good ones).
pub fn step_of(lengths: &[f64], split: u32, unit: f64) -> f64 {
    let longest = lengths.iter().copied().fold(0.0, f64::max);
    let mut step = unit / f64::from(split.max(1));
    let mut limit = 4.0;
    loop {
        let (mut sum, mut units) = (0.0, 0.0);
        for &len in lengths {
            let u = len / step;
            if u <= limit + 0.5 {
                sum += len;
                units += u.round().max(1.0);
            }
        }
        if units > 0.0 {
            step = sum / units;
        }
        if longest / step <= limit || !step.is_finite() {
            break;
        }
        limit *= 4.0;
    }
    if noisy(lengths, step) {
        best_fit(lengths, step)
    } else {
        step
    }
}

/// How far pieces are from whole numbers of `step`: the sum of squares, in
/// steps.
fn misfit(lengths: &[f64], step: f64) -> f64 {
    lengths
        .iter()
        .map(|&len| {
            let u = len / step;
            (u - u.round().max(1.0)).powi(2)
        })
        .sum()
}

/// The step within 10 % of `step` that fits the pieces best (a sample of
/// them: the longest and an even spread of the rest), then refined by least
/// squares with each piece's count of steps fixed.
fn best_fit(lengths: &[f64], step: f64) -> f64 {
    if !(step.is_finite() && step > 0.0) || lengths.is_empty() {
        return step;
    }
    let mut sorted = lengths.to_vec();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let mut sample: Vec<f64> = sorted.iter().copied().take(200).collect();
    let rest = &sorted[sample.len()..];
    let stride = (rest.len() / 200).max(1);
    sample.extend(rest.iter().step_by(stride).copied());
    let mut best = (misfit(&sample, step), step);
    let mut s = 0.9 * step;
    while s <= 1.1 * step {
        let m = misfit(&sample, s);
        if m < best.0 {
            best = (m, s);
        }
        s *= 1.0 + 2e-4;
    }
    let (mut num, mut den) = (0.0, 0.0);
    for &len in lengths {
        let k = (len / best.1).round().max(1.0);
        num += len * k;
        den += k * k;
    }
    let refined = if den > 0.0 { num / den } else { best.1 };
    if refined.is_finite() && misfit(&sample, refined) <= misfit(&sample, step) {
        refined
    } else {
        step
    }
}

/// How far a piece may be from a whole number of steps: `WHOLE`, or any
/// distance in a noisy drawing (whose long pieces may be off by half a
/// step; they are rounded, and the grammar's redraw judges the result).
fn whole_tolerance(lengths: &[f64], step: f64) -> f64 {
    if noisy(lengths, step) { 0.5 } else { WHOLE }
}

/// Whether the pieces about one step long spread by more than 5 % about it
/// (a jittered or hand-traced drawing).
fn noisy(lengths: &[f64], step: f64) -> bool {
    let ones: Vec<f64> = lengths
        .iter()
        .map(|&l| l / step)
        .filter(|u| (0.75..1.25).contains(u))
        .collect();
    if ones.len() < 8 {
        return false;
    }
    let spread = (ones.iter().map(|u| (u - 1.0).powi(2)).sum::<f64>() / ones.len() as f64).sqrt();
    spread > 0.05
}

/// Pieces of segments, each split where a vertex lies on it.
fn pieces(segs: &[(u32, u32)], points: &[DVec2], tol: f64, unit: f64) -> Vec<(u32, u32)> {
    // Samples along each segment `h` apart: a vertex within `tol` of the
    // segment lies within h/2 + tol of a sample.
    let h = 0.5 * unit.max(tol);
    let grid = PointGrid::with_cell(points, h);
    // How near a whole number of steps, from the drawing's own tolerance:
    // at 72° and 36° a vertex can lie on a step 1.236 or 0.764 steps
    // along it (where another stroke crosses it), which is not a touch.
    let whole = (3.0 * tol / unit).clamp(0.02, WHOLE);
    let mut out = Vec::with_capacity(segs.len());
    for &(a, b) in segs {
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let d = pb - pa;
        let len2 = d.length_squared();
        let len = len2.sqrt();
        let mut on: Vec<(f64, u32)> = Vec::new();
        let samples = (len / h).ceil().max(1.0) as usize;
        for k in 0..=samples {
            let c = pa.lerp(pb, k as f64 / samples as f64);
            for v in grid.within(c, 0.5 * h + tol) {
                let v = v as u32;
                if v == a || v == b {
                    continue;
                }
                let p = points[v as usize];
                let t = (p - pa).dot(d) / len2;
                if t * len <= tol || (1.0 - t) * len <= tol {
                    continue;
                }
                // A stroke that starts or touches mid-segment does so a
                // whole number of steps along it (a vertex merely near a
                // segment, as turns by small angles bring them, does not).
                let along = t * len / unit;
                let rest = len / unit - along;
                if along.round() < 1.0
                    || rest.round() < 1.0
                    || (along - along.round()).abs() > whole
                {
                    continue;
                }
                if (pa + d * t).distance(p) <= tol {
                    on.push((t, v));
                }
            }
        }
        on.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        on.dedup_by_key(|x| x.1);
        let mut from = a;
        for (_, v) in on {
            if v != from {
                out.push((from, v));
                from = v;
            }
        }
        if from != b {
            out.push((from, b));
        }
    }
    out
}

/// The stroke graph of `lines` (world coordinates), with steps `split`
/// to the shortest piece. An error says why the drawing is not steps of one
/// length.
pub fn build(lines: &[Vec<DVec2>], split: u32) -> Result<Graph, String> {
    let mut ends: Vec<DVec2> = Vec::new();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for l in lines {
        for p in l {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
    }
    let scale = (hi - lo).max_element().max(1e-300);
    // A segment drawn exactly again more than once, either way (copies of
    // one `<use>` stacked in one place), counts twice: a turtle that goes
    // back over a step draws it twice (the paths' order keeps both), and
    // 90,000 copies of 46 segments would crowd the clustering.
    let mut seen: HashMap<_, u8> = HashMap::new();
    let key = |p: DVec2| (p.x.to_bits(), p.y.to_bits());
    for l in lines {
        for w in l.windows(2) {
            let (a, b) = (key(w[0]), key(w[1]));
            let times = seen.entry((a.min(b), a.max(b))).or_insert(0);
            *times = times.saturating_add(1);
            if w[0].distance(w[1]) > 1e-9 * scale && *times <= 2 {
                ends.push(w[0]);
                ends.push(w[1]);
            }
        }
    }
    if ends.is_empty() {
        return Err("no segment has a length".into());
    }
    let unit = unit_length(&ends) / f64::from(split.max(1));
    let tol = snap_tolerance(&ends, unit);
    let (of, points) = cluster(&ends, tol);
    let segs: Vec<(u32, u32)> = of
        .chunks(2)
        .filter(|c| c[0] != c[1])
        .map(|c| (c[0], c[1]))
        .collect();
    let parts = pieces(&segs, &points, tol, unit);
    let lengths: Vec<f64> = parts
        .iter()
        .map(|&(a, b)| points[a as usize].distance(points[b as usize]))
        .collect();
    let step = step_of(&lengths, split, unit_length_of(&lengths));
    if !(step.is_finite() && step > 0.0) {
        return Err("no segment has a length".into());
    }
    // Cut every piece into unit steps; the points between steps join the
    // vertices (where strokes cross or touch at a lattice point).
    let mut all = points.clone();
    let mut chains: Vec<(Vec<u32>, u32)> = Vec::with_capacity(parts.len());
    let mut total = 0usize;
    let whole = whole_tolerance(&lengths, step);
    for (&(a, b), &len) in parts.iter().zip(&lengths) {
        let u = len / step;
        let r = u.round();
        if r < 1.0 || (u - r).abs() > whole {
            return Err(format!(
                "a segment of {:.4} is not a whole number of steps of {:.4}",
                len, step
            ));
        }
        total = total.saturating_add(r as usize);
        if total > MAX_EDGES {
            return Err(format!("more than {MAX_EDGES} steps of equal length"));
        }
        let mut chain = vec![a];
        let (pa, pb) = (points[a as usize], points[b as usize]);
        for k in 1..r as usize {
            all.push(pa.lerp(pb, k as f64 / r));
            chain.push(all.len() as u32 - 1);
        }
        chain.push(b);
        chains.push((chain, r as u32));
    }
    let (of2, vertices) = cluster(&all, tol.min(0.3 * step));
    let mut edge_of: HashMap<(u32, u32), u32> = HashMap::new();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut adj: Vec<Vec<(u32, u32)>> = vec![Vec::new(); vertices.len()];
    let mut runs = Vec::new();
    let mut piece = Vec::new();
    let mut order = Vec::with_capacity(total);
    for (i, (chain, run)) in chains.iter().enumerate() {
        for w in chain.windows(2) {
            let (a, b) = (of2[w[0] as usize], of2[w[1] as usize]);
            if a == b {
                continue;
            }
            order.push((a, b));
            let key = (a.min(b), a.max(b));
            if edge_of.contains_key(&key) {
                continue;
            }
            let e = edges.len() as u32;
            edge_of.insert(key, e);
            edges.push([a, b]);
            runs.push(*run);
            piece.push(i as u32);
            adj[a as usize].push((b, e));
            adj[b as usize].push((a, e));
        }
    }
    // Noise: how far the drawing's own points lie from their vertices.
    let (mut ss, mut n) = (0.0f64, 0.0f64);
    for (i, p) in ends.iter().enumerate() {
        let v = of2[of[i] as usize];
        ss += p.distance_squared(vertices[v as usize]);
        n += 1.0;
    }
    // And how far the unit edges' lengths spread about the step (points
    // drawn once show their noise only there).
    let (mut sl, mut nl) = (0.0f64, 0.0f64);
    for [a, b] in &edges {
        let len = vertices[*a as usize].distance(vertices[*b as usize]);
        sl += (len / step - 1.0).powi(2);
        nl += 1.0;
    }
    let noise = ((ss / n.max(1.0)).sqrt() / step).max((sl / nl.max(1.0)).sqrt());
    let grid = PointGrid::with_cell(&vertices, tol.min(0.3 * step));
    let mut g = Graph {
        step,
        points: vertices,
        edges,
        adj,
        runs,
        piece,
        noise,
        delta: 0.0,
        tol: tol.min(0.3 * step),
        order,
        grid,
        edge_of,
    };
    g.delta = smallest_turn(&g);
    Ok(g)
}

/// The turns the drawing shows, degrees: at each vertex of two edges, the
/// turn a walk through it makes (180° less the angle between its rays); and
/// at other vertices, the angles between two rays folded into [0°, 90°]
/// (either that angle or 180° less it is a turn).
pub fn turns(g: &Graph) -> (Vec<f64>, Vec<f64>) {
    let (mut two, mut others) = (Vec::new(), Vec::new());
    let angle = |a: f64, b: f64| {
        let d = (a - b).rem_euclid(360.0);
        if d > 180.0 { 360.0 - d } else { d }
    };
    for (v, nb) in g.adj.iter().enumerate() {
        let dirs: Vec<f64> = nb
            .iter()
            .map(|&(_, e)| g.direction(e, v as u32).to_degrees())
            .collect();
        if dirs.len() == 2 {
            two.push(180.0 - angle(dirs[0], dirs[1]));
            continue;
        }
        for i in 0..dirs.len().min(8) {
            for j in i + 1..dirs.len().min(8) {
                let a = angle(dirs[i], dirs[j]);
                others.push(a.min(180.0 - a));
            }
        }
    }
    (two, others)
}

/// δ₀: the turns' smallest common unit (see `read::delta_from_turns`).
/// Turns at two-edge vertices are true turns: they are used alone when at
/// least 8 of them bend, or all that there are bend; else every angle.
fn smallest_turn(g: &Graph) -> f64 {
    let (mut two, others) = turns(g);
    let bending = two.iter().filter(|t| t.abs() > 1.0).count();
    if !(bending >= 8 || bending > 0 && bending == two.len()) {
        two.extend(others);
    }
    super::read::delta_from_turns(&two).map_or(90.0, |a| a.delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    /// 100,000 copies of three segments stacked in place (nested `<use>`s
    /// draw so) are the three segments' graph, built as quickly (each
    /// step in the paths' order at most twice, as a turtle going back over
    /// it draws it).
    #[test]
    fn stacked_copies_are_one_segment() {
        let three = [
            vec![v(0.0, 0.0), v(0.0, 2.0)],
            vec![v(0.0, 1.0), v(-1.0, 1.0)],
            vec![v(0.0, 2.0), v(1.0, 2.0)],
        ];
        let mut lines = Vec::new();
        for i in 0..100_000 {
            let mut l = three[i % 3].clone();
            if i % 2 == 1 {
                l.reverse();
            }
            lines.push(l);
        }
        let g = build(&lines, 1).expect("builds");
        assert_eq!((g.edges.len(), g.points.len()), (4, 5), "{g:?}");
        assert_eq!(g.order.len(), 8);
    }

    #[test]
    fn order_direction_and_splitting_do_not_matter() {
        // F[+F]F on the square lattice, drawn as one path and a branch,
        // then as unit segments in another order, reversed, with noise.
        let whole = vec![
            vec![v(0.0, 0.0), v(0.0, 2.0)],
            vec![v(0.0, 1.0), v(-1.0, 1.0)],
        ];
        let split = vec![
            vec![v(-1.0, 1.0), v(0.01, 0.99)],
            vec![v(0.0, 2.0), v(0.0, 1.01)],
            vec![v(-0.01, 0.0), v(0.0, 1.0)],
        ];
        for lines in [whole, split] {
            let g = build(&lines, 1).expect("builds");
            assert_eq!(g.edges.len(), 3, "{g:?}");
            assert_eq!(g.points.len(), 4);
            assert!((g.step - 1.0).abs() < 0.02);
            let mid = g.vertex_at(v(0.0, 1.0)).expect("junction");
            assert_eq!(g.adj[mid as usize].len(), 3);
            assert!((g.delta - 90.0).abs() < 1.0, "{}", g.delta);
        }
    }

    #[test]
    fn a_piece_that_is_not_whole_steps_is_refused() {
        let mut line: Vec<DVec2> = (0..9)
            .map(|k| v(f64::from(k % 2), f64::from(k / 2)))
            .collect();
        line.push(v(1.5, 4.0));
        let lines = vec![line];
        assert!(build(&lines, 1).is_err());
    }
}
