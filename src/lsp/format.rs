//! Formatting through the one canonical printer.
//!
//! Owns: turning `fmt::format_file`'s text into edits: none when the document
//! is already canonical, none when it does not parse (as `lsyc fmt` refuses
//! such a file), else one edit spanning only the part that changes. Range
//! formatting prints the top-level items the range touches with
//! `fmt::format_items`, the same printer, and leaves the rest of the file as
//! it is (the blank lines around that run of items included). Both print the
//! tree the document's analysis already holds: a request parses nothing.

use super::analysis::Analysis;
use super::text::LineIndex;
use crate::fmt::{format_file, format_items};
use crate::span::Span;
use lsp_types::TextEdit;

/// The edits that make the document canonical, or `None` if it has syntax
/// errors (or was too large to analyse).
pub fn format(a: &Analysis) -> Option<Vec<TextEdit>> {
    if !a.parsed() {
        return None;
    }
    Some(edit(&a.text, 0, a.text.len(), &format_file(&a.file)))
}

/// The edits that make the items touched by bytes `range` canonical, or
/// `None` if the document has syntax errors (or was too large to analyse).
pub fn format_range(a: &Analysis, range: std::ops::Range<usize>) -> Option<Vec<TextEdit>> {
    if !a.parsed() {
        return None;
    }
    let text = a.text.as_str();
    // Each item's extent: the item with its comments (leading ones may sit
    // inside it, a trailing one after it).
    let extent = |n: &crate::ast::Node<crate::ast::Item>| {
        let t = &n.trivia;
        t.leading
            .iter()
            .chain(t.trailing.as_ref())
            .fold(n.span, |s, c| s.to(c.span))
    };
    let items = &a.file.items.stmts;
    let touched: Vec<usize> = (0..items.len())
        .filter(|&i| {
            let e = extent(&items[i]);
            (e.start as usize) <= range.end && range.start <= e.end as usize
        })
        .collect();
    let (Some(&first), Some(&last)) = (touched.first(), touched.last()) else {
        return Some(Vec::new());
    };
    let start = extent(&items[first]).start as usize;
    let end = extent(&items[last]).end as usize;
    let out = format_items(&a.file, first..last + 1);
    let out = out.strip_suffix('\n').unwrap_or(&out);
    Some(edit(text, start, end, out))
}

/// One edit that writes `out` in place of `text[from..to]`, trimmed to the
/// part that changes; none if nothing does.
fn edit(text: &str, from: usize, to: usize, out: &str) -> Vec<TextEdit> {
    let old = &text[from..to];
    if out == old {
        return Vec::new();
    }
    // The changed middle: skip the common prefix and suffix (on character
    // boundaries), so the editor keeps the cursor and folds where nothing moves.
    let mut pre = old
        .bytes()
        .zip(out.bytes())
        .take_while(|(a, b)| a == b)
        .count();
    while !old.is_char_boundary(pre) || !out.is_char_boundary(pre) {
        pre -= 1;
    }
    let max_suf = old.len().min(out.len()) - pre;
    let mut suf = old
        .bytes()
        .rev()
        .zip(out.bytes().rev())
        .take(max_suf)
        .take_while(|(a, b)| a == b)
        .count();
    while !old.is_char_boundary(old.len() - suf) || !out.is_char_boundary(out.len() - suf) {
        suf -= 1;
    }
    let lines = LineIndex::new(text);
    let range = lines.range(text, Span::new(from + pre, to - suf));
    vec![TextEdit {
        range,
        new_text: out[pre..out.len() - suf].to_string(),
    }]
}
