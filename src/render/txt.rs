//! The derived string as text in the language's own syntax: modules written
//! without parameters stay bare, so `F -> F-F+F` prints just its letters.

use crate::ast::ModName;
use crate::compile::Program;
use crate::derive::ModString;
use std::io::{self, Write};

/// Writes `s` followed by a newline.
pub fn write(out: &mut dyn Write, prog: &Program, s: &ModString) -> io::Result<()> {
    let info = &prog.symbols.info;
    // With multi-letter modules about, letters are spaced so that no run of them
    // can read as one of those names.
    let multi = info
        .iter()
        .any(|i| matches!(&i.name, ModName::Name(n) if n.chars().count() > 1));
    let texts: Vec<String> = info.iter().map(|i| i.name.text().into_owned()).collect();
    let mut buf = Vec::with_capacity(1 << 16);
    let mut p = 0usize;
    // (name-like, had parameters, single letter, last char)
    let mut prev: Option<(bool, bool, bool, char)> = None;
    for &sym in &s.syms {
        let i = &info[sym as usize];
        let n = i.arity as usize;
        let params = &s.params[p..p + n];
        p += n;
        let text = &texts[sym as usize];
        let name_like = matches!(i.name, ModName::Name(_) | ModName::Query(_) | ModName::Cut);
        let single = text.chars().count() == 1 && matches!(i.name, ModName::Name(_));
        let first = text.chars().next().unwrap_or(' ');
        if let Some((pn, pargs, psingle, plast)) = prev {
            let space = if pargs {
                name_like
            } else if pn && name_like {
                multi || !(psingle && single)
            } else {
                plast == '/' && (first == '/' || first == '*')
            };
            if space {
                buf.push(b' ');
            }
        }
        buf.extend_from_slice(text.as_bytes());
        if n > 0 {
            buf.push(b'(');
            for (k, v) in params.iter().enumerate() {
                if k > 0 {
                    buf.extend_from_slice(b", ");
                }
                buf.extend_from_slice(crate::fmt::format_number(*v).as_bytes());
            }
            buf.push(b')');
        }
        prev = Some((name_like, n > 0, single, text.chars().last().unwrap_or(' ')));
        if buf.len() >= 1 << 16 {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    buf.push(b'\n');
    out.write_all(&buf)
}
