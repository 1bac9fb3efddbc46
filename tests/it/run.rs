//! Running programs: derived strings, counts, pictures, determinism, runtime errors.

use crate::support::{lsy_files, read_text, rel, render_plain, root};
use glam::DVec3;
use lsyc::run::{self, Derived, Format, Options, Picture};
use lsyc::turtle::{self, Sink};
use lsyc::{frontend, run::Stats};
use std::process::Command;

fn derive_text(text: &str, steps: Option<u32>) -> Result<Derived, String> {
    let fe = frontend::run(text, Vec::new(), &[]);
    let checked = fe
        .checked
        .as_ref()
        .filter(|_| !fe.has_errors())
        .ok_or_else(|| render_plain(&fe.diagnostics, "test.lsy", text))?;
    let opts = Options {
        steps,
        ..Options::default()
    };
    run::derive(&fe.file, checked, &opts, &|_, _| {})
        .map_err(|d| render_plain(&[d], "test.lsy", text))
}

fn txt(d: &Derived) -> String {
    let mut out = Vec::new();
    run::write_output(d, Format::Txt, Picture::default(), 0, &mut out).ok();
    String::from_utf8(out)
        .unwrap_or_default()
        .trim_end()
        .to_string()
}

#[test]
fn d0l_strings_match_hand_derivations() {
    // The slides' Fibonacci example: b, a, ab, aba, abaab, abaababa.
    let fib = "lsystem Fib { axiom b; a -> ab; b -> a; }";
    let want = ["b", "a", "ab", "aba", "abaab", "abaababa"];
    for (n, w) in want.iter().enumerate() {
        let d = derive_text(fib, Some(n as u32)).expect("derives");
        assert_eq!(txt(&d), *w, "step {n}");
    }
    let koch = "lsystem K { axiom F-F-F-F; F -> F-F+F+FF-F-F+F; }";
    let d = derive_text(koch, Some(1)).expect("derives");
    assert_eq!(
        txt(&d),
        "F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F"
    );
    // Erasure, brackets and the identity of modules without rules.
    let d = derive_text("lsystem E { axiom A[B]C; A -> ; B -> BB; }", Some(2)).expect("derives");
    assert_eq!(txt(&d), "[BBBB]C");
}

#[test]
fn parametric_conditions_context_and_cut() {
    let src = "lsystem P { axiom A(0); A(x) : x < 3 -> F(x) A(x + 1); A(x) -> B(x * 2); }";
    assert_eq!(
        txt(&derive_text(src, Some(4)).expect("derives")),
        "F(0) F(1) F(2) B(6)"
    );
    // Context: a signal moving right, skipping the branch and the ignored `+`.
    let src = "lsystem S { ignore +; axiom b a [a] + a a; b < a -> b; b -> a; }";
    assert_eq!(
        txt(&derive_text(src, Some(1)).expect("derives")),
        "ab[a]+aa"
    );
    assert_eq!(
        txt(&derive_text(src, Some(2)).expect("derives")),
        "aa[b]+ba"
    );
    // Right context across a branch.
    let src = "lsystem R { axiom A[X]B; A > B -> C; }";
    assert_eq!(txt(&derive_text(src, Some(1)).expect("derives")), "C[X]B");
    // cut erases the rest of its branch.
    let src = "lsystem C { axiom F[A F F]F; A -> cut; }";
    assert_eq!(txt(&derive_text(src, Some(1)).expect("derives")), "F[]F");
}

