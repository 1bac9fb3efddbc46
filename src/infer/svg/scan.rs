//! The pass over a drawing's raw text before any XML parser sees it: what
//! would make the parser itself run out of memory or time is refused here,
//! in one linear pass that allocates little.
//!
//! Owns: the limits on input size, elements, attributes per element and in
//! all, the expansion of the DOCTYPE's entities (a "billion laughs" or a
//! quadratic blow-up: each reference counted at its expanded size), and
//! numbers in geometry attributes beyond what usvg's 32-bit floats hold
//! (`1e308` would silently become infinity and the shape vanish). Must not
//! build a tree or judge what is well-formed: a document the scan does not
//! understand passes, and the XML parser says what is wrong with it.

use super::{Place, Refusal};
use std::collections::HashMap;

/// The largest drawing read, in bytes (the CLI's own limit too).
pub const MAX_BYTES: usize = crate::infer::MAX_SVG_BYTES;
/// The most attributes one element may have (an SVG element has a few
/// dozen at most; the XML parser compares each with all before it).
pub const MAX_ATTRIBUTES: usize = 1024;
/// The most attributes a document may have in all.
pub const MAX_ALL_ATTRIBUTES: usize = 4_000_000;
/// The most elements a document may have (as the parser's node limit).
pub const MAX_ELEMENTS: usize = super::MAX_XML_NODES as usize;
/// The most text the document's entity references may expand to, in bytes.
pub const MAX_EXPANSION: u64 = 4 * 1024 * 1024;
/// The largest coordinate usvg holds (a 32-bit float).
pub const MAX_NUMBER: f64 = f32::MAX as f64;

/// Attributes whose numbers are coordinates, lengths or transforms.
const GEOMETRY: &[&str] = &[
    "d",
    "points",
    "x",
    "y",
    "x1",
    "y1",
    "x2",
    "y2",
    "cx",
    "cy",
    "r",
    "rx",
    "ry",
    "width",
    "height",
    "transform",
    "gradientTransform",
    "patternTransform",
    "viewBox",
];

/// Scans `text` and refuses it if it passes a limit.
pub fn scan(text: &str) -> Result<(), Refusal> {
    if text.len() > MAX_BYTES {
        return Err(Refusal::TooLarge {
            limit_mib: MAX_BYTES >> 20,
        });
    }
    Scanner::new(text).run()
}

/// Where the scan is, and what it has counted.
struct Scanner<'a> {
    text: &'a str,
    bytes: &'a [u8],
    at: usize,
    elements: usize,
    attributes: usize,
    /// Each declared entity's expanded size (`None` while it is expanded,
    /// to find an entity that contains itself).
    entities: HashMap<&'a str, u64>,
    expanded: u64,
}

