//! The checker: names, arities, types, constants and scenes of a parsed file.
//!
//! Owns: every rule of meaning that can be decided without running the program,
//! reported as diagnostics (errors and warnings), and the constant values the
//! run starts from. Must not derive or draw; it never stops at the first problem.

mod expr;
mod lsystem;
mod scene;

pub use expr::{CONST_STEP, Env, Ty, Value, distance, suggest};

use crate::ast::{ConstDecl, Expr, ExprKind, File, Item};
use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use crate::vm::Fault;
use crate::vm::expr::ExprError;
use std::collections::{BTreeMap, HashMap, HashSet};

/// The most parameters a module may have (its count is stored in a byte).
pub const MAX_PARAMS: usize = 255;

/// A `-D NAME=VALUE` from the command line, as typed.
#[derive(Clone, Debug)]
pub struct Override {
    pub name: String,
    pub value: String,
}

impl Override {
    /// Parses `NAME=VALUE`.
    pub fn parse(s: &str) -> Result<Override, String> {
        match s.split_once('=') {
            Some((n, v)) if !n.trim().is_empty() => Ok(Override {
                name: n.trim().to_string(),
                value: v.trim().to_string(),
            }),
            _ => Err(format!("`{s}` is not of the form NAME=VALUE")),
        }
    }
}

/// What the checker learned, for the phases after it.
#[derive(Debug, Default)]
pub struct Checked {
    pub diagnostics: Vec<Diagnostic>,
    /// Every constant with a value (overrides applied; random ones drawn from
    /// the seed the checker was given).
    pub consts: BTreeMap<String, Constant>,
    /// The value of every expression that must be known before derivation
    /// (settings, polygon and seed coordinates, headings, token counts, edge
    /// indices, element widths), by the expression's span.
    pub values: HashMap<Span, f64>,
}

/// A constant's value and whether it was drawn from the run's generator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant {
    pub value: Value,
    pub random: bool,
}

impl Checked {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }

    /// A constant as the compiler sees it (booleans as 0 and 1).
    pub fn lookup(&self, name: &str) -> Option<crate::vm::expr::Known> {
        self.consts.get(name).map(|c| crate::vm::expr::Known {
            value: c.value.as_f64(),
            random: c.random,
        })
    }

    /// The value the checker computed for an expression that must be known
    /// before derivation.
    pub fn value_of(&self, e: &Expr) -> Option<f64> {
        self.values.get(&e.span).copied()
    }
}

struct ConstInfo<'a> {
    decl: &'a ConstDecl,
    span: Span,
    ty: Ty,
    value: Option<Value>,
    /// Drawn from the run's generator (directly or through another constant).
    random: bool,
    /// The `-D NAME=VALUE` that gave it its value, if one did.
    overridden: Option<String>,
}

struct ModuleInfo {
    /// `None` for elements (any number of parameters).
    arity: Option<usize>,
    span: Span,
    element: bool,
}

struct Checker<'a> {
    diags: Vec<Diagnostic>,
    consts: HashMap<&'a str, ConstInfo<'a>>,
    used_consts: HashSet<String>,
    modules: HashMap<&'a str, ModuleInfo>,
    used_modules: HashSet<String>,
    systems: HashMap<&'a str, (Span, usize)>,
    used_systems: HashSet<String>,
    /// The parameters of the lsystem being checked (for a better "unknown name").
    lsystem_params: Vec<String>,
    /// Unknown query names already reported in this lsystem.
    reported_queries: HashSet<String>,
    /// The run's seed, for constants that draw random numbers.
    seed: u64,
    /// Values of expressions that must be known before derivation.
    values: HashMap<Span, f64>,
}

/// Checks a parsed file. `overrides` are the command line's `-D` values;
/// random constants draw from `seed` (the run's `--seed`).
pub fn check(file: &File, overrides: &[Override], seed: u64) -> Checked {
    let mut c = Checker {
        seed,
        values: HashMap::new(),
        diags: Vec::new(),
        consts: HashMap::new(),
        used_consts: HashSet::new(),
        modules: HashMap::new(),
        used_modules: HashSet::new(),
        systems: HashMap::new(),
        used_systems: HashSet::new(),
        lsystem_params: Vec::new(),
        reported_queries: HashSet::new(),
    };
    c.declarations(file);
    c.constants(file, overrides);
    let mut palette: Option<Span> = None;
    for item in &file.items.stmts {
        match &item.node {
            Item::Lsystem(ls) => c.lsystem(ls),
            Item::Element(e) => c.element(e),
            Item::Palette(p) => {
                if let Some(first) = palette {
                    c.diags.push(
                        Diagnostic::error(Code::DuplicateSetting, "a second palette")
                            .primary(p.keyword, "given again here")
                            .secondary(first, "first given here")
                            .help("a file has one palette: merge them"),
                    );
                }
                palette.get_or_insert(p.keyword);
                c.palette(p);
            }
            Item::Scene(s) => c.scene(s),
            Item::Module(_) | Item::Const(_) | Item::Error => {}
        }
    }
    c.unused(file);
    let consts = c
        .consts
        .iter()
        .filter_map(|(k, v)| {
            let value = v.value?;
            Some((
                k.to_string(),
                Constant {
                    value,
                    random: v.random,
                },
            ))
        })
        .collect();
    let mut diagnostics = c.diags;
    crate::diagnostic::sort(&mut diagnostics);
    Checked {
        diagnostics,
        consts,
        values: c.values,
    }
}

