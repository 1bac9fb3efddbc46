//! The symbol index of one file: every definition and every use, by span.
//!
//! Owns: which name in the text refers to which thing (a constant, a module,
//! an element, an lsystem, a scene, a guide, a parameter, a letter module of
//! one lsystem), following the language's scopes: a rule's parameters are
//! bound by its predecessor and contexts and seen by its condition, weight and
//! successor; an lsystem's parameters by its axiom; everything else sees the
//! constants. Built from the public AST alone on every change; it decides
//! nothing about meaning (the checker does) and never fails: a file the parser
//! recovered from is indexed as far as it goes.

use super::words;
use crate::ast::{
    Expr, ExprKind, File, GuideStmt, Item, LinkStmt, Lsystem, ModName, Module, PropValue, Scene,
    SceneStmt, Stmt,
};
use crate::span::Span;
use std::collections::HashMap;

/// What a symbol is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Const,
    /// A declared module (`module Apex(l);`), at the top or in an lsystem.
    Module,
    Element,
    Lsystem,
    Scene,
    Guide,
    /// A parameter of a rule or of an lsystem.
    Param,
    /// An undeclared module of one lsystem: a single letter (or a name the
    /// resolver could not split, which the checker reports).
    Letter,
}

impl Kind {
    pub fn noun(self) -> &'static str {
        match self {
            Kind::Const => "constant",
            Kind::Module => "module",
            Kind::Element => "element",
            Kind::Lsystem => "lsystem",
            Kind::Scene => "scene",
            Kind::Guide => "guide",
            Kind::Param => "parameter",
            Kind::Letter => "module",
        }
    }
}

/// Where a symbol comes from in the AST, for hover.
#[derive(Clone, Debug, PartialEq)]
pub enum Origin {
    /// A top-level item (`file.items.stmts[i]`).
    Item(usize),
    /// A `module` statement `j` of the lsystem at item `i`.
    LsystemStmt(usize, usize),
    /// Parameter `k` of the lsystem at item `i`.
    LsystemParam(usize, usize),
    /// A parameter bound by argument `arg` of `module` in rule statement
    /// `stmt` of the lsystem at item `item`.
    RuleParam {
        item: usize,
        stmt: usize,
        module: ModName,
        arg: usize,
    },
    /// Guide statement `j` of the scene at item `i`.
    Guide(usize, usize),
    /// A letter module of the lsystem at item `i`.
    Letter(usize),
}

#[derive(Clone, Debug)]
pub struct Symbol {
    pub kind: Kind,
    pub name: String,
    /// The name where it is declared (none for letter modules).
    pub decl: Option<Span>,
    /// The predecessors (name spans) of the rules that rewrite it (modules).
    pub rules: Vec<Span>,
    pub origin: Origin,
    /// The top-level item it belongs to (an lsystem or scene for local
    /// symbols), or `None` for file-wide ones.
    pub scope: Option<usize>,
}

impl Symbol {
    /// Where go-to-definition leads: the declaration, or for a letter module
    /// (declared by use) the predecessors of the rules that rewrite it.
    /// Empty for a letter no rule rewrites (`F`, or a letter that only
    /// appears in strings).
    pub fn definition(&self) -> Vec<Span> {
        match self.decl {
            Some(d) => vec![d],
            None => self.rules.clone(),
        }
    }

    /// The rule (item, statement) or lsystem header (item, `usize::MAX`) a
    /// parameter belongs to.
    pub fn origin_rule(&self) -> Option<(usize, usize)> {
        match self.origin {
            Origin::RuleParam { item, stmt, .. } => Some((item, stmt)),
            Origin::LsystemParam(i, _) => Some((i, usize::MAX)),
            _ => None,
        }
    }
}

/// What a piece of text refers to.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    Symbol(usize),
    /// A query module, `?X` with its `?`.
    Query(String),
    /// A turtle or structure symbol.
    Turtle(char),
    Cut,
    /// A built-in function.
    Function(String),
    /// A word of the language written where a name could be: the module
    /// `tropism(e)`, a link setting (`aim`, `take`) and its value words
    /// (`continue`, `middle`, `closest`). Never a constant, never renamed.
    Word(String),
}