impl<'a> Scanner<'a> {
    fn new(text: &'a str) -> Scanner<'a> {
        Scanner {
            text,
            bytes: text.as_bytes(),
            at: 0,
            elements: 0,
            attributes: 0,
            entities: HashMap::new(),
            expanded: 0,
        }
    }

    fn run(mut self) -> Result<(), Refusal> {
        while let Some(lt) = find(self.bytes, self.at, b"<") {
            self.references(self.at, lt)?;
            self.at = lt;
            let rest = &self.bytes[lt..];
            let skipped = if rest.starts_with(b"<!--") {
                self.skip_past(b"-->")
            } else if rest.starts_with(b"<![CDATA[") {
                self.skip_past(b"]]>")
            } else if rest.starts_with(b"<?") {
                self.skip_past(b"?>")
            } else if rest.starts_with(b"<!DOCTYPE") {
                self.doctype()?
            } else if rest.starts_with(b"</") || rest.starts_with(b"<!") {
                self.skip_past(b">")
            } else {
                self.element()?
            };
            if !skipped {
                return Ok(());
            }
        }
        self.references(self.at, self.bytes.len())
    }

    /// Moves past the next `end`; false if there is none.
    fn skip_past(&mut self, end: &[u8]) -> bool {
        match find(self.bytes, self.at + 1, end) {
            Some(i) => {
                self.at = i + end.len();
                true
            }
            None => false,
        }
    }

    /// Counts the entity references in `from..to` (text or an attribute
    /// value) at their expanded sizes.
    fn references(&mut self, from: usize, to: usize) -> Result<(), Refusal> {
        if self.entities.is_empty() {
            return Ok(());
        }
        let mut i = from;
        while let Some(amp) = find(&self.bytes[..to], i, b"&") {
            let Some(semi) = find(&self.bytes[..to], amp, b";") else {
                break;
            };
            let name = &self.text[amp + 1..semi];
            if let Some(&size) = self.entities.get(name) {
                self.expanded = self.expanded.saturating_add(size);
                if self.expanded > MAX_EXPANSION {
                    return Err(Refusal::EntityExpansion {
                        at: place(self.bytes, amp),
                        limit_mib: MAX_EXPANSION >> 20,
                    });
                }
            }
            i = semi + 1;
        }
        Ok(())
    }

    /// A DOCTYPE: its internal subset's entity declarations, with their
    /// expanded sizes. False if it does not end.
    fn doctype(&mut self) -> Result<bool, Refusal> {
        let start = self.at;
        let Some(close) = self.doctype_end(start) else {
            return Ok(false);
        };
        let mut values: HashMap<&'a str, (&'a str, usize)> = HashMap::new();
        let mut i = start;
        while let Some(decl) = find(&self.bytes[..close], i, b"<!ENTITY") {
            i = decl + 8;
            // Parameter entities (`<!ENTITY % name …>`) are not expanded in
            // the document; the XML parser refuses what it cannot read.
            if let Some((name, value, end)) = entity(self.text, i, close)
                && name != "%"
            {
                values.entry(name).or_insert((value, decl));
                i = end;
            }
        }
        let names: Vec<&str> = values.keys().copied().collect();
        for name in names {
            let size = expanded_size(name, &values, &mut self.entities, 0).ok_or_else(|| {
                Refusal::EntityExpansion {
                    at: place(self.bytes, values[name].1),
                    limit_mib: MAX_EXPANSION >> 20,
                }
            })?;
            self.entities.insert(name, size);
        }
        self.at = close + 1;
        Ok(true)
    }

    /// The `>` that closes a DOCTYPE starting at `start` (past its internal
    /// subset in brackets, whose quoted values may hold `>`).
    fn doctype_end(&self, start: usize) -> Option<usize> {
        let mut quote = None;
        let mut depth = 0usize;
        for (i, &b) in self.bytes.iter().enumerate().skip(start + 2) {
            match (quote, b) {
                (Some(q), _) if b == q => quote = None,
                (Some(_), _) => {}
                (None, b'"' | b'\'') => quote = Some(b),
                (None, b'[') => depth += 1,
                (None, b']') => depth = depth.saturating_sub(1),
                (None, b'>') if depth == 0 => return Some(i),
                _ => {}
            }
        }
        None
    }

    /// A start tag: its attributes counted, their entity references and the
    /// numbers of geometry attributes checked. False if it does not end.
    fn element(&mut self) -> Result<bool, Refusal> {
        let start = self.at;
        self.elements += 1;
        if self.elements > MAX_ELEMENTS {
            return Err(Refusal::TooManyNodes);
        }
        let mut i = start + 1;
        let name_end = self.name_end(i);
        let tag = &self.text[i..name_end];
        i = name_end;
        let mut count = 0usize;
        loop {
            i = self.skip_space(i);
            match self.bytes.get(i) {
                None => return Ok(false),
                Some(b'>') => break,
                Some(b'/') => {
                    i += 1;
                    continue;
                }
                Some(_) => {}
            }
            let Some((name, value, end)) = self.attribute(i) else {
                // Not an attribute as XML writes one: the parser will say so.
                return Ok(self.skip_past(b">"));
            };
            count += 1;
            self.attributes += 1;
            if count > MAX_ATTRIBUTES {
                return Err(Refusal::TooManyAttributes {
                    at: place(self.bytes, start),
                    tag: tag.to_string(),
                    limit: MAX_ATTRIBUTES,
                });
            }
            if self.attributes > MAX_ALL_ATTRIBUTES {
                return Err(Refusal::TooMany {
                    what: "attributes",
                    limit: MAX_ALL_ATTRIBUTES,
                });
            }
            self.references(value.0, value.1)?;
            if GEOMETRY.contains(&name) {
                self.numbers(tag, name, value)?;
            }
            i = end;
        }
        self.at = i + 1;
        Ok(true)
    }

