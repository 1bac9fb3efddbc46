//! The one canonical pretty printer: any `ast::File` back to `.lsy` text.
//!
//! Owns: the canonical layout of the language (indentation, spacing, where
//! parentheses go, how numbers and strings are spelt, which module strings need a
//! space) and the promise that `parse(format(parse(x)))` equals `parse(x)` up to
//! spans, comments and blank lines included, and that formatting is idempotent.
//! Blank lines follow `trivia::blank_between`, the policy shared with the parser;
//! a blank line between a node's leading comments and the node is kept
//! (`Trivia::blank_after_leading`); blank lines among the comments are not.
//! Must not read source text or spans (it prints ASTs built in code too), must not
//! check or change meaning, and must never panic: `Error` nodes are skipped
//! (`ExprKind::Error` prints as `0`).
//!
//! Things no text can express, printed as the nearest text that parses:
//! NaN as `(0 / 0)`, infinities as `(1 / 0)` and `(-1 / 0)`, a negative number
//! literal as unary minus (`-3`), `-0` as `0`.

use crate::ast::{
    BinOp, Block, EdgeRef, Element, Expr, ExprKind, File, Guide, GuideStmt, Item, Link, LinkStmt,
    Lsystem, ModName, Module, ModuleDecl, Point, Prop, PropValue, Rule, Scene, SceneStmt, Seed,
    Stmt, UNARY_PRECEDENCE, UnOp,
};
use crate::lexer::{self, Comment, Token};
use crate::resolve::{self, Scope};
use crate::trivia::{self, Nested};

/// One level of indentation.
const INDENT: &str = "    ";
/// Elements and links fit on one line up to this many columns.
const MAX_WIDTH: usize = 100;
/// Precedence of literals, names, calls and parenthesised expressions.
const ATOM: u8 = 8;

/// Prints a whole file in canonical layout. Ends with exactly one newline unless
/// the file holds nothing at all (then it is `""`).
pub fn format_file(file: &File) -> String {
    let mut p = Printer::default();
    let top = Scope::file(file);
    p.block(
        &file.items,
        0,
        |it| !matches!(it, Item::Error),
        |p, it, ind| p.item(it, ind, &top),
    );
    p.out
}

/// Prints the top-level items `range` of a file as `format_file` prints them
/// there (the file's module declarations decide how letters are spaced), for
/// formatting part of a file. The blank line before the first one, and the
/// comments after the file's last item, are left to the caller.
pub fn format_items(file: &File, range: std::ops::Range<usize>) -> String {
    let mut p = Printer::default();
    let top = Scope::file(file);
    let part = crate::ast::Block {
        stmts: file.items.stmts.get(range).unwrap_or_default().to_vec(),
        end_comments: Vec::new(),
    };
    p.block(
        &part,
        0,
        |it| !matches!(it, Item::Error),
        |p, it, ind| p.item(it, ind, &top),
    );
    p.out
}

/// Prints an expression with the fewest parentheses that parse back to it.
pub fn format_expr(e: &Expr) -> String {
    let mut s = String::new();
    write_expr(&mut s, e);
    s
}

/// Prints a number as the lexer reads it back: `30`, `0.7`, `1e-7`, `1.5e20`.
/// Negative values get a leading `-` (which parses as unary minus); NaN and the
/// infinities, which no literal can spell, print as `(0 / 0)`, `(1 / 0)`, `(-1 / 0)`.
pub fn format_number(v: f64) -> String {
    crate::number::source(v)
}

/// Prints a string literal with the escapes the lexer knows: `\\ \" \n \t`.
pub fn format_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '"' => out.push_str("\\\""),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Prints a module string (axiom, successor, context) as it would appear in the
/// lsystem whose declarations `scope` holds.
pub fn format_modules(ms: &[Module], scope: &Scope) -> String {
    let n = ms.len();
    let mut space: Vec<bool> = ms.windows(2).map(|w| needs_space(&w[0], &w[1])).collect();
    // Glued runs of single letters must not read back as a declared name or a
    // keyword: `A` `B` with `module AB;` prints `A B`, `c` `u` `t` prints `c u t`.
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && glues_letters(&ms[j], &ms[j + 1]) && !space[j] {
            j += 1;
        }
        if j > i {
            let word: String = ms[i..=j].iter().map(|m| m.name.text()).collect();
            if scope.declares(&word) || !lexes_as_one_name(&word) {
                for s in &mut space[i..j] {
                    *s = true;
                }
            }
        }
        i = j + 1;
    }
    let mut out = String::new();
    for (k, m) in ms.iter().enumerate() {
        write_module(&mut out, m);
        if space.get(k).copied().unwrap_or(false) {
            out.push(' ');
        }
    }
    out
}

#[derive(Default)]
struct Printer {
    out: String,
}

impl Printer {
    fn indent(&mut self, level: usize) {
        for _ in 0..level {
            self.out.push_str(INDENT);
        }
    }

    fn comment_line(&mut self, c: &Comment, level: usize) {
        self.indent(level);
        self.out.push_str(&c.text);
        self.out.push('\n');
    }

