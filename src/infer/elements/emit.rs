//! The grammar of a drawing's elements as an `ast::File`, built with the
//! shared kit (`infer::program`): a comment header, the element kinds as
//! `element` items, named constants for the counts and transforms of the
//! repeated structures, and one lsystem.
//!
//! Owns: names (elements `A`, `B`, … without `F`; sequence rules `P1`, `P2`, …,
//! branchings `R1`, …, pairs `Q1`, …), the paper's post-processing (no `t0`
//! parameter unless the turns change along a sequence, `+(0)`, `f(0)` and
//! `*(1)` dropped, a sequence used only with m = 1 written as `P -> A T A`,
//! pair transforms inlined), rounding every number to the shortest decimal
//! that keeps the drawing within the tolerance, and the `derive` count that
//! expands everything. Must not print text: `fmt::format_file` does.

use super::read::Element;
use super::rules::{Body, Grammar, Sym};
use super::shape::{Frame, Instancing, map_subpaths, rotate};
use super::space::Tr;
use crate::ast::{
    BinOp, Block, ConstDecl, Element as ElementItem, Expr, ExprKind, File, Ident, Item, ModName,
    Module, ModuleDecl, Node, Prop, PropValue, Rule, Stmt,
};
use crate::infer::program::{bin, comment, file, lsystem, named, nice, node, rule, sym, var};
use crate::infer::svg::Seg;
use crate::span::Span;
use glam::DVec2;
use std::collections::{BTreeMap, BTreeSet};

/// What the emitter needs besides the grammar.
pub struct Settings<'a> {
    /// The drawing's file name, for the header.
    pub source: &'a str,
    /// The lsystem's name.
    pub name: String,
    /// `--symmetrize`: the grammar's transforms are already regular (see
    /// `rules::regular`); the header says so.
    pub symmetrize: bool,
    /// `--jitter J`: the transforms of repeated structures vary at random
    /// (turns by ±30·J degrees, steps and scales by ±J of their value), drawn
    /// anew at each use from `lsyc run --seed`.
    pub jitter: Option<f64>,
}

fn element_name(k: usize) -> String {
    const LETTERS: &str = "ABCDEGHIJKLMNOSTUVWXYZ";
    match LETTERS.chars().nth(k) {
        Some(c) => c.to_string(),
        None => format!("E{}", k + 1),
    }
}

struct Names {
    elements: Vec<String>,
    rules: Vec<String>,
}

impl Names {
    fn new(kinds: usize, g: &Grammar, inline: &[bool]) -> Names {
        let (mut p, mut r, mut q) = (0, 0, 0);
        let rules = g
            .rules
            .iter()
            .zip(inline)
            .enumerate()
            .map(|(i, (rule, &inlined))| match rule.body {
                _ if inlined => String::new(),
                Body::Seq { .. } if !counted(g, i) => {
                    q += 1;
                    format!("Q{q}")
                }
                Body::Seq { .. } => {
                    p += 1;
                    format!("P{p}")
                }
                Body::Branch { .. } => {
                    r += 1;
                    format!("R{r}")
                }
                Body::Pair { .. } => {
                    q += 1;
                    format!("Q{q}")
                }
            })
            .collect();
        Names {
            elements: (0..kinds).map(element_name).collect(),
            rules,
        }
    }
}

/// The pair rules used exactly once, not by the axiom: each is written
/// where it is used, so that a period reads as one rule (`P(m) -> A f(18)
/// +(12) B f(18) +(12) P(m - 1)`, not a pair rule and a sequence of pairs).
fn inlined(g: &Grammar) -> Vec<bool> {
    let mut uses = vec![0usize; g.rules.len()];
    let mut count = |s: &Sym| {
        if let Sym::Rule(r, _) = s {
            uses[*r] += 1;
        }
    };
    for rule in &g.rules {
        match &rule.body {
            Body::Seq { a, tip, .. } => {
                count(a);
                if let Some(b) = tip {
                    count(b);
                }
            }
            Body::Branch { a, tip, .. } => {
                count(a);
                if let Some(b) = tip {
                    count(b);
                }
            }
            Body::Pair { a, b, .. } => {
                count(a);
                count(b);
            }
        }
    }
    let axiom = match g.axiom {
        Some((_, Sym::Rule(r, _))) => Some(r),
        _ => None,
    };
    g.rules
        .iter()
        .zip(uses)
        .enumerate()
        .map(|(r, (rule, n))| n == 1 && axiom != Some(r) && matches!(rule.body, Body::Pair { .. }))
        .collect()
}

/// What `s` draws when its inlined pairs are written out: each symbol with
/// its frame relative to where `s` starts.
fn unit(g: &Grammar, inline: &[bool], s: Sym) -> Vec<(Sym, Frame)> {
    match s {
        Sym::Rule(r, _) if inline[r] => match &g.rules[r].body {
            Body::Pair { a, t, b, swap } => {
                let at = t.apply(&Frame::IDENTITY);
                let first = unit(g, inline, *a);
                let second = unit(g, inline, *b)
                    .into_iter()
                    .map(|(x, f)| (x, at.then(&f)));
                in_paint_order(first, second, *swap)
            }
            _ => vec![(s, Frame::IDENTITY)],
        },
        _ => vec![(s, Frame::IDENTITY)],
    }
}

