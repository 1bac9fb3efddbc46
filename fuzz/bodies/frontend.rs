//! The front end on arbitrary bytes: bytes → lexer → parser → checker, and
//! for every input that parses, the formatter's promises (its output parses
//! to the same tree and formatting it again changes nothing). A program that
//! checks clean is also derived a few steps under small limits and measured:
//! any failure must be a diagnostic, never a panic or a hang.
//!
//! Shared by the cargo-fuzz target `frontend` and the smoke test
//! (tests/it/fuzz_smoke.rs), which replays the seed corpus through it.

use lsyc::diagnostic::Code;
use lsyc::{derive, diagnostic, dump, fmt, frontend, parser, run, source};

/// The largest input the fuzz target passes on (see docs/fuzzing.md): the
/// time of one execution grows faster than its size (every syntax error
/// is rendered with its line), and nothing the body checks needs more.
#[allow(dead_code)]
pub const MAX_INPUT: usize = 8 * 1024;

/// How many diagnostics of one input are rendered (besides the last).
const RENDERED: usize = 32;

pub fn run(data: &[u8]) {
    let src = source::from_bytes("fuzz.lsy".to_string(), data);
    let fe = frontend::run(&src.text, src.diagnostics, &[]);
    // Every label lies in the text, on character boundaries: what the
    // renderer and the language server's conversion to UTF-16 rely on.
    for d in &fe.diagnostics {
        for l in &d.labels {
            let (start, end) = (l.span.start as usize, l.span.end as usize);
            assert!(
                start <= end && end <= src.text.len(),
                "{:?}: label {start}..{end} outside the text ({} bytes)",
                d.code,
                src.text.len()
            );
            assert!(
                src.text.is_char_boundary(start) && src.text.is_char_boundary(end),
                "{:?}: label {start}..{end} inside a character",
                d.code
            );
        }
    }
    // Rendering must not panic either. Each diagnostic is rendered with its
    // whole line, so an input with a thousand errors on a long line costs a
    // thousand times that line: the first RENDERED and the last are enough
    // to render every kind of diagnostic the input has near its start and
    // end (the last is often the end of the file's).
    let d = &fe.diagnostics;
    let shown: Vec<_> = if d.len() > RENDERED + 1 {
        d[..RENDERED].iter().chain(d.last()).cloned().collect()
    } else {
        d.clone()
    };
    let _ = diagnostic::render(
        &shown,
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
    // The front end's tree is the parser's, formatted only if it parsed
    // without a syntax error: the checker ran (it runs exactly then), or
    // the only error is the invalid UTF-8 read before parsing (the lossy
    // text parsed clean; the checker does not run on such a file).
    let syntax_ok = fe.checked.is_some()
        || !fe
            .diagnostics
            .iter()
            .any(|d| d.is_error() && d.code != Code::InvalidUtf8);
    if !syntax_ok {
        return;
    }
    let once = fmt::format_file(&fe.file);
    let again = parser::parse(&once);
    assert!(
        !again.diagnostics.iter().any(|d| d.is_error()),
        "formatted text does not parse:\n{once}"
    );
    assert_eq!(
        dump::dump(&fe.file, false),
        dump::dump(&again.file, false),
        "formatting changed the tree:\n{once}"
    );
    assert_eq!(
        once,
        fmt::format_file(&again.file),
        "formatting is not idempotent"
    );
}
