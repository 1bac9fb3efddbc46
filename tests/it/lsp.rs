//! `lsyc lsp` driven by a scripted client: the built binary on pipes, JSON-RPC
//! with `Content-Length` framing, every wait bounded so that a hang fails the
//! test instead of stalling CI.

use crate::support::root;
use serde_json::{Value, json};
use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

const WAIT: Duration = Duration::from_secs(20);

struct Client {
    child: Child,
    stdin: ChildStdin,
    rx: Receiver<Value>,
    /// Notifications read while waiting for a response.
    pending: VecDeque<Value>,
    next_id: i64,
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
        Client {
            child,
            stdin,
            rx,
            pending: VecDeque::new(),
            next_id: 1,
        }
    }

    fn send_raw(&mut self, body: &[u8]) {
        write!(self.stdin, "Content-Length: {}\r\n\r\n", body.len()).expect("write");
        self.stdin.write_all(body).expect("write");
        self.stdin.flush().expect("flush");
    }

    fn send(&mut self, v: &Value) {
        self.send_raw(v.to_string().as_bytes());
    }

    fn recv(&mut self) -> Value {
        match self.rx.recv_timeout(WAIT) {
            Ok(v) => v,
            Err(RecvTimeoutError::Timeout) => {
                let _ = self.child.kill();
                panic!("lsyc lsp did not answer within {WAIT:?}")
            }
            Err(RecvTimeoutError::Disconnected) => panic!("lsyc lsp closed its output"),
        }
    }

    /// Sends a request and waits for its response (the whole message).
    fn request_raw(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(&json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let v = self.recv();
            if v.get("id") == Some(&json!(id)) {
                return v;
            }
            self.pending.push_back(v);
        }
    }

    /// A request's result; fails on an error response.
    fn request(&mut self, method: &str, params: Value) -> Value {
        let v = self.request_raw(method, params);
        assert!(v.get("error").is_none(), "{method}: {v}");
        v["result"].clone()
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    /// The next notification of `method`.
    fn notification(&mut self, method: &str) -> Value {
        if let Some(i) = self.pending.iter().position(|v| v["method"] == method) {
            return self.pending.remove(i).expect("present")["params"].clone();
        }
        loop {
            let v = self.recv();
            if v["method"] == method {
                return v["params"].clone();
            }
            self.pending.push_back(v);
        }
    }

    fn initialize(&mut self) -> Value {
        let r = self.request(
            "initialize",
            json!({"processId": null, "rootUri": null, "capabilities": {}}),
        );
        self.notify("initialized", json!({}));
        r
    }

    fn open(&mut self, uri: &str, text: &str) -> Value {
        self.notify(
            "textDocument/didOpen",
            json!({"textDocument": {"uri": uri, "languageId": "lsy", "version": 1, "text": text}}),
        );
        self.notification("textDocument/publishDiagnostics")
    }

    /// Waits for the process to end and returns its exit code.
    fn wait(mut self) -> Option<i32> {
        let start = Instant::now();
        loop {
            if let Some(s) = self.child.try_wait().expect("wait") {
                return s.code();
            }
            if start.elapsed() > WAIT {
                let _ = self.child.kill();
                panic!("lsyc lsp did not exit within {WAIT:?}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn read_frame(r: &mut impl BufRead) -> Option<Value> {
    let mut len = None;
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
            len = v.parse::<usize>().ok();
        }
    }
    let mut body = vec![0; len?];
    r.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

fn pos(text: &str, needle: &str, nth: usize) -> Value {
    let off = text
        .match_indices(needle)
        .nth(nth)
        .unwrap_or_else(|| panic!("`{needle}` #{nth} not in the text"))
        .0;
    position_of(text, off)
}

/// A byte offset as an LSP position (UTF-16 columns), computed independently
/// of the server.
fn position_of(text: &str, off: usize) -> Value {
    let before = &text[..off];
    let line = before.matches('\n').count();
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    let character: usize = before[start..].encode_utf16().count();
    json!({"line": line, "character": character})
}

fn offset_of(text: &str, p: &Value) -> usize {
    let line = p["line"].as_u64().expect("line") as usize;
    let ch = p["character"].as_u64().expect("character") as usize;
    let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
    let mut units = 0;
    for (i, c) in text[start..].char_indices() {
        if units >= ch || c == '\n' {
            return start + i;
        }
        units += c.len_utf16();
    }
    text.len()
}

/// Applies text edits (non-overlapping) to a text.
fn apply(text: &str, edits: &Value) -> String {
    let mut spans: Vec<(usize, usize, String)> = edits
        .as_array()
        .expect("edits")
        .iter()
        .map(|e| {
            (
                offset_of(text, &e["range"]["start"]),
                offset_of(text, &e["range"]["end"]),
                e["newText"].as_str().expect("newText").to_string(),
            )
        })
        .collect();
    spans.sort_by_key(|s| std::cmp::Reverse(s.0));
    let mut out = text.to_string();
    for (a, b, t) in spans {
        out.replace_range(a..b, &t);
    }
    out
}

/// Diagnostics as lines for a snapshot: `line:col-line:col severity code message`.
fn show_diagnostics(p: &Value) -> String {
    let mut out = String::new();
    for d in p["diagnostics"].as_array().expect("diagnostics") {
        let r = &d["range"];
        let sev = match d["severity"].as_u64() {
            Some(1) => "error",
            Some(2) => "warning",
            _ => "?",
        };
        out.push_str(&format!(
            "{}:{}-{}:{} {sev} {} {}\n",
            r["start"]["line"].as_u64().expect("l") + 1,
            r["start"]["character"].as_u64().expect("c") + 1,
            r["end"]["line"].as_u64().expect("l") + 1,
            r["end"]["character"].as_u64().expect("c") + 1,
            d["code"].as_str().unwrap_or("-"),
            d["message"].as_str().unwrap_or("").replace('\n', "\n    "),
        ));
        for rel in d["relatedInformation"].as_array().into_iter().flatten() {
            let r = &rel["location"]["range"];
            out.push_str(&format!(
                "    related {}:{}: {}\n",
                r["start"]["line"].as_u64().expect("l") + 1,
                r["start"]["character"].as_u64().expect("c") + 1,
                rel["message"].as_str().unwrap_or("")
            ));
        }
    }
    out
}

fn hover_text(v: &Value) -> String {
    v["contents"]["value"]
        .as_str()
        .unwrap_or_else(|| panic!("no hover: {v}"))
        .to_string()
}

fn gallery(name: &str) -> String {
    std::fs::read_to_string(root().join("lang-examples").join(name)).expect("gallery program")
}

#[test]
fn session_on_a_gallery_program() {
    let text = gallery("monopodial-tree.lsy");
    let uri = "file:///gallery/monopodial-tree.lsy";
    let mut c = Client::start();

    // Before initialize, a request is refused with the protocol's error.
    let early = c.request_raw("textDocument/hover", json!({}));
    assert_eq!(early["error"]["code"], -32002, "{early}");

    let init = c.initialize();
    let caps = &init["capabilities"];
    for cap in [
        "hoverProvider",
        "definitionProvider",
        "completionProvider",
        "documentSymbolProvider",
        "documentFormattingProvider",
        "renameProvider",
    ] {
        assert!(
            caps.get(cap).is_some_and(|v| !v.is_null()),
            "{cap} missing: {caps}"
        );
    }
    assert_eq!(init["serverInfo"]["name"], "lsyc");

    // A gallery program: no diagnostics.
    let d = c.open(uri, &text);
    assert_eq!(d["uri"], uri);
    assert_eq!(d["diagnostics"], json!([]), "{d}");

    // Hover: a constant's value and comment, a letter module, a parameter, a
    // turtle symbol.
    let doc = |p: Value| json!({"textDocument": {"uri": uri}, "position": p});
    let mut hovers = String::new();
    for (needle, nth, what) in [
        ("r2 ", 0, "constant at its declaration"),
        ("r2,", 0, "constant in a rule"),
        ("B(l", 0, "letter module"),
        ("l * r1", 0, "rule parameter"),
        ("&(a0)", 0, "turtle symbol"),
        ("$C", 0, "roll to horizontal"),
    ] {
        let h = c.request("textDocument/hover", doc(pos(&text, needle, nth)));
        hovers.push_str(&format!("--- {what} (`{needle}`)\n{}\n", hover_text(&h)));
    }
    insta::assert_snapshot!("lsp_hover_monopodial", hovers);

    // Definition: the constant's declaration, from its use in a rule.
    let def = c.request("textDocument/definition", doc(pos(&text, "r2,", 0)));
    assert_eq!(def["uri"], uri);
    assert_eq!(def["range"]["start"], pos(&text, "r2 =", 0), "{def}");
    // A letter module's "definition" is the rule that rewrites it.
    let def = c.request("textDocument/definition", doc(pos(&text, "C(l * r2", 0)));
    assert_eq!(def["range"]["start"], pos(&text, "C(l, w)", 0), "{def}");

    // Completion inside a rule: its parameters, the constants, the query
    // modules with their signatures, turtle symbols and keywords.
    let items = c.request("textDocument/completion", doc(pos(&text, "l * r2", 0)));
    let labels: Vec<&str> = items
        .as_array()
        .expect("items")
        .iter()
        .map(|i| i["label"].as_str().expect("label"))
        .collect();
    for want in [
        "l", "w", "r1", "wr", "A", "B", "?X", "?N_G", "+", "axiom", "sin",
    ] {
        assert!(
            labels.contains(&want),
            "completion lacks `{want}`: {labels:?}"
        );
    }
    let qx = items
        .as_array()
        .expect("items")
        .iter()
        .find(|i| i["label"] == "?X")
        .expect("?X");
    assert_eq!(qx["detail"], "?X(found, id, delta, …)");
    // After `?`, only query modules, replacing the `?` typed.
    let mut typing = text.clone();
    let at = typing.find("A(l * r1").expect("A");
    typing.insert_str(at, "?N");
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [{"text": typing}]}),
    );
    c.notification("textDocument/publishDiagnostics");
    let items = c.request("textDocument/completion", doc(position_of(&typing, at + 2)));
    let items = items.as_array().expect("items");
    assert!(
        items
            .iter()
            .all(|i| i["label"].as_str().is_some_and(|l| l.starts_with('?'))),
        "{items:?}"
    );
    assert_eq!(
        items[0]["textEdit"]["range"]["start"],
        position_of(&typing, at)
    );

    // Back to the program, then break it: diagnostics with codes on the right lines.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 3}, "contentChanges": [{"text": text}]}),
    );
    assert_eq!(
        c.notification("textDocument/publishDiagnostics")["diagnostics"],
        json!([])
    );
    let broken = text
        .replace("B(l * r2, w * wr)]/(d)", "B(l * r3, w * wr)]/(d)")
        .replace("C(l * r1, w * wr);\n    C", "C(l * r1);\n    C")
        + "const unused = 1;\n";
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 4}, "contentChanges": [{"text": broken}]}),
    );
    let d = c.notification("textDocument/publishDiagnostics");
    assert_eq!(d["version"], 4);
    insta::assert_snapshot!("lsp_diagnostics_broken", show_diagnostics(&d));

    // An incremental change: a syntax error typed into one line.
    let at = broken.find("axiom A(100, 10);").expect("axiom") + "axiom".len();
    let p = position_of(&broken, at);
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 5}, "contentChanges": [
            {"range": {"start": p, "end": p}, "text": " ="}
        ]}),
    );
    let d = c.notification("textDocument/publishDiagnostics");
    let ds = d["diagnostics"].as_array().expect("diagnostics");
    assert!(!ds.is_empty(), "{d}");
    assert_eq!(ds[0]["code"], "E0201", "{d}");
    assert_eq!(ds[0]["range"]["start"]["line"], p["line"], "{d}");

    // Back to the gallery program: symbols and rename.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 6}, "contentChanges": [{"text": text}]}),
    );
    c.notification("textDocument/publishDiagnostics");
    let symbols = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri}}),
    );
    insta::assert_snapshot!("lsp_symbols_monopodial", show_symbols(&symbols, 0));

    let prep = c.request("textDocument/prepareRename", doc(pos(&text, "r2,", 0)));
    assert_eq!(prep["placeholder"], "r2");
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(&text, "r2,", 0), "newName": "q2"}),
    );
    let renamed = apply(&text, &edit["changes"][uri]);
    // The declaration and its three uses; comments are left alone.
    assert_eq!(renamed.matches("q2").count(), 4, "{renamed}");
    assert_eq!(
        renamed.matches("r2").count(),
        text.matches("r2").count() - 4
    );
    assert!(renamed.contains("-D r2=0.9"), "{renamed}");
    assert_eq!(
        lsyc::frontend::run(&renamed, Vec::new(), &[])
            .diagnostics
            .len(),
        0
    );
    // A module (here a letter) across the file.
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(&text, "C(l * r2", 0), "newName": "K"}),
    );
    let renamed = apply(&text, &edit["changes"][uri]);
    assert_eq!(renamed.matches("K(").count(), text.matches("C(").count());
    // A rename that would let a parameter capture the constant is refused.
    let refused = c.request_raw(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(&text, "r2,", 0), "newName": "l"}),
    );
    assert!(refused.get("error").is_some(), "{refused}");
    let refused = c.request_raw(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(&text, "r2,", 0), "newName": "lsystem"}),
    );
    assert!(refused.get("error").is_some(), "{refused}");

    // Broken messages and unknown methods: protocol errors, and the server goes on.
    c.send_raw(b"{\"jsonrpc\": \"2.0\", \"id\": 99, \"method\"");
    let e = c.recv();
    assert_eq!(e["error"]["code"], -32700, "{e}");
    assert_eq!(e["id"], Value::Null);
    c.send_raw(b"[1, 2, 3]");
    assert_eq!(c.recv()["error"]["code"], -32600);
    let e = c.request_raw("lsyc/noSuchMethod", json!({}));
    assert_eq!(e["error"]["code"], -32601, "{e}");
    let e = c.request_raw("textDocument/hover", json!({"textDocument": 5}));
    assert_eq!(e["error"]["code"], -32602, "{e}");
    let e = c.request_raw("textDocument/hover", doc_of("file:///not/open.lsy"));
    assert!(e.get("error").is_some(), "{e}");
    // Still answering.
    let h = c.request("textDocument/hover", doc(pos(&text, "r2,", 0)));
    assert!(hover_text(&h).contains("const r2"));

    // Shutdown, then exit: a clean end.
    assert_eq!(c.request("shutdown", Value::Null), Value::Null);
    let e = c.request_raw("textDocument/hover", doc(pos(&text, "r2,", 0)));
    assert!(e.get("error").is_some(), "{e}");
    c.notify("exit", Value::Null);
    assert_eq!(c.wait(), Some(0));
}

