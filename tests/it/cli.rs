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
