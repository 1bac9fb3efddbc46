//! Checks of one `lsystem`: settings, rules, module arities, query signatures,
//! brackets, and the warnings about rules that cannot fire.

use super::expr::{Env, Ty, Value, plural};
use super::{Checker, duplicate};
use crate::ast::{ExprKind, Lsystem, ModName, Module, Rule, Stmt};
use crate::diagnostic::{Code, Diagnostic};
use crate::query::{self, Query};
use crate::resolve::is_letter;
use crate::span::Span;
use std::collections::{HashMap, HashSet};

/// What a module of a module string is.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// A declared multi-letter module with its arity.
    Declared(usize),
    Element,
    /// A single letter other than F and f.
    Letter,
    /// F, f and the turtle symbols: read their first parameter, accept more.
    Turtle,
    Query(&'static Query),
    UnknownQuery,
    /// `[ ] { } % cut`: structure, no parameters, never rewritten.
    Structure,
    /// An undeclared multi-letter name: the resolver has reported it.
    Undeclared,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Axiom,
    Successor,
    Context,
    Ignore,
}

struct Local {
    decls: HashMap<String, (usize, Span)>,
    rule_arity: HashMap<ModName, (usize, Span)>,
    turtle_arities: HashMap<ModName, HashSet<usize>>,
    query_pass: HashMap<String, (usize, Span)>,
    /// (symbol, arity) pairs already warned about as never rewritten.
    warned: HashSet<(ModName, usize)>,
    /// Queries whose pass-through mismatch is already reported.
    pass_reported: HashSet<&'static str>,
    /// Whether a `consider` list was given.
    considers: bool,
}

impl<'a> Checker<'a> {
    pub(super) fn lsystem(&mut self, ls: &'a Lsystem) {
        self.lsystem_params = ls.params.iter().map(|p| p.name.clone()).collect();
        self.reported_queries.clear();
        self.labels(ls);
        let mut local = Local {
            decls: HashMap::new(),
            rule_arity: HashMap::new(),
            turtle_arities: HashMap::new(),
            query_pass: HashMap::new(),
            warned: HashSet::new(),
            pass_reported: HashSet::new(),
            considers: false,
        };
        self.settings(ls, &mut local);
        let rules: Vec<&Rule> = ls
            .body
            .stmts
            .iter()
            .filter_map(|s| match &s.node {
                Stmt::Rule(r) => Some(r),
                _ => None,
            })
            .collect();
        for r in &rules {
            self.predecessor(r, &mut local);
        }
        // Uses: axiom, successors, contexts, ignore lists.
        let mut axiom_env = Env::new();
        for p in &ls.params {
            axiom_env.add(&p.name, p.span);
        }
        for s in &ls.body.stmts {
            match &s.node {
                Stmt::Axiom(ms) => {
                    self.module_list(ms, Role::Axiom, &mut local);
                    for m in ms {
                        self.module_args(m, &axiom_env);
                    }
                    self.brackets(ms);
                }
                Stmt::Ignore(ms) | Stmt::Consider(ms) => {
                    self.module_list(ms, Role::Ignore, &mut local)
                }
                Stmt::Rule(r) => {
                    for ctx in [&r.left, &r.right].into_iter().flatten() {
                        self.module_list(ctx, Role::Context, &mut local);
                    }
                    self.module_list(&r.succ, Role::Successor, &mut local);
                }
                _ => {}
            }
        }
        for p in &axiom_env.params {
            if !p.used.get() && !p.name.starts_with('_') {
                self.diags.push(
                    Diagnostic::warning(
                        Code::Unused,
                        format!("lsystem parameter `{}` is never used", p.name),
                    )
                    .primary(p.span, "declared here")
                    .help("use it in the axiom, or name it `_` if only the count matters"),
                );
            }
        }
        for r in &rules {
            self.rule_body(r);
        }
        self.unreachable_rules(ls, &rules);
        self.star_contexts(&rules);
        self.does_nothing(ls, &rules, &local);
        self.interpret_cycles(&rules);
    }

