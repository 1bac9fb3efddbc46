//! `lsyc studio`: the protocol against the command line it stands for (a run
//! draws what `lsyc run -o x.svg` writes, a drag writes what `lsyc edit`
//! writes and draws what a full run of that text draws), the server over HTTP
//! (first line, 127.0.0.1, superseded runs, atomic save), the committed bundle
//! against its sources, and the page itself in headless Chromium.

use crate::support::root;
use lsyc::studio::protocol::{self, Drag, DragSession, Program};
use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

fn lsyc() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lsyc"));
    c.current_dir(root()).env("NO_COLOR", "1");
    c
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).expect("reads")
}

/// What `lsyc run FILE -o x.svg [more]` writes.
fn cli_svg(file: &Path, more: &[&str]) -> String {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.svg");
    let status = lsyc()
        .arg("run")
        .arg(file)
        .arg("-o")
        .arg(&out)
        .args(more)
        .output()
        .expect("runs");
    assert!(status.status.success(), "{status:?}");
    std::fs::read_to_string(out).expect("wrote")
}

fn program(source: &str) -> Program {
    Program {
        source: source.to_string(),
        ..Program::default()
    }
}

#[test]
fn a_run_draws_what_lsyc_run_writes() {
    let rel = "lang-examples/monopodial-tree.lsy";
    let reply = protocol::run(&program(&read(rel)), rel);
    assert!(reply.ok, "{:?}", reply.diagnostics);
    assert!(!reply.is_scene);
    assert_eq!(
        reply.svg.as_deref(),
        Some(cli_svg(&root().join(rel), &[]).as_str())
    );
    let stats = reply.stats.expect("stats");
    assert_eq!(stats["system"], "MonopodialTree");
    assert_eq!(stats["steps"], 10);
    let names: Vec<&str> = reply.constants.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["r1", "r2", "a0", "a2", "d", "wr"]);

    // A slider's value (like -D) and a step (like -n).
    let mut p = program(&read(rel));
    p.defines.insert("r2".to_string(), 0.8);
    p.step = Some(4);
    let reply = protocol::run(&p, rel);
    let expected = cli_svg(&root().join(rel), &["-D", "r2=0.8", "-n", "4"]);
    assert_eq!(reply.svg.as_deref(), Some(expected.as_str()));
    let previous = cli_svg(&root().join(rel), &["-D", "r2=0.8", "-n", "3"]);
    assert_eq!(reply.previous_svg.as_deref(), Some(previous.as_str()));
}

#[test]
fn a_scene_draws_its_guides_as_lsyc_run_guides_does() {
    let rel = "lang-examples/palm.lsy";
    let reply = protocol::run(&program(&read(rel)), rel);
    assert!(reply.ok, "{:?}", reply.diagnostics);
    assert!(reply.is_scene);
    let svg = reply.svg.expect("svg");
    assert_eq!(svg, cli_svg(&root().join(rel), &["--guides"]));
    assert!(svg.contains("class=\"guide\""), "outlines drawn");
    assert_eq!(reply.guides.len(), 11);
    assert_eq!(reply.guides[2].name, "trunk3");
    assert_eq!(reply.guides[2].points[2], [85.0, 339.1]);
}

#[test]
fn errors_come_with_the_codes_and_words_of_lsyc_check() {
    let text = "lsystem A {\n    axiom F(;\n    F -> G(x);\n}\n";
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("broken.lsy");
    std::fs::write(&file, text).expect("writes");
    let reply = protocol::run(&program(text), "broken.lsy");
    assert!(!reply.ok);
    assert!(reply.svg.is_none());
    let out = lsyc()
        .arg("check")
        .arg(&file)
        .args(["--error-format", "json"])
        .output()
        .expect("runs");
    let cli: Vec<Value> = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|v| v.get("code").is_some())
        .collect();
    assert!(!cli.is_empty());
    assert_eq!(reply.diagnostics.len(), cli.len());
    for (ours, theirs) in reply.diagnostics.iter().zip(&cli) {
        for key in ["code", "message", "line", "column", "severity", "labels"] {
            assert_eq!(ours[key], theirs[key], "{key}");
        }
    }
    // The editor's positions: UTF-16 units of the primary span.
    let d = &reply.diagnostics[0];
    assert!(d["code"].as_str().is_some_and(|c| c.starts_with('E')));
    assert_eq!(
        d["from"], d["labels"][0]["start"],
        "ASCII text: bytes = UTF-16 units"
    );
    // é: 2 bytes, 1 unit; 𝄞: 4 bytes, 2 units.
    assert_eq!(protocol::utf16_offset("é𝄞x", 2 + 4), 1 + 2);
    assert_eq!(
        protocol::utf16_offset("é𝄞x", 3),
        1,
        "inside a character: its start"
    );
}

