//! A uniform grid over segments: the index behind crossing, nearest-segment
//! and ray queries (the environment's `?X`, `?D_A` and `?N_A` over what a
//! guide drew).
//!
//! Owns: choosing the cells (`Layout`: about one per segment where the
//! segments are, up to `DENSER` per segment when they gather in a small part
//! of their box; never smaller than the mean segment length, at most
//! `MAX_CELLS_PER_AXIS` a side),
//! registering each segment in the cells along it, and the three searches,
//! written once over any store of cells (`Cells`: this grid's fixed lists,
//! `AppendGrid`'s growing ones). Every search returns exactly what a scan of
//! all segments would (ties go to the lowest index, or to the lowest `order`
//! the caller gives), so the index changes speed, never answers. Segments that touch the asking point
//! (a turtle's own last segment) are skipped, as the scan skips them. Must not
//! know guides or systems.

use crate::geometry::{closest_on_segment, crossing, ray_hit};
use glam::DVec2;
use std::cell::RefCell;

thread_local! {
    /// Cells and candidates of a search, reused from search to search (a
    /// query asks several grids many times a step).
    static SCRATCH: RefCell<(Vec<u32>, Vec<u32>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// The grid never has more than this many cells along an axis.
pub const MAX_CELLS_PER_AXIS: usize = 2048;

/// With fewer segments than this, the grid is one cell.
pub const SCAN_BELOW_SEGMENTS: usize = 32;

/// A segment touching the asking point within this distance is the asker's own.
pub const TOUCH: f64 = 1e-9;

/// Whether segment `s` touches `p` (and so is skipped by queries from `p`).
pub fn touches(s: &(DVec2, DVec2), p: DVec2) -> bool {
    // An end farther than twice the distance along an axis is farther in all
    // (rounding cannot bring it within): most segments are let go here,
    // without a square root.
    let near = |e: DVec2| {
        let d = (e - p).abs();
        d.x <= 2.0 * TOUCH && d.y <= 2.0 * TOUCH && (e - p).length() <= TOUCH
    };
    near(s.0) || near(s.1)
}

/// Where a grid's cells are: the box of its segments cut into `nx` × `ny`
/// cells (no cells when it holds no finite segment).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    min: DVec2,
    max: DVec2,
    /// Cell sizes (0 along an axis with one cell of zero extent).
    cell: DVec2,
    inv: DVec2,
    nx: usize,
    ny: usize,
    /// Length of the pieces a segment or ray is walked in: no longer than a
    /// cell along any axis with more than one cell.
    stride: f64,
}

/// A margin around every walked piece, so that rounding never hides a cell.
fn margin(p: DVec2) -> f64 {
    1e-9 * (1.0 + p.x.abs().max(p.y.abs()))
}

/// Whether both ends of a segment are finite (others cross nothing).
pub(crate) fn finite(s: &(DVec2, DVec2)) -> bool {
    s.0.is_finite() && s.1.is_finite()
}

impl Layout {
    /// No cells (nothing to find).
    pub(crate) fn empty() -> Layout {
        Layout {
            min: DVec2::splat(f64::INFINITY),
            max: DVec2::splat(f64::NEG_INFINITY),
            cell: DVec2::ZERO,
            inv: DVec2::ZERO,
            nx: 0,
            ny: 0,
            stride: f64::INFINITY,
        }
    }

    /// One cell over the box `min`–`max`.
    pub(crate) fn single(min: DVec2, max: DVec2) -> Layout {
        Layout {
            min,
            max,
            nx: 1,
            ny: 1,
            ..Layout::empty()
        }
    }

    /// About `n` cells over the box `min`–`max`, none shorter than `mean`
    /// (a mean segment's length), at most `MAX_CELLS_PER_AXIS` a side.
    pub(crate) fn fit(min: DVec2, max: DVec2, n: f64, mean: f64) -> Layout {
        let size = max - min;
        if !size.is_finite() {
            return Layout::single(min, max);
        }
        let c = mean.max((size.x * size.y / n).sqrt()).max(1e-12);
        let count = |extent: f64| -> usize {
            if extent <= 0.0 {
                1
            } else {
                ((extent / c).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS)
            }
        };
        let (nx, ny) = (count(size.x), count(size.y));
        let cell = DVec2::new(size.x / nx as f64, size.y / ny as f64);
        let inv = DVec2::new(
            if nx > 1 { 1.0 / cell.x } else { 0.0 },
            if ny > 1 { 1.0 / cell.y } else { 0.0 },
        );
        let mut stride = f64::INFINITY;
        if nx > 1 {
            stride = stride.min(cell.x);
        }
        if ny > 1 {
            stride = stride.min(cell.y);
        }
        Layout {
            min,
            max,
            cell,
            inv,
            nx,
            ny,
            stride,
        }
    }

    /// How many cells there are.
    pub(crate) fn cells(&self) -> usize {
        self.nx * self.ny
    }

    /// Whether the box holds segment `s` (without a margin).
    pub(crate) fn holds(&self, s: &(DVec2, DVec2)) -> bool {
        let (lo, hi) = (s.0.min(s.1), s.0.max(s.1));
        lo.x >= self.min.x && lo.y >= self.min.y && hi.x <= self.max.x && hi.y <= self.max.y
    }

    /// Calls `f(cell)` for every cell of finite segment `s`. A segment
    /// within one cell's stride is registered in the cells of its box (no
    /// margin: queries widen their own boxes), a longer one piece by piece.
    pub(crate) fn each_cell(
        &self,
        s: &(DVec2, DVec2),
        scratch: &mut Vec<u32>,
        mut f: impl FnMut(u32),
    ) {
        let (lo, hi) = (s.0.min(s.1), s.0.max(s.1));
        if hi.x - lo.x <= self.stride && hi.y - lo.y <= self.stride {
            let (c0, c1) = (self.col(lo.x), self.col(hi.x));
            let (r0, r1) = (self.row(lo.y), self.row(hi.y));
            for r in r0..=r1 {
                for c in c0..=c1 {
                    f((r * self.nx + c) as u32);
                }
            }
        } else {
            scratch.clear();
            self.walk(s.0, s.1, scratch);
            for &c in scratch.iter() {
                f(c);
            }
        }
    }

    fn col(&self, x: f64) -> usize {
        // The cast truncates, which is the floor here (the value is not negative).
        (((x - self.min.x) * self.inv.x).max(0.0) as usize).min(self.nx - 1)
    }

    fn row(&self, y: f64) -> usize {
        (((y - self.min.y) * self.inv.y).max(0.0) as usize).min(self.ny - 1)
    }

    /// The cells whose boxes meet the box of `a`–`b` widened by a margin, or
    /// nothing when that box misses the grid.
    fn boxed(&self, a: DVec2, b: DVec2, out: &mut Vec<u32>) -> bool {
        let m = margin(a).max(margin(b));
        let lo = a.min(b) - DVec2::splat(m);
        let hi = a.max(b) + DVec2::splat(m);
        if hi.x < self.min.x || hi.y < self.min.y || lo.x > self.max.x || lo.y > self.max.y {
            return false;
        }
        let (c0, c1) = (self.col(lo.x), self.col(hi.x));
        let (r0, r1) = (self.row(lo.y), self.row(hi.y));
        for r in r0..=r1 {
            for c in c0..=c1 {
                out.push((r * self.nx + c) as u32);
            }
        }
        true
    }

    /// The cells along `a`–`b`, each once: the segment is walked in pieces no
    /// longer than a cell, so a long segment touches few cells per piece.
    fn walk(&self, a: DVec2, b: DVec2, out: &mut Vec<u32>) {
        let len = (b - a).length();
        let pieces = if self.stride.is_finite() && len > self.stride {
            ((len / self.stride).ceil() as usize).min(4 * MAX_CELLS_PER_AXIS)
        } else {
            1
        };
        if pieces == 1 {
            // One box: its cells are distinct already.
            self.boxed(a, b, out);
            return;
        }
        let first = out.len();
        for k in 0..pieces {
            let p = a.lerp(b, k as f64 / pieces as f64);
            let q = a.lerp(b, (k + 1) as f64 / pieces as f64);
            self.boxed(p, q, out);
        }
        out[first..].sort_unstable();
        let mut w = first;
        for r in first..out.len() {
            if r == first || out[r] != out[w - 1] {
                out[w] = out[r];
                w += 1;
            }
        }
        out.truncate(w);
    }

    /// The length of a cell's side along its shortest axis of more than one
    /// cell (infinite for one cell).
    pub(crate) fn stride(&self) -> f64 {
        self.stride
    }

    /// The distance from `p` to the farthest corner of the box.
    pub(crate) fn far_corner(&self, p: DVec2) -> f64 {
        (p - self.min).abs().max((p - self.max).abs()).length()
    }

    /// The smallest distance from `p` to the box.
    pub(crate) fn box_distance(&self, p: DVec2) -> f64 {
        (self.min - p).max(p - self.max).max(DVec2::ZERO).length()
    }
}

/// Segments in cells, as the searches read them. Segment `i` is ordered
/// among equally good answers by `order(i)`, given to each search.
pub(crate) trait Cells {
    fn layout(&self) -> &Layout;
    fn segs(&self) -> &[(DVec2, DVec2)];
    /// Calls `f` with every segment in cell `c`, each once.
    fn for_items(&self, c: u32, f: impl FnMut(u32));
}

/// The segments in `cells`, each once, in index order, into `out`.
fn candidates(g: &impl Cells, cells: &[u32], out: &mut Vec<u32>) {
    out.clear();
    for &c in cells {
        g.for_items(c, |i| out.push(i));
    }
    out.sort_unstable();
    out.dedup();
}

/// The segment that `p`–`q` meets first going from `p` (crossing, touching
/// or overlapping on one line; [`crossing`]): (parameter along `p`–`q`,
/// index), the lowest `order` among equally near ones. Segments touching `p`
/// (the asker's own) and segments that `p` lies on (what the turtle stands
/// on) are skipped.
pub(crate) fn first_crossing(
    g: &impl Cells,
    p: DVec2,
    q: DVec2,
    order: &impl Fn(usize) -> u64,
) -> Option<(f64, usize)> {
    let l = g.layout();
    if l.nx == 0 || !(p.is_finite() && q.is_finite()) {
        return None;
    }
    let segs = g.segs();
    let hit = |i: usize| -> Option<(f64, usize)> {
        let s = &segs[i];
        if touches(s, p) {
            return None;
        }
        crossing(p, q, s.0, s.1)
            .filter(|&t| t > 0.0)
            .map(|t| (t, i))
    };
    let nearer = |best: Option<(f64, usize)>, x: (f64, usize)| match best {
        Some(b)
            if b.0
                .total_cmp(&x.0)
                .then_with(|| order(b.1).cmp(&order(x.1)))
                .is_le() =>
        {
            Some(b)
        }
        _ => Some(x),
    };
    if l.cells() == 1 {
        // Boxes apart: no segment is met (as `crossing` decides it first).
        if p.x.max(q.x) < l.min.x
            || l.max.x < p.x.min(q.x)
            || p.y.max(q.y) < l.min.y
            || l.max.y < p.y.min(q.y)
        {
            return None;
        }
        let mut best = None;
        g.for_items(0, |i| {
            if let Some(x) = hit(i as usize) {
                best = nearer(best, x);
            }
        });
        return best;
    }
    SCRATCH.with_borrow_mut(|(cells, cands)| {
        cells.clear();
        l.walk(p, q, cells);
        candidates(g, cells, cands);
        cands
            .iter()
            .filter_map(|&i| hit(i as usize))
            .fold(None, nearer)
    })
}

/// The closest segment to `p` not touching it: (distance, closest point,
/// index), the lowest `order` among equally close ones.
pub(crate) fn nearest(
    g: &impl Cells,
    p: DVec2,
    order: &impl Fn(usize) -> u64,
) -> Option<(f64, DVec2, usize)> {
    let l = g.layout();
    if l.nx == 0 || !p.is_finite() {
        return None;
    }
    let segs = g.segs();
    let (ci, cj) = (l.col(p.x), l.row(p.y));
    let mut best: Option<(f64, DVec2, usize)> = None;
    let better = |d: f64, i: usize, b: &Option<(f64, DVec2, usize)>| match b {
        None => true,
        Some((bd, _, bi)) => d
            .total_cmp(bd)
            .then_with(|| order(i).cmp(&order(*bi)))
            .is_lt(),
    };
    let visit = |col: usize, row: usize, best: &mut Option<(f64, DVec2, usize)>| {
        g.for_items((row * l.nx + col) as u32, |i| {
            let i = i as usize;
            let s = &segs[i];
            if touches(s, p) {
                return;
            }
            let c = closest_on_segment(p, s.0, s.1);
            let d = (c - p).length();
            if better(d, i, best) {
                *best = Some((d, c, i));
            }
        });
    };
    for r in 0..l.nx.max(l.ny) {
        let (c0, c1) = (ci.saturating_sub(r), (ci + r).min(l.nx - 1));
        let (r0, r1) = (cj.saturating_sub(r), (cj + r).min(l.ny - 1));
        // Only the ring at distance r: the inside was searched before.
        let top = cj + r < l.ny;
        let bottom = r > 0 && cj >= r;
        for col in c0..=c1 {
            if bottom {
                visit(col, cj - r, &mut best);
            }
            if top {
                visit(col, cj + r, &mut best);
            }
        }
        let inner = (
            cj.saturating_sub(r.saturating_sub(1)),
            (cj + r).saturating_sub(1).min(l.ny - 1),
        );
        if r > 0 {
            for row in inner.0..=inner.1 {
                if ci >= r {
                    visit(ci - r, row, &mut best);
                }
                if ci + r < l.nx {
                    visit(ci + r, row, &mut best);
                }
            }
        }
        // Whatever lies beyond the searched block is at least this far away.
        let mut bound = f64::INFINITY;
        if c0 > 0 {
            bound = bound.min(p.x - (l.min.x + c0 as f64 * l.cell.x));
        }
        if c1 + 1 < l.nx {
            bound = bound.min(l.min.x + (c1 + 1) as f64 * l.cell.x - p.x);
        }
        if r0 > 0 {
            bound = bound.min(p.y - (l.min.y + r0 as f64 * l.cell.y));
        }
        if r1 + 1 < l.ny {
            bound = bound.min(l.min.y + (r1 + 1) as f64 * l.cell.y - p.y);
        }
        if bound == f64::INFINITY {
            break;
        }
        if let Some((d, _, _)) = best
            && d < bound - margin(p) * 16.0
        {
            break;
        }
    }
    best
}

/// The first segment hit by the ray from `p` along unit `dir`, not farther
/// than `limit`: (distance, index), the lowest `order` among equal distances.
/// Segments touching `p` are skipped.
pub(crate) fn ray(
    g: &impl Cells,
    p: DVec2,
    dir: DVec2,
    limit: f64,
    order: &impl Fn(usize) -> u64,
) -> Option<(f64, usize)> {
    let l = g.layout();
    if l.nx == 0 || !(p.is_finite() && dir.is_finite()) {
        return None;
    }
    if dir.length_squared() == 0.0 {
        return None;
    }
    // The part of the ray inside the grid's box (widened by a margin).
    let m = DVec2::splat(margin(l.min).max(margin(l.max)) * 16.0);
    let (lo, hi) = (l.min - m, l.max + m);
    let (mut enter, mut exit) = (0.0f64, f64::INFINITY);
    for (o, d, a, b) in [(p.x, dir.x, lo.x, hi.x), (p.y, dir.y, lo.y, hi.y)] {
        if d == 0.0 {
            if o < a || o > b {
                return None;
            }
        } else {
            let (t0, t1) = ((a - o) / d, (b - o) / d);
            enter = enter.max(t0.min(t1));
            exit = exit.min(t0.max(t1));
        }
    }
    if enter.is_nan() || exit.is_nan() || enter > exit || enter > limit {
        return None;
    }
    // One piece when there is one cell; else pieces of a cell's length.
    let (stride, pieces) = if l.stride.is_finite() && l.cells() > 1 {
        let across = (exit.min(limit) - enter) / l.stride;
        (
            l.stride,
            (across.ceil().max(0.0) as usize).min(8 * MAX_CELLS_PER_AXIS) + 2,
        )
    } else {
        (f64::INFINITY, 1)
    };
    let segs = g.segs();
    SCRATCH.with_borrow_mut(|(cells, cands)| {
        let mut best: Option<(f64, usize)> = None;
        for k in 0..pieces {
            let t0 = enter + k as f64 * stride;
            if t0 > limit || t0 > exit {
                break;
            }
            let t1 = t0 + stride;
            cells.clear();
            if pieces == 1 {
                cells.extend(0..l.cells() as u32);
            } else if !l.boxed(p + dir * t0, p + dir * t1, cells) {
                break;
            }
            candidates(g, cells, cands);
            for &i in cands.iter() {
                let i = i as usize;
                let s = &segs[i];
                if touches(s, p) {
                    continue;
                }
                if let Some(t) = ray_hit(p, dir, s.0, s.1)
                    && t <= limit
                    && best.is_none_or(|(bt, bi)| {
                        t.total_cmp(&bt)
                            .then_with(|| order(i).cmp(&order(bi)))
                            .is_lt()
                    })
                {
                    best = Some((t, i));
                }
            }
            // A hit not yet seen lies beyond this piece.
            if best.is_some_and(|(t, _)| t < t1 - margin(p + dir * t1) * 16.0) {
                break;
            }
        }
        best
    })
}

/// Segments in a grid of cells, fixed once built; see the module note.
pub struct SegmentGrid {
    segs: Vec<(DVec2, DVec2)>,
    layout: Layout,
    /// Cell `c` holds `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Cells for SegmentGrid {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn segs(&self) -> &[(DVec2, DVec2)] {
        &self.segs
    }
    fn for_items(&self, c: u32, f: impl FnMut(u32)) {
        let c = c as usize;
        self.items[self.start[c] as usize..self.start[c + 1] as usize]
            .iter()
            .copied()
            .for_each(f);
    }
}

