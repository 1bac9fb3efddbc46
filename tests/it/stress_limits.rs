//! Limits everywhere, for real: settings that would exhaust the machine are
//! refused with a usage error before any work (`--threads`), and work that
//! would not end ends with an error naming its cause (a scene linked to
//! itself: tests/data/hostile/self-linked-guide.lsy, run by `hostile`; SVG
//! numbers beyond 32-bit floats and entity bombs: `hostile_svg`).

use crate::support::root;
use std::process::{Command, Stdio};

#[test]
fn thread_counts_beyond_the_machine_are_usage_errors() {
    let koch = root().join("lang-examples/koch-island.lsy");
    for n in ["100000", "0", "4.5", "many"] {
        let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
            .args(["run", "--threads", n])
            .arg(&koch)
            .stdin(Stdio::null())
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--threads {n}: {err}");
        assert!(
            err.contains("the number of threads must be a whole number from 1 to"),
            "--threads {n}: {err}"
        );
    }
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(["run", "--threads", "1", "--stats"])
        .arg(&koch)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0));
}
