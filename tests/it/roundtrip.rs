//! infer(run(P)) ≈ P (issue 13): every hand-written program of
//! tests/data/roundtrip/ is drawn, inferred back and compared with itself.
//!
//! Two drawings of each program go through the same inference:
//! - **use**: `lsyc run -o X.svg`, neutralized (ids renamed `d1`, `d2`, …,
//!   every `class` and `data-*` attribute and every comment removed), so that
//!   only geometry and the `<use>` frames the drawing gives are left;
//! - **plain**: the derived string (`lsyc run -o X.txt`) drawn by a small
//!   turtle of this file, independent of lsyc's renderer, as `<path>`s with
//!   absolute coordinates (no `<use>`, no transforms): the frame must be found
//!   from geometry alone.
//!
//! Measured for each: (a) the redraw (symmetric Chamfer distance of sampled
//! outlines ≤ 10⁻³ of the diagonal, every element drawn once), which every
//! case must meet; (b) the number of rule statements, the original's ± 1
//! (`P(m) : m > 0` and `P(m) : m == 0` are two); (c) the original's transform
//! numbers (arguments of `+ - f F *`, constants substituted; 0 and a scale of
//! 1 skipped) found among the inferred program's numbers within 0.1 %. A case
//! that does not meet (b) and (c) yet is listed in `NOT_YET` (or
//! `NOT_YET_PLAIN`) with the reason; a listed case that meets them fails the
//! test until it is removed from the list.

use crate::support::{
    drawing_distance as relative_chamfer, lsy_files, read_text, rel, render_plain,
};
use glam::DVec2;
use lsyc::ast::{Expr, ExprKind, File, Item, ModName, Module, PropValue, Stmt};
use lsyc::check::Checked;
use lsyc::frontend;
use lsyc::infer::elements::{self, Options, read};
use lsyc::vm::Random;
use lsyc::vm::expr::evaluate;
use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Cases whose `<use>` drawing does not give back the program's rules and
/// numbers yet, with the reason.
const NOT_YET: &[(&str, &str)] = &[];

/// Cases whose plain drawing does not give back the program's rules and
/// numbers yet, with the reason.
const NOT_YET_PLAIN: &[(&str, &str)] = &[
    (
        "fig1-branching",
        "one branching rule, but the leaf's pen starts at (-3, 0), not at the writer's origin (0, 0) between the base's corners, and the fewest-turns heading is not the writer's: steps 65 and 179.9, turns -20, 24, 6",
    ),
    (
        "fig5-sequence",
        "without the drawing's frames the leaves' frames are not the writer's: no linear chain is found (a binary branching, a pair and a sequence of 9 placed elements)",
    ),
    (
        "linear-step",
        "a step that grows by a constant is not a linear sequence: every leaf is a pair (14 rules)",
    ),
    (
        "spiral",
        "one sequence with its scale and turn, but the arrow's pen starts at (-1, 0), not at the writer's origin (0, 0): the step is 13.4, not 12",
    ),
    (
        "two-kinds",
        "a period of two kinds is coded as pairs (13 rules)",
    ),
];

/// The largest Chamfer distance of a redraw, relative to the diagonal.
const REDRAW: f64 = 1e-3;
/// How close an inferred number must be to the original's, relative.
const NUMBER: f64 = 1e-3;

// ---------------------------------------------------------------- sampling

fn element_count(svg: &[u8]) -> usize {
    read::read(svg).expect("reads").elements.len()
}

// ---------------------------------------------------------------- neutral SVG