#[derive(Clone, Debug)]
pub struct Occurrence {
    pub span: Span,
    pub target: Target,
    /// The declaration itself (or a binding in a predecessor).
    pub decl: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Index {
    pub symbols: Vec<Symbol>,
    /// Sorted by start.
    pub occurrences: Vec<Occurrence>,
}

/// Namespaces: a name may be a constant, a module and an lsystem at once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Ns {
    Const,
    Module,
    Lsystem,
    Scene,
    Guide,
    Letter,
}

/// A named thing's scope in the key table: the file, or one item.
type Key = (Option<usize>, Ns, String);

impl Index {
    pub fn build(file: &File) -> Index {
        let mut b = Builder {
            index: Index::default(),
            keys: HashMap::new(),
        };
        b.file(file);
        b.index
            .occurrences
            .sort_by_key(|o| (o.span.start, o.span.end));
        b.index
    }

    /// The occurrence at a byte offset: one that contains it, else one that
    /// ends at it (a cursor just after a name).
    pub fn at(&self, offset: usize) -> Option<&Occurrence> {
        let off = u32::try_from(offset).unwrap_or(u32::MAX);
        let upto = self.occurrences.partition_point(|o| o.span.start <= off);
        let candidates = &self.occurrences[..upto];
        candidates
            .iter()
            .rev()
            .take(64)
            .filter(|o| off < o.span.end)
            .min_by_key(|o| o.span.end - o.span.start)
            .or_else(|| candidates.iter().rev().take(64).find(|o| o.span.end == off))
    }

    /// Every occurrence of a target, declarations included, in order.
    pub fn occurrences_of<'a>(
        &'a self,
        t: &'a Target,
    ) -> impl Iterator<Item = &'a Occurrence> + 'a {
        self.occurrences.iter().filter(move |o| &o.target == t)
    }

    pub fn symbol(&self, t: &Target) -> Option<&Symbol> {
        match t {
            Target::Symbol(id) => self.symbols.get(*id),
            _ => None,
        }
    }

    /// The symbols visible by name in the item `scope` (the file's, plus the
    /// item's own), in order of declaration.
    pub fn visible(&self, scope: Option<usize>) -> impl Iterator<Item = &Symbol> {
        self.symbols
            .iter()
            .filter(move |s| s.scope.is_none() || (scope.is_some() && s.scope == scope))
    }
}

struct Builder {
    index: Index,
    keys: HashMap<Key, usize>,
}

/// Parameters in scope: name and symbol.
type Locals<'a> = [(&'a str, usize)];

impl Builder {
    fn define(&mut self, key: Key, kind: Kind, decl: Span, origin: Origin) -> usize {
        let id = match self.keys.get(&key) {
            Some(&id) => id, // a duplicate: the checker reports it; uses go to the first
            None => {
                let id = self.index.symbols.len();
                self.index.symbols.push(Symbol {
                    kind,
                    name: key.2.clone(),
                    decl: Some(decl),
                    rules: Vec::new(),
                    origin,
                    scope: key.0,
                });
                self.keys.insert(key, id);
                id
            }
        };
        self.occ(decl, Target::Symbol(id), true);
        id
    }

    fn param(&mut self, name: &str, span: Span, origin: Origin, scope: usize) -> usize {
        let id = self.index.symbols.len();
        self.index.symbols.push(Symbol {
            kind: Kind::Param,
            name: name.to_string(),
            decl: Some(span),
            rules: Vec::new(),
            origin,
            scope: Some(scope),
        });
        self.occ(span, Target::Symbol(id), true);
        id
    }

    fn occ(&mut self, span: Span, target: Target, decl: bool) {
        if span.is_empty() && !matches!(target, Target::Symbol(_)) {
            return;
        }
        self.index
            .occurrences
            .push(Occurrence { span, target, decl });
    }

