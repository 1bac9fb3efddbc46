//! The program of a tree sketch as an `ast::File`, built with the shared kit
//! (`infer::program`): header comment, constants, module declarations and one
//! lsystem whose rules are the reduced productions.
//!
//! Owns: the shape of programs inferred from sketches (see `docs/language.md`, "Inferring a
//! tree from a sketch"): module `R` is the root `r`, `B<k>` is id `k`; every rule
//! `M(l, w)` draws its base branch as sketched (segments as fractions of `l`,
//! bends as turns), with each child in brackets at its junction, turned by a
//! measured angle constant, `l` scaled by a measured ratio constant and `w` by
//! `KW`; in 3D each child also pitches out of the sketch plane. Measurements
//! are rounded here. Must not print text: `fmt::format_file` does.

use super::productions::{Analysis, Child, Production};
use super::skeleton::{Branch, Skeleton, angle};
use crate::ast::{BinOp, ConstDecl, Expr, File, Ident, Item, Module, ModuleDecl, Node, Stmt};
use crate::infer::program::{self, bin, comment, named, node, sym, var};
use glam::DVec2;
use std::collections::HashMap;

/// Stroke widths vary when the widest is this much wider than the narrowest.
const WIDTHS_VARY: f64 = 1.15;
/// Without measured widths the trunk is this fraction of its length wide.
const TRUNK_WIDTH_OF_LENGTH: f64 = 1.0 / 12.0;
/// Default lean of children out of the sketch plane in 3D, degrees.
pub const SPREAD: f64 = 35.0;

/// What the emitter needs besides the tree and its productions.
pub struct Settings<'a> {
    /// The sketch's file name, for the header.
    pub source: &'a str,
    /// The lsystem's name.
    pub name: String,
    /// Number of strokes read.
    pub strokes: usize,
    /// For each branch, the number of its stroke in the document (1-based).
    pub numbers: Vec<usize>,
    /// 3D: the seed of the perturbation, `None` for a 2D program.
    pub seed_3d: Option<u64>,
}

/// `v` rounded to `digits` decimals.
fn round(v: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (v * k).round() / k + 0.0
}

fn mul(a: Expr, b: Expr) -> Expr {
    bin(BinOp::Mul, a, b)
}

/// `+(a)` for a left turn, `-(a)` for a right one (by `a`'s sign), nothing for 0.
fn turn(deg: f64) -> Option<Module> {
    let d = round(deg, 1);
    (d != 0.0).then(|| sym(if d > 0.0 { '+' } else { '-' }, Some(Expr::num(d.abs()))))
}

/// The letters that name modules, in order: not `F` (it draws) nor `R` (the root).
const LETTERS: &str = "ABCDEGHIJKLMNOPQSTUVWXYZ";

/// The `k`-th module name after `R`: `A`, `B`, …, `Z`, then `AA`, `AB`, …
/// Letters only, so that a derived string reads back as an axiom.
fn letters_name(mut k: usize) -> String {
    let base = LETTERS.len();
    let mut out = Vec::new();
    loop {
        out.push(LETTERS.as_bytes()[k % base] as char);
        if k < base {
            break;
        }
        k = k / base - 1;
    }
    out.iter().rev().collect()
}

/// Module names of the productions: `R` for the root `r`, letters for the
/// other ids in P order.
pub fn module_names(prods: &[Production]) -> HashMap<usize, String> {
    let mut names = HashMap::from([(0, "R".to_string())]);
    for p in prods.iter().filter(|p| p.id != 0) {
        let k = names.len() - 1;
        names.insert(p.id, letters_name(k));
    }
    names
}

fn name_of(names: &HashMap<usize, String>, c: Child) -> String {
    match c {
        Child::Id(k) => names.get(&k).cloned().unwrap_or_else(|| "R".to_string()),
        Child::T => "R".to_string(),
    }
}

/// A 64-bit generator for the 3D perturbation (SplitMix64).
struct SplitMix(u64);

