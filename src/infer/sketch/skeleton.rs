//! The skeleton of a sketch: strokes become branches of one tree.
//!
//! Owns: attaching each later stroke to the earlier stroke nearest its start
//! (its parent; a stroke drawn from the tip inward is turned round), the order
//! of children (left to right around the parent), Douglas–Peucker simplification
//! that keeps the junctions where children start as vertices, and the errors of
//! a stroke that attaches to nothing. Must not know productions or the language.

use super::strokes::Stroke;
use glam::DVec2;

/// Default Douglas–Peucker tolerance, as a fraction of the drawing's diagonal.
pub const EPSILON_OF_DIAGONAL: f64 = 0.015;
/// How far a stroke may start from its parent, as a fraction of the diagonal.
pub const ATTACH_OF_DIAGONAL: f64 = 0.04;

/// A stroke that starts on no earlier stroke.
#[derive(Clone, Debug, PartialEq)]
pub struct Detached {
    /// `Stroke::describe` of the stroke.
    pub stroke: String,
    /// Its distance to the nearest earlier stroke.
    pub distance: f64,
    /// The largest distance that attaches.
    pub limit: f64,
}

/// One branch: a simplified stroke and its place in the tree.
#[derive(Clone, Debug)]
pub struct Branch {
    /// Index into the strokes given to `build`.
    pub stroke: usize,
    pub parent: Option<usize>,
    /// Simplified points, world coordinates; every junction is a vertex.
    pub points: Vec<DVec2>,
    /// Children, left to right around this branch.
    pub children: Vec<usize>,
    /// For each child (same order), the vertex of `points` where it starts.
    pub child_vertex: Vec<usize>,
    /// The root is level 0.
    pub level: usize,
    pub width: Option<f64>,
}

impl Branch {
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }

    pub fn segments(&self) -> usize {
        self.points.len().saturating_sub(1)
    }

    /// Unit direction of segment `k` (clamped to the existing ones).
    pub fn direction(&self, k: usize) -> DVec2 {
        let k = k.min(self.segments().saturating_sub(1));
        match (self.points.get(k), self.points.get(k + 1)) {
            (Some(a), Some(b)) => (*b - *a).try_normalize().unwrap_or(DVec2::Y),
            _ => DVec2::Y,
        }
    }

    /// The heading at vertex `v`: the segment arriving there (the first
    /// segment at the start).
    pub fn heading_at(&self, v: usize) -> DVec2 {
        self.direction(v.saturating_sub(1))
    }
}

/// The tree of a sketch.
#[derive(Clone, Debug)]
pub struct Skeleton {
    /// Branch `i` is stroke `i`; branch 0 is the trunk.
    pub branches: Vec<Branch>,
    pub epsilon: f64,
    pub attach: f64,
    /// The raw strokes' bounding box, world coordinates: [minx, miny, maxx, maxy].
    pub bbox: [f64; 4],
}

impl Skeleton {
    pub fn segments(&self) -> usize {
        self.branches.iter().map(Branch::segments).sum()
    }

    pub fn height(&self) -> usize {
        self.branches.iter().map(|b| b.level).max().unwrap_or(0)
    }

    /// Children lists, for the productions.
    pub fn children(&self) -> Vec<Vec<usize>> {
        self.branches.iter().map(|b| b.children.clone()).collect()
    }

    /// Bounding box of the simplified branches.
    pub fn simplified_bbox(&self) -> [f64; 4] {
        bbox(self.branches.iter().flat_map(|b| b.points.iter()))
    }
}

/// Signed angle from `a` to `b` in degrees, counter-clockwise positive.
pub fn angle(a: DVec2, b: DVec2) -> f64 {
    a.perp_dot(b).atan2(a.dot(b)).to_degrees()
}

fn bbox<'a>(points: impl Iterator<Item = &'a DVec2>) -> [f64; 4] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in points {
        b = [b[0].min(p.x), b[1].min(p.y), b[2].max(p.x), b[3].max(p.y)];
    }
    if b[0] > b[2] { [0.0; 4] } else { b }
}

/// The nearest point of a polyline to `p`: (distance, arc length there).
fn nearest(points: &[DVec2], p: DVec2) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    let mut along = 0.0;
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let len2 = d.length_squared();
        let t = if len2 > 0.0 {
            ((p - w[0]).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = p.distance(w[0] + d * t);
        if dist < best.0 {
            best = (dist, along + t * len2.sqrt());
        }
        along += len2.sqrt();
    }
    best
}