/// A pair's two parts in the order the drawing paints them.
fn in_paint_order(
    first: Vec<(Sym, Frame)>,
    second: impl Iterator<Item = (Sym, Frame)>,
    swap: bool,
) -> Vec<(Sym, Frame)> {
    if swap {
        second.chain(first).collect()
    } else {
        first.into_iter().chain(second).collect()
    }
}

/// Whether a rule takes the count `m`: sequences longer than a pair,
/// branchings, and sequences of such (two rows of a grid).
fn counted(g: &Grammar, r: usize) -> bool {
    let rule = &g.rules[r];
    rule.repeats()
        || matches!(rule.body, Body::Seq { a: Sym::Rule(q, _), .. } if g.rules[q].repeats())
}

/// Derivation steps to expand `s` completely, as named counts (with their
/// multiplicities) plus a number, so that `derive` follows `-D` edits of the
/// counts. `named[r]` is rule `r`'s count constant, if it has one.
fn steps(
    g: &Grammar,
    s: Sym,
    named: &[Option<String>],
    inline: &[bool],
) -> (BTreeMap<String, u64>, u64) {
    match s {
        Sym::Element(_) => (BTreeMap::new(), 0),
        Sym::Rule(r, m) => match &g.rules[r].body {
            Body::Seq { a, tip, .. } | Body::Branch { a, tip, .. } => {
                let (mut names, mut n) = steps(g, *a, named, inline);
                if let Some(b) = tip {
                    let (y, k) = steps(g, *b, named, inline);
                    for (name, c) in y {
                        let e = names.entry(name).or_default();
                        *e = (*e).max(c);
                    }
                    n = n.max(k);
                }
                if !counted(g, r) {
                    return (names, n + 1);
                }
                match &named[r] {
                    Some(c) => {
                        *names.entry(c.clone()).or_default() += 1;
                        (names, n + 1)
                    }
                    None => (names, n + 1 + u64::from(m)),
                }
            }
            Body::Pair { a, b, .. } => {
                // max(x + y, z + w) ≤ max(x, z) + max(y, w) for counts ≥ 0.
                let (mut x, n) = steps(g, *a, named, inline);
                let (y, k) = steps(g, *b, named, inline);
                for (name, c) in y {
                    let e = x.entry(name).or_default();
                    *e = (*e).max(c);
                }
                // An inlined pair is rewritten with the rule that uses it.
                (x, u64::from(!inline[r]) + n.max(k))
            }
        },
    }
}

fn steps_expr(names: BTreeMap<String, u64>, n: u64) -> Expr {
    let mut out: Option<Expr> = None;
    for (name, c) in names {
        let term = if c == 1 {
            var(&name)
        } else {
            bin(BinOp::Mul, Expr::num(c as f64), var(&name))
        };
        out = Some(match out {
            Some(e) => bin(BinOp::Add, e, term),
            None => term,
        });
    }
    match out {
        Some(e) if n > 0 => bin(BinOp::Add, e, Expr::num(n as f64)),
        Some(e) => e,
        None => Expr::num(n.max(1) as f64),
    }
}

/// How long a rule's transform is applied in a row, at most.
fn run(g: &Grammar, r: usize) -> f64 {
    g.rules[r].counts.iter().copied().max().unwrap_or(1).max(1) as f64
}

struct Consts {
    items: Vec<Node<Item>>,
    /// The kinds of constant written (`N`, `TURN`, …), for the header's legend.
    used: BTreeSet<&'static str>,
}

/// How a jittered constant varies.
#[derive(Clone, Copy)]
enum Jitter {
    /// Plus or minus this many degrees.
    Turn(f64),
    /// Times 1 ± this.
    Factor(f64),
}

fn uniform(lo: f64, hi: f64) -> Expr {
    Expr::new(ExprKind::Call(
        Ident::new("uniform"),
        vec![Expr::num(lo), Expr::num(hi)],
    ))
}

impl Consts {
    fn add(&mut self, name: &str, value: f64, note: &str) -> Expr {
        self.add_jittered(name, value, None, note)
    }

    fn add_jittered(&mut self, name: &str, value: f64, jitter: Option<Jitter>, note: &str) -> Expr {
        let init = match jitter {
            Some(Jitter::Turn(d)) if d > 0.0 => bin(BinOp::Add, Expr::num(value), uniform(-d, d)),
            Some(Jitter::Factor(f)) if f > 0.0 => bin(
                BinOp::Mul,
                Expr::num(value),
                uniform(nice(1.0 - f, 1e-9), nice(1.0 + f, 1e-9)),
            ),
            _ => Expr::num(value),
        };
        let mut n = node(Item::Const(ConstDecl {
            name: Ident::new(name),
            value: init,
        }));
        if !note.is_empty() {
            n.trivia.trailing = Some(comment(note));
        }
        self.items.push(n);
        var(name)
    }
}

