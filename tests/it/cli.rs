//! The command line end to end: bad inputs of every kind are clear errors that
//! name the file (never a panic), exit statuses follow the contract, and `fmt`
//! writes safely.

use std::path::Path;
use std::process::{Command, Output};

fn lsyc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("the lsyc binary runs")
}

struct Run {
    status: i32,
    stdout: String,
    stderr: String,
}

fn run(args: &[&str]) -> Run {
    let out = lsyc(args);
    Run {
        status: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn check_bytes(name: &str, bytes: &[u8]) -> Run {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).expect("write input");
    let r = run(&[
        "check",
        path.to_str().expect("utf-8 path"),
        "--color",
        "never",
    ]);
    assert!(
        !r.stderr.contains("panicked"),
        "{name}: lsyc panicked:\n{}",
        r.stderr
    );
    r
}

/// An input error: exit 1, an error code, and the file named with line and column.
fn assert_input_error(name: &str, r: &Run, code: &str) {
    assert_eq!(r.status, 1, "{name}: exit status\n{}", r.stderr);
    assert!(
        r.stderr.contains(&format!("error[{code}]")),
        "{name}: expected {code}:\n{}",
        r.stderr
    );
    assert!(
        r.stderr.contains(name),
        "{name}: the file is not named:\n{}",
        r.stderr
    );
}

#[test]
fn empty_file_is_fine() {
    let r = check_bytes("empty.lsy", b"");
    assert_eq!(r.status, 0, "{}", r.stderr);
}

#[test]
fn random_bytes() {
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let bytes: Vec<u8> = (0..20_000)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect();
    let r = check_bytes("random.lsy", &bytes);
    assert_input_error("random.lsy", &r, "E0101");
}

#[test]
fn invalid_utf8() {
    let r = check_bytes(
        "latin1.lsy",
        b"lsystem A {\n    axiom F;\n    // caf\xe9\n}\n",
    );
    assert_input_error("latin1.lsy", &r, "E0101");
    assert!(r.stderr.contains("latin1.lsy:3:"), "{}", r.stderr);
}

#[test]
fn nul_bytes() {
    let r = check_bytes("nul.lsy", b"lsystem A {\n    axiom F\0;\n}\n");
    assert_input_error("nul.lsy", &r, "E0102");
    assert!(r.stderr.contains("nul.lsy:2:12"), "{}", r.stderr);
}

#[test]
fn deeply_nested_brackets() {
    let mut src = String::from("lsystem A {\n    axiom ");
    src.push_str(&"[".repeat(100_000));
    src.push_str("F;\n}\n");
    let r = check_bytes("nested.lsy", src.as_bytes());
    assert_input_error("nested.lsy", &r, "E0601");
}

#[test]
fn deeply_nested_expressions() {
    let mut src = String::from("const x = ");
    src.push_str(&"(".repeat(100_000));
    src.push('1');
    src.push_str(&")".repeat(100_000));
    src.push_str(";\nconst y = ");
    src.push_str(&"-".repeat(100_000));
    src.push_str("1;\nconst z = ");
    src.push_str(&"1 + ".repeat(100_000));
    src.push_str("1;\n");
    let r = check_bytes("deep.lsy", src.as_bytes());
    assert_input_error("deep.lsy", &r, "E0203");
}

#[test]
fn a_one_megabyte_line() {
    let mut src = String::from("lsystem A { axiom ");
    src.push_str(&"F+".repeat(500_000));
    src.push_str("F; F -> FF; }");
    let r = check_bytes("long.lsy", src.as_bytes());
    assert_eq!(r.status, 0, "{}", r.stderr);
}

#[test]
fn unterminated_comment() {
    let r = check_bytes(
        "comment.lsy",
        b"lsystem A {\n    axiom F; /* never closed\n}\n",
    );
    assert_input_error("comment.lsy", &r, "E0104");
    assert!(r.stderr.contains("comment.lsy:2:14"), "{}", r.stderr);
}

#[test]
fn huge_number() {
    let r = check_bytes("huge.lsy", b"const big = 1e999999;\n");
    assert_input_error("huge.lsy", &r, "E0106");
}

#[test]
fn missing_file() {
    let r = run(&["check", "no/such/file.lsy"]);
    assert_eq!(r.status, 1);
    assert!(
        r.stderr.contains("error[E0001]") && r.stderr.contains("no/such/file.lsy"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("no such file"), "{}", r.stderr);
}

#[test]
fn a_directory() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().to_str().expect("utf-8");
    let r = run(&["check", p]);
    assert_eq!(r.status, 1);
    assert!(
        r.stderr.contains("error[E0001]") && r.stderr.contains("is a directory"),
        "{}",
        r.stderr
    );
}

#[test]
fn too_large_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("big.lsy");
    let f = std::fs::File::create(&path).expect("create");
    f.set_len(lsyc::source::MAX_SOURCE_BYTES + 1)
        .expect("sparse file");
    let r = run(&["check", path.to_str().expect("utf-8")]);
    assert_eq!(r.status, 1);
    assert!(
        r.stderr.contains("error[E0002]") && r.stderr.contains("big.lsy"),
        "{}",
        r.stderr
    );
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(run(&["frobnicate"]).status, 2);
    assert_eq!(run(&["check"]).status, 2);
    assert_eq!(run(&["fmt", "--write", "--check", "x.lsy"]).status, 2);
    let r = run(&["check", "x.lsy", "-D", "novalue"]);
    assert_eq!(r.status, 2, "{}", r.stderr);
    assert!(r.stderr.contains("E0506"), "{}", r.stderr);
}

