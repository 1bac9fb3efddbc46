//! Files under stress, for real: fifty writers of one file at once (threads
//! of one process, and processes), read-only files, a full disk (`/dev/full`)
//! on stdout and stderr, and an interrupt during a long write. Whatever
//! happens, a file holds one whole version (the old one or a new one), no
//! temporary file is left behind, and a failed write exits 1, never 0, never
//! a panic (101).

use crate::support::root;
use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn lsyc() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lsyc"));
    cmd.env("NO_COLOR", "1").stdin(Stdio::null());
    cmd
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The temporary files lsyc left in `dir` (hidden, ending `.tmp`).
fn leftovers(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .expect("reads the folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[cfg(unix)]
fn mode(path: &Path) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    fs::metadata(path).expect("metadata").permissions().mode() & 0o777
}

#[cfg(unix)]
fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    fs::set_permissions(path, fs::Permissions::from_mode(mode)).expect("chmod");
}

/// Version `k` of a file: large enough that a mix of two would show.
fn version(k: usize) -> Vec<u8> {
    let line = format!("// version {k:02} {}\n", "x".repeat(70));
    line.repeat(4000).into_bytes()
}

#[test]
fn fifty_threads_saving_one_file_leave_one_whole_version() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("plant.lsy");
    fs::write(&path, b"// the original\n").expect("writes");
    let results: Vec<std::io::Result<()>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..50)
            .map(|k| {
                let path = &path;
                s.spawn(move || lsyc::source::write_atomic(path, &version(k)))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("no panic"))
            .collect()
    });
    for (k, r) in results.iter().enumerate() {
        assert!(r.is_ok(), "save {k} failed: {r:?}");
    }
    let now = fs::read(&path).expect("reads");
    let matches = (0..50).filter(|&k| now == version(k)).count();
    assert_eq!(
        matches,
        1,
        "the file is not one of the saved versions ({} bytes)",
        now.len()
    );
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
}

#[test]
fn fifty_processes_writing_one_output_leave_one_whole_version() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Fifty programs whose derived strings differ in length.
    let expected: Vec<String> = (0..50).map(|k| "F+".repeat(2000 + k * 50)).collect();
    for (k, axiom) in expected.iter().enumerate() {
        let program = format!("lsystem P{k} {{ derive 0; axiom {axiom}; }}\n");
        fs::write(dir.path().join(format!("p{k}.lsy")), program).expect("writes");
    }
    let children: Vec<_> = (0..50)
        .map(|k| {
            lsyc()
                .current_dir(dir.path())
                .args(["run", &format!("p{k}.lsy"), "-o", "out.txt"])
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("starts lsyc")
        })
        .collect();
    for (k, child) in children.into_iter().enumerate() {
        let out = child.wait_with_output().expect("waits");
        assert_eq!(out.status.code(), Some(0), "run {k}: {}", text(&out.stderr));
    }
    let now = fs::read_to_string(dir.path().join("out.txt")).expect("reads");
    let matches = expected
        .iter()
        .filter(|e| now.trim_end() == e.as_str())
        .count();
    assert_eq!(matches, 1, "out.txt is not one whole output");
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
}

/// A scene to edit, copied into `dir`.
fn palm(dir: &Path) -> PathBuf {
    let path = dir.join("palm.lsy");
    fs::copy(root().join("lang-examples/palm.lsy"), &path).expect("copies");
    path
}

#[cfg(unix)]
#[test]
fn read_only_files_are_never_replaced() {
    let dir = tempfile::tempdir().expect("tempdir");
    let messy = dir.path().join("messy.lsy");
    fs::write(&messy, "lsystem A{axiom F;F->F+F;}").expect("writes");
    let scene = palm(dir.path());
    for path in [&messy, &scene] {
        set_mode(path, 0o444);
    }
    let before: Vec<Vec<u8>> = [&messy, &scene]
        .iter()
        .map(|p| fs::read(p).expect("reads"))
        .collect();
    let runs: [(&Path, Vec<&str>); 2] = [
        (&messy, vec!["fmt", "--write", "messy.lsy"]),
        (
            &scene,
            vec![
                "edit",
                "palm.lsy",
                "--by",
                "trunk3.v2=30,-5",
                "--pin",
                "trunk2",
                "--write",
            ],
        ),
    ];
    for (k, (path, args)) in runs.iter().enumerate() {
        let out = lsyc()
            .current_dir(dir.path())
            .args(args)
            .output()
            .expect("runs");
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        let name = path.file_name().unwrap().to_string_lossy();
        assert!(
            err.contains(&format!("cannot write `{name}`")) && err.contains("read-only"),
            "{args:?}: {err}"
        );
        assert_eq!(fs::read(path).expect("reads"), before[k], "{args:?}");
        assert_eq!(mode(path), 0o444, "{args:?}");
    }
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
}

