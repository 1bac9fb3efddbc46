//! `lsyc lsp` under stress: a 20 MB document (a diagnostic, not an abort),
//! two dozen requests at once on a large document (answered from its one
//! analysis, with the server's memory measured), and `$/cancelRequest`.

use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(120);
const URI: &str = "file:///big.lsy";

struct Client {
    child: Child,
    stdin: ChildStdin,
    rx: Receiver<Value>,
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn read_frame(r: &mut impl BufRead) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if r.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length: ") {
            length = v.parse().ok();
        }
    }
    let mut body = vec![0; length?];
    r.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

impl Client {
    fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_lsyc"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start lsyc lsp");
        let stdin = child.stdin.take().expect("stdin");
        let stdout = child.stdout.take().expect("stdout");
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            while let Some(v) = read_frame(&mut r) {
                if tx.send(v).is_err() {
                    return;
                }
            }
        });
        let mut c = Client { child, stdin, rx };
        c.send(&json!({"jsonrpc": "2.0", "id": 0, "method": "initialize", "params": {"capabilities": {}}}));
        c.until(|m| m["id"] == 0);
        c.send(&json!({"jsonrpc": "2.0", "method": "initialized", "params": {}}));
        c
    }

    fn send(&mut self, v: &Value) {
        let body = v.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("write");
        self.stdin.flush().expect("flush");
    }

    /// The next message that `want` accepts (others are dropped).
    fn until(&mut self, want: impl Fn(&Value) -> bool) -> Value {
        loop {
            let m = self
                .rx
                .recv_timeout(WAIT)
                .unwrap_or_else(|e| panic!("lsyc lsp did not answer within {WAIT:?}: {e}"));
            if want(&m) {
                return m;
            }
        }
    }

    fn open(&mut self, text: &str) -> Value {
        self.send(
            &json!({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
            "textDocument": {"uri": URI, "languageId": "lsy", "version": 1, "text": text}}}),
        );
        self.until(|m| m["method"] == "textDocument/publishDiagnostics")
    }

    fn request(&mut self, id: i64, method: &str, params: Value) {
        self.send(&json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
    }

    fn peak_mib(&self) -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id()))
            .unwrap_or_default();
        status
            .lines()
            .find(|l| l.starts_with("VmHWM:"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<u64>().ok())
            .map_or(0, |kb| kb / 1024)
    }
}

/// A program of about `bytes` bytes: one long axiom (the densest text to analyse).
fn big_program(bytes: usize) -> String {
    let mut text = String::from("const r2 = 0.6;\nlsystem A {\n    axiom ");
    while text.len() < bytes {
        text.push_str("F(r2) +(2) ");
    }
    text.push_str(";\n}\n");
    text
}

fn hover_at(line: u32, character: u32) -> Value {
    json!({"textDocument": {"uri": URI}, "position": {"line": line, "character": character}})
}

#[test]
fn a_20_mb_document_gets_a_diagnostic_not_an_abort() {
    let mut c = Client::start();
    let diags = c.open(&big_program(20 << 20));
    assert_eq!(
        diags["params"]["diagnostics"][0]["code"], "E0002",
        "{diags}"
    );
    let message = diags["params"]["diagnostics"][0]["message"]
        .as_str()
        .unwrap_or("");
    assert!(message.contains("MiB"), "{message}");
    c.request(1, "textDocument/hover", hover_at(2, 12));
    let hover = c.until(|m| m["id"] == 1);
    assert_eq!(hover["result"], Value::Null, "{hover}");
    let peak = c.peak_mib();
    eprintln!("a 20 MB document: peak {peak} MiB");
    assert!(peak < 512, "peak memory {peak} MiB");
}

#[test]
fn two_dozen_requests_share_one_analysis() {
    let mut c = Client::start();
    let diags = c.open(&big_program(1_500_000));
    assert_eq!(diags["params"]["diagnostics"], json!([]), "{diags}");
    for id in 1..=24 {
        let method = if id % 3 == 0 {
            "textDocument/completion"
        } else {
            "textDocument/hover"
        };
        c.request(id, method, hover_at(2, 12));
    }
    for id in 1..=24 {
        let m = c.until(|m| m["id"] == id);
        assert!(m["error"].is_null(), "{m}");
    }
    let peak = c.peak_mib();
    eprintln!("24 requests on a 1.5 MB document: peak {peak} MiB");
    assert!(peak < 1024, "peak memory {peak} MiB");
}

#[test]
fn cancelled_requests_are_not_answered_with_work() {
    let mut c = Client::start();
    c.open(&big_program(1_500_000));
    // A slow request first (formatting the whole document), then hovers,
    // half of which the client cancels while the first is being answered.
    c.request(
        1,
        "textDocument/formatting",
        json!({"textDocument": {"uri": URI},
        "options": {"tabSize": 4, "insertSpaces": true}}),
    );
    for id in 2..=11 {
        c.request(id, "textDocument/hover", hover_at(2, 12));
    }
    for id in (2..=11).filter(|i| i % 2 == 0) {
        c.send(&json!({"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": id}}));
    }
    let first = c.until(|m| m["id"] == 1);
    assert!(first["error"].is_null(), "{first}");
    for id in 2..=11 {
        let m = c.until(|m| m["id"] == id);
        if id % 2 == 0 {
            assert_eq!(m["error"]["code"], -32800, "{m}");
        } else {
            assert!(m["result"]["contents"].is_object(), "{m}");
        }
    }
}

#[test]
fn a_request_cancelled_while_it_runs_is_answered_cancelled() {
    let mut c = Client::start();
    c.open(&big_program(1_500_000));
    let formatting = || {
        json!({"textDocument": {"uri": URI},
        "options": {"tabSize": 4, "insertSpaces": true}})
    };
    // Formatting the whole document, not cancelled: it answers, in `took`.
    let start = std::time::Instant::now();
    c.request(1, "textDocument/formatting", formatting());
    let first = c.until(|m| m["id"] == 1);
    assert!(first["error"].is_null(), "{first}");
    let took = start.elapsed();
    eprintln!("formatting a 1.5 MB document: {took:?}");
    // Again, cancelled a quarter of the way through. Nothing else is queued,
    // so the server is answering it when the cancellation arrives: only the
    // request being answered can be stopped.
    c.request(2, "textDocument/formatting", formatting());
    std::thread::sleep(took / 4);
    c.send(&json!({"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": 2}}));
    let m = c.until(|m| m["id"] == 2);
    // (The document itself is not printed: 1.5 MB.)
    let answer = if m["result"].is_null() {
        "no result"
    } else {
        "the formatting edits"
    };
    assert_eq!(m["error"]["code"], -32800, "answered {answer}");
    assert!(m["result"].is_null(), "answered {answer}");
    // A cancellation for a request already answered changes nothing, and
    // the server goes on answering.
    c.send(&json!({"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": 1}}));
    c.request(3, "textDocument/hover", hover_at(2, 12));
    let m = c.until(|m| m["id"] == 3);
    assert!(m["result"]["contents"].is_object(), "{m}");
}