    /// ABOP's and cpfg's `*` in a context means "any module"; here it is the
    /// scale module, so such a rule never fires where it was meant to.
    fn star_contexts(&mut self, rules: &[&Rule]) {
        for r in rules {
            for m in [&r.left, &r.right].into_iter().flatten().flatten() {
                if m.name == ModName::Symbol('*') && m.args.is_none() {
                    self.diags.push(
                        Diagnostic::warning(
                            Code::StarContext,
                            "`*` in a context is the scale module, not a wildcard",
                        )
                        .primary(m.span, "matches only a `*` module")
                        .note("in ABOP and cpfg `*` in a context matches any module; lsyc has no wildcard")
                        .help("leave that side of the context out: a rule without context matches whatever surrounds the module"),
                    );
                }
            }
        }
    }

    /// A letter written with parameters that no rule of any kind rewrites, no
    /// context reads and the turtle does not draw: a silent no-op, often a
    /// command of another tool (cpfg's `T(…)` tropism).
    fn does_nothing(&mut self, ls: &Lsystem, rules: &[&Rule], local: &Local) {
        // A name with rules of another arity is E0402's business.
        let mut handled: HashSet<&ModName> = HashSet::new();
        let mut read: HashSet<&ModName> = HashSet::new();
        for r in rules {
            handled.insert(&r.pred.name);
            for m in [&r.left, &r.right].into_iter().flatten().flatten() {
                read.insert(&m.name);
            }
        }
        let mut warned: HashSet<(&ModName, usize)> = HashSet::new();
        let strings = ls.body.stmts.iter().flat_map(|s| {
            let ms = match &s.node {
                Stmt::Axiom(ms) => ms.as_slice(),
                Stmt::Rule(r) => r.succ.as_slice(),
                _ => &[],
            };
            // With the module before each: a letter glued to a letter before it
            // comes from a split word, which W0301 reports.
            ms.iter()
                .enumerate()
                .map(move |(k, m)| (k.checked_sub(1).map(|j| &ms[j]), m))
        });
        for (prev, m) in strings {
            let arity = m.arity();
            let glued = prev.is_some_and(|p| {
                p.args.is_none()
                    && matches!(&p.name, ModName::Name(n) if is_letter(n))
                    && p.span.end == m.span.start
            });
            if arity == 0
                || arity > 255
                || glued
                || !matches!(self.kind(m, local), Kind::Letter)
                || handled.contains(&m.name)
                || read.contains(&m.name)
                || !warned.insert((&m.name, arity))
            {
                continue;
            }
            let name = m.name.text();
            let mut d = Diagnostic::warning(
                Code::DoesNothing,
                format!(
                    "`{name}` with {arity} parameter{} is never rewritten and draws nothing",
                    plural(arity)
                ),
            )
            .primary(m.span, "this module has no effect")
            .note("only `F` and `f`, turtle symbols, elements and modules with `interpret` rules draw");
            d = if name == "T" && (arity == 4 || arity == 1) {
                d.help("for tropism write the statement `tropism (x, y, z) e;` in the lsystem (and `tropism(e)` in a string to change e)")
            } else {
                d.help(format!(
                    "add a rule for `{name}` with {arity} parameter{}, an `interpret` rule to draw it, or remove it",
                    plural(arity)
                ))
            };
            self.diags.push(d);
        }
    }