impl SplitMix {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One child of a rule, measured from the base branch.
struct ChildGeom {
    module: String,
    vertex: usize,
    /// Signed turn from the parent's heading at the junction, degrees.
    angle: f64,
    ratio: f64,
    /// 3D: sine of the child's azimuth around the parent (0 in 2D).
    lean: f64,
    stroke: usize,
}

struct Consts {
    items: Vec<Node<Item>>,
}

impl Consts {
    fn add(&mut self, name: &str, value: f64, note: String) -> Expr {
        let mut n = node(Item::Const(ConstDecl {
            name: Ident::new(name),
            value: Expr::num(value),
        }));
        n.trivia.trailing = Some(comment(note));
        self.items.push(n);
        var(name)
    }
}

/// Width of the trunk and the child/parent width ratio, and how they were found.
fn widths(sk: &Skeleton) -> (f64, Option<f64>, &'static str) {
    let trunk = &sk.branches[0];
    let ws: Vec<f64> = sk.branches.iter().filter_map(|b| b.width).collect();
    let (lo, hi) = ws.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &w| {
        (lo.min(w), hi.max(w))
    });
    let pairs: Vec<(&Branch, &Branch)> = sk
        .branches
        .iter()
        .filter_map(|c| c.parent.map(|p| (&sk.branches[p], c)))
        .collect();
    if ws.len() == sk.branches.len() && hi > lo * WIDTHS_VARY && !pairs.is_empty() {
        // Measured: the geometric mean of child/parent stroke widths.
        let logs: f64 = pairs
            .iter()
            .filter_map(|(p, c)| Some((c.width? / p.width?).ln()))
            .sum();
        let kw = (logs / pairs.len() as f64).exp();
        return (
            trunk.width.unwrap_or(hi),
            Some(kw),
            "measured stroke widths",
        );
    }
    let trunk_w = trunk
        .width
        .unwrap_or(0.0)
        .max(trunk.length() * TRUNK_WIDTH_OF_LENGTH);
    if pairs.is_empty() {
        return (trunk_w, None, "pipe model");
    }
    // Pipe model: a parent's cross-section is shared by its children in
    // proportion to their lengths, w_c = w_p * sqrt(l_c / sum of l).
    let mut sum = 0.0;
    for (p, c) in &pairs {
        let total: f64 = p.children.iter().map(|&k| sk.branches[k].length()).sum();
        if total > 0.0 {
            sum += (c.length() / total).sqrt();
        }
    }
    (trunk_w, Some(sum / pairs.len() as f64), "pipe model")
}

/// The program for a skeleton and its productions.
pub fn program(sk: &Skeleton, a: &Analysis, s: &Settings) -> File {
    let mut consts = Consts { items: Vec::new() };
    let prods = productions(a);
    let (axiom, kw) = trunk(sk, s, &mut consts);
    let names = module_names(&prods);
    let geoms = child_geometry(sk, a, &prods, &names, s.seed_3d);
    let spread = if s.seed_3d.is_some() && geoms.iter().flatten().any(|g| g.lean != 0.0) {
        Some(consts.add(
            "SPREAD",
            SPREAD,
            "3D: how far children lean out of the sketch plane (degrees)".into(),
        ))
    } else {
        None
    };
    let mut stmts: Vec<Node<Stmt>> = Vec::new();
    stmts.push(node(Stmt::Derive(Expr::num(sk.height() as f64 + 1.0))));
    stmts.push(node(Stmt::Axiom(axiom)));
    let mut decls: Vec<Node<Item>> = Vec::new();
    let widths = Widths {
        kw: kw.as_ref(),
        spread: spread.as_ref(),
    };
    for (p, g) in prods.iter().zip(&geoms) {
        let m = name_of(&names, Child::Id(p.id));
        decls.push(node(Item::Module(ModuleDecl {
            name: Ident::new(m.clone()),
            params: vec![Ident::new("l"), Ident::new("w")],
        })));
        stmts.push(rule(sk, a, s, p, g, &m, &widths, &mut consts));
    }
    let header = header(sk, a, s, &prods, &names);
    assemble(&header, consts, decls, stmts, &s.name)
}

/// The productions to write: the reduced ones, or the trunk alone.
fn productions(a: &Analysis) -> Vec<Production> {
    if a.reduced.is_empty() {
        vec![Production {
            id: 0,
            succ: Vec::new(),
        }]
    } else {
        a.reduced.clone()
    }
}

/// The axiom, placing the trunk where the sketch has it, and the constants
/// of its placement, length and width; also the width ratio of a branch to
/// its parent, if the sketch has one.
fn trunk(sk: &Skeleton, s: &Settings, consts: &mut Consts) -> (Vec<Module>, Option<Expr>) {
    let trunk = &sk.branches[0];
    let base = trunk.points.first().copied().unwrap_or(DVec2::ZERO);
    let (bx, by) = (round(base.x, 1), round(base.y, 1));
    let lean = round(angle(DVec2::Y, trunk.direction(0)), 1);
    let mut axiom = Vec::new();
    if by != 0.0 {
        let e = consts.add(
            "BASE_Y",
            by,
            "where the trunk starts: y of the sketch, upward".into(),
        );
        axiom.push(sym('f', Some(e)));
    }
    if bx != 0.0 {
        let e = consts.add(
            "BASE_X",
            bx,
            "where the trunk starts: x of the sketch".into(),
        );
        axiom.push(sym('-', Some(Expr::num(90.0))));
        axiom.push(sym('f', Some(e)));
        axiom.push(sym('+', Some(Expr::num(90.0))));
    }
    if lean != 0.0 {
        let e = consts.add(
            "LEAN",
            lean,
            "the trunk's lean from vertical (degrees, left positive)".into(),
        );
        axiom.push(sym('+', Some(e)));
    }
    let trunk_len = consts.add(
        "TRUNK",
        round(trunk.length(), 1),
        format!("length of the trunk ({})", stroke_name(s, 0)),
    );
    let (w0, kw, how) = widths(sk);
    let width = consts.add("WIDTH", round(w0, 2), format!("width of the trunk ({how})"));
    let kw = kw.map(|k| {
        consts.add(
            "KW",
            round(k, 3),
            format!("width of a branch relative to its parent ({how})"),
        )
    });
    axiom.push(named("R", vec![trunk_len, width]));
    (axiom, kw)
}