/// The turtle commands of a transform `+(α) f(d) *(s) +(β)`, identity parts
/// dropped. Each part is a fixed number or a named constant.
enum Part {
    Value(f64),
    Expr(Expr),
}

fn transform(alpha: Part, d: Part, s: Part, beta: Part) -> Vec<Module> {
    let mut out = Vec::new();
    // Without a step, the two turns are one.
    let (alpha, beta) = match (alpha, &d, beta) {
        (Part::Value(a), Part::Value(0.0), Part::Value(b)) => {
            // Within (−180, 180]: a left turn of 270° is a right turn of 90°.
            let turn = (a + b).rem_euclid(360.0);
            let turn = if turn > 180.0 { turn - 360.0 } else { turn };
            (Part::Value(nice(turn, 1e-9)), Part::Value(0.0))
        }
        (a, _, b) => (a, b),
    };
    let turn = |p: Part, out: &mut Vec<Module>| match p {
        Part::Value(0.0) => {}
        Part::Value(v) => out.push(sym(
            if v > 0.0 { '+' } else { '-' },
            Some(Expr::num(v.abs())),
        )),
        Part::Expr(e) => out.push(sym('+', Some(e))),
    };
    turn(alpha, &mut out);
    match d {
        Part::Value(0.0) => {}
        Part::Value(v) => out.push(sym('f', Some(Expr::num(v)))),
        Part::Expr(e) => out.push(sym('f', Some(e))),
    }
    match s {
        Part::Value(1.0) => {}
        Part::Value(v) => out.push(sym('*', Some(Expr::num(v)))),
        Part::Expr(e) => out.push(sym('*', Some(e))),
    }
    turn(beta, &mut out);
    out
}

/// Rounding tolerances for a transform applied `n` times in a row, in a
/// drawing whose size is `size` (in the transform's units).
struct Round {
    angle: f64,
    d: f64,
    s: f64,
}

impl Round {
    fn new(n: f64, d: f64) -> Round {
        Round {
            angle: 0.01 / n,
            d: (d * 1e-4).max(1e-5) / n.sqrt(),
            s: 1e-4 / n.sqrt(),
        }
    }

    fn values(&self, t: &Tr) -> (f64, f64, f64, f64) {
        // Angles prefer round multiples (of 90°, 45°, 30°, 15°, 5°) when
        // the tolerance allows one.
        let angle = |v: f64| {
            [90.0, 45.0, 30.0, 15.0, 5.0]
                .iter()
                .map(|k| (v / k).round() * k + 0.0)
                .find(|r| (r - v).abs() <= self.angle)
                .unwrap_or_else(|| nice(v, self.angle))
        };
        (
            angle(t.alpha.to_degrees()),
            nice(t.d, self.d),
            nice(t.s, self.s),
            angle(t.beta.to_degrees()),
        )
    }
}

fn module_of(names: &Names, g: &Grammar, s: Sym, count: Option<Expr>) -> Module {
    match s {
        Sym::Element(k) => Module::new(ModName::Name(names.elements[k].clone()), None),
        Sym::Rule(r, m) => {
            let args = counted(g, r).then(|| vec![count.unwrap_or_else(|| Expr::num(m as f64))]);
            Module::new(ModName::Name(names.rules[r].clone()), args)
        }
    }
}

/// `[X]` for a rule instance (its drawing moves the turtle), `A` for an element.
fn placed(names: &Names, g: &Grammar, s: Sym, count: Option<Expr>) -> Vec<Module> {
    let m = module_of(names, g, s, count);
    match s {
        Sym::Element(_) => vec![m],
        Sym::Rule(..) => vec![sym('[', None), m, sym(']', None)],
    }
}

/// SVG path data for subpaths, relative to `origin`, with about four
/// significant digits for a shape of `radius`.
pub fn path_data(subpaths: &[Vec<Seg>], origin: DVec2, radius: f64) -> String {
    let decimals = (3.0 - radius.max(1e-9).log10().floor()).clamp(0.0, 8.0) as i32;
    let k = 10f64.powi(decimals);
    let num = |v: f64| {
        let r = (v * k).round() / k + 0.0;
        format!("{r}")
    };
    let pt = |p: DVec2| {
        let q = p - origin;
        format!("{} {}", num(q.x), num(q.y))
    };
    let mut out: Vec<String> = Vec::new();
    for sub in subpaths {
        for s in sub {
            out.push(match *s {
                Seg::Move(p) => format!("M{}", pt(p)),
                Seg::Line(p) => format!("L{}", pt(p)),
                Seg::Quad(c, p) => format!("Q{} {}", pt(c), pt(p)),
                Seg::Cubic(a, b, p) => format!("C{} {} {}", pt(a), pt(b), pt(p)),
                Seg::Close => "Z".to_string(),
            });
        }
    }
    out.join(" ")
}

