//! The answers to query modules from a guide's geometry and what its systems
//! drew: ?P ?H ?D_* ?N_* (`query`) and ?X (`collide`), and `Probe`, the turtle
//! sink that collects a system's segments and query requests.
//!
//! Owns: the numbers each query kind outputs (`Answer`) and the numbering of
//! ids (guide edges first, then drawn segments). Reads the scene model
//! (`scene`) and the drawn segments (`index`); must not derive, keep token
//! states or send messages (that is `engine`).

use super::index::Layers;
use super::scene::Scene;
use crate::geometry::exact::orient;
use crate::geometry::{closest_on_segment, crossing, ray_hit, signed_angle, signed_area};
use crate::query::QueryKind;
use crate::turtle::{Sink, State};
use glam::{DVec2, DVec3};
use std::cmp::Ordering;

/// Collects one instance's segments and query requests.
#[derive(Default)]
pub(crate) struct Probe {
    pub(crate) segments: Vec<(DVec2, DVec2)>,
    pub(crate) queries: Vec<(usize, u8, State)>,
}

impl Sink for Probe {
    fn segment(&mut self, a: DVec3, b: DVec3, _: f64, _: u32) {
        self.segments.push((a.truncate(), b.truncate()));
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, at: DVec3, h: DVec3, _: DVec3, scale: f64, _: u32) {
        // An element occupies its base-to-tip axis for collisions.
        self.segments
            .push((at.truncate(), (at + h * scale).truncate()));
    }
    fn query(&mut self, module: usize, kind: u8, state: &State) {
        self.queries.push((module, kind, *state));
    }
}

/// The edges of a polygon: (index, start, end), the last closing it.
fn edges(poly: &[DVec2]) -> impl Iterator<Item = (usize, DVec2, DVec2)> + '_ {
    (0..poly.len()).map(move |i| (i, poly[i], poly[(i + 1) % poly.len()]))
}

/// The outputs of one query module (at most four numbers).
#[derive(Clone, Copy)]
pub(crate) struct Answer {
    values: [f64; 4],
    len: usize,
}

impl Answer {
    fn new(v: &[f64]) -> Answer {
        let mut values = [0.0; 4];
        values[..v.len()].copy_from_slice(v);
        Answer {
            values,
            len: v.len(),
        }
    }

