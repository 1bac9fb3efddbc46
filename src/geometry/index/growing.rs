//! A segment index that follows a drawing as it grows: segments are added in
//! batches (parts) and never moved, each with a key; one more part (`live`)
//! is replaced whenever the caller likes (the segments still changing). The
//! caller numbers the segments: every search takes `rank`, which turns a key
//! into the segment's current number. Numbers may change from search to
//! search, but not the order of two segments a part holds (a drawing that
//! grows inserts segments, it does not move them).
//!
//! Owns: the parts (a grid over each batch, in number order, with each
//! segment's key) and when they are merged: at most [`MAX_PARTS`] kept parts
//! (every search asks each part), and a part at least a quarter of the size
//! of the one before it is merged into it, so that a part indexed anew stays
//! small. Every search returns what one `SegmentGrid` over all segments in
//! number order returns (ties to the lowest number), as a number; the parts
//! change speed, never answers. Must not know guides or systems.

use super::segments::SegmentGrid;
use glam::DVec2;

/// The most grids the kept segments are in (the live part comes on top).
pub const MAX_PARTS: usize = 6;

/// A grid over some of the segments; `keys[i]` is the key of the grid's
/// segment `i` (in number order).
struct Part {
    grid: SegmentGrid,
    keys: Vec<u64>,
}

impl Part {
    fn new(segs: Vec<(DVec2, DVec2)>, keys: Vec<u64>) -> Part {
        debug_assert_eq!(segs.len(), keys.len());
        Part {
            grid: SegmentGrid::new(segs),
            keys,
        }
    }

    /// The two parts as one, in number order.
    fn merge(a: &Part, b: &Part, rank: &impl Fn(u64) -> u64) -> Part {
        let n = a.keys.len() + b.keys.len();
        let (mut segs, mut keys) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let (sa, sb) = (a.grid.segs(), b.grid.segs());
        let (mut i, mut j) = (0, 0);
        while i < sa.len() || j < sb.len() {
            if j == sb.len() || (i < sa.len() && rank(a.keys[i]) < rank(b.keys[j])) {
                segs.push(sa[i]);
                keys.push(a.keys[i]);
                i += 1;
            } else {
                segs.push(sb[j]);
                keys.push(b.keys[j]);
                j += 1;
            }
        }
        Part::new(segs, keys)
    }
}

/// Segments in parts, each with a key; see the module note.
#[derive(Default)]
pub struct GrowingGrid {
    parts: Vec<Part>,
    live: Option<Part>,
}

impl GrowingGrid {
    /// Indexes `segs` as one kept part, keyed by their indices.
    pub fn new(segs: Vec<(DVec2, DVec2)>) -> GrowingGrid {
        let mut g = GrowingGrid::default();
        let keys = (0..segs.len() as u64).collect();
        g.push(segs, keys, &|k| k);
        g
    }

    /// Adds segments for good, with their keys (none already held), in
    /// number order.
    pub fn push(&mut self, segs: Vec<(DVec2, DVec2)>, keys: Vec<u64>, rank: &impl Fn(u64) -> u64) {
        if segs.is_empty() {
            return;
        }
        self.parts.push(Part::new(segs, keys));
        // Too many parts, or a part at least a quarter of the size of the one
        // before it: the last two become one.
        while let [.., a, b] = &self.parts[..]
            && (self.parts.len() > MAX_PARTS || b.keys.len() * 4 >= a.keys.len())
        {
            let m = Part::merge(a, b, rank);
            self.parts.truncate(self.parts.len() - 2);
            self.parts.push(m);
        }
    }

    /// Replaces the live part (segments that may still change) with `segs`
    /// and their keys (none held by a kept part), in number order.
    pub fn set_live(&mut self, segs: Vec<(DVec2, DVec2)>, keys: Vec<u64>) {
        self.live = (!segs.is_empty()).then(|| Part::new(segs, keys));
    }