fn string_prop(key: &str, value: String) -> Node<Prop> {
    node(Prop {
        key: Ident::new(key),
        value: PropValue::Str(value, Span::default()),
    })
}

/// Counts of each symbol's uses, for the rule comments.
fn describe(names: &Names, s: Sym) -> String {
    match s {
        Sym::Element(k) => names.elements[k].clone(),
        Sym::Rule(r, _) => names.rules[r].clone(),
    }
}

/// The program for a grammar.
pub fn program(elements: &[Element], inst: &Instancing, g: &Grammar, s: &Settings) -> File {
    let inline = inlined(g);
    let names = Names::new(inst.kinds.len(), g, &inline);
    let mut consts = Consts {
        items: Vec::new(),
        used: BTreeSet::new(),
    };
    let element_items = match turned(inst, &g.tilt) {
        Some(inst) => kinds(elements, &inst, &names),
        None => kinds(elements, inst, &names),
    };
    let count_of = count_constants(g, &names, &mut consts);
    let mut decls: Vec<Node<Item>> = Vec::new();
    let mut rules: Vec<Node<Stmt>> = Vec::new();
    for (r, rule) in g.rules.iter().enumerate() {
        if inline[r] {
            continue;
        }
        let counted_r = counted(g, r);
        let name = names.rules[r].clone();
        decls.push(node(Item::Module(ModuleDecl {
            name: Ident::new(name.clone()),
            params: if counted_r {
                vec![Ident::new("m")]
            } else {
                Vec::new()
            },
        })));
        let mut w = RuleWriter {
            g,
            inline: &inline,
            names: &names,
            jitter: s.jitter,
            count_of: &count_of,
            pred: Module::new(
                ModName::Name(name.clone()),
                counted_r.then(|| vec![var("m")]),
            ),
            name,
            out: &mut rules,
        };
        match &rule.body {
            Body::Seq {
                a,
                t,
                delta,
                place,
                tip,
            } if counted_r => {
                w.sequence(
                    &mut consts,
                    run(g, r),
                    (*a, tip.unwrap_or(*a)),
                    t,
                    delta.as_ref(),
                    place.as_ref(),
                );
            }
            Body::Branch { a, ts, tip, tip_at } => {
                let tip = (tip.unwrap_or(*a), tip_at.as_ref());
                w.branching(&mut consts, run(g, r), *a, tip, ts)
            }
            // A sequence used only with m = 1 is the pair P -> A T A.
            Body::Seq { a, t, tip, .. } => w.pair(*a, t, tip.unwrap_or(*a), false),
            Body::Pair { a, t, b, swap } => w.pair(*a, t, *b, *swap),
        }
    }
    let (axiom, derive) = axiom(elements, g, &names, &count_of, &inline);
    let mut stmts: Vec<Node<Stmt>> = Vec::new();
    stmts.push(node(Stmt::Derive(derive)));
    stmts.push(node(Stmt::Axiom(axiom)));
    stmts.extend(rules);
    let mut sys = lsystem(&s.name, stmts);
    sys.trivia.blank_before = true;
    let header = header(elements, inst, g, s, &count_of, &consts.used);
    assemble(&header, element_items, consts, decls, sys)
}

/// The kinds with each outline turned by its kind's tilt about the kind's
/// origin (see `Grammar::tilt`), or `None` when no kind turns. A kind drawn
/// as another one mirrored shares its outline, so neither turns.
fn turned(inst: &Instancing, tilt: &[(usize, f64)]) -> Option<Instancing> {
    let mirrored = |k: usize| {
        inst.kinds[k].mirror_of.is_some() || inst.kinds.iter().any(|o| o.mirror_of == Some(k))
    };
    let turn = |k: usize| tilt.iter().find(|t| t.0 == k).map_or(0.0, |t| t.1);
    let any = (0..inst.kinds.len()).any(|k| turn(k) != 0.0 && !mirrored(k));
    if !any {
        return None;
    }
    let mut out = inst.clone();
    for (k, kind) in out.kinds.iter_mut().enumerate() {
        let a = turn(k);
        if a != 0.0 && !mirrored(k) {
            let o = kind.frame.pos;
            kind.subpaths = map_subpaths(&kind.subpaths, |p| o + rotate(p - o, a));
        }
    }
    Some(out)
}