#[test]
fn a_runtime_error_keeps_no_drawing_and_says_where() {
    let text = "const z = 0;\nlsystem A {\n    axiom F(1 / z);\n}\n";
    let reply = protocol::run(&program(text), "z.lsy");
    assert!(!reply.ok);
    let codes: Vec<&str> = reply
        .diagnostics
        .iter()
        .filter_map(|d| d["code"].as_str())
        .collect();
    assert!(codes.iter().any(|c| c.starts_with('E')), "{codes:?}");
}

#[test]
fn a_drag_writes_what_lsyc_edit_move_seeds_writes_and_draws_what_a_full_run_draws() {
    let rel = "lang-examples/palm.lsy";
    let text = read(rel);
    let p = program(&text);
    let mut session = DragSession::new(&p).expect("a scene");
    assert!(session.matches(&p));
    let mut last = None;
    // Several moves of one drag, each from the text at the start of the drag.
    for (x, y) in [(90.0, 338.0), (100.0, 335.0), (112.5, 330.0)] {
        let d = Drag {
            program: p.clone(),
            vertex: "trunk3.v2".to_string(),
            x,
            y,
            pins: vec!["trunk1".to_string()],
            ..Drag::default()
        };
        last = Some(session.drag(&d, rel).expect("drags"));
    }
    let reply = last.expect("a reply");
    let formatted = reply.formatted.expect("the new text");
    let out = lsyc()
        .args([
            "edit",
            rel,
            "--move",
            "trunk3.v2=112.5,330",
            "--pin",
            "trunk1",
            "--move-seeds",
        ])
        .output()
        .expect("runs");
    assert!(out.status.success());
    assert_eq!(formatted, String::from_utf8_lossy(&out.stdout));
    assert!(formatted.contains("// The palm of Beneš"), "comments kept");
    assert!(
        formatted.contains("(112.5, 330)"),
        "the vertex is where it was dragged"
    );
    let trunk3 = &reply.guides[2];
    assert_eq!(trunk3.points[2], [112.5, 330.0]);
    // Pinned: trunk1 did not move; the crown followed (frond bases are trunk3's top).
    assert_eq!(reply.guides[0].points[0], [-14.2, 4.7]);
    assert_eq!(reply.guides[3].points[1], [112.5, 330.0]);
    assert!(!reply.recomputed.contains(&"trunk1".to_string()));
    assert!(reply.recomputed.contains(&"frond1".to_string()));
    // The incremental runner draws what a full run of the new text draws.
    let dir = tempfile::tempdir().expect("tempdir");
    let moved = dir.path().join("palm.lsy");
    std::fs::write(&moved, &formatted).expect("writes");
    assert_eq!(
        reply.svg.as_deref(),
        Some(cli_svg(&moved, &["--guides"]).as_str())
    );
}

/// A page's drawing after a patch: the head, each layer sent or kept from
/// the drawing before, the tail.
fn patched(before: &str, patch: &protocol::Patch) -> String {
    let (_, old, _) = protocol::split_layers(before).expect("layers");
    let mut out = patch.head.clone();
    assert_eq!(old.len(), patch.layers.len());
    for ((name, sent), (old_name, old_text)) in patch.layers.iter().zip(old) {
        assert_eq!(name, old_name);
        out.push_str(sent.as_deref().unwrap_or(old_text));
    }
    out.push_str(&patch.tail);
    out
}