    /// Prints the statements of a block at `level`, one per line, with their
    /// comments and blank lines. `keep` filters out `Error` nodes.
    fn block<T: Nested>(
        &mut self,
        block: &Block<T>,
        level: usize,
        keep: impl Fn(&T) -> bool,
        mut print: impl FnMut(&mut Printer, &T, usize),
    ) {
        let mut prev: Option<&T> = None;
        for node in block.stmts.iter().filter(|n| keep(&n.node)) {
            if let Some(p) = prev
                && (node.trivia.blank_before || trivia::blank_between(p, &node.node, false))
            {
                self.out.push('\n');
            }
            for c in &node.trivia.leading {
                self.comment_line(c, level);
            }
            if node.trivia.blank_after_leading && !node.trivia.leading.is_empty() {
                self.out.push('\n');
            }
            self.indent(level);
            print(self, &node.node, level);
            if let Some(c) = &node.trivia.trailing {
                self.out.push(' ');
                self.out.push_str(&c.text);
            }
            self.out.push('\n');
            prev = Some(&node.node);
        }
        for c in &block.end_comments {
            self.comment_line(c, level);
        }
    }

    /// `head {` block `}`; `head {}` when the block prints nothing. The caller has
    /// written the indentation of `head`; no newline after `}`.
    fn braced<T: Nested>(
        &mut self,
        head: &str,
        block: &Block<T>,
        level: usize,
        keep: impl Fn(&T) -> bool,
        print: impl FnMut(&mut Printer, &T, usize),
    ) {
        self.out.push_str(head);
        if block.end_comments.is_empty() && !block.stmts.iter().any(|n| keep(&n.node)) {
            self.out.push_str(" {}");
            return;
        }
        self.out.push_str(" {\n");
        self.block(block, level + 1, keep, print);
        self.indent(level);
        self.out.push('}');
    }

    /// Like `braced`, but on one line (`head { a; b; }`) when the block has no
    /// comments or blank lines and the line fits in `MAX_WIDTH` columns.
    fn braced_inline<T: Nested>(
        &mut self,
        head: &str,
        block: &Block<T>,
        level: usize,
        keep: impl Fn(&T) -> bool,
        one: impl Fn(&T) -> String,
    ) {
        let kept: Vec<_> = block.stmts.iter().filter(|n| keep(&n.node)).collect();
        let plain = block.end_comments.is_empty()
            && kept.iter().enumerate().all(|(i, n)| {
                n.trivia.leading.is_empty()
                    && n.trivia.trailing.is_none()
                    && (i == 0 || !n.trivia.blank_before)
            });
        if plain && !kept.is_empty() {
            let mut line = format!("{head} {{");
            for n in &kept {
                line.push(' ');
                line.push_str(&one(&n.node));
            }
            line.push_str(" }");
            let width = INDENT.len() * level + line.chars().count();
            if width <= MAX_WIDTH && !line.contains('\n') {
                self.out.push_str(&line);
                return;
            }
        }
        self.braced(head, block, level, keep, |p, s, _| p.out.push_str(&one(s)));
    }

    fn item(&mut self, item: &Item, level: usize, top: &Scope) {
        match item {
            Item::Lsystem(l) => self.lsystem(l, level, top),
            Item::Module(m) => self.out.push_str(&module_decl(m)),
            Item::Const(c) => {
                self.out.push_str(&format!(
                    "const {} = {};",
                    c.name.name,
                    format_expr(&c.value)
                ));
            }
            Item::Element(e) => self.element(e, level),
            Item::Palette(p) => self.braced(
                "palette",
                &p.body,
                level,
                |e| !matches!(e.index.kind, ExprKind::Error),
                |pr, e, _| {
                    pr.out.push_str(&format!(
                        "{} {}{};",
                        format_expr(&e.index),
                        format_string(&e.color),
                        e.name
                            .as_ref()
                            .map_or(String::new(), |n| format!(" {}", n.name))
                    ))
                },
            ),
            Item::Scene(s) => self.scene(s, level),
            Item::Error => {}
        }
    }

    fn lsystem(&mut self, l: &Lsystem, level: usize, top: &Scope) {
        let scope = top.with_lsystem(&l.body.stmts);
        let head = format!("lsystem {}{}", l.name.name, params(&l.params));
        self.braced(
            &head,
            &l.body,
            level,
            |s| !matches!(s, Stmt::Error),
            |p, s, _| p.out.push_str(&stmt(s, &scope)),
        );
    }

    fn element(&mut self, e: &Element, level: usize) {
        let head = format!("element {}", e.name.name);
        self.braced_inline(&head, &e.props, level, |p| !p.key.name.is_empty(), prop);
    }

    fn scene(&mut self, s: &Scene, level: usize) {
        let head = format!("scene {}", s.name.name);
        self.braced(
            &head,
            &s.body,
            level,
            |s| !matches!(s, SceneStmt::Error),
            |p, s, level| match s {
                SceneStmt::Guide(g) => p.guide(g, level),
                SceneStmt::Link(l) => p.link(l, level),
                SceneStmt::Error => {}
            },
        );
    }

    fn guide(&mut self, g: &Guide, level: usize) {
        let head = format!("guide {}", g.name.name);
        self.braced(
            &head,
            &g.body,
            level,
            |s| !matches!(s, GuideStmt::Error),
            |p, s, _| p.out.push_str(&guide_stmt(s)),
        );
    }

    fn link(&mut self, l: &Link, level: usize) {
        let head = format!("link {} -> {}", edge_ref(&l.from), edge_ref(&l.to));
        self.braced_inline(
            &head,
            &l.body,
            level,
            |s| !matches!(s, LinkStmt::Error),
            link_stmt,
        );
    }
}