/// The element kinds as `element` items, each with a comment saying how
/// many there are and where its outline comes from.
fn kinds(elements: &[Element], inst: &Instancing, names: &Names) -> Vec<Node<Item>> {
    let mut element_items = Vec::new();
    for (k, kind) in inst.kinds.iter().enumerate() {
        let e = &elements[kind.representative];
        let sh = &inst.shapes[kind.representative];
        // The outline in the kind's local frame.
        let local = map_subpaths(&kind.subpaths, |p| kind.frame.local(p));
        let mut props = vec![string_prop(
            "path",
            path_data(&local, DVec2::ZERO, sh.radius / kind.frame.scale),
        )];
        props.push(string_prop(
            "fill",
            e.style.fill.clone().unwrap_or_else(|| "none".into()),
        ));
        if let Some(st) = &e.style.stroke {
            props.push(string_prop("stroke", st.clone()));
            if let Some(w) = e.style.width {
                props.push(node(Prop {
                    key: Ident::new("width"),
                    value: PropValue::Expr(Expr::num(nice(w, w * 1e-3))),
                }));
            }
        }
        let count = inst.of.iter().filter(|(kk, _)| *kk == k).count();
        let mut item = node(Item::Element(ElementItem {
            name: Ident::new(names.elements[k].clone()),
            props: Block {
                stmts: props,
                end_comments: Vec::new(),
            },
        }));
        let sym_note = match kind.symmetry {
            0 => ", round".to_string(),
            1 => String::new(),
            n => format!(", {n}-fold symmetric"),
        };
        let drawn = match kind.mirror_of {
            Some(twin) => format!("{} mirrored", names.elements[twin]),
            None => format!(
                "element {} of the drawing, {}",
                e.number,
                if kind.given {
                    "in its own frame"
                } else {
                    "framed for simple rules"
                }
            ),
        };
        item.trivia.leading.push(comment(format!(
            "{}: {count} in the drawing{sym_note}; {drawn}.",
            names.elements[k]
        )));
        element_items.push(item);
    }
    element_items
}

/// A count argument for each rule: a named constant when the rule is used
/// with one count.
fn count_constants(g: &Grammar, names: &Names, consts: &mut Consts) -> Vec<Option<Expr>> {
    let mut count_of: Vec<Option<Expr>> = vec![None; g.rules.len()];
    for (r, rule) in g.rules.iter().enumerate() {
        if counted(g, r) && rule.counts.len() == 1 {
            let n = *rule.counts.iter().next().unwrap_or(&0);
            consts.used.insert(match rule.body {
                Body::Branch { .. } => "LEVELS",
                _ => "N",
            });
            count_of[r] = Some(consts.add(&format!("{}_N", names.rules[r]), n as f64, ""));
        }
    }
    count_of
}

fn m_minus_1() -> Expr {
    bin(BinOp::Sub, var("m"), Expr::num(1.0))
}

fn m_is(op: BinOp) -> Option<Expr> {
    Some(bin(op, var("m"), Expr::num(0.0)))
}

/// Writes the rules of one rule of the grammar, named `name`, into `out`.
struct RuleWriter<'a> {
    g: &'a Grammar,
    /// Pair rules written where they are used (see `inlined`).
    inline: &'a [bool],
    names: &'a Names,
    jitter: Option<f64>,
    count_of: &'a [Option<Expr>],
    name: String,
    /// The predecessor: the name, with `m` if the rule is counted.
    pred: Module,
    out: &'a mut Vec<Node<Stmt>>,
}

