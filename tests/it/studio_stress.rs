//! `lsyc studio` under stress, over real sockets: a thousand idle
//! connections with the common 1024 open-file limit, a never-ending export
//! stopped by an edit, pages that reload or open a second tab, two dozen
//! concurrent hovers on a large program with the server's memory measured,
//! a save refused because the file changed on disk, and clients that leave
//! mid-run (their jobs stop and free the workers).

use crate::support::root;
use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A program whose derivation never ends in practice: a million steps of a
/// string that keeps its hundred modules.
const NEVER_ENDING: &str = "lsystem A {\n    derive 1000000;\n    axiom B;\n    B -> C C C C C C C C C C;\n    C -> A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0);\n    A(x) -> A(x + 1);\n}\n";

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

impl Server {
    /// The server's peak resident memory so far, in MiB (Linux's `VmHWM`).
    fn peak_mib(&self) -> Option<u64> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb / 1024)
    }

    fn alive(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

/// `lsyc studio FILE --port 0 --no-open` with at most 1024 open files (the
/// common default), as a user's shell starts it.
fn serve(file: &Path) -> Server {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("ulimit -n 1024 && exec \"$0\" studio \"$1\" --port 0 --no-open")
        .arg(env!("CARGO_BIN_EXE_lsyc"))
        .arg(file)
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let mut line = String::new();
    let stdout = child.stdout.take().expect("stdout");
    BufReader::new(stdout).read_line(&mut line).expect("a line");
    let port = line
        .trim_end()
        .strip_prefix("lsyc studio: http://127.0.0.1:")
        .and_then(|r| r.strip_suffix('/'))
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("first line: {line:?}"));
    Server { child, port }
}

fn scratch(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join(name);
    std::fs::copy(root().join("lang-examples").join(name), &file).expect("copies");
    (dir, file)
}

/// One request as the page sends it, answered within `within`: the status
/// and the body.
fn request(port: u16, method: &str, path: &str, body: &str, within: Duration) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connects");
    s.set_read_timeout(Some(within)).expect("timeout");
    // A server that refuses the request (too large) answers before reading
    // the body and closes: the rest of the body is then not sent.
    let _ = write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: http://127.0.0.1:{port}\r\n\
         Content-Type: application/json\r\nConnection: close\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    );
    let mut out = Vec::new();
    s.read_to_end(&mut out)
        .unwrap_or_else(|e| panic!("{path}: no answer within {within:?}: {e}"));
    let split = out
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| {
            panic!(
                "{path}: not an HTTP answer: {:?}",
                String::from_utf8_lossy(&out)
            )
        });
    let head = String::from_utf8_lossy(&out[..split]).into_owned();
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("a status");
    let mut body = out[split + 4..].to_vec();
    if head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        body = unchunk(&body);
    }
    (status, body)
}

/// The body of a chunked answer.
fn unchunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let Some(eol) = b.windows(2).position(|w| w == b"\r\n") else {
            return out;
        };
        let size =
            usize::from_str_radix(String::from_utf8_lossy(&b[..eol]).trim(), 16).unwrap_or(0);
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + size]);
        b = &b[eol + 2 + size + 2..];
    }
}

fn post(port: u16, path: &str, body: &Value, within: Duration) -> (u16, Value) {
    let (status, bytes) = request(port, "POST", path, &body.to_string(), within);
    let v = serde_json::from_slice(&bytes)
        .unwrap_or_else(|_| panic!("{path}: not JSON: {}", String::from_utf8_lossy(&bytes)));
    (status, v)
}

/// Raises this process's soft limit on open files to at least `n` (within
/// the hard limit), so that the test itself can hold its idle connections.
#[allow(unsafe_code)]
fn allow_open_files(n: u64) {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit and setrlimit read and write the one struct given.
    unsafe {
        if libc::getrlimit(libc::RLIMIT_NOFILE, &mut lim) == 0 && lim.rlim_cur < n {
            lim.rlim_cur = n.min(lim.rlim_max);
            libc::setrlimit(libc::RLIMIT_NOFILE, &lim);
        }
    }
}

const SOON: Duration = Duration::from_secs(5);
const LONG: Duration = Duration::from_secs(60);