fn doc_of(uri: &str) -> Value {
    json!({"textDocument": {"uri": uri}, "position": {"line": 0, "character": 0}})
}

fn show_symbols(v: &Value, depth: usize) -> String {
    let mut out = String::new();
    for s in v.as_array().into_iter().flatten() {
        out.push_str(&format!(
            "{}{} [{}] {} line {}\n",
            "  ".repeat(depth),
            s["name"].as_str().unwrap_or("?"),
            s["kind"],
            s["detail"].as_str().unwrap_or(""),
            s["selectionRange"]["start"]["line"].as_u64().unwrap_or(0) + 1
        ));
        out.push_str(&show_symbols(&s["children"], depth + 1));
    }
    out
}

#[test]
fn formatting_gives_what_lsyc_fmt_prints() {
    let mut c = Client::start();
    c.initialize();
    // A gallery scene, badly indented and spaced.
    let canonical = gallery("palm.lsy");
    let messy: String = canonical
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let l = l.trim_start().replace(" -> ", "->").replace(", ", ",");
            format!("{}{l}\n", " ".repeat(i % 7))
        })
        .collect();
    assert_ne!(messy, canonical);
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("messy.lsy");
    std::fs::write(&file, &messy).expect("write");
    let fmt = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .arg("fmt")
        .arg(&file)
        .output()
        .expect("lsyc fmt");
    assert!(fmt.status.success());
    let expected = String::from_utf8(fmt.stdout).expect("utf-8");

    let uri = "file:///tmp/messy.lsy";
    c.open(uri, &messy);
    let opts = json!({"tabSize": 4, "insertSpaces": true});
    let edits = c.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": uri}, "options": opts}),
    );
    assert!(!edits.as_array().expect("edits").is_empty());
    assert_eq!(apply(&messy, &edits), expected);

    // Already canonical: no edits.
    let uri2 = "file:///tmp/palm.lsy";
    c.open(uri2, &canonical);
    let edits = c.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": uri2}, "options": opts}),
    );
    assert_eq!(edits, json!([]));

    // A file that does not parse: no edits, no error, and the server goes on.
    let uri3 = "file:///tmp/broken.lsy";
    c.open(uri3, "lsystem A {\n  axiom F;\n  F -> F[+F;\n  oops (\n");
    let edits = c.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": uri3}, "options": opts}),
    );
    assert!(edits.is_null() || edits == json!([]), "{edits}");
    assert_eq!(c.request("shutdown", Value::Null), Value::Null);
    c.notify("exit", Value::Null);
    assert_eq!(c.wait(), Some(0));
}