#[test]
fn help_has_examples() {
    let r = run(&["--help"]);
    assert_eq!(r.status, 0);
    assert!(
        r.stdout.contains("Examples:") && r.stdout.contains("lsyc check"),
        "{}",
        r.stdout
    );
    let r = run(&["fmt", "--help"]);
    assert!(
        r.stdout.contains("--write") && r.stdout.contains("Examples:"),
        "{}",
        r.stdout
    );
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p.to_str().expect("utf-8").to_string()
}

#[test]
fn overrides_must_name_constants() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = write(
        dir.path(),
        "c.lsy",
        "const depth = 5;\nlsystem A {\n    derive depth;\n    axiom F;\n}\n",
    );
    assert_eq!(run(&["check", &f, "-D", "depth=7"]).status, 0);
    let r = run(&["check", &f, "-D", "dept=7"]);
    assert_eq!(r.status, 1);
    assert!(
        r.stderr.contains("E0506") && r.stderr.contains("did you mean `depth`"),
        "{}",
        r.stderr
    );
    let r = run(&["check", &f, "-D", "depth=seven"]);
    assert_eq!(r.status, 1);
    assert!(r.stderr.contains("E0506"), "{}", r.stderr);
    let r = run(&["check", &f, "-D", "depth=2.5"]);
    assert_eq!(
        r.status, 1,
        "an override is checked like the constant: derive must be whole"
    );
    assert!(r.stderr.contains("E0505"), "{}", r.stderr);
}

#[test]
fn json_diagnostics() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = write(
        dir.path(),
        "j.lsy",
        "lsystem A {\n    axiom F;\n    F -> G2;\n}\n",
    );
    let r = run(&["check", &f, "--error-format", "json"]);
    assert_eq!(r.status, 1);
    let line = r.stderr.lines().next().expect("one diagnostic");
    let v: serde_json::Value = serde_json::from_str(line).expect("JSON");
    assert_eq!(v["code"], "E0301");
    assert_eq!(v["severity"], "error");
    assert_eq!(v["line"], 3);
    assert_eq!(v["column"], 10);
    assert!(v["file"].as_str().is_some_and(|s| s.ends_with("j.lsy")));
    assert!(v["help"].as_str().is_some_and(|s| s.contains("G(2)")));
}