    /// Interpretation rules that always apply and produce, directly or through
    /// each other, the module they rewrite: interpretation would never end (the
    /// run fails with E0905); reported here, at the rule.
    fn interpret_cycles(&mut self, rules: &[&Rule]) {
        // For each (name, arity): its first interpret rule, when it always applies.
        let mut first: HashMap<(&ModName, usize), Option<&Rule>> = HashMap::new();
        for r in rules.iter().filter(|r| r.interpret) {
            first
                .entry((&r.pred.name, r.pred.arity()))
                .or_insert((r.cond.is_none() && r.weight.is_none()).then_some(*r));
        }
        let mut reported: HashSet<(&ModName, usize)> = HashSet::new();
        for r in rules.iter().filter(|r| r.interpret) {
            let start = (&r.pred.name, r.pred.arity());
            let Some(Some(rule)) = first.get(&start).copied() else {
                continue;
            };
            // Walk the modules reachable through always-applying rules.
            let mut seen: HashSet<(&ModName, usize)> = HashSet::new();
            let mut todo: Vec<(&ModName, usize)> =
                rule.succ.iter().map(|m| (&m.name, m.arity())).collect();
            let mut cycle = false;
            while let Some(k) = todo.pop() {
                if k == start {
                    cycle = true;
                    break;
                }
                if !seen.insert(k) {
                    continue;
                }
                if let Some(Some(r)) = first.get(&k) {
                    todo.extend(r.succ.iter().map(|m| (&m.name, m.arity())));
                }
            }
            if !cycle || !reported.insert(start) {
                continue;
            }
            let name = start.0.text();
            let span = rule
                .pred
                .span
                .to(rule.succ.last().map_or(rule.pred.span, |m| m.span));
            let mut d = Diagnostic::error(
                Code::InterpretTooDeep,
                format!("`interpret {name}` produces `{name}` again, so drawing would never end"),
            )
            .primary(
                span,
                "this rule always applies and its successor leads back to it",
            )
            .note("interpretation rules apply again to the modules they produce");
            d = if rule.succ.iter().any(|m| (&m.name, m.arity()) == start) {
                d.help(format!(
                    "derive another letter and interpret that one, e.g. `I` in the rules and `interpret I -> {name} …;`; or give the rule a condition that ends the recursion"
                ))
            } else {
                d.help("give one of these rules a condition that ends the recursion")
            };
            self.diags.push(d);
        }
    }