fn duplicate(what: &str, name: &str, span: Span, first: Span) -> Diagnostic {
    Diagnostic::error(Code::Duplicate, format!("{what} `{name}` is defined twice"))
        .primary(span, "defined again here")
        .secondary(first, "first defined here")
        .help("rename one of them")
}

impl<'a> Checker<'a> {
    fn declarations(&mut self, file: &'a File) {
        for item in &file.items.stmts {
            match &item.node {
                Item::Module(m) => {
                    if let Some(prev) = self.modules.get(m.name.name.as_str()) {
                        self.diags
                            .push(duplicate("module", &m.name.name, m.name.span, prev.span));
                        continue;
                    }
                    self.check_param_names(&m.params);
                    self.too_many_params(m.params.len(), m.name.span);
                    self.modules.insert(
                        &m.name.name,
                        ModuleInfo {
                            arity: Some(m.params.len()),
                            span: m.name.span,
                            element: false,
                        },
                    );
                }
                Item::Element(e) => {
                    if let Some(prev) = self.modules.get(e.name.name.as_str()) {
                        self.diags
                            .push(duplicate("module", &e.name.name, e.name.span, prev.span));
                        continue;
                    }
                    self.modules.insert(
                        &e.name.name,
                        ModuleInfo {
                            arity: None,
                            span: e.name.span,
                            element: true,
                        },
                    );
                }
                Item::Palette(_) => {}
                Item::Lsystem(l) => {
                    if let Some((prev, _)) = self.systems.get(l.name.name.as_str()) {
                        self.diags
                            .push(duplicate("lsystem", &l.name.name, l.name.span, *prev));
                        continue;
                    }
                    self.check_param_names(&l.params);
                    self.systems
                        .insert(&l.name.name, (l.name.span, l.params.len()));
                }
                Item::Scene(s) => {
                    if let Some((prev, _)) = self.systems.get(s.name.name.as_str()) {
                        self.diags
                            .push(duplicate("item", &s.name.name, s.name.span, *prev));
                    }
                }
                Item::Const(_) | Item::Error => {}
            }
        }
    }

    /// A module string stores a module's parameter count in a byte.
    fn too_many_params(&mut self, n: usize, span: Span) {
        if n > MAX_PARAMS {
            self.diags.push(
                Diagnostic::error(
                    Code::TooManyParameters,
                    format!("a module takes at most {MAX_PARAMS} parameters; this one has {n}"),
                )
                .primary(span, format!("{n} parameters"))
                .help("group the values differently, or keep some in constants"),
            );
        }
    }

    fn check_param_names(&mut self, params: &[crate::ast::Ident]) {
        for (i, p) in params.iter().enumerate() {
            if let Some(first) = params[..i]
                .iter()
                .find(|q| q.name == p.name && p.name != "_")
            {
                self.diags
                    .push(duplicate("parameter", &p.name, p.span, first.span));
            }
        }
    }