/// The fixes of `--error-format json`: applied (all edits of the first fix,
/// from the end so earlier offsets hold), each program checks clean.
#[test]
fn json_fixes_repair_the_program() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases = [
        // `=` as a web tool's rule arrow, and `=` in a condition.
        ("lsystem A {\n    axiom X;\n    X = F[+X];\n}\n", "->"),
        ("lsystem A {\n    axiom X;\n    X => F[+X];\n}\n", "->"),
        (
            "lsystem A {\n    axiom A(2);\n    A(x) : x = 2 -> F;\n}\n",
            "==",
        ),
        // A misspelt constant: did you mean.
        ("const len = 2;\nlsystem A {\n    axiom F(lem);\n}\n", "len"),
        // A missing `;`.
        ("lsystem A {\n    axiom F\n    derive 2;\n}\n", ";"),
    ];
    for (i, (text, replacement)) in cases.iter().enumerate() {
        let f = write(dir.path(), &format!("fix{i}.lsy"), text);
        let r = run(&["check", &f, "--error-format", "json"]);
        assert_eq!(r.status, 1, "{text}");
        let v: serde_json::Value = r
            .stderr
            .lines()
            .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("JSON"))
            .find(|v| v["fixes"].is_array())
            .unwrap_or_else(|| panic!("a diagnostic with a fix for {text}: {}", r.stderr));
        let fix = &v["fixes"][0];
        let mut edits: Vec<(usize, usize, String)> = fix["edits"]
            .as_array()
            .expect("edits")
            .iter()
            .map(|e| {
                let at = |k: &str| e[k].as_u64().expect("offset") as usize;
                let with = e["replacement"].as_str().expect("replacement");
                (at("start"), at("end"), with.to_string())
            })
            .collect();
        assert_eq!(edits[0].2, *replacement, "{}", fix["title"]);
        edits.sort_by_key(|e| std::cmp::Reverse(e.0));
        let mut fixed = text.to_string();
        for (start, end, with) in edits {
            fixed.replace_range(start..end, &with);
        }
        let g = write(dir.path(), &format!("fixed{i}.lsy"), &fixed);
        let r = run(&["check", &g]);
        assert_eq!(r.status, 0, "{fixed}\n{}", r.stderr);
    }
}

#[test]
fn color_always_uses_ansi() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = write(dir.path(), "c.lsy", "lsystem A { axiom [F; }\n");
    let r = run(&["check", &f, "--color", "always"]);
    assert!(r.stderr.contains('\u{1b}'), "{}", r.stderr);
    let r = run(&["check", &f, "--color", "never"]);
    assert!(!r.stderr.contains('\u{1b}'), "{}", r.stderr);
}

