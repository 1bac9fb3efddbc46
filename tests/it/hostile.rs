//! Hostile programs: every one ends in a clear answer (exit 0, or exit 1 with a
//! diagnostic that names the file, line and column) within a generous time,
//! never a panic, stack overflow, abort or runaway. The small inputs live in
//! `tests/data/hostile/` with their expectation on the first line
//! (`// expect: E0907 args: -n 4000000000`, or `// expect: ok`); the large ones
//! are generated here, so the repository does not carry megabytes of brackets.

use crate::support::root;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Generous: the debug binary on a busy two-core machine.
const TIME_BOUND: Duration = Duration::from_secs(300);

struct Outcome {
    status: i32,
    stderr: String,
    took: Duration,
}

fn lsyc(args: &[&str], dir: &Path) -> Outcome {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("the lsyc binary runs");
    Outcome {
        status: out.status.code().unwrap_or(-1),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        took: start.elapsed(),
    }
}

/// What a hostile input must give: `None` is success, `Some(code)` an input error.
fn assert_outcome(name: &str, o: &Outcome, want: Option<&str>) {
    let head: String = o.stderr.chars().take(2000).collect();
    for bad in [
        "panicked",
        "overflow",
        "fatal runtime error",
        "memory allocation",
    ] {
        assert!(!o.stderr.contains(bad), "{name}: {bad}:\n{head}");
    }
    assert!(
        o.took < TIME_BOUND,
        "{name}: took {:?}, more than {TIME_BOUND:?}",
        o.took
    );
    match want {
        None => assert_eq!(o.status, 0, "{name}: expected success:\n{head}"),
        Some(code) => {
            assert_eq!(o.status, 1, "{name}: expected exit 1:\n{head}");
            assert!(
                o.stderr.contains(&format!("error[{code}]")),
                "{name}: expected {code}:\n{head}"
            );
            assert!(
                o.stderr.contains(&format!("{name}:")),
                "{name}: the message does not name the file with a line and column:\n{head}"
            );
        }
    }
}

/// `// expect: CODE|ok [args: …]` from the first line of a hostile program.
fn expectation(text: &str) -> (Option<String>, Vec<String>) {
    let Some(rest) = text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("// expect: "))
    else {
        return (Some("E0605".to_string()), Vec::new());
    };
    let (code, args) = match rest.split_once(" args: ") {
        Some((c, a)) => (c, a.split_whitespace().map(str::to_string).collect()),
        None => (rest, Vec::new()),
    };
    let code = (code.trim() != "ok").then(|| code.trim().to_string());
    (code, args)
}

#[test]
fn every_hostile_program_is_answered_clearly() {
    let dir = root().join("tests/data/hostile");
    let out = tempfile::tempdir().expect("tempdir");
    let mut seen = 0;
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/data/hostile")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "lsy"))
        .collect();
    paths.sort();
    for path in paths {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .expect("a file name")
            .to_string();
        let text = std::fs::read_to_string(&path).expect("read");
        let (want, extra) = expectation(&text);
        let target = out.path().join(name.replace(".lsy", ".svg"));
        let mut args = vec!["run".to_string(), name.clone()];
        args.extend(extra.into_iter().map(|a| {
            if a == "OUT.svg" {
                target.display().to_string()
            } else {
                a
            }
        }));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = lsyc(&args, &dir);
        assert_outcome(&name, &o, want.as_deref());
        seen += 1;
    }
    assert!(seen >= 9, "only {seen} hostile programs found");
}

/// A generated program, written to a temporary folder and run with `args`.
fn generated(name: &str, text: &str, args: &[&str], want: Option<&str>) -> Outcome {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join(name), text).expect("write");
    let mut all = args.to_vec();
    all.push(name);
    let o = lsyc(&all, dir.path());
    assert_outcome(name, &o, want);
    o
}

#[test]
fn a_chain_of_100000_constants_in_reverse_order() {
    let n = 100_000;
    let mut text: String = (1..=n)
        .rev()
        .map(|i| format!("const c{i} = c{} + 1;\n", i - 1))
        .collect();
    text.push_str("const c0 = 1;\nlsystem Chain { axiom A(c100000); }\n");
    generated("chain.lsy", &text, &["check"], None);
    generated("chain.lsy", &text, &["run"], None);
}

#[test]
fn a_cycle_at_the_end_of_a_long_chain_is_reported_once() {
    let n = 50_000;
    let mut text: String = (1..=n)
        .map(|i| format!("const c{i} = c{} + 1;\n", i - 1))
        .collect();
    text.push_str(&format!(
        "const c0 = c{n};\nlsystem Chain {{ axiom A(c1); }}\n"
    ));
    let o = generated("cycle.lsy", &text, &["check"], Some("E0503"));
    assert_eq!(o.stderr.matches("error[E0503]").count(), 1, "{}", o.stderr);
}

#[test]
fn more_distinct_modules_than_a_string_can_number() {
    let n = 70_000;
    let mut text: String = (0..n).map(|i| format!("module M{i};\n")).collect();
    text.push_str("lsystem Many {\n    axiom");
    for i in 0..n {
        text.push_str(&format!(" M{i}"));
    }
    text.push_str(";\n}\n");
    generated("modules.lsy", &text, &["run"], Some("E0906"));
}

#[test]
fn a_million_nested_brackets() {
    let n = 1_000_000;
    let text = format!(
        "lsystem Deep {{ axiom {}F{}; }}\n",
        "[".repeat(n),
        "]".repeat(n)
    );
    generated("brackets.lsy", &text, &["run"], None);
    generated("brackets.lsy", &text, &["fmt"], None);
}

#[test]
fn deeply_nested_parentheses_and_expressions() {
    let n = 100_000;
    // Parentheses alone add no depth to an expression.
    let text = format!(
        "lsystem P {{ axiom F({}1{}); }}\n",
        "(".repeat(n),
        ")".repeat(n)
    );
    generated("parens.lsy", &text, &["run"], None);
    let text = format!(
        "lsystem P {{ axiom F({}1{}); }}\n",
        "1+(".repeat(n),
        ")".repeat(n)
    );
    generated("nested.lsy", &text, &["run"], Some("E0203"));
}

#[test]
fn limit_messages_are_the_same_on_every_run_and_thread_count() {
    let dir = root().join("tests/data/hostile");
    let runs: Vec<String> = ["1", "2", "2", "4"]
        .iter()
        .map(|t| {
            let o = lsyc(
                &[
                    "run",
                    "parametric-explosion.lsy",
                    "--max-modules",
                    "100000",
                    "--threads",
                    t,
                ],
                &dir,
            );
            assert_outcome("parametric-explosion.lsy", &o, Some("E0903"));
            o.stderr
        })
        .collect();
    assert!(runs.windows(2).all(|w| w[0] == w[1]), "{runs:#?}");
}
