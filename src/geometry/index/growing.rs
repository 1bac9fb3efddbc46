//! A segment index that follows a drawing as it grows: segments are added
//! for good (kept) and never moved, each with a key; one more batch (`live`)
//! is replaced whenever the caller likes (the segments still changing). The
//! caller numbers the segments: every search takes `rank`, which turns a key
//! into the segment's current number. Numbers may change from search to
//! search (a drawing that grows inserts segments between others).
//!
//! Owns: the kept segments in one `AppendGrid` (adding a batch costs the
//! batch) with their keys, and the live batch in a `SegmentGrid`. Every
//! search returns what one `SegmentGrid` over all segments in number order
//! returns (ties to the lowest number), as a number; the two grids change
//! speed, never answers. Must not know guides or systems.

use super::append::AppendGrid;
use super::segments::{self, Cells, GridLists, SegmentGrid};
use glam::DVec2;

/// The live batch: a grid over it, and each segment's key.
struct Live {
    grid: SegmentGrid,
    keys: Vec<u64>,
}

/// Segments kept and live, each with a key; see the module note.
#[derive(Default)]
pub struct GrowingGrid {
    kept: AppendGrid,
    /// The key of each kept segment, in the order added.
    keys: Vec<u64>,
    live: Option<Live>,
    /// The lists of the live batch before, emptied (`set_live_with` fills
    /// them rather than allocating new ones at every batch).
    spare: Option<(GridLists, Vec<u64>)>,
}

/// The better of two answers: the smaller first value, then the lower number.
fn better<T>(a: Option<(f64, T, u64)>, b: Option<(f64, T, u64)>) -> Option<(f64, T, u64)> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if y.0.total_cmp(&x.0).then(y.2.cmp(&x.2)).is_lt() {
            y
        } else {
            x
        }),
        (x, None) => x,
        (None, y) => y,
    }
}

impl GrowingGrid {
    /// Indexes `segs` as kept segments, keyed by their indices.
    pub fn new(segs: Vec<(DVec2, DVec2)>) -> GrowingGrid {
        let mut g = GrowingGrid::default();
        let keys = (0..segs.len() as u64).collect();
        g.push(&segs, keys);
        g
    }

    /// Adds segments for good, with their keys (none already held).
    pub fn push(&mut self, segs: &[(DVec2, DVec2)], keys: Vec<u64>) {
        debug_assert_eq!(segs.len(), keys.len());
        if segs.is_empty() {
            return;
        }
        self.kept.extend(segs);
        self.keys.extend(keys);
    }

    /// Replaces the live batch (segments that may still change) with `segs`
    /// and their keys (none held as kept).
    pub fn set_live(&mut self, segs: Vec<(DVec2, DVec2)>, keys: Vec<u64>) {
        self.set_live_with(|s, k| {
            *s = segs;
            *k = keys;
        });
    }

    /// Replaces the live batch with the segments and keys that `fill` adds
    /// to the two empty lists it is given (those of the batch before).
    pub fn set_live_with(&mut self, fill: impl FnOnce(&mut Vec<(DVec2, DVec2)>, &mut Vec<u64>)) {
        let (mut lists, mut keys) = match self.live.take() {
            Some(l) => {
                let mut keys = l.keys;
                keys.clear();
                (l.grid.into_lists(), keys)
            }
            None => self.spare.take().unwrap_or_default(),
        };
        fill(&mut lists.segs, &mut keys);
        debug_assert_eq!(lists.segs.len(), keys.len());
        if lists.segs.is_empty() {
            self.spare = Some((lists, keys));
        } else {
            self.live = Some(Live {
                grid: SegmentGrid::from_lists(lists),
                keys,
            });
        }
    }

    /// How many grids hold segments.
    pub fn parts(&self) -> usize {
        usize::from(!self.kept.is_empty()) + usize::from(self.live.is_some())
    }

    /// How many cells the grids have in all.
    pub fn cells(&self) -> usize {
        self.kept.cells() + self.live.as_ref().map_or(0, |l| l.grid.cells())
    }

