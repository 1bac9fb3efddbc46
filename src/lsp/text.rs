//! Positions as the protocol counts them: lines and UTF-16 code units.
//!
//! Owns: the one conversion between byte offsets (what spans hold) and LSP
//! positions, and applying a client's edits to a document's text. Every other
//! part of the server speaks bytes and converts here, at the edge, once.

use crate::span::Span;
use lsp_types::{Position, Range, TextDocumentContentChangeEvent};

/// The byte offsets where lines start. A line ends at `\n`, `\r\n` or a lone
/// `\r`, as the protocol says.
#[derive(Clone, Debug)]
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub fn new(text: &str) -> LineIndex {
        let mut starts = vec![0];
        let b = text.as_bytes();
        for (i, &c) in b.iter().enumerate() {
            if c == b'\n' || (c == b'\r' && b.get(i + 1) != Some(&b'\n')) {
                starts.push(i + 1);
            }
        }
        LineIndex { starts }
    }

    /// The 0-based line holding a byte offset.
    pub fn line(&self, offset: usize) -> usize {
        match self.starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i.saturating_sub(1),
        }
    }

    /// The position of a byte offset (clamped to the text, and moved back to
    /// the start of a character it falls inside).
    pub fn position(&self, text: &str, offset: usize) -> Position {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.line(offset);
        let start = self.starts[line];
        let character: usize = text[start..offset].chars().map(char::len_utf16).sum();
        Position {
            line: u32::try_from(line).unwrap_or(u32::MAX),
            character: u32::try_from(character).unwrap_or(u32::MAX),
        }
    }

    /// The byte offset of a position. A line past the end gives the end of the
    /// text; a character past the end of its line gives the line's end; a
    /// position inside a surrogate pair gives the character's start.
    pub fn offset(&self, text: &str, pos: Position) -> usize {
        let line = pos.line as usize;
        let Some(&start) = self.starts.get(line) else {
            return text.len();
        };
        let end = self.line_end(text, line);
        let mut units = 0usize;
        for (i, c) in text[start..end].char_indices() {
            if units >= pos.character as usize {
                return start + i;
            }
            units += c.len_utf16();
            if units > pos.character as usize {
                return start + i;
            }
        }
        end
    }

    /// The end of a line's content (before its line break).
    fn line_end(&self, text: &str, line: usize) -> usize {
        let next = self.starts.get(line + 1).copied().unwrap_or(text.len());
        let s = &text.as_bytes()[self.starts[line]..next];
        let mut end = next;
        if s.ends_with(b"\r\n") {
            end -= 2;
        } else if s.ends_with(b"\n") || s.ends_with(b"\r") {
            end -= 1;
        }
        end
    }

    pub fn range(&self, text: &str, span: Span) -> Range {
        Range {
            start: self.position(text, span.start as usize),
            end: self.position(text, span.end as usize),
        }
    }

    /// The byte range of an LSP range (ends swapped if given backwards).
    pub fn span(&self, text: &str, range: Range) -> std::ops::Range<usize> {
        let a = self.offset(text, range.start);
        let b = self.offset(text, range.end);
        a.min(b)..a.max(b)
    }
}

/// Applies a client's changes in order: a change without a range replaces the
/// whole text; one with a range replaces that part (positions are read against
/// the text as the earlier changes left it).
pub fn apply_changes(text: &mut String, changes: Vec<TextDocumentContentChangeEvent>) {
    for ch in changes {
        match ch.range {
            None => *text = ch.text,
            Some(r) => {
                let index = LineIndex::new(text);
                let span = index.span(text, r);
                text.replace_range(span, &ch.text);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(line: u32, character: u32) -> Position {
        Position { line, character }
    }

    #[test]
    fn utf16_columns_round_trip() {
        // `é` is one UTF-16 unit and two bytes, `𝄞` two units and four bytes.
        let text = "ab\né𝄞x\r\ny\rz";
        let ix = LineIndex::new(text);
        assert_eq!(ix.position(text, 0), pos(0, 0));
        assert_eq!(ix.position(text, 3), pos(1, 0));
        assert_eq!(ix.position(text, 5), pos(1, 1));
        assert_eq!(ix.position(text, 9), pos(1, 3));
        assert_eq!(ix.position(text, 7), pos(1, 1), "inside 𝄞: its start");
        assert_eq!(ix.offset(text, pos(1, 3)), 9);
        assert_eq!(ix.offset(text, pos(1, 2)), 5, "inside a surrogate pair");
        assert_eq!(ix.offset(text, pos(1, 99)), 10, "past the line: its end");
        assert_eq!(ix.offset(text, pos(2, 0)), 12);
        assert_eq!(ix.offset(text, pos(3, 0)), 14, "a lone \\r ends a line");
        assert_eq!(ix.offset(text, pos(9, 0)), text.len());
        for off in 0..=text.len() {
            if text.is_char_boundary(off) && !text[..off].ends_with('\r') {
                assert_eq!(ix.offset(text, ix.position(text, off)), off, "{off}");
            }
        }
    }

    #[test]
    fn changes_apply_in_order() {
        let mut text = String::from("axiom F;\nF -> F+F;\n");
        let change = |l0, c0, l1, c1, t: &str| TextDocumentContentChangeEvent {
            range: Some(Range {
                start: pos(l0, c0),
                end: pos(l1, c1),
            }),
            range_length: None,
            text: t.to_string(),
        };
        apply_changes(
            &mut text,
            vec![change(1, 5, 1, 8, "FF"), change(0, 6, 0, 7, "X")],
        );
        assert_eq!(text, "axiom X;\nF -> FF;\n");
    }
}
