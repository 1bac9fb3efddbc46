//! Code actions: the quick fixes the checker attaches to its diagnostics.
//!
//! Owns: offering each `diagnostic::Fix` whose diagnostic touches the
//! requested range as a quick fix. The fixes themselves are made where the
//! problem is found (the lexer, parser and checker: a did-you-mean name, a
//! cpfg spelling rewritten, a missing `;`); nothing is re-derived here.

use super::analysis::Analysis;
use lsp_types as lsp;
use std::collections::HashMap;

/// Whether two ranges touch (a cursor at either end of a range touches it).
fn touches(a: &lsp::Range, b: &lsp::Range) -> bool {
    a.start <= b.end && b.start <= a.end
}

// `WorkspaceEdit::changes` is keyed by `Uri`, which clippy deems mutable.
#[allow(clippy::mutable_key_type)]
pub fn quick_fixes(a: &Analysis, uri: &lsp::Uri, range: lsp::Range) -> Vec<lsp::CodeAction> {
    let mut out = Vec::new();
    for d in &a.diagnostics {
        if d.fixes.is_empty() {
            continue;
        }
        let diag = a.convert(d, uri);
        if !touches(&diag.range, &range) {
            continue;
        }
        for f in &d.fixes {
            let edits: Vec<lsp::TextEdit> = f
                .edits
                .iter()
                .map(|(span, text)| lsp::TextEdit {
                    range: a.range(*span),
                    new_text: text.clone(),
                })
                .collect();
            let mut changes = HashMap::new();
            changes.insert(uri.clone(), edits);
            out.push(lsp::CodeAction {
                title: f.title.clone(),
                kind: Some(lsp::CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![diag.clone()]),
                edit: Some(lsp::WorkspaceEdit {
                    changes: Some(changes),
                    ..Default::default()
                }),
                is_preferred: Some(d.fixes.len() == 1),
                ..Default::default()
            });
        }
    }
    out
}
