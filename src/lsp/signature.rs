//! Signature help: inside a module's or a function's parentheses, its
//! parameters with the one being typed highlighted.
//!
//! Owns: finding the call around the cursor. The call is read from the text
//! (the open parenthesis the cursor is inside, the name before it, the commas
//! before the cursor), because a statement being typed rarely parses; what
//! the name means comes from the AST (a `module` declaration, the rules of a
//! letter), `query` (query modules), `builtins` and `words` (turtle symbols).

use super::analysis::Analysis;
use super::hover::in_line_comment;
use super::index::{Kind, Origin, Target};
use super::words;
use crate::ast::{ExprKind, Item, ModName, Stmt};
use crate::{builtins, query};
use lsp_types::{
    Documentation, MarkupContent, MarkupKind, ParameterInformation, ParameterLabel, SignatureHelp,
    SignatureInformation,
};

/// The open `(` before `offset` that is not closed before it, and the number
/// of commas at its depth between them. Stops at a statement's end.
fn open_paren(text: &str, offset: usize) -> Option<(usize, usize)> {
    let mut depth = 0usize;
    let mut commas = 0usize;
    for (i, c) in text[..offset].char_indices().rev() {
        match c {
            ')' => depth += 1,
            '(' if depth == 0 => return Some((i, commas)),
            '(' => depth -= 1,
            ',' if depth == 0 => commas += 1,
            ';' | '{' | '}' if depth == 0 => return None,
            _ => {}
        }
    }
    None
}

/// The name written right before a `(`: a word, a `?query`, or one symbol.
fn callee(text: &str, paren: usize) -> Option<(usize, &str)> {
    let before = &text[..paren];
    let start = before
        .char_indices()
        .rev()
        .take_while(|(_, c)| c.is_alphanumeric() || *c == '_')
        .last()
        .map(|(i, _)| i);
    match start {
        Some(s) => {
            let s = if before[..s].ends_with('?') { s - 1 } else { s };
            Some((s, &before[s..]))
        }
        None => {
            let (i, c) = before.char_indices().next_back()?;
            words::turtle(c).map(|_| (i, &before[i..]))
        }
    }
}

fn info(label: String, params: Vec<String>, doc: String, active: usize) -> SignatureInformation {
    SignatureInformation {
        label,
        documentation: (!doc.is_empty()).then_some(Documentation::MarkupContent(MarkupContent {
            kind: MarkupKind::Markdown,
            value: doc,
        })),
        parameters: Some(
            params
                .into_iter()
                .map(|p| ParameterInformation {
                    label: ParameterLabel::Simple(p),
                    documentation: None,
                })
                .collect(),
        ),
        active_parameter: u32::try_from(active).ok(),
    }
}

/// The parameter names of the rules' predecessors for module `name` in the
/// lsystem at item `ls` (the first rule that binds names there).
fn rule_params(a: &Analysis, ls: usize, name: &str) -> Option<Vec<String>> {
    let Some(Item::Lsystem(l)) = a.file.items.stmts.get(ls).map(|n| &n.node) else {
        return None;
    };
    l.body.stmts.iter().find_map(|st| match &st.node {
        Stmt::Rule(r) if r.pred.name == ModName::Name(name.to_string()) => {
            let args = r.pred.args.as_ref()?;
            Some(
                args.iter()
                    .enumerate()
                    .map(|(k, e)| match &e.kind {
                        ExprKind::Var(v) => v.clone(),
                        _ => format!("p{}", k + 1),
                    })
                    .collect(),
            )
        }
        _ => None,
    })
}

pub fn signature_help(a: &Analysis, offset: usize) -> Option<SignatureHelp> {
    let offset = offset.min(a.text.len());
    if !a.text.is_char_boundary(offset) || in_line_comment(&a.text, offset) {
        return None;
    }
    let (paren, active) = open_paren(&a.text, offset)?;
    let (start, name) = callee(&a.text, paren)?;
    // In a predecessor (before `->` on the statement) a query module is
    // written with its outputs; in a successor with its pass-through values.
    let stmt_start = a.text[..start].rfind([';', '{']).map_or(0, |i| i + 1);
    let in_successor = a.text[stmt_start..start].contains("->");
    let sig = if let Some(q) = name.strip_prefix('?').and(query::lookup(name)) {
        let mut params: Vec<String> = Vec::new();
        if !in_successor {
            params.extend(q.outputs.iter().map(|s| s.to_string()));
        }
        params.extend(q.inputs.iter().map(|s| s.to_string()));
        params.push("…".to_string());
        let what = if in_successor {
            "in a successor: the pass-through values only"
        } else {
            "in a predecessor or context: the outputs, then the pass-through parameters"
        };
        info(
            format!("{}({})", q.name, params.join(", ")),
            params,
            format!("{}.\n\nWritten {what}.", q.doc),
            active,
        )
    } else if let Some(b) = builtins::lookup(name) {
        let params: Vec<String> = (0..b.arity)
            .map(|i| ["x", "y", "z"][i.min(2)].to_string())
            .collect();
        info(
            format!("{}({})", b.name, params.join(", ")),
            params,
            b.doc.to_string(),
            active,
        )
    } else if name == "tropism" {
        let k = words::word("tropism")?;
        info(
            "tropism(e)".to_string(),
            vec!["e".to_string()],
            k.doc.to_string(),
            active,
        )
    } else if let Some(w) = name
        .chars()
        .next()
        .filter(|_| name.chars().count() == 1)
        .and_then(words::turtle)
        && w.form.contains('(')
        && !matches!(
            a.index.at(start).map(|o| &o.target),
            Some(Target::Symbol(id)) if !a.index.symbols[*id].rules.is_empty()
        )
    {
        let p = w.form[2..w.form.len() - 1].to_string();
        info(
            w.form.to_string(),
            vec![p],
            format!("Turtle: {}.", w.meaning),
            active,
        )
    } else {
        // A module of the file: declared, or a letter its rules give names.
        let o = a
            .index
            .at(start)
            .filter(|o| o.span.start as usize == start)?;
        let Target::Symbol(id) = &o.target else {
            return None;
        };
        let s = &a.index.symbols[*id];
        let params: Vec<String> = match (&s.origin, s.kind) {
            (Origin::Item(i), Kind::Module) => match a.file.items.stmts.get(*i).map(|n| &n.node) {
                Some(Item::Module(m)) => m.params.iter().map(|p| p.name.clone()).collect(),
                _ => return None,
            },
            (Origin::LsystemStmt(i, j), Kind::Module) => {
                match a.file.items.stmts.get(*i).map(|n| &n.node) {
                    Some(Item::Lsystem(l)) => match l.body.stmts.get(*j).map(|n| &n.node) {
                        Some(Stmt::Module(m)) => m.params.iter().map(|p| p.name.clone()).collect(),
                        _ => return None,
                    },
                    _ => return None,
                }
            }
            (Origin::Letter(i), _) => rule_params(a, *i, &s.name)?,
            _ => return None,
        };
        let doc = match s.kind {
            Kind::Letter => format!(
                "Module `{}`, named as its rules' predecessor binds them.",
                s.name
            ),
            _ => format!("Module `{}` as declared.", s.name),
        };
        info(
            format!("{}({})", s.name, params.join(", ")),
            params,
            doc,
            active,
        )
    };
    Some(SignatureHelp {
        signatures: vec![sig],
        active_signature: Some(0),
        active_parameter: u32::try_from(active).ok(),
    })
}
