//! The plane geometry the environment uses, from the crate's one geometry
//! module (`crate::geometry`). Must not define geometry of its own.

pub use crate::geometry::{closest_on_segment, crossing, inside, ray_hit, signed_angle};
