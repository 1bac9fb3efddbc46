//! cargo-fuzz target `lsp`: the body is fuzz/bodies/lsp.rs, shared with the
//! smoke test that replays the seed corpus in `cargo test`. Inputs over
//! `body::MAX_INPUT` are passed over (run with `-max_len` at most that).
#![no_main]

#[path = "../bodies/lsp.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if data.len() <= body::MAX_INPUT {
        body::run(data);
    }
});
