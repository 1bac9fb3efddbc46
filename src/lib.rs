//! lsyc: a language and toolchain for parametric Open L-systems.
//!
//! The pipeline: `lexer` → `parser` (LALRPOP, `grammar/lsy.lalrpop`) → `trivia`
//! and `resolve` → `check`; `fmt` prints any `ast::File` back to canonical text.
#![deny(unsafe_code)]

pub mod ast;
pub mod builtins;
pub mod check;
pub mod compile;
pub mod derive;
pub mod diagnostic;
pub mod dump;
pub mod edit;
pub mod env;
pub mod fmt;
pub mod frontend;
pub mod geometry;
pub mod infer;
pub mod lexer;
pub mod lsp;
pub mod number;
pub mod organ;
pub mod parser;
pub mod path;
pub mod query;
pub mod render;
pub mod resolve;
pub mod run;
pub mod source;
pub mod span;
pub mod studio;
pub mod trivia;
pub mod turtle;
pub mod vm;
pub mod write;