#[test]
fn a_drag_sends_only_the_layers_that_changed_and_they_make_the_full_drawing() {
    let rel = "lang-examples/tree.lsy";
    let text = read(rel);
    let p = program(&text);
    let first = protocol::run(&p, rel);
    let full = first.svg.expect("a drawing");
    assert_eq!(first.layers.len(), 10, "one hash per guide layer");
    let mut session = DragSession::new(&p).expect("a scene");
    let mut shown = full.clone();
    let mut have = first.layers.clone();
    for (x, y) in [(104.0, 102.0), (96.0, 98.0), (100.5, 99.0)] {
        let d = Drag {
            program: p.clone(),
            vertex: "limbR1.v2".to_string(),
            x,
            y,
            pins: vec!["trunk".to_string()],
            have: Some(have.clone()),
            ..Drag::default()
        };
        let reply = session.drag(&d, rel).expect("drags");
        assert!(reply.svg.is_none(), "a patch instead of the whole drawing");
        let patch = reply.patch.expect("a patch");
        let sent: Vec<&str> = patch
            .layers
            .iter()
            .filter(|(_, t)| t.is_some())
            .map(|(n, _)| n.as_str())
            .collect();
        assert!(
            !sent.is_empty() && sent.len() < 10,
            "some layers, not all: {sent:?}"
        );
        assert!(
            !sent.contains(&"trunk"),
            "the pinned trunk is kept: {sent:?}"
        );
        shown = patched(&shown, &patch);
        // What the page shows is what a full run of the dragged text draws.
        let dir = tempfile::tempdir().expect("tempdir");
        let moved = dir.path().join("tree.lsy");
        std::fs::write(&moved, reply.formatted.as_deref().expect("text")).expect("writes");
        assert_eq!(shown, cli_svg(&moved, &["--guides"]));
        have = reply.layers;
    }
    // A page that says it has nothing gets every layer.
    let d = Drag {
        program: p.clone(),
        vertex: "limbR1.v2".to_string(),
        x: 101.0,
        y: 99.0,
        pins: vec!["trunk".to_string()],
        have: Some(Default::default()),
        ..Drag::default()
    };
    let patch = session
        .drag(&d, rel)
        .expect("drags")
        .patch
        .expect("a patch");
    assert!(patch.layers.iter().all(|(_, t)| t.is_some()));
}

#[test]
fn a_stiff_spring_is_what_lsyc_edit_stiff_writes() {
    let rel = "lang-examples/palm.lsy";
    let p = program(&read(rel));
    let mut session = DragSession::new(&p).expect("a scene");
    let d = Drag {
        program: p.clone(),
        vertex: "trunk3.v2".to_string(),
        x: 112.5,
        y: 330.0,
        pins: vec!["trunk1".to_string()],
        stiff: vec!["trunk3.v2=frond1.v4".to_string()],
        ..Drag::default()
    };
    let reply = session.drag(&d, rel).expect("drags");
    let out = lsyc()
        .args([
            "edit",
            rel,
            "--move",
            "trunk3.v2=112.5,330",
            "--pin",
            "trunk1",
            "--stiff",
            "trunk3.v2=frond1.v4",
            "--move-seeds",
        ])
        .output()
        .expect("runs");
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        reply.formatted.as_deref(),
        Some(String::from_utf8_lossy(&out.stdout).as_ref())
    );
    let loose = Drag {
        stiff: Vec::new(),
        ..d.clone()
    };
    let mut other = DragSession::new(&p).expect("a scene");
    let loose = other.drag(&loose, rel).expect("drags");
    assert_ne!(
        loose.formatted, reply.formatted,
        "the spring changes the relaxation"
    );
    let bad = Drag {
        stiff: vec!["trunk3.v2".to_string()],
        ..d
    };
    assert!(session.drag(&bad, rel).is_err());
}