/// The stroke nearest to `p` among those whose bounding box is within `within`
/// of it: (index, (distance, arc length there)).
fn near(
    raw: &[Vec<DVec2>],
    boxes: &[[f64; 4]],
    p: DVec2,
    within: f64,
) -> Option<(usize, (f64, f64))> {
    raw.iter()
        .zip(boxes)
        .enumerate()
        .filter(|(_, (_, b))| {
            let dx = (b[0] - p.x).max(p.x - b[2]).max(0.0);
            let dy = (b[1] - p.y).max(p.y - b[3]).max(0.0);
            dx * dx + dy * dy <= within * within
        })
        .map(|(j, (r, _))| (j, nearest(r, p)))
        .min_by(|a, b| a.1.0.total_cmp(&b.1.0))
}

/// Builds the tree. `epsilon` defaults to `EPSILON_OF_DIAGONAL` of the drawing.
/// `strokes` must not be empty.
pub fn build(strokes: &[Stroke], epsilon: Option<f64>) -> Result<Skeleton, Detached> {
    let bb = bbox(strokes.iter().flat_map(|s| s.points.iter()));
    let diagonal = DVec2::new(bb[2] - bb[0], bb[3] - bb[1]).length();
    let epsilon = epsilon.unwrap_or(EPSILON_OF_DIAGONAL * diagonal).max(0.0);
    let attach = (ATTACH_OF_DIAGONAL * diagonal).max(2.0 * epsilon);
    let n = strokes.len();
    let mut raw: Vec<Vec<DVec2>> = strokes.iter().map(|s| s.points.clone()).collect();
    // Trees grow up: a trunk drawn downward is turned round.
    if let Some(t) = raw.first_mut()
        && let (Some(a), Some(b)) = (t.first(), t.last())
        && b.y < a.y
    {
        t.reverse();
    }
    let boxes: Vec<[f64; 4]> = raw.iter().map(|r| bbox(r.iter())).collect();
    let mut parent: Vec<Option<(usize, f64)>> = vec![None; n];
    for i in 1..n {
        let (Some(first), Some(last)) = (raw[i].first().copied(), raw[i].last().copied()) else {
            continue;
        };
        let at_start = near(&raw[..i], &boxes[..i], first, attach);
        let at_end = near(&raw[..i], &boxes[..i], last, attach);
        let (j, s) = match (at_start, at_end) {
            (Some((j, (d, s))), _) if d <= attach => (j, s),
            (_, Some((j, (d, s)))) if d <= attach => {
                // Drawn from the tip inward: turn it round.
                raw[i].reverse();
                (j, s)
            }
            _ => {
                let distance = near(&raw[..i], &boxes[..i], first, f64::INFINITY)
                    .map_or(f64::INFINITY, |(_, (d, _))| d);
                return Err(Detached {
                    stroke: strokes[i].describe(),
                    distance,
                    limit: attach,
                });
            }
        };
        // Starting at the start of a sibling (a fork drawn as separate strokes)
        // means starting where that sibling starts: on their parent.
        let (mut j, mut s) = (j, s);
        while s <= attach / 2.0
            && let Some((pj, ps)) = parent[j]
        {
            (j, s) = (pj, ps);
        }
        parent[i] = Some((j, s));
    }
    // Junctions on each stroke, by arc length.
    let mut cuts: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (i, p) in parent.iter().enumerate() {
        if let Some((j, s)) = p {
            cuts[*j].push((i, *s));
        }
    }
    let mut branches: Vec<Branch> = Vec::with_capacity(n);
    let mut vertex_of: Vec<usize> = vec![0; n];
    for (i, pts) in raw.iter().enumerate() {
        let (points, vertices) = simplify_with_junctions(pts, &cuts[i], epsilon);
        for (child, v) in vertices {
            vertex_of[child] = v;
        }
        branches.push(Branch {
            stroke: i,
            parent: parent[i].map(|p| p.0),
            points,
            children: Vec::new(),
            child_vertex: Vec::new(),
            level: 0,
            width: strokes[i].width,
        });
    }
    // Levels (parents always come first) and children left to right.
    for i in 1..n {
        if let Some(p) = branches[i].parent {
            branches[i].level = branches[p].level + 1;
        }
    }
    let mut children_of: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (c, b) in branches.iter().enumerate() {
        if let Some(p) = b.parent {
            children_of[p].push(c);
        }
    }
    for (p, cs) in children_of.iter().enumerate() {
        let mut kids: Vec<(f64, usize, usize)> = cs
            .iter()
            .map(|&c| {
                let v = vertex_of[c];
                let a = angle(branches[p].heading_at(v), branches[c].direction(0));
                (a, v, c)
            })
            .collect();
        kids.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        branches[p].children = kids.iter().map(|k| k.2).collect();
        branches[p].child_vertex = kids.iter().map(|k| k.1).collect();
    }
    Ok(Skeleton {
        branches,
        epsilon,
        attach,
        bbox: bb,
    })
}

