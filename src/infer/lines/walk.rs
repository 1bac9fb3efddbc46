//! The walks a turtle could have drawn a branching stroke graph in, or a
//! path, when the drawing's paths no longer say (one path per step, in any
//! order).
//!
//! A bracketed L-system draws a tree: from its root, at every vertex, each
//! branch in brackets first and the rest of the axis after them, in the
//! same order at every vertex (the successors say it once). So a tree-shaped
//! graph is walked depth first from a root, the edges leaving each vertex
//! taken in one order of their turns, and written as polylines in that
//! order, which the turtle reading (`read`, `turtle`) turns into the same
//! tree a turtle drawing it in order gives. The root is one of the ends; a
//! plant's trunk is its longest straight run, so the ends are tried by the
//! length of their straight run.
//!
//! One order of turns does not fit every grammar: at a vertex the turtle
//! finishes the innermost successor it is in before the one around it, and
//! which of the edges leaving a vertex belongs to which depends on the
//! successor (`F -> FF+[-FFF]F-[++F-F]` leaves one vertex straight on into
//! a branch before it turns left to go on). But the innermost successor's
//! branches are the last level's, a few steps; the one around it draws a
//! branch expanded once more, and the axis the rest. So the edges are also
//! tried smaller subtree first, equal ones by their turns.
//!
//! Owns: which roots and orders are tried. Must not search grammars.

use super::graph::Graph;
use glam::DVec2;

/// Roots tried.
const ROOTS: usize = 2;

/// How close (degrees) two edges must be in direction to be one straight
/// run.
const STRAIGHT: f64 = 1.0;

/// How the edges leaving a vertex are ordered by their turn from the edge
/// that reached it.
#[derive(Clone, Copy, Debug)]
enum Order {
    /// Left turns first, the straightest edge last.
    LeftStraightLast,
    /// Right turns first, the straightest edge last.
    RightStraightLast,
    /// Left turns first.
    Left,
    /// Right turns first.
    Right,
    /// The smaller subtree first, left turns first among equals.
    SmallerLeft,
    /// The smaller subtree first, right turns first among equals.
    SmallerRight,
}

const ORDERS: [Order; 6] = [
    Order::LeftStraightLast,
    Order::RightStraightLast,
    Order::Left,
    Order::Right,
    Order::SmallerLeft,
    Order::SmallerRight,
];

/// The drawing as the polylines of each walk worth trying, when its graph
/// is a tree that branches; none otherwise.
pub fn trees(g: &Graph) -> Vec<Vec<Vec<DVec2>>> {
    if !branches(g) {
        return Vec::new();
    }
    // Subtrees have sizes only in a tree (a graph whose branches touch has
    // cycles, and walks enough for its four orders of turns).
    let tree = g.edges.len() + 1 == g.points.len();
    let orders = if tree { &ORDERS[..] } else { &ORDERS[..4] };
    let mut out = Vec::new();
    for root in roots(g) {
        for &order in orders {
            let w = walk(g, root, order);
            if !out.contains(&w) {
                out.push(w);
            }
        }
    }
    out
}

/// The drawing as one polyline from each end, when its graph is one path
/// that does not touch itself (a Hilbert or Peano curve): the turtle drew
/// it from one end to the other, whatever the order and direction its
/// steps were saved in.
pub fn paths(g: &Graph) -> Vec<Vec<Vec<DVec2>>> {
    let ends: Vec<u32> = (0..g.points.len() as u32)
        .filter(|&v| g.adj[v as usize].len() == 1)
        .collect();
    if ends.len() != 2 || g.adj.iter().any(|a| a.len() > 2) || !g.connected() {
        return Vec::new();
    }
    ends.into_iter()
        .map(|end| walk(g, end, Order::Left))
        .collect()
}

/// Whether the edges are connected and some vertex has three or more (a
/// tree, or one whose branches touch or cross: each edge is walked once).
fn branches(g: &Graph) -> bool {
    g.adj.iter().any(|a| a.len() > 2) && g.connected()
}

/// The ends, longest straight run first (then farthest from the centre).
fn roots(g: &Graph) -> Vec<u32> {
    let n = g.points.len().max(1) as f64;
    let centre = g.points.iter().fold(DVec2::ZERO, |s, p| s + *p) / n;
    let mut ends: Vec<(usize, f64, u32)> = (0..g.points.len() as u32)
        .filter(|&v| g.adj[v as usize].len() == 1)
        .map(|v| {
            let far = g.points[v as usize].distance(centre);
            (run(g, v), far, v)
        })
        .collect();
    ends.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.total_cmp(&a.1)).then(a.2.cmp(&b.2)));
    ends.into_iter().take(ROOTS).map(|(_, _, v)| v).collect()
}

