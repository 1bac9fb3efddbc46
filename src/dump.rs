//! A compact, complete text form of the AST, for snapshots and for comparing
//! trees while ignoring spans (the formatter's round-trip property).
//!
//! Owns: nothing but printing. Every field of every node is printed; the
//! destructuring below makes a new AST field a compile error here until it is.

use crate::ast::*;
use crate::lexer::Comment;
use std::fmt::Write;

/// Dumps a file. With `spans`, every node shows `@start..end`.
pub fn dump(file: &File, spans: bool) -> String {
    let mut d = Dumper {
        out: String::new(),
        spans,
        depth: 0,
    };
    d.block(&file.items, |d, item| d.item(item));
    d.out
}

struct Dumper {
    out: String,
    spans: bool,
    depth: usize,
}

impl Dumper {
    fn line(&mut self, text: &str) {
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn sp(&self, s: crate::span::Span) -> String {
        if self.spans {
            format!(" @{}..{}", s.start, s.end)
        } else {
            String::new()
        }
    }

    fn comment(&mut self, kind: &str, c: &Comment) {
        let s = format!("{kind} {:?}{}", c.text, self.sp(c.span));
        self.line(&s);
    }

    fn block<T>(&mut self, b: &Block<T>, mut f: impl FnMut(&mut Dumper, &T)) {
        let Block {
            stmts,
            end_comments,
        } = b;
        for n in stmts {
            let Node { trivia, node, span } = n;
            let Trivia {
                leading,
                trailing,
                blank_before,
                blank_after_leading,
            } = trivia;
            if *blank_before {
                self.line("(blank)");
            }
            for c in leading {
                self.comment("lead", c);
            }
            if *blank_after_leading {
                self.line("(blank)");
            }
            let s = format!("node{}", self.sp(*span));
            self.line(&s);
            self.depth += 1;
            f(self, node);
            if let Some(c) = trailing {
                self.comment("trail", c);
            }
            self.depth -= 1;
        }
        for c in end_comments {
            self.comment("end", c);
        }
    }

    fn ident(&self, i: &Ident) -> String {
        format!("{}{}", i.name, self.sp(i.span))
    }

    fn idents(&self, is: &[Ident]) -> String {
        is.iter()
            .map(|i| self.ident(i))
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Lsystem(Lsystem { name, params, body }) => {
                let s = format!("lsystem {} ({})", self.ident(name), self.idents(params));
                self.line(&s);
                self.depth += 1;
                self.block(body, |d, s| d.stmt(s));
                self.depth -= 1;
            }
            Item::Module(m) => self.module_decl(m),
            Item::Const(ConstDecl { name, value }) => {
                let s = format!("const {} = {}", self.ident(name), self.expr(value));
                self.line(&s);
            }
            Item::Palette(Palette { body, .. }) => {
                self.line("palette");
                self.depth += 1;
                self.block(body, |d, e| {
                    let name = e
                        .name
                        .as_ref()
                        .map_or(String::new(), |n| format!(" {}", d.ident(n)));
                    let s = format!(
                        "color {} = {:?}{}{name}",
                        d.expr(&e.index),
                        e.color,
                        d.sp(e.color_span)
                    );
                    d.line(&s);
                });
                self.depth -= 1;
            }
            Item::Element(Element { name, props }) => {
                let s = format!("element {}", self.ident(name));
                self.line(&s);
                self.depth += 1;
                self.block(props, |d, p| {
                    let Prop { key, value } = p;
                    let v = match value {
                        PropValue::Str(s, span) => format!("{s:?}{}", d.sp(*span)),
                        PropValue::Expr(e) => d.expr(e),
                    };
                    let s = format!("prop {} = {v}", d.ident(key));
                    d.line(&s);
                });
                self.depth -= 1;
            }
            Item::Scene(Scene { name, body }) => {
                let s = format!("scene {}", self.ident(name));
                self.line(&s);
                self.depth += 1;
                self.block(body, |d, s| d.scene_stmt(s));
                self.depth -= 1;
            }
            Item::Error => self.line("error"),
        }
    }

    fn module_decl(&mut self, m: &ModuleDecl) {
        let ModuleDecl { name, params } = m;
        let s = format!("module {} ({})", self.ident(name), self.idents(params));
        self.line(&s);
    }