/// The children of each rule, measured on its base branch; in 3D each
/// leans out of the plane by the sine of its place around the parent
/// (`seed_3d` seeds the perturbation).
fn child_geometry(
    sk: &Skeleton,
    a: &Analysis,
    prods: &[Production],
    names: &HashMap<usize, String>,
    seed_3d: Option<u64>,
) -> Vec<Vec<ChildGeom>> {
    let mut rng = seed_3d.map(SplitMix);
    let mut geoms: Vec<Vec<ChildGeom>> = Vec::new();
    for p in prods {
        let b = &sk.branches[a.branch_of.get(p.id).copied().unwrap_or(0)];
        let n = p.succ.len();
        let mut g = Vec::new();
        for (i, c) in p.succ.iter().enumerate() {
            let (Some(&cb), Some(&v)) = (b.children.get(i), b.child_vertex.get(i)) else {
                continue;
            };
            let child = &sk.branches[cb];
            let lean = match rng.as_mut() {
                Some(r) => {
                    let step = 360.0 / n as f64;
                    let delta = (r.unit() * 2.0 - 1.0) * step / 4.0;
                    ((i as f64 + 0.5) * step + delta).to_radians().sin()
                }
                None => 0.0,
            };
            g.push(ChildGeom {
                module: name_of(names, *c),
                vertex: v,
                angle: angle(b.heading_at(v), child.direction(0)),
                ratio: child.length() / b.length().max(f64::MIN_POSITIVE),
                lean: round(lean, 3),
                stroke: cb,
            });
        }
        geoms.push(g);
    }
    geoms
}

/// The constants every rule's children use.
struct Widths<'a> {
    /// Width of a branch relative to its parent.
    kw: Option<&'a Expr>,
    /// 3D: how far children lean out of the plane.
    spread: Option<&'a Expr>,
}

/// The rule of production `p` (module `m`): its branch as sketched, the
/// children `g` in brackets at their junctions, with their constants.
#[allow(clippy::too_many_arguments)]
fn rule(
    sk: &Skeleton,
    a: &Analysis,
    s: &Settings,
    p: &Production,
    g: &[ChildGeom],
    m: &str,
    widths: &Widths,
    consts: &mut Consts,
) -> Node<Stmt> {
    let base = a.branch_of.get(p.id).copied().unwrap_or(0);
    let b = &sk.branches[base];
    let children: Vec<(usize, Vec<Module>)> = g
        .iter()
        .enumerate()
        .map(|(i, c)| (c.vertex, child_bracket(s, m, i, c, widths, consts)))
        .collect();
    let mut succ = vec![sym('!', Some(var("w")))];
    let segs = b.segments().max(1);
    let total = b.length().max(f64::MIN_POSITIVE);
    let at = |v: usize, succ: &mut Vec<Module>| {
        for (cv, br) in &children {
            if *cv == v {
                succ.extend(br.iter().cloned());
            }
        }
    };
    for k in 0..segs {
        at(k, &mut succ);
        if k > 0
            && let Some(t) = turn(angle(b.direction(k - 1), b.direction(k)))
        {
            succ.push(t);
        }
        let len = match (b.points.get(k), b.points.get(k + 1)) {
            (Some(p), Some(q)) => p.distance(*q),
            _ => total,
        };
        let f = if segs == 1 {
            var("l")
        } else {
            mul(var("l"), Expr::num(round(len / total, 3)))
        };
        succ.push(sym('F', Some(f)));
    }
    at(segs, &mut succ);
    let pred = named(m, vec![var("l"), var("w")]);
    let mut rule = node(Stmt::Rule(program::rule(pred, succ)));
    rule.trivia.leading.push(comment(format!(
        "{p}: module {m}, drawn like {}{}",
        stroke_name(s, base),
        if p.succ.is_empty() {
            ""
        } else {
            ", children at their junctions"
        }
    )));
    rule.trivia.blank_before = true;
    rule
}

