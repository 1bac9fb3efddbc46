//! The environment of Open L-systems: scenes of guides that host L-systems,
//! links between guide edges that carry tokens and send messages, and the
//! answers to query modules.
//!
//! Owns: building a runnable scene from a checked file (`scene::build`), the
//! answers to queries and the centre rule that clips each guide's drawing
//! (`scene`), the derive–interpret–answer loop of Měch & Prusinkiewicz (1996)
//! over all active L-systems with token states, messages and incremental reruns
//! (`engine`, run through `scene::run`), the spatial index of drawn segments
//! (`index`), and geometry helpers. Must not parse or print programs.

pub mod engine;
pub mod geometry;
pub mod index;
pub mod scene;

pub use scene::{Outcome, Scene, build, run};
