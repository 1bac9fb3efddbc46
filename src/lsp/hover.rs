//! Hover: what the name under the cursor is, where it is declared, and what
//! the language says about it.
//!
//! Owns: the hover texts. Facts come from the index (declarations, rules),
//! the checker (constants' values), `query` (signatures), `builtins` and
//! `words` (turtle symbols, keywords); nothing is computed here twice.

use super::analysis::Analysis;
use super::index::{Kind, Origin, Symbol, Target};
use super::words;
use crate::ast::{Item, ModName, Node, Stmt, Trivia};
use crate::check::Value;
use crate::fmt::{format_expr, format_number};
use crate::{builtins, query};
use lsp_types as lsp;

/// The hover text at a byte offset, or `None` where there is nothing to say.
pub fn hover(a: &Analysis, offset: usize) -> Option<lsp::Hover> {
    let (text, span) = match a.index.at(offset) {
        Some(o) => (target_text(a, &o.target)?, o.span),
        None if in_line_comment(&a.text, offset) => return None,
        None => {
            let (word, span) = word_at(&a.text, offset)?;
            let k = words::keyword(word)?;
            (format!("```lsy\n{}\n```\n\n{}", k.word, k.doc), span)
        }
    };
    Some(lsp::Hover {
        contents: lsp::HoverContents::Markup(lsp::MarkupContent {
            kind: lsp::MarkupKind::Markdown,
            value: text,
        }),
        range: Some(a.range(span)),
    })
}

/// Whether an offset is after `//` on its line (outside a string).
pub fn in_line_comment(text: &str, offset: usize) -> bool {
    let offset = offset.min(text.len());
    let Some(before) = text.get(..offset) else {
        return false;
    };
    let line = &before[before.rfind('\n').map_or(0, |i| i + 1)..];
    let mut in_str = false;
    let mut prev = ' ';
    for c in line.chars() {
        match c {
            '"' if prev != '\\' => in_str = !in_str,
            '/' if prev == '/' && !in_str => return true,
            _ => {}
        }
        prev = c;
    }
    false
}

/// The word (letters, digits, `_`) around an offset.
pub fn word_at(text: &str, offset: usize) -> Option<(&str, crate::span::Span)> {
    let offset = offset.min(text.len());
    if !text.is_char_boundary(offset) {
        return None;
    }
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let start = text[..offset]
        .char_indices()
        .rev()
        .take_while(|(_, c)| is_word(*c))
        .last()
        .map_or(offset, |(i, _)| i);
    let end = text[offset..]
        .char_indices()
        .find(|(_, c)| !is_word(*c))
        .map_or(text.len(), |(i, _)| offset + i);
    (start < end).then(|| (&text[start..end], crate::span::Span::new(start, end)))
}

fn target_text(a: &Analysis, t: &Target) -> Option<String> {
    match t {
        Target::Symbol(id) => Some(symbol_text(a, a.index.symbols.get(*id)?)),
        Target::Query(q) => Some(query_text(q)),
        Target::Turtle(c) => words::turtle(*c).map(turtle_text),
        Target::Word(w) => words::word(w).map(|k| format!("```lsy\n{}\n```\n\n{}", k.word, k.doc)),
        Target::Cut => words::turtle('%').map(|w| format!("```lsy\ncut\n```\n\n{}", w.meaning)),
        Target::Function(f) => Some(match builtins::lookup(f) {
            Some(b) => {
                let args: Vec<String> = (0..b.arity)
                    .map(|i| ["x", "y", "z"][i.min(2)].to_string())
                    .collect();
                let random = if b.random {
                    "\n\nDrawn from the run's seeded generator (`--seed`)."
                } else {
                    ""
                };
                format!(
                    "```lsy\n{}({})\n```\n\n{}{random}",
                    b.name,
                    args.join(", "),
                    b.doc
                )
            }
            None => format!("`{f}` is not a built-in function"),
        }),
    }
}