#[test]
fn positions_count_utf16_code_units() {
    let mut c = Client::start();
    c.initialize();
    // `é` is one UTF-16 unit (two bytes), `𝄞` two units (four bytes).
    let text = "const a = 1; /* é 𝄞 */ const b = nope;\nlsystem L { axiom F(a + b); }\n";
    let d = c.open("file:///tmp/utf16.lsy", text);
    let ds = d["diagnostics"].as_array().expect("diagnostics");
    let e = ds
        .iter()
        .find(|d| d["code"] == "E0302")
        .unwrap_or_else(|| panic!("{d}"));
    assert_eq!(e["range"]["start"], pos(text, "nope", 0));
    assert_eq!(e["range"]["start"]["character"], 34);
    // Hover after the wide characters lands on the right name.
    let h = c.request(
        "textDocument/hover",
        json!({"textDocument": {"uri": "file:///tmp/utf16.lsy"}, "position": pos(text, "b)", 0)}),
    );
    assert!(hover_text(&h).contains("const b"), "{h}");
    drop(c);
}

#[test]
fn scene_hover_definition_and_query_modules() {
    let text = gallery("palm.lsy");
    let uri = "file:///gallery/palm.lsy";
    let mut c = Client::start();
    c.initialize();
    assert_eq!(c.open(uri, &text)["diagnostics"], json!([]));
    let doc = |p: Value| json!({"textDocument": {"uri": uri}, "position": p});
    let mut hovers = String::new();
    for (needle, what) in [
        ("?D_L(found, d, beta, _", "query module in a predecessor"),
        ("found, d, beta, _", "query output"),
        ("?X(D, w * 0.985)", "collision query"),
        ("NEAR &&", "constant in a condition"),
    ] {
        let h = c.request("textDocument/hover", doc(pos(&text, needle, 0)));
        hovers.push_str(&format!("--- {what} (`{needle}`)\n{}\n", hover_text(&h)));
    }
    insta::assert_snapshot!("lsp_hover_palm", hovers);
    // `system Trunk;` in a guide goes to the lsystem.
    let def = c.request(
        "textDocument/definition",
        doc(pos(&text, "system Trunk", 0)),
    );
    // the position of `Trunk` in `system Trunk`
    let at = text.find("system Trunk").expect("system") + "system ".len();
    let def2 = c.request("textDocument/definition", doc(position_of(&text, at)));
    assert!(def.is_null() || def == def2);
    assert_eq!(
        def2["range"]["start"],
        pos(&text, "Trunk(D, w)", 0),
        "{def2}"
    );
    let symbols = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri}}),
    );
    insta::assert_snapshot!("lsp_symbols_palm", show_symbols(&symbols, 0));
}