#[test]
fn hover_and_completion_are_the_language_servers() {
    let text = read("lang-examples/monopodial-tree.lsy");
    // On a use of `r2` (UTF-16 offsets; the file has non-ASCII comments).
    let byte = text.rfind("r2").expect("a use of r2");
    let at = protocol::utf16_offset(&text, byte) + 1;
    let h = protocol::hover(&text, at).expect("a hover");
    let a = lsyc::lsp::analysis::Analysis::new(text.clone());
    let want = lsyc::lsp::hover::hover(&a, byte + 1).expect("the server's hover");
    let lsp_types::HoverContents::Markup(m) = want.contents else {
        panic!("markdown")
    };
    assert_eq!(h["text"], json!(m.value));
    assert!(m.value.contains("r2"), "{}", m.value);
    let (from, to) = (h["from"].as_u64().unwrap(), h["to"].as_u64().unwrap());
    assert_eq!(to - from, 2, "the span of `r2`");
    assert_eq!(protocol::byte_offset(&text, from as usize), byte);
    assert!(protocol::hover(&text, 0).is_none() || protocol::hover("", 0).is_none());
    // Completion after `r` at the end of a rule: the constants starting with it.
    let cut = text.find("const r2").expect("r2") + "const r2 = 0.6;\n".len();
    let items = protocol::complete(&text, protocol::utf16_offset(&text, cut));
    let all = lsyc::lsp::complete::complete(&a, cut);
    assert_eq!(items.len(), all.len());
    let labels: Vec<&str> = items.iter().filter_map(|i| i["label"].as_str()).collect();
    assert!(labels.contains(&"lsystem"), "{labels:?}");
}

