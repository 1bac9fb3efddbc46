//! `lsyc edit`: guides moved by the mass-spring system, written back through the
//! formatter with every comment kept; the error cases and their exit statuses.

use crate::support::root;
use std::process::Command;

const SCENE: &str = "tests/data/edit/garden.lsy";

struct Run {
    status: i32,
    stdout: String,
    stderr: String,
}

fn lsyc(args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .current_dir(root())
        .env("NO_COLOR", "1")
        .output()
        .expect("the lsyc binary runs");
    let r = Run {
        status: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    };
    assert!(
        !r.stderr.contains("panicked"),
        "lsyc panicked:\n{}",
        r.stderr
    );
    r
}

fn edit(ops: &[&str]) -> Run {
    let mut args = vec!["edit", SCENE];
    args.extend_from_slice(ops);
    lsyc(&args)
}

/// The lines of `after` that differ from `before`, as a small diff.
fn diff(before: &str, after: &str) -> String {
    let mut out = String::new();
    for (a, b) in before.lines().zip(after.lines()) {
        if a != b {
            out.push_str(&format!("- {a}\n+ {b}\n"));
        }
    }
    out
}

/// Every comment of the source is still in the output, in the same order.
fn assert_comments_kept(before: &str, after: &str) {
    let comments = |s: &str| -> Vec<String> {
        s.lines()
            .filter_map(|l| {
                l.find("//")
                    .or_else(|| l.find("/*"))
                    .map(|i| l[i..].to_string())
            })
            .collect()
    };
    assert_eq!(comments(before), comments(after));
}

fn snapshot(ops: &[&str]) -> String {
    let source = std::fs::read_to_string(root().join(SCENE)).expect("the scene is there");
    let r = edit(ops);
    assert_eq!(r.status, 0, "{}", r.stderr);
    assert_eq!(
        source.lines().count(),
        r.stdout.lines().count(),
        "layout kept"
    );
    assert_comments_kept(&source, &r.stdout);
    format!(
        "$ lsyc edit {SCENE} {}\n--- changed lines\n{}--- stderr\n{}",
        ops.join(" "),
        diff(&source, &r.stdout),
        r.stderr
    )
}

