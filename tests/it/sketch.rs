//! `lsyc infer --skeleton`: tree sketches (tests/data/sketch/*.svg) to programs,
//! end to end: the programs check cleanly and are canonical, their default
//! derivation redraws the sketch, `-n` grows it, 3D programs write valid OBJ.

use crate::support::{render_plain, root};
use lsyc::infer::sketch::{self, Inferred, Options};
use lsyc::run::{self, Derived, Format, Picture};
use lsyc::{fmt, frontend};
use std::process::Command;

fn sketch_path(name: &str) -> std::path::PathBuf {
    root().join(format!("tests/data/sketch/{name}.svg"))
}

fn infer_sketch(name: &str, opts: &Options) -> Inferred {
    let path = sketch_path(name);
    let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    sketch::from_svg(&data, &format!("{name}.svg"), opts).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Checks the program (no diagnostic at all), checks it is canonical, derives it.
fn checked_derive(name: &str, text: &str, steps: Option<u32>) -> Derived {
    let fe = frontend::run(text, Vec::new(), &[]);
    assert!(
        fe.diagnostics.is_empty(),
        "{name}: {}",
        render_plain(&fe.diagnostics, name, text)
    );
    assert_eq!(fmt::format_file(&fe.file), text, "{name}: not canonical");
    let checked = fe.checked.as_ref().expect("checked");
    let opts = run::Options {
        steps,
        ..run::Options::default()
    };
    run::derive(&fe.file, checked, &opts, &|_, _| {})
        .unwrap_or_else(|d| panic!("{name}: {}", render_plain(&[d], name, text)))
}

fn segments_and_bbox(d: &Derived) -> (u64, [f64; 4]) {
    let (drawn, _) = run::measure(d, 0).expect("draws");
    (drawn.segments, drawn.bbox.unwrap_or([0.0; 4]))
}

const SKETCHES: [&str; 6] = [
    "binary",
    "ternary",
    "jitter",
    "unbalanced",
    "group",
    "figure2",
];

#[test]
fn inferred_programs_are_clean_canonical_and_snapshotted() {
    for name in SKETCHES {
        let inf = infer_sketch(name, &Options::default());
        checked_derive(name, &inf.text, None);
        insta::assert_snapshot!(format!("sketch_{name}"), inf.text);
    }
}

/// Sketches whose similar branches agree (self-similar trees, also drawn by a
/// shaky hand) are redrawn exactly: as many segments as the simplified strokes
/// and the same bounding box.
#[test]
fn the_default_derivation_redraws_self_similar_sketches() {
    for name in ["binary", "ternary", "jitter"] {
        let inf = infer_sketch(name, &Options::default());
        let sk = &inf.skeleton;
        let d = checked_derive(name, &inf.text, None);
        let (segments, bbox) = segments_and_bbox(&d);
        assert_eq!(segments as usize, sk.segments(), "{name}");
        let want = sk.simplified_bbox();
        let diag = (want[2] - want[0]).hypot(want[3] - want[1]);
        for k in 0..4 {
            assert!(
                (bbox[k] - want[k]).abs() < 0.01 * diag,
                "{name}: bbox {bbox:?}, sketch {want:?}"
            );
        }
    }
    // Douglas–Peucker takes the hand's jitter away: one segment per stroke.
    let jitter = infer_sketch("jitter", &Options::default());
    assert_eq!(jitter.skeleton.segments(), 15);
    assert_eq!(jitter.analysis.reduced.len(), 1);
}

/// Every sketch: the default derivation draws all the sketch's levels (at least
/// its segments, where terminals of the sketch grow as the reduced productions
/// say), sits on the sketch (same trunk base, same height within 5%), and each
/// further step grows the tree.
#[test]
fn every_sketch_is_drawn_where_it_was_and_grows_with_more_steps() {
    for name in SKETCHES {
        let inf = infer_sketch(name, &Options::default());
        let sk = &inf.skeleton;
        let d = checked_derive(name, &inf.text, None);
        assert_eq!(d.steps as usize, sk.height() + 1, "{name}");
        let (segments, bbox) = segments_and_bbox(&d);
        assert!(segments as usize >= sk.segments(), "{name}: {segments}");
        let want = sk.simplified_bbox();
        let height = want[3] - want[1];
        assert!((bbox[1] - want[1]).abs() < 0.5, "{name}: {bbox:?} {want:?}");
        assert!(
            ((bbox[3] - bbox[1]) - height).abs() < 0.05 * height,
            "{name}: {bbox:?} {want:?}"
        );
        let more = checked_derive(name, &inf.text, Some(d.steps + 1));
        assert!(segments_and_bbox(&more).0 > segments, "{name}");
    }
}

#[test]
fn figure_2_sketched_gives_the_papers_productions() {
    let inf = infer_sketch("figure2", &Options::default());
    let a = &inf.analysis;
    let show = |ps: &[lsyc::infer::sketch::productions::Production]| {
        ps.iter().map(|p| p.to_string()).collect::<Vec<_>>()
    };
    assert_eq!(a.initial.len(), 15);
    assert_eq!(
        show(&a.pre_reduced),
        [
            "r -> {1, 2}",
            "1 -> {3, 14}",
            "2 -> {5, 6, 14}",
            "3 -> {14, 13}",
            "5 -> {14, 14}",
            "6 -> {14, 13, 14}",
            "13 -> {t, t, t}",
            "14 -> {t, t}"
        ]
    );
    assert_eq!(
        show(&a.reduced),
        ["r -> {1, 2}", "1 -> {r, r}", "2 -> {1, 2, r}"]
    );
    for line in [
        "//   r -> {1, 2}",
        "//   1 -> {r, r}",
        "//   2 -> {1, 2, r}",
    ] {
        assert!(inf.text.contains(line), "{}", inf.text);
    }
    assert!(inf.text.contains("B(l, w) -> "), "{}", inf.text);
}

/// Parses an OBJ file and checks it: every face index names an existing vertex
/// and normal, no face repeats a vertex or has no area. Returns (v, vn, f).
fn check_obj(name: &str, obj: &str) -> (usize, usize, usize) {
    let mut vs: Vec<[f64; 3]> = Vec::new();
    let mut normals = 0;
    let mut faces = 0;
    for line in obj.lines() {
        let mut parts = line.split_whitespace();
        match parts.next() {
            Some("v") => {
                let c: Vec<f64> = parts.filter_map(|p| p.parse().ok()).collect();
                assert!(
                    c.len() >= 3 && c.iter().all(|x| x.is_finite()),
                    "{name}: {line}"
                );
                vs.push([c[0], c[1], c[2]]);
            }
            Some("vn") => normals += 1,
            Some("f") => {
                faces += 1;
                let mut idx = Vec::new();
                for p in parts {
                    let mut f = p.split('/');
                    let v: usize = f.next().and_then(|x| x.parse().ok()).expect("index");
                    assert!(v >= 1 && v <= vs.len(), "{name}: {line}");
                    let n: usize = f.nth(1).and_then(|x| x.parse().ok()).expect("normal");
                    assert!(n >= 1 && n <= normals, "{name}: {line}");
                    idx.push(v - 1);
                }
                assert!(idx.len() >= 3, "{name}: {line}");
                let mut sorted = idx.clone();
                sorted.sort_unstable();
                sorted.dedup();
                assert_eq!(sorted.len(), idx.len(), "{name}: repeated vertex in {line}");
                let (a, b, c) = (vs[idx[0]], vs[idx[1]], vs[idx[2]]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let cross = [
                    u[1] * w[2] - u[2] * w[1],
                    u[2] * w[0] - u[0] * w[2],
                    u[0] * w[1] - u[1] * w[0],
                ];
                let area2 = cross.iter().map(|x| x * x).sum::<f64>();
                assert!(area2 > 0.0, "{name}: degenerate face {line}");
            }
            _ => {}
        }
    }
    (vs.len(), normals, faces)
}

#[test]
fn three_d_programs_are_deterministic_and_write_valid_obj() {
    for name in ["binary", "unbalanced", "figure2"] {
        let opts = Options {
            three_d: true,
            seed: 7,
            ..Options::default()
        };
        let inf = infer_sketch(name, &opts);
        assert_eq!(infer_sketch(name, &opts).text, inf.text, "{name}");
        let other = infer_sketch(
            name,
            &Options {
                seed: 8,
                ..opts.clone()
            },
        );
        assert_ne!(other.text, inf.text, "{name}: the seed changes nothing");
        assert!(inf.text.contains("const SPREAD = 35;"), "{name}");
        if name == "unbalanced" {
            insta::assert_snapshot!("sketch_unbalanced_3d", inf.text);
        }
        let d = checked_derive(name, &inf.text, None);
        assert!(d.prog.is_3d, "{name}");
        // Children only lean out of the sketch plane: seen from the front, the
        // tree keeps the sketch's height and base.
        let (segments, bbox) = segments_and_bbox(&d);
        assert!(segments as usize >= inf.skeleton.segments());
        let want = inf.skeleton.simplified_bbox();
        assert!((bbox[1] - want[1]).abs() < 0.5, "{name}: {bbox:?} {want:?}");
        assert!(bbox[3] <= want[3] + 0.05 * (want[3] - want[1]), "{name}");
        let mut out = Vec::new();
        if run::write_output(&d, Format::Obj, Picture::default(), 0, &mut out).is_err() {
            panic!("{name}: OBJ output failed");
        }
        let obj = String::from_utf8(out).expect("utf-8");
        let (v, vn, f) = check_obj(name, &obj);
        assert!(v > 0 && vn > 0 && f > 0, "{name}: {v} {vn} {f}");
    }
}

fn lsyc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("lsyc runs")
}

#[test]
fn the_command_line() {
    let path = |n: &str| sketch_path(n).to_string_lossy().into_owned();
    // stdout without -o, the same text as the library.
    let o = lsyc(&["infer", "--skeleton", &path("binary")]);
    assert_eq!(o.status.code(), Some(0));
    let lib = infer_sketch("binary", &Options::default());
    assert_eq!(String::from_utf8_lossy(&o.stdout), lib.text);

    // -o writes the file; the output may not be the sketch.
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("tree.lsy");
    let out_s = out.to_string_lossy().into_owned();
    let o = lsyc(&[
        "infer",
        "--skeleton",
        &path("unbalanced"),
        "--3d",
        "--seed",
        "3",
        "-o",
        &out_s,
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let written = std::fs::read_to_string(&out).expect("written");
    assert!(written.contains("SPREAD"));
    let copy = dir.path().join("s.svg");
    std::fs::copy(sketch_path("binary"), &copy).expect("copy");
    let copy_s = copy.to_string_lossy().into_owned();
    let o = lsyc(&["infer", "--skeleton", &copy_s, "-o", &copy_s]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read(&copy).expect("read"),
        std::fs::read(sketch_path("binary")).expect("read")
    );

    // The written program runs to OBJ.
    let obj = dir.path().join("tree.obj");
    let o = lsyc(&["run", &out_s, "-o", &obj.to_string_lossy()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    // Input errors name the file and the stroke; exit 1.
    let err = |args: &[&str]| {
        let o = lsyc(args);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, msg) = err(&["infer", "--skeleton", &path("bad")]);
    assert_eq!(code, Some(1));
    assert!(
        msg.contains("bad.svg") && msg.contains("not an SVG"),
        "{msg}"
    );
    let (code, msg) = err(&["infer", "--skeleton", &path("detached")]);
    assert_eq!(code, Some(1));
    assert!(
        msg.contains(
            "stroke 4 (the path with id `b3`) starts 78.1 units from every earlier stroke"
        ),
        "{msg}"
    );
    let (code, msg) = err(&["infer", "--skeleton", &path("empty")]);
    assert_eq!(code, Some(1));
    assert!(
        msg.contains("empty.svg") && msg.contains("no strokes"),
        "{msg}"
    );
    let (code, msg) = err(&["infer", "--skeleton", &path("missing")]);
    assert_eq!(code, Some(1));
    assert!(
        msg.contains("missing.svg") && msg.contains("no such file"),
        "{msg}"
    );

    // Usage errors: exit 2.
    let (code, msg) = err(&["infer", &path("binary"), "--skeleton", &path("binary")]);
    assert!(msg.contains("cannot be used with"), "{msg}");
    assert_eq!(code, Some(2));
    let (code, msg2) = err(&["infer"]);
    assert_eq!(code, Some(2));
    assert!(msg2.contains("give a drawing"), "{msg} {msg2}");
    let (code, _) = err(&["infer", "--skeleton", &path("binary"), "--epsilon", "-1"]);
    assert_eq!(code, Some(2));
}
