//! Hostile SVG inputs to `lsyc infer ART.svg` and `lsyc infer --skeleton`:
//! each ends quickly with a clear error naming the file (exit status 1), or
//! with a program (0) where one is the right answer; never a panic, a stack
//! overflow, a hang or running out of memory. Small inputs are in
//! tests/data/hostile/svg/; large ones (a million subpaths, 100,000 nested
//! groups, 50,000 chained strokes) are written here into a temporary
//! directory.

use crate::support::root;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A hang guard, not a timing: generous, so that a loaded machine running a
/// debug build does not flake (a release build takes a few seconds at most
/// on each; timings are in the benches).
const TIME: Duration = Duration::from_secs(300);

/// What a run must end with: a program, or an error saying this.
#[derive(Clone, Copy, Debug)]
enum Expect {
    Program,
    Error(&'static str),
}

use Expect::{Error, Program};

fn hostile(name: &str) -> PathBuf {
    root().join("tests/data/hostile/svg").join(name)
}

/// Runs `lsyc infer` (`skeleton`: with `--skeleton`) on `file` and checks
/// the outcome, the message and the time.
fn check(file: &Path, skeleton: bool, expect: Expect) {
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    let mode = if skeleton { "--skeleton" } else { "art" };
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lsyc"));
    cmd.arg("infer");
    if skeleton {
        cmd.arg("--skeleton");
    }
    let start = Instant::now();
    let out = cmd
        .arg(file)
        .stdin(Stdio::null())
        .output()
        .expect("runs lsyc");
    let took = start.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("overflow"),
        "{name} ({mode}): {err}"
    );
    assert!(took < TIME, "{name} ({mode}): took {took:?}");
    match expect {
        Program => {
            assert_eq!(out.status.code(), Some(0), "{name} ({mode}): {err}");
            assert!(!out.stdout.is_empty(), "{name} ({mode}): no program");
        }
        Error(says) => {
            assert_eq!(out.status.code(), Some(1), "{name} ({mode}): {err}");
            assert!(
                err.contains(&name) && err.contains(says),
                "{name} ({mode}): expected `{says}`, got: {err}"
            );
            assert!(out.stdout.is_empty(), "{name} ({mode})");
        }
    }
}

fn both(file: &Path, art: Expect, skeleton: Expect) {
    check(file, false, art);
    check(file, true, skeleton);
}

#[test]
fn small_hostile_files() {
    let not_svg = "is not an SVG drawing lsyc can read";
    let cycle = "so it would draw itself without end";
    for (file, art, skeleton) in [
        ("empty.svg", Error(not_svg), Error(not_svg)),
        ("png.svg", Error(not_svg), Error(not_svg)),
        ("random-bytes.svg", Error(not_svg), Error(not_svg)),
        // Numbers usvg cannot hold in 32-bit floats would vanish: refused,
        // with the place, even beside drawable paths.
        (
            "huge-coordinates.svg",
            Error("line 2, column 18: the number 1e308 in `d` of `<path>`"),
            Error("line 2, column 18: the number 1e308 in `d` of `<path>`"),
        ),
        (
            "huge-among-lines.svg",
            Error("line 4, column 18: the number 1e308"),
            Error("line 4, column 18: the number 1e308"),
        ),
        ("use-cycle.svg", Error(cycle), Error(cycle)),
        ("use-self.svg", Error(cycle), Error(cycle)),
        (
            "use-bomb.svg",
            Error("elements once its `<use>` elements are expanded"),
            Error("elements once its `<use>` elements are expanded"),
        ),
        (
            "entity-bomb.svg",
            Error("entities expand to more than 4 MiB"),
            Error("entities expand to more than 4 MiB"),
        ),
        (
            "entity-quadratic.svg",
            Error("line 6, column 73: its DOCTYPE's entities expand to more than 4 MiB"),
            Error("line 6, column 73: its DOCTYPE's entities expand to more than 4 MiB"),
        ),
        (
            "compressed.svg",
            Error("decompress it first"),
            Error("decompress it first"),
        ),
        // Images are skipped, never loaded (`/dev/zero` would never end).
        ("image-device.svg", Program, Program),
    ] {
        both(&hostile(file), art, skeleton);
    }
}