/// Douglas–Peucker over `points`, keeping the junctions `cuts` (child, arc
/// length) as vertices. Junctions closer than `epsilon` (along the stroke) to an
/// end or to each other share one vertex. Returns the points and, per child,
/// its vertex.
pub fn simplify_with_junctions(
    points: &[DVec2],
    cuts: &[(usize, f64)],
    epsilon: f64,
) -> (Vec<DVec2>, Vec<(usize, usize)>) {
    if points.len() < 2 {
        return (points.to_vec(), cuts.iter().map(|&(c, _)| (c, 0)).collect());
    }
    let total: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
    let snap = epsilon.min(total / 4.0);
    let mut cuts: Vec<(usize, f64)> = cuts
        .iter()
        .map(|&(c, s)| {
            let s = if s <= snap {
                0.0
            } else if total - s <= snap {
                total
            } else {
                s
            };
            (c, s)
        })
        .collect();
    cuts.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    // Cluster junctions: each takes the position of its cluster's first.
    let mut positions: Vec<f64> = Vec::new();
    let mut cluster_of: Vec<(usize, usize)> = Vec::new();
    for &(c, s) in &cuts {
        match positions.last() {
            Some(&last) if s - last <= snap => {}
            _ => positions.push(s),
        }
        cluster_of.push((c, positions.len() - 1));
    }
    // The polyline with the junction points inserted; `forced` marks vertices
    // that must stay (the ends and the junctions).
    let mut dense: Vec<DVec2> = Vec::with_capacity(points.len() + positions.len());
    let mut forced: Vec<bool> = Vec::new();
    let mut at_position: Vec<usize> = vec![0; positions.len()];
    let mut next = 0;
    let mut along = 0.0;
    for (k, w) in points.windows(2).enumerate() {
        if k == 0 {
            dense.push(w[0]);
            forced.push(true);
        }
        let len = w[0].distance(w[1]);
        while next < positions.len() && positions[next] <= along + len {
            let s = positions[next];
            let p = if len > 0.0 {
                w[0].lerp(w[1], ((s - along) / len).clamp(0.0, 1.0))
            } else {
                w[0]
            };
            if dense.last().is_some_and(|l| l.distance(p) <= 1e-9) {
                if let Some(f) = forced.last_mut() {
                    *f = true;
                }
            } else {
                dense.push(p);
                forced.push(true);
            }
            at_position[next] = dense.len() - 1;
            next += 1;
        }
        along += len;
        if dense.last().is_some_and(|l| l.distance(w[1]) <= 1e-9) {
            continue;
        }
        dense.push(w[1]);
        forced.push(false);
    }
    // Junctions past the end (rounding) sit on the last point.
    let end = dense.len().saturating_sub(1);
    for slot in at_position.iter_mut().skip(next) {
        *slot = end;
    }
    if let Some(f) = forced.last_mut() {
        *f = true;
    }
    // Douglas–Peucker between consecutive forced vertices.
    let mut keep = forced.clone();
    let anchors: Vec<usize> = (0..dense.len()).filter(|&k| forced[k]).collect();
    for w in anchors.windows(2) {
        douglas_peucker(&dense, w[0], w[1], epsilon, &mut keep);
    }
    // A closed stroke whose ends meet keeps its farthest point, so that it
    // does not collapse into nothing.
    if let (Some(a), Some(b)) = (dense.first(), dense.last())
        && a.distance(*b) <= epsilon
        && keep.iter().filter(|k| **k).count() == 2
        && let Some((far, _)) = dense
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.distance(*a).total_cmp(&y.1.distance(*a)))
        && far > 0
        && far + 1 < dense.len()
    {
        keep[far] = true;
    }
    let mut new_index = vec![0; dense.len()];
    let mut out = Vec::new();
    for (k, p) in dense.iter().enumerate() {
        if keep[k] {
            out.push(*p);
        }
        new_index[k] = out.len().saturating_sub(1);
    }
    let vertices = cluster_of
        .into_iter()
        .map(|(c, cl)| (c, new_index[at_position[cl]]))
        .collect();
    (out, vertices)
}

