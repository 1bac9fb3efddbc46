//! `lsyc infer ART.svg`: drawings of repeated elements (tests/data/infer/) to
//! programs, end to end: each program checks cleanly and is canonical, `lsyc
//! run` draws it back on top of the input (symmetric Chamfer distance between
//! the sampled outlines under 0.1 % of the bounding-box diagonal), the
//! recovered counts and parameters are those of the generator, and the
//! programs are snapshots.

use crate::support::{rel, render_plain, root};
use glam::DVec2;
use lsyc::infer::art::{self, Options, read, space::Grid};
use lsyc::{fmt, frontend};
use std::path::Path;
use std::process::Command;

fn infer(path: &Path, opts: &Options) -> art::Inferred {
    let data = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", rel(path)));
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    art::from_svg(&data, &name, opts, &mut |_| {}).unwrap_or_else(|e| panic!("{}: {e}", rel(path)))
}

/// Points spread along every element outline, `step` apart.
fn samples(svg: &[u8], step: f64) -> Vec<DVec2> {
    let d = read::read(svg).expect("reads");
    let mut out = Vec::new();
    for e in &d.elements {
        for line in &e.outline {
            for w in line.windows(2) {
                let n = (w[0].distance(w[1]) / step).ceil().max(1.0) as usize;
                for k in 0..n {
                    out.push(w[0].lerp(w[1], k as f64 / n as f64));
                }
            }
        }
    }
    out
}

fn diagonal(points: &[DVec2]) -> f64 {
    let (lo, hi) = points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (hi - lo).length()
}

/// Symmetric Chamfer distance: the mean of both mean nearest distances.
fn chamfer(a: &[DVec2], b: &[DVec2]) -> f64 {
    let one_way = |from: &[DVec2], to: &[DVec2]| {
        let g = Grid::new(to);
        from.iter()
            .map(|p| p.distance(to[g.nearest(*p, 1)[0]]))
            .sum::<f64>()
            / from.len() as f64
    };
    (one_way(a, b) + one_way(b, a)) / 2.0
}

/// Infers, checks, runs with the `lsyc` binary, and returns the program and
/// the Chamfer distance relative to the input's diagonal.
fn round_trip(name: &str, opts: &Options) -> (String, f64) {
    let path = root().join(format!("tests/data/infer/{name}.svg"));
    let inferred = infer(&path, opts);
    let text = inferred.text;
    let fe = frontend::run(&text, Vec::new(), &[]);
    assert!(
        fe.diagnostics.is_empty(),
        "{name}: {}\n{text}",
        render_plain(&fe.diagnostics, name, &text)
    );
    assert_eq!(fmt::format_file(&fe.file), text, "{name}: not canonical");
    let dir = tempfile::tempdir().expect("tempdir");
    let prog = dir.path().join(format!("{name}.lsy"));
    let back = dir.path().join(format!("{name}.svg"));
    std::fs::write(&prog, &text).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .arg("run")
        .arg(&prog)
        .arg("-o")
        .arg(&back)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let input = std::fs::read(&path).expect("input");
    let output = std::fs::read(&back).expect("output");
    let a0 = samples(&input, 1.0);
    let diag = diagonal(&a0);
    let step = diag / 1500.0;
    let (a, b) = (samples(&input, step), samples(&output, step));
    (text, chamfer(&a, &b) / diag)
}

const EXACT: &[&str] = &[
    "row",
    "grid",
    "ring",
    "helix",
    "branching",
    "two-kinds",
    "spiral-scale",
    "stars-grid",
    "linear-angle",
    "circles",
    "groups-use",
    "shapes",
    "subpaths",
    "clutter",
    "mixed-skip",
    "noisy-grid",
];

#[test]
fn every_case_draws_back_on_its_input() {
    let mut failures = Vec::new();
    for name in EXACT {
        let (text, d) = round_trip(name, &Options::default());
        if d > 1e-3 {
            failures.push(format!("{name}: Chamfer {d:.2e} of the diagonal"));
        }
        insta::assert_snapshot!(format!("infer_{name}"), text);
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