#[cfg(unix)]
#[test]
fn a_replaced_file_keeps_its_permissions() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("messy.lsy");
    fs::write(&path, "lsystem A{axiom F;F->F+F;}").expect("writes");
    set_mode(&path, 0o640);
    let out = lsyc()
        .current_dir(dir.path())
        .args(["fmt", "--write", "messy.lsy"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        fs::read_to_string(&path)
            .expect("reads")
            .contains("F -> F+F;")
    );
    assert_eq!(mode(&path), 0o640);
}

/// Runs lsyc in `dir` with stdout and/or stderr on `/dev/full`.
fn on_full_disk(dir: &Path, args: &[&str], stdout_full: bool, stderr_full: bool) -> Output {
    let full = || Stdio::from(File::create("/dev/full").expect("opens /dev/full"));
    let mut cmd = lsyc();
    cmd.current_dir(dir).args(args);
    cmd.stdout(if stdout_full { full() } else { Stdio::piped() });
    cmd.stderr(if stderr_full { full() } else { Stdio::piped() });
    cmd.output().expect("runs")
}

#[test]
fn a_full_disk_is_an_error_never_success_or_a_panic() {
    if !Path::new("/dev/full").exists() {
        eprintln!("no /dev/full on this system");
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    fs::copy(
        root().join("lang-examples/koch-island.lsy"),
        dir.path().join("koch.lsy"),
    )
    .expect("copies");
    fs::write(dir.path().join("broken.lsy"), "lsystem B { axiom F(; }\n").expect("writes");
    palm(dir.path());
    fs::write(
        dir.path().join("art.svg"),
        r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0h10v10h-10z"/><path d="M20 0h10v10h-10z"/></svg>"#,
    )
    .expect("writes");
    let edit = [
        "edit",
        "palm.lsy",
        "--by",
        "trunk3.v2=30,-5",
        "--pin",
        "trunk2",
    ];
    // (arguments, stdout full, stderr full)
    let cases: [(&[&str], bool, bool); 11] = [
        (&["fmt", "koch.lsy"], true, false),
        (&["infer", "art.svg"], true, false),
        (&edit, true, false),
        (&["run", "koch.lsy", "--stats"], true, false),
        (&["run", "koch.lsy", "--stats"], false, true),
        (&["run", "koch.lsy", "--disasm"], true, false),
        (&["run", "koch.lsy", "-o", "-"], true, false),
        (&["run", "koch.lsy"], false, true),
        (&["check", "broken.lsy"], false, true),
        (&["check", "koch.lsy"], false, true),
        (&["man"], true, false),
    ];
    for (args, out_full, err_full) in cases {
        let out = on_full_disk(dir.path(), args, out_full, err_full);
        let err = text(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{args:?} (stdout full: {out_full}, stderr full: {err_full}): {err}"
        );
        if !err_full {
            assert!(
                err.contains("cannot write") && !err.contains("panicked"),
                "{args:?}: {err}"
            );
        }
    }
}

/// Runs lsyc in `dir`; (exit status, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = lsyc().current_dir(dir).args(args).output().expect("runs");
    (out.status.code().unwrap_or(-1), text(&out.stderr))
}