    /// The end of a name starting at `i`.
    fn name_end(&self, mut i: usize) -> usize {
        while let Some(&b) = self.bytes.get(i) {
            if b.is_ascii_whitespace() || b == b'>' || b == b'/' || b == b'=' {
                break;
            }
            i += 1;
        }
        i
    }

    fn skip_space(&self, mut i: usize) -> usize {
        while self.bytes.get(i).is_some_and(u8::is_ascii_whitespace) {
            i += 1;
        }
        i
    }

    /// An attribute `name = "value"` at `i`: its name, the value's range and
    /// where it ends.
    fn attribute(&self, i: usize) -> Option<(&'a str, (usize, usize), usize)> {
        let name_end = self.name_end(i);
        if name_end == i {
            return None;
        }
        let eq = self.skip_space(name_end);
        if self.bytes.get(eq) != Some(&b'=') {
            return None;
        }
        let open = self.skip_space(eq + 1);
        let quote = *self
            .bytes
            .get(open)
            .filter(|q| **q == b'"' || **q == b'\'')?;
        let close = find(self.bytes, open + 1, &[quote])?;
        Some((&self.text[i..name_end], (open + 1, close), close + 1))
    }

    /// Refuses a number in `value` that a 32-bit float cannot hold.
    fn numbers(&self, tag: &str, attribute: &str, value: (usize, usize)) -> Result<(), Refusal> {
        let v = &self.bytes[value.0..value.1];
        let mut i = 0;
        while i < v.len() {
            let starts = v[i].is_ascii_digit()
                || (v[i] == b'.' && v.get(i + 1).is_some_and(u8::is_ascii_digit));
            if !starts {
                i += 1;
                continue;
            }
            let end = number_end(v, i);
            let text = &self.text[value.0 + i..value.0 + end];
            if text
                .parse::<f64>()
                .is_ok_and(|n| !(n.is_finite() && n <= MAX_NUMBER))
            {
                return Err(Refusal::NumberTooLarge {
                    at: place(self.bytes, value.0 + i),
                    number: format!("{text} in `{attribute}` of `<{tag}>`"),
                });
            }
            i = end;
        }
        Ok(())
    }
}

/// The end of the number starting at `i` (digits, a point, digits, an
/// exponent).
fn number_end(v: &[u8], mut i: usize) -> usize {
    let digits = |v: &[u8], mut i: usize| {
        while v.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    i = digits(v, i);
    if v.get(i) == Some(&b'.') {
        i = digits(v, i + 1);
    }
    if matches!(v.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(v.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if v.get(j).is_some_and(u8::is_ascii_digit) {
            i = digits(v, j);
        }
    }
    i
}

/// How deep entities may refer to entities (the XML parser stops at 10).
const MAX_ENTITY_DEPTH: usize = 16;

/// The expanded size of entity `name` (`values`: each declared entity's
/// value and place), remembered in `sizes`; `None` past `MAX_EXPANSION`
/// or `MAX_ENTITY_DEPTH` (an entity that contains itself too).
fn expanded_size<'a>(
    name: &'a str,
    values: &HashMap<&'a str, (&'a str, usize)>,
    sizes: &mut HashMap<&'a str, u64>,
    depth: usize,
) -> Option<u64> {
    if let Some(&s) = sizes.get(name) {
        return Some(s);
    }
    if depth > MAX_ENTITY_DEPTH {
        return None;
    }
    let (value, _) = values.get(name)?;
    let mut size = 0u64;
    let mut rest = *value;
    while let Some(amp) = rest.find('&') {
        size += amp as u64;
        let after = &rest[amp + 1..];
        let Some(semi) = after.find(';') else {
            size += after.len() as u64 + 1;
            rest = "";
            break;
        };
        let inner = &after[..semi];
        let part = if values.contains_key(inner) {
            expanded_size(inner, values, sizes, depth + 1)?
        } else {
            semi as u64 + 2
        };
        size = size.saturating_add(part);
        rest = &after[semi + 1..];
    }
    size = size.saturating_add(rest.len() as u64);
    if size > MAX_EXPANSION {
        return None;
    }
    sizes.insert(name, size);
    Some(size)
}