/// `(a, b)`, or nothing for no parameters.
fn params(ps: &[crate::ast::Ident]) -> String {
    if ps.is_empty() {
        return String::new();
    }
    let names: Vec<&str> = ps.iter().map(|p| p.name.as_str()).collect();
    format!("({})", names.join(", "))
}

fn module_decl(m: &ModuleDecl) -> String {
    format!("module {}{};", m.name.name, params(&m.params))
}

fn stmt(s: &Stmt, scope: &Scope) -> String {
    match s {
        Stmt::Angle(e) => format!("angle {};", format_expr(e)),
        Stmt::Derive(e) => format!("derive {};", format_expr(e)),
        Stmt::Step(e) => format!("step {};", format_expr(e)),
        Stmt::Axiom(ms) => {
            let text = format_modules(ms, scope);
            if text.is_empty() {
                "axiom;".to_string()
            } else {
                format!("axiom {text};")
            }
        }
        Stmt::Ignore(ms) => {
            let mut out = "ignore".to_string();
            for m in ms {
                out.push(' ');
                write_module(&mut out, m);
            }
            out.push(';');
            out
        }
        Stmt::Consider(ms) => {
            let mut out = "consider".to_string();
            for m in ms {
                out.push(' ');
                write_module(&mut out, m);
            }
            out.push(';');
            out
        }
        Stmt::Tropism(t) => format!(
            "tropism ({}, {}, {}) {};",
            format_expr(&t.dir[0]),
            format_expr(&t.dir[1]),
            format_expr(&t.dir[2]),
            format_expr(&t.elasticity)
        ),
        Stmt::Module(m) => module_decl(m),
        Stmt::Rule(r) => rule(r, scope),
        Stmt::Error => String::new(),
    }
}

fn rule(r: &Rule, scope: &Scope) -> String {
    let mut out = String::new();
    if let Some(label) = &r.label {
        out.push_str(&label.name);
        out.push_str(": ");
    }
    if r.interpret {
        out.push_str("interpret ");
    }
    if r.decompose {
        out.push_str("decompose ");
    }
    if let Some(left) = r.left.as_deref().filter(|l| !l.is_empty()) {
        out.push_str(&format_modules(left, scope));
        out.push_str(" < ");
    }
    write_module(&mut out, &r.pred);
    if let Some(right) = r.right.as_deref().filter(|l| !l.is_empty()) {
        out.push_str(" > ");
        out.push_str(&format_modules(right, scope));
    }
    if let Some(cond) = &r.cond {
        out.push_str(" : ");
        write_expr(&mut out, cond);
    }
    out.push_str(" ->");
    if let Some(w) = &r.weight {
        out.push('(');
        write_expr(&mut out, w);
        out.push(')');
    }
    out.push(' ');
    out.push_str(&format_modules(&r.succ, scope));
    out.push(';');
    out
}

fn prop(p: &Prop) -> String {
    match &p.value {
        PropValue::Str(s, _) => format!("{} {};", p.key.name, format_string(s)),
        PropValue::Expr(e) => format!("{} {};", p.key.name, format_expr(e)),
    }
}

fn point(p: &Point) -> String {
    format!("({}, {})", format_expr(&p.x), format_expr(&p.y))
}

fn args(es: &[Expr]) -> String {
    let mut out = String::new();
    write_args(&mut out, es);
    out
}

fn guide_stmt(s: &GuideStmt) -> String {
    match s {
        GuideStmt::Polygon(ps) => {
            let mut out = "polygon".to_string();
            for p in ps {
                out.push(' ');
                out.push_str(&point(p));
            }
            out.push(';');
            out
        }
        GuideStmt::System(name) => format!("system {};", name.name),
        GuideStmt::Seed(Seed {
            at,
            heading,
            args: with,
        }) => {
            let mut out = format!("seed {}", point(at));
            if let Some(h) = heading {
                out.push_str(" heading ");
                out.push_str(&format_expr(h));
            }
            if let Some(a) = with {
                out.push_str(" with ");
                out.push_str(&args(a));
            }
            out.push(';');
            out
        }
        GuideStmt::Error => String::new(),
    }
}

fn edge_ref(e: &EdgeRef) -> String {
    format!("{}.edge({})", e.guide.name, format_expr(&e.index))
}

fn link_stmt(s: &LinkStmt) -> String {
    match s {
        LinkStmt::Tokens(e) => format!("tokens {};", format_expr(e)),
        LinkStmt::Heading(e) => format!("heading {};", format_expr(e)),
        LinkStmt::Setting(k, e) => format!("{} {};", k.name, format_expr(e)),
        LinkStmt::Error => String::new(),
    }
}

// ------------------------------------------------------------------ modules

fn write_module(out: &mut String, m: &Module) {
    out.push_str(&m.name.text());
    if let Some(a) = &m.args {
        write_args(out, a);
    }
}

/// Letters, names, query modules and `cut`: modules spelt with name characters.
fn name_like(n: &ModName) -> bool {
    !matches!(n, ModName::Symbol(_))
}

fn is_letter(n: &ModName) -> bool {
    matches!(n, ModName::Name(s) if resolve::is_letter(s))
}

/// Whether `a` and `b` are bare-then-any single letters, printed glued (`FF`,
/// `FG(2)`): the lexer reads them as one name that the resolver splits again.
fn glues_letters(a: &Module, b: &Module) -> bool {
    a.args.is_none() && is_letter(&a.name) && is_letter(&b.name)
}