#[test]
fn outputs_never_replace_inputs_or_files_lsyc_did_not_write() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let program = "lsystem T { derive 2; axiom F; F -> F[+F]F; }\n";
    let leaf = r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 C6 4 7 14 1 20 Z"/></svg>"#;
    for (name, body) in [
        ("tree-000.txt", program),
        ("plant.mtl", program),
        ("tree.lsy", program),
        ("tree.mtl", "newmtl bark\nKd 0.4 0.3 0.2\n"),
        ("leaf-001.svg", leaf),
        ("grow-001.svg", leaf),
        (
            "el.lsy",
            "element Leaf { path \"M0 0 L1 1 L0 2 Z\"; }\nlsystem E { derive 1; axiom A; A -> F Leaf A; }\n",
        ),
    ] {
        fs::write(d.join(name), body).expect("writes");
    }
    let before = |name: &str| fs::read(d.join(name)).expect("reads");
    let kept: Vec<(&str, Vec<u8>)> = [
        "tree-000.txt",
        "plant.mtl",
        "tree.mtl",
        "leaf-001.svg",
        "grow-001.svg",
    ]
    .iter()
    .map(|n| (*n, before(n)))
    .collect();
    let refused: [&[&str]; 6] = [
        &["run", "tree-000.txt", "--frames", "-o", "tree.txt"],
        &[
            "run",
            "el.lsy",
            "--element",
            "Leaf=leaf-001.svg",
            "--frames",
            "-o",
            "leaf.svg",
        ],
        &["run", "tree.lsy", "-o", "tree.obj"],
        &["run", "plant.mtl", "-o", "plant.obj"],
        &["run", "el.lsy", "--frames", "-o", "grow.svg"],
        // --force never allows writing over an input.
        &["run", "plant.mtl", "-o", "plant.obj", "--force"],
    ];
    let mut messages = String::new();
    for args in refused {
        let (status, err) = run_in(d, args);
        assert_eq!(status, 2, "{args:?}: {err}");
        messages.push_str(&format!("$ lsyc {}\n{err}\n", args.join(" ")));
    }
    for (name, bytes) in &kept {
        assert_eq!(&before(name), bytes, "{name} was changed");
    }
    assert!(!d.join("plant.obj").exists() && !d.join("tree.obj").exists());
    insta::assert_snapshot!("stress_outputs_refused", messages);
    // Outputs of earlier runs are replaced: users run commands again.
    let again: [&[&str]; 6] = [
        &["run", "tree.lsy", "-o", "tree.svg"],
        &["run", "tree.lsy", "-o", "tree.svg"],
        &["run", "tree.lsy", "-o", "tree.png"],
        &["run", "tree.lsy", "-o", "tree.png"],
        &["run", "el.lsy", "--frames", "-o", "again.glb"],
        &["run", "el.lsy", "--frames", "-o", "again.glb"],
    ];
    for args in again {
        let (status, err) = run_in(d, args);
        assert_eq!(status, 0, "{args:?}: {err}");
    }
    // A hard link to the program is the program.
    fs::hard_link(d.join("tree.lsy"), d.join("linked.svg")).expect("links");
    let (status, err) = run_in(d, &["run", "tree.lsy", "-o", "linked.svg"]);
    assert_eq!(status, 2, "{err}");
    // --force replaces somebody else's sidecar, and says nothing about it.
    let (status, err) = run_in(d, &["run", "tree.lsy", "-o", "tree.obj", "--force"]);
    assert_eq!(status, 0, "{err}");
    assert!(before("tree.mtl").starts_with(b"# lsyc MTL"));
    let (status, err) = run_in(d, &["run", "tree.lsy", "-o", "tree.obj"]);
    assert_eq!(status, 0, "an .mtl lsyc wrote is replaced: {err}");
    let (status, err) = run_in(d, &["infer", "leaf-001.svg", "-o", "leaf-001.svg"]);
    assert_eq!(status, 2, "{err}");
    assert_eq!(before("leaf-001.svg"), leaf.as_bytes());
}

/// The temporary files in `dir` (polled while a child writes).
fn wait_for_temp(dir: &Path, child: &mut std::process::Child) -> bool {
    let start = std::time::Instant::now();
    while start.elapsed() < std::time::Duration::from_secs(240) {
        if !leftovers(dir).is_empty() {
            return true;
        }
        if child.try_wait().ok().flatten().is_some() {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    false
}

#[cfg(unix)]
#[test]
fn an_interrupt_during_a_long_write_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    fs::copy(
        root().join("lang-examples/koch-island.lsy"),
        dir.path().join("koch.lsy"),
    )
    .expect("copies");
    fs::write(dir.path().join("koch.svg"), "the old drawing").expect("writes");
    // Tries again if the child finished its write before it was caught in it.
    for _ in 0..3 {
        let mut child = lsyc()
            .current_dir(dir.path())
            .args(["run", "koch.lsy", "-n", "6", "-o", "koch.svg"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("starts lsyc");
        if !wait_for_temp(dir.path(), &mut child) {
            let _ = child.wait();
            fs::write(dir.path().join("koch.svg"), "the old drawing").expect("writes");
            continue;
        }
        let killed = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .expect("runs kill");
        assert!(killed.success());
        let status = child.wait().expect("waits");
        assert_eq!(status.code(), Some(130), "{status:?}");
        assert_eq!(leftovers(dir.path()), Vec::<String>::new());
        assert_eq!(
            fs::read_to_string(dir.path().join("koch.svg")).expect("reads"),
            "the old drawing"
        );
        return;
    }
    panic!("lsyc wrote koch.svg too fast to be interrupted three times");
}
