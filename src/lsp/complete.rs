//! Completion: the names in scope where the cursor is, query modules with
//! their signatures, turtle symbols, built-in functions and keywords.
//!
//! Owns: which candidates fit where. The enclosing item comes from the AST;
//! the parameters of the statement being typed are read from its tokens,
//! because a statement being typed rarely parses.

use super::analysis::Analysis;
use super::hover::{query_text, turtle_text};
use super::index::{Kind, Origin, Symbol};
use super::words::{self, Context};
use crate::ast::Item;
use crate::lexer::{Token, lex};
use crate::span::Span;
use crate::{builtins, query};
use lsp_types::{
    CompletionItem, CompletionItemKind, CompletionTextEdit, Documentation, MarkupContent,
    MarkupKind, TextEdit,
};

/// Where the cursor is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    Top,
    Lsystem(usize),
    Scene(usize),
    Element,
}

fn place(a: &Analysis, offset: usize) -> Place {
    let off = offset as u32;
    for (i, item) in a.file.items.stmts.iter().enumerate() {
        if item.span.start < off && off < item.span.end {
            return match &item.node {
                Item::Lsystem(_) => Place::Lsystem(i),
                Item::Scene(_) => Place::Scene(i),
                Item::Element(_) => Place::Element,
                _ => Place::Top,
            };
        }
    }
    Place::Top
}

/// The start of the name being typed before `offset` (a `?` included).
fn prefix_start(text: &str, offset: usize) -> usize {
    let mut start = offset;
    for (i, c) in text[..offset].char_indices().rev() {
        if c.is_alphanumeric() || c == '_' {
            start = i;
        } else {
            if c == '?' {
                start = i;
            }
            break;
        }
    }
    start
}

/// The parameters a rule being typed binds: names inside the parentheses of
/// its predecessor (and contexts), before `:` or `->`.
fn typed_params(text: &str, offset: usize, item_start: usize) -> (Vec<String>, bool) {
    let before = &text[item_start..offset];
    // The statement starts after the last `;`, or after the lsystem's `{`
    // (braces inside a body are polygon symbols, not blocks).
    let open = before.find('{').map_or(0, |i| i + 1);
    let start = before.rfind(';').map_or(0, |i| i + 1).max(open);
    let stmt = &before[start..];
    let lexed = lex(stmt);
    let toks: Vec<&Token> = lexed.tokens.iter().map(|(_, t, _)| t).collect();
    let is_axiom = matches!(toks.first(), Some(Token::Axiom));
    let head_end = toks
        .iter()
        .position(|t| matches!(t, Token::Colon | Token::Arrow));
    let mut names = Vec::new();
    if let Some(end) = head_end {
        let mut depth = 0i32;
        for t in &toks[..end] {
            match t {
                Token::LParen => depth += 1,
                Token::RParen => depth -= 1,
                Token::Ident(n) if depth > 0 && n != "_" && !names.contains(n) => {
                    names.push(n.clone())
                }
                _ => {}
            }
        }
    }
    (names, is_axiom)
}

fn md(text: String) -> Option<Documentation> {
    Some(Documentation::MarkupContent(MarkupContent {
        kind: MarkupKind::Markdown,
        value: text,
    }))
}

struct Out {
    items: Vec<CompletionItem>,
    range: lsp_types::Range,
}

impl Out {
    fn push(
        &mut self,
        label: &str,
        kind: CompletionItemKind,
        detail: Option<String>,
        doc: Option<String>,
        rank: u8,
    ) {
        if self
            .items
            .iter()
            .any(|i| i.label == label && i.kind == Some(kind))
        {
            return;
        }
        self.items.push(CompletionItem {
            label: label.to_string(),
            kind: Some(kind),
            detail,
            documentation: doc.and_then(md),
            sort_text: Some(format!("{rank}_{label}")),
            text_edit: Some(CompletionTextEdit::Edit(TextEdit {
                range: self.range,
                new_text: label.to_string(),
            })),
            ..CompletionItem::default()
        });
    }
}

fn symbol_item(out: &mut Out, a: &Analysis, s: &Symbol) {
    let (kind, rank) = match s.kind {
        Kind::Const => (CompletionItemKind::CONSTANT, 2),
        Kind::Module | Kind::Letter => (CompletionItemKind::MODULE, 3),
        Kind::Element => (CompletionItemKind::STRUCT, 3),
        Kind::Lsystem => (CompletionItemKind::CLASS, 3),
        Kind::Scene => return,
        Kind::Guide => (CompletionItemKind::FIELD, 3),
        Kind::Param => (CompletionItemKind::VARIABLE, 1),
    };
    let detail = match (&s.origin, s.kind) {
        (Origin::Item(i), Kind::Const) => match a.file.items.stmts.get(*i).map(|n| &n.node) {
            Some(Item::Const(c)) => Some(format!(
                "const {} = {}",
                c.name.name,
                crate::fmt::format_expr(&c.value)
            )),
            _ => None,
        },
        _ => Some(s.kind.noun().to_string()),
    };
    out.push(&s.name, kind, detail, None, rank);
}