    fn file(&mut self, file: &File) {
        // Declarations first: items may use names declared further down.
        for (i, item) in file.items.stmts.iter().enumerate() {
            let (ns, kind, name) = match &item.node {
                Item::Const(c) => (Ns::Const, Kind::Const, &c.name),
                Item::Module(m) => (Ns::Module, Kind::Module, &m.name),
                Item::Element(e) => (Ns::Module, Kind::Element, &e.name),
                Item::Lsystem(l) => (Ns::Lsystem, Kind::Lsystem, &l.name),
                Item::Scene(s) => (Ns::Scene, Kind::Scene, &s.name),
                // A palette names colours and materials, not anything a program refers to.
                Item::Palette(_) | Item::Error => continue,
            };
            if name.name.is_empty() {
                continue;
            }
            self.define(
                (None, ns, name.name.clone()),
                kind,
                name.span,
                Origin::Item(i),
            );
        }
        for (i, item) in file.items.stmts.iter().enumerate() {
            match &item.node {
                Item::Const(c) => self.expr(&c.value, &[]),
                Item::Element(e) => {
                    for p in &e.props.stmts {
                        if let PropValue::Expr(x) = &p.node.value {
                            self.expr(x, &[]);
                        }
                    }
                }
                Item::Lsystem(l) => self.lsystem(i, l),
                Item::Scene(s) => self.scene(i, s),
                Item::Module(_) | Item::Palette(_) | Item::Error => {}
            }
        }
    }

    fn lsystem(&mut self, i: usize, ls: &Lsystem) {
        for (j, st) in ls.body.stmts.iter().enumerate() {
            if let Stmt::Module(m) = &st.node {
                self.define(
                    (Some(i), Ns::Module, m.name.name.clone()),
                    Kind::Module,
                    m.name.span,
                    Origin::LsystemStmt(i, j),
                );
            }
        }
        let mut ls_params: Vec<(&str, usize)> = Vec::new();
        for (k, p) in ls.params.iter().enumerate() {
            if p.name != "_" {
                let id = self.param(&p.name, p.span, Origin::LsystemParam(i, k), i);
                ls_params.push((&p.name, id));
            }
        }
        for (j, st) in ls.body.stmts.iter().enumerate() {
            match &st.node {
                Stmt::Angle(e) | Stmt::Derive(e) | Stmt::Step(e) => self.expr(e, &[]),
                Stmt::Axiom(ms) => self.modules(i, ms, &ls_params),
                Stmt::Ignore(ms) | Stmt::Consider(ms) => self.modules(i, ms, &[]),
                Stmt::Tropism(t) => {
                    for e in t.dir.iter().chain(std::iter::once(&t.elasticity)) {
                        self.expr(e, &[]);
                    }
                }
                // Declared above; a statement the parser skipped has nothing.
                Stmt::Module(_) | Stmt::Error => {}
                Stmt::Rule(r) => {
                    let mut params: Vec<(&str, usize)> = Vec::new();
                    let pats = r
                        .left
                        .iter()
                        .flatten()
                        .chain(std::iter::once(&r.pred))
                        .chain(r.right.iter().flatten());
                    for pm in pats {
                        self.module(i, pm);
                        for (k, a) in pm.args.iter().flatten().enumerate() {
                            match &a.kind {
                                ExprKind::Var(n) if n == "_" => {}
                                ExprKind::Var(n) => {
                                    if let Some(&(_, id)) = params.iter().find(|(p, _)| p == n) {
                                        self.occ(a.span, Target::Symbol(id), false);
                                    } else {
                                        let origin = Origin::RuleParam {
                                            item: i,
                                            stmt: j,
                                            module: pm.name.clone(),
                                            arg: k,
                                        };
                                        let id = self.param(n, a.span, origin, i);
                                        params.push((n, id));
                                    }
                                }
                                _ => self.expr(a, &[]),
                            }
                        }
                    }
                    if let ModName::Name(n) = &r.pred.name
                        && let Some(id) = self.module_symbol(i, n)
                    {
                        self.index.symbols[id].rules.push(r.pred.name_span);
                    }
                    for e in [&r.cond, &r.weight].into_iter().flatten() {
                        self.expr(e, &params);
                    }
                    self.modules(i, &r.succ, &params);
                }
            }
        }
    }

    fn modules(&mut self, ls: usize, ms: &[Module], locals: &Locals) {
        for m in ms {
            self.module(ls, m);
            for a in m.args.iter().flatten() {
                self.expr(a, locals);
            }
        }
    }