    fn constants(&mut self, file: &'a File, overrides: &[Override]) {
        let mut order: Vec<&'a str> = Vec::new();
        for item in &file.items.stmts {
            let Item::Const(c) = &item.node else { continue };
            if let Some(prev) = self.consts.get(c.name.name.as_str()) {
                self.diags
                    .push(duplicate("constant", &c.name.name, c.name.span, prev.span));
                continue;
            }
            order.push(&c.name.name);
            self.consts.insert(
                &c.name.name,
                ConstInfo {
                    decl: c,
                    span: c.name.span,
                    ty: Ty::Err,
                    value: None,
                    random: false,
                    overridden: None,
                },
            );
        }
        // Dependencies between constants, then a depth-first order that reports cycles.
        let deps: HashMap<&str, Vec<(String, Span)>> = order
            .iter()
            .map(|n| {
                let mut refs = Vec::new();
                names_in(&self.consts[n].decl.value, &mut refs);
                refs.retain(|(r, _)| self.consts.contains_key(r.as_str()));
                (*n, refs)
            })
            .collect();
        let (sorted, in_cycle) = self.sort_consts(&order, &deps);
        let overridden: HashMap<&str, &Override> =
            overrides.iter().map(|o| (o.name.as_str(), o)).collect();
        self.unknown_overrides(overrides);
        let index: HashMap<&str, usize> = order.iter().enumerate().map(|(i, n)| (*n, i)).collect();
        for n in sorted {
            let decl = self.consts[n].decl;
            let ty = if in_cycle.contains(n) {
                Ty::Err
            } else {
                self.expr(&decl.value, &Env::new())
            };
            let (mut value, mut random) = (None, false);
            if ty != Ty::Err {
                let stream = index.get(n).map_or(u64::MAX, |&i| i as u64);
                match self.evaluate(&decl.value, &Env::new(), stream) {
                    Ok((v, r)) => (value, random) = (Some(v), r),
                    Err(ExprError::Vm(err)) => self.diags.push(
                        Diagnostic::error(
                            match err.fault {
                                Fault::DivisionByZero => Code::DivisionByZero,
                                Fault::NotFinite => Code::NotFinite,
                            },
                            format!("constant `{n}` has no finite value"),
                        )
                        .primary(err.span, err.fault.label())
                        .help("constants are computed before the run; give it a value that is a finite number"),
                    ),
                    Err(_) => {}
                }
            }
            if let Some(o) = overridden.get(n)
                && let Some(v) = self.override_value(o, ty, decl.value.span)
            {
                (value, random) = (Some(v), false);
                if let Some(info) = self.consts.get_mut(n) {
                    info.overridden = Some(format!("-D {}={}", o.name, o.value));
                }
            }
            if let Some(info) = self.consts.get_mut(n) {
                info.ty = ty;
                info.value = value;
                info.random = random;
            }
        }
    }

    /// `-D` overrides that name no constant of the program.
    fn unknown_overrides(&mut self, overrides: &[Override]) {
        for o in overrides {
            if !self.consts.contains_key(o.name.as_str()) {
                let mut d = Diagnostic::error(
                    Code::BadOverride,
                    format!("`-D {}`: the program has no constant `{}`", o.name, o.name),
                );
                let names: Vec<&str> = self.consts.keys().copied().collect();
                // `-D depth=3` for `DEPTH`: the case alone differs, whatever the length.
                let same_letters = names
                    .iter()
                    .copied()
                    .filter(|n| n.eq_ignore_ascii_case(&o.name))
                    .min();
                if let Some(s) = same_letters.or_else(|| suggest(&o.name, names.iter().copied())) {
                    d = d.help(format!("did you mean `{s}`?"));
                    if let Some(c) = self.consts.get(s) {
                        d = d.secondary(c.span, format!("`{s}` is declared here"));
                    }
                } else if names.is_empty() {
                    d = d.note("the program declares no constants; add `const NAME = VALUE;` to make a value overridable");
                } else {
                    let mut names = names;
                    names.sort_unstable();
                    d = d.note(format!("its constants are: {}", names.join(", ")));
                }
                self.diags.push(d);
            }
        }
    }

    /// The value a `-D` override gives a constant of type `ty` (defined at
    /// `def`), or `None` (reported) if it is not a value of that kind.
    fn override_value(&mut self, o: &Override, ty: Ty, def: Span) -> Option<Value> {
        let Some(v) = parse_value(&o.value) else {
            self.diags.push(
                Diagnostic::error(
                    Code::BadOverride,
                    format!("`-D {}={}`: `{}` is not a number", o.name, o.value, o.value),
                )
                .help("write the value as a number, e.g. `-D N=7` or `-D angle=22.5`"),
            );
            return None;
        };
        let vty = match v {
            Value::Num(_) => Ty::Num,
            Value::Bool(_) => Ty::Bool,
        };
        if ty != Ty::Err && vty != ty {
            self.diags.push(
                Diagnostic::error(
                    Code::BadOverride,
                    format!(
                        "`-D {}={}` gives {} a value of the wrong kind",
                        o.name, o.value, o.name
                    ),
                )
                .secondary(
                    def,
                    "the constant is defined here with a value of another kind",
                ),
            );
            return None;
        }
        Some(v)
    }