    /// `SegmentGrid::first_crossing` over all segments: (parameter, number).
    pub fn first_crossing(
        &self,
        p: DVec2,
        q: DVec2,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        let order = |i: usize| rank(self.keys[i]);
        let kept = self
            .kept
            .first_crossing(p, q, &order)
            .map(|(t, i)| (t, (), order(i)));
        let live = self.live.as_ref().and_then(|l| {
            let order = |i: usize| rank(l.keys[i]);
            segments::first_crossing(&l.grid, p, q, &order).map(|(t, i)| (t, (), order(i)))
        });
        better(kept, live).map(|(t, (), i)| (t, i))
    }

    /// `SegmentGrid::nearest` over all segments: (distance, point, number).
    pub fn nearest(&self, p: DVec2, rank: &impl Fn(u64) -> u64) -> Option<(f64, DVec2, u64)> {
        let order = |i: usize| rank(self.keys[i]);
        let kept = self
            .kept
            .nearest(p, &order)
            .map(|(d, c, i)| (d, c, order(i)));
        let live = self.live.as_ref().and_then(|l| {
            if kept.is_some_and(|k| l.grid.box_distance(p) > k.0) {
                return None;
            }
            let order = |i: usize| rank(l.keys[i]);
            segments::nearest(&l.grid, p, &order).map(|(d, c, i)| (d, c, order(i)))
        });
        better(kept, live)
    }

    /// `SegmentGrid::ray` over all segments: (distance, number).
    pub fn ray(
        &self,
        p: DVec2,
        dir: DVec2,
        limit: f64,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        // A grid with few segments far apart would walk the ray far to its
        // own first hit: ask both within a short reach first, and only when
        // nothing is hit there, twice as far (the nearest hit within a reach
        // is the nearest of all).
        let layouts = [
            Some(self.kept.layout()),
            self.live.as_ref().map(|l| l.grid.layout()),
        ];
        let layouts = layouts.iter().flatten().filter(|l| l.cells() > 0);
        let cell = layouts
            .clone()
            .map(|l| l.stride())
            .fold(f64::INFINITY, f64::min);
        // Beyond the farthest corner of every box, a longer reach finds nothing more.
        let far = layouts.map(|l| l.far_corner(p)).fold(0.0, f64::max);
        let mut reach = 4.0 * cell;
        while reach.is_finite() && reach < limit && reach < far {
            if let Some(hit) = self.ray_within(p, dir, reach, rank) {
                return Some(hit);
            }
            reach *= 2.0;
        }
        self.ray_within(p, dir, limit, rank)
    }