#[test]
fn an_export_is_what_lsyc_run_writes() {
    let rel = "lang-examples/monopodial-tree.lsy";
    let p = Program {
        view: Some([60.0, 10.0]),
        ..program(&read(rel))
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for ext in ["svg", "png", "obj", "glb"] {
        let bytes = protocol::export(&p, ext).expect("exports");
        let out = dir.path().join(format!("x.{ext}"));
        let status = lsyc()
            .arg("run")
            .arg(rel)
            .arg("-o")
            .arg(&out)
            .args(["--view", "60,10"])
            .output()
            .expect("runs");
        assert!(status.status.success(), "{status:?}");
        let mut want = std::fs::read(&out).expect("wrote");
        if ext == "obj" {
            // The command line names its `.mtl` beside the file; a download has none.
            let text = String::from_utf8(want).expect("text");
            want = text
                .lines()
                .filter(|l| !l.starts_with("mtllib "))
                .flat_map(|l| [l, "\n"])
                .collect::<String>()
                .into_bytes();
        }
        assert!(
            bytes == want,
            ".{ext}: {} bytes, not {}",
            bytes.len(),
            want.len()
        );
    }
    assert!(protocol::export(&p, "gif").is_err());
    assert!(protocol::export(&program("lsystem A {"), "svg").is_err());
    // The page's drawing of a 3D program in that view is `--view`'s.
    let reply = protocol::run(&p, rel);
    assert!(reply.is_3d);
    assert_eq!(
        reply.svg.as_deref(),
        Some(cli_svg(&root().join(rel), &["--view", "60,10"]).as_str())
    );
    let scene = protocol::export(&program(&read("lang-examples/palm.lsy")), "svg").expect("svg");
    assert_eq!(
        String::from_utf8_lossy(&scene),
        cli_svg(&root().join("lang-examples/palm.lsy"), &["--guides"])
    );
}

#[test]
fn a_drag_of_a_vertex_that_does_not_exist_is_an_error() {
    let p = program(&read("lang-examples/palm.lsy"));
    let mut session = DragSession::new(&p).expect("a scene");
    let d = Drag {
        program: p.clone(),
        vertex: "trunk9.v2".to_string(),
        x: 0.0,
        y: 0.0,
        pins: Vec::new(),
        ..Drag::default()
    };
    let e = session.drag(&d, "palm.lsy").expect_err("no such guide");
    assert!(e.contains("trunk9"), "{e}");
    assert!(DragSession::new(&program("lsystem A { axiom F; }")).is_err());
}

#[test]
fn a_slider_writes_its_constant_through_the_formatter() {
    let text = read("lang-examples/monopodial-tree.lsy");
    let out = protocol::set_constant(&text, "r2", 0.75).expect("writes");
    assert!(out.contains("const r2 = 0.75; // contraction ratio for branches"));
    assert!(out.contains("// ABOP fig. 2.6"));
    let fe = lsyc::frontend::run(&out, Vec::new(), &[]);
    assert!(!fe.has_errors());
    assert_eq!(lsyc::fmt::format_file(&fe.file), out, "canonical");
    assert!(protocol::set_constant(&text, "nope", 1.0).is_none());
    assert!(protocol::set_constant("const a = ;", "a", 1.0).is_none());
}

#[test]
fn the_derived_string_of_a_step() {
    let mut p = program("lsystem A { derive 5; axiom F; F -> F+F; }");
    p.step = Some(2);
    let (text, cut) = protocol::derived_string(&p).expect("runs");
    assert_eq!(text.trim(), "F+F+F+F");
    assert!(!cut);
    p.step = Some(18);
    let (text, cut) = protocol::derived_string(&p).expect("runs");
    assert!(cut);
    assert_eq!(text.len(), protocol::STRING_LIMIT);
}

// ---- the server ----

struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(file: &Path) -> Server {
    let mut child = lsyc()
        .arg("studio")
        .arg(file)
        .args(["--port", "0", "--no-open"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let mut line = String::new();
    let stdout = child.stdout.take().expect("stdout");
    BufReader::new(stdout).read_line(&mut line).expect("a line");
    let rest = line
        .trim_end()
        .strip_prefix("lsyc studio: http://127.0.0.1:")
        .unwrap_or_else(|| panic!("first line: {line:?}"));
    let port: u16 = rest
        .strip_suffix('/')
        .expect("ends in /")
        .parse()
        .expect("a port");
    assert_ne!(port, 0);
    Server { child, port }
}

/// One HTTP request as the page sends it; returns the status and the body.
fn http(port: u16, method: &str, path: &str, body: &str) -> (u16, String) {
    let headers = format!(
        "Host: 127.0.0.1:{port}\r\nOrigin: http://127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
    );
    raw(port, method, path, &headers, body)
}

/// One HTTP/1.0 request with the given header lines.
fn raw(port: u16, method: &str, path: &str, headers: &str, body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connects");
    write!(
        s,
        "{method} {path} HTTP/1.0\r\n{headers}Connection: close\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .expect("sends");
    let mut out = String::new();
    s.read_to_string(&mut out).expect("reads");
    let status = out
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("a status");
    let body = out
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    (status, body)
}

fn post(port: u16, path: &str, body: &Value) -> Value {
    let (status, text) = http(port, "POST", path, &body.to_string());
    assert_eq!(status, 200, "{text}");
    serde_json::from_str(&text).expect("json")
}

fn scratch(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join(name);
    std::fs::copy(root().join("lang-examples").join(name), &file).expect("copies");
    (dir, file)
}

#[test]
fn the_server_serves_the_page_and_runs_programs() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    let (status, page) = http(s.port, "GET", "/", "");
    assert_eq!(status, 200);
    for hook in [
        "data-role=\"editor\"",
        "data-role=\"drawing\"",
        "data-role=\"diagnostics\"",
        "data-role=\"step\"",
        "data-role=\"save\"",
        "/studio.js",
    ] {
        assert!(page.contains(hook), "{hook}");
    }
    let (status, js) = http(s.port, "GET", "/studio.js", "");
    assert_eq!(status, 200);
    assert!(js.contains("lsycStudio"));
    assert_eq!(http(s.port, "GET", "/nothing", "").0, 404);
    let f: Value = serde_json::from_str(&http(s.port, "GET", "/api/file", "").1).expect("json");
    assert_eq!(f["text"], std::fs::read_to_string(&file).expect("reads"));
    let r = post(
        s.port,
        "/api/run",
        &json!({ "seq": 1, "source": f["text"] }),
    );
    assert_eq!(r["seq"], 1);
    assert_eq!(r["ok"], true);
    assert!(r["svg"].as_str().is_some_and(|t| t.starts_with("<?xml")));
    let r = post(
        s.port,
        "/api/run",
        &json!({ "seq": 2, "source": "lsystem {" }),
    );
    assert_eq!(r["ok"], false);
    assert!(r["diagnostics"][0]["code"].as_str().is_some());
    // The studio's module limit: far below `lsyc run`'s.
    let big = "lsystem A { derive 22; axiom F; F -> FF; }";
    let r = post(s.port, "/api/run", &json!({ "seq": 3, "source": big }));
    assert_eq!(r["ok"], false);
    assert_eq!(r["diagnostics"][0]["code"], "E0903");
    let r = post(s.port, "/api/run", &json!({ "source": 3 }));
    assert_eq!(r["ok"], false);
    assert!(
        r["error"]
            .as_str()
            .is_some_and(|e| e.contains("does not understand"))
    );
}

#[test]
fn a_newer_run_supersedes_an_older_one() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    // A run long enough in any build that the newer request arrives while
    // it works (a million steps of a hundred modules, over a second in a
    // release build; the newer request stops it).
    let slow = "lsystem A { derive 1000000; axiom B; B -> C C C C C C C C C C; \
                C -> A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0); A(x) -> A(x + 1); }";
    let port = s.port;
    let first =
        std::thread::spawn(move || post(port, "/api/run", &json!({ "seq": 10, "source": slow })));
    std::thread::sleep(std::time::Duration::from_millis(300));
    let second = post(
        port,
        "/api/run",
        &json!({ "seq": 11, "source": "lsystem A { axiom F; }" }),
    );
    let first = first.join().expect("answers");
    assert_eq!(first["superseded"], true, "{first}");
    assert_eq!(second["seq"], 11);
    assert_eq!(second["ok"], true);
}

#[test]
fn a_newer_edit_stops_a_run_in_progress() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    // A million cheap steps of a hundred modules: over a second in a
    // release build, many minutes in a debug build if left to run.
    let slow = "lsystem A {\n    derive 1000000;\n    axiom B;\n    B -> C C C C C C C C C C;\n    C -> A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0);\n    A(x) -> A(x + 1);\n}\n";
    let port = s.port;
    let started = std::time::Instant::now();
    let first =
        std::thread::spawn(move || post(port, "/api/run", &json!({ "seq": 20, "source": slow })));
    std::thread::sleep(std::time::Duration::from_millis(500));
    let second = post(
        port,
        "/api/run",
        &json!({ "seq": 21, "source": "lsystem A { axiom F; }" }),
    );
    let first = first.join().expect("answers");
    let took = started.elapsed();
    assert_eq!(first["superseded"], true, "{first}");
    assert_eq!(second["seq"], 21);
    assert_eq!(second["ok"], true, "{second}");
    assert!(
        took < std::time::Duration::from_secs(20),
        "the old run was stopped, not waited for: {took:?}"
    );
    // The run stops between steps with E0912 when the flag is set.
    static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);
    let p = Program {
        cancel: protocol::Cancel(Some(&STOP)),
        ..program(slow)
    };
    let reply = protocol::run(&p, "slow.lsy");
    assert!(!reply.ok);
    assert_eq!(
        reply.diagnostics[0]["code"], "E0912",
        "{:?}",
        reply.diagnostics
    );
}

