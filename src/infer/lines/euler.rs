//! A curve drawn in one stroke that touches or crosses itself, its steps in
//! any order: the walks that draw every edge of its graph once, taken step
//! by step as the level parse asks.
//!
//! Where a curve passes a vertex twice, the graph no longer says which way
//! it went on: each unused edge there is a turn the walk may take. The walk
//! offers those turns to the parse (`levels::Drawing`), which takes them
//! with its own choices, so a wrong one fails as a wrong cut does. A turn
//! onto an edge that would cut the edges not yet drawn in two (a bridge of
//! what is left, Fleury's rule) is not offered while another is: no walk
//! that takes it draws them all.
//!
//! Owns: the walk and its choices. Must not parse (`levels` does).

use super::graph::Graph;
use super::levels::Drawing;
use super::turtle;

/// A walk over a stroke graph from a start edge.
pub struct Walk<'a> {
    g: &'a Graph,
    /// δ₀, degrees.
    delta: f64,
    m: i32,
    /// The start vertex and edge.
    start: (u32, u32),
    /// Drawn edges and the vertex each was drawn from.
    trail: Vec<(u32, u32)>,
    used: Vec<bool>,
    /// Per vertex, the search that last reached it (bridge tests).
    seen: Vec<u32>,
    stamp: u32,
    /// Work of the bridge tests since the parse last asked.
    work: u64,
}

impl<'a> Walk<'a> {
    /// A walk from vertex `start.0` along edge `start.1`, turns in δ₀ =
    /// 360°/m.
    pub fn new(g: &'a Graph, delta: f64, start: (u32, u32)) -> Walk<'a> {
        Walk {
            g,
            delta,
            m: (360.0 / delta).round() as i32,
            start,
            trail: Vec::new(),
            used: vec![false; g.edges.len()],
            seen: vec![0; g.points.len()],
            stamp: 0,
            work: 0,
        }
    }

    /// The drawn edges and the vertex each was drawn from.
    pub fn trail(&self) -> &[(u32, u32)] {
        &self.trail
    }

    /// The vertex the walk is at.
    fn at(&self) -> u32 {
        match self.trail.last() {
            Some(&(e, from)) => self.other(e, from),
            None => self.start.0,
        }
    }

    fn other(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.g.edges[e as usize];
        if a == v { b } else { a }
    }

    /// The turn (0..m) onto edge `e` from the last drawn, when it is a
    /// multiple of δ₀ (an edge half way between is no turtle's next step).
    fn turn_onto(&self, e: u32) -> Option<i32> {
        let Some(&(last, from)) = self.trail.last() else {
            return Some(0);
        };
        let d = self.g.direction(e, self.at()) - self.g.direction(last, from);
        let t = turtle::wrap_degrees(d.to_degrees()) / self.delta;
        ((t - t.round()).abs() < 0.25).then(|| (t.round() as i32).rem_euclid(self.m))
    }

    /// The edges not yet drawn at the vertex the walk is at, each with the
    /// turn onto it (none when it is no multiple of δ₀).
    fn open(&self) -> Vec<(u32, Option<i32>)> {
        self.g.adj[self.at() as usize]
            .iter()
            .map(|&(_, e)| e)
            .filter(|&e| !self.used[e as usize])
            .map(|e| (e, self.turn_onto(e)))
            .collect()
    }

    /// Whether the walk may draw `e`, one of the `open` edges at `v`: it
    /// is the only one, or no bridge of what is left.
    fn may_take(&mut self, v: u32, e: u32, open: usize) -> bool {
        open == 1 || self.keeps_the_rest(v, e)
    }

    /// Whether drawing `e` from `v` leaves the edges not yet drawn at `v`
    /// reachable from its other end (so it is no bridge of what is left).
    fn keeps_the_rest(&mut self, v: u32, e: u32) -> bool {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.iter_mut().for_each(|s| *s = 0);
            self.stamp = 1;
        }
        let w = self.other(e, v);
        let mut stack = vec![w];
        self.seen[w as usize] = self.stamp;
        while let Some(x) = stack.pop() {
            for &(y, f) in &self.g.adj[x as usize] {
                self.work += 1;
                if f == e || self.used[f as usize] {
                    continue;
                }
                if y == v {
                    return true;
                }
                if self.seen[y as usize] != self.stamp {
                    self.seen[y as usize] = self.stamp;
                    stack.push(y);
                }
            }
        }
        false
    }
}