#[test]
fn fmt_check_write_and_stdout() {
    let dir = tempfile::tempdir().expect("tempdir");
    let messy = "lsystem  Koch{angle 90;derive 2;\naxiom F-F-F-F; // start\nF->F-F+F+FF-F-F+F;}\n";
    let f = write(dir.path(), "k.lsy", messy);
    let r = run(&["fmt", &f]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    insta::assert_snapshot!("fmt_stdout", r.stdout);
    assert_eq!(
        std::fs::read_to_string(&f).expect("read"),
        messy,
        "fmt without --write must not touch the file"
    );
    assert_eq!(run(&["fmt", "--check", &f]).status, 1);
    assert_eq!(run(&["fmt", "--write", &f]).status, 0);
    assert_eq!(std::fs::read_to_string(&f).expect("read"), r.stdout);
    assert_eq!(run(&["fmt", "--check", &f]).status, 0);
    // Syntax errors: nothing is written.
    let bad = write(dir.path(), "bad.lsy", "lsystem A { axiom F F -> ; }\n");
    let r = run(&["fmt", "--write", &bad]);
    assert_eq!(r.status, 1);
    assert_eq!(
        std::fs::read_to_string(&bad).expect("read"),
        "lsystem A { axiom F F -> ; }\n"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

/// With `--error-format json` every line on stderr is one JSON object:
/// diagnostics, one-line errors, warnings and summaries alike.
#[test]
fn json_mode_writes_only_json_lines() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = write(
        dir.path(),
        "w.lsy",
        "const unused = 1;\nlsystem A {\n    axiom F;\n}\n",
    );
    let out = dir.path().join("w.svg");
    let cases: Vec<Vec<&str>> = vec![
        vec!["run", &f, "--error-format", "json"],
        vec![
            "run",
            &f,
            "-o",
            out.to_str().expect("utf-8"),
            "--error-format",
            "json",
        ],
        vec!["run", &f, "-o", &f, "--error-format", "json"],
        vec!["check", &f, "--error-format", "json"],
        vec!["fmt", &f, "--check", "--error-format", "json"],
        vec!["infer", "--error-format", "json"],
        vec!["run", &f, "--no-such-flag", "--error-format", "json"],
        vec!["run", "--error-format=json"],
    ];
    for args in cases {
        let r = run(&args);
        assert!(!r.stderr.trim().is_empty(), "{args:?}: nothing on stderr");
        for line in r.stderr.lines() {
            let v: serde_json::Value = serde_json::from_str(line)
                .unwrap_or_else(|e| panic!("{args:?}: not JSON ({e}): {line}"));
            assert!(v["severity"].is_string(), "{args:?}: {line}");
        }
    }
}

/// Runs lsyc in `dir`, so that messages name files as given (relative) and
/// snapshots hold no machine paths.
fn run_in(dir: &Path, args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("the lsyc binary runs");
    Run {
        status: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// The raw stdout of a run in `dir` (for binary formats).
fn stdout_bytes_in(dir: &Path, args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the lsyc binary runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Summary lines carry timings; a snapshot shows them as `N ms`.
fn scrub_ms(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split(' ').collect();
        let mut kept = Vec::new();
        for (i, w) in words.iter().enumerate() {
            let next_is_ms = words.get(i + 1).is_some_and(|n| n.starts_with("ms"));
            if next_is_ms && w.chars().all(|c| c.is_ascii_digit()) {
                kept.push("N");
            } else {
                kept.push(w);
            }
        }
        out.push_str(&kept.join(" "));
        out.push('\n');
    }
    out
}

const DEPTH_PROGRAM: &str = "const DEPTH = 4;\nconst turn = 90;\nlsystem A {\n    angle turn;\n    derive DEPTH;\n    axiom F;\n    F -> F+F;\n}\n";

/// `-D depth=3` when the constant is `DEPTH`: a difference of case alone gets a
/// "did you mean", however long the name; `-D DEPTH=3.5` for a constant used as
/// a count is an error whose note names the `-D`.
#[test]
fn overrides_suggest_by_case_and_name_their_source() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), "depth.lsy", DEPTH_PROGRAM);
    let case = run_in(dir.path(), &["check", "depth.lsy", "-D", "depth=3"]);
    assert_eq!(case.status, 1, "{}", case.stderr);
    let fraction = run_in(dir.path(), &["check", "depth.lsy", "-D", "DEPTH=3.5"]);
    assert_eq!(fraction.status, 1, "{}", fraction.stderr);
    // A fraction is fine where any number is.
    let angle = run_in(dir.path(), &["check", "depth.lsy", "-D", "turn=22.5"]);
    assert_eq!(angle.status, 0, "{}", angle.stderr);
    insta::assert_snapshot!(
        "override_case_and_fraction",
        format!(
            "$ lsyc check depth.lsy -D depth=3\n{}\n$ lsyc check depth.lsy -D DEPTH=3.5\n{}",
            case.stderr, fraction.stderr
        )
    );
}

/// `-n` takes a whole number within derive's own limit, with derive's message
/// (not clap's tip about `-- -1`), as a usage error.
#[test]
fn steps_out_of_range_get_derives_message() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), "depth.lsy", DEPTH_PROGRAM);
    let mut shown = String::new();
    for n in ["-1", "2.5", "1000001", "4000000000"] {
        let r = run_in(dir.path(), &["run", "depth.lsy", "-n", n]);
        assert_eq!(r.status, 2, "-n {n}: {}", r.stderr);
        assert!(!r.stderr.contains("-- "), "-n {n}: {}", r.stderr);
        shown.push_str(&format!("$ lsyc run depth.lsy -n {n}\n{}\n", r.stderr));
    }
    insta::assert_snapshot!("steps_out_of_range", shown);
    let r = run_in(dir.path(), &["run", "depth.lsy", "-n", "0"]);
    assert_eq!(r.status, 0, "{}", r.stderr);
}

