//! Element outlines for the OBJ mesh: the flat face an element prints.
//!
//! Owns: choosing an element's outline (its path's largest closed subpath,
//! read and flattened by `crate::path`) and orienting it counter-clockwise.
//! Must not read path data itself or write anything.

use crate::geometry::signed_area;
use crate::path::{clean_outline, largest_outline};
use glam::DVec2;

/// A flattened closed outline in an element's local frame (x right, y forward).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementOutline {
    pub points: Vec<DVec2>,
}

impl ElementOutline {
    /// The outline cleaned and counter-clockwise; empty when it has no area.
    pub(super) fn oriented(self) -> Vec<DVec2> {
        let mut pts = clean_outline(self.points);
        let area = signed_area(&pts);
        if area < 0.0 {
            pts.reverse();
        }
        if pts.len() < 3 || area == 0.0 {
            pts.clear();
        }
        pts
    }
}

/// The outline of the largest closed subpath (by area) of SVG path data;
/// curves become `path::CURVE_STEPS` pieces each, arcs are converted to
/// curves. `None` when no subpath encloses any area (an open stroke, empty or
/// bad data).
pub fn outline_from_path(d: &str) -> Option<ElementOutline> {
    largest_outline(d).map(|points| ElementOutline { points })
}
