//! The one kit every inference writes its program with: pieces of the one
//! AST (comments, nodes, names, symbols, rules, the lsystem and the file),
//! numbers rounded to the shortest decimal within a tolerance, and the names
//! a drawing's file gives its program.
//!
//! Owns: building `ast` nodes without spans, as inferred programs have none,
//! and naming. Must not know any kind of drawing (each folder's `emit` writes
//! its own programs with this kit) and must not print text:
//! `fmt::format_file` does, for hand-written and inferred programs alike.

use crate::ast::{
    BinOp, Block, Expr, ExprKind, File, Ident, Item, Lsystem, ModName, Module, Node, Rule, Stmt,
};
use crate::lexer::Comment;
use crate::span::Span;

/// A line comment, `//` and the text.
pub(crate) fn comment(text: impl AsRef<str>) -> Comment {
    let t = text.as_ref();
    Comment {
        text: if t.is_empty() {
            "//".to_string()
        } else {
            format!("// {t}")
        },
        span: Span::default(),
    }
}

pub(crate) fn node<T>(node: T) -> Node<T> {
    Node::new(node, Span::default())
}

pub(crate) fn var(name: &str) -> Expr {
    Expr::new(ExprKind::Var(name.to_string()))
}

pub(crate) fn bin(op: BinOp, a: Expr, b: Expr) -> Expr {
    Expr::new(ExprKind::Binary(op, Box::new(a), Box::new(b)))
}

/// A turtle symbol or a single letter (`F`, `f`) with an optional parameter.
pub(crate) fn sym(c: char, arg: Option<Expr>) -> Module {
    let name = if c.is_alphabetic() {
        ModName::Name(c.to_string())
    } else {
        ModName::Symbol(c)
    };
    Module::new(name, arg.map(|a| vec![a]))
}

/// A module by name with its parameters.
pub(crate) fn named(name: &str, args: Vec<Expr>) -> Module {
    Module::new(ModName::Name(name.to_string()), Some(args))
}

/// `pred -> succ`: no label, context, condition or weight.
pub(crate) fn rule(pred: Module, succ: Vec<Module>) -> Rule {
    Rule {
        label: None,
        interpret: false,
        decompose: false,
        left: None,
        pred,
        right: None,
        cond: None,
        weight: None,
        succ,
    }
}

/// `lsystem name { stmts }`, without parameters.
pub(crate) fn lsystem(name: &str, stmts: Vec<Node<Stmt>>) -> Node<Item> {
    node(Item::Lsystem(Lsystem {
        name: Ident::new(name),
        params: Vec::new(),
        body: Block {
            stmts,
            end_comments: Vec::new(),
        },
    }))
}

/// The file of `items`.
pub(crate) fn file(items: Vec<Node<Item>>) -> File {
    File {
        items: Block {
            stmts: items,
            end_comments: Vec::new(),
        },
    }
}

/// Derives the program `text` `more` steps beyond its own `derive` and
/// draws it into `sink`, as `lsyc run` does (seed 0): how inference checks
/// what a program it wrote draws. `None` if it does not run.
pub(crate) fn draw(text: &str, more: u32, sink: &mut dyn crate::turtle::Sink) -> Option<()> {
    draw_compiled(&compiled(text)?, more, sink)
}

/// The program `text` compiled; `None` if it has errors.
pub(crate) fn compiled(text: &str) -> Option<crate::compile::Program> {
    let fe = crate::frontend::run(text, Vec::new(), &[]);
    if fe.has_errors() {
        return None;
    }
    let checked = fe.checked.as_ref()?;
    crate::compile::compile(&fe.file, checked, None).ok()
}

/// `draw` for a compiled program.
pub(crate) fn draw_compiled(
    prog: &crate::compile::Program,
    more: u32,
    sink: &mut dyn crate::turtle::Sink,
) -> Option<()> {
    let limits = crate::derive::Limits::default();
    let axiom = crate::derive::axiom(prog, &vec![0.0; prog.params.len()], 0).ok()?;
    let steps = prog.derive.checked_add(more)?;
    let string = crate::derive::derive(prog, axiom, steps, 0, limits, &|_, _| {}).ok()?;
    let state = crate::turtle::State::default();
    crate::turtle::interpret_limited(prog, &string, 0, state, limits, sink)
        .ok()
        .map(|_| ())
}

/// The shortest decimal within `tol` of `v` (at most 6 decimals).
pub fn nice(v: f64, tol: f64) -> f64 {
    for digits in 0..=6 {
        let k = 10f64.powi(digits);
        let r = (v * k).round() / k;
        if (r - v).abs() <= tol {
            return r + 0.0;
        }
    }
    let k = 1e6;
    (v * k).round() / k + 0.0
}

/// For a drawing's file name: the name the header gives (the file's own name)
/// and the lsystem's name (from its stem: `sketch-tree.svg` → `SketchTree`).
pub fn names(name: &str) -> (String, String) {
    let path = std::path::Path::new(name);
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let source = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| name.to_string());
    (source, system_name(&stem))
}

/// A file stem as an lsystem name: `sketch-tree` becomes `SketchTree`.
pub fn system_name(stem: &str) -> String {
    let mut out = String::new();
    for part in stem.split(|c: char| !c.is_ascii_alphanumeric()) {
        let mut cs = part.chars();
        if let Some(c) = cs.next() {
            out.push(c.to_ascii_uppercase());
            out.extend(cs);
        }
    }
    // All capitals could be a module (`R`, `AB`) or a constant (`KW`).
    let clashes = out == out.to_ascii_uppercase();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) || clashes {
        out = format!("Sketch{out}");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn system_names() {
        assert_eq!(system_name("sketch-tree"), "SketchTree");
        assert_eq!(system_name("3d_oak"), "Sketch3dOak");
        assert_eq!(system_name("r"), "SketchR");
        assert_eq!(system_name("KW"), "SketchKW");
        assert_eq!(system_name("b12"), "SketchB12");
        assert_eq!(system_name("é"), "Sketch");
    }
}