/// The VS Code extension's files are valid JSON, claim `.lsy`, start `lsyc
/// lsp`, and the TextMate grammar knows every keyword and built-in function.
#[test]
fn editor_support_files_fit_the_language() {
    let dir = root().join("editors/vscode");
    let json = |name: &str| -> Value {
        let text =
            std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    let pkg = json("package.json");
    assert_eq!(
        pkg["contributes"]["languages"][0]["extensions"],
        json!([".lsy"])
    );
    let grammar_path = pkg["contributes"]["grammars"][0]["path"]
        .as_str()
        .expect("grammar path");
    let grammar = json(grammar_path.trim_start_matches("./"));
    json("language-configuration.json");
    let lock = json("package-lock.json");
    assert_eq!(
        lock["packages"][""]["dependencies"], pkg["dependencies"],
        "package-lock.json is out of date: run `npm install --package-lock-only` in editors/vscode"
    );
    let client =
        std::fs::read_to_string(dir.join(pkg["main"].as_str().expect("main"))).expect("client");
    assert!(
        client.contains("args: [\"lsp\"]"),
        "the client does not start `lsyc lsp`"
    );
    let text = grammar.to_string();
    let lexer_keywords: Vec<&str> = lsyc::lsp::words::KEYWORDS
        .iter()
        .map(|k| k.word)
        .filter(|w| {
            let lexed = lsyc::lexer::lex(w);
            matches!(&lexed.tokens[..], [(_, t, _)] if t.is_keyword())
        })
        .collect();
    assert!(lexer_keywords.len() > 20, "{lexer_keywords:?}");
    for w in lexer_keywords {
        assert!(
            text.contains(w),
            "the grammar does not highlight the keyword `{w}`"
        );
    }
    // Words a link takes that are names to the lexer (`aim middle;`).
    for k in lsyc::lsp::words::KEYWORDS {
        if k.context == lsyc::lsp::words::Context::Link {
            assert!(
                text.contains(k.word),
                "the grammar does not know the link word `{}`",
                k.word
            );
        }
    }
    for b in lsyc::builtins::BUILTINS {
        assert!(
            text.contains(&format!("|{}|", b.name))
                || text.contains(&format!("({}|", b.name))
                || text.contains(&format!("|{})", b.name)),
            "the grammar does not know `{}`",
            b.name
        );
    }
}

/// Over the gallery and the test corpus (valid, broken and hostile programs):
/// every use the index finds lies in the text on character boundaries and
/// names what is written there; every use of a declared thing goes to a
/// declaration of the same name; hover, completion, symbols, prepareRename and
/// formatting answer at every name without panicking; formatting's edits give
/// `fmt`'s text whenever the file parses.
#[test]
fn every_file_every_name() {
    use lsyc::lsp::index::Target;
    use lsyc::lsp::{Analysis, complete, format, hover, outline, rename};
    let files = crate::support::lsy_files(&["lang-examples", "tests/data"]);
    assert!(files.len() > 60, "{}", files.len());
    let mut names = 0;
    for path in files {
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue; // invalid UTF-8 on purpose: an editor would not send it
        };
        if text.len() > 1 << 20 {
            continue;
        }
        let rel = crate::support::rel(&path);
        let a = Analysis::new(text.clone());
        for o in &a.index.occurrences {
            let (s, e) = (o.span.start as usize, o.span.end as usize);
            assert!(
                e <= text.len() && text.is_char_boundary(s) && text.is_char_boundary(e),
                "{rel}: {o:?}"
            );
            let written = &text[s..e];
            match &o.target {
                Target::Symbol(id) => {
                    let sym = &a.index.symbols[*id];
                    assert_eq!(written, sym.name, "{rel}: {o:?}");
                    if let Some(d) = sym.decl {
                        assert_eq!(
                            &text[d.range()],
                            sym.name,
                            "{rel}: declaration of {}",
                            sym.name
                        );
                    }
                    names += 1;
                }
                Target::Query(q) => assert_eq!(written, q, "{rel}"),
                Target::Turtle(c) => assert_eq!(written, c.to_string(), "{rel}"),
                Target::Cut => assert_eq!(written, "cut", "{rel}"),
                Target::Function(f) | Target::Word(f) => assert_eq!(written, f, "{rel}"),
            }
            assert!(hover::hover(&a, s).is_some(), "{rel}: no hover at {o:?}");
            assert!(a.index.at(s).is_some(), "{rel}");
            if matches!(o.target, Target::Symbol(_)) {
                assert!(rename::prepare(&a, s).is_ok(), "{rel}: {o:?}");
            }
        }
        // Completion anywhere (every 97th byte on a boundary) answers.
        for off in (0..=text.len())
            .step_by(97)
            .filter(|&o| text.is_char_boundary(o))
        {
            complete::complete(&a, off);
            hover::hover(&a, off);
        }
        outline::outline(&a);
        let parsed = lsyc::parser::parse(&text);
        match format::format(&a) {
            Some(edits) => {
                let want = lsyc::fmt::format_file(&parsed.file);
                let edits = serde_json::to_value(edits).expect("json");
                assert_eq!(apply(&text, &edits), want, "{rel}");
            }
            None => assert!(parsed.diagnostics.iter().any(|d| d.is_error()), "{rel}"),
        }
    }
    assert!(names > 2000, "only {names} names indexed");
}

