//! Rename: a constant, a module (declared, an element, or a letter of one
//! lsystem), an lsystem, a scene, a guide or a parameter, everywhere in the
//! file it means the same thing.
//!
//! Owns: which renames are allowed. A new name must be a name of the
//! language (not a keyword), must not be taken in the same namespace, and the
//! renamed program must mean the same: it is analysed again and every symbol
//! must keep its number of uses and no new error may appear (so a rename never
//! lets a parameter capture a constant, or a module name swallow its
//! neighbours in a run of letters).

use super::analysis::Analysis;
use super::index::{Index, Kind, Target};
use crate::lexer::{Token, lex};
use crate::resolve::is_letter;
use crate::span::Span;
use lsp_types::TextEdit;

/// The name at an offset that can be renamed, with its span.
pub fn prepare(a: &Analysis, offset: usize) -> Result<(Span, String), String> {
    let occ = a
        .index
        .at(offset)
        .ok_or("there is no name here to rename")?;
    match &occ.target {
        Target::Symbol(id) => Ok((occ.span, a.index.symbols[*id].name.clone())),
        Target::Query(_) => {
            Err("query modules are the environment's; they cannot be renamed".into())
        }
        Target::Turtle(_) | Target::Cut => Err("turtle symbols cannot be renamed".into()),
        Target::Function(_) => Err("built-in functions cannot be renamed".into()),
        Target::Word(w) => Err(format!(
            "`{w}` is a word of the language; it cannot be renamed"
        )),
    }
}

/// Counts of uses per symbol, the shape a rename must keep.
fn shape(ix: &Index) -> Vec<usize> {
    let mut counts = vec![0usize; ix.symbols.len()];
    for o in &ix.occurrences {
        if let Target::Symbol(id) = o.target {
            counts[id] += 1;
        }
    }
    counts.sort_unstable();
    counts
}

pub fn rename(a: &Analysis, offset: usize, new_name: &str) -> Result<Vec<TextEdit>, String> {
    let (_, old) = prepare(a, offset)?;
    let occ = a
        .index
        .at(offset)
        .ok_or("there is no name here to rename")?;
    let Target::Symbol(id) = occ.target else {
        return Err("only names can be renamed".into());
    };
    let sym = &a.index.symbols[id];
    let lexed = lex(new_name);
    let is_name = lexed.diagnostics.is_empty()
        && matches!(&lexed.tokens[..], [(_, Token::Ident(n), _)] if n == new_name);
    if !is_name {
        return Err(format!(
            "`{new_name}` is not a name (names are letters, digits and `_`, and not a keyword)"
        ));
    }
    if new_name == old {
        return Ok(Vec::new());
    }
    if sym.kind == Kind::Letter && !is_letter(new_name) {
        return Err(format!(
            "`{old}` is an undeclared single-letter module; `{new_name}` would be read as several modules (declare `module {new_name};` first, or choose one letter)"
        ));
    }
    if matches!(sym.kind, Kind::Letter | Kind::Module | Kind::Element)
        && matches!(new_name, "F" | "f")
    {
        return Err(
            "`F` and `f` draw and move; a module renamed to them would change the drawing".into(),
        );
    }
    let module_like = |k: Kind| matches!(k, Kind::Module | Kind::Element | Kind::Letter);
    let clash = a.index.symbols.iter().any(|s| {
        s.name == new_name
            && match sym.kind {
                Kind::Const => s.kind == Kind::Const,
                Kind::Lsystem | Kind::Scene => s.kind == sym.kind,
                Kind::Guide => s.kind == Kind::Guide && s.scope == sym.scope,
                Kind::Param => s.kind == Kind::Param && s.origin_rule() == sym.origin_rule(),
                // A file-wide module clashes with any module of that name.
                _ if sym.scope.is_none() => module_like(s.kind),
                _ => module_like(s.kind) && (s.scope.is_none() || s.scope == sym.scope),
            }
    });
    if clash {
        return Err(format!(
            "`{new_name}` is already a {} here",
            sym.kind.noun()
        ));
    }
    let spans: Vec<Span> = a
        .index
        .occurrences_of(&Target::Symbol(id))
        .map(|o| o.span)
        .collect();
    // Check that the renamed program means the same.
    let mut text = a.text.clone();
    for s in spans.iter().rev() {
        text.replace_range(s.range(), new_name);
    }
    let after = Analysis::new(text);
    let errors = |x: &Analysis| x.diagnostics.iter().filter(|d| d.is_error()).count();
    if errors(&after) > errors(a) || shape(&after.index) != shape(&a.index) {
        return Err(format!(
            "renaming `{old}` to `{new_name}` would change what the program means (a name would refer to something else)"
        ));
    }
    Ok(spans
        .iter()
        .map(|s| TextEdit {
            range: a.range(*s),
            new_text: new_name.to_string(),
        })
        .collect())
}