#[test]
fn save_writes_the_file_atomically() {
    let (dir, file) = scratch("palm.lsy");
    let s = serve(&file);
    let text = std::fs::read_to_string(&file).expect("reads") + "\n// saved\n";
    let r = post(s.port, "/api/save", &json!({ "text": text }));
    assert_eq!(r["ok"], true);
    assert_eq!(std::fs::read_to_string(&file).expect("reads"), text);
    let f: Value = serde_json::from_str(&http(s.port, "GET", "/api/file", "").1).expect("json");
    assert_eq!(f["version"], r["version"], "the page knows its own save");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("lists")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["palm.lsy"], "no temporary file left");
}

#[test]
fn other_sites_cannot_use_the_server() {
    let (_dir, file) = scratch("palm.lsy");
    let before = std::fs::read_to_string(&file).expect("reads");
    let s = serve(&file);
    let p = s.port;
    let save = json!({ "text": "stolen" }).to_string();
    let own = format!("Host: 127.0.0.1:{p}\r\n");
    // Another site's form (text/plain, no preflight), another site's script,
    // a rebound DNS name.
    let attempts = [
        format!("{own}Origin: http://evil.example\r\nContent-Type: text/plain\r\n"),
        format!("{own}Origin: http://evil.example\r\nContent-Type: application/json\r\n"),
        format!("{own}Content-Type: text/plain\r\n"),
        "Host: evil.example\r\nContent-Type: application/json\r\n".to_string(),
    ];
    for headers in &attempts {
        let (status, _) = raw(p, "POST", "/api/save", headers, &save);
        assert_eq!(status, 403, "{headers}");
    }
    let (status, _) = raw(p, "GET", "/api/file", "Host: evil.example:80\r\n", "");
    assert_eq!(status, 403);
    assert_eq!(std::fs::read_to_string(&file).expect("reads"), before);
    // The page itself (its own host, no Origin on a GET).
    assert_eq!(raw(p, "GET", "/", &own, "").0, 200);
    assert_eq!(
        raw(p, "GET", "/", &format!("Host: localhost:{p}\r\n"), "").0,
        200
    );
}