fn lsyc_check(text: &str) -> (bool, String) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("fixed.lsy");
    std::fs::write(&path, text).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(["check", path.to_str().expect("utf-8")])
        .output()
        .expect("run lsyc check");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Programs with one problem each whose diagnostic carries a fix: the server
/// offers it as a quick fix on the diagnostic's line, and the program the edit
/// gives is one `lsyc check` accepts (and the server then reports no error).
#[test]
fn quick_fixes_give_programs_lsyc_check_accepts() {
    const CASES: &[(&str, &str, &str)] = &[
        (
            "a constant misspelt",
            "const len = 2;\nlsystem A {\n    axiom F(lne);\n}\n",
            "replace with `len`",
        ),
        (
            "a parameter misspelt",
            "lsystem A {\n    axiom A(1);\n    A(size) -> F(sise) A(size);\n}\n",
            "replace with `size`",
        ),
        (
            "a function misspelt",
            "lsystem A {\n    axiom F(sqtr(4));\n}\n",
            "replace with `sqrt`",
        ),
        (
            "a query module misspelt",
            "lsystem A {\n    axiom A ?Q;\n    A > ?P(x, y, _) -> F(x + y);\n}\n",
            "replace with `?P`",
        ),
        (
            "an element property by another name",
            "element Leaf {\n    path \"M0 0 L0 10\";\n    colour \"green\";\n}\nlsystem A {\n    axiom F Leaf;\n}\n",
            "replace with `fill`",
        ),
        (
            "a guide's lsystem misspelt",
            "lsystem Trunk {\n    axiom F;\n}\nscene S {\n    guide g {\n        polygon (0, 0) (10, 0) (10, 10);\n        system Trnk;\n        seed (1, 1);\n    }\n}\n",
            "replace with `Trunk`",
        ),
        (
            "a link's guide misspelt",
            "lsystem T {\n    axiom F;\n}\nscene S {\n    guide stem {\n        polygon (0, 0) (10, 0) (10, 10);\n        system T;\n        seed (1, 1);\n    }\n    guide crown {\n        polygon (0, 10) (10, 10) (10, 20);\n        system T;\n    }\n    link stem.edge(1) -> crwon.edge(0) {\n        tokens 1;\n    }\n}\n",
            "replace with `crown`",
        ),
        (
            "cpfg's #define",
            "#define N 5\nlsystem A {\n    derive N;\n    axiom F;\n}\n",
            "write it as a constant",
        ),
        (
            "cpfg's #ignore",
            "lsystem A {\n    #ignore: + -\n    axiom B F A;\n    B < A -> F;\n}\n",
            "write `ignore …;`",
        ),
        (
            "cpfg's #consider",
            "lsystem A {\n    #consider: A B;\n    axiom B F A;\n    B < A -> F;\n}\n",
            "write `consider …;`",
        ),
        (
            "ω: as in the books",
            "lsystem A {\n    ω: F;\n    F -> F F;\n}\n",
            "write `axiom`",
        ),
        (
            "ignore with a colon",
            "lsystem A {\n    axiom B F A;\n    ignore: F;\n    B < A -> F;\n}\n",
            "write `ignore`",
        ),
        (
            "= for ==",
            "lsystem A {\n    axiom A(1);\n    A(x) : x = 1 -> A(x + 1);\n}\n",
            "replace with `==`",
        ),
        (
            "cpfg's : *",
            "lsystem A {\n    axiom A;\n    A : * -> F A;\n}\n",
            "remove `: *`",
        ),
        (
            "a missing ;",
            "lsystem A {\n    axiom A\n    A -> F A;\n}\n",
            "insert `;`",
        ),
        (
            "the arrow →",
            "lsystem A {\n    axiom A;\n    A → F A;\n}\n",
            "replace with `->`",
        ),
        (
            "endlsystem",
            "lsystem A {\n    axiom A;\n    A -> F A;\n    endlsystem\n}\n",
            "remove it",
        ),
        (
            "a section label (a warning)",
            "lsystem A {\n    axiom A;\n    A -> B;\n    decomposition: B -> F F;\n}\n",
            "write `decompose`",
        ),
    ];
    let mut c = Client::start();
    c.initialize();
    let mut report = String::new();
    for (n, (what, text, title)) in CASES.iter().enumerate() {
        let uri = format!("file:///fix/{n}.lsy");
        let diags = c.open(&uri, text);
        // The first error, or the warning when there is no error.
        let all = diags["diagnostics"].as_array().expect("diagnostics");
        let first = all
            .iter()
            .find(|d| d["severity"] == 1)
            .or(all.first())
            .unwrap_or_else(|| panic!("{what}: no diagnostic"))
            .clone();
        // Asked at the diagnostic's range, as an editor does for the cursor.
        let actions = c.request(
            "textDocument/codeAction",
            json!({
                "textDocument": {"uri": uri},
                "range": first["range"],
                "context": {"diagnostics": [first], "only": ["quickfix"]},
            }),
        );
        let actions = actions.as_array().expect("actions");
        let action = actions
            .iter()
            .find(|a| a["title"] == *title)
            .unwrap_or_else(|| panic!("{what}: no `{title}` among {actions:?}"));
        assert_eq!(action["kind"], "quickfix", "{what}");
        assert_eq!(
            action["diagnostics"][0]["code"], first["code"],
            "{what}: the fix names its diagnostic"
        );
        let edits = &action["edit"]["changes"][&uri];
        let fixed = apply(text, edits);
        let (ok, stderr) = lsyc_check(&fixed);
        assert!(ok, "{what}: after `{title}`:\n{fixed}\n{stderr}");
        c.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri, "version": 2},
                   "contentChanges": [{"text": fixed}]}),
        );
        let after = c.notification("textDocument/publishDiagnostics");
        assert!(
            after["diagnostics"]
                .as_array()
                .expect("diagnostics")
                .iter()
                .all(|d| d["severity"] != 1),
            "{what}: {after}"
        );
        report.push_str(&format!(
            "--- {what}: {} `{title}`\n{fixed}",
            first["code"].as_str().unwrap_or("-")
        ));
    }
    // Nothing is offered where the diagnostic has no concrete fix, nor when
    // the client asks only for other kinds of actions.
    let uri = "file:///fix/none.lsy";
    let text = "lsystem A {\n    axiom F(zzzz);\n}\n";
    let d = c.open(uri, text);
    let first = d["diagnostics"][0].clone();
    assert_eq!(first["code"], "E0302", "{d}");
    let none = c.request(
        "textDocument/codeAction",
        json!({"textDocument": {"uri": uri}, "range": first["range"],
               "context": {"diagnostics": [first]}}),
    );
    assert_eq!(none, json!([]));
    let refactor = c.request(
        "textDocument/codeAction",
        json!({"textDocument": {"uri": "file:///fix/0.lsy"},
               "range": {"start": {"line": 0, "character": 0}, "end": {"line": 9, "character": 0}},
               "context": {"diagnostics": [], "only": ["refactor"]}}),
    );
    assert!(refactor.is_null() || refactor == json!([]), "{refactor}");
    insta::assert_snapshot!("lsp_quick_fixes", report);
}

