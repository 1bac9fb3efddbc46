//! cargo-fuzz target `lsp`: the body is fuzz/bodies/lsp.rs, shared with the
//! smoke test that replays the seed corpus in `cargo test`.
#![no_main]

#[path = "../bodies/lsp.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