#[test]
fn a_thousand_idle_connections_do_not_lock_the_page_out() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let mut s = serve(&file);
    allow_open_files(1200);
    let mut idle = Vec::new();
    for _ in 0..1000 {
        // The kernel completes a connection before the server sees it: a
        // refused one would only fail later, on use.
        idle.push(TcpStream::connect(("127.0.0.1", s.port)).expect("connects"));
    }
    let started = Instant::now();
    let (status, file_reply) = request(s.port, "GET", "/api/file", "", SOON);
    assert_eq!(status, 200);
    let f: Value = serde_json::from_slice(&file_reply).expect("json");
    let run = json!({ "session": "a", "seq": 1, "source": f["text"] });
    let (status, reply) = post(s.port, "/api/run", &run, SOON);
    assert_eq!(status, 200);
    assert_eq!(reply["ok"], true, "{reply}");
    let took = started.elapsed();
    eprintln!("after 1,000 idle connections: file and run answered in {took:?}");
    assert!(took < SOON, "{took:?}");
    assert!(s.alive(), "the server is still running");
    drop(idle);
}

#[test]
fn a_never_ending_export_is_stopped_by_an_edit() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    let port = s.port;
    let started = Instant::now();
    let export = std::thread::spawn(move || {
        let body = json!({ "session": "p", "source": NEVER_ENDING, "format": "svg" });
        post(port, "/api/export", &body, LONG)
    });
    // Another page's run is not held up by it.
    std::thread::sleep(Duration::from_millis(500));
    let other = json!({ "session": "q", "seq": 1, "source": "lsystem A { axiom F; }" });
    let (_, reply) = post(port, "/api/run", &other, SOON);
    assert_eq!(reply["ok"], true, "{reply}");
    // The edit of the page that asked for the export stops it.
    let edit = json!({ "session": "p", "seq": 1, "source": "lsystem A { axiom F; }" });
    let (_, reply) = post(port, "/api/run", &edit, SOON);
    assert_eq!(reply["ok"], true, "{reply}");
    let (status, stopped) = export.join().expect("answers");
    assert_eq!(status, 409, "{stopped}");
    assert!(
        stopped["error"]
            .as_str()
            .is_some_and(|e| e.contains("stopped")),
        "{stopped}"
    );
    let took = started.elapsed();
    eprintln!(
        "a never-ending export stopped by an edit: answered after {took:?} (the edit came at 0.5 s)"
    );
    assert!(took < Duration::from_secs(20), "{took:?}");
    // An export over the studio's limits says why, for the page to show.
    let big = json!({ "session": "p", "source": "lsystem A { derive 22; axiom F; F -> FF; }", "format": "png" });
    let (status, reply) = post(port, "/api/export", &big, LONG);
    assert_eq!(status, 400);
    assert!(
        reply["error"]
            .as_str()
            .is_some_and(|e| e.contains("modules")),
        "{reply}"
    );
}

#[test]
fn a_never_ending_string_and_drag_are_stopped_by_newer_requests() {
    let (_dir, file) = scratch("palm.lsy");
    let s = serve(&file);
    let port = s.port;
    let string = std::thread::spawn(move || {
        let body = json!({ "session": "p", "source": NEVER_ENDING });
        post(port, "/api/string", &body, LONG)
    });
    std::thread::sleep(Duration::from_millis(500));
    let newer = json!({ "session": "p", "source": "lsystem A { axiom F; }" });
    let (_, reply) = post(port, "/api/string", &newer, SOON);
    assert_eq!(reply["text"].as_str().map(str::trim), Some("F"), "{reply}");
    let (_, stopped) = string.join().expect("answers");
    assert_eq!(stopped["superseded"], true, "{stopped}");

    // A drag of a scene whose systems never end, then an edit.
    let palm = std::fs::read_to_string(&file).expect("reads");
    let endless = palm.replacen("derive ", "derive 1000000; // was ", 1);
    let drag = json!({ "session": "d", "seq": 1, "source": endless, "vertex": "trunk3.v2", "x": 1.0, "y": 1.0 });
    let dragging = std::thread::spawn(move || post(port, "/api/drag", &drag, LONG));
    std::thread::sleep(Duration::from_millis(500));
    let edit = json!({ "session": "d", "seq": 2, "source": palm });
    let (_, reply) = post(port, "/api/run", &edit, LONG);
    assert_eq!(reply["ok"], true, "{reply}");
    let (_, dragged) = dragging.join().expect("answers");
    // Stopped by the edit, or by the scene's step limit before the edit was
    // sent (a quick machine reaches 100,000 steps within the 500 ms).
    let done_before = dragged["stats"]["total_ms"]
        .as_f64()
        .is_some_and(|ms| ms < 500.0);
    assert!(
        dragged["superseded"] == true || dragged["ok"] == false || done_before,
        "{dragged}"
    );
}