/// The box of the finite segments, their count and total length.
pub(crate) fn extent(segs: &[(DVec2, DVec2)]) -> (DVec2, DVec2, usize, f64) {
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    let mut len = 0.0;
    let mut n = 0usize;
    for s in segs.iter().filter(|s| finite(s)) {
        min = min.min(s.0).min(s.1);
        max = max.max(s.0).max(s.1);
        len += (s.1 - s.0).length();
        n += 1;
    }
    (min, max, n, len)
}

/// Registers every finite segment of `segs` in the cells of `l` along it
/// (counting sort: one pass counts, one pass places): cell `c` holds
/// `items[start[c]..start[c + 1]]`. `start` and `items` come empty.
fn fill(l: &Layout, segs: &[(DVec2, DVec2)], start: &mut Vec<u32>, items: &mut Vec<u32>) {
    let cells = l.cells();
    start.resize(cells + 1, 0);
    let mut scratch = Vec::new();
    for s in segs.iter().filter(|s| finite(s)) {
        l.each_cell(s, &mut scratch, |c| start[c as usize + 1] += 1);
    }
    for c in 0..cells {
        start[c + 1] += start[c];
    }
    items.resize(start[cells] as usize, 0);
    // Each cell's start serves as its cursor, which ends at the next cell's
    // start; the starts are then shifted back by one cell.
    for (i, s) in segs.iter().enumerate().filter(|(_, s)| finite(s)) {
        l.each_cell(s, &mut scratch, |c| {
            let at = &mut start[c as usize];
            items[*at as usize] = i as u32;
            *at += 1;
        });
    }
    start.copy_within(0..cells, 1);
    start[0] = 0;
}