#[test]
fn stochastic_choices_follow_the_weights_and_the_seed() {
    let src = "lsystem S { axiom A; A ->(1) A X; A ->(3) A Y; }";
    let fe = frontend::run(src, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("checks");
    let count = |seed: u64| {
        let opts = Options {
            steps: Some(4000),
            seed,
            ..Options::default()
        };
        let d = run::derive(&fe.file, checked, &opts, &|_, _| {}).expect("derives");
        let s = txt(&d);
        (s.matches('X').count(), s.matches('Y').count(), s)
    };
    let (x, y, a) = count(1);
    assert_eq!(x + y, 4000);
    let share = y as f64 / 4000.0;
    assert!((share - 0.75).abs() < 0.04, "Y share {share}");
    assert_eq!(a, count(1).2, "same seed, same string");
    assert_ne!(a, count(2).2, "another seed, another string");
}

/// Records segment end points.
#[derive(Default)]
struct Points(Vec<(DVec3, DVec3)>);

impl Sink for Points {
    fn segment(&mut self, a: DVec3, b: DVec3, _: f64, _: u32) {
        self.0.push((a, b));
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
}

#[test]
fn the_3d_hilbert_curve_visits_every_cell_once() {
    let text = read_text(&root().join("lang-examples/hilbert-3d.lsy"));
    for n in 1..=3u32 {
        let d = derive_text(&text, Some(n)).expect("derives");
        let mut pts = Points::default();
        turtle::interpret(&d.prog, &d.string, 0, &mut pts).expect("draws");
        let cells = 8usize.pow(n);
        assert_eq!(pts.0.len(), cells - 1, "n = {n}");
        let mut seen = std::collections::HashSet::new();
        let key = |p: DVec3| (p.x.round() as i64, p.y.round() as i64, p.z.round() as i64);
        seen.insert(key(pts.0[0].0));
        for (k, &(a, b)) in pts.0.iter().enumerate() {
            assert!(((b - a).length() - 1.0).abs() < 1e-9, "unit steps");
            if k > 0 {
                assert!((a - pts.0[k - 1].1).length() < 1e-9, "one connected curve");
            }
            seen.insert(key(b));
        }
        assert_eq!(seen.len(), cells, "n = {n}: every cell of the cube once");
        let side = 2i64.pow(n) - 1;
        assert!(
            seen.iter()
                .all(|&(x, y, z)| [x, y, z].iter().all(|c| c.abs() <= side))
        );
    }
}

#[test]
fn turtle_conventions() {
    // `+` turns left (counter-clockwise): from heading +y to -x.
    let d = derive_text("lsystem T { angle 90; axiom F+F; }", None).expect("derives");
    let mut pts = Points::default();
    turtle::interpret(&d.prog, &d.string, 0, &mut pts).expect("draws");
    assert!(
        (pts.0[1].1 - DVec3::new(-1.0, 1.0, 0.0)).length() < 1e-12,
        "{:?}",
        pts.0
    );
    // `&` pitches down: the heading goes toward -U = -z.
    let d = derive_text("lsystem T { angle 90; axiom &F; }", None).expect("derives");
    let mut pts = Points::default();
    turtle::interpret(&d.prog, &d.string, 0, &mut pts).expect("draws");
    assert!(
        (pts.0[0].1 - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12,
        "{:?}",
        pts.0
    );
    // `*` scales, `[ ]` restore, `|` turns around.
    let d = derive_text("lsystem T { axiom F[*(2)F]|F; }", None).expect("draws");
    let mut pts = Points::default();
    turtle::interpret(&d.prog, &d.string, 0, &mut pts).expect("draws");
    assert!((pts.0[1].1 - DVec3::new(0.0, 3.0, 0.0)).length() < 1e-12);
    assert!((pts.0[2].1 - DVec3::ZERO).length() < 1e-12);
}

fn stats_of(d: &Derived) -> serde_json::Value {
    let (drawn, _) = run::measure(d, 0).expect("draws");
    let mut v = serde_json::to_value(Stats::new(d, &drawn, 0.0)).expect("json");
    if let Some(o) = v.as_object_mut() {
        o.remove("derive_ms");
        o.remove("interpret_ms");
    }
    v
}

#[test]
fn gallery_stats() {
    let mut settings = insta::Settings::clone_current();
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        insta::glob!("../..", "lang-examples/*.lsy", |path| {
            let text = read_text(path);
            if text.contains("\nscene ") {
                return; // scenes run with their environment
            }
            let d = derive_text(&text, None).unwrap_or_else(|e| panic!("{}: {e}", rel(path)));
            let v = stats_of(&d);
            insta::assert_snapshot!(
                "stats",
                serde_json::to_string_pretty(&v).unwrap_or_default()
            );
        });
    });
}

#[test]
fn koch_island_counts_and_bounds() {
    let text = read_text(&root().join("lang-examples/koch-island.lsy"));
    let d = derive_text(&text, Some(1)).expect("derives");
    let v = stats_of(&d);
    assert_eq!(v["segments"], 32);
    assert_eq!(v["modules"], 4 * 14 + 3);
    // After one step a side is 4 units long with bumps of 1 on either side.
    let b = &v["bbox"];
    let w = b[2].as_f64().unwrap_or(0.0) - b[0].as_f64().unwrap_or(0.0);
    assert!((w - 6.0).abs() < 1e-9, "{v}");
}

fn lsyc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("lsyc runs")
}