    /// The first hit not farther than `limit`, asking both grids.
    fn ray_within(
        &self,
        p: DVec2,
        dir: DVec2,
        limit: f64,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        let order = |i: usize| rank(self.keys[i]);
        let kept = self
            .kept
            .ray(p, dir, limit, &order)
            .map(|(t, i)| (t, (), order(i)));
        // Hits at the kept hit's distance still count (a lower number wins).
        let lim = kept.map_or(limit, |k| k.0);
        let live = self.live.as_ref().and_then(|l| {
            let order = |i: usize| rank(l.keys[i]);
            segments::ray(&l.grid, p, dir, lim, &order).map(|(t, i)| (t, (), order(i)))
        });
        better(kept, live).map(|(t, (), i)| (t, i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::index::Lcg;

    /// Grows a drawing step by step: segments of several systems kept in
    /// batches at random, the rest live, with keys that are not in number
    /// order; every search must equal one grid over all segments in number
    /// order.
    #[test]
    fn answers_equal_one_grid_over_all_segments_in_key_order() {
        let mut r = Lcg(11);
        let systems = 4u64;
        // Per system: its segments, how many of them are kept.
        let mut drawn: Vec<(Vec<(DVec2, DVec2)>, usize)> =
            (0..systems).map(|_| (Vec::new(), 0)).collect();
        let mut grid = GrowingGrid::default();
        let (mut found, mut most_parts) = ([0usize; 3], 0);
        let mut placed: Vec<usize> = Vec::new();
        for step in 0..60 {
            let mut batch: Vec<(u64, (DVec2, DVec2))> = Vec::new();
            for (k, (segs, kept)) in drawn.iter_mut().enumerate() {
                let add = 1 + (r.next() * (4.0 + step as f64)) as usize;
                for _ in 0..add {
                    let from = segs.last().map_or(DVec2::ZERO, |s| s.1);
                    let a = (r.next() * 8.0).floor() * std::f64::consts::FRAC_PI_4;
                    // Axis-aligned and diagonal strides: many touches and overlaps.
                    let to = (from + DVec2::new(a.cos(), a.sin()) * 2.0).round();
                    segs.push((from, to));
                }
                // Keep some of the live ones for good.
                let keep = *kept + (r.next() * (segs.len() - *kept) as f64) as usize;
                for (i, s) in segs.iter().enumerate().take(keep).skip(*kept) {
                    batch.push(((k as u64) << 32 | i as u64, *s));
                }
                *kept = keep;
            }
            batch.sort_by_key(|b| b.0);
            // Keys are not numbers: the numbers are the places in `all`.
            let number = |k: u64| -> u64 { (k >> 32) * 1_000_000 + (k & 0xffff_ffff) };
            let segs: Vec<_> = batch.iter().map(|b| b.1).collect();
            grid.push(&segs, batch.iter().map(|b| !b.0).collect());
            let mut live: Vec<(u64, (DVec2, DVec2))> = Vec::new();
            let mut all: Vec<(u64, (DVec2, DVec2))> = Vec::new();
            for (k, (segs, kept)) in drawn.iter().enumerate() {
                for (i, s) in segs.iter().enumerate() {
                    let key = (k as u64) << 32 | i as u64;
                    all.push((key, *s));
                    if i >= *kept {
                        live.push((key, *s));
                    }
                }
            }
            grid.set_live(
                live.iter().map(|b| b.1).collect(),
                live.iter().map(|b| !b.0).collect(),
            );
            let rank = |k: u64| number(!k);
            most_parts = most_parts.max(grid.parts());
            if placed.last() != Some(&grid.kept.cells()) {
                placed.push(grid.kept.cells());
            }
            let whole = SegmentGrid::new(all.iter().map(|b| b.1).collect());
            let key = |i: usize| number(all[i].0);
            for k in 0..40 {
                let p = if k % 2 == 0 {
                    all[(r.next() * all.len() as f64) as usize].1.1
                } else {
                    DVec2::new(r.next() * 40.0 - 20.0, r.next() * 40.0 - 20.0)
                };
                let a = r.next() * std::f64::consts::TAU;
                let dir = DVec2::new(a.cos(), a.sin());
                let q = p + dir * 3.0;
                let x = whole.first_crossing(p, q).map(|(t, i)| (t, key(i)));
                assert_eq!(grid.first_crossing(p, q, &rank), x, "step {step}: {p} {q}");
                let n = whole.nearest(p).map(|(d, c, i)| (d, c, key(i)));
                assert_eq!(grid.nearest(p, &rank), n, "step {step}: {p}");
                let y = whole.ray(p, dir, f64::INFINITY).map(|(t, i)| (t, key(i)));
                assert_eq!(
                    grid.ray(p, dir, f64::INFINITY, &rank),
                    y,
                    "step {step}: {p}"
                );
                found[0] += usize::from(x.is_some());
                found[1] += usize::from(n.is_some());
                found[2] += usize::from(y.is_some());
            }
        }
        // The searches met segments; the kept grid chose its cells again
        // several times as it grew (asked in between at every step).
        assert!(found.iter().all(|&f| f > 300), "{found:?}");
        assert_eq!(most_parts, 2);
        assert!(placed.len() >= 4, "{placed:?}");
    }

    #[test]
    fn an_empty_grid_finds_nothing() {
        let mut g = GrowingGrid::default();
        assert_eq!(g.parts(), 0);
        let id = |k: u64| k;
        assert_eq!(g.first_crossing(DVec2::ZERO, DVec2::ONE, &id), None);
        let s = |x: f64| (DVec2::new(x, 0.0), DVec2::new(x, 1.0));
        g.set_live(vec![s(1.0)], vec![7]);
        assert_eq!(
            g.ray(DVec2::new(0.0, 0.5), DVec2::X, 100.0, &id),
            Some((1.0, 7))
        );
        g.set_live(Vec::new(), Vec::new());
        assert_eq!(g.parts(), 0);
        assert_eq!(g.ray(DVec2::new(0.0, 0.5), DVec2::X, 100.0, &id), None);
    }
}
