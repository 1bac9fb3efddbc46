//! Checking an inferred program with the library itself: the program's text
//! is parsed, checked, derived and drawn as `lsyc run` would, and the drawn
//! segments are compared with the drawing's.
//!
//! Owns: the comparison (segments matched, the symmetric Chamfer distance of
//! points sampled along both drawings). Must not change the program.

use super::ideal::Similarity;
use super::turtle::PER_CELL;
use crate::geometry::index::PointGrid;
use crate::turtle::Sink;
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// How a redraw compares with the drawing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Redraw {
    /// Steps of the drawing drawn again.
    pub matched: usize,
    /// Steps of the drawing.
    pub steps: usize,
    /// Steps the program drew.
    pub drawn: usize,
    /// Symmetric Chamfer distance (mean of both mean nearest distances) of
    /// points sampled along both, user units.
    pub chamfer: f64,
    /// The drawing's diagonal, user units.
    pub diagonal: f64,
}

impl Redraw {
    /// The Chamfer distance relative to the diagonal.
    pub fn relative(&self) -> f64 {
        if self.diagonal > 0.0 {
            self.chamfer / self.diagonal
        } else {
            self.chamfer
        }
    }
}

/// Collects drawn segments in the plane.
#[derive(Default)]
struct Segments(Vec<(DVec2, DVec2)>);

impl Sink for Segments {
    fn segment(&mut self, a: DVec3, b: DVec3, _width: f64, _color: u32) {
        self.0.push((a.truncate(), b.truncate()));
    }
    fn polygon(&mut self, _points: &[DVec3], _color: u32) {}
    fn element(&mut self, _i: u16, _at: DVec3, _h: DVec3, _l: DVec3, _s: f64, _c: u32) {}
}

/// Cuts segments into steps of `step`.
fn steps(segments: &[(DVec2, DVec2)], step: f64) -> Vec<(DVec2, DVec2)> {
    let mut out = Vec::new();
    for &(a, b) in segments {
        let n = (a.distance(b) / step).round().max(1.0) as usize;
        for k in 0..n {
            out.push((
                a.lerp(b, k as f64 / n as f64),
                a.lerp(b, (k + 1) as f64 / n as f64),
            ));
        }
    }
    out
}

/// Derives and draws the program `text` and compares it with `segments`
/// (world coordinates, steps of `step`). `None` if the program does not run
/// (which would be a bug of the emitter).
pub fn redraw(text: &str, segments: &[(DVec2, DVec2)], step: f64) -> Option<Redraw> {
    let drawn = steps(&drawn(text, 0)?, step);
    let input = steps(segments, step);
    Some(compare(&input, &drawn, step))
}

/// The segments (x–y plane) the program `text` draws when derived `more`
/// steps beyond its own `derive`, as `lsyc run` derives and draws it (seed
/// 0). `None` if the program does not run.
pub fn drawn(text: &str, more: u32) -> Option<Vec<(DVec2, DVec2)>> {
    let mut sink = Segments::default();
    crate::infer::program::draw(text, more, &mut sink)?;
    Some(sink.0)
}

/// Compares two sets of steps.
pub fn compare(input: &[(DVec2, DVec2)], drawn: &[(DVec2, DVec2)], step: f64) -> Redraw {
    let tol = 0.1 * step;
    let cell = step / 2.0;
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut by_mid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in input.iter().enumerate() {
        by_mid.entry(key((s.0 + s.1) / 2.0)).or_default().push(i);
    }
    let mut used = vec![false; input.len()];
    let mut matched = 0;
    for s in drawn {
        let mid = (s.0 + s.1) / 2.0;
        let (cx, cy) = key(mid);
        let mut hit = None;
        'look: for dx in -1..=1 {
            for dy in -1..=1 {
                let cell = by_mid.get(&(cx + dx, cy + dy)).map_or(&[][..], |v| &v[..]);
                for &i in cell.iter().take(PER_CELL) {
                    let t = input[i];
                    let same = (t.0.distance(s.0) <= tol && t.1.distance(s.1) <= tol)
                        || (t.0.distance(s.1) <= tol && t.1.distance(s.0) <= tol);
                    if same && !used[i] {
                        hit = Some(i);
                        break 'look;
                    }
                }
            }
        }
        if let Some(i) = hit {
            used[i] = true;
            matched += 1;
        }
    }
    let (lo, hi) = input.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), s| (lo.min(s.0).min(s.1), hi.max(s.0).max(s.1)),
    );
    let diagonal = if input.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    };
    Redraw {
        matched,
        steps: input.len(),
        drawn: drawn.len(),
        chamfer: chamfer(input, drawn),
        diagonal,
    }
}