/// One piece of an XML text: text between tags, or a tag.
enum Piece<'a> {
    Text(&'a str),
    /// A start or empty-element tag: its name, attributes (name, quote, value)
    /// and whether it closes itself.
    Open(&'a str, Vec<(&'a str, char, &'a str)>, bool),
    /// Any other markup (end tag, declaration, processing instruction), verbatim.
    Other(&'a str),
    Comment,
}

/// Splits the XML that `lsyc run` writes into pieces (enough XML for it: quoted
/// attribute values, comments, no CDATA).
fn pieces(xml: &str) -> Vec<Piece<'_>> {
    let mut out = Vec::new();
    let mut rest = xml;
    while let Some(lt) = rest.find('<') {
        if lt > 0 {
            out.push(Piece::Text(&rest[..lt]));
        }
        rest = &rest[lt..];
        if rest.starts_with("<!--") {
            let end = rest.find("-->").expect("a closed comment") + 3;
            out.push(Piece::Comment);
            rest = &rest[end..];
            continue;
        }
        if rest[1..].starts_with(['/', '?', '!']) {
            let end = rest.find('>').expect("a closed tag") + 1;
            out.push(Piece::Other(&rest[..end]));
            rest = &rest[end..];
            continue;
        }
        let mut s = &rest[1..];
        let name_end = s
            .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
            .expect("a tag name");
        let name = &s[..name_end];
        s = &s[name_end..];
        let mut attrs = Vec::new();
        let closed = loop {
            s = s.trim_start();
            if let Some(r) = s.strip_prefix("/>") {
                s = r;
                break true;
            }
            if let Some(r) = s.strip_prefix('>') {
                s = r;
                break false;
            }
            let eq = s.find('=').expect("an attribute value");
            let key = s[..eq].trim();
            let after = s[eq + 1..].trim_start();
            let quote = after.chars().next().expect("a quoted value");
            assert!(quote == '"' || quote == '\'', "unquoted attribute {key}");
            let close = after[1..].find(quote).expect("a closing quote") + 1;
            attrs.push((key, quote, &after[1..close]));
            s = &after[close + 1..];
        };
        out.push(Piece::Open(name, attrs, closed));
        rest = s;
    }
    if !rest.is_empty() {
        out.push(Piece::Text(rest));
    }
    out
}

/// The drawing with its ids renamed `d1`, `d2`, … in document order (references
/// `#id` and `url(#id)` follow), and without any `class`, `data-*` attribute or
/// comment: what is left is geometry, style and structure.
fn neutralize(svg: &str) -> String {
    let pieces = pieces(svg);
    let mut ids = HashMap::new();
    for p in &pieces {
        if let Piece::Open(_, attrs, _) = p {
            for (k, _, v) in attrs {
                if *k == "id" {
                    let n = ids.len() + 1;
                    ids.insert(v.to_string(), format!("d{n}"));
                }
            }
        }
    }
    let mut out = String::new();
    for p in &pieces {
        match p {
            Piece::Text(t) | Piece::Other(t) => out.push_str(t),
            Piece::Comment => {}
            Piece::Open(name, attrs, closed) => {
                out.push('<');
                out.push_str(name);
                for (k, q, v) in attrs {
                    if *k == "class" || k.starts_with("data-") {
                        continue;
                    }
                    let value = if *k == "id" {
                        ids[*v].clone()
                    } else if let Some(target) = v.strip_prefix('#') {
                        ids.get(target).map_or(v.to_string(), |n| format!("#{n}"))
                    } else {
                        let mut v = v.to_string();
                        for (old, new) in &ids {
                            v = v.replace(&format!("url(#{old})"), &format!("url(#{new})"));
                        }
                        v
                    };
                    write!(out, " {k}={q}{value}{q}").expect("writes");
                }
                out.push_str(if *closed { "/>" } else { ">" });
            }
        }
    }
    for left in ["class=", "data-", "<!--", "<title", "<desc", "<metadata"] {
        assert!(!out.contains(left), "neutral SVG still holds {left}");
    }
    out
}

// ---------------------------------------------------------------- plain drawer

/// An element's path data as commands with absolute points, and its fill.
struct Shape {
    commands: Vec<(char, Vec<DVec2>)>,
    fill: String,
}

/// Reads path data of absolute `M L C Q Z` commands (what the corpus uses).
fn parse_path(d: &str) -> Vec<(char, Vec<DVec2>)> {
    let mut out: Vec<(char, Vec<DVec2>)> = Vec::new();
    let mut numbers = Vec::new();
    let mut command = None;
    let flush = |c: Option<char>, numbers: &mut Vec<f64>, out: &mut Vec<(char, Vec<DVec2>)>| {
        let Some(c) = c else { return };
        let per = match c {
            'M' | 'L' => 1,
            'C' => 3,
            'Q' => 2,
            'Z' => 0,
            _ => panic!("the plain drawer reads M L C Q Z, not {c}"),
        };
        let points: Vec<DVec2> = numbers.chunks(2).map(|p| DVec2::new(p[0], p[1])).collect();
        if per == 0 {
            assert!(points.is_empty(), "Z takes no numbers");
            out.push(('Z', Vec::new()));
        } else {
            assert!(
                numbers.len().is_multiple_of(2) && points.len().is_multiple_of(per),
                "{c} with {} numbers",
                numbers.len()
            );
            for (i, chunk) in points.chunks(per).enumerate() {
                // Pairs after a moveto are linetos.
                let c = if c == 'M' && i > 0 { 'L' } else { c };
                out.push((c, chunk.to_vec()));
            }
        }
        numbers.clear();
    };
    let mut rest = d.trim_start();
    while !rest.is_empty() {
        let c = rest.chars().next().expect("not empty");
        if c.is_ascii_alphabetic() {
            flush(command, &mut numbers, &mut out);
            command = Some(c);
            rest = &rest[1..];
        } else {
            let end = rest
                .char_indices()
                .skip(1)
                .find(|&(_, ch)| !(ch.is_ascii_digit() || ch == '.' || ch == 'e'))
                .map_or(rest.len(), |(i, _)| i);
            numbers.push(rest[..end].parse().expect("a number in path data"));
            rest = &rest[end..];
        }
        rest = rest.trim_start_matches(|ch: char| ch.is_whitespace() || ch == ',');
    }
    flush(command, &mut numbers, &mut out);
    out
}

/// The elements of a program, by name.
fn shapes(file: &File) -> HashMap<String, Shape> {
    let mut out = HashMap::new();
    for item in &file.items.stmts {
        let Item::Element(e) = &item.node else {
            continue;
        };
        let prop = |key: &str| {
            e.props.stmts.iter().find_map(|p| match &p.node.value {
                PropValue::Str(s, _) if p.node.key.name == key => Some(s.clone()),
                _ => None,
            })
        };
        let shape = Shape {
            commands: parse_path(&prop("path").expect("an element has a path")),
            fill: prop("fill").unwrap_or_else(|| "black".into()),
        };
        out.insert(e.name.name.clone(), shape);
    }
    out
}

/// The modules of a derived string as `lsyc run -o X.txt` writes it: names
/// and symbols, each with its numbers.
fn derived_modules(s: &str) -> Vec<(String, Option<Vec<f64>>)> {
    let mut out = Vec::new();
    let mut rest = s.trim_start();
    while let Some(c) = rest.chars().next() {
        let len = if c.is_alphabetic() || c == '_' || c == '?' {
            rest.char_indices()
                .skip(1)
                .find(|&(_, ch)| !(ch.is_alphanumeric() || ch == '_'))
                .map_or(rest.len(), |(i, _)| i)
        } else {
            c.len_utf8()
        };
        let name = rest[..len].to_string();
        rest = &rest[len..];
        let mut args = None;
        if let Some(r) = rest.strip_prefix('(') {
            let close = r.find(')').expect("a closed parameter list");
            args = Some(
                r[..close]
                    .split(',')
                    .map(|a| a.trim().parse().expect("a number in the derived string"))
                    .collect(),
            );
            rest = &r[close + 1..];
        }
        out.push((name, args));
        rest = rest.trim_start();
    }
    out
}

/// Writes a number for SVG path data, four decimals at most.
fn svg_number(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Draws a derived string with a 2D turtle of its own: start at (0, 0) heading
/// +y with scale 1; `f(d)` and `F(d)` move d·scale along the heading, `+(a)`
/// turns left (counter-clockwise) by a degrees and `-(a)` right, `*(k)`
/// scales, `[` `]` push and pop; an element prints its path with its local +y
/// along the heading and +x to the heading's right, scaled. World y is up, so
/// a world point (x, y) is written (x, −y). Every element becomes one `<path>`
/// with absolute coordinates (a similarity maps cubic control points exactly).
fn plain_svg(derived: &str, shapes: &HashMap<String, Shape>) -> String {
    #[derive(Clone, Copy)]
    struct Turtle {
        at: DVec2,
        heading: f64,
        scale: f64,
    }
    let mut t = Turtle {
        at: DVec2::ZERO,
        heading: 90.0,
        scale: 1.0,
    };
    let mut stack = Vec::new();
    let mut paths = Vec::new();
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for (name, args) in derived_modules(derived) {
        let one = || match args.as_deref() {
            Some([v]) => *v,
            _ => panic!("the plain drawer needs `{name}` with one explicit number"),
        };
        match name.as_str() {
            "[" => stack.push(t),
            "]" => t = stack.pop().expect("a `[` before `]`"),
            "+" => t.heading += one(),
            "-" => t.heading -= one(),
            "*" => t.scale *= one(),
            "f" | "F" => {
                let h = DVec2::from_angle(t.heading.to_radians());
                t.at += h * one() * t.scale;
                assert!(name == "f", "the corpus draws elements only, no F");
            }
            _ => {
                if let Some(shape) = shapes.get(&name) {
                    let h = DVec2::from_angle(t.heading.to_radians());
                    let right = DVec2::new(h.y, -h.x);
                    let mut d = String::new();
                    for (c, points) in &shape.commands {
                        d.push(*c);
                        for p in points {
                            let w = t.at + (right * p.x + h * p.y) * t.scale;
                            let svg = DVec2::new(w.x, -w.y);
                            lo = lo.min(svg);
                            hi = hi.max(svg);
                            write!(d, "{} {} ", svg_number(svg.x), svg_number(svg.y))
                                .expect("writes");
                        }
                    }
                    paths.push((d.trim_end().to_string(), shape.fill.clone()));
                } else {
                    let c = name.chars().next().expect("a name");
                    assert!(
                        c.is_alphabetic() && args.is_some(),
                        "the plain drawer does not know `{name}`"
                    );
                }
            }
        }
    }
    assert!(!paths.is_empty(), "nothing drawn");
    let margin = (hi - lo).max_element() * 0.02 + 1.0;
    let (lo, size) = (lo - margin, hi - lo + 2.0 * margin);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"800\" height=\"{}\">\n",
        svg_number(lo.x),
        svg_number(lo.y),
        svg_number(size.x),
        svg_number(size.y),
        (800.0 * size.y / size.x).round()
    );
    for (d, fill) in paths {
        writeln!(svg, "<path d=\"{d}\" fill=\"{fill}\"/>").expect("writes");
    }
    svg.push_str("</svg>\n");
    svg
}

// ---------------------------------------------------------------- programs

fn rule_count(file: &File) -> usize {
    file.items
        .stmts
        .iter()
        .filter_map(|i| match &i.node {
            Item::Lsystem(l) => Some(
                l.body
                    .stmts
                    .iter()
                    .filter(|s| matches!(s.node, Stmt::Rule(_)))
                    .count(),
            ),
            _ => None,
        })
        .sum()
}

/// Every module string of a program's lsystems: axioms and successors.
fn module_strings(file: &File) -> Vec<&[Module]> {
    let mut out = Vec::new();
    for item in &file.items.stmts {
        if let Item::Lsystem(l) = &item.node {
            for s in &l.body.stmts {
                match &s.node {
                    Stmt::Axiom(m) => out.push(m.as_slice()),
                    Stmt::Rule(r) => out.push(r.succ.as_slice()),
                    _ => {}
                }
            }
        }
    }
    out
}

/// The values of the largest parts of `e` that need no rule parameter:
/// `D0 - DD * m` gives D0 and DD.
fn constant_parts(e: &Expr, checked: &Checked, out: &mut Vec<f64>) {
    let lookup = |n: &str| checked.lookup(n);
    if let Ok(v) = evaluate(e, &lookup, &mut Random::new(0, 0, 0)) {
        out.push(v.value);
        return;
    }
    match &e.kind {
        ExprKind::Unary(_, a) => constant_parts(a, checked, out),
        ExprKind::Binary(_, a, b) => {
            constant_parts(a, checked, out);
            constant_parts(b, checked, out);
        }
        ExprKind::Call(_, args) => {
            for a in args {
                constant_parts(a, checked, out);
            }
        }
        _ => {}
    }
}

/// A program's transform numbers: the arguments of `+ - f F *` with
/// constants substituted, without 0 and without a scale of 1; each once.
fn transform_numbers(file: &File, checked: &Checked) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for string in module_strings(file) {
        for m in string {
            let (turtle, scale) = match &m.name {
                ModName::Symbol('+' | '-') => (true, false),
                ModName::Symbol('*') => (true, true),
                ModName::Name(n) => (n == "f" || n == "F", false),
                _ => (false, false),
            };
            if !turtle {
                continue;
            }
            let mut values = Vec::new();
            for a in m.args.iter().flatten() {
                constant_parts(a, checked, &mut values);
            }
            for v in values {
                let v = v.abs();
                if v == 0.0 || (scale && v == 1.0) || out.iter().any(|&o| close(o, v)) {
                    continue;
                }
                out.push(v);
            }
        }
    }
    out
}

