//! The fuzz targets' smoke run: the seed corpus of each cargo-fuzz target
//! (see fuzz/seed.sh and docs/fuzzing.md), and so every crash reproducer
//! kept in tests/data/hostile/, replayed through the very functions the
//! targets call (fuzz/bodies/*.rs, included here). CI runs them on stable
//! without cargo-fuzz; a panic names the file.

use crate::support::root;
use std::path::{Path, PathBuf};

#[path = "../../fuzz/bodies/frontend.rs"]
mod frontend;
#[path = "../../fuzz/bodies/lsp.rs"]
mod lsp;
#[path = "../../fuzz/bodies/svg_reader.rs"]
mod svg_reader;

/// The largest seed (fuzz/seed.sh keeps the same).
const MAX_SEED: u64 = 64 * 1024;

fn walk(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, ext, out);
        } else if p.extension().is_some_and(|x| x == ext)
            && e.metadata().is_ok_and(|m| m.len() <= MAX_SEED)
        {
            out.push(p);
        }
    }
}

/// The seeds of a target: `.lsy` files in lang-examples/ and tests/data/,
/// or `.svg` files in tests/data/.
fn seeds(ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if ext == "lsy" {
        walk(&root().join("lang-examples"), ext, &mut out);
    }
    walk(&root().join("tests/data"), ext, &mut out);
    out.sort();
    assert!(out.len() > 50, "too few .{ext} seeds: {}", out.len());
    out
}

fn replay(ext: &str, body: fn(&[u8])) {
    for p in seeds(ext) {
        let data = std::fs::read(&p).expect("read seed");
        let name = p.strip_prefix(root()).unwrap_or(&p).display().to_string();
        if std::panic::catch_unwind(|| body(&data)).is_err() {
            panic!("the fuzz body panicked on {name}");
        }
    }
}

#[test]
fn frontend_seeds() {
    replay("lsy", frontend::run);
}

#[test]
fn lsp_seeds() {
    replay("lsy", lsp::run);
}

#[test]
fn svg_reader_seeds() {
    replay("svg", svg_reader::run);
}
