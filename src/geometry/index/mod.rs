//! The spatial indexes, one module: uniform grids over points (`PointGrid`:
//! the k nearest, those within a distance) and over segments (`SegmentGrid`:
//! first crossing, nearest segment, first ray hit) and over the segments of a
//! drawing that grows step by step (`GrowingGrid`: the same searches, only
//! what was inserted since the last step indexed anew).
//!
//! Owns: every spatial search of the crate. Each search returns exactly what a
//! scan of all items would, ties broken by the lower index, so an index changes
//! speed, never answers (and never depends on thread count or hash order).
//! Must not know what the points and segments stand for.

pub mod growing;
pub mod points;
pub mod segments;

pub use growing::GrowingGrid;
pub use points::PointGrid;
pub use segments::SegmentGrid;
