//! `lsyc lsp`: a Language Server for `.lsy` files (diagnostics and their quick
//! fixes, formatting, hover, go-to-definition, references, completion,
//! signature help, semantic tokens, document symbols, rename).
//!
//! Owns: the editor's view of a program. It is a thin layer over the same
//! library the command line uses: `frontend` for diagnostics (what `lsyc
//! check` prints), `fmt` for formatting (what `lsyc fmt` prints), the public
//! AST for the symbol index. It has no parser or checker of its own and must
//! not grow one. The protocol types are lsp-types'; the message types and
//! their framing lsp-server's (docs/lsp.md says why and where we differ).

pub mod actions;
pub mod analysis;
pub mod complete;
pub mod format;
pub mod hover;
pub mod index;
pub mod outline;
pub mod rename;
pub mod semantic;
pub mod server;
pub mod signature;
pub mod text;
pub mod transport;
pub mod words;

pub use analysis::Analysis;
pub use server::{End, serve, serve_threaded};
