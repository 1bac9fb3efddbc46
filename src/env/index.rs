//! The spatial index of the segments drawn in a guide, as the environment
//! asks it: a `Grid` (the crate's `geometry::index::GrowingGrid`, kept from
//! step to step while the systems grow; the engine keeps one per guide, over
//! the segments of all its systems), and `Layers`, which turns the grid's
//! keys into ids: the segments of all systems of the guide numbered in order,
//! as if all were one list.
//!
//! Owns: the keys (a piece of a system's drawing and a segment's place in it)
//! and turning them into ids. Must not index or search segments itself.

pub use crate::geometry::index::GrowingGrid as Grid;
pub use crate::geometry::index::segments::{
    MAX_CELLS_PER_AXIS, SCAN_BELOW_SEGMENTS, TOUCH, touches,
};
use glam::DVec2;

/// The key of segment `place` of the piece `piece` of a drawing (pieces are
/// numbered in a guide as they are made).
pub fn key(piece: usize, place: usize) -> u64 {
    ((piece as u64) << 32) | place as u64
}

/// A guide's grid with the id of each piece's first segment.
pub struct Layers<'a> {
    pub grid: Option<&'a Grid>,
    /// Per piece: the id of its first segment (how many segments the guide's
    /// drawings hold before it).
    pub offsets: &'a [usize],
}

/// The id of the segment with key `key`, given each piece's first id.
pub fn id(offsets: &[usize], key: u64) -> u64 {
    (offsets[(key >> 32) as usize] + (key & u64::from(u32::MAX)) as usize) as u64
}