/// How many edges run straight on from the end `v`.
fn run(g: &Graph, v: u32) -> usize {
    let Some(&(mut at, mut e)) = g.adj[v as usize].first() else {
        return 0;
    };
    let mut dir = g.direction(e, v);
    let mut count = 1;
    loop {
        let next = g.adj[at as usize]
            .iter()
            .find(|&&(_, f)| f != e && turn(g.direction(f, at), dir).abs() <= STRAIGHT);
        let Some(&(to, f)) = next else {
            return count;
        };
        dir = g.direction(f, at);
        (at, e) = (to, f);
        count += 1;
        if count > g.edges.len() {
            return count;
        }
    }
}

/// The turn (degrees, left positive, in (−180, 180]) from heading `from`
/// to heading `to` (radians).
fn turn(to: f64, from: f64) -> f64 {
    super::turtle::wrap_degrees((to - from).to_degrees())
}

/// The tree walked depth first from `root`, each vertex's edges in
/// `order`, as polylines (a new one wherever a step does not start where
/// the last ended).
fn walk(g: &Graph, root: u32, order: Order) -> Vec<Vec<DVec2>> {
    let mut steps: Vec<(u32, u32)> = Vec::with_capacity(g.edges.len());
    // (vertex, the edge that reached it, its heading).
    let Some(&(_, first)) = g.adj[root as usize].first() else {
        return Vec::new();
    };
    let size = match order {
        Order::SmallerLeft | Order::SmallerRight => sizes(g, root),
        _ => Vec::new(),
    };
    let mut used = vec![false; g.edges.len()];
    let mut stack: Vec<(u32, u32, f64)> = vec![(root, u32::MAX, g.direction(first, root))];
    while let Some((v, from, heading)) = stack.pop() {
        if from != u32::MAX {
            if used[from as usize] {
                continue;
            }
            used[from as usize] = true;
            let [a, b] = g.edges[from as usize];
            steps.push(if b == v { (a, b) } else { (b, a) });
        }
        let mut next: Vec<(f64, u32, u32)> = g.adj[v as usize]
            .iter()
            .filter(|&&(_, e)| !used[e as usize])
            .map(|&(to, e)| (turn(g.direction(e, v), heading), to, e))
            .collect();
        sort(&mut next, order);
        if !size.is_empty() {
            // Stable: equal subtrees keep the order of their turns.
            next.sort_by_key(|&(_, to, _)| size[to as usize]);
        }
        // Pushed last to first, so the first is walked first.
        for &(_, to, e) in next.iter().rev() {
            stack.push((to, e, g.direction(e, v)));
        }
    }
    g.polylines(steps.into_iter())
}

/// Each vertex's count of edges below it, the graph walked depth first
/// from `root` (an edge that closes a cycle counts where it is first met).
fn sizes(g: &Graph, root: u32) -> Vec<usize> {
    let n = g.points.len();
    let mut size = vec![0usize; n];
    let mut seen = vec![false; n];
    let mut used = vec![false; g.edges.len()];
    let mut order = Vec::with_capacity(n);
    let mut parent = vec![u32::MAX; n];
    let mut stack = vec![root];
    seen[root as usize] = true;
    while let Some(v) = stack.pop() {
        order.push(v);
        for &(to, e) in &g.adj[v as usize] {
            if used[e as usize] {
                continue;
            }
            used[e as usize] = true;
            size[v as usize] += 1;
            if !seen[to as usize] {
                seen[to as usize] = true;
                parent[to as usize] = v;
                stack.push(to);
            }
        }
    }
    for &v in order.iter().rev() {
        let p = parent[v as usize];
        if p != u32::MAX {
            size[p as usize] += size[v as usize];
        }
    }
    size
}

/// Orders a vertex's edges (turn, to, edge).
fn sort(next: &mut [(f64, u32, u32)], order: Order) {
    let left = |a: &(f64, u32, u32), b: &(f64, u32, u32)| b.0.total_cmp(&a.0).then(a.2.cmp(&b.2));
    match order {
        Order::Left | Order::SmallerLeft => next.sort_by(left),
        Order::Right | Order::SmallerRight => next.sort_by(|a, b| left(b, a)),
        Order::LeftStraightLast | Order::RightStraightLast => {
            if matches!(order, Order::LeftStraightLast) {
                next.sort_by(left);
            } else {
                next.sort_by(|a, b| left(b, a));
            }
            let straightest =
                (0..next.len()).min_by(|&i, &j| next[i].0.abs().total_cmp(&next[j].0.abs()));
            if let Some(i) = straightest {
                next[i..].rotate_left(1);
            }
        }
    }
}