pub fn complete(a: &Analysis, offset: usize) -> Vec<CompletionItem> {
    let offset = offset.min(a.text.len());
    if !a.text.is_char_boundary(offset) || super::hover::in_line_comment(&a.text, offset) {
        return Vec::new();
    }
    let start = prefix_start(&a.text, offset);
    let mut out = Out {
        items: Vec::new(),
        range: a.range(Span::new(start, offset)),
    };
    let place = place(a, offset);
    let typing_query = a.text[start..offset].starts_with('?');
    let queries = |out: &mut Out| {
        for q in query::QUERIES {
            out.push(
                q.name,
                CompletionItemKind::FUNCTION,
                Some(q.signature()),
                Some(query_text(q.name)),
                4,
            );
        }
    };
    if typing_query {
        queries(&mut out);
        return out.items;
    }
    let consts: Vec<&Symbol> = a
        .index
        .visible(None)
        .filter(|s| s.kind == Kind::Const)
        .collect();
    let keywords = |out: &mut Out, ctx: &[Context]| {
        for k in words::KEYWORDS.iter().filter(|k| ctx.contains(&k.context)) {
            out.push(
                k.word,
                CompletionItemKind::KEYWORD,
                None,
                Some(k.doc.to_string()),
                5,
            );
        }
    };
    let functions = |out: &mut Out| {
        for b in builtins::BUILTINS {
            out.push(
                b.name,
                CompletionItemKind::FUNCTION,
                Some(format!("{}/{}", b.name, b.arity)),
                Some(b.doc.to_string()),
                6,
            );
        }
    };
    match place {
        Place::Top => keywords(&mut out, &[Context::Top]),
        Place::Element => {
            keywords(&mut out, &[Context::Element]);
            for s in &consts {
                symbol_item(&mut out, a, s);
            }
            functions(&mut out);
        }
        Place::Scene(i) => {
            keywords(&mut out, &[Context::Scene, Context::Guide, Context::Link]);
            for s in a.index.visible(Some(i)) {
                if matches!(s.kind, Kind::Const | Kind::Lsystem | Kind::Guide) {
                    symbol_item(&mut out, a, s);
                }
            }
            functions(&mut out);
        }
        Place::Lsystem(i) => {
            let item_start = a.file.items.stmts[i].span.start as usize;
            let (params, is_axiom) = typed_params(&a.text, offset, item_start);
            for p in &params {
                out.push(
                    p,
                    CompletionItemKind::VARIABLE,
                    Some("rule parameter".to_string()),
                    None,
                    1,
                );
            }
            if is_axiom {
                for s in a.index.visible(Some(i)) {
                    if matches!(s.origin, Origin::LsystemParam(j, _) if j == i) {
                        symbol_item(&mut out, a, s);
                    }
                }
            }
            for s in a.index.visible(Some(i)) {
                if matches!(
                    s.kind,
                    Kind::Const | Kind::Module | Kind::Element | Kind::Letter
                ) {
                    symbol_item(&mut out, a, s);
                }
            }
            queries(&mut out);
            keywords(&mut out, &[Context::Lsystem, Context::Anywhere]);
            for w in words::TURTLE {
                out.push(
                    &w.symbol.to_string(),
                    CompletionItemKind::OPERATOR,
                    Some(w.form.to_string()),
                    Some(turtle_text(w)),
                    7,
                );
            }
            functions(&mut out);
        }
    }
    out.items
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_in_comments_and_places_decide() {
        let text = "// derive\nconst k = 2;\nlsystem A(n) {\n    axiom F(n);\n    F(x) -> {F(x * k) // x\n;\n}\n";
        let a = Analysis::new(text.to_string());
        let labels = |off: usize| -> Vec<String> {
            complete(&a, off).into_iter().map(|i| i.label).collect()
        };
        assert!(labels(5).is_empty(), "inside a comment");
        assert!(labels(text.find("// x").expect("x") + 4).is_empty());
        let top = labels(text.find("const").expect("const"));
        assert!(
            top.contains(&"lsystem".to_string()) && !top.contains(&"axiom".to_string()),
            "{top:?}"
        );
        let rule = labels(text.find("x * k").expect("rule") + 4);
        for want in ["x", "k", "F", "?X", "+", "axiom", "sqrt"] {
            assert!(rule.contains(&want.to_string()), "{want}: {rule:?}");
        }
        assert!(
            !rule.contains(&"n".to_string()),
            "the lsystem's parameter is the axiom's only"
        );
        let axiom = labels(text.find("F(n)").expect("axiom") + 2);
        assert!(axiom.contains(&"n".to_string()), "{axiom:?}");
    }
}