#[test]
fn a_reloaded_page_and_a_second_tab_draw() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    let source = std::fs::read_to_string(&file).expect("reads");
    let run = |session: &str, seq: u64| {
        let body = json!({ "session": session, "seq": seq, "source": source });
        post(s.port, "/api/run", &body, LONG).1
    };
    for seq in 1..=5 {
        assert_eq!(run("first", seq)["ok"], true);
    }
    // A reload (a new session) and a second tab start from 1 again.
    let reloaded = run("reloaded", 1);
    assert_eq!(reloaded["ok"], true, "{reloaded}");
    assert_eq!(reloaded["seq"], 1);
    assert_eq!(run("tab", 1)["ok"], true);
    // Within a session an older request is still superseded.
    assert_eq!(run("first", 3)["superseded"], true);
}

#[test]
fn two_dozen_concurrent_hovers_share_one_analysis() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    // A program of 1.5 MB (a long axiom, the densest text to analyse).
    let mut big = String::from("const r2 = 0.6;\nlsystem A {\n    axiom ");
    while big.len() < 1_500_000 {
        big.push_str("F(r2) +(2) ");
    }
    big.push_str(";\n}\n");
    let at = big.find("r2").expect("a name") + 1;
    let port = s.port;
    let started = Instant::now();
    let threads: Vec<_> = (0..24)
        .map(|i| {
            let body = if i % 2 == 0 {
                json!({ "session": "h", "source": big, "at": at })
            } else {
                json!({ "session": "h", "source": big, "at": at + 7 })
            };
            let path = if i % 3 == 0 {
                "/api/complete"
            } else {
                "/api/hover"
            };
            std::thread::spawn(move || post(port, path, &body, LONG))
        })
        .collect();
    for t in threads {
        let (status, reply) = t.join().expect("answers");
        assert_eq!(status, 200);
        assert_eq!(reply["ok"], true, "{reply}");
    }
    let took = started.elapsed();
    let peak = s.peak_mib().unwrap_or(0);
    eprintln!("24 hovers of a 1.5 MB program: {took:?}, peak {peak} MiB");
    assert!(peak < 1024, "the server's peak memory: {peak} MiB");
    // A document over the limit gets no analysis, and no failure.
    let over = "F ".repeat(3 << 19);
    let (status, reply) = post(
        port,
        "/api/hover",
        &json!({ "source": over, "at": 3 }),
        LONG,
    );
    assert_eq!((status, &reply["hover"]), (200, &Value::Null), "{reply}");
    // A body over the server's limit is refused before it is read.
    let mut c = TcpStream::connect(("127.0.0.1", port)).expect("connects");
    c.set_read_timeout(Some(SOON)).expect("timeout");
    write!(
        c,
        "POST /api/hover HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\n\r\n",
        20 << 20
    )
    .expect("sends");
    let mut answer = String::new();
    let _ = c.read_to_string(&mut answer);
    assert!(answer.starts_with("HTTP/1.1 413"), "{answer}");
    let too_big = "F ".repeat(3 << 19);
    let (_, reply) = post(
        port,
        "/api/run",
        &json!({ "seq": 1, "source": too_big }),
        LONG,
    );
    assert_eq!(reply["diagnostics"][0]["code"], "E0002", "{reply}");
}

