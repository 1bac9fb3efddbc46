//! Helpers shared by the integration tests.

use lsyc::diagnostic::{self, Diagnostic, Format};
use std::path::{Path, PathBuf};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.lsy` file under the given repo-relative directories, sorted.
pub fn lsy_files(dirs: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for d in dirs {
        collect(&root().join(d), &mut out);
    }
    out.sort();
    out
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out);
        } else if p.extension().is_some_and(|x| x == "lsy") {
            out.push(p);
        }
    }
}

/// The path relative to the repository, with `/` separators, for messages and snapshots.
pub fn rel(path: &Path) -> String {
    path.strip_prefix(root())
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

pub fn read_text(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", rel(path)));
    lsyc::source::from_bytes(rel(path), &bytes).text
}

pub fn render_plain(diags: &[Diagnostic], file: &str, text: &str) -> String {
    diagnostic::render(diags, file, text, Format::Human { color: false })
}

/// The errors (not warnings) of parsing `text`.
pub fn parse_errors(text: &str) -> Vec<Diagnostic> {
    lsyc::parser::parse(text)
        .diagnostics
        .into_iter()
        .filter(Diagnostic::is_error)
        .collect()
}
