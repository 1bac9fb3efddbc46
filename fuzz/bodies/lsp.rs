//! The language server's features on arbitrary text: the analysis made on
//! every change (parse, check, index), its diagnostics in the protocol's
//! terms, semantic tokens, the outline, formatting, and the requests that
//! take a position (hover, completion, signature help, references, rename,
//! range formatting, quick fixes) at positions drawn from the input. The
//! server catches a feature's panic and answers with an internal error; here
//! nothing catches it, so the fuzzer sees it. The same bytes are also read as
//! JSON-RPC framing, as the server's transport reads its input.
//!
//! Shared by the cargo-fuzz target `lsp` and the smoke test
//! (tests/it/fuzz_smoke.rs), which replays the seed corpus through it.

use lsp_types::{Position, Range, TextDocumentContentChangeEvent, Uri};
use lsyc::lsp::transport::{self, Incoming};
use lsyc::lsp::{
    Analysis, actions, complete, format, hover, outline, rename, semantic, signature, text,
};

/// How many positions each input is asked about.
const POSITIONS: usize = 4;

/// The largest input the fuzz target passes on (see docs/fuzzing.md): far
/// below the server's document limit, and every feature is reached well
/// within it.
#[allow(dead_code)]
pub const MAX_INPUT: usize = 8 * 1024;

pub fn run(data: &[u8]) {
    framing(data);
    // A document's text arrives in JSON: always UTF-8.
    let a = Analysis::new(String::from_utf8_lossy(data).into_owned());
    let Ok(uri) = "file:///fuzz.lsy".parse::<Uri>() else {
        return;
    };
    let _ = a.lsp_diagnostics(&uri);
    let _ = semantic::tokens(&a);
    let _ = outline::outline(&a);
    let _ = format::format(&a);
    let positions = positions(data, &a);
    for (i, &pos) in positions.iter().enumerate() {
        let off = a.offset(pos);
        assert!(off <= a.text.len(), "offset {off} past the end");
        assert!(
            a.text.is_char_boundary(off),
            "offset {off} inside a character"
        );
        let _ = hover::hover(&a, off);
        let _ = complete::complete(&a, off);
        let _ = signature::signature_help(&a, off);
        if let Some(o) = a.index.at(off) {
            for x in a.index.occurrences_of(&o.target) {
                let _ = a.range(x.span);
            }
            if let Some(sym) = a.index.symbol(&o.target) {
                for sp in sym.definition() {
                    let _ = a.range(sp);
                }
            }
        }
        let _ = rename::prepare(&a, off);
        let _ = rename::rename(&a, off, "renamed");
        let end = positions[(i + 1) % positions.len()];
        let range = Range { start: pos, end };
        let _ = format::format_range(&a, a.lines.span(&a.text, range));
        let _ = actions::quick_fixes(&a, &uri, range);
        // An edit at this range, as `didChange` applies it.
        let mut edited = a.text.clone();
        text::apply_changes(
            &mut edited,
            vec![TextDocumentContentChangeEvent {
                range: Some(range),
                range_length: None,
                text: "x(".into(),
            }],
        );
    }
}

/// Positions in (and a little beyond) the document, drawn from the bytes:
/// lines up to two past the last, characters up to 64 past the line's
/// start, in UTF-16 units as a client sends them.
fn positions(data: &[u8], a: &Analysis) -> Vec<Position> {
    let lines = a.text.lines().count() as u64 + 2;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut out = Vec::with_capacity(POSITIONS);
    for k in 0..POSITIONS {
        for &b in data.iter().rev().take(16).chain([k as u8].iter()) {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
        out.push(Position {
            line: (h % lines) as u32,
            character: ((h >> 32) % 64) as u32,
        });
    }
    out
}

/// Reads `data` as the server's input: framed JSON-RPC messages until the
/// end (a few at most: every read consumes bytes).
fn framing(data: &[u8]) {
    let mut r = std::io::Cursor::new(data);
    for _ in 0..8 {
        match transport::read(&mut r) {
            Ok(Incoming::Eof) | Err(_) => return,
            Ok(_) => {}
        }
    }
    let _ = transport::parse(data);
}