#[test]
fn outputs_are_deterministic_across_runs_and_threads() {
    let dir = tempfile::tempdir().expect("tempdir");
    for prog in ["stochastic-plant", "monopodial-tree", "hogeweg-plant"] {
        let input = root().join(format!("lang-examples/{prog}.lsy"));
        let input = input.to_str().expect("utf-8");
        let mut outs = Vec::new();
        for (k, threads) in ["1", "2", "1"].iter().enumerate() {
            let out = dir.path().join(format!("{prog}-{k}.svg"));
            let o = lsyc(&[
                "run",
                input,
                "-o",
                out.to_str().expect("utf-8"),
                "--seed",
                "7",
                "--threads",
                threads,
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            outs.push(std::fs::read(&out).expect("written"));
        }
        assert!(
            outs[0] == outs[1] && outs[1] == outs[2],
            "{prog}: outputs differ"
        );
    }
}

#[test]
fn svg_rereads_with_usvg_and_png_decodes() {
    let dir = tempfile::tempdir().expect("tempdir");
    for prog in ["plant-e", "helix", "bush-3d", "dragon-curve"] {
        let input = root().join(format!("lang-examples/{prog}.lsy"));
        let svg = dir.path().join(format!("{prog}.svg"));
        let png = dir.path().join(format!("{prog}.png"));
        for out in [&svg, &png] {
            let o = lsyc(&[
                "run",
                input.to_str().expect("utf-8"),
                "-o",
                out.to_str().expect("utf-8"),
                "--size",
                "300",
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        let data = std::fs::read(&svg).expect("svg");
        let tree = usvg::Tree::from_data(&data, &usvg::Options::default())
            .unwrap_or_else(|e| panic!("{prog}: usvg cannot read our SVG: {e}"));
        assert!(tree.root().has_children(), "{prog}: empty SVG");
        let bytes = std::fs::read(&png).expect("png");
        let pixmap = tiny_skia::Pixmap::decode_png(&bytes).expect("a PNG");
        assert_eq!(pixmap.width().max(pixmap.height()), 300);
        let ink = pixmap
            .pixels()
            .iter()
            .filter(|p| p.red() < 200 || p.green() < 200)
            .count();
        assert!(ink > 100, "{prog}: the picture is blank");
    }
}

#[test]
fn text_output_parses_back_as_an_axiom() {
    // The .txt output is in the language's syntax: it can be an axiom again.
    for path in lsy_files(&["lang-examples"]) {
        let text = read_text(&path);
        if text.contains("\nscene ") {
            continue;
        }
        let Ok(d) = derive_text(&text, Some(2)) else {
            continue;
        };
        let s = txt(&d);
        if s.len() > 20_000 {
            continue;
        }
        // After the file itself, so that its declared modules are known.
        let program = format!("{text}\nlsystem Again {{ axiom {s}; }}");
        let errs = crate::support::parse_errors(&program);
        assert!(
            errs.is_empty(),
            "{}: {}",
            rel(&path),
            render_plain(&errs, "again", &program)
        );
    }
}

#[test]
fn runtime_errors_point_at_the_expression() {
    let src = "lsystem Z {\n    axiom A(3);\n    A(x) -> A(x - 1) F(10 / x);\n}\n";
    let Err(err) = derive_text(src, Some(5)) else {
        panic!("expected an error");
    };
    assert!(
        err.contains("error[E0901]") && err.contains("step 4"),
        "{err}"
    );
    assert!(err.contains("test.lsy:3:24"), "{err}");
    let src = "lsystem N {\n    axiom A(-1);\n    A(x) -> F(sqrt(x));\n}\n";
    let Err(err) = derive_text(src, Some(1)) else {
        panic!("expected an error");
    };
    assert!(
        err.contains("error[E0902]") && err.contains("test.lsy:3:15"),
        "{err}"
    );
    // && does not evaluate its right side when the left is false.
    let src = "lsystem G { axiom A(0); A(x) : x != 0 && 1 / x > 2 -> B; }";
    assert!(derive_text(src, Some(1)).is_ok());
}

#[test]
fn an_explosion_stops_with_a_clear_error() {
    // How quickly it stops is measured by `cargo bench --bench limits`.
    let src = "lsystem Boom { axiom F; F -> FFFFFFFFFF; }";
    let Err(err) = derive_text(src, Some(40)) else {
        panic!("expected an error");
    };
    assert!(
        err.contains("error[E0903]") && err.contains("modules"),
        "{err}"
    );
}

/// Derive's own limit on steps (the CLI's `-n` stops earlier, as a usage error).
#[test]
fn steps_beyond_the_limit_are_an_error() {
    let Err(err) = derive_text("lsystem Still { axiom F; }", Some(4_000_000_000)) else {
        panic!("expected an error");
    };
    assert!(
        err.contains("error[E0907]") && err.contains("the most is 1000000"),
        "{err}"
    );
}

#[test]
fn endless_interpretation_is_an_error() {
    // A cycle of rules that always apply is caught by the checker, at the rule.
    let src = "lsystem I { axiom A; interpret A -> B; interpret B -> A F; }";
    let err = derive_text(src, Some(0)).err().unwrap_or_default();
    assert!(err.contains("error[E0905]"), "{err}");
    // One behind a condition that always holds is caught while drawing.
    let src =
        "lsystem I { axiom A(0); interpret A(n) : n >= 0 -> B(n); interpret B(n) -> A(n + 1) F; }";
    let d = derive_text(src, Some(0)).expect("derives");
    let err = run::measure(&d, 0).expect_err("fails");
    assert_eq!(err.code, lsyc::diagnostic::Code::InterpretTooDeep);
}

#[test]
fn disassembly_snapshots() {
    for prog in ["monopodial-tree", "stochastic-plant", "hogeweg-plant"] {
        let out = lsyc(&[
            "run",
            root()
                .join(format!("lang-examples/{prog}.lsy"))
                .to_str()
                .expect("utf-8"),
            "--disasm",
        ]);
        assert!(out.status.success());
        insta::assert_snapshot!(
            format!("disasm_{prog}"),
            String::from_utf8_lossy(&out.stdout)
        );
    }
}

#[test]
fn run_refuses_to_overwrite_its_input_and_unknown_formats() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("a.lsy");
    std::fs::write(&p, "lsystem A { axiom F; }\n").expect("write");
    let ps = p.to_str().expect("utf-8");
    let o = lsyc(&["run", ps, "-o", ps]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(&p).expect("read"),
        "lsystem A { axiom F; }\n"
    );
    let o = lsyc(&["run", ps, "-o", "x.pdf"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn obj_output_is_a_valid_mesh() {
    let dir = tempfile::tempdir().expect("tempdir");
    for prog in ["hilbert-3d", "bush-3d", "monopodial-tree"] {
        let out = dir.path().join(format!("{prog}.obj"));
        let input = root().join(format!("lang-examples/{prog}.lsy"));
        let o = lsyc(&[
            "run",
            input.to_str().expect("utf-8"),
            "-n",
            "3",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(&out).expect("obj");
        let (mut v, mut vn, mut faces) = (0usize, 0usize, 0usize);
        for line in text.lines() {
            let mut parts = line.split_whitespace();
            match parts.next() {
                Some("v") => v += 1,
                Some("vn") => vn += 1,
                Some("f") => {
                    faces += 1;
                    let idx: Vec<(usize, Option<usize>)> = parts
                        .map(|p| {
                            let mut it = p.split("//");
                            let vi = it.next().and_then(|x| x.parse().ok()).unwrap_or(0);
                            (vi, it.next().and_then(|x| x.parse().ok()))
                        })
                        .collect();
                    assert!(idx.len() >= 3, "{prog}: a face with fewer than 3 corners");
                    let mut seen = std::collections::HashSet::new();
                    for &(vi, ni) in &idx {
                        assert!(vi >= 1 && vi <= v, "{prog}: vertex index {vi} of {v}");
                        if let Some(n) = ni {
                            assert!(n >= 1 && n <= vn, "{prog}: normal index {n} of {vn}");
                        }
                        assert!(
                            seen.insert(vi),
                            "{prog}: a degenerate face repeats vertex {vi}"
                        );
                    }
                }
                _ => {}
            }
        }
        assert!(faces > 100 && vn > 0, "{prog}: {faces} faces, {vn} normals");
    }
}

#[test]
fn a_scene_runs_whole_or_one_system_at_a_time() {
    let palm = root().join("lang-examples/palm.lsy");
    let p = palm.to_str().expect("utf-8");
    let o = lsyc(&["run", p, "--stats"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stats: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(stats["messages"], 10);
    let o = lsyc(&["run", p, "--system", "Trunk", "--stats"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `--stats`' bbox covers what is drawn, element outlines included: for every
/// 2D program of the gallery it is the box the SVG and PNG writers fit (the
/// outlines' control points placed by the turtle), and the apex shoot's
/// leaves reach left of its stem (x = -17.6), not only their bases.
#[test]
fn stats_bbox_includes_element_outlines() {
    for path in lsy_files(&["lang-examples"]) {
        let text = read_text(&path);
        if text.contains("\nscene ") {
            continue;
        }
        let d = derive_text(&text, None).unwrap_or_else(|e| panic!("{}: {e}", rel(&path)));
        if d.prog.is_3d {
            continue; // the writers' box is of the projected view
        }
        let (drawn, bounds) = run::measure(&d, 0).expect("draws");
        let Some(b) = drawn.bbox else { continue };
        let fitted = [bounds.min.x, bounds.min.y, bounds.max.x, bounds.max.y];
        for k in 0..4 {
            assert!(
                (b[k] - fitted[k]).abs() <= 1e-9 * (1.0 + fitted[k].abs()),
                "{}: bbox {b:?}, the writers fit {fitted:?}",
                rel(&path)
            );
        }
    }
    let text = read_text(&root().join("lang-examples/apex-shoot.lsy"));
    let d = derive_text(&text, None).expect("derives");
    let v = stats_of(&d);
    let minx = v["bbox"][0].as_f64().expect("bbox");
    assert!(minx < -17.0, "{v}");
}

/// The reference: constants are evaluated before anything runs and keep one
/// value, so a random constant is drawn once per run, the same at every use
/// (and another seed draws another value).
#[test]
fn a_random_constant_is_drawn_once() {
    let src = "const a = uniform(0, 100);\nlsystem R { derive 3; axiom B F(a) F(a); B -> F(a) B; }";
    let run_with = |seed: u64| {
        let fe = frontend::run_seeded(src, Vec::new(), &[], seed);
        let checked = fe.checked.as_ref().expect("checks");
        let opts = Options {
            seed,
            ..Options::default()
        };
        let d = run::derive(&fe.file, checked, &opts, &|_, _| {}).expect("derives");
        txt(&d)
    };
    let values = |text: &str| -> Vec<String> {
        text.split("F(")
            .skip(1)
            .filter_map(|s| s.split(')').next())
            .map(str::to_string)
            .collect()
    };
    let first = values(&run_with(1));
    assert_eq!(first.len(), 5, "{first:?}");
    assert!(first.iter().all(|v| *v == first[0]), "{first:?}");
    let other = values(&run_with(2));
    assert!(other.iter().all(|v| *v == other[0]), "{other:?}");
    assert_ne!(first[0], other[0], "another seed draws another value");
}

/// `--guides` draws the links in PNG as in SVG: red hairlines (palette 8,
/// SVG's link colour) from edge to edge, which the palm does not draw otherwise.
#[test]
fn png_guides_draw_links() {
    let text = read_text(&root().join("lang-examples/palm.lsy"));
    let fe = frontend::run(&text, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("checks");
    let r = run::run_scene(&fe.file, checked, None, &Options::default()).expect("runs");
    let red_pixels = |guides: bool| {
        let mut png = Vec::new();
        let picture = Picture {
            size: 400,
            ..Picture::default()
        };
        if run::write_scene(&r, Some(Format::Png), picture, 0, guides, &mut png).is_err() {
            panic!("the palm draws");
        }
        let pixmap = tiny_skia::Pixmap::decode_png(&png).expect("a PNG");
        pixmap
            .pixels()
            .iter()
            .filter(|p| p.red() > 150 && p.green() < 90 && p.blue() < 90)
            .count()
    };
    assert_eq!(red_pixels(false), 0, "the palm itself has no red");
    // 18 links, most of them some 50 to 150 pixels long at this size.
    let with = red_pixels(true);
    assert!(with > 500, "{with} link pixels");
}

/// An element's `width` is in pixels of the picture in PNG as in SVG
/// (`non-scaling-stroke`): an outline of width 4 covers about four times the
/// pixels of width 1, and width 0 draws no outline.
#[test]
fn png_element_width_is_in_pixels() {
    let inked = |width: &str| {
        let src = format!(
            "element A {{ path \"M0 0 C18 15 -18 40 0 60\"; stroke \"#000000\"; fill \"none\"; width {width}; }}\nlsystem W {{ axiom A; }}"
        );
        let d = derive_text(&src, None).expect("derives");
        let mut png = Vec::new();
        let picture = Picture {
            size: 200,
            ..Picture::default()
        };
        if run::write_output(&d, Format::Png, picture, 0, &mut png).is_err() {
            panic!("draws");
        }
        let pixmap = tiny_skia::Pixmap::decode_png(&png).expect("a PNG");
        pixmap.pixels().iter().filter(|p| p.red() < 128).count()
    };
    let (none, one, four) = (inked("0"), inked("1"), inked("4"));
    assert_eq!(none, 0);
    assert!(one > 50, "{one} pixels at width 1");
    let ratio = four as f64 / one as f64;
    assert!(
        (3.0..5.5).contains(&ratio),
        "width 4: {four}, width 1: {one}"
    );
}