/// `[ +(M_Ai) &(SPREAD * lean) Child(l * M_Ki, w * KW) ]` for child `i`
/// of module `m`, with its angle and length constants.
fn child_bracket(
    s: &Settings,
    m: &str,
    i: usize,
    c: &ChildGeom,
    widths: &Widths,
    consts: &mut Consts,
) -> Vec<Module> {
    let what = format!(
        "{}'s child {} ({}, {})",
        m,
        i + 1,
        c.module,
        stroke_name(s, c.stroke)
    );
    let ae = consts.add(
        &format!("{m}_A{}", i + 1),
        round(c.angle.abs(), 1),
        format!(
            "angle of {what} to it, degrees {}",
            if c.angle >= 0.0 { "left" } else { "right" }
        ),
    );
    let ke = consts.add(
        &format!("{m}_K{}", i + 1),
        round(c.ratio, 3),
        format!("length of {what} relative to it"),
    );
    let mut bracket = vec![sym('[', None)];
    bracket.push(sym(if c.angle >= 0.0 { '+' } else { '-' }, Some(ae)));
    if let Some(sp) = widths.spread
        && c.lean != 0.0
    {
        let pitch = mul(sp.clone(), Expr::num(c.lean.abs()));
        bracket.push(sym(if c.lean > 0.0 { '&' } else { '^' }, Some(pitch)));
    }
    let w = match widths.kw {
        Some(k) => mul(var("w"), k.clone()),
        None => var("w"),
    };
    bracket.push(named(&c.module, vec![mul(var("l"), ke), w]));
    bracket.push(sym(']', None));
    bracket
}

/// The comment header: the sketch, the productions at each stage of
/// reduction, the modules' names and how to grow the tree.
fn header(
    sk: &Skeleton,
    a: &Analysis,
    s: &Settings,
    prods: &[Production],
    names: &HashMap<usize, String>,
) -> Vec<String> {
    let mut header = vec![
        format!(
            "Inferred by `lsyc infer --skeleton` from {}{}.",
            s.source,
            if s.seed_3d.is_some() { " --3d" } else { "" }
        ),
        format!(
            "{} strokes (the first is the trunk), {} segments after Douglas-Peucker (epsilon {}).",
            s.strokes,
            sk.segments(),
            round(sk.epsilon, 2)
        ),
        format!(
            "Productions (Hegde & Rathi): {} scanned, {} after pre-reduction, {} after reduction:",
            a.initial.len(),
            a.pre_reduced.len(),
            a.reduced.len()
        ),
    ];
    for p in &a.reduced {
        header.push(format!("  {p}"));
    }
    let mut named: Vec<String> = prods
        .iter()
        .map(|p| format!("{} is {}", name_of(names, Child::Id(p.id)), Child::Id(p.id)))
        .collect();
    if let Some(last) = named.last_mut() {
        last.push('.');
    }
    for (k, chunk) in named.chunks(8).enumerate() {
        let lead = if k == 0 { "Modules: " } else { "  " };
        header.push(format!("{lead}{}", chunk.join(", ")));
    }
    header.push(
        "Each rule draws its branch as sketched, with the children at their junctions;".into(),
    );
    header.push(format!(
        "derive {} draws the sketch's {} levels, and more steps (-n) grow the tree further.",
        sk.height() + 1,
        sk.height() + 1
    ));
    if let Some(seed) = s.seed_3d {
        header.push(
            "3D: children spread around their parent at angles 360/n apart plus a random".into(),
        );
        header.push(format!(
            "perturbation (seed {seed}); each leans SPREAD times the sine of its angle out of the plane."
        ));
    }
    header
}

/// The file: constants (the header on the first), module declarations and
/// the lsystem `name` with `stmts`.
fn assemble(
    header: &[String],
    consts: Consts,
    decls: Vec<Node<Item>>,
    stmts: Vec<Node<Stmt>>,
    name: &str,
) -> File {
    let mut items: Vec<Node<Item>> = Vec::new();
    let mut first = true;
    for mut c in consts.items {
        if first {
            c.trivia.leading = header.iter().map(comment).collect();
            c.trivia.blank_after_leading = true;
            first = false;
        }
        items.push(c);
    }
    for (k, mut d) in decls.into_iter().enumerate() {
        d.trivia.blank_before = k == 0;
        items.push(d);
    }
    let mut sys = program::lsystem(name, stmts);
    sys.trivia.blank_before = true;
    items.push(sys);
    program::file(items)
}

fn stroke_name(s: &Settings, branch: usize) -> String {
    format!(
        "stroke {}",
        s.numbers.get(branch).copied().unwrap_or(branch + 1)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn module_names_are_letters() {
        assert_eq!(letters_name(0), "A");
        assert_eq!(letters_name(4), "E");
        assert_eq!(letters_name(5), "G");
        assert_eq!(letters_name(23), "Z");
        assert_eq!(letters_name(24), "AA");
        assert_eq!(letters_name(24 * 25 - 1), "ZZ");
        assert_eq!(letters_name(24 * 25), "AAA");
    }
}
