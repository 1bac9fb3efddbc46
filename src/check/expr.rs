//! Expression checking: names, types (number or boolean), calls, and constant
//! evaluation (through the compiler and VM) of what must be known before derivation.

use super::Checker;
use crate::ast::{BinOp, Expr, ExprKind, UnOp};
use crate::builtins;
use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use crate::vm::expr::{ExprError, Known, evaluate};
use crate::vm::{Fault, Random};
use std::cell::Cell;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    Num,
    Bool,
    /// Already reported; stay quiet.
    Err,
}

impl Ty {
    fn name(self) -> &'static str {
        match self {
            Ty::Num => "a number",
            Ty::Bool => "a boolean",
            Ty::Err => "an error",
        }
    }
}

/// A value known at check time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Num(f64),
    Bool(bool),
}

impl Value {
    /// The value as the VM holds it: booleans are 0 and 1.
    pub fn as_f64(self) -> f64 {
        match self {
            Value::Num(x) => x,
            Value::Bool(b) => f64::from(u8::from(b)),
        }
    }
}

/// The derivation "step" of the random stream constants draw from: apart from
/// every step the derivation and the turtle use.
pub const CONST_STEP: u32 = u32::MAX - 1;

/// Names in scope for an expression besides the constants: parameters.
#[derive(Default)]
pub struct Env {
    pub params: Vec<Param>,
}

pub struct Param {
    pub name: String,
    pub span: Span,
    pub ty: Ty,
    pub used: Cell<bool>,
}

impl Env {
    pub fn new() -> Env {
        Env::default()
    }

    pub fn add(&mut self, name: &str, span: Span) {
        self.add_typed(name, span, Ty::Num);
    }

    /// A parameter of a known type: the `found` output of a query is a boolean.
    pub fn add_typed(&mut self, name: &str, span: Span, ty: Ty) {
        self.params.push(Param {
            name: name.to_string(),
            span,
            ty,
            used: Cell::new(false),
        });
    }

    fn find(&self, name: &str) -> Option<&Param> {
        self.params.iter().find(|p| p.name == name)
    }
}

