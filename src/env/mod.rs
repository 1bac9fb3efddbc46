//! The environment of Open L-systems: scenes of guides that host L-systems,
//! links between guide edges that carry tokens and send messages, and the
//! answers to query modules.
//!
//! Files, each named for what it owns:
//! - `scene` — the scene model (`Scene`, `Guide`, `Seed`, `Link`), building it
//!   from a checked file (`build`, `SceneError`) and a seed's turtle
//!   (`seed_state`);
//! - `index` — the segments drawn in a guide and their ids (`Grid`, `Layers`,
//!   `key`);
//! - `query` — the answers to query modules (`Probe`, `Answer`, `query`,
//!   `collide`);
//! - `redraw` — a system's drawing for its queries and index, drawn again
//!   after a step by reusing what did not change, and cut where what comes
//!   before can no longer change it (`Sketch`, `draw`, `redraw`, `cut`);
//! - `grown` — a running system's string and drawing in pieces kept for good
//!   and live pieces, so that a step works on the live pieces only (`Grown`);
//! - `clip` — the centre rule (`Clip`, `element_centres`, `outline_centre`);
//! - `explain` — what each guide did in a run and the warnings a run
//!   deserves (`explain`, `warnings`);
//! - `engine` — the derive–interpret–answer loop of Měch & Prusinkiewicz
//!   (1996) over all active L-systems with token states, messages and
//!   incremental reruns (`execute`, `Runner`), and the entry `run`.
//!
//! Who may call whom (a DAG; an arrow reads "imports"): `explain` → `engine`,
//! `scene`, `clip`; `engine` → `grown`, `query`, `redraw`, `scene`, `index`;
//! `grown` → `redraw`; `redraw` → `query`; `query` → `scene`, `index`.
//! `scene`, `index` and `clip` import nothing from `env`. Plane geometry comes from `crate::geometry`.
//!
//! Must not parse or print programs.

pub mod clip;
pub mod engine;
pub mod explain;
pub mod grown;
pub mod index;
pub mod query;
pub mod redraw;
pub mod scene;

pub use clip::{Clip, element_centres, outline_centre};
pub use engine::{Config, Instance, MAX_SCENE_STEPS, Outcome, Runner, run};
pub use scene::{Guide, Scene, SceneError, build};