#[test]
fn nothing_to_do_prints_the_program_as_fmt_does() {
    let r = edit(&[]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    let fmt = lsyc(&["fmt", SCENE]);
    assert_eq!(r.stdout, fmt.stdout);
    let source = std::fs::read_to_string(root().join(SCENE)).expect("the scene is there");
    assert_eq!(r.stdout, source, "the test scene is in canonical form");
    assert!(r.stderr.contains("no guide changed"), "{}", r.stderr);
}

#[test]
fn dragging_a_vertex_moves_the_snapped_guide_too() {
    insta::assert_snapshot!("drag_by", snapshot(&["--by", "bed.v2=5,5"]));
}

#[test]
fn translating_a_guide_carries_its_snapped_neighbour() {
    insta::assert_snapshot!("translate", snapshot(&["--translate", "hedge=0,10"]));
}

#[test]
fn rotate_and_scale_a_lone_guide() {
    insta::assert_snapshot!(
        "rotate_scale",
        snapshot(&["--rotate", "pond=90", "--scale", "pond=1.5"])
    );
}

#[test]
fn pinned_vertices_hold_while_one_is_dragged() {
    insta::assert_snapshot!(
        "move_pinned",
        snapshot(&[
            "--move",
            "arbour.v2=42.25,76",
            "--pin",
            "arbour.v0",
            "--pin",
            "arbour.v1"
        ])
    );
}

#[test]
fn a_stiff_spring_ties_two_guides() {
    let alone = edit(&["--translate", "arbour=10,0"]);
    let tied = edit(&[
        "--translate",
        "arbour=10,0",
        "--stiff",
        "arbour.v0=hedge.v3",
    ]);
    assert_eq!(alone.status, 0, "{}", alone.stderr);
    assert_eq!(tied.status, 0, "{}", tied.stderr);
    assert!(
        alone.stderr.contains("changed arbour (4 vertices);"),
        "{}",
        alone.stderr
    );
    // Tied, the hedge (and the bed snapped to it) follow the arbour.
    assert!(
        tied.stderr
            .contains("changed bed (4 vertices), hedge (4 vertices), arbour (4 vertices)"),
        "{}",
        tied.stderr
    );
    insta::assert_snapshot!(
        "stiff",
        snapshot(&[
            "--translate",
            "arbour=10,0",
            "--stiff",
            "arbour.v0=hedge.v3"
        ])
    );
}

#[test]
fn operations_apply_in_the_order_given() {
    let a = edit(&["--move", "pond.v0=90,90", "--translate", "pond=1,0"]);
    let b = edit(&["--translate", "pond=1,0", "--move", "pond.v0=90,90"]);
    assert!(
        a.stdout.contains("polygon (91, 90) (121, 100)"),
        "{}",
        a.stdout
    );
    assert!(
        b.stdout.contains("polygon (90, 90) (121, 100)"),
        "{}",
        b.stdout
    );
}

#[test]
fn the_same_edit_gives_the_same_bytes() {
    let ops = ["--by", "hedge.v2=3,-4", "--rotate", "bed=7"];
    let first = edit(&ops);
    assert_eq!(first.status, 0, "{}", first.stderr);
    for _ in 0..3 {
        let again = edit(&ops);
        assert_eq!(again.stdout, first.stdout);
        assert_eq!(again.stderr, first.stderr);
    }
}

#[test]
fn write_rewrites_the_file_atomically() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("garden.lsy");
    std::fs::copy(root().join(SCENE), &path).expect("copy");
    let p = path.to_str().expect("utf-8 path");
    let printed = lsyc(&["edit", p, "--by", "bed.v2=5,5"]);
    let written = lsyc(&["edit", p, "--by", "bed.v2=5,5", "--write"]);
    assert_eq!(written.status, 0, "{}", written.stderr);
    assert!(written.stdout.is_empty());
    let text = std::fs::read_to_string(&path).expect("read back");
    assert_eq!(text, printed.stdout);
    let leftovers = std::fs::read_dir(dir.path()).expect("list").count();
    assert_eq!(leftovers, 1, "no temporary file is left behind");
    // The edited program is still a valid program, and fmt leaves it as it is.
    let check = lsyc(&["check", p]);
    assert_eq!(check.status, 0, "{}", check.stderr);
    let fmt = lsyc(&["fmt", "--check", p]);
    assert_eq!(fmt.status, 0, "{}", fmt.stderr);
}