    /// Labels name rules, so two rules of one lsystem may not share one.
    fn labels(&mut self, ls: &Lsystem) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for s in &ls.body.stmts {
            if let Stmt::Rule(r @ Rule { label: Some(l), .. }) = &s.node {
                let (help, word) = match l.name.as_str() {
                    "decomposition" | "decompositions" => (
                        Some("lsyc marks each rule instead of a section: `decompose A -> B C;`"),
                        "decompose",
                    ),
                    "homomorphism" | "homomorphisms" | "interpretation" => (
                        Some("lsyc marks each rule instead of a section: `interpret A -> F;`"),
                        "interpret",
                    ),
                    "production" | "productions" | "derivation" | "endgroup" | "group" => {
                        (Some("lsyc rules need no section: remove the label"), "")
                    }
                    _ => (None, ""),
                };
                // The label and its colon, replaced by the rule's kind (when
                // the rule can be one: no kind yet, no context).
                let plain = !r.interpret && !r.decompose && r.left.is_none() && r.right.is_none();
                let fix = (word.is_empty() || plain).then(|| {
                    let title = if word.is_empty() {
                        "remove the label".to_string()
                    } else {
                        format!("write `{word}`")
                    };
                    (
                        title,
                        Span::new(l.span.start as usize, l.span.end as usize + 1),
                        word,
                    )
                });
                if let Some(help) = help {
                    let mut d = Diagnostic::warning(
                        Code::SectionLabel,
                        format!(
                            "`{}:` is read as the label of one rule, not as a section",
                            l.name
                        ),
                    )
                    .primary(l.span, "a rule label (a name for this rule only)")
                    .note("cpfg and L-Py divide an L-system into sections; lsyc has none")
                    .help(help);
                    if let Some((title, span, word)) = fix {
                        d = d.fix(title, span, word);
                    }
                    self.diags.push(d);
                }
                if let Some(first) = seen.get(l.name.as_str()) {
                    self.diags
                        .push(duplicate("rule label", &l.name, l.span, *first));
                } else {
                    seen.insert(&l.name, l.span);
                }
            }
        }
    }

    fn kind(&self, m: &Module, local: &Local) -> Kind {
        match &m.name {
            ModName::Name(n) => {
                if let Some((a, _)) = local.decls.get(n) {
                    return Kind::Declared(*a);
                }
                match self.modules.get(n.as_str()) {
                    Some(info) if info.element => Kind::Element,
                    Some(info) => Kind::Declared(info.arity.unwrap_or(0)),
                    None if n == "F" || n == "f" || n == "tropism" => Kind::Turtle,
                    None if is_letter(n) => Kind::Letter,
                    None => Kind::Undeclared,
                }
            }
            ModName::Symbol('[' | ']' | '{' | '}' | '%') | ModName::Cut => Kind::Structure,
            ModName::Symbol(_) => Kind::Turtle,
            ModName::Query(q) => query::lookup(q).map_or(Kind::UnknownQuery, Kind::Query),
        }
    }

    fn settings(&mut self, ls: &'a Lsystem, local: &mut Local) {
        let mut seen: HashMap<&'static str, Span> = HashMap::new();
        for s in &ls.body.stmts {
            let key = match &s.node {
                Stmt::Angle(_) => "angle",
                Stmt::Derive(_) => "derive",
                Stmt::Step(_) => "step",
                Stmt::Axiom(_) => "axiom",
                Stmt::Tropism(_) => "tropism",
                Stmt::Ignore(_) | Stmt::Consider(_) => "ignore",
                Stmt::Module(m) => {
                    if let Some((_, first)) = local.decls.get(&m.name.name) {
                        self.diags
                            .push(duplicate("module", &m.name.name, m.name.span, *first));
                    } else if let Some(info) = self.modules.get(m.name.name.as_str()) {
                        self.diags
                            .push(duplicate("module", &m.name.name, m.name.span, info.span));
                    } else {
                        self.check_param_names(&m.params);
                        local
                            .decls
                            .insert(m.name.name.clone(), (m.params.len(), m.name.span));
                    }
                    continue;
                }
                _ => continue,
            };
            let word = match &s.node {
                Stmt::Consider(_) => "consider",
                _ => key,
            };
            let span = Span::new(s.span.start as usize, s.span.start as usize + word.len());
            if key == "ignore" {
                // Several `ignore` lists add up; `consider` is the complement and
                // cannot be mixed with them.
                if let Some(first) = seen.get(key)
                    && (matches!(s.node, Stmt::Consider(_)) || local.considers)
                {
                    self.diags.push(
                        Diagnostic::error(
                            Code::IgnoreAndConsider,
                            "`ignore` and `consider` cannot both be given in one lsystem",
                        )
                        .primary(span, "given here")
                        .secondary(*first, "the other list")
                        .help("keep one: `consider` lists the modules context sees, `ignore` the modules it skips"),
                    );
                }
                local.considers |= matches!(s.node, Stmt::Consider(_));
                seen.entry(key).or_insert(span);
                continue;
            }
            if let Some(first) = seen.get(key) {
                self.diags.push(
                    Diagnostic::error(Code::DuplicateSetting, format!("`{key}` is given twice"))
                        .primary(span, "given again here")
                        .secondary(*first, "first given here")
                        .help("keep one of them"),
                );
                continue;
            }
            seen.insert(key, span);
            match &s.node {
                Stmt::Angle(e) => {
                    self.const_num(e, "the angle");
                }
                Stmt::Step(e) => {
                    self.const_num(e, "the step");
                }
                Stmt::Derive(e) => {
                    self.const_int(e, "the number of derivation steps", 0.0, 1_000_000.0);
                }
                Stmt::Tropism(t) => {
                    for (e, what) in t.dir.iter().zip([
                        "the tropism vector's x",
                        "the tropism vector's y",
                        "the tropism vector's z",
                    ]) {
                        self.const_num(e, what);
                    }
                    self.const_num(&t.elasticity, "the elasticity");
                }
                _ => {}
            }
        }
        if !seen.contains_key("axiom") {
            self.diags.push(
                Diagnostic::error(
                    Code::MissingAxiom,
                    format!("lsystem `{}` has no axiom", ls.name.name),
                )
                .primary(ls.name.span, "this lsystem needs a starting string")
                .help("add a statement such as `axiom F;`"),
            );
        }
    }

    /// Checks a rule's predecessor and context patterns and records arities.
    fn predecessor(&mut self, r: &Rule, local: &mut Local) {
        let m = &r.pred;
        if r.interpret || r.decompose {
            let (kw, a) = if r.interpret {
                ("interpret", "an")
            } else {
                ("decompose", "a")
            };
            for ctx in [&r.left, &r.right].into_iter().flatten() {
                let span = match (ctx.first(), ctx.last()) {
                    (Some(a), Some(b)) => a.span.to(b.span),
                    _ => m.span,
                };
                self.diags.push(
                    Diagnostic::error(
                        Code::ContextNotAllowed,
                        format!("{a} `{kw}` rule cannot have context"),
                    )
                    .primary(span, "context here")
                    .help(format!(
                        "`{kw}` rules rewrite one module by itself (conditions and weights are allowed); match the context in a derivation rule"
                    )),
                );
            }
        }
        let arity = m.arity();
        match self.kind(m, local) {
            Kind::Structure => self.diags.push(
                Diagnostic::error(
                    Code::NotRewritable,
                    format!("`{}` cannot be rewritten", m.name.text()),
                )
                .primary(m.name_span, "a predecessor must be a module that rules can replace")
                .help("brackets, polygon braces and `cut` are structure; rewrite the modules around them"),
            ),
            Kind::UnknownQuery => self.unknown_query(m),
            Kind::Undeclared => {}
            Kind::Declared(n) => self.declared_arity(m, n),
            Kind::Query(q) => self.query_full(m, q, local),
            Kind::Letter | Kind::Element => {
                self.record_rule_arity(m, arity, local, true);
            }
            Kind::Turtle => {
                local
                    .turtle_arities
                    .entry(m.name.clone())
                    .or_default()
                    .insert(arity);
            }
        }
        // Predecessor parameters are names to bind.
        let pats = r
            .left
            .iter()
            .flatten()
            .chain(std::iter::once(&r.pred))
            .chain(r.right.iter().flatten());
        for pm in pats {
            for a in pm.args.iter().flatten() {
                if !matches!(a.kind, ExprKind::Var(_) | ExprKind::Error) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::PatternNotName,
                            "a predecessor parameter must be a name",
                        )
                        .primary(a.span, "an expression cannot be matched")
                        .help("bind a name here, as in `A(x)`, and test its value in a condition: `A(x) : x == 2 -> …`"),
                    );
                }
            }
        }
    }

    fn record_rule_arity(&mut self, m: &Module, arity: usize, local: &mut Local, is_pred: bool) {
        match local.rule_arity.get(&m.name) {
            Some(&(a, first)) if a != arity => {
                let what = if is_pred {
                    "this rule's predecessor"
                } else {
                    "this module"
                };
                self.diags.push(
                    Diagnostic::error(
                        Code::ArityRules,
                        format!(
                            "`{}` has {} parameter{} here, but its rules take {}",
                            m.name.text(),
                            arity,
                            plural(arity),
                            a
                        ),
                    )
                    .primary(m.span, format!("{what} has {arity}"))
                    .secondary(first, format!("a rule for `{}` with {a} starts here", m.name.text()))
                    .help("a module matches a rule only with the same number of parameters; use the same count everywhere"),
                );
            }
            Some(_) => {}
            None => {
                if is_pred {
                    local.rule_arity.insert(m.name.clone(), (arity, m.span));
                }
            }
        }
    }

    fn declared_arity(&mut self, m: &Module, n: usize) {
        let arity = m.arity();
        if arity != n {
            let decl_span = match &m.name {
                ModName::Name(name) => self.modules.get(name.as_str()).map(|i| i.span),
                _ => None,
            };
            let mut d = Diagnostic::error(
                Code::ArityDeclared,
                format!(
                    "`{}` is declared with {} parameter{}, but has {} here",
                    m.name.text(),
                    n,
                    plural(n),
                    arity
                ),
            )
            .primary(m.span, format!("{arity} parameter{}", plural(arity)));
            if let Some(s) = decl_span {
                d = d.secondary(s, "declared here");
            }
            self.diags.push(d);
        }
    }

    fn unknown_query(&mut self, m: &Module) {
        let name = m.name.text();
        if !self.reported_queries.insert(name.to_string()) {
            return;
        }
        let mut d = Diagnostic::error(
            Code::UnknownQuery,
            format!("`{name}` is not a query module"),
        )
        .primary(m.name_span, "the environment does not answer this query");
        let prefixed: Vec<String> = query::QUERIES
            .iter()
            .filter(|q| q.name.starts_with(name.as_ref()))
            .map(|q| format!("`{}`", q.name))
            .collect();
        if !prefixed.is_empty() {
            d = d.help(format!("did you mean {}?", prefixed.join(" or ")));
            for q in query::QUERIES
                .iter()
                .filter(|q| q.name.starts_with(name.as_ref()))
            {
                d = d.fix(format!("replace with `{}`", q.name), m.name_span, q.name);
            }
        } else if let Some(s) = super::suggest(&name, query::QUERIES.iter().map(|q| q.name)) {
            d = d.did_you_mean(m.name_span, s);
        } else {
            let names: Vec<&str> = query::QUERIES.iter().map(|q| q.name).collect();
            d = d.note(format!("the query modules are {}", names.join(" ")));
        }
        self.diags.push(d);
    }

    /// A query written in full (predecessor or context): outputs then pass-through.
    fn query_full(&mut self, m: &Module, q: &'static Query, local: &mut Local) {
        let arity = m.arity();
        let k = q.outputs.len();
        if arity < k + q.inputs.len() {
            self.diags.push(
                Diagnostic::error(
                    Code::QuerySignature,
                    format!(
                        "`{}` in a predecessor needs at least {} parameters",
                        q.name,
                        k + q.inputs.len()
                    ),
                )
                .primary(m.span, format!("{arity} given"))
                .note(format!(
                    "its signature is {}: the environment fills {}",
                    q.signature(),
                    q.outputs.join(", ")
                ))
                .help("write `_` for outputs you do not use"),
            );
            return;
        }
        self.record_pass(m, q, arity - k, local);
    }

    fn record_pass(&mut self, m: &Module, q: &'static Query, pass: usize, local: &mut Local) {
        match local.query_pass.get(q.name) {
            Some(&(p, first)) if p != pass && local.pass_reported.insert(q.name) => self.diags.push(
                Diagnostic::error(
                    Code::QuerySignature,
                    format!("`{}` carries {} pass-through parameter{} here but {} elsewhere", q.name, pass, plural(pass), p),
                )
                .primary(m.span, format!("{pass} pass-through"))
                .secondary(first, format!("{p} pass-through here"))
                .note(format!(
                    "in a predecessor `{}` is written with its outputs ({}) first; in a successor only the pass-through parameters are written",
                    q.name,
                    q.outputs.join(", ")
                )),
            ),
            Some(_) => {}
            None => {
                local.query_pass.insert(q.name.to_string(), (pass, m.span));
            }
        }
    }

    fn module_list(&mut self, ms: &[Module], role: Role, local: &mut Local) {
        for m in ms {
            let arity = m.arity();
            if let ModName::Name(n) = &m.name
                && !local.decls.contains_key(n)
            {
                self.used_modules.insert(n.clone());
            }
            if role == Role::Ignore {
                if m.args.is_some() {
                    self.diags.push(
                        Diagnostic::error(
                            Code::ArgsNotAllowed,
                            "an `ignore` or `consider` list names modules without parameters",
                        )
                        .primary(m.span, "parameters here")
                        .help(format!("write just `{}`", m.name.text())),
                    );
                }
                continue;
            }
            match self.kind(m, local) {
                Kind::Structure => {
                    if m.args.is_some() {
                        self.diags.push(
                            Diagnostic::error(
                                Code::ArgsNotAllowed,
                                format!("`{}` takes no parameters", m.name.text()),
                            )
                            .primary(m.span, "parameters here")
                            .help(format!("write just `{}`", m.name.text())),
                        );
                    }
                }
                Kind::UnknownQuery => self.unknown_query(m),
                Kind::Undeclared => {}
                Kind::Declared(n) => self.declared_arity(m, n),
                Kind::Query(q) => {
                    if role == Role::Context {
                        self.query_full(m, q, local);
                    } else if arity < q.inputs.len() {
                        self.diags.push(
                            Diagnostic::error(
                                Code::QuerySignature,
                                format!("`{}` needs {} as its first parameter", q.name, q.inputs.join(", ")),
                            )
                            .primary(m.span, format!("{arity} given"))
                            .note(format!(
                                "in a successor only the pass-through parameters are written, starting with {}",
                                q.inputs.join(", ")
                            )),
                        );
                    } else {
                        self.record_pass(m, q, arity, local);
                    }
                }
                Kind::Letter | Kind::Element => {
                    if local.rule_arity.contains_key(&m.name) {
                        self.record_rule_arity(m, arity, local, false);
                    }
                }
                Kind::Turtle => {
                    if let Some(set) = local.turtle_arities.get(&m.name)
                        && !set.contains(&arity)
                        && role != Role::Context
                        && local.warned.insert((m.name.clone(), arity))
                    {
                        let mut ar: Vec<usize> = set.iter().copied().collect();
                        ar.sort_unstable();
                        let ar: Vec<String> = ar.iter().map(ToString::to_string).collect();
                        self.diags.push(
                                Diagnostic::warning(
                                    Code::ArityNeverRewritten,
                                    format!(
                                        "this `{}` is never rewritten: its rules take {} parameter{}",
                                        m.name.text(),
                                        ar.join(" or "),
                                        if ar.len() == 1 && ar[0] == "1" { "" } else { "s" }
                                    ),
                                )
                                .primary(m.span, format!("{arity} parameter{}", plural(arity)))
                                .help("give it the same number of parameters as the rules' predecessor, or add a rule for this form"),
                            );
                    }
                }
            }
        }
    }

    fn module_args(&mut self, m: &Module, env: &Env) {
        // A declared module's count is checked at its declaration (E0406) and
        // against it here (E0401).
        if !matches!(&m.name, ModName::Name(n) if self.modules.contains_key(n.as_str())) {
            self.too_many_params(m.arity(), m.span);
        }
        for a in m.args.iter().flatten() {
            self.expect(a, env, Ty::Num);
        }
    }

    fn rule_body(&mut self, r: &Rule) {
        let mut env = Env::new();
        let mut bound: Vec<(String, Span)> = Vec::new();
        let pats = r
            .left
            .iter()
            .flatten()
            .chain(std::iter::once(&r.pred))
            .chain(r.right.iter().flatten());
        for pm in pats {
            let outputs = match &pm.name {
                ModName::Query(q) => query::lookup(q).map_or(&[][..], |q| q.outputs),
                _ => &[],
            };
            for (k, a) in pm.args.iter().flatten().enumerate() {
                if let ExprKind::Var(n) = &a.kind
                    && n != "_"
                {
                    if let Some((_, first)) = bound.iter().find(|(b, _)| b == n) {
                        self.diags.push(duplicate("parameter", n, a.span, *first));
                        continue;
                    }
                    bound.push((n.clone(), a.span));
                    let ty = if outputs.get(k) == Some(&"found") {
                        Ty::Bool
                    } else {
                        Ty::Num
                    };
                    env.add_typed(n, a.span, ty);
                }
            }
        }
        if let Some(c) = &r.cond {
            let before = self.diags.len();
            let t = self.expr(c, &env);
            let clean = self.diags.len() == before;
            if t == Ty::Num {
                self.diags.push(
                    Diagnostic::error(Code::ConditionNotBool, "a condition must be true or false")
                        .primary(c.span, "this is a number")
                        .help("compare it, for example `x > 0` or `x != 0`"),
                );
            } else if clean && t == Ty::Bool && self.eval(c) == Some(Value::Bool(false)) {
                self.diags.push(
                    Diagnostic::warning(
                        Code::AlwaysFalse,
                        "this rule can never fire: its condition is always false",
                    )
                    .primary(c.span, "always false")
                    .help("check the constants it uses, or remove the rule"),
                );
            }
        }
        if let Some(w) = &r.weight
            && self.expect(w, &env, Ty::Num) == Ty::Num
            && let Some(Value::Num(v)) = self.eval(w)
            && !(v >= 0.0 && v.is_finite())
        {
            self.diags.push(
                Diagnostic::error(Code::OutOfRange, "a weight must be zero or positive")
                    .primary(w.span, format!("this is {v}")),
            );
        }
        for m in &r.succ {
            self.module_args(m, &env);
        }
        self.brackets(&r.succ);
        let malformed_query = match &r.pred.name {
            ModName::Query(q) => {
                query::lookup(q).is_some_and(|q| r.pred.arity() < q.outputs.len() + q.inputs.len())
            }
            _ => false,
        };
        for p in env.params.iter().filter(|_| !malformed_query) {
            if !p.used.get() && !p.name.starts_with('_') {
                self.diags.push(
                    Diagnostic::warning(
                        Code::UnusedParameter,
                        format!("parameter `{}` is never used", p.name),
                    )
                    .primary(p.span, "bound here")
                    .help(format!("write `_` (or `_{}`) if it only matches", p.name)),
                );
            }
        }
    }

    fn brackets(&mut self, ms: &[Module]) {
        for (open, close, code) in [
            ('[', ']', Code::UnbalancedBrackets),
            ('{', '}', Code::UnbalancedPolygon),
        ] {
            let mut stack: Vec<Span> = Vec::new();
            for m in ms {
                match m.name {
                    ModName::Symbol(c) if c == open => stack.push(m.span),
                    ModName::Symbol(c) if c == close && stack.pop().is_none() => {
                        self.diags.push(
                                Diagnostic::error(code, format!("`{close}` without a matching `{open}`"))
                                    .primary(m.span, "nothing to close here".to_string())
                                    .help(format!("remove it or add `{open}` before it; each module string must balance")),
                            );
                    }
                    _ => {}
                }
            }
            if let Some(&first_open) = stack.first() {
                let mut d =
                    Diagnostic::error(code, format!("{} `{open}` never closed", stack.len()))
                        .primary(
                            *stack.last().unwrap_or(&first_open),
                            format!("this `{open}` has no `{close}`"),
                        );
                if stack.len() > 1 {
                    d = d.note(format!(
                        "{} unclosed `{open}` in this module string",
                        stack.len()
                    ));
                }
                self.diags.push(d.help(format!("add `{close}` at the end")));
            }
        }
    }

    /// Rules whose predecessor never appears, and rules after one that always applies.
    fn unreachable_rules(&mut self, ls: &Lsystem, rules: &[&Rule]) {
        let mut produced: HashSet<&ModName> = HashSet::new();
        for s in &ls.body.stmts {
            match &s.node {
                Stmt::Axiom(ms) => produced.extend(ms.iter().map(|m| &m.name)),
                Stmt::Rule(r) if !r.interpret => produced.extend(r.succ.iter().map(|m| &m.name)),
                Stmt::Tropism(_) => {}
                _ => {}
            }
        }
        let mut reported: HashSet<&ModName> = HashSet::new();
        let mut always: HashMap<(u8, &ModName, usize), Span> = HashMap::new();
        let mut prev: Option<&Rule> = None;
        for r in rules {
            let name = &r.pred.name;
            let rewritable = !matches!(
                name,
                ModName::Symbol('[' | ']' | '{' | '}' | '%') | ModName::Cut
            );
            let known = match name {
                ModName::Name(n) => {
                    is_letter(n)
                        || self.modules.contains_key(n.as_str())
                        || ls
                            .body
                            .stmts
                            .iter()
                            .any(|s| matches!(&s.node, Stmt::Module(m) if &m.name.name == n))
                }
                ModName::Query(q) => query::lookup(q).is_some(),
                _ => true,
            };
            if rewritable && known && !produced.contains(name) && reported.insert(name) {
                let mut d = Diagnostic::warning(
                    Code::NeverProduced,
                    format!(
                        "this rule can never fire: `{}` appears in no axiom or successor",
                        name.text()
                    ),
                )
                .primary(r.pred.name_span, "never produced")
                .help(format!(
                    "add `{}` to the axiom or to a successor, or remove the rule",
                    name.text()
                ));
                if let Some(l) = r.label.as_ref().filter(|l| is_letter(&l.name)) {
                    d = d.secondary(l.span, "read as a rule label").note(format!(
                        "`{0}:` is a rule label; if `{0}` is the predecessor and the rest a condition, write `{0} : …` with a space",
                        l.name
                    ));
                }
                self.diags.push(d);
            }
            let key = (rule_kind(r), name, r.pred.arity());
            let same_group = r.weight.is_some()
                && prev.is_some_and(|p| {
                    p.weight.is_some() && p.pred.name == *name && rule_kind(p) == rule_kind(r)
                });
            if let Some(&earlier) = always.get(&key) {
                if !same_group {
                    self.diags.push(
                        Diagnostic::warning(
                            Code::Shadowed,
                            "this rule can never fire: an earlier rule always applies",
                        )
                        .primary(r.pred.span, "hidden")
                        .secondary(
                            earlier,
                            "this rule has no condition or context, so it always applies first",
                        )
                        .help("move this rule above it, or give the earlier rule a condition"),
                    );
                }
            } else if r.cond.is_none() && r.left.is_none() && r.right.is_none() {
                always.insert(key, r.pred.span);
            }
            prev = Some(r);
        }
    }
}

/// 0 for a derivation rule, 1 for `interpret`, 2 for `decompose`.
fn rule_kind(r: &Rule) -> u8 {
    if r.interpret {
        1
    } else if r.decompose {
        2
    } else {
        0
    }
}