/// Over the gallery and the test corpus, in every file the checker accepts
/// (so it resolved every name): every name token has a definition answer,
/// except these classes, which have nowhere to go:
/// - words of the language (`tropism(e)`, `aim`, `take`, `continue`,
///   `middle`, `closest`) and built-in functions: hover explains them;
/// - letter modules no rule rewrites (`F`, or a letter that is only written
///   in strings): declared by use, with no declaration or rule to show;
/// - the parameters of a `module` declaration and of a module declared in an
///   lsystem, and element property keys: names with no uses;
/// - `_`, which binds nothing.
#[test]
fn every_resolved_name_has_a_definition() {
    use lsyc::lexer::{Token, lex};
    use lsyc::lsp::index::{Kind, Target};
    use lsyc::lsp::{Analysis, hover};
    let files = crate::support::lsy_files(&["lang-examples", "tests/data"]);
    let (mut checked, mut defined, mut excluded) = (0, 0, 0);
    let mut unexplained = Vec::new();
    for path in files {
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let a = Analysis::new(text.clone());
        if a.diagnostics.iter().any(|d| d.is_error()) {
            continue;
        }
        checked += 1;
        let rel = crate::support::rel(&path);
        // Names that declare nothing other names use: `module` parameters,
        // element property keys and palette material names.
        let mut unused_decl = std::collections::HashSet::new();
        for item in &a.file.items.stmts {
            match &item.node {
                lsyc::ast::Item::Module(m) => {
                    unused_decl.extend(m.params.iter().map(|p| p.span.start));
                }
                lsyc::ast::Item::Lsystem(l) => {
                    for st in &l.body.stmts {
                        if let lsyc::ast::Stmt::Module(m) = &st.node {
                            unused_decl.extend(m.params.iter().map(|p| p.span.start));
                        }
                    }
                }
                lsyc::ast::Item::Element(e) => {
                    unused_decl.extend(e.props.stmts.iter().map(|p| p.node.key.span.start));
                }
                // A palette's material names are written to OBJ and glTF only.
                lsyc::ast::Item::Palette(p) => {
                    unused_decl.extend(
                        p.body
                            .stmts
                            .iter()
                            .filter_map(|e| e.node.name.as_ref())
                            .map(|n| n.span.start),
                    );
                }
                _ => {}
            }
        }
        for (start, tok, end) in lex(&text).tokens {
            // A keyword is never a name (the module `tropism(e)` is a word).
            if tok.is_keyword() {
                if let Some(o) = a.index.at(start).filter(|o| o.span.start as usize == start) {
                    assert!(
                        !matches!(o.target, Target::Symbol(_)),
                        "{rel}:{start}: the keyword {tok} is indexed as a name"
                    );
                }
                continue;
            }
            let Token::Ident(name) = tok else { continue };
            if name == "_" || unused_decl.contains(&(start as u32)) {
                excluded += 1;
                continue;
            }
            // Every letter of a run the resolver split is its own module.
            for off in start..end {
                if !text.is_char_boundary(off) {
                    continue;
                }
                let Some(o) = a.index.at(off).filter(|o| o.span.start as usize == off) else {
                    if off == start {
                        unexplained.push(format!("{rel}:{start}: `{name}` is not indexed"));
                    }
                    continue;
                };
                match &o.target {
                    Target::Symbol(id) => {
                        let sym = &a.index.symbols[*id];
                        if !sym.definition().is_empty() {
                            defined += 1;
                        } else if sym.kind == Kind::Letter && lsyc::resolve::is_letter(&sym.name) {
                            excluded += 1;
                        } else {
                            unexplained
                                .push(format!("{rel}:{off}: `{}` has no definition", sym.name));
                        }
                    }
                    Target::Word(_) | Target::Function(_) => {
                        assert!(hover::hover(&a, off).is_some(), "{rel}:{off}");
                        excluded += 1;
                    }
                    other => unexplained.push(format!("{rel}:{off}: `{name}` is {other:?}")),
                }
            }
        }
    }
    assert!(
        unexplained.is_empty(),
        "{} names:\n{}",
        unexplained.len(),
        unexplained.join("\n")
    );
    assert!(checked > 40, "{checked} files");
    assert!(
        defined > 2000 && excluded > 100,
        "{defined} defined, {excluded} excluded"
    );
}

