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
use crate::geometry::{closest_on_segment, crossing, ray_hit, signed_angle};
use crate::query::QueryKind;
use crate::turtle::{Sink, State};
use glam::{DVec2, DVec3};

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
    let link_edges = || -> Vec<(usize, DVec2, DVec2)> {
        scene
            .links
            .iter()
            .enumerate()
            .filter(|(_, l)| l.from.0 == gi)
            .map(|(i, l)| {
                let e = l.from.1 % poly.len().max(1);
                (i, poly[e], poly[(e + 1) % poly.len()])
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
        QueryKind::DistanceLink => nearest(&link_edges()),
        QueryKind::DistanceGuide => nearest(&guide_edges()),
        // Drawn segments have ids after the guide's edges, as for ?N_A and ?X.
        QueryKind::DistanceElement => match grid.and_then(|g| g.nearest(p)) {
            Some((d, c, i)) => closest(d, c, poly.len() + i),
            None => Answer::new(&[0.0; 4]),
        },
        QueryKind::AheadLink => ahead(first_ahead(&link_edges())),
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
pub(crate) fn collide(
    scene: &Scene,
    grid: Option<&Layers>,
    gi: usize,
    st: &State,
    delta: f64,
) -> (Answer, Option<usize>) {
    let p = st.pos.truncate();
    let q = (st.pos + st.h * delta * st.scale).truncate();
    let poly = &scene.guides[gi].polygon;
    let mut best: Option<(f64, usize)> = None;
    for (i, a, b) in edges(poly) {
        if let Some(t) = crossing(p, q, a, b)
            && t > 1e-6
            && best.is_none_or(|(bt, _)| t < bt)
        {
            best = Some((t, i));
        }
    }
    if let Some((_, edge)) = best {
        return (Answer::new(&[1.0, edge as f64]), Some(edge));
    }
    if let Some(i) = grid.and_then(|g| g.first_crossing(p, q)) {
        return (Answer::new(&[1.0, (poly.len() + i) as f64]), None);
    }
    (Answer::new(&[0.0, 0.0]), None)
}
