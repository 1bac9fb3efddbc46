//! The program of a line drawing as an `ast::File`, built with the shared kit
//! (`infer::program`): a header comment saying how well it matches, then one
//! lsystem with `angle`, `derive`, `step` (when it is not 1), the axiom behind
//! the moves that place it on the drawing, the rules, and `interpret` rules
//! for drawing letters other than `F`.
//!
//! Owns: the shape of programs inferred from line drawings (see
//! `docs/language.md`, "Line drawings"). Must not print text:
//! `fmt::format_file` does.

use super::grammar::{Action, Grammar, Sym};
use super::verify::Redraw;
use crate::ast::{Expr, File, ModName, Module, Node, Rule, Stmt};
use crate::infer::program::{self, comment, file, lsystem, named, node, sym, var};

/// What the emitter needs besides the grammar.
pub struct Settings<'a> {
    /// The drawing's file name, for the header.
    pub source: &'a str,
    /// The lsystem's name.
    pub name: String,
    /// δ as written.
    pub angle: f64,
    /// The step length as written.
    pub step: f64,
    /// Turns and moves before the axiom that put the drawing where it was.
    pub frame: Vec<Module>,
    pub redraw: Redraw,
}

fn module(g: &Grammar, s: Sym) -> Module {
    match s {
        Sym::Letter(k) => sym(g.letters.get(k as usize).map_or('F', |l| l.name), None),
        Sym::Plus => sym('+', None),
        Sym::Minus => sym('-', None),
        Sym::Push => Module::new(ModName::Symbol('['), None),
        Sym::Pop => Module::new(ModName::Symbol(']'), None),
    }
}

fn modules(g: &Grammar, syms: &[Sym]) -> Vec<Module> {
    syms.iter().map(|&s| module(g, s)).collect()
}

fn rule(pred: Module, succ: Vec<Module>, interpret: bool) -> Node<Stmt> {
    node(Stmt::Rule(Rule {
        interpret,
        ..program::rule(pred, succ)
    }))
}

/// A distance as text, two significant digits; below `zero`, 0 (rounding
/// noise, which differs between platforms' sines and cosines).
fn short(v: f64, zero: f64) -> String {
    if v.is_nan() || v.abs() <= zero {
        return "0".into();
    }
    format!("{:.1e}", v)
}

/// The header lines.
fn header(g: &Grammar, s: &Settings) -> Vec<String> {
    let r = &s.redraw;
    vec![
        format!(
            "Inferred by `lsyc infer` from {}: a line drawing of {} steps of {}, turning by",
            s.source,
            r.steps,
            crate::number::source(s.step)
        ),
        format!(
            "multiples of {} degrees; this D0L system draws it at derive {}.",
            crate::number::source(s.angle),
            g.depth
        ),
        format!(
            "Redrawn: {} of {} segments matched, Chamfer distance {} ({} of the diagonal).",
            r.matched,
            r.steps,
            short(r.chamfer, 1e-9 * r.diagonal),
            short(r.relative(), 1e-9)
        ),
        format!(
            "More steps grow it further: lsyc run FILE.lsy -n {}.",
            g.depth + 1
        ),
    ]
}

/// The program for `g`.
pub fn program(g: &Grammar, s: &Settings) -> File {
    let mut stmts: Vec<Node<Stmt>> = vec![
        node(Stmt::Angle(Expr::num(s.angle))),
        node(Stmt::Derive(Expr::num(f64::from(g.depth)))),
    ];
    if s.step != 1.0 {
        stmts.push(node(Stmt::Step(Expr::num(s.step))));
    }
    let mut axiom = s.frame.clone();
    axiom.extend(modules(g, &g.axiom));
    stmts.push(node(Stmt::Axiom(axiom)));
    // Node letters' rules first (as ABOP writes X before F), then drawing
    // letters', then moves'.
    let order = |a: Action| match a {
        Action::Nothing => 0,
        Action::Draw => 1,
        Action::Move => 2,
    };
    let mut letters: Vec<usize> = (0..g.letters.len()).collect();
    letters.sort_by_key(|&k| order(g.letters[k].action));
    for &k in &letters {
        let l = &g.letters[k];
        if let Some(r) = &l.rule {
            stmts.push(rule(sym(l.name, None), modules(g, r), false));
        }
    }
    // The move that places the drawing is not one of the grammar's moves.
    let placed = s.frame.iter().any(|m| m.name == ModName::Name("f".into()));
    if placed && g.letters.iter().any(|l| l.name == 'f' && l.rule.is_some()) {
        let f = || named("f", vec![var("d")]);
        let mut r = rule(f(), vec![f()], false);
        r.trivia.trailing = Some(comment("the move that puts the drawing in place"));
        stmts.push(r);
    }
    for &k in &letters {
        let l = &g.letters[k];
        if l.action == Action::Draw && l.name != 'F' {
            stmts.push(rule(sym(l.name, None), vec![sym('F', None)], true));
        }
    }
    let mut sys = lsystem(&s.name, stmts);
    sys.trivia.leading = header(g, s).iter().map(comment).collect();
    sys.trivia.blank_after_leading = true;
    file(vec![sys])
}