/// A drawing given to `run`, `check` or `fmt` (by its extension, or by its
/// first bytes) is one clear error pointing at `lsyc infer`, not a cascade of
/// parse errors.
#[test]
fn a_drawing_given_as_a_program() {
    let dir = tempfile::tempdir().expect("tempdir");
    let svg = "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 10 10\">\n  <path d=\"M0 0 L5 5\"/>\n</svg>\n";
    write(dir.path(), "leaf.svg", svg);
    write(dir.path(), "named.lsy", svg);
    write(
        dir.path(),
        "bare.lsy",
        "\u{feff}  <svg viewBox=\"0 0 1 1\"></svg>\n",
    );
    let mut shown = String::new();
    for args in [
        ["run", "leaf.svg"],
        ["check", "leaf.svg"],
        ["fmt", "leaf.svg"],
        ["check", "named.lsy"],
        ["fmt", "bare.lsy"],
    ] {
        let r = run_in(dir.path(), &args);
        assert_eq!(r.status, 1, "{args:?}: {}", r.stderr);
        assert!(!r.stderr.contains("E0"), "{args:?}: {}", r.stderr);
        assert_eq!(r.stderr.lines().count(), 2, "{args:?}: {}", r.stderr);
        shown.push_str(&format!("$ lsyc {}\n{}\n", args.join(" "), r.stderr));
    }
    insta::assert_snapshot!("drawing_as_program", shown);
}

/// `-o -` writes every format to stdout, byte for byte what `-o FILE` writes:
/// SVG by default, the others by `--format`; `infer -o -` is the program.
#[test]
fn dash_o_writes_to_stdout() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    write(
        d,
        "plant.lsy",
        "lsystem P {\n    angle 25;\n    derive 3;\n    axiom X;\n    X -> F[+X][-X]{.+F.-F.F.}FX;\n    F -> FF;\n}\n",
    );
    for (format, ext) in [
        (None, "svg"),
        (Some("svg"), "svg"),
        (Some("txt"), "txt"),
        (Some("obj"), "obj"),
        (Some("png"), "png"),
    ] {
        let file = format!("plant.{ext}");
        let r = run_in(d, &["run", "plant.lsy", "-o", &file]);
        assert_eq!(r.status, 0, "{}", r.stderr);
        let mut args = vec!["run", "plant.lsy", "-o", "-"];
        if let Some(f) = format {
            args.extend(["--format", f]);
        }
        let piped = stdout_bytes_in(d, &args);
        let mut written = std::fs::read(d.join(&file)).expect("the file");
        assert!(!written.is_empty(), "{file}");
        if ext == "obj" {
            // A file names its materials beside it (`mtllib plant.mtl`);
            // stdout has no beside, so that line is all that differs.
            let text = String::from_utf8(written).expect("OBJ is text");
            assert!(text.contains("mtllib plant.mtl\n"), "{text}");
            written = text.replacen("mtllib plant.mtl\n", "", 1).into_bytes();
        }
        assert!(piped == written, "{args:?} differs from -o {file}");
    }
    // `--format` that disagrees with the file, or names no format: usage errors.
    let r = run_in(d, &["run", "plant.lsy", "-o", "x.svg", "--format", "png"]);
    assert_eq!(r.status, 2, "{}", r.stderr);
    let r = run_in(d, &["run", "plant.lsy", "-o", "-", "--format", "jpeg"]);
    assert_eq!(r.status, 2, "{}", r.stderr);
    assert!(r.stderr.contains("svg, png, obj and txt"), "{}", r.stderr);
    // infer: `-o -` is stdout, as without -o.
    let art = crate::support::root().join("tests/data/infer/grid.svg");
    let art = art.to_str().expect("utf-8");
    let dash = stdout_bytes_in(d, &["infer", art, "-o", "-"]);
    let plain = stdout_bytes_in(d, &["infer", art]);
    assert!(String::from_utf8_lossy(&dash).contains("lsystem"));
    assert_eq!(dash, plain);
}

/// `--stats` follows one rule: its JSON goes to stdout, unless stdout carries
/// the result itself (`run -o -`, `infer` without `-o`), then to stderr.
#[test]
fn stats_go_to_stdout_unless_the_result_is_there() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    write(d, "depth.lsy", DEPTH_PROGRAM);
    let json_line = |text: &str| -> serde_json::Value {
        let line = text
            .lines()
            .find(|l| l.starts_with('{'))
            .unwrap_or_else(|| panic!("no JSON line in:\n{text}"));
        serde_json::from_str(line).expect("JSON")
    };
    let r = run_in(d, &["run", "depth.lsy", "--stats"]);
    assert_eq!(json_line(&r.stdout)["segments"], 16);
    assert!(!r.stderr.contains('{'), "{}", r.stderr);
    let r = run_in(d, &["run", "depth.lsy", "-o", "out.svg", "--stats"]);
    assert_eq!(json_line(&r.stdout)["segments"], 16);
    let r = run_in(d, &["run", "depth.lsy", "-o", "-", "--stats"]);
    assert!(r.stdout.starts_with("<?xml"), "{}", r.stdout);
    assert_eq!(json_line(&r.stderr)["segments"], 16);
    let art = crate::support::root().join("tests/data/infer/grid.svg");
    let art = art.to_str().expect("utf-8");
    let r = run_in(d, &["infer", art, "-o", "grid.lsy", "--stats"]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    assert!(json_line(&r.stdout)["elements"].as_u64() > Some(1));
    let r = run_in(d, &["infer", art, "--stats"]);
    assert!(r.stdout.contains("lsystem") && !r.stdout.contains("\"elements\""));
    assert!(json_line(&r.stderr)["elements"].as_u64() > Some(1));
}