impl Layers<'_> {
    /// The id of the segment with key `key`.
    pub fn id(&self, key: u64) -> u64 {
        id(self.offsets, key)
    }

    /// `Grid::first_crossing`: the nearest along `p`–`q`, then the lowest id.
    pub fn first_crossing(&self, p: DVec2, q: DVec2) -> Option<(f64, usize)> {
        let (t, i) = self.grid?.first_crossing(p, q, &|k| self.id(k))?;
        Some((t, i as usize))
    }

    /// `Grid::nearest`: the closest, then the lowest id.
    pub fn nearest(&self, p: DVec2) -> Option<(f64, DVec2, usize)> {
        let (d, c, i) = self.grid?.nearest(p, &|k| self.id(k))?;
        Some((d, c, i as usize))
    }

    /// `Grid::ray`: the nearest hit, then the lowest id.
    pub fn ray(&self, p: DVec2, dir: DVec2, limit: f64) -> Option<(f64, usize)> {
        let (t, i) = self.grid?.ray(p, dir, limit, &|k| self.id(k))?;
        Some((t, i as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::index::Lcg;
    use crate::geometry::{closest_on_segment, crossing, ray_hit};

    fn scan_crossing(segs: &[(DVec2, DVec2)], p: DVec2, q: DVec2) -> Option<(f64, usize)> {
        segs.iter()
            .enumerate()
            .filter(|(_, s)| !touches(s, p))
            .filter_map(|(i, s)| {
                crossing(p, q, s.0, s.1)
                    .filter(|&t| t > 0.0)
                    .map(|t| (t, i))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
    }

    fn scan_nearest(segs: &[(DVec2, DVec2)], p: DVec2) -> Option<(f64, usize)> {
        segs.iter()
            .enumerate()
            .filter(|(_, s)| !touches(s, p))
            .map(|(i, s)| ((closest_on_segment(p, s.0, s.1) - p).length(), i))
            .min_by(|x, y| x.0.total_cmp(&y.0))
    }

    fn scan_ray(segs: &[(DVec2, DVec2)], p: DVec2, dir: DVec2) -> Option<(f64, usize)> {
        segs.iter()
            .enumerate()
            .filter(|(_, s)| !touches(s, p))
            .filter_map(|(i, s)| ray_hit(p, dir, s.0, s.1).map(|t| (t, i)))
            .min_by(|x, y| x.0.total_cmp(&y.0))
    }

    /// Compares the grid with the scans; returns how many asks found something
    /// (crossing, nearest, ray).
    fn check(segs: &[(DVec2, DVec2)], asks: &[(DVec2, DVec2)]) -> [usize; 3] {
        let grid = Grid::new(segs.to_vec());
        let id = |k: u64| k;
        let mut found = [0; 3];
        for &(p, dir) in asks {
            let q = p + dir * 3.0;
            let x = grid.first_crossing(p, q, &id).map(|(t, k)| (t, k as usize));
            found[0] += usize::from(x.is_some());
            found[1] += usize::from(grid.nearest(p, &id).is_some());
            found[2] += usize::from(grid.ray(p, dir, f64::INFINITY, &id).is_some());
            assert_eq!(x, scan_crossing(segs, p, q), "{p} {q}");
            // The same segments as three systems' drawings, in a kept part
            // and the live one, ids running on.
            let (a, b) = (segs.len() / 3, 2 * segs.len() / 3);
            let mut split = Grid::default();
            let keyed = |range: std::ops::Range<usize>| -> Vec<u64> {
                range
                    .map(|i| {
                        let k = usize::from(i >= a) + usize::from(i >= b);
                        key(k, i - [0, a, b][k])
                    })
                    .collect()
            };
            let kept: Vec<usize> = (0..segs.len()).filter(|i| i % 3 != 1).collect();
            let offsets = [0, a, b];
            let kept_segs: Vec<_> = kept.iter().map(|&i| segs[i]).collect();
            split.push(
                &kept_segs,
                kept.iter().flat_map(|&i| keyed(i..i + 1)).collect(),
            );
            let live: Vec<usize> = (0..segs.len()).filter(|i| i % 3 == 1).collect();
            split.set_live(
                live.iter().map(|&i| segs[i]).collect(),
                live.iter().flat_map(|&i| keyed(i..i + 1)).collect(),
            );
            let layers = Layers {
                grid: Some(&split),
                offsets: &offsets,
            };
            assert_eq!(layers.first_crossing(p, q), x);
            assert_eq!(
                layers.nearest(p).map(|(d, _, i)| (d, i)),
                scan_nearest(segs, p)
            );
            assert_eq!(layers.ray(p, dir, f64::INFINITY), scan_ray(segs, p, dir));
            assert_eq!(
                grid.nearest(p, &id).map(|(d, _, i)| (d, i as usize)),
                scan_nearest(segs, p),
                "{p}"
            );
            assert_eq!(
                grid.ray(p, dir, f64::INFINITY, &id)
                    .map(|(t, k)| (t, k as usize)),
                scan_ray(segs, p, dir),
                "{p} {dir}"
            );
        }
        found
    }

    #[test]
    fn answers_equal_a_scan_of_every_segment() {
        let mut r = Lcg(7);
        let mut found = [0; 3];
        for round in 0..20 {
            let n = 1 + round * 37;
            let spread = 10.0 + round as f64 * 20.0;
            let mut segs = Vec::new();
            let mut at = DVec2::ZERO;
            for k in 0..n {
                // Chains of short segments (like growth), a few long ones.
                if k % 13 == 0 {
                    at = DVec2::new(r.next() * spread, r.next() * spread);
                }
                let len = if k % 29 == 0 {
                    spread
                } else {
                    1.0 + r.next() * 3.0
                };
                let a = r.next() * std::f64::consts::TAU;
                let next = at + DVec2::new(a.cos(), a.sin()) * len;
                segs.push((at, next));
                at = next;
            }
            // Ask from segment ends (the asker's own segment is skipped), from
            // free points, and from outside everything.
            let mut asks = Vec::new();
            for s in segs.iter().step_by(3) {
                let a = r.next() * std::f64::consts::TAU;
                asks.push((s.1, DVec2::new(a.cos(), a.sin())));
            }
            for _ in 0..50 {
                let a = r.next() * std::f64::consts::TAU;
                let p = DVec2::new(r.next() * 1.4 - 0.2, r.next() * 1.4 - 0.2) * spread;
                asks.push((p, DVec2::new(a.cos(), a.sin())));
            }
            let f = check(&segs, &asks);
            for k in 0..3 {
                found[k] += f[k];
            }
        }
        // The asks meet the geometry often enough to test something.
        assert!(found.iter().all(|&f| f > 300), "{found:?}");
    }

    #[test]
    fn ties_go_to_the_lowest_index_and_degenerate_sets_work() {
        let id = |k: u64| k;
        // Two copies of one segment after 40 far-away ones: the lower index wins
        // every query, through the cells and through the one-cell scan.
        let s = (DVec2::new(0.0, 5.0), DVec2::new(10.0, 5.0));
        let mut segs: Vec<_> = (0..40)
            .map(|i| (DVec2::new(50.0, i as f64), DVec2::new(51.0, i as f64)))
            .collect();
        segs.extend([s, s]);
        let p = DVec2::new(5.0, 0.0);
        for n in [42, 20] {
            let grid = Grid::new(segs[40 - (n - 2)..].to_vec());
            let segs = &segs[40 - (n - 2)..];
            assert_eq!(grid.cells() > 1, n == 42);
            let first = segs.len() as u64 - 2;
            assert_eq!(
                grid.first_crossing(p, DVec2::new(5.0, 10.0), &id),
                Some((0.5, first))
            );
            assert_eq!(grid.nearest(p, &id).map(|x| x.2), Some(first));
            assert_eq!(
                grid.ray(p, DVec2::Y, f64::INFINITY, &id),
                Some((5.0, first))
            );
            assert_eq!(grid.ray(p, DVec2::Y, 4.0, &id), None, "beyond the limit");
        }
        // All on one horizontal line, all at one point, empty, not finite.
        let line: Vec<_> = (0..100)
            .map(|i| (DVec2::new(i as f64, 0.0), DVec2::new(i as f64 + 0.5, 0.0)))
            .collect();
        check(
            &line,
            &[
                (DVec2::new(10.2, -1.0), DVec2::Y),
                (DVec2::new(-3.0, 0.0), DVec2::X),
            ],
        );
        let point = vec![(DVec2::ONE, DVec2::ONE); 3];
        check(&point, &[(DVec2::ZERO, DVec2::ONE.normalize())]);
        check(&[], &[(DVec2::ZERO, DVec2::Y)]);
        let wild = vec![
            (DVec2::new(f64::NAN, 0.0), DVec2::ONE),
            (DVec2::new(-1e300, 0.0), DVec2::new(1e300, 1.0)),
        ];
        let g = Grid::new(wild);
        assert_eq!(
            g.first_crossing(DVec2::new(0.0, -1.0), DVec2::new(0.0, 2.0), &id)
                .map(|x| x.1),
            Some(1)
        );
    }

    #[test]
    fn segments_gathered_in_a_corner_get_finer_cells_and_the_same_answers() {
        // A dense lattice of short streets in one corner of a wide box (the
        // growing tips of a drawing, far from one another), a few far away.
        let mut segs = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let p = DVec2::new(i as f64, j as f64);
                segs.push((p, p + DVec2::X));
                segs.push((p, p + DVec2::Y));
            }
        }
        segs.push((DVec2::new(1000.0, 1000.0), DVec2::new(1001.0, 1000.0)));
        segs.push((DVec2::new(1000.0, 0.0), DVec2::new(1000.0, 1.0)));
        let n = segs.len();
        let grid = crate::geometry::index::segments::SegmentGrid::new(segs.clone());
        // One cell per segment over the whole box would make cells of about
        // 22 units, each holding some 1,000 segments of the lattice.
        assert!(grid.cells() > 4 * n, "{} cells", grid.cells());
        let mut r = Lcg(11);
        let mut asks = Vec::new();
        for _ in 0..300 {
            let a = r.next() * std::f64::consts::TAU;
            // On the lattice's points and lines, and between them.
            let p = DVec2::new((r.next() * 45.0).round(), r.next() * 45.0);
            asks.push((p, DVec2::new(a.cos(), a.sin())));
            asks.push((DVec2::new(p.y, p.x), DVec2::X));
        }
        asks.push((DVec2::new(500.0, 500.0), DVec2::ONE.normalize()));
        asks.push((DVec2::new(999.0, 0.5), DVec2::X));
        let found = check(&segs, &asks);
        assert!(found.iter().all(|&f| f > 200), "{found:?}");
    }
}