/// Marks in `keep` the points of `points[a..=b]` that Douglas–Peucker keeps.
fn douglas_peucker(points: &[DVec2], a: usize, b: usize, epsilon: f64, keep: &mut [bool]) {
    let mut stack = vec![(a, b)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (p, q) = (points[a], points[b]);
        let d = q - p;
        let len = d.length();
        let mut best = (0.0, a);
        for (k, x) in points.iter().enumerate().take(b).skip(a + 1) {
            let dist = if len > 0.0 {
                (d.perp_dot(*x - p) / len).abs()
            } else {
                x.distance(p)
            };
            if dist > best.0 {
                best = (dist, k);
            }
        }
        if best.0 > epsilon {
            keep[best.1] = true;
            stack.push((a, best.1));
            stack.push((best.1, b));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stroke(number: usize, pts: &[(f64, f64)]) -> Stroke {
        Stroke {
            number,
            id: format!("s{number}"),
            subpath: 0,
            points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            width: None,
        }
    }

    #[test]
    fn douglas_peucker_drops_small_wiggles_and_keeps_corners() {
        let pts: Vec<DVec2> = [(0.0, 0.0), (1.0, 0.2), (2.0, -0.1), (3.0, 0.0), (3.0, 5.0)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        let (out, _) = simplify_with_junctions(&pts, &[], 0.5);
        assert_eq!(
            out,
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(3.0, 0.0),
                DVec2::new(3.0, 5.0)
            ]
        );
        let (out, _) = simplify_with_junctions(&pts, &[], 0.05);
        assert_eq!(out.len(), 5);
    }

    #[test]
    fn a_closed_stroke_keeps_its_far_point() {
        let pts: Vec<DVec2> = [(0.0, 0.0), (1.0, 0.0), (0.0, 0.0)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        let (out, _) = simplify_with_junctions(&pts, &[], 5.0);
        assert_eq!(out.len(), 3);
    }

    #[test]
    fn junctions_become_vertices_and_snap_to_ends() {
        let pts = vec![DVec2::new(0.0, 0.0), DVec2::new(0.0, 10.0)];
        let (out, v) = simplify_with_junctions(&pts, &[(1, 4.0), (2, 9.9), (3, 4.05)], 0.2);
        assert_eq!(
            out,
            vec![DVec2::ZERO, DVec2::new(0.0, 4.0), DVec2::new(0.0, 10.0)]
        );
        assert_eq!(v, vec![(1, 1), (3, 1), (2, 2)]);
    }

    #[test]
    fn children_attach_left_to_right_and_reversed_strokes_turn_round() {
        let strokes = vec![
            stroke(1, &[(0.0, 0.0), (0.0, 10.0)]),
            stroke(2, &[(0.0, 10.0), (5.0, 15.0)]),
            // Drawn from its tip down to the trunk's top.
            stroke(3, &[(-5.0, 15.0), (0.0, 10.0)]),
        ];
        let sk = build(&strokes, None).expect("attaches");
        assert_eq!(sk.branches[0].children, vec![2, 1]);
        assert_eq!(sk.branches[2].points[0], DVec2::new(0.0, 10.0));
        assert_eq!(sk.height(), 1);
        assert_eq!(sk.segments(), 3);
    }

    #[test]
    fn a_stroke_starting_at_a_siblings_start_attaches_to_the_parent() {
        let strokes = vec![
            stroke(1, &[(0.0, 0.0), (0.0, 100.0)]),
            stroke(2, &[(0.0, 100.0), (-40.0, 140.0)]),
            // Starts nearer to stroke 2's start than to the trunk's tip.
            stroke(3, &[(-0.5, 101.0), (40.0, 140.0)]),
        ];
        let sk = build(&strokes, None).expect("attaches");
        assert_eq!(sk.branches[2].parent, Some(0));
        assert_eq!(sk.branches[0].children, vec![1, 2]);
    }

    #[test]
    fn a_trunk_drawn_downward_grows_up() {
        let strokes = vec![
            stroke(1, &[(0.0, 100.0), (0.0, 0.0)]),
            stroke(2, &[(0.0, 100.0), (30.0, 130.0)]),
        ];
        let sk = build(&strokes, None).expect("attaches");
        assert_eq!(sk.branches[0].points[0], DVec2::ZERO);
        assert_eq!(sk.branches[0].child_vertex, vec![1]);
    }

    #[test]
    fn a_detached_stroke_is_named() {
        let strokes = vec![
            stroke(1, &[(0.0, 0.0), (0.0, 100.0)]),
            stroke(2, &[(50.0, 50.0), (80.0, 90.0)]),
        ];
        let e = build(&strokes, None).expect_err("detached");
        assert_eq!(e.stroke, "stroke 2 (the path with id `s2`)");
        assert!((e.distance - 50.0).abs() < 1e-9);
    }
}
