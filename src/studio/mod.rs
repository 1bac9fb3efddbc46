//! `lsyc studio`: a live editor in the browser.
//!
//! Files, each named for what it owns:
//! - `protocol` — the requests and replies, and running them through the
//!   library as the command line does (no sockets, no files);
//! - `server` — the HTTP server on 127.0.0.1 (connections, timeouts, routes),
//!   the file on disk;
//! - `jobs` — the worker pool that runs programs, with a stop flag per
//!   worker, and the pages' sessions, whose newer requests stop older ones;
//! - `layers` — a dragged scene's drawing kept guide by guide, so that a
//!   move draws again only the guides it changed;
//! - `assets` — the page (HTML, JavaScript, CSS) compiled into the binary.
//!
//! The studio is the top layer: it calls `run`, `edit`, `env`, `fmt` and
//! `frontend`, and nothing in the library calls it.

pub mod assets;
pub mod jobs;
pub mod layers;
pub mod protocol;
pub mod server;

pub use server::Studio;
