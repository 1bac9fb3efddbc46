//! cargo-fuzz target `frontend`: the body is fuzz/bodies/frontend.rs, shared with the
//! smoke test that replays the seed corpus in `cargo test`.
#![no_main]

#[path = "../bodies/frontend.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