/// The similarity that brings the steps `drawn` nearest the steps
/// `truth`: least squares over the steps' ends and midpoints, each paired
/// with the nearest point of `truth` to where the last fit puts it, in
/// `ROUNDS` rounds. `None` when either is empty.
pub(crate) fn similarity_fit(
    drawn: &[(DVec2, DVec2)],
    truth: &[(DVec2, DVec2)],
) -> Option<Similarity> {
    const ROUNDS: usize = 12;
    const MOST_POINTS: usize = 30_000;
    if drawn.is_empty() || truth.is_empty() {
        return None;
    }
    let every = (3 * drawn.len()).div_ceil(MOST_POINTS).max(1);
    let points: Vec<DVec2> = drawn
        .iter()
        .flat_map(|&(a, b)| [a, (a + b) / 2.0, b])
        .step_by(every)
        .collect();
    let grid = crate::geometry::index::SegmentGrid::new(truth.to_vec());
    let mut fit: Option<Similarity> = None;
    for _ in 0..ROUNDS {
        let pairs: Vec<(DVec2, DVec2)> = points
            .iter()
            .filter_map(|&p| {
                let at = fit.map_or(p, |f| f.apply(p));
                grid.nearest(at).map(|(_, q, _)| (p, q))
            })
            .collect();
        fit = Some(Similarity::fit(&pairs)?);
    }
    fit
}

/// Points a quarter of a step apart along each step (at most about 2
/// million in all: farther apart on larger drawings).
fn samples(steps: &[(DVec2, DVec2)]) -> Vec<DVec2> {
    let per = (2_000_000 / steps.len().max(1)).clamp(1, 4);
    let mut out = Vec::with_capacity(steps.len() * per);
    for &(a, b) in steps {
        for k in 0..per {
            out.push(a.lerp(b, (k as f64 + 0.5) / per as f64));
        }
    }
    out
}

/// Symmetric Chamfer distance of points sampled along two sets of steps.
pub fn chamfer(a: &[(DVec2, DVec2)], b: &[(DVec2, DVec2)]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::INFINITY;
    }
    let (sa, sb) = (samples(a), samples(b));
    // Cells about the sample spacing: an exact redraw finds each point's
    // twin in its own cell; others go to the point grid.
    let spacing = a
        .iter()
        .map(|s| s.0.distance(s.1))
        .fold(0.0, f64::max)
        .max(1e-12);
    (one_way(&sa, &sb, spacing) + one_way(&sb, &sa, spacing)) / 2.0
}

fn one_way(from: &[DVec2], to: &[DVec2], cell: f64) -> f64 {
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
    for (i, p) in to.iter().enumerate() {
        cells.entry(key(*p)).or_default().push(i as u32);
    }
    let mut grid: Option<PointGrid> = None;
    let mut sum = 0.0;
    for p in from {
        let (cx, cy) = key(*p);
        let mut best = f64::INFINITY;
        for dx in -1..=1 {
            for dy in -1..=1 {
                let cell = cells.get(&(cx + dx, cy + dy)).map_or(&[][..], |v| &v[..]);
                for &i in cell.iter().take(PER_CELL) {
                    best = best.min(p.distance(to[i as usize]));
                }
            }
        }
        // Within the 3×3 cells, the nearest is certain only up to one cell.
        if best > cell {
            let g = grid.get_or_insert_with(|| PointGrid::new(to));
            best = g
                .nearest(*p, 1)
                .first()
                .map_or(f64::INFINITY, |&i| p.distance(to[i]));
        }
        sum += best;
    }
    sum / from.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_similarity_is_fitted_back() {
        // A zigzag of 40 steps, turned by 0.3°, scaled by 1.002 and moved
        // by 0.36: the fit brings the first within a twentieth of the second
        // (nearest points slide along the steps, so not exactly).
        let mut steps = Vec::new();
        let mut p = DVec2::ZERO;
        for i in 0..40 {
            let q = p + DVec2::new(1.0, if i % 2 == 0 { 0.7 } else { -0.4 });
            steps.push((p, q));
            p = q;
        }
        let (angle, scale, shift) = (0.3f64.to_radians(), 1.002, DVec2::new(0.3, -0.2));
        let moved_point = |p: DVec2| DVec2::from_angle(angle).rotate(p) * scale + shift;
        let moved: Vec<_> = steps
            .iter()
            .map(|&(a, b)| (moved_point(a), moved_point(b)))
            .collect();
        let fit = similarity_fit(&steps, &moved).expect("a fit");
        assert!((fit.angle() - angle).abs() < 1e-4, "{fit:?}");
        assert!((fit.scale() - scale).abs() < 1e-3, "{fit:?}");
        for &(a, _) in &steps {
            assert!(fit.apply(a).distance(moved_point(a)) < 0.05, "{fit:?}");
        }
    }
}
