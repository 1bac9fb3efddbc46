//! A uniform grid that segments are added to and never leave: each cell a
//! list that grows, so adding a batch costs the batch, not the grid. The
//! cells are chosen again (every segment placed anew) only when the grid has
//! grown four times since they were chosen, or a segment lies outside their
//! box; the box is then widened by a quarter on every side, so a drawing
//! that grows outward is placed anew a few times, not at every batch.
//!
//! Owns: the cells and when they are chosen again. The searches are
//! `segments`' (ties to the lowest `order` the caller gives). Must not know
//! what the segments stand for.

use super::segments::{
    Cells, Layout, SCAN_BELOW_SEGMENTS, extent, finite, first_crossing, nearest, ray,
};
use glam::DVec2;

/// Segments a chunk holds.
const CHUNK: usize = 6;

/// No chunk.
const NONE: u32 = u32::MAX;

/// Some of a cell's segments, and the chunk with the rest.
#[derive(Clone, Copy)]
struct Chunk {
    items: [u32; CHUNK],
    len: u32,
    next: u32,
}

/// Segments in growing cells; see the module note.
pub struct AppendGrid {
    segs: Vec<(DVec2, DVec2)>,
    layout: Layout,
    /// Per cell, its newest chunk (`NONE`: the cell is empty).
    heads: Vec<u32>,
    /// The chunks of every cell, one list per cell (in one arena, so that
    /// adding a segment allocates nothing per cell).
    chunks: Vec<Chunk>,
    /// The cells are chosen again once this many segments are held.
    again_at: usize,
}

impl Default for AppendGrid {
    fn default() -> AppendGrid {
        AppendGrid {
            segs: Vec::new(),
            layout: Layout::empty(),
            heads: Vec::new(),
            chunks: Vec::new(),
            again_at: 0,
        }
    }
}

impl Cells for AppendGrid {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn segs(&self) -> &[(DVec2, DVec2)] {
        &self.segs
    }
    fn for_items(&self, c: u32, mut f: impl FnMut(u32)) {
        let mut at = self.heads[c as usize];
        while at != NONE {
            let k = &self.chunks[at as usize];
            k.items[..k.len as usize].iter().for_each(|&i| f(i));
            at = k.next;
        }
    }
}

/// Adds segment `i` to cell `c`.
fn add(heads: &mut [u32], chunks: &mut Vec<Chunk>, c: u32, i: u32) {
    let head = &mut heads[c as usize];
    if *head != NONE {
        let k = &mut chunks[*head as usize];
        if (k.len as usize) < CHUNK {
            k.items[k.len as usize] = i;
            k.len += 1;
            return;
        }
    }
    let mut items = [0; CHUNK];
    items[0] = i;
    chunks.push(Chunk {
        items,
        len: 1,
        next: *head,
    });
    *head = (chunks.len() - 1) as u32;
}

impl AppendGrid {
    /// How many segments it holds.
    pub fn len(&self) -> usize {
        self.segs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.segs.is_empty()
    }

    /// How many cells it has.
    pub fn cells(&self) -> usize {
        self.layout.cells()
    }

    /// Segment `i` (in the order added).
    pub fn seg(&self, i: usize) -> (DVec2, DVec2) {
        self.segs[i]
    }

    /// Adds `segs`; they get the next indices, in order. Segments with a
    /// coordinate that is not finite are held but in no cell.
    pub fn extend(&mut self, segs: &[(DVec2, DVec2)]) {
        let first = self.segs.len();
        self.segs.extend_from_slice(segs);
        let outside = segs.iter().any(|s| finite(s) && !self.layout.holds(s));
        if self.segs.len() >= self.again_at || outside {
            self.place_all();
            return;
        }
        self.place(first);
    }

    /// Places the segments from `first` on in their cells.
    fn place(&mut self, first: usize) {
        let mut scratch = Vec::new();
        let l = self.layout;
        let (heads, chunks) = (&mut self.heads, &mut self.chunks);
        for (i, s) in self.segs.iter().enumerate().skip(first) {
            if finite(s) {
                l.each_cell(s, &mut scratch, |c| add(heads, chunks, c, i as u32));
            }
        }
    }

    /// Chooses the cells for what is held (about two per segment, over the
    /// box widened by a quarter on every side) and places every segment.
    fn place_all(&mut self) {
        let (min, max, n, len) = extent(&self.segs);
        self.again_at = 4 * self.segs.len().max(SCAN_BELOW_SEGMENTS / 4);
        self.heads.clear();
        self.chunks.clear();
        if n == 0 {
            self.layout = Layout::empty();
            return;
        }
        let pad = (max - min) * 0.25;
        let (lo, hi) = (min - pad, max + pad);
        self.layout = if !(lo.is_finite() && hi.is_finite()) {
            Layout::single(min, max)
        } else if n < SCAN_BELOW_SEGMENTS {
            Layout::single(lo, hi)
        } else {
            Layout::fit(lo, hi, 2.0 * n as f64, len / n as f64)
        };
        self.heads.resize(self.layout.cells(), NONE);
        self.place(0);
    }

    /// [`first_crossing`], ties to the lowest `order`.
    pub fn first_crossing(
        &self,
        p: DVec2,
        q: DVec2,
        order: &impl Fn(usize) -> u64,
    ) -> Option<(f64, usize)> {
        first_crossing(self, p, q, order)
    }

    /// [`nearest`], ties to the lowest `order`.
    pub fn nearest(&self, p: DVec2, order: &impl Fn(usize) -> u64) -> Option<(f64, DVec2, usize)> {
        nearest(self, p, order)
    }

    /// [`ray`], ties to the lowest `order`.
    pub fn ray(
        &self,
        p: DVec2,
        dir: DVec2,
        limit: f64,
        order: &impl Fn(usize) -> u64,
    ) -> Option<(f64, usize)> {
        ray(self, p, dir, limit, order)
    }
}
