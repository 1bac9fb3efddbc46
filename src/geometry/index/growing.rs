//! A segment index that follows a drawing from step to step: when the new list
//! of segments holds the old one in order (what growth does: segments are
//! inserted, none removed or moved), only the inserted segments are indexed
//! anew; the earlier grids are kept and their segments renumbered.
//!
//! Owns: finding the old list in the new one, the parts (grids over earlier
//! lists, each with the current index of each of its segments) and when parts
//! are merged: at most [`MAX_PARTS`] (every search asks each part), and a part
//! at least a quarter of the size of the one before it is merged into it, so
//! that the part indexed anew at each step stays small. Every search returns
//! what `SegmentGrid` over the whole current list returns (ties to the lowest
//! index), so the parts change speed, never answers. Must not know guides or
//! systems.

use super::segments::SegmentGrid;
use glam::DVec2;

/// The most grids the segments are kept in.
pub const MAX_PARTS: usize = 3;

/// A grid over some of the current segments; `ids[i]` is the current index
/// of the grid's segment `i` (increasing).
struct Part {
    grid: SegmentGrid,
    ids: Vec<u32>,
}

impl Part {
    /// A grid over `segs[ids]` (`ids` increasing).
    fn over(segs: &[(DVec2, DVec2)], ids: Vec<u32>) -> Part {
        let picked = ids.iter().map(|&i| segs[i as usize]).collect();
        Part {
            grid: SegmentGrid::new(picked),
            ids,
        }
    }
}

/// The segments of a drawing in parts; see the module note.
pub struct GrowingGrid {
    segs: Vec<(DVec2, DVec2)>,
    parts: Vec<Part>,
    /// The list before the last update, emptied, for the caller to fill with
    /// the next (`buffer`): a large list is not allocated anew at each step.
    spare: Vec<(DVec2, DVec2)>,
}

/// Whether two segments are the same, bit for bit.
fn same(a: &(DVec2, DVec2), b: &(DVec2, DVec2)) -> bool {
    let bits = |s: &(DVec2, DVec2)| {
        [
            s.0.x.to_bits(),
            s.0.y.to_bits(),
            s.1.x.to_bits(),
            s.1.y.to_bits(),
        ]
    };
    bits(a) == bits(b)
}

/// Where each segment of `old` is in `new`, if `new` holds `old` in order
/// (the earliest such places), and the indices of the others.
fn embed(old: &[(DVec2, DVec2)], new: &[(DVec2, DVec2)]) -> Option<(Vec<u32>, Vec<u32>)> {
    if old.len() > new.len() || new.len() > u32::MAX as usize {
        return None;
    }
    let mut at = Vec::with_capacity(old.len());
    let mut fresh = Vec::with_capacity(new.len() - old.len());
    for (i, s) in new.iter().enumerate() {
        if at.len() < old.len() && same(&old[at.len()], s) {
            at.push(i as u32);
        } else {
            fresh.push(i as u32);
        }
    }
    (at.len() == old.len()).then_some((at, fresh))
}

/// Merges two increasing lists of indices (disjoint) into one.
fn merge(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] < b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

impl GrowingGrid {
    /// Indexes `segs` as one grid.
    pub fn new(segs: Vec<(DVec2, DVec2)>) -> GrowingGrid {
        if segs.len() > u32::MAX as usize {
            // Beyond what ids hold: never reached within the limits of a run.
            panic!("more than 2^32 segments in one drawing");
        }
        let parts = if segs.is_empty() {
            Vec::new()
        } else {
            vec![Part {
                grid: SegmentGrid::new(segs.clone()),
                ids: (0..segs.len() as u32).collect(),
            }]
        };
        GrowingGrid {
            segs,
            parts,
            spare: Vec::new(),
        }
    }

    /// An empty list with room, to fill with the segments of the next update.
    pub fn buffer(&mut self) -> Vec<(DVec2, DVec2)> {
        std::mem::take(&mut self.spare)
    }

