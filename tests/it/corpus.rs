//! Properties over every program in the repository: the AST snapshots, the
//! formatter's round trip and idempotence, and a clean gallery.

use crate::support::{lsy_files, read_text, rel, render_plain};
use lsyc::ast::{Block, File, Item, Node, SceneStmt};
use lsyc::dump::dump;
use lsyc::{fmt, frontend, parser};

/// Spans lie inside the source and sibling statements come in order.
fn check_spans(file: &File, len: u32, name: &str) {
    fn block<T>(b: &Block<T>, len: u32, name: &str, inner: &dyn Fn(&T)) {
        let mut last = 0;
        for Node { node, span, .. } in &b.stmts {
            assert!(
                span.start <= span.end && span.end <= len,
                "{name}: span {span:?} outside the source"
            );
            assert!(
                span.start >= last,
                "{name}: statement at {} starts before its predecessor ends ({last})",
                span.start
            );
            last = span.end;
            inner(node);
        }
    }
    block(&file.items, len, name, &|item| match item {
        Item::Lsystem(l) => block(&l.body, len, name, &|_| {}),
        Item::Element(e) => block(&e.props, len, name, &|_| {}),
        Item::Scene(s) => block(&s.body, len, name, &|st| match st {
            SceneStmt::Guide(g) => block(&g.body, len, name, &|_| {}),
            SceneStmt::Link(l) => block(&l.body, len, name, &|_| {}),
            SceneStmt::Error => {}
        }),
        _ => {}
    });
}

#[test]
fn ast_snapshots() {
    let mut settings = insta::Settings::clone_current();
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        insta::glob!(
            "../..",
            "{lang-examples,tests/data/parse/ok}/*.lsy",
            |path| {
                let text = read_text(path);
                let parsed = parser::parse(&text);
                let errors: Vec<_> = parsed
                    .diagnostics
                    .iter()
                    .filter(|d| d.is_error())
                    .cloned()
                    .collect();
                assert!(
                    errors.is_empty(),
                    "{} does not parse:\n{}",
                    rel(path),
                    render_plain(&errors, &rel(path), &text)
                );
                check_spans(&parsed.file, text.len() as u32, &rel(path));
                insta::assert_snapshot!("ast", dump(&parsed.file, true));
            }
        );
    });
}

/// Every parsable program: parse(fmt(x)) == parse(x) (spans aside) and fmt is idempotent.
#[test]
fn formatter_round_trip_and_idempotence() {
    let files = lsy_files(&["lang-examples", "tests/data"]);
    assert!(files.len() > 10, "the corpus is missing");
    let mut checked = 0;
    for path in files {
        let text = read_text(&path);
        let parsed = parser::parse(&text);
        if parsed.diagnostics.iter().any(|d| d.is_error()) {
            continue;
        }
        let once = fmt::format_file(&parsed.file);
        let reparsed = parser::parse(&once);
        let errs = crate::support::parse_errors(&once);
        assert!(
            errs.is_empty(),
            "{}: the formatted text does not parse:\n{}\n{once}",
            rel(&path),
            render_plain(&errs, "formatted", &once)
        );
        similar_asserts_eq(
            &dump(&parsed.file, false),
            &dump(&reparsed.file, false),
            &rel(&path),
            "AST changed by formatting",
        );
        let twice = fmt::format_file(&reparsed.file);
        similar_asserts_eq(&once, &twice, &rel(&path), "formatting is not idempotent");
        checked += 1;
    }
    assert!(checked > 10);
}

fn similar_asserts_eq(a: &str, b: &str, file: &str, what: &str) {
    if a != b {
        let line = a
            .lines()
            .zip(b.lines())
            .position(|(x, y)| x != y)
            .unwrap_or(0);
        let show = |s: &str| {
            s.lines()
                .skip(line.saturating_sub(2))
                .take(6)
                .collect::<Vec<_>>()
                .join("\n")
        };
        panic!(
            "{file}: {what}; first difference at line {}:\n--- before\n{}\n--- after\n{}",
            line + 1,
            show(a),
            show(b)
        );
    }
}

/// The gallery checks without any diagnostic and is in canonical form.
#[test]
fn gallery_is_clean_and_canonical() {
    let files = lsy_files(&["lang-examples"]);
    assert!(files.len() >= 10, "the gallery needs at least 10 programs");
    let mut problems = String::new();
    for path in files {
        let text = read_text(&path);
        let fe = frontend::run(&text, Vec::new(), &[]);
        if !fe.diagnostics.is_empty() {
            problems.push_str(&render_plain(&fe.diagnostics, &rel(&path), &text));
        }
        if !fe.has_errors() && fmt::format_file(&fe.file) != text {
            problems.push_str(&format!(
                "{}: not in canonical form (lsyc fmt --write it)\n",
                rel(&path)
            ));
        }
    }
    assert!(problems.is_empty(), "{problems}");
}

/// Programs under tests/data/check/ok check without any diagnostic.
#[test]
fn clean_programs_have_no_diagnostics() {
    for path in lsy_files(&["tests/data/check/ok"]) {
        let text = read_text(&path);
        let fe = frontend::run(&text, Vec::new(), &[]);
        assert!(
            fe.diagnostics.is_empty(),
            "{}",
            render_plain(&fe.diagnostics, &rel(&path), &text)
        );
    }
}

/// The language reference lists every diagnostic code with its title.
#[test]
fn the_reference_lists_every_code() {
    let doc = read_text(&crate::support::root().join("docs/language.md"));
    for code in lsyc::diagnostic::Code::ALL {
        let row = format!("| `{}` | {} |", code.as_str(), code.title());
        assert!(doc.contains(&row), "docs/language.md lacks the row {row}");
    }
}