/// Every number of a program: its constants and the constant parts of every
/// module's arguments, as absolute values.
fn all_numbers(file: &File, checked: &Checked) -> Vec<f64> {
    let mut out: Vec<f64> = checked.consts.values().map(|c| c.value.as_f64()).collect();
    for string in module_strings(file) {
        for m in string {
            for a in m.args.iter().flatten() {
                constant_parts(a, checked, &mut out);
            }
        }
    }
    out.iter().map(|v| v.abs()).collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= NUMBER * a.abs().max(b.abs())
}

// ---------------------------------------------------------------- the round trip

fn lsyc(args: &[&Path]) {
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .output()
        .expect("runs lsyc");
    assert!(
        out.status.success(),
        "lsyc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// What one drawing of a program gave back.
struct Outcome {
    program: String,
    /// Problems that fail the test whatever the lists say.
    broken: Vec<String>,
    rules: usize,
    matched: usize,
    chamfer: f64,
}

impl Outcome {
    fn gives_back(&self, orig: &Original) -> bool {
        self.rules.abs_diff(orig.rules) <= 1 && self.matched == orig.numbers.len()
    }
}

struct Original {
    rules: usize,
    numbers: Vec<f64>,
}

/// Infers a program from `svg`, checks it, draws it back and measures it.
fn measure(case: &str, column: &str, svg: &[u8], orig: &Original, dir: &Path) -> Outcome {
    let mut broken = Vec::new();
    let name = format!("{case}.svg");
    let program = match elements::from_svg(svg, &name, &Options::default(), &mut |_| {}) {
        Ok(inferred) => inferred.text,
        Err(e) => {
            return Outcome {
                program: String::new(),
                broken: vec![format!("{case} ({column}): inference failed: {e}")],
                rules: 0,
                matched: 0,
                chamfer: f64::INFINITY,
            };
        }
    };
    let fe = frontend::run(&program, Vec::new(), &[]);
    if !fe.diagnostics.is_empty() {
        broken.push(format!(
            "{case} ({column}): the inferred program has diagnostics:\n{}",
            render_plain(&fe.diagnostics, &name, &program)
        ));
    }
    let (rules, matched) = match &fe.checked {
        Some(checked) if !fe.has_errors() => {
            let found = all_numbers(&fe.file, checked);
            let matched = orig
                .numbers
                .iter()
                .filter(|&&o| found.iter().any(|&x| close(o, x)))
                .count();
            (rule_count(&fe.file), matched)
        }
        _ => (0, 0),
    };
    let prog = dir.join(format!("{case}-{column}.lsy"));
    let back = dir.join(format!("{case}-{column}-back.svg"));
    std::fs::write(&prog, &program).expect("writes");
    lsyc(&["run".as_ref(), &prog, "-o".as_ref(), &back]);
    let output = std::fs::read(&back).expect("reads the redraw");
    let chamfer = relative_chamfer(svg, &output);
    let (n_in, n_out) = (element_count(svg), element_count(&output));
    if n_in != n_out {
        broken.push(format!(
            "{case} ({column}): {n_out} elements drawn back of {n_in}"
        ));
    }
    if chamfer.is_nan() || chamfer > REDRAW {
        broken.push(format!(
            "{case} ({column}): Chamfer {chamfer:.2e} of the diagonal"
        ));
    }
    Outcome {
        program,
        broken,
        rules,
        matched,
        chamfer,
    }
}

struct Case {
    name: String,
    elements: usize,
    orig: Original,
    used: Outcome,
    plain: Outcome,
}

fn run_case(path: &Path, dir: &Path) -> Case {
    let name = path
        .file_stem()
        .expect("a file name")
        .to_string_lossy()
        .into_owned();
    let text = read_text(path);
    let fe = frontend::run(&text, Vec::new(), &[]);
    assert!(
        fe.diagnostics.is_empty(),
        "{}",
        render_plain(&fe.diagnostics, &rel(path), &text)
    );
    let checked = fe.checked.as_ref().expect("checked");
    let orig = Original {
        rules: rule_count(&fe.file),
        numbers: transform_numbers(&fe.file, checked),
    };
    let (svg_path, txt_path) = (
        dir.join(format!("{name}.svg")),
        dir.join(format!("{name}.txt")),
    );
    lsyc(&["run".as_ref(), path, "-o".as_ref(), &svg_path]);
    lsyc(&["run".as_ref(), path, "-o".as_ref(), &txt_path]);
    let drawn = std::fs::read_to_string(&svg_path).expect("reads the drawing");
    let neutral = neutralize(&drawn);
    let elements = element_count(drawn.as_bytes());
    assert_eq!(
        element_count(neutral.as_bytes()),
        elements,
        "{name}: neutralizing keeps every element"
    );
    let derived = std::fs::read_to_string(&txt_path).expect("reads the string");
    let plain = plain_svg(&derived, &shapes(&fe.file));
    // The independent drawer agrees with lsyc's (up to lsyc's rounding).
    let agree = relative_chamfer(drawn.as_bytes(), plain.as_bytes());
    assert!(
        agree < 1e-4 && element_count(plain.as_bytes()) == elements,
        "{name}: the plain drawing differs from lsyc's (Chamfer {agree:.2e})"
    );
    let used = measure(&name, "use", neutral.as_bytes(), &orig, dir);
    let plain = measure(&name, "plain", plain.as_bytes(), &orig, dir);
    Case {
        name,
        elements,
        orig,
        used,
        plain,
    }
}

fn table(cases: &[Case]) -> String {
    let mut t = String::from(
        "| case | elements | rules | use: rules | numbers | Chamfer | given back | plain: rules | numbers | Chamfer | given back |\n\
         |---|---:|---:|---:|---:|---:|---|---:|---:|---:|---|\n",
    );
    let cell = |o: &Outcome, c: &Case| {
        format!(
            "{} | {}/{} | {:.1e} | {}",
            o.rules,
            o.matched,
            c.orig.numbers.len(),
            o.chamfer,
            if o.gives_back(&c.orig) {
                "yes"
            } else {
                "not yet"
            }
        )
    };
    for c in cases {
        writeln!(
            t,
            "| {} | {} | {} | {} | {} |",
            c.name,
            c.elements,
            c.orig.rules,
            cell(&c.used, c),
            cell(&c.plain, c)
        )
        .expect("writes");
    }
    t
}

/// Checks one column against its list: hard failures, cases that do not give
/// back their program but are not listed, and listed cases that now do.
fn judge(
    cases: &[Case],
    column: &str,
    list: &[(&str, &str)],
    pick: fn(&Case) -> &Outcome,
    failures: &mut Vec<String>,
) {
    let listed: BTreeMap<&str, &str> = list.iter().copied().collect();
    for (name, _) in list {
        if !cases.iter().any(|c| c.name == *name) {
            failures.push(format!("{column}: {name} is listed but is not a case"));
        }
    }
    for c in cases {
        let o = pick(c);
        failures.extend(o.broken.iter().cloned());
        let gives_back = o.gives_back(&c.orig);
        match (gives_back, listed.contains_key(c.name.as_str())) {
            (true, true) => failures.push(format!(
                "{column}: {} now gives back its program: remove {} from {}",
                c.name,
                c.name,
                if column == "use" {
                    "NOT_YET"
                } else {
                    "NOT_YET_PLAIN"
                }
            )),
            (false, false) => failures.push(format!(
                "{column}: {} does not give back its program (rules {} of {}, numbers {}/{}: {:?})",
                c.name,
                o.rules,
                c.orig.rules,
                o.matched,
                c.orig.numbers.len(),
                c.orig.numbers
            )),
            _ => {}
        }
    }
}

#[test]
fn inferred_programs_give_back_the_hand_written_ones() {
    let files = lsy_files(&["tests/data/roundtrip"]);
    assert!(files.len() >= 16, "the round-trip corpus is missing");
    let dir = tempfile::tempdir().expect("tempdir");
    // One case per thread at a time: inference and the runs are independent.
    let next = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut cases: Vec<Case> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(path) = files.get(i) else {
                            return done;
                        };
                        done.push(run_case(path, dir.path()));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("a case panicked"))
            .collect()
    });
    cases.sort_by(|a, b| a.name.cmp(&b.name));
    for c in &cases {
        insta::assert_snapshot!(format!("roundtrip_{}_use", c.name), c.used.program);
        insta::assert_snapshot!(format!("roundtrip_{}_plain", c.name), c.plain.program);
    }
    insta::assert_snapshot!("roundtrip_table", table(&cases));
    let mut failures = Vec::new();
    judge(&cases, "use", NOT_YET, |c| &c.used, &mut failures);
    judge(&cases, "plain", NOT_YET_PLAIN, |c| &c.plain, &mut failures);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn neutralizing_leaves_geometry_only() {
    let svg = r##"<?xml version="1.0" encoding="UTF-8"?>
<!-- drawn by lsyc -->
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 10 10">
<defs>
<path id="e0" class="element" data-element="Leaf" d="M0 0 L1 1 Z" fill="url(#e1)"/>
<linearGradient id="e1"/>
</defs>
<use href="#e0" xlink:href='#e0' data-module="A" transform="matrix(1 0 0 -1 0 0)"/>
</svg>
"##;
    let out = neutralize(svg);
    assert_eq!(
        out,
        r##"<?xml version="1.0" encoding="UTF-8"?>

<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 10 10">
<defs>
<path id="d1" d="M0 0 L1 1 Z" fill="url(#d2)"/>
<linearGradient id="d2"/>
</defs>
<use href="#d1" xlink:href='#d1' transform="matrix(1 0 0 -1 0 0)"/>
</svg>
"##
    );
}

#[test]
fn the_plain_drawer_follows_the_turtle() {
    let file = lsyc::parser::parse(r#"element T { path "M0 0 L1 0 L0 2 Z"; fill "red"; }"#).file;
    // Turn left by 90 (heading -x), move 2, scale by 3: the element's +y
    // points along -x and its +x along +y, from (-2, 0).
    let svg = plain_svg("+(90) f(2)*(3) T", &shapes(&file));
    assert!(
        svg.contains(r#"<path d="M-2 0 L-2 -3 L-8 0 Z" fill="red"/>"#),
        "{svg}"
    );
}
