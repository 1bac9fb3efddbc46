//! A uniform grid over points: the index for nearest neighbours (inference's
//! transformation spaces) and for the points within a distance (snapping guide
//! vertices in `lsyc edit`).
//!
//! Owns: choosing the cells (about two points a cell, or a size the caller
//! gives) and the two searches. Every search returns exactly what a scan of all
//! points would, ties broken by the lower index. Must not know what the points
//! stand for.

use crate::geometry::dist;
use glam::DVec2;
use std::collections::HashMap;

/// The most cells along either axis.
pub const MAX_CELLS_PER_AXIS: usize = 1 << 16;

/// Points in square cells, by cell.
pub struct PointGrid {
    points: Vec<DVec2>,
    min: DVec2,
    cell: f64,
    cols: i64,
    rows: i64,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl PointGrid {
    /// A grid of about two points a cell, also when the points lie on a line.
    pub fn new(points: &[DVec2]) -> PointGrid {
        let size = extent(points).1;
        let n = points.len().max(1) as f64;
        let cell = (2.0 * size.x * size.y / n)
            .sqrt()
            .max(2.0 * size.x.max(size.y) / n)
            .max(1e-12);
        PointGrid::with_cell(points, cell)
    }

    /// A grid of cells `cell` wide: for searches within a known distance, that
    /// distance. Cells are at least 10⁻¹² wide and at most [`MAX_CELLS_PER_AXIS`]
    /// span the points (the answers do not depend on the cell size).
    pub fn with_cell(points: &[DVec2], cell: f64) -> PointGrid {
        let (min, size) = extent(points);
        let cell = if cell.is_finite() { cell } else { 1.0 }
            .max(1e-12)
            .max(size.x.max(size.y) / MAX_CELLS_PER_AXIS as f64);
        let cols = ((size.x / cell).floor() as i64).saturating_add(1);
        let rows = ((size.y / cell).floor() as i64).saturating_add(1);
        let mut g = PointGrid {
            points: points.to_vec(),
            min,
            cell,
            cols,
            rows,
            cells: HashMap::new(),
        };
        for (i, p) in points.iter().enumerate() {
            let k = g.key(*p);
            g.cells.entry(k).or_default().push(i);
        }
        g
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        let q = (p - self.min) / self.cell;
        (
            (q.x.floor() as i64).clamp(0, self.cols - 1),
            (q.y.floor() as i64).clamp(0, self.rows - 1),
        )
    }

    /// The `k` points nearest to `p` (including any at `p` itself), nearest
    /// first (by squared distance), ties by index.
    pub fn nearest(&self, p: DVec2, k: usize) -> Vec<usize> {
        let k = k.min(self.points.len());
        if k == 0 {
            return Vec::new();
        }
        let (cx, cy) = self.key(p);
        let mut found: Vec<(f64, usize)> = Vec::new();
        let mut ring = 0i64;
        loop {
            // A sparse grid (far-apart points in small cells): once a ring
            // would visit more cells than there are points, a scan is cheaper
            // and gives the same answer.
            if ring > 0
                && (2 * ring + 1).saturating_mul(2 * ring + 1) > 4 * self.points.len() as i64 + 64
            {
                return self.scan(p, k);
            }
            let (x0, x1) = ((cx - ring).max(0), (cx + ring).min(self.cols - 1));
            let (y0, y1) = ((cy - ring).max(0), (cy + ring).min(self.rows - 1));
            for x in x0..=x1 {
                // Only the ring's border: all of a column at its two ends.
                let border = (x - cx).abs() == ring;
                let mut y = y0;
                while y <= y1 {
                    if border || (y - cy).abs() == ring {
                        if let Some(c) = self.cells.get(&(x, y)) {
                            for &i in c {
                                found.push((self.points[i].distance_squared(p), i));
                            }
                        }
                        y += 1;
                    } else {
                        // Jump to the bottom edge of the ring.
                        y = (cy + ring).max(y + 1);
                    }
                }
            }
            // Every point within `ring` cells of p's cell has been seen; a
            // point outside is at least `ring` cells away.
            if found.len() >= k {
                found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                let reach = ring as f64 * self.cell;
                if found[k - 1].0 <= reach * reach {
                    break;
                }
            }
            if ring > self.cols.max(self.rows) {
                found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                break;
            }
            ring += 1;
        }
        found.truncate(k);
        found.into_iter().map(|(_, i)| i).collect()
    }

    /// The `k` nearest points by a scan of all, ordered as [`Self::nearest`].
    fn scan(&self, p: DVec2, k: usize) -> Vec<usize> {
        let mut all: Vec<(f64, usize)> = self
            .points
            .iter()
            .enumerate()
            .map(|(i, q)| (q.distance_squared(p), i))
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        all.into_iter().take(k).map(|(_, i)| i).collect()
    }

    /// The points within distance `r` of `p` ([`dist`] ≤ r), by index.
    pub fn within(&self, p: DVec2, r: f64) -> Vec<usize> {
        if !(p.is_finite() && r.is_finite()) || self.points.is_empty() {
            return Vec::new();
        }
        let (x0, y0) = self.key(p - DVec2::splat(r));
        let (x1, y1) = self.key(p + DVec2::splat(r));
        let mut out: Vec<usize> = (x0..=x1)
            .flat_map(|x| (y0..=y1).map(move |y| (x, y)))
            .filter_map(|c| self.cells.get(&c))
            .flatten()
            .copied()
            .filter(|&i| dist(self.points[i], p) <= r)
            .collect();
        out.sort_unstable();
        out
    }
}

/// The lower corner and the size (at least 10⁻⁹ a side) of the points' box; the
/// origin and a unit size for none.
fn extent(points: &[DVec2]) -> (DVec2, DVec2) {
    if points.is_empty() {
        return (DVec2::ZERO, DVec2::ONE);
    }
    let (min, max) = points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (min, (max - min).max(DVec2::splat(1e-9)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice() -> Vec<DVec2> {
        (0..100)
            .map(|i| DVec2::new((i % 10) as f64, (i / 10) as f64 * 1.5))
            .collect()
    }

    #[test]
    fn nearest_points_in_order() {
        let g = PointGrid::new(&lattice());
        assert_eq!(g.nearest(DVec2::new(4.1, 3.0), 3), vec![24, 25, 23]);
        assert_eq!(g.nearest(DVec2::new(100.0, 100.0), 1), vec![99]);
        assert!(PointGrid::new(&[]).nearest(DVec2::ZERO, 3).is_empty());
    }

    #[test]
    fn within_is_a_scan() {
        let pts = lattice();
        for cell in [0.1, 1.0, 7.0] {
            let g = PointGrid::with_cell(&pts, cell);
            for (p, r) in [(DVec2::new(4.1, 3.0), 1.2), (DVec2::new(-1.0, 0.0), 1.0)] {
                let scan: Vec<usize> = (0..pts.len()).filter(|&i| dist(pts[i], p) <= r).collect();
                assert_eq!(g.within(p, r), scan, "cell {cell}, {p}");
            }
        }
    }

    #[test]
    fn far_apart_points_and_tiny_cells_neither_overflow_nor_hang() {
        let pts = [
            DVec2::new(-1e150, 0.0),
            DVec2::ZERO,
            DVec2::new(1e150, 1e150),
        ];
        let g = PointGrid::with_cell(&pts, 1e-4);
        assert_eq!(g.within(DVec2::ZERO, 1e-4), vec![1]);
        assert_eq!(g.nearest(DVec2::new(2e150, 1e150), 2), vec![2, 1]);
        let huge = [DVec2::new(f64::MAX, 0.0), DVec2::new(-f64::MAX, 0.0)];
        let g = PointGrid::with_cell(&huge, 1.0);
        assert_eq!(g.nearest(DVec2::ZERO, 1), vec![0]);
        assert_eq!(g.within(DVec2::new(f64::MAX, 0.0), 1.0), vec![0]);
    }
}