    fn stmt(&mut self, s: &Stmt) {
        let text = match s {
            Stmt::Angle(e) => format!("angle {}", self.expr(e)),
            Stmt::Derive(e) => format!("derive {}", self.expr(e)),
            Stmt::Step(e) => format!("step {}", self.expr(e)),
            Stmt::Axiom(ms) => format!("axiom {}", self.modules(ms)),
            Stmt::Ignore(ms) => format!("ignore {}", self.modules(ms)),
            Stmt::Consider(ms) => format!("consider {}", self.modules(ms)),
            Stmt::Tropism(t) => format!(
                "tropism ({}, {}, {}) {}",
                self.expr(&t.dir[0]),
                self.expr(&t.dir[1]),
                self.expr(&t.dir[2]),
                self.expr(&t.elasticity)
            ),
            Stmt::Module(m) => return self.module_decl(m),
            Stmt::Rule(r) => {
                let Rule {
                    label,
                    interpret,
                    decompose,
                    left,
                    pred,
                    right,
                    cond,
                    weight,
                    succ,
                } = r;
                let mut t = String::from("rule");
                if let Some(l) = label {
                    let _ = write!(t, " label={}", self.ident(l));
                }
                if *interpret {
                    t.push_str(" interpret");
                }
                if *decompose {
                    t.push_str(" decompose");
                }
                if let Some(l) = left {
                    let _ = write!(t, " left=[{}]", self.modules(l));
                }
                let _ = write!(t, " pred={}", self.module(pred));
                if let Some(r) = right {
                    let _ = write!(t, " right=[{}]", self.modules(r));
                }
                if let Some(c) = cond {
                    let _ = write!(t, " cond={}", self.expr(c));
                }
                if let Some(w) = weight {
                    let _ = write!(t, " weight={}", self.expr(w));
                }
                let _ = write!(t, " succ=[{}]", self.modules(succ));
                t
            }
            Stmt::Error => "error".to_string(),
        };
        self.line(&text);
    }

    fn scene_stmt(&mut self, s: &SceneStmt) {
        match s {
            SceneStmt::Guide(Guide { name, body }) => {
                let t = format!("guide {}", self.ident(name));
                self.line(&t);
                self.depth += 1;
                self.block(body, |d, g| {
                    let t = match g {
                        GuideStmt::Polygon(pts) => format!(
                            "polygon {}",
                            pts.iter().map(|p| d.point(p)).collect::<Vec<_>>().join(" ")
                        ),
                        GuideStmt::System(n) => format!("system {}", d.ident(n)),
                        GuideStmt::Seed(Seed { at, heading, args }) => {
                            let mut t = format!("seed {}", d.point(at));
                            if let Some(h) = heading {
                                let _ = write!(t, " heading {}", d.expr(h));
                            }
                            if let Some(a) = args {
                                let _ = write!(t, " with ({})", d.exprs(a));
                            }
                            t
                        }
                        GuideStmt::Error => "error".to_string(),
                    };
                    d.line(&t);
                });
                self.depth -= 1;
            }
            SceneStmt::Link(Link { from, to, body }) => {
                let t = format!("link {} -> {}", self.edge(from), self.edge(to));
                self.line(&t);
                self.depth += 1;
                self.block(body, |d, l| {
                    let t = match l {
                        LinkStmt::Tokens(e) => format!("tokens {}", d.expr(e)),
                        LinkStmt::Heading(e) => format!("heading {}", d.expr(e)),
                        LinkStmt::Setting(k, e) => format!("{} {}", k.name, d.expr(e)),
                        LinkStmt::Error => "error".to_string(),
                    };
                    d.line(&t);
                });
                self.depth -= 1;
            }
            SceneStmt::Error => self.line("error"),
        }
    }

    fn point(&self, p: &Point) -> String {
        let Point { x, y, span } = p;
        format!("({}, {}){}", self.expr(x), self.expr(y), self.sp(*span))
    }

    fn edge(&self, e: &EdgeRef) -> String {
        let EdgeRef { guide, index, span } = e;
        format!(
            "{}.edge({}){}",
            self.ident(guide),
            self.expr(index),
            self.sp(*span)
        )
    }

    fn modules(&self, ms: &[Module]) -> String {
        ms.iter()
            .map(|m| self.module(m))
            .collect::<Vec<_>>()
            .join(" ")
    }

    fn module(&self, m: &Module) -> String {
        let Module {
            name,
            name_span,
            args,
            span,
        } = m;
        let n = match name {
            ModName::Name(s) => s.clone(),
            ModName::Symbol(c) => format!("'{c}'"),
            ModName::Query(q) => q.clone(),
            ModName::Cut => "cut".to_string(),
        };
        let mut t = format!("{n}{}", self.sp(*name_span));
        if let Some(a) = args {
            let _ = write!(t, "({})", self.exprs(a));
        }
        if self.spans && span != name_span {
            let _ = write!(t, "{}", self.sp(*span));
        }
        t
    }

    fn exprs(&self, es: &[Expr]) -> String {
        es.iter()
            .map(|e| self.expr(e))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Fully parenthesised, so the tree shape is visible.
    fn expr(&self, e: &Expr) -> String {
        let Expr { kind, span } = e;
        let body = match kind {
            ExprKind::Num(v) => format!("{v}"),
            ExprKind::Bool(b) => format!("{b}"),
            ExprKind::Var(n) => n.clone(),
            ExprKind::Unary(op, a) => {
                let o = match op {
                    UnOp::Neg => "-",
                    UnOp::Not => "!",
                };
                format!("({o}{})", self.expr(a))
            }
            ExprKind::Binary(op, a, b) => {
                format!("({} {} {})", self.expr(a), op.text(), self.expr(b))
            }
            ExprKind::Call(f, args) => format!("{}({})", self.ident(f), self.exprs(args)),
            ExprKind::Error => "<error>".to_string(),
        };
        if self.spans
            && !matches!(
                kind,
                ExprKind::Num(_) | ExprKind::Var(_) | ExprKind::Bool(_)
            )
        {
            format!("{body}{}", self.sp(*span))
        } else {
            body
        }
    }
}