#[test]
fn the_palm_of_the_gallery_can_be_edited() {
    // Fig. 4 b: the top of the trunk dragged to the right, the trunk's lower guides
    // held; the leaves' guides share the top's vertices and follow it.
    let r = lsyc(&[
        "edit",
        "lang-examples/palm.lsy",
        "--by",
        "trunk3.v2=30,-5",
        "--by",
        "trunk3.v3=30,-5",
        "--pin",
        "trunk1",
        "--pin",
        "trunk2",
    ]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    let source = std::fs::read_to_string(root().join("lang-examples/palm.lsy")).expect("palm");
    assert_comments_kept(&source, &r.stdout);
    // The gallery file changes as the scene grows; check what the edit promises:
    // the two vertices moved by exactly what was asked, the pinned guides kept.
    let polygon = |text: &str, guide: &str| -> String {
        let at = text.find(&format!("guide {guide} {{")).expect("the guide");
        let line = text[at..].lines().nth(1).expect("its polygon").trim();
        line.to_string()
    };
    for g in ["trunk1", "trunk2"] {
        assert_eq!(polygon(&source, g), polygon(&r.stdout, g), "{g}");
    }
    let before = numbers(&polygon(&source, "trunk3"));
    let after = numbers(&polygon(&r.stdout, "trunk3"));
    assert_eq!(before[..4], after[..4], "the bottom is snapped to trunk2");
    for (k, (b, a)) in before[4..].iter().zip(&after[4..]).enumerate() {
        let by = if k % 2 == 0 { 30.0 } else { -5.0 };
        assert!((a - b - by).abs() < 0.051, "{before:?} -> {after:?}");
    }
    // Every leaf's base is the trunk's top edge: each leaf moved with it.
    for k in 1..=8 {
        let leaf = numbers(&polygon(&r.stdout, &format!("frond{k}")));
        let mut base = [leaf[0], leaf[1], leaf[2], leaf[3]];
        if base[0] > base[2] {
            base = [base[2], base[3], base[0], base[1]];
        }
        assert_eq!(base, [after[6], after[7], after[4], after[5]], "frond{k}");
    }
    assert!(
        r.stderr
            .contains("changed trunk3 (2 vertices), frond1 (10 vertices)"),
        "{}",
        r.stderr
    );
}

/// The numbers of a `polygon (x, y) …;` line.
fn numbers(line: &str) -> Vec<f64> {
    line.trim_start_matches("polygon")
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter(|t| !t.is_empty())
        .map(|t| t.parse().expect("a number"))
        .collect()
}

fn error(args: &[&str], status: i32) -> String {
    let r = lsyc(args);
    assert_eq!(r.status, status, "{args:?}\n{}", r.stderr);
    assert!(r.stdout.is_empty(), "{}", r.stdout);
    format!("$ lsyc {}\n{}", args.join(" "), r.stderr)
}

#[test]
fn argument_errors_exit_2() {
    let cases = [
        error(&["edit", SCENE, "--move", "hedgw.v0=1,2"], 2),
        error(&["edit", SCENE, "--move", "pond.v5=1,2"], 2),
        error(&["edit", SCENE, "--scale", "garden=2"], 2),
        error(&["edit", SCENE, "--pin", "bed.v9"], 2),
        error(&["edit", SCENE, "--scene", "Gardn"], 2),
    ];
    insta::assert_snapshot!("argument_errors", cases.join("\n"));
    // Malformed values are refused by the argument parser, naming the form.
    for (flag, bad) in [
        ("--move", "bed=1,2"),
        ("--move", "bed.v1=1"),
        ("--move", "bed.v1=x,2"),
        ("--by", "bed.one=1,2"),
        ("--translate", "bed=1"),
        ("--rotate", "bed=left"),
        ("--scale", "bed=0"),
        ("--stiff", "bed.v0"),
    ] {
        let r = lsyc(&["edit", SCENE, flag, bad]);
        assert_eq!(r.status, 2, "{flag} {bad}\n{}", r.stderr);
        assert!(r.stderr.contains(bad), "{flag} {bad}:\n{}", r.stderr);
        assert!(r.stdout.is_empty());
    }
}

#[test]
fn input_errors_exit_1() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p.to_str().expect("utf-8 path").to_string()
    };
    let no_scene = write("plain.lsy", "lsystem A { axiom F; F -> FF; }\n");
    let syntax = write(
        "syntax.lsy",
        "scene S { guide g { polygon (0, 0) (1, 0) (1 1); } }\n",
    );
    let checks = write(
        "check.lsy",
        "lsystem A { axiom F; }\nscene S { guide g { polygon (0, 0) (1, 0); system B; } }\n",
    );
    let clean = |s: String| s.replace(&format!("{}/", dir.path().display()), "TMP/");
    let cases = [
        clean(error(&["edit", &no_scene, "--move", "g.v0=1,1"], 1)),
        clean(error(&["edit", &syntax, "--move", "g.v0=1,1"], 1)),
        clean(error(&["edit", &checks, "--move", "g.v0=1,1"], 1)),
        error(&["edit", "tests/data/edit/missing.lsy"], 1),
    ];
    insta::assert_snapshot!("input_errors", cases.join("\n"));
}

#[test]
fn seeds_stay_unless_asked_to_follow() {
    insta::assert_snapshot!(
        "seeds",
        [
            snapshot(&["--rotate", "bed=-30"]),
            snapshot(&["--rotate", "bed=-30", "--move-seeds"]),
        ]
        .join("\n")
    );
}