/// A program with the newer syntax: `tropism` (statement and module),
/// `consider`, `decompose`, and a link's `heading continue; aim middle; take v;`.
const NEWER: &str = "// Newer syntax in one file.
const E = 0.2;
const V = 1;
module Apex(len, depth);
lsystem Tree(w) {
    tropism (0, -1, 0) E;
    consider A Apex;
    axiom A(w) Apex(1, 2);
    A(x) -> F(x) [+(30) tropism(E * 2) A(x * 0.5)] A(x);
    decompose Apex(l, d) : d > 0 -> F(l) Apex(l, d - 1);
}
scene S {
    guide g {
        polygon (0, 0) (10, 0) (10, 10);
        system Tree;
        seed (1, 1) with (1);
    }
    guide h {
        polygon (0, 10) (10, 10) (10, 20);
        system Tree;
    }
    link g.edge(1) -> h.edge(0) { tokens 1; heading continue; aim middle; take V; }
}
";

#[test]
fn newer_syntax_is_indexed_and_explained() {
    let text = NEWER;
    let uri = "file:///newer.lsy";
    let mut c = Client::start();
    c.initialize();
    assert_eq!(c.open(uri, text)["diagnostics"], json!([]));
    let doc = |p: Value| json!({"textDocument": {"uri": uri}, "position": p});
    let mut hovers = String::new();
    for (needle, nth, want) in [
        ("tropism (", 0, "after every `F`"),
        ("tropism(E", 0, "rest of the branch"),
        ("consider", 0, "sees only these modules"),
        ("decompose", 0, "decomposition rule"),
        ("continue", 0, "keeps the heading"),
        ("aim", 0, "middle of this link's edge"),
        ("middle", 0, "middle of the link's edge"),
        ("take", 0, "`?X`"),
        ("E;", 0, "const E = 0.2"),
        ("V;", 0, "const V = 1"),
    ] {
        let h = c.request("textDocument/hover", doc(pos(text, needle, nth)));
        let t = hover_text(&h);
        assert!(t.contains(want), "{needle}: {t}");
        hovers.push_str(&format!("--- `{needle}`\n{t}\n"));
    }
    insta::assert_snapshot!("lsp_hover_newer_syntax", hovers);
    // Definitions through the new places.
    let def = |c: &mut Client, needle: &str, nth: usize| -> Value {
        let d = c.request("textDocument/definition", doc(pos(text, needle, nth)));
        if d.is_array() { d[0].clone() } else { d }
    };
    assert_eq!(
        def(&mut c, "E;", 0)["range"]["start"],
        pos(text, "E = 0.2", 0)
    );
    assert_eq!(
        def(&mut c, "E * 2", 0)["range"]["start"],
        pos(text, "E = 0.2", 0)
    );
    assert_eq!(
        def(&mut c, "V;", 0)["range"]["start"],
        pos(text, "V = 1", 0)
    );
    assert_eq!(
        def(&mut c, "Apex;", 0)["range"]["start"],
        pos(text, "Apex(len", 0)
    );
    // `A` in `consider` is a letter: it goes to the rule that rewrites it.
    assert_eq!(
        def(&mut c, "A Apex;", 0)["range"]["start"],
        pos(text, "A(x) ->", 0)
    );
    // The words are not names: nothing to go to, nothing to rename.
    for w in ["tropism(E", "continue", "middle", "aim"] {
        assert!(def(&mut c, w, 0).is_null(), "{w}");
        let r = c.request_raw("textDocument/prepareRename", doc(pos(text, w, 0)));
        assert!(r.get("error").is_some(), "{w}: {r}");
    }
    // A constant used in `tropism` and in `take` renames everywhere.
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(text, "E = 0.2", 0), "newName": "elasticity"}),
    );
    let renamed = apply(text, &edit["changes"][uri]);
    assert_eq!(renamed.matches("elasticity").count(), 3, "{renamed}");
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": uri}, "position": pos(text, "V;", 0), "newName": "leader"}),
    );
    assert!(apply(text, &edit["changes"][uri]).contains("take leader;"));
    // Completion in a link offers its words.
    let at = text.find("take V").expect("take");
    let items = c.request("textDocument/completion", doc(position_of(text, at)));
    let labels: Vec<&str> = items
        .as_array()
        .expect("items")
        .iter()
        .filter_map(|i| i["label"].as_str())
        .collect();
    for w in ["aim", "take", "continue", "middle", "tokens"] {
        assert!(labels.contains(&w), "{w}: {labels:?}");
    }
}

/// Semantic tokens decoded back to text: `line:col text type [modifiers]`.
fn show_tokens(text: &str, legend: &Value, data: &Value) -> String {
    let types = legend["tokenTypes"].as_array().expect("types");
    let mods = legend["tokenModifiers"].as_array().expect("modifiers");
    let lines: Vec<&str> = text.split('\n').collect();
    let d: Vec<u64> = data
        .as_array()
        .expect("data")
        .iter()
        .map(|v| v.as_u64().expect("u32"))
        .collect();
    assert_eq!(d.len() % 5, 0);
    let (mut line, mut col) = (0u64, 0u64);
    let mut out = String::new();
    for t in d.chunks(5) {
        if t[0] > 0 {
            line += t[0];
            col = t[1];
        } else {
            col += t[1];
        }
        let l: Vec<u16> = lines[line as usize].encode_utf16().collect();
        let word = String::from_utf16_lossy(&l[col as usize..(col + t[2]) as usize]);
        let m: Vec<&str> = (0..mods.len())
            .filter(|i| t[4] & (1 << i) != 0)
            .map(|i| mods[i].as_str().expect("name"))
            .collect();
        out.push_str(&format!(
            "{}:{} {word} {} {}\n",
            line + 1,
            col + 1,
            types[t[3] as usize].as_str().expect("type"),
            m.join(",")
        ));
    }
    out
}