    /// Every part, kept then live.
    fn all(&self) -> impl Iterator<Item = &Part> {
        self.parts.iter().chain(self.live.as_ref())
    }

    /// How many grids hold the segments.
    pub fn parts(&self) -> usize {
        self.all().count()
    }

    /// How many cells the grids have in all.
    pub fn cells(&self) -> usize {
        self.all().map(|p| p.grid.cells()).sum()
    }

    /// The smallest distance from `p` to the box of the segments.
    pub fn box_distance(&self, p: DVec2) -> f64 {
        self.all()
            .map(|x| x.grid.box_distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// `SegmentGrid::first_crossing` over all segments: (parameter, number).
    pub fn first_crossing(
        &self,
        p: DVec2,
        q: DVec2,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        let mut best: Option<(f64, u64)> = None;
        for part in self.all() {
            if let Some((t, i)) = part.grid.first_crossing(p, q) {
                let i = rank(part.keys[i]);
                if best.is_none_or(|b| t.total_cmp(&b.0).then(i.cmp(&b.1)).is_lt()) {
                    best = Some((t, i));
                }
            }
        }
        best
    }

    /// `SegmentGrid::nearest` over all segments: (distance, point, number).
    pub fn nearest(&self, p: DVec2, rank: &impl Fn(u64) -> u64) -> Option<(f64, DVec2, u64)> {
        let mut best: Option<(f64, DVec2, u64)> = None;
        for part in self.all() {
            if best.is_some_and(|b| part.grid.box_distance(p) > b.0) {
                continue;
            }
            if let Some((d, c, i)) = part.grid.nearest(p) {
                let i = rank(part.keys[i]);
                if best.is_none_or(|b| d.total_cmp(&b.0).then(i.cmp(&b.2)).is_lt()) {
                    best = Some((d, c, i));
                }
            }
        }
        best
    }

    /// `SegmentGrid::ray` over all segments: (distance, number).
    pub fn ray(
        &self,
        p: DVec2,
        dir: DVec2,
        limit: f64,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        if self.parts() < 2 {
            return self.ray_within(p, dir, limit, rank);
        }
        // A part with few segments far apart would walk the ray far to its own
        // first hit: ask every part within a short reach first, and only
        // when nothing is hit there, twice as far (the nearest hit within a
        // reach is the nearest of all).
        let cell = self
            .all()
            .map(|x| x.grid.stride())
            .fold(f64::INFINITY, f64::min);
        // Beyond the farthest corner of every box, a longer reach finds nothing more.
        let far = self
            .all()
            .filter(|x| x.grid.cells() > 0)
            .map(|x| {
                let (lo, hi) = x.grid.bounds();
                (p - lo).abs().max((p - hi).abs()).length()
            })
            .fold(0.0, f64::max);
        let mut reach = 4.0 * cell;
        while reach.is_finite() && reach < limit && reach < far {
            if let Some(hit) = self.ray_within(p, dir, reach, rank) {
                return Some(hit);
            }
            reach *= 2.0;
        }
        self.ray_within(p, dir, limit, rank)
    }

    /// The first hit not farther than `limit`, asking every part.
    fn ray_within(
        &self,
        p: DVec2,
        dir: DVec2,
        limit: f64,
        rank: &impl Fn(u64) -> u64,
    ) -> Option<(f64, u64)> {
        let mut best: Option<(f64, u64)> = None;
        for part in self.all() {
            // Hits at the best distance so far still count (a lower index wins).
            let lim = best.map_or(limit, |b| b.0);
            if let Some((t, i)) = part.grid.ray(p, dir, lim) {
                let i = rank(part.keys[i]);
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
            grid.push(
                batch.iter().map(|b| b.1).collect(),
                batch.iter().map(|b| !b.0).collect(),
                &|k| number(!k),
            );
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
        // The searches met segments, and the kept parts were merged.
        assert!(found.iter().all(|&f| f > 300), "{found:?}");
        assert!((3..=MAX_PARTS + 1).contains(&most_parts), "{most_parts}");
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