    /// The constants in an order where each comes after those it uses (a
    /// depth-first search in declaration order, with an explicit stack: a chain
    /// of 100,000 constants must not overflow the thread's stack), and the
    /// constants on a cycle, each cycle reported once.
    fn sort_consts(
        &mut self,
        order: &[&'a str],
        deps: &HashMap<&str, Vec<(String, Span)>>,
    ) -> (Vec<&'a str>, HashSet<String>) {
        let mut state: HashMap<&'a str, u8> = HashMap::new(); // 1 visiting, 2 done
        let mut sorted: Vec<&'a str> = Vec::new();
        let mut in_cycle: HashSet<String> = HashSet::new();
        for &root in order {
            if state.contains_key(root) {
                continue;
            }
            state.insert(root, 1);
            let mut stack: Vec<(&'a str, usize)> = vec![(root, 0)];
            while let Some(top) = stack.last_mut() {
                let n = top.0;
                let Some((d, _)) = deps.get(n).and_then(|v| v.get(top.1)) else {
                    state.insert(n, 2);
                    sorted.push(n);
                    stack.pop();
                    continue;
                };
                top.1 += 1;
                let Some((&key, _)) = self.consts.get_key_value(d.as_str()) else {
                    continue;
                };
                match state.get(key) {
                    Some(2) => {}
                    Some(_) => {
                        let start = stack.iter().position(|(p, _)| *p == key).unwrap_or(0);
                        let cycle: Vec<&str> = stack[start..].iter().map(|(p, _)| *p).collect();
                        self.report_cycle(&cycle, &mut in_cycle);
                    }
                    None => {
                        state.insert(key, 1);
                        stack.push((key, 0));
                    }
                }
            }
        }
        (sorted, in_cycle)
    }

    fn report_cycle(&mut self, cycle: &[&str], in_cycle: &mut HashSet<String>) {
        if cycle.is_empty() || cycle.iter().any(|c| in_cycle.contains(*c)) {
            return;
        }
        let first = self.consts[cycle[0]].span;
        if cycle.len() == 1 {
            self.diags.push(
                Diagnostic::error(
                    Code::ConstCycle,
                    format!("constant `{}` is defined in terms of itself", cycle[0]),
                )
                .primary(first, "its value uses its own name")
                .help("give it a value that does not refer to itself"),
            );
            in_cycle.insert(cycle[0].to_string());
            return;
        }
        // A long cycle is named by its first constants only: the message stays
        // readable (and small) however many constants the cycle runs through.
        const SHOWN: usize = 8;
        let shown = &cycle[..cycle.len().min(SHOWN)];
        let more = cycle.len() - shown.len();
        let names = shown
            .iter()
            .map(|c| format!("`{c}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let names = if more > 0 {
            format!("{names} and {more} more")
        } else {
            names
        };
        let mut d = Diagnostic::error(
            Code::ConstCycle,
            format!("constants {names} are defined in terms of each other"),
        )
        .primary(first, "this constant depends on itself");
        for c in &shown[1..] {
            d = d.secondary(self.consts[c].span, "which depends on this one");
        }
        let mut chain: Vec<&str> = shown.to_vec();
        if more > 0 {
            chain.push("…");
        }
        chain.push(cycle[0]);
        d = d
            .note(format!("the cycle: {}", chain.join(" → ")))
            .help("give one of them a value that does not refer back");
        self.diags.push(d);
        for c in cycle {
            in_cycle.insert(c.to_string());
        }
    }

    fn unused(&mut self, file: &File) {
        let has_scene = file
            .items
            .stmts
            .iter()
            .any(|i| matches!(i.node, Item::Scene(_)));
        for item in &file.items.stmts {
            let (what, name, span) = match &item.node {
                Item::Const(c)
                    if !self.used_consts.contains(&c.name.name)
                        && self
                            .consts
                            .get(c.name.name.as_str())
                            .is_none_or(|i| i.ty != Ty::Err) =>
                {
                    ("constant", &c.name.name, c.name.span)
                }
                Item::Module(m) if !self.used_modules.contains(&m.name.name) => {
                    ("module", &m.name.name, m.name.span)
                }
                Item::Element(e) if !self.used_modules.contains(&e.name.name) => {
                    ("element", &e.name.name, e.name.span)
                }
                Item::Lsystem(l) if has_scene && !self.used_systems.contains(&l.name.name) => {
                    ("lsystem", &l.name.name, l.name.span)
                }
                _ => continue,
            };
            self.diags.push(
                Diagnostic::warning(Code::Unused, format!("{what} `{name}` is never used"))
                    .primary(span, "declared here")
                    .help(format!(
                        "remove it, or use it in a rule{}",
                        if what == "lsystem" {
                            " or a guide's `system`"
                        } else {
                            ""
                        }
                    )),
            );
        }
    }
}

/// All variable names an expression refers to.
pub fn names_in(e: &Expr, out: &mut Vec<(String, Span)>) {
    match &e.kind {
        ExprKind::Var(n) => out.push((n.clone(), e.span)),
        ExprKind::Unary(_, a) => names_in(a, out),
        ExprKind::Binary(_, a, b) => {
            names_in(a, out);
            names_in(b, out);
        }
        ExprKind::Call(_, args) => args.iter().for_each(|a| names_in(a, out)),
        ExprKind::Num(_) | ExprKind::Bool(_) | ExprKind::Error => {}
    }
}

fn parse_value(s: &str) -> Option<Value> {
    match s {
        "true" => Some(Value::Bool(true)),
        "false" => Some(Value::Bool(false)),
        _ => s
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .map(Value::Num),
    }
}
