//! Document symbols: the file's outline of constants, modules, elements,
//! lsystems with their rules, and scenes with their guides and links.

use super::analysis::Analysis;
use crate::ast::{Item, SceneStmt, Stmt};
use crate::fmt::format_expr;
use crate::span::Span;
use lsp_types::{DocumentSymbol, SymbolKind};

#[allow(deprecated)] // `DocumentSymbol::deprecated` must be written, as `None`
fn sym(
    a: &Analysis,
    name: String,
    detail: Option<String>,
    kind: SymbolKind,
    span: Span,
    select: Span,
    children: Vec<DocumentSymbol>,
) -> DocumentSymbol {
    let span = span.to(select);
    DocumentSymbol {
        name: if name.is_empty() {
            "?".to_string()
        } else {
            name
        },
        detail,
        kind,
        tags: None,
        deprecated: None,
        range: a.range(span),
        selection_range: a.range(select),
        children: (!children.is_empty()).then_some(children),
    }
}

fn one_line(s: &str, max: usize) -> String {
    let s: String = s.split_whitespace().collect::<Vec<_>>().join(" ");
    if s.chars().count() > max {
        s.chars().take(max - 1).collect::<String>() + "…"
    } else {
        s
    }
}

pub fn outline(a: &Analysis) -> Vec<DocumentSymbol> {
    let mut out = Vec::new();
    for item in &a.file.items.stmts {
        let span = item.span;
        match &item.node {
            Item::Const(c) => out.push(sym(
                a,
                c.name.name.clone(),
                Some(format!("= {}", format_expr(&c.value))),
                SymbolKind::CONSTANT,
                span,
                c.name.span,
                Vec::new(),
            )),
            Item::Module(m) => out.push(sym(
                a,
                m.name.name.clone(),
                Some(format!("module({})", m.params.len())),
                SymbolKind::STRUCT,
                span,
                m.name.span,
                Vec::new(),
            )),
            Item::Element(e) => out.push(sym(
                a,
                e.name.name.clone(),
                Some("element".to_string()),
                SymbolKind::OBJECT,
                span,
                e.name.span,
                Vec::new(),
            )),
            Item::Lsystem(l) => {
                let mut children = Vec::new();
                for st in &l.body.stmts {
                    match &st.node {
                        Stmt::Rule(r) => {
                            let mut name = a.slice(r.pred.span).to_string();
                            if let Some(lbl) = &r.label {
                                name = format!("{}: {name}", lbl.name);
                            }
                            let succ = r
                                .succ
                                .first()
                                .zip(r.succ.last())
                                .map(|(f, l)| a.slice(f.span.to(l.span)))
                                .unwrap_or("ε");
                            // Which phase the rule belongs to, as the source says it.
                            let phase = if r.interpret {
                                "interpret "
                            } else if r.decompose {
                                "decompose "
                            } else {
                                ""
                            };
                            children.push(sym(
                                a,
                                one_line(&name, 60),
                                Some(one_line(&format!("{phase}-> {succ}"), 60)),
                                SymbolKind::METHOD,
                                st.span,
                                r.pred.span,
                                Vec::new(),
                            ));
                        }
                        Stmt::Module(m) => children.push(sym(
                            a,
                            m.name.name.clone(),
                            Some(format!("module({})", m.params.len())),
                            SymbolKind::STRUCT,
                            st.span,
                            m.name.span,
                            Vec::new(),
                        )),
                        _ => {}
                    }
                }
                out.push(sym(
                    a,
                    l.name.name.clone(),
                    Some("lsystem".to_string()),
                    SymbolKind::CLASS,
                    span,
                    l.name.span,
                    children,
                ));
            }
            Item::Scene(s) => {
                let mut children = Vec::new();
                for st in &s.body.stmts {
                    match &st.node {
                        SceneStmt::Guide(g) => children.push(sym(
                            a,
                            g.name.name.clone(),
                            Some("guide".to_string()),
                            SymbolKind::OBJECT,
                            st.span,
                            g.name.span,
                            Vec::new(),
                        )),
                        SceneStmt::Link(l) => children.push(sym(
                            a,
                            one_line(a.slice(l.from.span.to(l.to.span)), 60),
                            Some("link".to_string()),
                            SymbolKind::EVENT,
                            st.span,
                            l.from.span,
                            Vec::new(),
                        )),
                        _ => {}
                    }
                }
                out.push(sym(
                    a,
                    s.name.name.clone(),
                    Some("scene".to_string()),
                    SymbolKind::NAMESPACE,
                    span,
                    s.name.span,
                    children,
                ));
            }
            _ => {}
        }
    }
    out
}