pub fn query_text(q: &str) -> String {
    match query::lookup(q) {
        Some(q) => format!(
            "```lsy\n{}\n```\n\nQuery module: {}.\n\nOutputs, filled by the environment after each derivation step: {}. Then the pass-through parameters the program chooses{}.",
            q.signature(),
            q.doc,
            q.outputs
                .iter()
                .map(|o| format!("`{o}`"))
                .collect::<Vec<_>>()
                .join(", "),
            if q.inputs.is_empty() {
                String::new()
            } else {
                format!(
                    ", of which the environment reads {}",
                    q.inputs
                        .iter()
                        .map(|o| format!("`{o}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        ),
        None => format!("`{q}` is not a query module the environment answers"),
    }
}

pub fn turtle_text(w: &words::TurtleWord) -> String {
    format!("```lsy\n{}\n```\n\nTurtle: {}.", w.form, w.meaning)
}

/// The comments a person wrote about a node: the block of comments right above
/// it (not one a blank line keeps apart, such as a file's header) and the one
/// beside it, without delimiters.
fn comments(text: &str, t: &Trivia) -> String {
    let strip = |s: &str| -> String {
        let s = s.trim();
        let s = s.strip_prefix("//").unwrap_or(s);
        let s = s.strip_prefix("/*").unwrap_or(s);
        let s = s.strip_suffix("*/").unwrap_or(s);
        s.trim().to_string()
    };
    let mut block = 0;
    if !t.blank_after_leading {
        for (i, c) in t.leading.iter().enumerate().rev() {
            block += 1;
            let Some(prev) = i.checked_sub(1).map(|j| &t.leading[j]) else {
                break;
            };
            let gap = text
                .get(prev.span.end as usize..c.span.start as usize)
                .unwrap_or("");
            if gap.matches('\n').count() > 1 {
                break;
            }
        }
    }
    let mut lines: Vec<String> = t.leading[t.leading.len() - block..]
        .iter()
        .map(|c| strip(&c.text))
        .collect();
    if let Some(c) = &t.trailing {
        lines.push(strip(&c.text));
    }
    const MAX: usize = 20;
    if lines.len() > MAX {
        lines.truncate(MAX);
        lines.push("…".to_string());
    }
    lines.join("\n")
}

fn item(a: &Analysis, i: usize) -> Option<&Node<Item>> {
    a.file.items.stmts.get(i)
}

fn lsystem_name(a: &Analysis, i: usize) -> String {
    match item(a, i).map(|n| &n.node) {
        Some(Item::Lsystem(l)) => l.name.name.clone(),
        Some(Item::Scene(s)) => s.name.name.clone(),
        _ => "?".to_string(),
    }
}

fn params(ps: &[crate::ast::Ident]) -> String {
    if ps.is_empty() {
        String::new()
    } else {
        format!(
            "({})",
            ps.iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

fn value_text(v: Value) -> String {
    match v {
        Value::Num(x) => format_number(x),
        Value::Bool(b) => b.to_string(),
    }
}

fn symbol_text(a: &Analysis, s: &Symbol) -> String {
    let mut parts: Vec<String> = Vec::new();
    let declared = s.decl.map(|d| format!("line {}", a.line_of(d)));
    match (&s.origin, s.kind) {
        (Origin::Item(i), Kind::Const) => {
            if let Some(Node {
                node: Item::Const(c),
                trivia,
                ..
            }) = item(a, *i)
            {
                parts.push(format!(
                    "```lsy\nconst {} = {}\n```",
                    c.name.name,
                    format_expr(&c.value)
                ));
                let doc = comments(&a.text, trivia);
                if !doc.is_empty() {
                    parts.push(doc);
                }
                if let Some(k) = a.checked.as_ref().and_then(|ch| ch.consts.get(&s.name)) {
                    if k.random {
                        parts.push(format!(
                            "Value: drawn from the run's seed (`{}` with seed 0).",
                            value_text(k.value)
                        ));
                    } else {
                        parts.push(format!("Value: `{}`.", value_text(k.value)));
                    }
                }
                parts.push(format!("Overridable: `-D {}=…`.", c.name.name));
            }
        }
        (Origin::Item(i), Kind::Module) | (Origin::LsystemStmt(i, _), Kind::Module) => {
            let (decl, trivia, place) = match (&s.origin, item(a, *i).map(|n| (&n.node, &n.trivia)))
            {
                (Origin::Item(_), Some((Item::Module(m), t))) => {
                    (Some(m), Some(t), "file".to_string())
                }
                (Origin::LsystemStmt(_, j), Some((Item::Lsystem(l), _))) => {
                    match l.body.stmts.get(*j) {
                        Some(Node {
                            node: Stmt::Module(m),
                            trivia,
                            ..
                        }) => (Some(m), Some(trivia), format!("lsystem `{}`", l.name.name)),
                        _ => (None, None, String::new()),
                    }
                }
                _ => (None, None, String::new()),
            };
            if let Some(m) = decl {
                parts.push(format!(
                    "```lsy\nmodule {}{}\n```",
                    m.name.name,
                    params(&m.params)
                ));
                if let Some(t) = trivia {
                    let doc = comments(&a.text, t);
                    if !doc.is_empty() {
                        parts.push(doc);
                    }
                }
                parts.push(format!(
                    "Module with {} parameter{}, declared in the {place} at {}.",
                    m.params.len(),
                    if m.params.len() == 1 { "" } else { "s" },
                    declared.clone().unwrap_or_default()
                ));
            }
            parts.push(rules_text(a, s));
        }
        (Origin::Item(i), Kind::Element) => {
            if let Some(Node {
                node: Item::Element(e),
                trivia,
                ..
            }) = item(a, *i)
            {
                let mut props = Vec::new();
                for p in &e.props.stmts {
                    let v = match &p.node.value {
                        crate::ast::PropValue::Str(s, _) => {
                            let mut s = crate::fmt::format_string(s);
                            if s.chars().count() > 48 {
                                s = s.chars().take(45).collect::<String>() + "…\"";
                            }
                            s
                        }
                        crate::ast::PropValue::Expr(x) => format_expr(x),
                    };
                    props.push(format!("    {} {};", p.node.key.name, v));
                }
                parts.push(format!(
                    "```lsy\nelement {} {{\n{}\n}}\n```",
                    e.name.name,
                    props.join("\n")
                ));
                let doc = comments(&a.text, trivia);
                if !doc.is_empty() {
                    parts.push(doc);
                }
                parts.push(format!(
                    "Element: a terminal module that prints its path at the turtle's position, heading and scale. Declared at {}.",
                    declared.clone().unwrap_or_default()
                ));
            }
        }
        (Origin::Item(i), Kind::Lsystem) => {
            if let Some(Node {
                node: Item::Lsystem(l),
                trivia,
                ..
            }) = item(a, *i)
            {
                let mut head = format!("lsystem {}{}", l.name.name, params(&l.params));
                let mut rules = 0;
                for st in &l.body.stmts {
                    match &st.node {
                        Stmt::Angle(e) => {
                            head.push_str(&format!("\n    angle {};", format_expr(e)))
                        }
                        Stmt::Derive(e) => {
                            head.push_str(&format!("\n    derive {};", format_expr(e)))
                        }
                        Stmt::Step(e) => head.push_str(&format!("\n    step {};", format_expr(e))),
                        Stmt::Tropism(t) => head.push_str(&format!(
                            "\n    tropism ({}, {}, {}) {};",
                            format_expr(&t.dir[0]),
                            format_expr(&t.dir[1]),
                            format_expr(&t.dir[2]),
                            format_expr(&t.elasticity)
                        )),
                        Stmt::Rule(_) => rules += 1,
                        Stmt::Axiom(_)
                        | Stmt::Ignore(_)
                        | Stmt::Consider(_)
                        | Stmt::Module(_)
                        | Stmt::Error => {}
                    }
                }
                parts.push(format!("```lsy\n{head}\n```"));
                let doc = comments(&a.text, trivia);
                if !doc.is_empty() {
                    parts.push(doc);
                }
                parts.push(format!(
                    "{rules} rule{}; declared at {}.",
                    if rules == 1 { "" } else { "s" },
                    declared.clone().unwrap_or_default()
                ));
            }
        }
        (Origin::Item(i), Kind::Scene) => {
            if let Some(Node {
                node: Item::Scene(sc),
                trivia,
                ..
            }) = item(a, *i)
            {
                let guides = sc
                    .body
                    .stmts
                    .iter()
                    .filter(|s| matches!(s.node, crate::ast::SceneStmt::Guide(_)))
                    .count();
                let links = sc
                    .body
                    .stmts
                    .iter()
                    .filter(|s| matches!(s.node, crate::ast::SceneStmt::Link(_)))
                    .count();
                parts.push(format!("```lsy\nscene {}\n```", sc.name.name));
                let doc = comments(&a.text, trivia);
                if !doc.is_empty() {
                    parts.push(doc);
                }
                parts.push(format!(
                    "{guides} guides, {links} links; declared at {}.",
                    declared.clone().unwrap_or_default()
                ));
            }
        }
        (Origin::Guide(i, j), _) => {
            if let Some(Node {
                node: Item::Scene(sc),
                ..
            }) = item(a, *i)
                && let Some(Node {
                    node: crate::ast::SceneStmt::Guide(g),
                    trivia,
                    ..
                }) = sc.body.stmts.get(*j)
            {
                let mut lines = vec![format!("guide {}", g.name.name)];
                for gs in &g.body.stmts {
                    match &gs.node {
                        crate::ast::GuideStmt::Polygon(ps) => {
                            lines.push(format!("    polygon with {} vertices", ps.len()))
                        }
                        crate::ast::GuideStmt::System(n) => {
                            lines.push(format!("    system {};", n.name))
                        }
                        crate::ast::GuideStmt::Seed(_) => lines.push("    seed …;".to_string()),
                        crate::ast::GuideStmt::Error => {}
                    }
                }
                parts.push(format!("```lsy\n{}\n```", lines.join("\n")));
                let doc = comments(&a.text, trivia);
                if !doc.is_empty() {
                    parts.push(doc);
                }
                parts.push(format!(
                    "Guide of scene `{}`, declared at {}.",
                    sc.name.name,
                    declared.clone().unwrap_or_default()
                ));
            }
        }
        (Origin::LsystemParam(i, k), _) => {
            parts.push(format!("```lsy\n{}\n```", s.name));
            parts.push(format!(
                "Parameter {} of lsystem `{}`: the axiom may use it; a seed's `with (…)` or a link's message sets it.",
                k + 1,
                lsystem_name(a, *i)
            ));
        }
        (
            Origin::RuleParam {
                item: i,
                stmt,
                module,
                arg,
            },
            _,
        ) => {
            parts.push(format!("```lsy\n{}\n```", s.name));
            let rule_line = match item(a, *i).map(|n| &n.node) {
                Some(Item::Lsystem(l)) => l.body.stmts.get(*stmt).map(|st| {
                    let text = a.slice(st.span);
                    let first = text.lines().next().unwrap_or("");
                    (
                        a.line_of(st.span),
                        first.chars().take(80).collect::<String>(),
                    )
                }),
                _ => None,
            };
            let what = match module {
                ModName::Query(q) => match query::lookup(q) {
                    Some(qd) if *arg < qd.outputs.len() => format!(
                        "output `{}` of `{q}`, filled by the environment ({})",
                        qd.outputs[*arg], qd.doc
                    ),
                    Some(_) => format!("pass-through parameter {} of `{q}`", arg + 1),
                    None => format!("argument {} of `{q}`", arg + 1),
                },
                m => format!("argument {} of `{}`", arg + 1, m.text()),
            };
            parts.push(format!("Rule parameter: {what}."));
            if let Some((line, text)) = rule_line {
                parts.push(format!(
                    "Bound by the rule at line {line}:\n```lsy\n{text}\n```"
                ));
            }
        }
        (Origin::Letter(i), _) => {
            parts.push(format!("```lsy\n{}\n```", s.name));
            if let Some(c) = s
                .name
                .chars()
                .next()
                .filter(|_| s.name.chars().count() == 1)
                && let Some(w) = words::turtle(c)
            {
                parts.push(format!("Turtle: {}.", w.meaning));
            } else if crate::resolve::is_letter(&s.name) {
                parts.push("A single-letter module (no declaration needed). Letters other than F and f do not draw unless an `interpret` rule says so.".to_string());
            }
            parts.push(format!("In lsystem `{}`.", lsystem_name(a, *i)));
            parts.push(rules_text(a, s));
        }
        _ => parts.push(format!("{} `{}`", s.kind.noun(), s.name)),
    }
    parts.retain(|p| !p.is_empty());
    parts.join("\n\n")
}

fn rules_text(a: &Analysis, s: &Symbol) -> String {
    match s.rules.len() {
        0 => "No rule rewrites it.".to_string(),
        n => {
            let lines: Vec<String> = s.rules.iter().map(|r| a.line_of(*r).to_string()).collect();
            format!(
                "Rewritten by {n} rule{} (line{} {}).",
                if n == 1 { "" } else { "s" },
                if n == 1 { "" } else { "s" },
                lines.join(", ")
            )
        }
    }
}
