//! All integration tests, in one binary so that `cargo test` links once.

mod art_table;
mod bridge;
mod cli;
mod corpus;
mod diagnostics;
mod docs;
mod edit;
mod evaluator;
mod geometry;
mod guided;
mod hostile;
mod hostile_svg;
mod infer;
mod layers;
mod lines;
mod lsp;
mod outputs;
mod plants;
mod roundtrip;
mod run;
mod scene;
mod sketch;
mod studio;
mod support;
mod turtle_queries;