/// An entity declaration's name and quoted value, from just after
/// `<!ENTITY` (before `limit`), and where it ends.
fn entity(text: &str, from: usize, limit: usize) -> Option<(&str, &str, usize)> {
    let bytes = text.as_bytes();
    let mut i = from;
    let skip = |mut i: usize| {
        while i < limit && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        i
    };
    i = skip(i);
    let name_start = i;
    while i < limit && !bytes[i].is_ascii_whitespace() {
        i += 1;
    }
    let name = &text[name_start..i];
    i = skip(i);
    let quote = *bytes.get(i).filter(|q| **q == b'"' || **q == b'\'')?;
    let close = find(&bytes[..limit], i + 1, &[quote])?;
    Some((name, &text[i + 1..close], close + 1))
}

/// The first `needle` in `hay` at or after `from`.
fn find(hay: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    if from >= hay.len() || needle.is_empty() {
        return None;
    }
    if needle.len() == 1 {
        return hay[from..]
            .iter()
            .position(|&b| b == needle[0])
            .map(|p| p + from);
    }
    hay[from..]
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|p| p + from)
}

/// The line and column (from 1, columns in characters) of a byte offset.
fn place(bytes: &[u8], at: usize) -> Place {
    let before = &bytes[..at.min(bytes.len())];
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    Place { line, column }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = r#"<svg xmlns="http://www.w3.org/2000/svg">"#;

    #[test]
    fn ordinary_drawings_pass() {
        let plain = format!(
            r#"<?xml version="1.0"?><!-- a > b --><!DOCTYPE svg [ <!ENTITY ns "http://www.w3.org/2000/svg"> ]>{HEAD}<path d="M0 0L1.5e3 .5e-2z" title="&ns;"/><![CDATA[ <x> ]]></svg>"#
        );
        assert_eq!(scan(&plain), Ok(()));
        assert_eq!(scan("not xml at all"), Ok(()));
        assert_eq!(scan("<svg <broken"), Ok(()));
    }

    #[test]
    fn blow_ups_are_refused_before_parsing() {
        let mut bomb = String::from("<!DOCTYPE svg [<!ENTITY a \"");
        bomb.push_str(&"x".repeat(10_000));
        bomb.push_str("\"><!ENTITY b \"");
        bomb.push_str(&"&a;".repeat(255));
        bomb.push_str("\">]>");
        bomb.push_str(HEAD);
        bomb.push_str(&"<text>&b;</text>".repeat(10));
        bomb.push_str("</svg>");
        assert!(matches!(scan(&bomb), Err(Refusal::EntityExpansion { .. })));
        let attrs: String = (0..2000).map(|i| format!(" a{i}=\"1\"")).collect();
        let wide = format!("{HEAD}\n<path{attrs}/></svg>");
        assert_eq!(
            scan(&wide),
            Err(Refusal::TooManyAttributes {
                at: Place { line: 2, column: 1 },
                tag: "path".into(),
                limit: MAX_ATTRIBUTES
            })
        );
        let huge = format!("{HEAD}<path d=\"M0 0 L1e308 1\"/></svg>");
        assert!(matches!(
            scan(&huge),
            Err(Refusal::NumberTooLarge { ref number, .. }) if number == "1e308 in `d` of `<path>`"
        ));
        let fine = format!("{HEAD}<path d=\"M0 0 L3e38 1\" id=\"1e999\"/></svg>");
        assert_eq!(scan(&fine), Ok(()));
    }
}
