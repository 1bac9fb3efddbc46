//! A noisy line drawing redrawn as the turtle meant it: every step of the
//! stroke graph, in the paths' order, turned to the nearest multiple of δ
//! and one step long.
//!
//! A jittered or hand-traced drawing in turtle order fails the exact
//! reading (its turns are not whole multiples of one angle, its pieces not
//! whole numbers of steps) though every step says plainly which multiple of
//! δ it turns. Walking the graph's steps in order, each from the ideal
//! position of its start vertex (a vertex keeps the position it got first,
//! so a branch starts where its parent passed), along the nearest allowed
//! direction, gives the drawing those steps stand for; it is read and
//! searched as a clean one, and the program found is then checked against
//! the drawing as it is, within its measured noise.
//!
//! Owns: the redrawing. Must not search grammars.

use super::graph::Graph;
use super::synth;
use glam::DVec2;
use std::collections::HashMap;

/// How noisy (in steps) a drawing must be to be redrawn: a clean one is
/// read as it is.
pub const NOISY: f64 = 0.005;

/// The graph's steps in order, each turned to the nearest multiple of δ
/// (from the drawing's own phase) and one step long, as polylines; `None`
/// when the drawing is not noisy or has no δ that divides a full turn.
pub fn redrawn(g: &Graph) -> Option<Vec<Vec<DVec2>>> {
    if g.noise < NOISY || g.order.is_empty() {
        return None;
    }
    let delta = 360.0 / f64::from(turns_round(g)?);
    let phase = synth::phase(g, delta).unwrap_or(0.0);
    let d = delta.to_radians();
    let snap = |a: f64| phase + ((a - phase) / d).round() * d;
    let mut at: HashMap<u32, DVec2> = HashMap::new();
    let mut out: Vec<Vec<DVec2>> = Vec::new();
    let mut last = u32::MAX;
    for &(a, b) in &g.order {
        let e = g.edge(a, b)?;
        let from = *at.entry(a).or_insert(g.points[a as usize]);
        let dir = snap(g.direction(e, a));
        let to = *at
            .entry(b)
            .or_insert(from + g.step * DVec2::new(dir.cos(), dir.sin()));
        if a != last {
            out.push(vec![from]);
        }
        if let Some(l) = out.last_mut() {
            l.push(to);
        }
        last = b;
    }
    Some(out)
}

/// The most steps of δ a full turn is tried at.
const MOST: u32 = 36;

/// δ as 360/m from the directions of the drawing's edges, not its turns
/// (one noisy step spoils two turns, and the smallest turn seen is as noisy
/// as any): each edge's direction taken m times round points the same way
/// for every edge when δ is 360/m, so the m whose mean points most clearly
/// (of those within a fifth of the clearest, the smallest: δ and its
/// halves all line up) is the drawing's. `None` when no m lines them up.
fn turns_round(g: &Graph) -> Option<u32> {
    let clarity = |m: u32| {
        let mut z = DVec2::ZERO;
        for (e, [a, _]) in g.edges.iter().enumerate() {
            let t = g.direction(e as u32, *a) * f64::from(m);
            z += DVec2::new(t.cos(), t.sin());
        }
        z.length() / g.edges.len().max(1) as f64
    };
    let all: Vec<(u32, f64)> = (2..=MOST).map(|m| (m, clarity(m))).collect();
    let best = all.iter().map(|&(_, r)| r).fold(0.0, f64::max);
    if best < 0.3 {
        return None;
    }
    all.iter().find(|&&(_, r)| r >= 0.8 * best).map(|&(m, _)| m)
}