impl RuleWriter<'_> {
    fn child_count(&self, s: Sym) -> Option<Expr> {
        match s {
            Sym::Rule(c, _) => self.count_of[c].clone(),
            Sym::Element(_) => None,
        }
    }

    fn placed(&self, s: Sym) -> Vec<Module> {
        placed(self.names, self.g, s, self.child_count(s))
    }

    /// `s` with its inlined pairs written out, each move rounded for a
    /// structure repeated `n` times, and where the turtle ends (relative to
    /// where `s` starts). `last_open`: the last symbol is not bracketed (it
    /// ends the successor).
    fn unit(&self, s: Sym, n: f64, last_open: bool) -> (Vec<Module>, Frame) {
        self.write(&unit(self.g, self.inline, s), n, last_open)
    }

    /// Symbols at frames (relative to where the turtle starts), each move
    /// rounded for a structure repeated `n` times, and where the turtle ends.
    fn write(&self, items: &[(Sym, Frame)], n: f64, last_open: bool) -> (Vec<Module>, Frame) {
        let mut out = Vec::new();
        let mut at = Frame::IDENTITY;
        for (k, (x, f)) in items.iter().enumerate() {
            if k > 0 || *f != Frame::IDENTITY {
                let t = Tr::between(&at, f, 1.0);
                let (va, vd, vs, vb) = Round::new(n, t.d.max(1e-9)).values(&t);
                out.extend(transform(
                    Part::Value(va),
                    Part::Value(vd),
                    Part::Value(vs),
                    Part::Value(vb),
                ));
                at = *f;
            }
            if last_open && k + 1 == items.len() {
                out.push(module_of(self.names, self.g, *x, self.child_count(*x)));
            } else {
                out.extend(self.placed(*x));
            }
        }
        (out, at)
    }

    /// What `s` draws, for a comment: its name, or its inlined pairs' parts.
    fn describe(&self, s: Sym) -> String {
        self.summary(&unit(self.g, self.inline, s))
    }

    /// The symbols of a unit, counted in the order they first appear:
    /// `A and B`, `3 A and 2 B`.
    fn summary(&self, items: &[(Sym, Frame)]) -> String {
        let mut counts: Vec<(Sym, usize)> = Vec::new();
        for (x, _) in items {
            match counts.iter_mut().find(|c| c.0 == *x) {
                Some(c) => c.1 += 1,
                None => counts.push((*x, 1)),
            }
        }
        let parts: Vec<String> = counts
            .iter()
            .map(|&(x, n)| match n {
                1 => describe(self.names, x),
                n => format!("{n} {}", describe(self.names, x)),
            })
            .collect();
        match parts.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => parts.concat(),
        }
    }

    /// `s` written out, from and back to where it starts: bracketed when
    /// it moves the turtle.
    fn unit_in_place(&self, s: Sym, n: f64) -> Vec<Module> {
        let (mut out, at) = self.unit(s, n, false);
        if at != Frame::IDENTITY {
            out.insert(0, sym('[', None));
            out.push(sym(']', None));
        }
        out
    }

    fn recurse(&self) -> Module {
        named(&self.name, vec![m_minus_1()])
    }

    fn add(&mut self, cond: Option<Expr>, succ: Vec<Module>, note: Option<String>) {
        let mut n = node(Stmt::Rule(Rule {
            cond,
            ..rule(self.pred.clone(), succ)
        }));
        if let Some(note) = note {
            n.trivia.leading.push(comment(note));
            n.trivia.blank_before = true;
        }
        self.out.push(n);
    }

    /// The turn, step, scale and twist of `t` as values or named constants
    /// (`{name}_TURN{suffix}`, …), rounded for a structure repeated `n` times.
    fn parts(&self, consts: &mut Consts, t: &Tr, suffix: &str, n: f64) -> (Part, Part, Part, Part) {
        let (a, d, sc, b) = Round::new(n, t.d.max(1e-9)).values(t);
        let jitter = self.jitter;
        let name = &self.name;
        let mut part = |v: f64, trivial: f64, what: &str, note: &str| {
            // A scale of 1 stays 1: random scales would compound.
            let j = jitter
                .filter(|_| !(what == "SCALE" && v == 1.0))
                .map(|j| match what {
                    "TURN" | "TWIST" => Jitter::Turn(nice(30.0 * j, 1e-6)),
                    _ => Jitter::Factor(j),
                });
            if v == trivial && j.is_none() {
                Part::Value(v)
            } else {
                consts.used.insert(match what {
                    "TURN" => "TURN",
                    "STEP" => "STEP",
                    "SCALE" => "SCALE",
                    _ => "TWIST",
                });
                Part::Expr(consts.add_jittered(&format!("{name}_{what}{suffix}"), v, j, note))
            }
        };
        (
            part(a, 0.0, "TURN", ""),
            part(d, 0.0, "STEP", ""),
            part(sc, 1.0, "SCALE", ""),
            part(b, 0.0, "TWIST", ""),
        )
    }

    /// `a` drawn from the turtle moved by `place` (`[+(φ) f(r) -(φ) a]`), or
    /// placed as usual.
    fn placed_at(&self, a: Sym, place: Option<&Tr>) -> Vec<Module> {
        let Some(pl) = place else {
            return self.placed(a);
        };
        let (va, vd, vs, vb) = Round::new(1.0, pl.d.max(1e-9)).values(pl);
        let mut out = vec![sym('[', None)];
        out.extend(transform(
            Part::Value(va),
            Part::Value(vd),
            Part::Value(vs),
            Part::Value(vb),
        ));
        out.push(module_of(self.names, self.g, a, self.child_count(a)));
        out.push(sym(']', None));
        out
    }

    /// `P(m) : m > 0 -> [a] T P(m - 1); P(m) : m == 0 -> [tip]`; for a
    /// linear sequence (`delta`) each number of T that changes is `X + DX *
    /// m`, the paper's t(m) = t0 + tΔ·m, with named constants for t0 and tΔ.
    fn sequence(
        &mut self,
        consts: &mut Consts,
        n: f64,
        (a, tip): (Sym, Sym),
        t: &Tr,
        delta: Option<&Tr>,
        place: Option<&Tr>,
    ) {
        let name = self.name.clone();
        // A period written out ends where its last part is: the step goes
        // on from there (`A f(18) +(12) B f(18) +(12)`), unless it changes
        // with m (then the period is bracketed).
        let (mut succ, at) = match place {
            Some(_) => (self.placed_at(a, place), Frame::IDENTITY),
            None => self.unit(a, n, false),
        };
        let step = if at == Frame::IDENTITY {
            *t
        } else if delta.is_some() {
            succ = self.unit_in_place(a, n);
            *t
        } else {
            Tr::between(&at, &t.apply(&Frame::IDENTITY), 1.0)
        };
        let (pa, pd, ps, pb) = self.parts(consts, &step, "", n);
        let mut changing: Vec<&'static str> = Vec::new();
        let (pa, pd, ps, pb) = match delta {
            Some(dl) => {
                // A change per step is applied up to n times to a value
                // applied up to n times.
                let nn = n * n;
                let units = t.d.abs().max(dl.d.abs() * n).max(1e-9);
                let mut linear =
                    |base: Part, step: f64, tol: f64, what: &str, how: &'static str| {
                        let step = nice(step, tol);
                        let base = match base {
                            Part::Value(v) => Expr::num(v),
                            Part::Expr(e) => e,
                        };
                        if step == 0.0 {
                            return match base.kind {
                                ExprKind::Num(v) => Part::Value(v),
                                _ => Part::Expr(base),
                            };
                        }
                        changing.push(how);
                        consts.used.insert("D");
                        let c = consts.add(&format!("{name}_D{what}"), step, "");
                        Part::Expr(bin(BinOp::Add, base, bin(BinOp::Mul, c, var("m"))))
                    };
                let turn = 0.002 / nn;
                (
                    linear(
                        pa,
                        dl.alpha.to_degrees(),
                        turn,
                        "TURN",
                        "turning by a changing angle",
                    ),
                    linear(
                        pd,
                        dl.d,
                        units * 2e-5 / nn,
                        "STEP",
                        "stepping a changing distance",
                    ),
                    linear(ps, dl.s, 2e-5 / nn, "SCALE", "scaling by a changing factor"),
                    linear(
                        pb,
                        dl.beta.to_degrees(),
                        turn,
                        "TWIST",
                        "turning by a changing angle",
                    ),
                )
            }
            None => (pa, pd, ps, pb),
        };
        succ.extend(transform(pa, pd, ps, pb));
        succ.push(self.recurse());
        let mut hows: Vec<&str> = Vec::new();
        for how in changing {
            if !hows.contains(&how) {
                hows.push(how);
            }
        }
        let what = if tip == a {
            format!("m + 1 {}", self.describe(a))
        } else {
            format!("m {} ending in {}", self.describe(a), self.describe(tip))
        };
        let note = format!(
            "{name}(m): a sequence of {what}{}",
            if hows.is_empty() {
                String::new()
            } else {
                format!(", {}", hows.join(" and "))
            }
        );
        self.add(m_is(BinOp::Gt), succ, Some(note));
        let last = match place {
            Some(_) if tip == a => self.placed_at(a, place),
            _ => self.unit(tip, n, false).0,
        };
        self.add(m_is(BinOp::Eq), last, None);
    }

    /// `R(m) : m > 0 -> [a] [T R(m - 1)] [U R(m - 1)]…; R(m) : m == 0 -> [tip]`,
    /// the tip moved from where a child would be by `tip_at`'s inverse.
    fn branching(
        &mut self,
        consts: &mut Consts,
        n: f64,
        a: Sym,
        (tip, tip_at): (Sym, Option<&Frame>),
        ts: &[Tr],
    ) {
        let parts: Vec<_> = ts
            .iter()
            .enumerate()
            .map(|(i, t)| self.parts(consts, t, &(i + 1).to_string(), n))
            .collect();
        let mut succ = self.unit_in_place(a, n);
        for (pa, pd, ps, pb) in parts {
            succ.push(sym('[', None));
            succ.extend(transform(pa, pd, ps, pb));
            succ.push(self.recurse());
            succ.push(sym(']', None));
        }
        let tips = if tip == a {
            String::new()
        } else {
            format!(", {} at the tips", self.describe(tip))
        };
        let note = format!(
            "{}(m): {} branching in {}, m levels deep{tips}",
            self.name,
            self.describe(a),
            match ts.len() {
                2 => "two".to_string(),
                3 => "three".to_string(),
                k => k.to_string(),
            }
        );
        self.add(m_is(BinOp::Gt), succ, Some(note));
        let last = match tip_at {
            Some(rel) => {
                let place = Tr::between(&Frame::IDENTITY, &rel.inverse(), 1.0);
                self.placed_at(tip, Some(&place))
            }
            None => self.unit(tip, n, false).0,
        };
        self.add(m_is(BinOp::Eq), last, None);
    }

    /// `Q -> [a] T [b]`, the transform inlined, the parts in the order the
    /// drawing paints them.
    fn pair(&mut self, a: Sym, t: &Tr, b: Sym, swap: bool) {
        let at = t.apply(&Frame::IDENTITY);
        let first = unit(self.g, self.inline, a);
        let second = unit(self.g, self.inline, b)
            .into_iter()
            .map(|(x, f)| (x, at.then(&f)));
        let items = in_paint_order(first, second, swap);
        let (succ, _) = self.write(&items, 1.0, true);
        let note = match items.len() {
            2 if a == b => format!("{}: two {} (a pair)", self.name, self.describe(a)),
            2 => format!("{}: {} (a pair)", self.name, self.summary(&items)),
            _ => format!(
                "{}: {}, each placed from the one before",
                self.name,
                self.summary(&items)
            ),
        };
        self.add(None, succ, Some(note));
    }
}