impl Drawing for Walk<'_> {
    fn steps(&self) -> usize {
        self.g.edges.len()
    }

    fn drawn(&self) -> usize {
        self.trail.len()
    }

    fn choices(&mut self, out: &mut Vec<i32>) {
        if self.trail.is_empty() {
            out.push(0);
            return;
        }
        let v = self.at();
        let open = self.open();
        for &(e, t) in &open {
            if let Some(t) = t
                && self.may_take(v, e, open.len())
            {
                out.push(t);
            }
        }
    }

    fn take(&mut self, t: i32) -> bool {
        if self.trail.is_empty() {
            let (v, e) = self.start;
            self.used[e as usize] = true;
            self.trail.push((e, v));
            return true;
        }
        // (No list of the open edges: this is the parse's every step.)
        let v = self.at();
        let t = t.rem_euclid(self.m);
        let (mut open, mut next) = (0, None);
        for &(_, e) in &self.g.adj[v as usize] {
            if !self.used[e as usize] {
                open += 1;
                if next.is_none() && self.turn_onto(e) == Some(t) {
                    next = Some(e);
                }
            }
        }
        let Some(e) = next else {
            return false;
        };
        if !self.may_take(v, e, open) {
            return false;
        }
        self.used[e as usize] = true;
        self.trail.push((e, v));
        true
    }

    fn spent(&mut self) -> u64 {
        std::mem::take(&mut self.work) / 64
    }

    fn back(&mut self, n: usize) {
        while self.trail.len() > n {
            if let Some((e, _)) = self.trail.pop() {
                self.used[e as usize] = false;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::graph;
    use crate::infer::lines::levels::{self, tests::turns};
    use glam::DVec2;

    /// The unit segments of a curve with these turns (in δ), in a shuffled
    /// order, every other one reversed.
    fn segments(turns: &[i32], delta: f64) -> Vec<Vec<DVec2>> {
        let (mut p, mut h) = (DVec2::ZERO, 0f64);
        let mut out = Vec::new();
        for i in 0..=turns.len() {
            if i > 0 {
                h += turns[i - 1] as f64 * delta;
            }
            let q = p + DVec2::new(h.to_radians().cos(), h.to_radians().sin()) * 3.0;
            out.push(if i % 2 == 1 { vec![q, p] } else { vec![p, q] });
            p = q;
        }
        let mut state = 12345u64;
        for i in (1..out.len()).rev() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            out.swap(i, (state >> 33) as usize % (i + 1));
        }
        out
    }

    /// The walk from the curve's first step that takes its own turns.
    fn first_step(g: &Graph) -> (u32, u32) {
        let v = g.vertex_at(DVec2::ZERO).expect("the start");
        (v, g.adj[v as usize][0].1)
    }

    #[test]
    fn a_curve_that_touches_itself_is_walked_as_drawn_and_parsed() {
        let t = turns("F", &[('F', "F-FF+F")], 4);
        let g = graph::build(&segments(&t, 120.0), 1).expect("graph");
        assert!(g.adj.iter().any(|a| a.len() == 4), "it touches itself");
        assert_eq!(g.delta, 120.0);
        let mut w = Walk::new(&g, 120.0, first_step(&g));
        assert!(w.take(0));
        for (i, &x) in t.iter().enumerate() {
            let mut c = Vec::new();
            w.choices(&mut c);
            assert!(
                w.take(x),
                "the walk follows the curve's turns: step {i} turn {x} of {c:?}"
            );
        }
        let limits = levels::Limits {
            letters: 1,
            block: 24,
            axiom: 32,
            work: 200_000,
            single: false,
            bound: usize::MAX,
        };
        let p = levels::parse_drawing(&mut Walk::new(&g, 120.0, first_step(&g)), 3, &limits);
        let p = p.expect("parsed");
        assert_eq!((p.depth, p.rules.len()), (4, 1));
    }
}
