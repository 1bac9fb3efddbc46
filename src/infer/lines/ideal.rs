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
//! direction, gives the drawing those steps stand for, placed where it
//! fits the drawing best; it is refused when a vertex of it lies more than
//! half a step from the drawing's. It is read and searched as a clean
//! drawing, and the program must draw it exactly.
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
/// (from the drawing's own phase) and one step long, as polylines, placed
/// where they fit the drawing best (a similarity, least squares over the
/// vertices); `None` when the drawing is not noisy, has no δ that divides a
/// full turn, or when a vertex of the redrawing lies more than half a step
/// from the drawing's (a step misread, or a drift).
pub fn redrawn(g: &Graph) -> Option<Vec<Vec<DVec2>>> {
    if g.noise < NOISY || g.order.is_empty() {
        return None;
    }
    let m = turns_round(g)?;
    let delta = 360.0 / f64::from(m);
    let phase = synth::phase(g, delta).unwrap_or(0.0);
    let d = delta.to_radians();
    // Each vertex in whole steps along multiples of δ from the first.
    // (Vertices in the order first reached, so that the fit sums alike on
    // every run.)
    let mut index: HashMap<u32, usize> = HashMap::new();
    let mut lattice: Vec<(u32, DVec2)> = Vec::new();
    let mut place_at = |v: u32, l: DVec2| -> DVec2 {
        let i = *index.entry(v).or_insert_with(|| {
            lattice.push((v, l));
            lattice.len() - 1
        });
        lattice[i].1
    };
    let mut polylines: Vec<Vec<u32>> = Vec::new();
    let mut last = u32::MAX;
    let origin = g.points[g.order[0].0 as usize];
    for &(a, b) in &g.order {
        let e = g.edge(a, b)?;
        let from = place_at(a, (g.points[a as usize] - origin) / g.step);
        let k = ((g.direction(e, a) - phase) / d).round();
        place_at(b, from + DVec2::new((k * d).cos(), (k * d).sin()));
        if a != last {
            polylines.push(vec![a]);
        }
        if let Some(l) = polylines.last_mut() {
            l.push(b);
        }
        last = b;
    }
    let pairs: Vec<(DVec2, DVec2)> = lattice
        .iter()
        .map(|&(v, l)| (l, g.points[v as usize]))
        .collect();
    let place = fit(&pairs)?;
    let worst = pairs
        .iter()
        .map(|&(l, p)| place(l).distance(p))
        .fold(0.0, f64::max);
    if worst > 0.5 * g.step {
        return None;
    }
    Some(
        polylines
            .iter()
            .map(|l| l.iter().map(|v| place(lattice[index[v]].1)).collect())
            .collect(),
    )
}

/// The similarity z ↦ c + s·z (s a complex number: a turn and a scale)
/// that puts the first of each pair nearest the second, least squares.
fn fit(pairs: &[(DVec2, DVec2)]) -> Option<impl Fn(DVec2) -> DVec2> {
    let n = pairs.len() as f64;
    if n < 2.0 {
        return None;
    }
    let (cz, cw) = pairs
        .iter()
        .fold((DVec2::ZERO, DVec2::ZERO), |(a, b), (z, w)| {
            (a + *z, b + *w)
        });
    let (cz, cw) = (cz / n, cw / n);
    let (mut num, mut den) = (DVec2::ZERO, 0.0);
    for (z, w) in pairs {
        let (z, w) = (*z - cz, *w - cw);
        num += DVec2::new(w.x * z.x + w.y * z.y, w.y * z.x - w.x * z.y);
        den += z.length_squared();
    }
    if den <= 0.0 {
        return None;
    }
    let s = num / den;
    Some(move |p: DVec2| {
        let z = p - cz;
        DVec2::new(s.x * z.x - s.y * z.y, s.x * z.y + s.y * z.x) + cw
    })
}

/// The most steps of δ a full turn is tried at.
const MOST: u32 = 36;

/// δ as 360/m from the directions of the drawing's edges, not its turns
/// (one noisy step spoils two turns, and the smallest turn seen is as noisy
/// as any): each edge's direction taken m times round points the same way
/// for every edge when δ is 360/m. Each edge counts by how surely it says
/// its direction (an edge cut from a segment of r steps errs r times less
/// than a one-step segment: weight r²). The clearest m wins, or the
/// smallest of its divisors nearly as clear (δ and its halves all line up,
/// the halves a little less clearly, m times round turning the noise
/// further; a drawing mostly in one direction lines up nearly as well at
/// the m beside the right one, which are no divisors of it). `None` when
/// no m lines them up.
fn turns_round(g: &Graph) -> Option<u32> {
    let weight = |e: usize| f64::from(g.runs.get(e).copied().unwrap_or(1).max(1)).powi(2);
    let total: f64 = (0..g.edges.len()).map(weight).sum::<f64>().max(1e-300);
    let clarity = |m: u32| {
        let mut z = DVec2::ZERO;
        for (e, [a, _]) in g.edges.iter().enumerate() {
            let t = g.direction(e as u32, *a) * f64::from(m);
            z += DVec2::new(t.cos(), t.sin()) * weight(e);
        }
        z.length() / total
    };
    let all: Vec<(u32, f64)> = (2..=MOST).map(|m| (m, clarity(m))).collect();
    let &(best, clearest) = all.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
    if clearest < 0.3 {
        return None;
    }
    all.iter()
        .find(|&&(m, c)| best % m == 0 && c >= 0.97 * clearest)
        .map(|&(m, _)| m)
}