#[test]
fn a_port_in_use_is_a_clear_error() {
    let (_dir, file) = scratch("palm.lsy");
    let s = serve(&file);
    let out = lsyc()
        .arg("studio")
        .arg(&file)
        .args(["--port", &s.port.to_string(), "--no-open"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot listen on 127.0.0.1"), "{err}");
}

// ---- the bundle and the page ----

/// The hash `web/build.mjs` writes (FNV-1a over the sources in path order).
fn source_hash(web: &Path) -> String {
    fn walk(dir: &Path, web: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).expect("lists").flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, web, out);
            } else {
                let rel = p.strip_prefix(web).expect("under web");
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let mut files = vec!["build.mjs".to_string(), "package-lock.json".to_string()];
    walk(&web.join("src"), web, &mut files);
    files.sort();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for f in &files {
        eat(f.as_bytes());
        eat(&[0]);
        eat(&std::fs::read(web.join(f)).expect("reads"));
        eat(&[0]);
    }
    format!("{h:016x}")
}

#[test]
fn the_committed_bundle_was_built_from_the_sources() {
    let web = root().join("web");
    assert_eq!(
        lsyc::studio::assets::SOURCE_HASH.trim(),
        source_hash(&web),
        "web/dist is stale: run `npm ci && npm run build` in web/ and commit web/dist"
    );
    for f in ["index.html", "studio.css"] {
        assert_eq!(
            std::fs::read(web.join("src").join(f)).expect("reads"),
            std::fs::read(web.join("dist").join(f)).expect("reads"),
            "web/dist/{f} is stale"
        );
    }
}

/// Runs `cmd`, failing the test with `why` if it cannot.
fn must(cmd: &mut Command, why: &str) {
    match cmd.status() {
        Ok(s) if s.success() => {}
        other => panic!("{why}: {cmd:?} gave {other:?}"),
    }
}

/// The page in headless Chromium (tests/browser/studio.mjs): a gallery
/// program typed, broken, fixed, slid, stepped, saved and reloaded; the palm
/// scene's trunk dragged and saved; no console errors. Installs Chromium and
/// the pinned playwright-core when they are missing.
#[test]
fn studio_in_a_browser() {
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".to_string());
    if !Path::new(&chromium).exists() {
        must(
            Command::new("apt-get").args(["install", "-y", "chromium"]),
            "Chromium is missing and `apt-get install -y chromium` failed (the browser tests need it; set CHROMIUM to another binary)",
        );
    }
    assert!(Path::new(&chromium).exists(), "no Chromium at {chromium}");
    let browser = root().join("tests/browser");
    if !browser.join("node_modules/playwright-core").exists() {
        must(
            Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund"])
                .current_dir(&browser),
            "`npm ci` in tests/browser failed (the browser tests need node, npm and the registry)",
        );
    }
    let dir = tempfile::tempdir().expect("tempdir");
    for f in ["monopodial-tree.lsy", "palm.lsy", "tree.lsy"] {
        std::fs::copy(root().join("lang-examples").join(f), dir.path().join(f)).expect("copies");
    }
    let out = Command::new("node")
        .arg("studio.mjs")
        .arg(env!("CARGO_BIN_EXE_lsyc"))
        .arg(dir.path())
        .current_dir(&browser)
        .env("CHROMIUM", &chromium)
        .output()
        .expect("node runs (the browser tests need node)");
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "the browser tests failed:\n{log}");
    assert!(log.contains("ok: no console errors"), "{log}");
    eprintln!("{log}");
    let shots = [
        "gallery.png",
        "gallery-step.png",
        "palm.png",
        "tree.png",
        "studio-hover.png",
    ];
    for shot in shots {
        let len = std::fs::metadata(dir.path().join(shot)).map_or(0, |m| m.len());
        assert!(len > 10_000, "screenshot {shot}: {len} bytes");
    }
    if let Ok(keep) = std::env::var("LSYC_STUDIO_SCREENSHOTS") {
        for shot in shots {
            let _ = std::fs::copy(dir.path().join(shot), Path::new(&keep).join(shot));
        }
    }
}
