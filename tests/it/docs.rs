//! The reference runs as printed: every code block of docs/language.md says
//! what it is in its info string, and each is checked for being it. `lsy` is a
//! whole program: it checks without errors and, when it has an lsystem, `lsyc
//! run` draws it (a scene without any of the run's warnings W0801–W0803).
//! `lsy rules` are rules, checked inside an lsystem. `lsy fragment` is an
//! excerpt (`…`), which must not be a whole program (else it would be marked
//! `lsy`); `lsy error` must give errors. Other blocks are `sh` or `text`.

use crate::support::{read_text, root};
use lsyc::frontend;

/// The code blocks of a markdown text: (line of the opening fence, info
/// string, body).
fn blocks(md: &str) -> Vec<(usize, String, String)> {
    let mut out = Vec::new();
    let mut open: Option<(usize, String, String)> = None;
    for (i, line) in md.lines().enumerate() {
        let Some(rest) = line.strip_prefix("```") else {
            if let Some(b) = open.as_mut() {
                b.2.push_str(line);
                b.2.push('\n');
            }
            continue;
        };
        match open.take() {
            Some(b) => out.push(b),
            None => open = Some((i + 1, rest.trim().to_string(), String::new())),
        }
    }
    assert!(open.is_none(), "a code block is not closed");
    out
}

fn errors(text: &str) -> Vec<String> {
    let fe = frontend::run(text, Vec::new(), &[]);
    fe.diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{} {}", d.code.as_str(), d.message))
        .collect()
}

#[test]
fn every_block_of_the_reference_is_what_it_says() {
    let md = read_text(&root().join("docs/language.md"));
    let dir = tempfile::tempdir().expect("tempdir");
    let mut counts = std::collections::BTreeMap::new();
    for (line, info, body) in blocks(&md) {
        *counts.entry(info.clone()).or_insert(0) += 1;
        let at = format!("docs/language.md:{line} ({info})");
        match info.as_str() {
            "lsy" => {
                let errs = errors(&body);
                assert!(errs.is_empty(), "{at}: {errs:?}\n{body}");
                if !body.contains("lsystem ") {
                    continue;
                }
                let file = dir.path().join(format!("block{line}.lsy"));
                std::fs::write(&file, &body).expect("written");
                let out = dir.path().join(format!("block{line}.svg"));
                let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
                    .arg("run")
                    .arg(&file)
                    .arg("-o")
                    .arg(&out)
                    .output()
                    .expect("runs");
                let stderr = String::from_utf8_lossy(&o.stderr);
                assert!(o.status.success(), "{at}: {stderr}");
                assert!(!stderr.contains("warning[W08"), "{at}: {stderr}");
                assert!(out.exists(), "{at}: nothing written");
            }
            "lsy rules" => {
                let program = format!("lsystem Doc {{\n    axiom F;\n{body}}}\n");
                let errs = errors(&program);
                assert!(errs.is_empty(), "{at}: {errs:?}\n{program}");
            }
            "lsy fragment" => {
                assert!(
                    !errors(&body).is_empty(),
                    "{at}: this block is a whole program: mark it ```lsy"
                );
            }
            "lsy error" => {
                assert!(!errors(&body).is_empty(), "{at}: no error");
            }
            "sh" | "text" => {}
            other => panic!(
                "{at}: a code block needs an info string (lsy, lsy rules, lsy fragment, lsy error, sh, text), not `{other}`"
            ),
        }
    }
    // The reference has whole programs, scenes among them, and rules.
    assert!(counts.get("lsy").copied().unwrap_or(0) >= 5, "{counts:?}");
    assert!(counts.contains_key("lsy rules"), "{counts:?}");
}
