//! The centre rule of guides: a guide keeps only what its drawing centres
//! inside its polygon (Guided Procedural Modeling §3.1).
//!
//! Owns: `Clip`, the turtle sink that forwards what a guide keeps and counts
//! what it removes, and the centres of elements (`element_centres`,
//! `outline_centre`). Must not know about scenes, links or the run loop; it
//! reads only a polygon, element centres and `crate::geometry`.

use crate::compile::Program;
use crate::geometry::inside;
use crate::turtle::{Drawn, Sink};
use glam::{DVec2, DVec3};

/// The centre of every element of `prog` in its local frame (`outline_centre`).
pub fn element_centres(prog: &Program) -> Vec<DVec2> {
    prog.elements
        .iter()
        .map(|e| outline_centre(&e.path))
        .collect()
}

/// The centre of an element's path data in its local frame (x right, y along the
/// heading): the middle of its outline's bounding box, or the origin for a path
/// that encloses nothing.
pub fn outline_centre(path: &str) -> DVec2 {
    crate::path::largest_outline(path)
        .and_then(|pts| {
            let first = *pts.first()?;
            let (lo, hi) = pts
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
            Some((lo + hi) * 0.5)
        })
        .unwrap_or(DVec2::ZERO)
}

/// Forwards to `inner` only what lies inside the guide by the centre rule: a
/// segment, element or polygon whose centre is outside its guide is removed (an
/// element's centre is that of its outline, placed and scaled as it is drawn).
/// `kept` counts what went through (and its bounding box, as the turtle's
/// `Drawn` has it: segment ends, polygon points, element origins).
pub struct Clip<'a> {
    pub polygon: &'a [DVec2],
    /// Per element index, its local centre (`element_centres`).
    pub centres: &'a [DVec2],
    pub inner: &'a mut dyn Sink,
    pub kept: Drawn,
    pub removed: u64,
}

impl<'a> Clip<'a> {
    pub fn new(polygon: &'a [DVec2], centres: &'a [DVec2], inner: &'a mut dyn Sink) -> Clip<'a> {
        Clip {
            polygon,
            centres,
            inner,
            kept: Drawn::default(),
            removed: 0,
        }
    }

    fn grow(&mut self, p: DVec3) {
        let b = self.kept.bbox.get_or_insert([p.x, p.y, p.x, p.y]);
        b[0] = b[0].min(p.x);
        b[1] = b[1].min(p.y);
        b[2] = b[2].max(p.x);
        b[3] = b[3].max(p.y);
    }
}

impl Sink for Clip<'_> {
    fn segment(&mut self, a: DVec3, b: DVec3, w: f64, c: u32) {
        if inside(((a + b) * 0.5).truncate(), self.polygon) {
            self.kept.segments += 1;
            self.grow(a);
            self.grow(b);
            self.inner.segment(a, b, w, c);
        } else {
            self.removed += 1;
        }
    }
    fn polygon(&mut self, pts: &[DVec3], c: u32) {
        let centre = pts.iter().fold(DVec3::ZERO, |s, &p| s + p) / pts.len().max(1) as f64;
        if inside(centre.truncate(), self.polygon) {
            self.kept.polygons += 1;
            for &p in pts {
                self.grow(p);
            }
            self.inner.polygon(pts, c);
        } else {
            self.removed += 1;
        }
    }
    fn element(&mut self, i: u16, at: DVec3, h: DVec3, l: DVec3, s: f64, c: u32) {
        let local = self.centres.get(i as usize).copied().unwrap_or(DVec2::ZERO);
        // Local +x is -l, local +y is h.
        let centre = at + (h * local.y - l * local.x) * s;
        if inside(centre.truncate(), self.polygon) {
            self.kept.elements += 1;
            self.grow(at);
            self.inner.element(i, at, h, l, s, c);
        } else {
            self.removed += 1;
        }
    }
}