#[test]
fn save_refuses_to_overwrite_a_file_changed_on_disk() {
    let (_dir, file) = scratch("palm.lsy");
    let s = serve(&file);
    let (_, loaded) = request(s.port, "GET", "/api/file", "", SOON);
    let loaded: Value = serde_json::from_slice(&loaded).expect("json");
    let theirs = "// another editor's text\n";
    std::fs::write(&file, theirs).expect("writes");
    let mine = json!({ "text": "// mine\n", "base": loaded["version"] });
    let (_, reply) = post(s.port, "/api/save", &mine, SOON);
    assert_eq!(reply["ok"], false, "{reply}");
    assert_eq!(reply["conflict"], true);
    assert!(
        reply["error"]
            .as_str()
            .is_some_and(|e| e.contains("changed on disk")),
        "{reply}"
    );
    assert_eq!(reply["disk"]["text"], theirs);
    assert_eq!(std::fs::read_to_string(&file).expect("reads"), theirs);
    // Having seen that version, the page may write over it.
    let knowingly = json!({ "text": "// mine\n", "base": reply["disk"]["version"] });
    let (_, reply) = post(s.port, "/api/save", &knowingly, SOON);
    assert_eq!(reply["ok"], true, "{reply}");
    assert_eq!(std::fs::read_to_string(&file).expect("reads"), "// mine\n");
}

#[test]
fn a_slow_client_is_closed() {
    let (_dir, file) = scratch("palm.lsy");
    let mut s = serve(&file);
    let mut c = TcpStream::connect(("127.0.0.1", s.port)).expect("connects");
    c.set_read_timeout(Some(Duration::from_millis(900)))
        .expect("timeout");
    let started = Instant::now();
    let _ = write!(c, "GET / HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n", s.port);
    // One byte of a header a second, never finishing the request.
    let closed = loop {
        if started.elapsed() > Duration::from_secs(40) {
            break false;
        }
        let mut buf = [0; 512];
        match c.read(&mut buf) {
            Ok(0) => break true,
            Ok(_) => {} // an error status before closing
            Err(e)
                if e.kind() == std::io::ErrorKind::WouldBlock
                    || e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(_) => break true,
        }
        if c.write_all(b"X").is_err() {
            break true;
        }
    };
    let took = started.elapsed();
    eprintln!("a client sending its headers a byte a second: closed after {took:?}");
    assert!(closed, "still open after {took:?}");
    assert!(s.alive());
    let (status, _) = request(s.port, "GET", "/api/file", "", SOON);
    assert_eq!(status, 200);
}

#[test]
fn a_client_gone_mid_run_stops_its_job() {
    let (_dir, file) = scratch("monopodial-tree.lsy");
    let s = serve(&file);
    let port = s.port;
    // More never-ending runs than the pool has workers (at most 4), each
    // from a page of its own (so none supersedes another), and each client
    // gone while its run is under way.
    let gone: Vec<TcpStream> = (0..6)
        .map(|i| {
            let body = json!({ "session": format!("gone{i}"), "seq": 1, "source": NEVER_ENDING })
                .to_string();
            let mut c = TcpStream::connect(("127.0.0.1", port)).expect("connects");
            write!(
                c,
                "POST /api/run HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: http://127.0.0.1:{port}\r\n\
                 Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
                body.len()
            )
            .expect("sends");
            c
        })
        .collect();
    std::thread::sleep(Duration::from_millis(1000));
    // Every worker is taken by a run that never ends: another page waits.
    let probe = json!({ "session": "probe", "seq": 1, "source": "lsystem A { axiom F; }" });
    let waiting = std::thread::spawn(move || {
        let started = Instant::now();
        let (_, reply) = post(port, "/api/run", &probe, LONG);
        (reply, started.elapsed())
    });
    std::thread::sleep(Duration::from_millis(1000));
    assert!(
        !waiting.is_finished(),
        "a run got a worker while all were busy"
    );
    let closed = Instant::now();
    for c in gone {
        let _ = c.shutdown(std::net::Shutdown::Both);
    }
    // The clients are gone, so are their jobs: the waiting page is answered.
    let (reply, _) = waiting.join().expect("answers");
    let took = closed.elapsed();
    eprintln!("six clients gone mid-run: the waiting run answered {took:?} later");
    assert_eq!(reply["ok"], true, "{reply}");
    assert!(took < SOON, "answered {took:?} after the clients left");
}
