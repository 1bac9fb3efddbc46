//! The front end on arbitrary bytes: bytes → lexer → parser → checker, and
//! for every input that parses, the formatter's promises (its output parses
//! to the same tree and formatting it again changes nothing). A program that
//! checks clean is also derived a few steps under small limits and measured:
//! any failure must be a diagnostic, never a panic or a hang.
//!
//! Shared by the cargo-fuzz target `frontend` and the smoke test
//! (tests/it/fuzz_smoke.rs), which replays the seed corpus through it.

use lsyc::{derive, diagnostic, dump, fmt, frontend, parser, run, source};

pub fn run(data: &[u8]) {
    let src = source::from_bytes("fuzz.lsy".to_string(), data);
    let fe = frontend::run(&src.text, src.diagnostics, &[]);
    // Rendering must not panic either.
    let _ = diagnostic::render(
        &fe.diagnostics,
        "fuzz.lsy",
        &src.text,
        diagnostic::Format::Human { color: false },
    );
    if let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) {
        let opts = run::Options {
            steps: Some(3),
            seed: 1,
            limits: derive::Limits {
                max_modules: 20_000,
                max_bytes: 1 << 22,
                cancel: None,
            },
            system: None,
            // Meshes are looked for in a folder that does not exist.
            base_dir: Some("/nonexistent/lsyc-fuzz".into()),
        };
        if let Ok(d) = run::derive(&fe.file, checked, &opts, &|_, _| {}) {
            let _ = run::measure(&d, 1);
        }
    }
    let parsed = parser::parse(&src.text);
    if parsed.diagnostics.iter().any(|d| d.is_error()) {
        return;
    }
    let once = fmt::format_file(&parsed.file);
    let again = parser::parse(&once);
    assert!(
        !again.diagnostics.iter().any(|d| d.is_error()),
        "formatted text does not parse:\n{once}"
    );
    assert_eq!(
        dump::dump(&parsed.file, false),
        dump::dump(&again.file, false),
        "formatting changed the tree:\n{once}"
    );
    assert_eq!(
        once,
        fmt::format_file(&again.file),
        "formatting is not idempotent"
    );
}