/// Edit distance with adjacent transpositions (optimal string alignment), for
/// "did you mean": `crwon` is one edit from `crown`.
pub fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let (n, m) = (a.len(), b.len());
    let mut d = vec![vec![0usize; m + 1]; n + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=n {
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[n][m]
}

/// The closest candidate within a small edit distance; on a tie the earliest
/// candidate wins, so callers list the likeliest (rule parameters) first.
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let len = name.chars().count();
    if len < 2 {
        return None;
    }
    let limit = (len / 3).max(1);
    let mut best: Option<(usize, &'a str)> = None;
    for c in candidates {
        if c == name {
            continue;
        }
        let d = distance(name, c);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

impl Checker<'_> {
    /// The type of an expression, reporting every problem inside it.
    pub fn expr(&mut self, e: &Expr, env: &Env) -> Ty {
        match &e.kind {
            ExprKind::Num(_) => Ty::Num,
            ExprKind::Bool(_) => Ty::Bool,
            ExprKind::Error => Ty::Err,
            ExprKind::Var(name) => self.name(name, e.span, env),
            ExprKind::Unary(op, a) => {
                let (want, out) = match op {
                    UnOp::Neg => (Ty::Num, Ty::Num),
                    UnOp::Not => (Ty::Bool, Ty::Bool),
                };
                self.expect(a, env, want);
                out
            }
            ExprKind::Binary(op, a, b) => match op {
                BinOp::Or | BinOp::And => {
                    self.expect(a, env, Ty::Bool);
                    self.expect(b, env, Ty::Bool);
                    Ty::Bool
                }
                BinOp::Eq | BinOp::Ne => {
                    let ta = self.expr(a, env);
                    let tb = self.expr(b, env);
                    if ta != Ty::Err && tb != Ty::Err && ta != tb {
                        self.diags.push(
                            Diagnostic::error(
                                Code::TypeMismatch,
                                format!(
                                    "`{}` compares {} with {}",
                                    op.text(),
                                    ta.name(),
                                    tb.name()
                                ),
                            )
                            .primary(b.span, format!("this is {}", tb.name()))
                            .secondary(a.span, format!("this is {}", ta.name())),
                        );
                    }
                    Ty::Bool
                }
                _ if op.is_comparison() => {
                    self.expect(a, env, Ty::Num);
                    self.expect(b, env, Ty::Num);
                    Ty::Bool
                }
                _ => {
                    self.expect(a, env, Ty::Num);
                    self.expect(b, env, Ty::Num);
                    Ty::Num
                }
            },
            ExprKind::Call(f, args) => self.call(f, args, e.span, env),
        }
    }

    /// The type of a name: a parameter of `env`, or a constant.
    fn name(&mut self, name: &str, span: Span, env: &Env) -> Ty {
        if let Some(p) = env.find(name) {
            p.used.set(true);
            return p.ty;
        }
        if let Some(c) = self.consts.get(name) {
            self.used_consts.insert(name.to_string());
            return c.ty;
        }
        let mut d = Diagnostic::error(Code::UnknownName, format!("unknown name `{name}`"))
            .primary(span, "not a parameter of this rule or a constant");
        let mut consts: Vec<&str> = self.consts.keys().copied().collect();
        consts.sort_unstable();
        let names: Vec<&str> = env
            .params
            .iter()
            .map(|p| p.name.as_str())
            .chain(consts)
            .collect();
        if let Some(s) = suggest(name, names) {
            d = d.did_you_mean(span, s);
        } else if self.lsystem_params.iter().any(|p| p == name) {
            d = d.help(format!(
                "`{name}` is a parameter of the lsystem: it is visible in the axiom only; pass it on as a module parameter, e.g. `axiom A({name});`"
            ));
        } else if builtins::lookup(name).is_some() {
            d = d.help(format!("`{name}` is a function: call it as `{name}(…)`"));
        } else {
            d = d.help("parameters are bound by the predecessor, as in `A(x) -> F(x);`; constants by `const x = 1;`");
        }
        self.diags.push(d);
        Ty::Err
    }

    /// The type of a call of a built-in function (always a number).
    fn call(&mut self, f: &crate::ast::Ident, args: &[Expr], span: Span, env: &Env) -> Ty {
        let Some(b) = builtins::lookup(&f.name) else {
            let mut d = Diagnostic::error(
                Code::UnknownFunction,
                format!("unknown function `{}`", f.name),
            )
            .primary(f.span, "no built-in function has this name");
            if let Some(s) = suggest(&f.name, builtins::BUILTINS.iter().map(|b| b.name)) {
                d = d.did_you_mean(f.span, s);
            } else {
                d = d.note("the functions are listed in docs/language.md");
            }
            self.diags.push(d);
            for a in args {
                self.expr(a, env);
            }
            return Ty::Err;
        };
        if args.len() != b.arity {
            self.diags.push(
                Diagnostic::error(
                    Code::ArityFunction,
                    format!(
                        "`{}` takes {} argument{}, but {} {} given",
                        b.name,
                        b.arity,
                        plural(b.arity),
                        args.len(),
                        if args.len() == 1 { "was" } else { "were" }
                    ),
                )
                .primary(span, format!("{}: {}", b.name, b.doc)),
            );
        }
        for a in args {
            self.expect(a, env, Ty::Num);
        }
        Ty::Num
    }

    /// Checks an expression and reports it if it is not of type `want`.
    pub fn expect(&mut self, e: &Expr, env: &Env, want: Ty) -> Ty {
        let got = self.expr(e, env);
        if got != Ty::Err && got != want {
            self.diags.push(
                Diagnostic::error(
                    Code::TypeMismatch,
                    format!("expected {}, found {}", want.name(), got.name()),
                )
                .primary(e.span, format!("this is {}", got.name())),
            );
        }
        got
    }

    /// The value of an expression made only of literals, constants and
    /// functions, through the compiler and the VM (the one evaluator); `None`
    /// if it uses a parameter of `env`, an unknown name, draws random numbers
    /// or fails (a division by zero).
    pub fn eval_in(&self, e: &Expr, env: &Env) -> Option<Value> {
        match self.evaluate(e, env, u64::MAX) {
            Ok((v, false)) => Some(v),
            _ => None,
        }
    }

    /// `eval_in` with no parameters in scope.
    pub fn eval(&self, e: &Expr) -> Option<Value> {
        self.eval_in(e, &Env::new())
    }

    /// Evaluates a parameterless expression, drawing random numbers from the
    /// constants' stream `stream` of the run's seed. Returns the value (typed
    /// by the checker's type of `e`) and whether it is random.
    pub fn evaluate(&self, e: &Expr, env: &Env, stream: u64) -> Result<(Value, bool), ExprError> {
        let lookup = |name: &str| -> Option<Known> {
            if env.find(name).is_some() {
                return None;
            }
            let c = self.consts.get(name)?;
            Some(Known {
                value: c.value?.as_f64(),
                random: c.random,
            })
        };
        let mut rng = Random::new(self.seed, CONST_STEP, stream);
        let out = evaluate(e, &lookup, &mut rng)?;
        let v = if self.is_bool(e, env) {
            Value::Bool(out.value != 0.0)
        } else {
            Value::Num(out.value)
        };
        Ok((v, out.random))
    }

    /// Whether an expression is boolean (its type, without reporting anything).
    fn is_bool(&self, e: &Expr, env: &Env) -> bool {
        match &e.kind {
            ExprKind::Bool(_) => true,
            ExprKind::Var(n) => match env.find(n) {
                Some(p) => p.ty == Ty::Bool,
                None => self
                    .consts
                    .get(n.as_str())
                    .is_some_and(|c| c.ty == Ty::Bool),
            },
            ExprKind::Unary(UnOp::Not, _) => true,
            ExprKind::Binary(op, _, _) => {
                matches!(op, BinOp::And | BinOp::Or | BinOp::Eq | BinOp::Ne) || op.is_comparison()
            }
            _ => false,
        }
    }

    /// Records the value of a parameterless numeric expression that may draw
    /// random numbers (a seed's arguments), drawn from a stream of its own.
    pub fn record_value(&mut self, e: &Expr) {
        if let Ok((Value::Num(v), _)) = self.evaluate(e, &Env::new(), u64::from(e.span.start) << 32)
        {
            self.values.insert(e.span, v);
        }
    }

    /// Checks an expression that must be a number known before derivation
    /// (constants allowed, parameters and random functions not) and returns it.
    pub fn const_num(&mut self, e: &Expr, what: &str) -> Option<f64> {
        let env = Env::new();
        let before = self.diags.len();
        let ty = self.expect(e, &env, Ty::Num);
        if ty != Ty::Num || self.diags.len() > before {
            return None;
        }
        match self.evaluate(e, &env, u64::MAX) {
            Ok((Value::Num(v), false)) => {
                self.values.insert(e.span, v);
                Some(v)
            }
            Ok((Value::Bool(_), false)) => None,
            Err(ExprError::Vm(err)) => {
                self.diags.push(
                    Diagnostic::error(
                        match err.fault {
                            Fault::DivisionByZero => Code::DivisionByZero,
                            Fault::NotFinite => Code::OutOfRange,
                        },
                        format!("{what} is not a finite number"),
                    )
                    .primary(err.span, err.fault.label()),
                );
                None
            }
            _ => {
                self.diags.push(
                    Diagnostic::error(
                        Code::NotConstant,
                        format!("{what} must be known before derivation"),
                    )
                    .primary(
                        e.span,
                        "this uses a random function or a constant that is not known",
                    )
                    .help("use numbers, constants and deterministic functions here"),
                );
                None
            }
        }
    }

    /// Like `const_num`, and the value must be a whole number in `lo..=hi`.
    pub fn const_int(&mut self, e: &Expr, what: &str, lo: f64, hi: f64) -> Option<i64> {
        let v = self.const_num(e, what)?;
        if v.fract() != 0.0 || v < lo || v > hi {
            let range = if hi >= 1e15 {
                format!("a whole number ≥ {lo}")
            } else {
                format!("a whole number from {lo} to {hi}")
            };
            let mut d = Diagnostic::error(Code::OutOfRange, format!("{what} must be {range}"))
                .primary(e.span, format!("this is {v}"));
            // A value from the command line: say which `-D` gave it.
            let mut names = Vec::new();
            super::names_in(e, &mut names);
            let mut seen = std::collections::HashSet::new();
            for (n, _) in names.into_iter().filter(|(n, _)| seen.insert(n.clone())) {
                if let Some(o) = self
                    .consts
                    .get(n.as_str())
                    .and_then(|c| c.overridden.as_ref())
                {
                    d = d.note(format!(
                        "`{n}` has its value from `{o}` on the command line"
                    ));
                }
            }
            self.diags.push(d);
            return None;
        }
        Some(v as i64)
    }
}

pub fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}