/// Whether a space must (or, after an argument list, should) separate `a` from `b`.
fn needs_space(a: &Module, b: &Module) -> bool {
    if a.args.is_some() {
        // `)` ends a token; the space is for reading: `+(30) A(l)`.
        return name_like(&b.name);
    }
    match (&a.name, &b.name) {
        // `//` and `/*` start comments; `&&` and `||` are operators.
        (ModName::Symbol(x), ModName::Symbol(y)) => {
            matches!((x, y), ('/', '/') | ('/', '*') | ('&', '&') | ('|', '|'))
        }
        (x, y) => name_like(x) && name_like(y) && !glues_letters(a, b),
    }
}

/// Whether `word` lexes as exactly one name token (not a keyword, not split).
fn lexes_as_one_name(word: &str) -> bool {
    let lexed = lexer::lex(word);
    lexed.diagnostics.is_empty()
        && lexed.comments.is_empty()
        && matches!(lexed.tokens.as_slice(), [(_, Token::Ident(s), _)] if s == word)
}

// ------------------------------------------------------------------ expressions

/// The binding strength of `e` as printed (`ATOM` for anything self-delimiting).
fn precedence(e: &Expr) -> u8 {
    match &e.kind {
        ExprKind::Num(v) if *v < 0.0 && v.is_finite() => UNARY_PRECEDENCE,
        ExprKind::Unary(..) => UNARY_PRECEDENCE,
        ExprKind::Binary(op, ..) => op.precedence(),
        _ => ATOM,
    }
}

/// Writes `e`, in parentheses unless it binds at least as tightly as `min`.
fn write_operand(out: &mut String, e: &Expr, min: u8) {
    if precedence(e) < min {
        out.push('(');
        write_expr(out, e);
        out.push(')');
    } else {
        write_expr(out, e);
    }
}

fn write_args(out: &mut String, es: &[Expr]) {
    out.push('(');
    for (i, e) in es.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        write_expr(out, e);
    }
    out.push(')');
}