/// The axiom (from the origin, heading up, to the last instance's frame)
/// and the `derive` count that expands it completely.
fn axiom(
    elements: &[Element],
    g: &Grammar,
    names: &Names,
    count_of: &[Option<Expr>],
    inline: &[bool],
) -> (Vec<Module>, Expr) {
    let mut axiom = Vec::new();
    let mut derive = Expr::num(1.0);
    if let Some((frame, s)) = g.axiom {
        let origin = Frame {
            pos: DVec2::ZERO,
            rot: 0.0,
            scale: 1.0,
        };
        let t = Tr::between(&origin, &frame, 1.0);
        // Placement is as precise as the drawing: 10⁻⁵ of its diagonal.
        let (lo, hi) = elements.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), e| (lo.min(e.min), hi.max(e.max)),
        );
        let diagonal = (hi - lo).length().max(1e-9);
        let round = Round {
            d: diagonal * 1e-5,
            ..Round::new(1.0, 1.0)
        };
        let (a, d, sc, b) = round.values(&t);
        axiom.extend(transform(
            Part::Value(a),
            Part::Value(d),
            Part::Value(sc),
            Part::Value(b),
        ));
        axiom.push(module_of(names, g, s, {
            match s {
                Sym::Rule(c, _) => count_of[c].clone(),
                Sym::Element(_) => None,
            }
        }));
        let named: Vec<Option<String>> = count_of
            .iter()
            .map(|c| match c.as_ref().map(|e| &e.kind) {
                Some(ExprKind::Var(v)) => Some(v.clone()),
                _ => None,
            })
            .collect();
        let (names, n) = steps(g, s, &named, inline);
        derive = steps_expr(names, n);
    }
    (axiom, derive)
}