    /// The index of `segs`, reusing this one's grids when `segs` holds its
    /// segments in order; otherwise indexed anew.
    pub fn update(mut self, segs: Vec<(DVec2, DVec2)>) -> GrowingGrid {
        let Some((at, fresh)) = embed(&self.segs, &segs) else {
            return GrowingGrid::new(segs);
        };
        // Mostly new: one grid is cheaper than many parts.
        if fresh.len() * 2 > segs.len() {
            return GrowingGrid::new(segs);
        }
        for part in &mut self.parts {
            for id in &mut part.ids {
                *id = at[*id as usize];
            }
        }
        let mut old = std::mem::replace(&mut self.segs, segs);
        old.clear();
        self.spare = old;
        if !fresh.is_empty() {
            self.parts.push(Part::over(&self.segs, fresh));
        }
        // Too many parts, or a part at least a quarter of the size of the one
        // before it: the last two become one.
        while let [.., a, b] = &self.parts[..]
            && (self.parts.len() > MAX_PARTS || b.ids.len() * 4 >= a.ids.len())
        {
            let ids = merge(&a.ids, &b.ids);
            self.parts.truncate(self.parts.len() - 2);
            self.parts.push(Part::over(&self.segs, ids));
        }
        self
    }

    /// The indexed segments, in their order.
    pub fn segs(&self) -> &[(DVec2, DVec2)] {
        &self.segs
    }

    /// How many grids hold the segments.
    pub fn parts(&self) -> usize {
        self.parts.len()
    }

    /// How many cells the grids have in all.
    pub fn cells(&self) -> usize {
        self.parts.iter().map(|p| p.grid.cells()).sum()
    }

