//! The spatial indexes, one module: uniform grids over points (`PointGrid`:
//! the k nearest, those within a distance) and over segments (`SegmentGrid`:
//! first crossing, nearest segment, first ray hit; the searches are written
//! once, over any `segments::Cells`), over segments added and never removed
//! (`AppendGrid`: cells that grow) and over the segments of a drawing that
//! grows step by step (`GrowingGrid`: the same searches over segments added
//! in batches and kept, plus a live batch replaced at will, numbered by the
//! caller).
//!
//! Owns: every spatial search of the crate. Each search returns exactly what a
//! scan of all items would, ties broken by the lower index (or the caller's
//! order), so an index changes speed, never answers (and never depends on
//! thread count or hash order).
//! Must not know what the points and segments stand for.

pub mod append;
pub mod growing;
pub mod points;
pub mod segments;

pub use growing::GrowingGrid;
pub use points::PointGrid;
pub use segments::SegmentGrid;

/// A tiny deterministic generator of test geometry, for the indexes' tests and
/// their users' (numbers in [0, 1)).
#[cfg(test)]
pub(crate) struct Lcg(pub(crate) u64);

#[cfg(test)]
impl Lcg {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}
