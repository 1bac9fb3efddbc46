//! Diagnostics snapshots: every program under tests/data/check/err names the codes
//! it must produce on its first line (`// expect: E0402`), and its plain
//! rendering is snapshotted.

use crate::support::{lsy_files, read_text, rel, render_plain};
use lsyc::diagnostic::Code;
use lsyc::frontend;
use std::collections::BTreeSet;

/// Codes tested from the command line instead (tests/it/cli.rs).
const CLI_ONLY: &[Code] = &[
    Code::ReadFile,
    Code::FileTooLarge,
    Code::WriteOutput,
    Code::BadOverride,
    // Runtime errors: tests/it/run.rs.
    Code::DivisionByZero,
    Code::NotFinite,
    Code::TooManyModules,
    Code::TooMuchMemory,
    Code::InterpretTooDeep,
    Code::TooManySymbols,
    Code::TooManySteps,
    Code::TooMuchDrawing,
    Code::DrawingTooLarge,
    // Runaway decomposition: tests/it/plants.rs.
    Code::DecomposeTooDeep,
    // A run a newer request stopped: tests/it/studio.rs.
    Code::Cancelled,
    // Mesh files are read by `lsyc run`: tests/it/plants.rs.
    Code::MeshFile,
    // Only `lsyc run` needs an lsystem: tests/it/hostile.rs.
    Code::NoLsystem,
    // A scene still growing at its step limit: tests/data/hostile/self-linked-guide.lsy.
    Code::SceneNeverSettles,
    // Warnings of a scene's run: tests/it/guided.rs.
    Code::NeverSeeded,
    Code::DeriveRanOut,
    Code::LeavesAndComesBack,
];

fn expected_codes(text: &str) -> Vec<String> {
    text.lines()
        .next()
        .and_then(|l| l.trim().strip_prefix("// expect:"))
        .map(|rest| rest.split_whitespace().map(str::to_string).collect())
        .unwrap_or_default()
}

#[test]
fn error_programs_produce_their_codes() {
    let mut settings = insta::Settings::clone_current();
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        insta::glob!("../..", "tests/data/check/err/*.lsy", |path| {
            let text = read_text(path);
            let name = rel(path);
            let want = expected_codes(&text);
            assert!(
                !want.is_empty(),
                "{name}: the first line must be `// expect: CODE…`"
            );
            let bytes = std::fs::read(path).unwrap_or_default();
            let src = lsyc::source::from_bytes(name.clone(), &bytes);
            let fe = frontend::run(&src.text, src.diagnostics, &[]);
            let got: BTreeSet<&str> = fe.diagnostics.iter().map(|d| d.code.as_str()).collect();
            let rendered = render_plain(&fe.diagnostics, &name, &src.text);
            for w in &want {
                assert!(
                    got.contains(w.as_str()),
                    "{name}: expected {w}, got {got:?}\n{rendered}"
                );
            }
            insta::assert_snapshot!("diagnostics", rendered);
        });
    });
}

#[test]
fn every_code_has_an_error_program() {
    let mut covered = BTreeSet::new();
    for path in lsy_files(&["tests/data/check/err"]) {
        covered.extend(expected_codes(&read_text(&path)));
    }
    let missing: Vec<&str> = Code::ALL
        .iter()
        .filter(|c| !CLI_ONLY.contains(c) && !covered.contains(c.as_str()))
        .map(|c| c.as_str())
        .collect();
    assert!(
        missing.is_empty(),
        "codes without a program in tests/data/check/err: {missing:?}"
    );
}

/// Every diagnostic of the error corpus, seen through `miette::Diagnostic` (as
/// another Rust program would use the library): the same code, severity and
/// labels, and the labels read the same text out of the source.
#[test]
fn diagnostics_are_miette_diagnostics() {
    use miette::Diagnostic as _;
    let mut seen = 0;
    for path in lsy_files(&["tests/data/check/err"]) {
        let name = rel(&path);
        let bytes = std::fs::read(&path).unwrap_or_default();
        let src = lsyc::source::from_bytes(name.clone(), &bytes);
        let fe = frontend::run(&src.text, src.diagnostics, &[]);
        for d in fe.diagnostics {
            let want_code = d.code.as_str().to_string();
            let want: Vec<(usize, usize, bool)> = d
                .labels
                .iter()
                .map(|l| (l.span.start as usize, l.span.end as usize, l.primary))
                .collect();
            let inside = d.in_source(&name, &src.text);
            let code = inside.code().map(|c| c.to_string());
            assert_eq!(code.as_deref(), Some(want_code.as_str()), "{name}");
            let got: Vec<(usize, usize, bool)> = inside
                .labels()
                .map(|ls| {
                    ls.map(|l| (l.offset(), l.offset() + l.len(), l.primary()))
                        .collect()
                })
                .unwrap_or_default();
            assert_eq!(got, want, "{name}: labels");
            let source = inside.source_code().expect("the source is attached");
            for (start, end, _) in got.iter().filter(|(s, e, _)| e > s && *e <= src.text.len()) {
                let span = miette::SourceSpan::from(*start..*end);
                let read = source.read_span(&span, 0, 0).expect("the span reads");
                assert_eq!(read.data(), &src.text.as_bytes()[*start..*end], "{name}");
            }
            seen += 1;
        }
    }
    assert!(seen > 100, "only {seen} diagnostics seen");
}