    pub(crate) fn values(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

fn found(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// Answers ?P ?H ?D_* ?N_* for a turtle in guide `gi`; `grid` indexes what is
/// drawn in the guide (None when nothing asks about it).
pub(crate) fn query(
    scene: &Scene,
    grid: Option<&Layers>,
    gi: usize,
    kind: QueryKind,
    st: &State,
) -> Answer {
    let p = st.pos.truncate();
    let h = st.h.truncate();
    let dir = if h.length_squared() > 0.0 {
        h.normalize()
    } else {
        DVec2::Y
    };
    let poly = &scene.guides[gi].polygon;
    // A link that aims at its middle is the point in the middle of its edge.
    let link_edges = |aim: bool| -> Vec<(usize, DVec2, DVec2)> {
        scene
            .links
            .iter()
            .enumerate()
            .filter(|(_, l)| l.from.0 == gi)
            .map(|(i, l)| {
                let e = l.from.1 % poly.len().max(1);
                let (a, b) = (poly[e], poly[(e + 1) % poly.len()]);
                if aim && l.aim_middle {
                    let m = (a + b) * 0.5;
                    (i, m, m)
                } else {
                    (i, a, b)
                }
            })
            .collect()
    };
    let closest = |d: f64, c: DVec2, id: usize| -> Answer {
        let beta = if d > 0.0 {
            signed_angle(dir, c - p)
        } else {
            0.0
        };
        Answer::new(&[1.0, d, beta, id as f64])
    };
    let nearest = |set: &[(usize, DVec2, DVec2)]| -> Answer {
        let best = set
            .iter()
            .map(|&(id, a, b)| {
                let c = closest_on_segment(p, a, b);
                ((c - p).length(), c, id)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match best {
            Some((d, c, id)) => closest(d, c, id),
            None => Answer::new(&[0.0; 4]),
        }
    };
    let first_ahead = |set: &[(usize, DVec2, DVec2)]| -> Option<(f64, usize)> {
        set.iter()
            .filter_map(|&(id, a, b)| ray_hit(p, dir, a, b).map(|t| (t, id)))
            .min_by(|x, y| x.0.total_cmp(&y.0))
    };
    let ahead = |best: Option<(f64, usize)>| -> Answer {
        match best {
            Some((t, id)) => Answer::new(&[1.0, t, id as f64]),
            None => Answer::new(&[0.0; 3]),
        }
    };
    let guide_edges = || -> Vec<(usize, DVec2, DVec2)> { edges(poly).collect() };
    match kind {
        QueryKind::Position => Answer::new(&[st.pos.x, st.pos.y, st.pos.z]),
        QueryKind::Heading => Answer::new(&[st.h.x, st.h.y, st.h.z]),
        QueryKind::Up => Answer::new(&[st.u.x, st.u.y, st.u.z]),
        QueryKind::Left => Answer::new(&[st.l.x, st.l.y, st.l.z]),
        QueryKind::DistanceLink => nearest(&link_edges(true)),
        QueryKind::DistanceGuide => nearest(&guide_edges()),
        // Drawn segments have ids after the guide's edges, as for ?N_A and ?X.
        QueryKind::DistanceElement => match grid.and_then(|g| g.nearest(p)) {
            Some((d, c, i)) => closest(d, c, poly.len() + i),
            None => Answer::new(&[0.0; 4]),
        },
        QueryKind::AheadLink => ahead(first_ahead(&link_edges(false))),
        QueryKind::AheadGuide => ahead(first_ahead(&guide_edges())),
        QueryKind::AheadElement => {
            // Guide edges come first (ids 0..n), so they win ties.
            let edge = first_ahead(&guide_edges());
            let limit = edge.map_or(f64::INFINITY, |e| e.0);
            let element = grid
                .and_then(|g| g.ray(p, dir, limit))
                .map(|(t, i)| (t, poly.len() + i));
            ahead(match (edge, element) {
                (Some(e), Some(x)) if x.0.total_cmp(&e.0).is_lt() => Some(x),
                (Some(e), _) => Some(e),
                (None, x) => x,
            })
        }
        // Answered by `collide`, which also reports the edge crossed.
        QueryKind::Collision => Answer::new(&[found(false)]),
    }
}

/// ?X: does the next element of length `delta` leave the guide or hit an
/// element? Returns the answer (found, id) and the guide edge it would cross
/// (where a link may hold a token to reserve).
///
/// The answer is the *nearest* hit along the segment, guide edge or drawn
/// segment (an edge wins a tie). Whether something is hit is exact
/// (`geometry::exact`): a segment through a vertex, touching an edge or lying
/// along a drawn segment hits it. A guide edge counts where the segment leaves
/// the guide or touches the edge from inside, not where it enters (a system
/// seeded on an edge does not hit it going in). A segment through a corner
/// meets both edges there at once: the hit is credited to the edge that starts
/// a link if only one of them does, else to the lower edge index.
pub(crate) fn collide(
    scene: &Scene,
    grid: Option<&Layers>,
    gi: usize,
    st: &State,
    delta: f64,
) -> (Answer, Option<usize>) {
    let p = st.pos.truncate();
    let q = (st.pos + st.h * delta * st.scale).truncate();
    let edge = edge_hit(scene, gi, p, q);
    let poly = &scene.guides[gi].polygon;
    let drawn = grid
        .and_then(|g| g.first_crossing(p, q))
        .filter(|&(t, _)| edge.is_none_or(|(te, _)| t < te));
    match (edge, drawn) {
        (_, Some((_, i))) => (Answer::new(&[1.0, (poly.len() + i) as f64]), None),
        (Some((_, e)), None) => (Answer::new(&[1.0, e as f64]), Some(e)),
        (None, None) => (Answer::new(&[0.0, 0.0]), None),
    }
}

/// The guide edge that segment `p`–`q` of a system in guide `gi` meets first
/// (see `collide`): (parameter along `p`–`q`, edge).
pub(crate) fn edge_hit(scene: &Scene, gi: usize, p: DVec2, q: DVec2) -> Option<(f64, usize)> {
    let poly = &scene.guides[gi].polygon;
    let inward = inward(poly);
    let linked = |e: usize| scene.links.iter().any(|l| l.from == (gi, e));
    let mut best: Option<(f64, usize)> = None;
    for i in 0..poly.len() {
        let Some(t) = edge_meet(poly, inward, i, p, q) else {
            continue;
        };
        let better = match best {
            None => true,
            Some((bt, bi)) => t < bt || (t == bt && linked(i) && !linked(bi)),
        };
        if better {
            best = Some((t, i));
        }
    }
    best
}

/// The side of its edges (as `orient(a, b, ·)`) on which a polygon lies.
pub(crate) fn inward(poly: &[DVec2]) -> Ordering {
    if signed_area(poly) >= 0.0 {
        Ordering::Greater
    } else {
        Ordering::Less
    }
}

/// Where segment `p`–`q` meets edge `e` of `poly` as a guide edge counts
/// (see `collide`): not when it ends strictly on the inner side (entering, or
/// starting on the edge and going in). `inward` is `inward(poly)`.
pub(crate) fn edge_meet(
    poly: &[DVec2],
    inward: Ordering,
    e: usize,
    p: DVec2,
    q: DVec2,
) -> Option<f64> {
    let n = poly.len();
    let (a, b) = (poly[e % n], poly[(e + 1) % n]);
    crossing(p, q, a, b).filter(|_| orient(a, b, q) != inward)
}