/// The summary line counts polygons, and without `-o` says that nothing was
/// written and how to write a file.
#[test]
fn summary_line_counts_polygons_and_says_how_to_write() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    write(
        d,
        "leaf.lsy",
        "lsystem Leaf {\n    angle 60;\n    axiom {.F.+F.+F.};\n}\n",
    );
    let mut shown = String::new();
    for args in [
        vec!["run", "leaf.lsy"],
        vec!["run", "leaf.lsy", "-o", "leaf.svg"],
        vec!["run", "leaf.lsy", "-o", "-", "--format", "txt"],
    ] {
        let r = run_in(d, &args);
        assert_eq!(r.status, 0, "{}", r.stderr);
        shown.push_str(&format!(
            "$ lsyc {}\n{}",
            args.join(" "),
            scrub_ms(&r.stderr)
        ));
    }
    insta::assert_snapshot!("summary_lines", shown);
}

/// `lsyc completions SHELL` and `lsyc man [COMMAND]` come from the same clap
/// definition as `--help`: every command is in them.
#[test]
fn completions_and_manual_pages() {
    let commands = ["run", "check", "fmt", "infer", "edit", "completions", "man"];
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let r = run(&["completions", shell]);
        assert_eq!(r.status, 0, "{shell}: {}", r.stderr);
        for c in commands {
            assert!(r.stdout.contains(c), "{shell}: no `{c}`");
        }
    }
    assert!(
        run(&["completions", "bash"])
            .stdout
            .contains("--max-modules")
    );
    assert_eq!(run(&["completions", "tcsh"]).status, 2);
    let r = run(&["man"]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    assert!(
        r.stdout.starts_with(".ie") || r.stdout.contains(".TH lsyc 1"),
        "{}",
        r.stdout
    );
    for c in commands {
        assert!(
            r.stdout.contains(&format!("lsyc\\-{c}")),
            "lsyc(1) lists no `{c}`"
        );
    }
    let r = run(&["man", "run"]);
    assert_eq!(r.status, 0, "{}", r.stderr);
    assert!(r.stdout.contains(".TH lsyc-run 1"), "{}", r.stdout);
    for option in ["\\-\\-seed", "\\-\\-stats", "\\-\\-format", "\\-\\-guides"] {
        assert!(r.stdout.contains(option), "lsyc-run(1) has no {option}");
    }
    let r = run(&["man", "frobnicate"]);
    assert_eq!(r.status, 2, "{}", r.stderr);
    assert!(r.stderr.contains("run, fmt"), "{}", r.stderr);
}

/// The README's "A taste of the language" shows programs of the gallery:
/// every code block there is text of a file in lang-examples/.
#[test]
fn readme_taste_is_gallery_text() {
    let root = crate::support::root();
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README");
    let start = readme
        .find("## A taste of the language")
        .expect("the section");
    let rest = &readme[start + 3..];
    let section = &rest[..rest.find("\n## ").unwrap_or(rest.len())];
    let gallery: Vec<String> = crate::support::lsy_files(&["lang-examples"])
        .iter()
        .map(|p| crate::support::read_text(p))
        .collect();
    let blocks: Vec<&str> = section.split("```").skip(1).step_by(2).collect();
    assert!(blocks.len() >= 2, "{section}");
    for block in blocks {
        let code = block.strip_prefix('\n').unwrap_or(block);
        assert!(
            gallery.iter().any(|g| g.contains(code)),
            "not text of a gallery program:\n{code}"
        );
    }
}