#[test]
fn semantic_tokens_signatures_and_range_formatting() {
    let text = NEWER;
    let uri = "file:///newer.lsy";
    let mut c = Client::start();
    let init = c.initialize();
    let legend = init["capabilities"]["semanticTokensProvider"]["legend"].clone();
    c.open(uri, text);
    let toks = c.request(
        "textDocument/semanticTokens/full",
        json!({"textDocument": {"uri": uri}}),
    );
    let shown = show_tokens(text, &legend, &toks["data"]);
    for want in [
        "2:7 E variable declaration,readonly",
        "4:8 Apex type declaration",
        "6:5 tropism keyword",
        "6:24 E variable readonly",
        "9:7 x parameter declaration",
        "9:13 F type defaultLibrary",
        "9:19 + operator defaultLibrary",
        "9:25 tropism keyword",
        "10:5 decompose keyword",
        "22:53 continue keyword",
        "22:67 middle keyword",
        "22:80 V variable readonly",
    ] {
        assert!(shown.contains(want), "{want}:\n{shown}");
    }
    insta::assert_snapshot!("lsp_semantic_tokens_newer", shown);

    // Signature help inside a module's parentheses, the active one marked.
    let doc = |p: Value| json!({"textDocument": {"uri": uri}, "position": p});
    let after = |needle: &str| {
        let at = text.find(needle).expect("needle") + needle.len();
        doc(position_of(text, at))
    };
    let mut sigs = String::new();
    for needle in [
        "Apex(1, ",
        "Apex(1",
        "A(x * 0.",
        "tropism(E",
        "+(3",
        "F(l",
        "Apex(l, d - ",
    ] {
        let h = c.request("textDocument/signatureHelp", after(needle));
        let s = &h["signatures"][0];
        let active = h["activeParameter"].as_u64().expect("active") as usize;
        let param = s["parameters"][active]["label"].as_str().unwrap_or("?");
        sigs.push_str(&format!(
            "{needle:<12} {}  [{param}]\n",
            s["label"].as_str().expect("label")
        ));
    }
    assert!(
        sigs.contains("Apex(1,      Apex(len, depth)  [depth]"),
        "{sigs}"
    );
    assert!(
        sigs.contains("Apex(1       Apex(len, depth)  [len]"),
        "{sigs}"
    );
    assert!(sigs.contains("A(x * 0.     A(x)  [x]"), "{sigs}");
    assert!(sigs.contains("tropism(E    tropism(e)  [e]"), "{sigs}");
    // Outside parentheses there is none.
    let none = c.request("textDocument/signatureHelp", doc(pos(text, "consider", 0)));
    assert!(none.is_null(), "{none}");
    // A query module in a predecessor shows its outputs first.
    let palm = gallery("palm.lsy");
    c.open("file:///palm.lsy", &palm);
    let at = palm.find("?D_L(found, d, beta, _, D, w)").expect("?D_L") + "?D_L(found, ".len();
    let h = c.request(
        "textDocument/signatureHelp",
        json!({"textDocument": {"uri": "file:///palm.lsy"}, "position": position_of(&palm, at)}),
    );
    sigs.push_str(&format!(
        "?D_L(found,  {}  [{}]\n",
        h["signatures"][0]["label"], h["activeParameter"]
    ));
    assert_eq!(h["activeParameter"], 1, "{h}");
    insta::assert_snapshot!("lsp_signature_help", sigs);

    // Range formatting: the items the range touches come out as `lsyc fmt`
    // prints them; the others stay as written.
    let messy = text
        .replace("    ", "  ")
        .replace("F(x) [+(30)", "F(x)   [ +(30)");
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 2}, "contentChanges": [{"text": messy}]}),
    );
    c.notification("textDocument/publishDiagnostics");
    let canonical = lsyc::fmt::format_file(&lsyc::parser::parse(&messy).file);
    let range_format = |c: &mut Client, from: &str, to: &str| -> String {
        let edits = c.request(
            "textDocument/rangeFormatting",
            json!({"textDocument": {"uri": uri}, "options": {"tabSize": 4, "insertSpaces": true},
                   "range": {"start": pos(&messy, from, 0), "end": pos(&messy, to, 0)}}),
        );
        apply(&messy, &edits)
    };
    let whole = range_format(&mut c, "// Newer", "take V");
    assert_eq!(whole, canonical);
    // Only the lsystem (the range is inside its `A` rule).
    let part = range_format(&mut c, "A(x) ->", "A(x * 0.5)");
    let lsystem =
        |s: &str| s[s.find("lsystem").expect("ls")..s.find("scene").expect("scene")].to_string();
    let scene = |s: &str| s[s.find("scene").expect("scene")..].to_string();
    assert_eq!(lsystem(&part).trim_end(), lsystem(&canonical).trim_end());
    assert_eq!(scene(&part), scene(&messy), "the scene is left as written");
    assert!(part.starts_with(&messy[..messy.find("lsystem").expect("ls")]));
    // Already canonical: no edits.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri, "version": 3}, "contentChanges": [{"text": canonical}]}),
    );
    c.notification("textDocument/publishDiagnostics");
    let edits = c.request(
        "textDocument/rangeFormatting",
        json!({"textDocument": {"uri": uri}, "options": {"tabSize": 4, "insertSpaces": true},
               "range": {"start": {"line": 0, "character": 0}, "end": {"line": 40, "character": 0}}}),
    );
    assert_eq!(edits, json!([]));
}
