//! What `lsyc lsp` does on every keystroke: re-check a document and publish
//! its diagnostics.
//!
//! - `lsp_analysis/FILE`: the library's work alone: parse, check, index and
//!   convert the diagnostics to the protocol's (`lsp::Analysis`).
//! - `lsp_keystroke/FILE`: the server's whole path for one typed character:
//!   an incremental `didChange` read from JSON-RPC, applied, analysed, and the
//!   `publishDiagnostics` notification written (to a sink). Per keystroke.
//!
//! - `lsp_tokens/FILE`: semantic tokens for the whole document, which an
//!   editor asks for after every change too (`lsp::semantic::tokens`, the
//!   analysis already made).
//!
//! Files: a gallery program (`monopodial-tree.lsy`), the palm scene and the
//! largest scene of `lang-examples/` (`bridge.lsy`).
//!
//! `cargo bench --bench lsp`.

use criterion::{Criterion, criterion_group, criterion_main};
use lsyc::lsp::{Analysis, semantic, serve};
use serde_json::json;
use std::hint::black_box;
use std::io::BufReader;
use std::time::{Duration, Instant};

const FILES: &[&str] = &["monopodial-tree.lsy", "palm.lsy", "bridge.lsy"];

fn read(file: &str) -> String {
    let path = format!("{}/lang-examples/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).expect("the gallery file")
}

fn frame(out: &mut Vec<u8>, v: serde_json::Value) {
    let body = v.to_string();
    out.extend_from_slice(format!("Content-Length: {}\r\n\r\n{body}", body.len()).as_bytes());
}

/// A session that opens `text` and types `n` characters into it (a space
/// typed and deleted again, alternately, at the start of the last line).
fn session(text: &str, n: u64) -> Vec<u8> {
    let uri = "file:///bench/doc.lsy";
    let mut out = Vec::new();
    frame(
        &mut out,
        json!({"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {"capabilities": {}}}),
    );
    frame(
        &mut out,
        json!({"jsonrpc": "2.0", "method": "initialized", "params": {}}),
    );
    frame(
        &mut out,
        json!({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": uri, "languageId": "lsy", "version": 1, "text": text}}}),
    );
    let line = text.trim_end().lines().count().saturating_sub(1);
    for i in 0..n {
        let start = json!({"line": line, "character": 0});
        let end = if i % 2 == 0 {
            start.clone()
        } else {
            json!({"line": line, "character": 1})
        };
        let typed = if i % 2 == 0 { " " } else { "" };
        frame(
            &mut out,
            json!({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
                "textDocument": {"uri": uri, "version": i + 2},
                "contentChanges": [{"range": {"start": start, "end": end}, "text": typed}]
            }}),
        );
    }
    frame(
        &mut out,
        json!({"jsonrpc": "2.0", "id": 2, "method": "shutdown"}),
    );
    frame(&mut out, json!({"jsonrpc": "2.0", "method": "exit"}));
    out
}

fn bench(c: &mut Criterion) {
    let uri: lsp_types::Uri = "file:///bench/doc.lsy".parse().expect("uri");
    let mut g = c.benchmark_group("lsp_analysis");
    g.measurement_time(Duration::from_secs(5));
    for file in FILES {
        let text = read(file);
        let a = Analysis::new(text.clone());
        assert!(a.diagnostics.is_empty(), "{file}: {:?}", a.diagnostics);
        g.bench_function(*file, |b| {
            b.iter(|| {
                let a = Analysis::new(black_box(text.clone()));
                black_box(a.lsp_diagnostics(&uri))
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("lsp_keystroke");
    g.measurement_time(Duration::from_secs(5));
    for file in FILES {
        let text = read(file);
        g.bench_function(*file, |b| {
            b.iter_custom(|iters| {
                let input = session(&text, iters);
                let t = Instant::now();
                let end = serve(BufReader::new(&input[..]), std::io::sink()).expect("serve");
                assert_eq!(end, lsyc::lsp::End::Clean);
                t.elapsed()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("lsp_tokens");
    g.measurement_time(Duration::from_secs(3));
    for file in FILES {
        let a = Analysis::new(read(file));
        g.bench_function(*file, |b| {
            b.iter(|| black_box(semantic::tokens(black_box(&a))))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