    /// The symbol a module name means in lsystem `ls`: its own declaration,
    /// the file's, or a letter module of its own.
    fn module_symbol(&mut self, ls: usize, name: &str) -> Option<usize> {
        if name.is_empty() {
            return None;
        }
        for key in [
            (Some(ls), Ns::Module, name.to_string()),
            (None, Ns::Module, name.to_string()),
            (Some(ls), Ns::Letter, name.to_string()),
        ] {
            if let Some(&id) = self.keys.get(&key) {
                return Some(id);
            }
        }
        let id = self.index.symbols.len();
        self.index.symbols.push(Symbol {
            kind: Kind::Letter,
            name: name.to_string(),
            decl: None,
            rules: Vec::new(),
            origin: Origin::Letter(ls),
            scope: Some(ls),
        });
        self.keys
            .insert((Some(ls), Ns::Letter, name.to_string()), id);
        Some(id)
    }

    fn module(&mut self, ls: usize, m: &Module) {
        let target = match &m.name {
            ModName::Name(n) if crate::resolve::is_builtin(n) => Target::Word(n.clone()),
            ModName::Name(n) => match self.module_symbol(ls, n) {
                Some(id) => Target::Symbol(id),
                None => return,
            },
            ModName::Symbol(c) => Target::Turtle(*c),
            ModName::Query(q) => Target::Query(q.clone()),
            ModName::Cut => Target::Cut,
        };
        self.occ(m.name_span, target, false);
    }

    fn scene(&mut self, i: usize, s: &Scene) {
        for (j, st) in s.body.stmts.iter().enumerate() {
            if let SceneStmt::Guide(g) = &st.node {
                self.define(
                    (Some(i), Ns::Guide, g.name.name.clone()),
                    Kind::Guide,
                    g.name.span,
                    Origin::Guide(i, j),
                );
            }
        }
        for st in &s.body.stmts {
            match &st.node {
                SceneStmt::Guide(g) => {
                    for gs in &g.body.stmts {
                        match &gs.node {
                            GuideStmt::Polygon(ps) => {
                                for p in ps {
                                    self.expr(&p.x, &[]);
                                    self.expr(&p.y, &[]);
                                }
                            }
                            GuideStmt::System(name) => {
                                let key = (None, Ns::Lsystem, name.name.clone());
                                if let Some(&id) = self.keys.get(&key) {
                                    self.occ(name.span, Target::Symbol(id), false);
                                }
                            }
                            GuideStmt::Seed(seed) => {
                                self.expr(&seed.at.x, &[]);
                                self.expr(&seed.at.y, &[]);
                                for e in seed.heading.iter().chain(seed.args.iter().flatten()) {
                                    self.expr(e, &[]);
                                }
                            }
                            GuideStmt::Error => {}
                        }
                    }
                }
                SceneStmt::Link(l) => {
                    for edge in [&l.from, &l.to] {
                        let key = (Some(i), Ns::Guide, edge.guide.name.clone());
                        if let Some(&id) = self.keys.get(&key) {
                            self.occ(edge.guide.span, Target::Symbol(id), false);
                        }
                        self.expr(&edge.index, &[]);
                    }
                    for ls in &l.body.stmts {
                        match &ls.node {
                            // `heading continue;`, `aim middle;`: the value is a
                            // word, never a constant (as the checker reads it).
                            LinkStmt::Heading(e) if link_word(e) == Some("continue") => {
                                self.occ(e.span, Target::Word("continue".into()), false)
                            }
                            LinkStmt::Tokens(e) | LinkStmt::Heading(e) => self.expr(e, &[]),
                            LinkStmt::Setting(k, e) => {
                                // An unknown setting is the checker's error (E0805).
                                if words::is_link_setting(&k.name) {
                                    self.occ(k.span, Target::Word(k.name.clone()), false);
                                }
                                match link_word(e) {
                                    Some(w @ ("middle" | "closest")) if k.name == "aim" => {
                                        self.occ(e.span, Target::Word(w.to_string()), false)
                                    }
                                    _ => self.expr(e, &[]),
                                }
                            }
                            LinkStmt::Error => {}
                        }
                    }
                }
                SceneStmt::Error => {}
            }
        }
    }