fn write_expr(out: &mut String, e: &Expr) {
    match &e.kind {
        ExprKind::Num(v) => out.push_str(&format_number(*v)),
        ExprKind::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
        ExprKind::Var(name) => out.push_str(name),
        ExprKind::Unary(op, a) => {
            out.push(match op {
                UnOp::Neg => '-',
                UnOp::Not => '!',
            });
            let mut inner = String::new();
            write_operand(&mut inner, a, UNARY_PRECEDENCE);
            // `--x` would read back the same, but `-(-x)` reads better.
            if *op == UnOp::Neg && inner.starts_with('-') {
                out.push('(');
                out.push_str(&inner);
                out.push(')');
            } else {
                out.push_str(&inner);
            }
        }
        ExprKind::Binary(BinOp::Pow, a, b) => {
            // Grammar: Pow = Atom "^" Unary (right-associative through Unary).
            write_operand(out, a, ATOM);
            out.push('^');
            write_operand(out, b, UNARY_PRECEDENCE);
        }
        ExprKind::Binary(op, a, b) => {
            let p = op.precedence();
            // Comparisons do not chain: both sides must bind tighter.
            let left_min = if op.is_comparison() { p + 1 } else { p };
            write_operand(out, a, left_min);
            out.push(' ');
            out.push_str(op.text());
            out.push(' ');
            write_operand(out, b, p + 1);
        }
        ExprKind::Call(f, es) => {
            out.push_str(&f.name);
            write_args(out, es);
        }
        ExprKind::Error => out.push('0'),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ast::{Ident, Node};
    use crate::parser::parse;

    /// The Debug text of a tree with every span blanked out.
    fn erased<T: std::fmt::Debug>(t: &T) -> String {
        let text = format!("{t:?}");
        let mut out = String::new();
        let mut rest = text.as_str();
        while let Some(i) = rest.find("Span { start: ") {
            out.push_str(&rest[..i]);
            out.push_str("Span");
            rest = &rest[i..];
            match rest.find('}') {
                Some(j) => rest = &rest[j + 1..],
                None => rest = "",
            }
        }
        out.push_str(rest);
        out
    }

    fn parse_ok(src: &str) -> File {
        let p = parse(src);
        let errors: Vec<_> = p.diagnostics.iter().filter(|d| d.is_error()).collect();
        assert!(errors.is_empty(), "errors in:\n{src}\n{errors:#?}");
        p.file
    }

    /// Formats `src`, checks round trip and idempotence, returns the text.
    fn round_trip(src: &str) -> String {
        let first = parse_ok(src);
        let text = format_file(&first);
        let second = parse_ok(&text);
        assert_eq!(
            erased(&first),
            erased(&second),
            "round trip changed the tree; formatted:\n{text}"
        );
        let again = format_file(&second);
        assert_eq!(text, again, "not idempotent");
        text
    }

    #[test]
    fn canonical_layout() {
        let src = "const N=5;module Apex( len,d ) ;\nlsystem A(x){angle 90;derive 5;step 1;axiom F-F-F-F;ignore +-F;\
                   A(l,d):d<7->F(l)[+(30)A(l*0.7,d+1)];F->F-F+F+FF-F-F+F;A->;B->ε;}";
        assert_eq!(
            round_trip(src),
            "const N = 5;\nmodule Apex(len, d);\n\nlsystem A(x) {\n    angle 90;\n    derive 5;\n    \
             step 1;\n    axiom F-F-F-F;\n    ignore + - F;\n    \
             A(l, d) : d < 7 -> F(l)[+(30) A(l * 0.7, d + 1)];\n    F -> F-F+F+FF-F-F+F;\n    \
             A -> ;\n    B -> ;\n}\n"
        );
    }

    #[test]
    fn rules_with_everything() {
        let src = "module Apex(l);\nlsystem S {\n axiom A;\n r1: interpret B C < A(l) > [D]E : l > 0 && l<=2 ->(0.5) F(l) cut;\n\
                   F ->(1) F[+F]F;\n F ->(2) F[-F]F;\n ?X(found, id, d) : found -> F(d) cut;\n X -> ?X(d) f(d);\n\
                   A -> f(1) ?D_L(1) Apex(2)Apex F;\n}\n";
        let out = round_trip(src);
        assert!(
            out.contains(
                "    r1: interpret BC < A(l) > [D]E : l > 0 && l <= 2 ->(0.5) F(l) cut;\n"
            )
        );
        assert!(out.contains("    F ->(1) F[+F]F;\n"));
        assert!(out.contains("    ?X(found, id, d) : found -> F(d) cut;\n"));
        assert!(out.contains("    X -> ?X(d) f(d);\n"));
        assert!(out.contains("    A -> f(1) ?D_L(1) Apex(2) Apex F;\n"));
    }

    #[test]
    fn comments_everywhere() {
        let src = "// file header\n\n// before const\nconst N = 5; // trailing const\n\
                   module M; /* block */ // second on same line\n\
                   lsystem A { // after brace\n\n  angle 90; // angle\n\n\n  // before rule\n  \
                   F -> F /* inside */ F; /* multi\n     line */\n  axiom F;\n  // before close\n}\n\
                   element Leaf { path \"M0 0\"; fill \"green\"; } // leaf\n\
                   element Leaf2 { path \"M0 0\"; // p\n fill \"green\"; /* end */ }\n\
                   scene S { // s\n guide g { system A; // sys\n }\n link g.edge(0) -> g.edge(1) { tokens 1; }\n}\n\
                   // end of file\n/* really */\n";
        let out = round_trip(src);
        // Blank lines between leading comments are not kept by the parser.
        assert!(
            out.starts_with("// file header\n// before const\nconst N = 5; // trailing const\n")
        );
        // A second comment on the same line leads the next node.
        assert!(out.contains("module M; /* block */\n\n// second on same line\nlsystem A {\n"));
        // A blank line after leading comments is kept (a header stays apart).
        assert!(out.contains("lsystem A {\n    // after brace\n\n    angle 90;"));
        assert!(out.contains("    angle 90; // angle\n\n    // before rule\n    /* inside */\n    F -> FF; /* multi\n     line */\n    axiom F;\n"));
        assert!(out.contains("    // before close\n}\n"));
        assert!(out.contains("element Leaf { path \"M0 0\"; fill \"green\"; } // leaf\n"));
        assert!(out.contains(
            "element Leaf2 {\n    path \"M0 0\"; // p\n    fill \"green\"; /* end */\n}\n"
        ));
        assert!(out.contains(
            "scene S {\n    // s\n    guide g {\n        system A; // sys\n    }\n\n    link"
        ));
        assert!(out.ends_with("}\n// end of file\n/* really */\n"));
    }

    #[test]
    fn blank_lines_follow_source_and_policy() {
        let src =
            "const A = 1;\nconst B = 2;\n\n\nconst C = 3;\nlsystem L { axiom F; }\nconst D = 4;\n";
        assert_eq!(
            round_trip(src),
            "const A = 1;\nconst B = 2;\n\nconst C = 3;\n\nlsystem L {\n    axiom F;\n}\n\nconst D = 4;\n"
        );
    }

    #[test]
    fn empty_and_comment_only_files() {
        assert_eq!(round_trip(""), "");
        assert_eq!(round_trip("  \n\n"), "");
        assert_eq!(round_trip("// only\n\n/* me */"), "// only\n/* me */\n");
        assert_eq!(round_trip("lsystem E { }"), "lsystem E {}\n");
        assert_eq!(round_trip("element E { }"), "element E {}\n");
    }

    #[test]
    fn expression_parentheses() {
        let cases = [
            ("-2^2", "-2^2"),
            ("(-2)^2", "(-2)^2"),
            ("(a+b)*c", "(a + b) * c"),
            ("a-(b-c)", "a - (b - c)"),
            ("(a-b)-c", "a - b - c"),
            ("2^3^2", "2^3^2"),
            ("(2^3)^2", "(2^3)^2"),
            ("!(a<b)", "!(a < b)"),
            ("(a<b)==c", "(a < b) == c"),
            ("a==(b<c)", "a == (b < c)"),
            ("a||b&&c", "a || b && c"),
            ("(a||b)&&c", "(a || b) && c"),
            ("a&&(b||c)", "a && (b || c)"),
            ("2^-x", "2^-x"),
            ("2^(-x)^2", "2^(-x)^2"),
            ("2^-(x^2)", "2^-x^2"),
            ("--x", "-(-x)"),
            ("-(-x)", "-(-x)"),
            ("!!x", "!!x"),
            ("-x^2", "-x^2"),
            ("(a*b)^2", "(a * b)^2"),
            ("a/(b*c)", "a / (b * c)"),
            ("a % b * c", "a % b * c"),
            ("max(a,b+1)*sin(30)", "max(a, b + 1) * sin(30)"),
            ("rand()", "rand()"),
            ("a - -b", "a - -b"),
            (
                "(1.50)+.5+1e-3+1E20+0.0001",
                "1.5 + 0.5 + 0.001 + 1e20 + 0.0001",
            ),
            (
                "0.00001 + 1e15 + 123456789012345",
                "1e-5 + 1e15 + 123456789012345",
            ),
            ("true && !false", "true && !false"),
        ];
        for (src, want) in cases {
            let text = round_trip(&format!("const X = {src};\n"));
            assert_eq!(text, format!("const X = {want};\n"), "for {src}");
        }
    }

    #[test]
    fn numbers() {
        assert_eq!(format_number(30.0), "30");
        assert_eq!(format_number(0.7), "0.7");
        assert_eq!(format_number(1e-7), "1e-7");
        assert_eq!(format_number(1.5e20), "1.5e20");
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(-0.0), "0");
        assert_eq!(format_number(-3.0), "-3");
        assert_eq!(format_number(f64::MAX), "1.7976931348623157e308");
        assert_eq!(format_number(5e-324), "5e-324");
        for v in [
            0.1,
            1.0 / 3.0,
            123.456,
            1e-4,
            9.99e14,
            1e15,
            2.5e-5,
            f64::MAX,
            5e-324,
        ] {
            let text = format!("const X = {};", format_number(v));
            let file = parse_ok(&text);
            let Some(Item::Const(c)) = file.items.stmts.first().map(|n| &n.node) else {
                panic!("no const in {text}");
            };
            assert_eq!(c.value.kind, ExprKind::Num(v), "{text}");
        }
    }

    #[test]
    fn numbers_no_literal_can_spell() {
        let e = Expr::new(ExprKind::Binary(
            BinOp::Pow,
            Box::new(Expr::num(-2.0)),
            Box::new(Expr::num(f64::NAN)),
        ));
        assert_eq!(format_expr(&e), "(-2)^(0 / 0)");
        let e = Expr::new(ExprKind::Unary(UnOp::Neg, Box::new(Expr::num(-2.0))));
        assert_eq!(format_expr(&e), "-(-2)");
        let e = Expr::new(ExprKind::Binary(
            BinOp::Mul,
            Box::new(Expr::num(f64::INFINITY)),
            Box::new(Expr::num(f64::NEG_INFINITY)),
        ));
        assert_eq!(format_expr(&e), "(1 / 0) * (-1 / 0)");
        assert_eq!(format_expr(&Expr::new(ExprKind::Error)), "0");
        parse_ok("const X = (-2)^(0 / 0) + -(-2) + (1 / 0) * (-1 / 0);");
    }

    #[test]
    fn strings() {
        let out = round_trip("element E { path \"a\\\\b\\\"c\\nd\\te\"; }");
        assert_eq!(out, "element E { path \"a\\\\b\\\"c\\nd\\te\"; }\n");
        assert_eq!(format_string("x\"y\\"), "\"x\\\"y\\\\\"");
    }

    #[test]
    fn element_and_link_wrap_when_long() {
        let long = "M".repeat(90);
        let out = round_trip(&format!("element E {{ path \"{long}\"; fill \"green\"; }}"));
        assert_eq!(
            out,
            format!("element E {{\n    path \"{long}\";\n    fill \"green\";\n}}\n")
        );
        let out = round_trip(&format!("element E {{ path \"{}\"; }}", "M".repeat(78)));
        assert_eq!(out.lines().count(), 1, "exactly 100 columns fits");
        let out = round_trip(&format!("element E {{ path \"{}\"; }}", "M".repeat(79)));
        assert_eq!(out.lines().count(), 3);
        let out = round_trip("element E { path \"M\";\n\n width 2; // w\n}");
        assert_eq!(
            out,
            "element E {\n    path \"M\";\n\n    width 2; // w\n}\n"
        );
        // A blank line alone also keeps the block open.
        let mut e = parse_ok("element E { path \"M\"; width 2; }");
        if let Some(Item::Element(el)) = e.items.stmts.get_mut(0).map(|n| &mut n.node) {
            el.props.stmts[1].trivia.blank_before = true;
        }
        assert_eq!(
            format_file(&e),
            "element E {\n    path \"M\";\n\n    width 2;\n}\n"
        );
    }

    #[test]
    fn scene_layout() {
        let src = "scene Palm { guide trunk { polygon (0,0) (30,0) (30,300); system Trunk; seed (15,0) heading 0 with (3); seed (1, -2); }\n\
                   guide crown { system Leaves; } link trunk.edge(2) -> crown.edge(0) { tokens 1; heading 30; } \
                   link trunk.edge(1) -> crown.edge(1) {} }";
        assert_eq!(
            round_trip(src),
            "scene Palm {\n    guide trunk {\n        polygon (0, 0) (30, 0) (30, 300);\n        \
             system Trunk;\n        seed (15, 0) heading 0 with (3);\n        seed (1, -2);\n    }\n\n    \
             guide crown {\n        system Leaves;\n    }\n\n    \
             link trunk.edge(2) -> crown.edge(0) { tokens 1; heading 30; }\n    \
             link trunk.edge(1) -> crown.edge(1) {}\n}\n"
        );
    }

    #[test]
    fn declared_names_keep_letters_apart() {
        let src = "module AB;\nlsystem L {\n module CD(x);\n axiom A B AB C D(1) CD(1) E F;\n\
                   A -> A B(2) A B;\n C < D -> c u t;\n}\nlsystem M { axiom CD(1); }\n";
        let out = round_trip(src);
        assert!(out.contains("    axiom A B AB C D(1) CD(1) EF;\n"), "{out}");
        assert!(out.contains("    A -> A B(2) A B;\n"), "{out}");
        assert!(out.contains("    C < D -> c u t;\n"), "{out}");
        // CD is declared only in L: in M the letters glue again.
        assert!(out.contains("lsystem M {\n    axiom CD(1);\n}"), "{out}");
        let m = parse_ok(&out);
        let Some(Item::Lsystem(l)) = m.items.stmts.last().map(|n| &n.node) else {
            panic!("no lsystem");
        };
        let Some(Stmt::Axiom(ax)) = l.body.stmts.first().map(|n| &n.node) else {
            panic!("no axiom");
        };
        assert_eq!(ax.len(), 2);
    }

    fn all_modules() -> Vec<ModName> {
        let mut v: Vec<ModName> = "+-&^\\/|$*[]{}.!'%".chars().map(ModName::Symbol).collect();
        for n in ["F", "G", "Apex"] {
            v.push(ModName::Name(n.to_string()));
        }
        v.push(ModName::Query("?X".to_string()));
        v.push(ModName::Query("?D_L".to_string()));
        v.push(ModName::Cut);
        v
    }

    fn rule_node(pred: &str, succ: Vec<Module>) -> Node<Stmt> {
        Node::new(
            Stmt::Rule(Rule {
                label: None,
                interpret: false,
                decompose: false,
                left: None,
                pred: Module::new(ModName::Name(pred.to_string()), None),
                right: None,
                cond: None,
                weight: None,
                succ,
            }),
            Default::default(),
        )
    }

    fn file_with(stmts: Vec<Node<Stmt>>) -> File {
        let decl = Item::Module(ModuleDecl {
            name: Ident::new("Apex"),
            params: Vec::new(),
        });
        let ls = Item::Lsystem(Lsystem {
            name: Ident::new("T"),
            params: Vec::new(),
            body: Block {
                stmts,
                end_comments: Vec::new(),
            },
        });
        File {
            items: Block {
                stmts: vec![
                    Node::new(decl, Default::default()),
                    Node::new(ls, Default::default()),
                ],
                end_comments: Vec::new(),
            },
        }
    }

    fn module_names(ms: &[Module]) -> Vec<(ModName, usize)> {
        ms.iter().map(|m| (m.name.clone(), m.arity())).collect()
    }

    #[test]
    fn every_pair_of_modules_reads_back() {
        let mods = all_modules();
        for a in &mods {
            for b in &mods {
                for a_args in [None, Some(vec![Expr::num(1.0)])] {
                    let succ = vec![
                        Module::new(a.clone(), a_args.clone()),
                        Module::new(b.clone(), None),
                    ];
                    let axiom = Node::new(Stmt::Axiom(succ.clone()), Default::default());
                    let ignore = Node::new(Stmt::Ignore(succ.clone()), Default::default());
                    let file = file_with(vec![axiom, ignore, rule_node("A", succ.clone())]);
                    let text = format_file(&file);
                    let back = parse_ok(&text);
                    let Some(Item::Lsystem(l)) = back.items.stmts.get(1).map(|n| &n.node) else {
                        panic!("no lsystem in {text}");
                    };
                    let want = module_names(&succ);
                    for s in &l.body.stmts {
                        let got = match &s.node {
                            Stmt::Axiom(ms) | Stmt::Ignore(ms) => module_names(ms),
                            Stmt::Rule(r) => module_names(&r.succ),
                            other => panic!("unexpected {other:?} in {text}"),
                        };
                        assert_eq!(got, want, "in\n{text}");
                    }
                    assert_eq!(format_file(&back), text);
                }
            }
        }
    }

    #[test]
    fn symbol_pairs_print_tight_unless_they_would_merge() {
        let file = parse_ok("lsystem T { axiom F/ /F/ *F& &F| |F*/F-+F![F]{.}'%; }");
        let out = format_file(&file);
        assert_eq!(
            out,
            "lsystem T {\n    axiom F/ /F/ *F& &F| |F*/F-+F![F]{.}'%;\n}\n"
        );
    }

    #[test]
    fn code_built_ast_with_zero_spans() {
        let var = |s: &str| Expr::new(ExprKind::Var(s.to_string()));
        let bin = |op, a, b| Expr::new(ExprKind::Binary(op, Box::new(a), Box::new(b)));
        let m = |n: &str, args: Option<Vec<Expr>>| Module::new(ModName::Name(n.to_string()), args);
        let sym = |c| Module::new(ModName::Symbol(c), None);
        let rule = Rule {
            label: Some(Ident::new("grow")),
            interpret: false,
            decompose: false,
            left: Some(vec![m("B", None)]),
            pred: m("A", Some(vec![var("l")])),
            right: None,
            cond: Some(bin(BinOp::Gt, var("l"), Expr::num(0.0))),
            weight: Some(Expr::num(0.25)),
            succ: vec![
                m("F", Some(vec![var("l")])),
                sym('['),
                Module::new(ModName::Symbol('+'), Some(vec![Expr::num(30.0)])),
                m("A", Some(vec![bin(BinOp::Mul, var("l"), Expr::num(0.7))])),
                sym(']'),
                m("Apex", None),
                m("F", None),
                m("F", None),
                Module::new(ModName::Cut, None),
            ],
        };
        let mut axiom = Node::new(
            Stmt::Axiom(vec![m("A", Some(vec![Expr::num(1.0)]))]),
            Default::default(),
        );
        axiom.trivia.leading.push(Comment {
            text: "// start".to_string(),
            span: Default::default(),
        });
        let file = file_with(vec![axiom, Node::new(Stmt::Rule(rule), Default::default())]);
        let text = format_file(&file);
        assert_eq!(
            text,
            "module Apex;\n\nlsystem T {\n    // start\n    axiom A(1);\n    \
             grow: B < A(l) : l > 0 ->(0.25) F(l)[+(30) A(l * 0.7)]Apex FF cut;\n}\n"
        );
        let back = parse_ok(&text);
        // The parser records the blank line the policy puts before an lsystem.
        let mut want = file.clone();
        want.items.stmts[1].trivia.blank_before = true;
        assert_eq!(erased(&back), erased(&want));
    }

    #[test]
    fn error_nodes_do_not_panic() {
        let p = parse(
            "lsystem A { axiom F; F -> ) ; angle (; }\nconst = ;\nscene S { guide g { polygon; } link }\nelement E { path; }\n",
        );
        assert!(p.diagnostics.iter().any(|d| d.is_error()));
        let text = format_file(&p.file);
        assert!(text.contains("axiom F;"), "{text}");
        let mut file = File::default();
        file.items
            .stmts
            .push(Node::new(Item::Error, Default::default()));
        assert_eq!(format_file(&file), "");
    }

    /// A small deterministic generator of expressions (no dependencies).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self, n: u64) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 33) % n
        }

        fn expr(&mut self, depth: u32) -> Expr {
            const OPS: [BinOp; 14] = [
                BinOp::Or,
                BinOp::And,
                BinOp::Eq,
                BinOp::Ne,
                BinOp::Lt,
                BinOp::Le,
                BinOp::Gt,
                BinOp::Ge,
                BinOp::Add,
                BinOp::Sub,
                BinOp::Mul,
                BinOp::Div,
                BinOp::Rem,
                BinOp::Pow,
            ];
            let leaf = depth == 0 || self.next(4) == 0;
            let kind = if leaf {
                match self.next(4) {
                    0 => ExprKind::Num([0.0, 1.0, 2.5, 1e-7, 3e20][self.next(5) as usize]),
                    1 => ExprKind::Bool(self.next(2) == 0),
                    _ => ExprKind::Var(["a", "b", "x_1"][self.next(3) as usize].to_string()),
                }
            } else {
                match self.next(6) {
                    0 => ExprKind::Unary(
                        if self.next(2) == 0 {
                            UnOp::Neg
                        } else {
                            UnOp::Not
                        },
                        Box::new(self.expr(depth - 1)),
                    ),
                    1 => {
                        let n = self.next(3);
                        let args = (0..n).map(|_| self.expr(depth - 1)).collect();
                        ExprKind::Call(Ident::new("max"), args)
                    }
                    _ => ExprKind::Binary(
                        OPS[self.next(14) as usize],
                        Box::new(self.expr(depth - 1)),
                        Box::new(self.expr(depth - 1)),
                    ),
                }
            };
            Expr::new(kind)
        }
    }

    #[test]
    fn random_expressions_read_back() {
        let mut rng = Lcg(7);
        for _ in 0..3000 {
            let e = rng.expr(6);
            let text = format!("const X = {};", format_expr(&e));
            let file = parse_ok(&text);
            let Some(Item::Const(c)) = file.items.stmts.first().map(|n| &n.node) else {
                panic!("no const in {text}");
            };
            assert_eq!(erased(&c.value), erased(&e), "{text}");
        }
    }

    #[test]
    fn random_module_strings_read_back() {
        let mut pool = all_modules();
        for n in ["A", "B", "AB", "c", "u", "t", "e", "p", "s"] {
            pool.push(ModName::Name(n.to_string()));
        }
        let mut rng = Lcg(11);
        for _ in 0..2000 {
            let len = rng.next(7) as usize;
            let succ: Vec<Module> = (0..len)
                .map(|_| {
                    let name = pool[rng.next(pool.len() as u64) as usize].clone();
                    let args = (rng.next(3) == 0).then(|| vec![Expr::num(1.0)]);
                    Module::new(name, args)
                })
                .collect();
            let mut file = file_with(vec![
                Node::new(Stmt::Axiom(succ.clone()), Default::default()),
                rule_node("A", succ.clone()),
            ]);
            file.items.stmts.insert(
                0,
                Node::new(
                    Item::Module(ModuleDecl {
                        name: Ident::new("AB"),
                        params: Vec::new(),
                    }),
                    Default::default(),
                ),
            );
            let text = format_file(&file);
            let back = parse_ok(&text);
            let Some(Item::Lsystem(l)) = back.items.stmts.get(2).map(|n| &n.node) else {
                panic!("no lsystem in {text}");
            };
            for s in &l.body.stmts {
                let got = match &s.node {
                    Stmt::Axiom(ms) => module_names(ms),
                    Stmt::Rule(r) => module_names(&r.succ),
                    other => panic!("unexpected {other:?} in {text}"),
                };
                assert_eq!(got, module_names(&succ), "in\n{text}");
            }
        }
    }

    #[test]
    fn deep_expressions() {
        let mut src = String::from("const X = ");
        for _ in 0..150 {
            src.push_str("(1 + ");
        }
        src.push('1');
        for _ in 0..150 {
            src.push(')');
        }
        src.push_str(" + 2^2^2^2^2^2;");
        let out = round_trip(&src);
        assert!(out.starts_with("const X = 1 + (1 + (1 +"));
    }
}
