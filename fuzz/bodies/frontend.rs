//! Fuzzes the whole front end: bytes → lexer → parser → checker, and for every
//! input that parses, the formatter's promises (its output parses to the same
//! tree and formatting it again changes nothing). A program that checks clean
//! is also compiled, derived a few steps under small limits and drawn: any
//! failure must be a diagnostic, never a panic or a hang.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lsyc::{derive, dump, fmt, frontend, parser, run, source};

fuzz_target!(|data: &[u8]| {
    let src = source::from_bytes("fuzz.lsy".to_string(), data);
    let fe = frontend::run(&src.text, src.diagnostics, &[]);
    // Rendering must not panic either.
    let _ = lsyc::diagnostic::render(
        &fe.diagnostics,
        "fuzz.lsy",
        &src.text,
        lsyc::diagnostic::Format::Human { color: false },
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
    assert_eq!(dump::dump(&parsed.file, false), dump::dump(&again.file, false));
    assert_eq!(once, fmt::format_file(&again.file));
});