/// The comment header: where the program came from and how to edit it.
fn header(
    elements: &[Element],
    inst: &Instancing,
    g: &Grammar,
    s: &Settings,
    count_of: &[Option<Expr>],
    used: &BTreeSet<&'static str>,
) -> Vec<String> {
    let mut out = vec![
        format!(
            "Inferred by `lsyc infer{}` from {}.",
            if s.symmetrize { " --symmetrize" } else { "" },
            s.source
        ),
        format!(
            "{} elements of {} kind{}; {} rule{} found in {} round{}.",
            elements.len(),
            inst.kinds.len(),
            if inst.kinds.len() == 1 { "" } else { "s" },
            g.rules.len(),
            if g.rules.len() == 1 { "" } else { "s" },
            g.rounds,
            if g.rounds == 1 { "" } else { "s" },
        ),
    ];
    // One legend for the constants, not a comment on each.
    let mut legend: Vec<&str> = Vec::new();
    if used.contains("N") {
        legend.push("_N repeats after the first");
    }
    if used.contains("LEVELS") {
        legend.push(if used.contains("N") {
            "levels below the first for a branching"
        } else {
            "_N levels of branching below the first"
        });
    }
    if used.contains("TURN") || used.contains("TWIST") {
        legend.push("_TURN and _TWIST turn left (degrees) before and after the step");
    }
    if used.contains("STEP") {
        legend.push("_STEP moves");
    }
    if used.contains("SCALE") {
        legend.push("_SCALE scales per step");
    }
    if used.contains("D") {
        legend.push("_D… is a change per step of m");
    }
    if !legend.is_empty() {
        out.push(format!("Constants: {}.", legend.join("; ")));
    }
    out.push(match count_of.iter().flatten().next().map(|e| &e.kind) {
        Some(ExprKind::Var(v)) => format!(
            "Edit them or override them (lsyc run -D {v}=10); replace a path to draw something else."
        ),
        _ => "Edit the numbers; replace an element's path to draw something else in its place."
            .into(),
    });
    out
}

/// The file: elements, constants, module declarations (at the top, so that
/// a derived string reads back as an axiom) and the lsystem, the header on
/// the first item.
fn assemble(
    header: &[String],
    element_items: Vec<Node<Item>>,
    consts: Consts,
    decls: Vec<Node<Item>>,
    sys: Node<Item>,
) -> File {
    let mut items: Vec<Node<Item>> = Vec::new();
    let mut first = true;
    let mut push_item = |mut item: Node<Item>, items: &mut Vec<Node<Item>>| {
        if first {
            let mut lead: Vec<_> = header.iter().map(comment).collect();
            lead.append(&mut item.trivia.leading);
            item.trivia.leading = lead;
            item.trivia.blank_after_leading = item.trivia.leading.len() == header.len();
            first = false;
        }
        items.push(item);
    };
    for (k, mut e) in element_items.into_iter().enumerate() {
        e.trivia.blank_before = k > 0;
        push_item(e, &mut items);
    }
    for (k, mut c) in consts.items.into_iter().enumerate() {
        c.trivia.blank_before = k == 0;
        push_item(c, &mut items);
    }
    for (k, mut d) in decls.into_iter().enumerate() {
        d.trivia.blank_before = k == 0;
        push_item(d, &mut items);
    }
    push_item(sys, &mut items);
    file(items)
}