/// The most cells per segment a grid is given where its segments gather in
/// a small part of their box.
const DENSER: f64 = 8.0;

/// How many cells of `l` hold the middle of a finite segment of `segs`.
fn occupied(l: &Layout, segs: &[(DVec2, DVec2)]) -> usize {
    let mut seen = vec![0u64; l.cells().div_ceil(64)];
    let mut n = 0;
    for s in segs.iter().filter(|s| finite(s)) {
        let m = (s.0 + s.1) * 0.5;
        let c = l.row(m.y) * l.nx + l.col(m.x);
        let bit = 1u64 << (c % 64);
        if seen[c / 64] & bit == 0 {
            seen[c / 64] |= bit;
            n += 1;
        }
    }
    n
}

/// The lists a [`SegmentGrid`] is built in. A grid taken apart
/// ([`SegmentGrid::into_lists`]) gives them back emptied, so that the next
/// grid built from them ([`SegmentGrid::from_lists`]) allocates nothing new.
#[derive(Default)]
pub struct GridLists {
    /// The segments to index.
    pub segs: Vec<(DVec2, DVec2)>,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl SegmentGrid {
    /// Indexes `segs` (the grid keeps them). Segments with a coordinate that
    /// is not finite are left out (they cross nothing).
    pub fn new(segs: Vec<(DVec2, DVec2)>) -> SegmentGrid {
        SegmentGrid::from_lists(GridLists {
            segs,
            ..GridLists::default()
        })
    }

    /// Indexes `lists.segs`, building the cells in the other lists.
    pub fn from_lists(lists: GridLists) -> SegmentGrid {
        let GridLists {
            segs,
            mut start,
            mut items,
        } = lists;
        let (min, max, n, len) = extent(&segs);
        let layout = if n == 0 {
            Layout::empty()
        } else if n < SCAN_BELOW_SEGMENTS {
            // A few segments: a scan of one cell is cheaper than sorting them into cells.
            Layout::single(min, max)
        } else {
            // About one cell per segment where the segments are, and cells
            // at least as long as a mean segment.
            let mean = len / n as f64;
            let coarse = Layout::fit(min, max, n as f64, mean);
            let spread = coarse.cells() as f64 / occupied(&coarse, &segs).max(1) as f64;
            Layout::fit(min, max, n as f64 * spread.clamp(1.0, DENSER), mean)
        };
        start.clear();
        items.clear();
        if n > 0 {
            fill(&layout, &segs, &mut start, &mut items);
        }
        SegmentGrid {
            segs,
            layout,
            start,
            items,
        }
    }

    /// The grid's lists, emptied (see [`GridLists`]).
    pub fn into_lists(self) -> GridLists {
        let mut lists = GridLists {
            segs: self.segs,
            start: self.start,
            items: self.items,
        };
        lists.segs.clear();
        lists
    }

    /// How many cells the grid has (0 when it holds no finite segment).
    pub fn cells(&self) -> usize {
        self.layout.cells()
    }

    /// The smallest distance from `p` to the box of the segments.
    pub fn box_distance(&self, p: DVec2) -> f64 {
        self.layout.box_distance(p)
    }

    /// The indexed segments, in their order.
    pub fn segs(&self) -> &[(DVec2, DVec2)] {
        &self.segs
    }

    /// [`first_crossing`], ties to the lowest index.
    pub fn first_crossing(&self, p: DVec2, q: DVec2) -> Option<(f64, usize)> {
        first_crossing(self, p, q, &|i| i as u64)
    }

    /// [`nearest`], ties to the lowest index.
    pub fn nearest(&self, p: DVec2) -> Option<(f64, DVec2, usize)> {
        nearest(self, p, &|i| i as u64)
    }

    /// [`ray`], ties to the lowest index.
    pub fn ray(&self, p: DVec2, dir: DVec2, limit: f64) -> Option<(f64, usize)> {
        ray(self, p, dir, limit, &|i| i as u64)
    }
}
