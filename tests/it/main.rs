//! All integration tests, in one binary so that `cargo test` links once.

mod cli;
mod corpus;
mod diagnostics;
mod run;
mod sketch;
mod support;
