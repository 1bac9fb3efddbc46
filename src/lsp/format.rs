//! Formatting through the one canonical printer.
//!
//! Owns: turning `fmt::format_file`'s text into edits: none when the document
//! is already canonical, none when it does not parse (as `lsyc fmt` refuses
//! such a file), else one edit spanning only the part that changes.

use super::text::LineIndex;
use crate::fmt::format_file;
use crate::parser;
use lsp_types::TextEdit;

/// The edits that make `text` canonical, or `None` if it has syntax errors.
pub fn format(text: &str) -> Option<Vec<TextEdit>> {
    let parsed = parser::parse(text);
    if parsed.diagnostics.iter().any(|d| d.is_error()) {
        return None;
    }
    let out = format_file(&parsed.file);
    if out == text {
        return Some(Vec::new());
    }
    // The changed middle: skip the common prefix and suffix (on character
    // boundaries), so the editor keeps the cursor and folds where nothing moves.
    let mut pre = text
        .bytes()
        .zip(out.bytes())
        .take_while(|(a, b)| a == b)
        .count();
    while !text.is_char_boundary(pre) || !out.is_char_boundary(pre) {
        pre -= 1;
    }
    let max_suf = text.len().min(out.len()) - pre;
    let mut suf = text
        .bytes()
        .rev()
        .zip(out.bytes().rev())
        .take(max_suf)
        .take_while(|(a, b)| a == b)
        .count();
    while !text.is_char_boundary(text.len() - suf) || !out.is_char_boundary(out.len() - suf) {
        suf -= 1;
    }
    let lines = LineIndex::new(text);
    let range = lines.range(text, crate::span::Span::new(pre, text.len() - suf));
    Some(vec![TextEdit {
        range,
        new_text: out[pre..out.len() - suf].to_string(),
    }])
}
