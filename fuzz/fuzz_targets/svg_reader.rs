//! cargo-fuzz target `svg_reader`: the body is fuzz/bodies/svg_reader.rs, shared with the
//! smoke test that replays the seed corpus in `cargo test`.
#![no_main]

#[path = "../bodies/svg_reader.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