/// Writes `text` to `name` in a temporary directory.
fn generated(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("writes");
    path
}

const HEAD: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">"#;

#[test]
fn a_million_subpaths() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut d = String::with_capacity(12_000_000);
    for i in 0..1_000_000 {
        d.push_str(&format!("M{} 0h1", i % 100_000));
    }
    let file = generated(
        dir.path(),
        "million.svg",
        &format!(r#"{HEAD}<path stroke="black" d="{d}"/></svg>"#),
    );
    both(
        &file,
        Error("subpaths; lsyc infers from drawings of up to"),
        Error("points (curves flattened)"),
    );
}

#[test]
fn deep_nesting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let n = 100_000;
    let groups = generated(
        dir.path(),
        "deep-groups.svg",
        &format!(
            r#"{HEAD}{}<path d="M0 0L10 10" stroke="black"/>{}</svg>"#,
            "<g>".repeat(n),
            "</g>".repeat(n)
        ),
    );
    let deep = "levels deep";
    both(&groups, Error(deep), Error(deep));
    // A chain of `<use>`, each drawing the one before.
    let mut uses = String::from(r#"<defs><path id="u0" d="M0 0L1 1" stroke="black"/>"#);
    for k in 1..2000 {
        uses.push_str(&format!(
            r##"<use id="u{k}" href="#u{}" x="0.01"/>"##,
            k - 1
        ));
    }
    let chain = generated(
        dir.path(),
        "use-chain.svg",
        &format!(r##"{HEAD}{uses}</defs><use href="#u1999"/></svg>"##),
    );
    both(&chain, Error(deep), Error(deep));
}

/// Strokes each starting where the one before ended.
fn chained_strokes(n: usize) -> String {
    let mut s = String::from(HEAD);
    let (mut x, mut y) = (0.0f64, 0.0f64);
    for i in 0..n {
        let (nx, ny) = (x + if i % 2 == 0 { 0.3 } else { -0.3 }, y - 1.0);
        s.push_str(&format!(
            r#"<path d="M{x:.1} {y:.1}L{nx:.1} {ny:.1}" stroke="black"/>"#
        ));
        (x, y) = (nx, ny);
    }
    s.push_str("</svg>");
    s
}

#[test]
fn a_long_chain_of_strokes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let long = generated(dir.path(), "chain-50000.svg", &chained_strokes(50_000));
    check(&long, true, Error("strokes; lsyc infers trees of up to"));
    // Within the limits, a chain is a tree, however deep.
    let chain = generated(dir.path(), "chain-3000.svg", &chained_strokes(3000));
    check(&chain, true, Program);
}

#[test]
fn two_hundred_thousand_attributes_on_one_element() {
    let dir = tempfile::tempdir().expect("tempdir");
    let attrs: String = (0..200_000).map(|i| format!(" a{i}=\"1\"")).collect();
    let file = generated(
        dir.path(),
        "attributes.svg",
        &format!("{HEAD}\n<path d=\"M0 0L5 5\" stroke=\"black\"{attrs}/></svg>"),
    );
    let says = Error("line 2, column 1: `<path>` has more than 1024 attributes");
    both(&file, says, says);
}

/// The entity bombs under a memory limit of 512 MiB of address space (the
/// quadratic one grew to 2.47 GB before it was refused): each is refused
/// quickly, never killed.
#[cfg(unix)]
#[test]
fn entity_bombs_under_a_memory_limit() {
    for name in ["entity-quadratic.svg", "entity-bomb.svg"] {
        for mode in [&["infer"][..], &["infer", "--skeleton"][..]] {
            let start = Instant::now();
            let out = Command::new("sh")
                .arg("-c")
                .arg("ulimit -v 524288 && exec \"$@\"")
                .arg("sh")
                .arg(env!("CARGO_BIN_EXE_lsyc"))
                .args(mode)
                .arg(hostile(name))
                .stdin(Stdio::null())
                .output()
                .expect("runs sh");
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{name} {mode:?}: {err}");
            assert!(
                err.contains("entities expand to more than"),
                "{name}: {err}"
            );
            assert!(start.elapsed() < TIME, "{name}: {:?}", start.elapsed());
        }
    }
}