    fn expr(&mut self, e: &Expr, locals: &Locals) {
        match &e.kind {
            ExprKind::Var(n) => {
                if let Some(&(_, id)) = locals.iter().rev().find(|(p, _)| p == n) {
                    self.occ(e.span, Target::Symbol(id), false);
                } else if let Some(&id) = self.keys.get(&(None, Ns::Const, n.clone())) {
                    self.occ(e.span, Target::Symbol(id), false);
                }
            }
            ExprKind::Unary(_, a) => self.expr(a, locals),
            ExprKind::Binary(_, a, b) => {
                self.expr(a, locals);
                self.expr(b, locals);
            }
            ExprKind::Call(f, args) => {
                self.occ(f.span, Target::Function(f.name.clone()), false);
                for a in args {
                    self.expr(a, locals);
                }
            }
            ExprKind::Num(_) | ExprKind::Bool(_) | ExprKind::Error => {}
        }
    }
}

/// A link setting's value written as a bare word, as the checker reads it.
fn link_word(e: &Expr) -> Option<&str> {
    match &e.kind {
        ExprKind::Var(n) => Some(n),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsp::{Analysis, rename};

    fn uses(a: &Analysis, name: &str, kind: Kind) -> Vec<String> {
        let id = a
            .index
            .symbols
            .iter()
            .position(|s| s.name == name && s.kind == kind)
            .unwrap_or_else(|| panic!("no {kind:?} {name}"));
        a.index
            .occurrences_of(&Target::Symbol(id))
            .map(|o| format!("{}{}", a.line_of(o.span), if o.decl { "d" } else { "" }))
            .collect()
    }

    const SRC: &str = "const l = 1;\n\
        lsystem T(n) {\n\
        axiom A(l + n);\n\
        A(l) : l < 9 -> F(l) A(l + 1);\n\
        }\n\
        lsystem U { axiom A(l); }\n\
        scene S {\n\
        guide g { polygon (0, 0) (1, 0) (1, l); system T; }\n\
        guide h { polygon (0, 0) (1, 0) (1, 1); system U; }\n\
        link g.edge(0) -> h.edge(1) { tokens l; }\n\
        }\n";

    #[test]
    fn scopes_follow_the_language() {
        let a = Analysis::new(SRC.to_string());
        assert!(
            a.diagnostics.iter().all(|d| !d.is_error()),
            "{:?}",
            a.diagnostics
        );
        // The rule's `l` shadows the constant; the axioms see the constant.
        assert_eq!(uses(&a, "l", Kind::Const), ["1d", "3", "6", "8", "10"]);
        assert_eq!(uses(&a, "l", Kind::Param), ["4d", "4", "4", "4"]);
        assert_eq!(uses(&a, "n", Kind::Param), ["2d", "3"]);
        // `A` of T and `A` of U are different letter modules.
        let letters: Vec<_> = a.index.symbols.iter().filter(|s| s.name == "A").collect();
        assert_eq!(letters.len(), 2);
        assert_eq!(uses(&a, "T", Kind::Lsystem), ["2d", "8"]);
        assert_eq!(uses(&a, "g", Kind::Guide), ["8d", "10"]);
    }

    #[test]
    fn renames_keep_the_meaning() {
        let a = Analysis::new(SRC.to_string());
        let at = |needle: &str| SRC.find(needle).expect("needle");
        assert_eq!(
            rename::rename(&a, at("l = 1"), "len").map(|e| e.len()),
            Ok(5)
        );
        assert_eq!(rename::rename(&a, at("l) :"), "k").map(|e| e.len()), Ok(4));
        // The parameter `n` would capture the constant's use in T's axiom.
        assert!(rename::rename(&a, at("l = 1"), "n").is_err());
        // A letter module stays one letter; `F` would draw.
        assert!(rename::rename(&a, at("A(l) :"), "Apex").is_err());
        assert!(rename::rename(&a, at("A(l) :"), "F").is_err());
        assert_eq!(
            rename::rename(&a, at("A(l) :"), "B").map(|e| e.len()),
            Ok(3)
        );
        assert!(rename::rename(&a, at("g {"), "h").is_err(), "taken");
        assert!(rename::rename(&a, at("g {"), "axiom").is_err(), "a keyword");
        assert!(rename::rename(&a, at("l = 1"), "2x").is_err(), "not a name");
    }
}