    /// The smallest distance from `p` to the box of the segments.
    pub fn box_distance(&self, p: DVec2) -> f64 {
        self.parts
            .iter()
            .map(|x| x.grid.box_distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// `SegmentGrid::first_crossing` over the current segments.
    pub fn first_crossing(&self, p: DVec2, q: DVec2) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for part in &self.parts {
            if let Some((t, i)) = part.grid.first_crossing(p, q) {
                let i = part.ids[i] as usize;
                if best.is_none_or(|b| t.total_cmp(&b.0).then(i.cmp(&b.1)).is_lt()) {
                    best = Some((t, i));
                }
            }
        }
        best
    }

    /// `SegmentGrid::nearest` over the current segments.
    pub fn nearest(&self, p: DVec2) -> Option<(f64, DVec2, usize)> {
        let mut best: Option<(f64, DVec2, usize)> = None;
        for part in &self.parts {
            if best.is_some_and(|b| part.grid.box_distance(p) > b.0) {
                continue;
            }
            if let Some((d, c, i)) = part.grid.nearest(p) {
                let i = part.ids[i] as usize;
                if best.is_none_or(|b| d.total_cmp(&b.0).then(i.cmp(&b.2)).is_lt()) {
                    best = Some((d, c, i));
                }
            }
        }
        best
    }

    /// `SegmentGrid::ray` over the current segments.
    pub fn ray(&self, p: DVec2, dir: DVec2, limit: f64) -> Option<(f64, usize)> {
        if self.parts.len() < 2 {
            return self.ray_within(p, dir, limit);
        }
        // A part with few segments far apart would walk the ray far to its own
        // first hit: ask every part within a short reach first, and only
        // when nothing is hit there, twice as far (the nearest hit within a
        // reach is the nearest of all).
        let cell = self
            .parts
            .iter()
            .map(|x| x.grid.stride())
            .fold(f64::INFINITY, f64::min);
        // Beyond the farthest corner of every box, a longer reach finds nothing more.
        let far = self
            .parts
            .iter()
            .filter(|x| x.grid.cells() > 0)
            .map(|x| {
                let (lo, hi) = x.grid.bounds();
                (p - lo).abs().max((p - hi).abs()).length()
            })
            .fold(0.0, f64::max);
        let mut reach = 4.0 * cell;
        while reach.is_finite() && reach < limit && reach < far {
            if let Some(hit) = self.ray_within(p, dir, reach) {
                return Some(hit);
            }
            reach *= 2.0;
        }
        self.ray_within(p, dir, limit)
    }

    /// The first hit not farther than `limit`, asking every part.
    fn ray_within(&self, p: DVec2, dir: DVec2, limit: f64) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for part in &self.parts {
            // Hits at the best distance so far still count (a lower index wins).
            let lim = best.map_or(limit, |b| b.0);
            if let Some((t, i)) = part.grid.ray(p, dir, lim) {
                let i = part.ids[i] as usize;
                if best.is_none_or(|b| t.total_cmp(&b.0).then(i.cmp(&b.1)).is_lt()) {
                    best = Some((t, i));
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::index::Lcg;

    /// Grows a drawing step by step (segments inserted at random places, a few
    /// steps that remove or move one) and compares every search with one grid
    /// over the whole list.
    #[test]
    fn answers_equal_one_grid_over_the_whole_list_as_a_drawing_grows() {
        let mut r = Lcg(11);
        let mut segs: Vec<(DVec2, DVec2)> = Vec::new();
        let mut grid = GrowingGrid::new(Vec::new());
        let (mut found, mut most_parts, mut rebuilt) = ([0usize; 3], 0, 0);
        for step in 0..60 {
            let mut next = segs.clone();
            let add = 1 + (r.next() * (8.0 + step as f64 * 3.0)) as usize;
            for _ in 0..add {
                let at = (r.next() * (next.len() + 1) as f64) as usize;
                let from = if next.is_empty() {
                    DVec2::ZERO
                } else {
                    next[(r.next() * next.len() as f64) as usize].1
                };
                let a = (r.next() * 8.0).floor() * std::f64::consts::FRAC_PI_4;
                // Axis-aligned and diagonal strides: many touches and overlaps.
                let to = (from + DVec2::new(a.cos(), a.sin()) * 2.0).round();
                next.insert(at.min(next.len()), (from, to));
            }
            if step % 17 == 16 {
                next.remove(next.len() / 2);
            }
            if step % 23 == 22 {
                let last = next.len() - 1;
                next.swap(0, last);
            }
            let before = grid.parts();
            grid = grid.update(next.clone());
            rebuilt += usize::from(grid.parts() == 1 && before > 1);
            most_parts = most_parts.max(grid.parts());
            segs = next;
            let whole = SegmentGrid::new(segs.clone());
            assert_eq!(grid.segs(), &segs[..]);
            for k in 0..40 {
                let p = if k % 2 == 0 {
                    segs[(r.next() * segs.len() as f64) as usize].1
                } else {
                    DVec2::new(r.next() * 40.0 - 20.0, r.next() * 40.0 - 20.0)
                };
                let a = r.next() * std::f64::consts::TAU;
                let dir = DVec2::new(a.cos(), a.sin());
                let q = p + dir * 3.0;
                let x = whole.first_crossing(p, q);
                assert_eq!(grid.first_crossing(p, q), x, "step {step}: {p} {q}");
                let n = whole.nearest(p);
                assert_eq!(grid.nearest(p), n, "step {step}: {p}");
                let y = whole.ray(p, dir, f64::INFINITY);
                assert_eq!(grid.ray(p, dir, f64::INFINITY), y, "step {step}: {p}");
                found[0] += usize::from(x.is_some());
                found[1] += usize::from(n.is_some());
                found[2] += usize::from(y.is_some());
            }
        }
        // The searches met segments, the parts were used and merged.
        assert!(found.iter().all(|&f| f > 300), "{found:?}");
        assert!(most_parts >= 3, "{most_parts}");
        assert!(rebuilt > 0);
    }

    #[test]
    fn a_list_that_does_not_hold_the_old_one_is_indexed_anew() {
        let s = |x: f64| (DVec2::new(x, 0.0), DVec2::new(x, 1.0));
        let g = GrowingGrid::new((0..40).map(|i| s(f64::from(i))).collect());
        let g = g.update((0..40).map(|i| s(f64::from(i))).chain([s(50.0)]).collect());
        assert_eq!(g.parts(), 2);
        // The first segment moved: one grid again.
        let g = g.update((1..41).map(|i| s(f64::from(i))).collect());
        assert_eq!(g.parts(), 1);
        assert_eq!(g.ray(DVec2::new(0.0, 0.5), DVec2::X, 100.0), Some((1.0, 0)));
        let g = g.update(Vec::new());
        assert_eq!(g.parts(), 0);
        assert_eq!(g.first_crossing(DVec2::ZERO, DVec2::ONE), None);
    }
}
