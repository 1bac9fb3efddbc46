//! The compiler: one checked `lsystem` to a `Program` the engine runs.
//!
//! Owns: the symbol table (a symbol is a module name with an arity, so `F` and
//! `F(2)` are different symbols, as in cpfg), rules as patterns plus bytecode,
//! successor templates, constant folding, and the D0L fast-path table. Must not
//! report user mistakes the checker can find: it runs only on checked files.

use crate::ast::{File, Item, Lsystem, ModName, Module, Rule, Stmt};
use crate::check::Checked;
use crate::diagnostic::{Code as DiagCode, Diagnostic};
use crate::span::Span;
use crate::vm::{Chunk, Code, ExprCompiler, ExprError, Op};
use std::collections::HashMap;
use std::sync::Arc;

use crate::organ;

/// A symbol id: index into `Symbols`.
pub type Sym = u16;

/// What the turtle does with a symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    None,
    /// `F`: move and draw.
    Draw,
    /// `f`: move without drawing.
    Move,
    TurnLeft,
    TurnRight,
    PitchDown,
    PitchUp,
    RollLeft,
    RollRight,
    TurnAround,
    RollHorizontal,
    Scale,
    Push,
    Pop,
    PolygonStart,
    PolygonEnd,
    Vertex,
    Width,
    Color,
    Cut,
    /// Prints element `n` (index into `Program::elements`).
    Element(u16),
    /// A query module (index into `query::QUERIES`), answered by the environment.
    Query(u8),
    /// `tropism(e)`: sets the elasticity of tropism for the rest of the branch.
    Elasticity,
}

#[derive(Clone, Debug)]
pub struct SymbolInfo {
    pub name: ModName,
    pub arity: u8,
    pub action: Action,
}

/// The symbols of a program, each a (name, arity) pair.
#[derive(Clone, Debug, Default)]
pub struct Symbols {
    pub info: Vec<SymbolInfo>,
    map: HashMap<(ModName, u8), Sym>,
}

/// The most distinct (name, arity) pairs a program may use.
pub const MAX_SYMBOLS: usize = u16::MAX as usize;

impl Symbols {
    pub fn get(&self, name: &ModName, arity: usize) -> Option<Sym> {
        let a = u8::try_from(arity).ok()?;
        self.map.get(&(name.clone(), a)).copied()
    }

    pub fn len(&self) -> usize {
        self.info.len()
    }

    pub fn is_empty(&self) -> bool {
        self.info.is_empty()
    }

    pub fn arity(&self, s: Sym) -> usize {
        self.info[s as usize].arity as usize
    }
}

/// A module to emit: a symbol and the code of its parameters.
#[derive(Clone, Debug)]
pub struct Emit {
    pub sym: Sym,
    pub args: Vec<Code>,
}

/// A context module pattern: its symbol and where its parameters go.
#[derive(Clone, Debug)]
pub struct Pattern {
    pub sym: Sym,
    /// First slot for its parameters.
    pub slot: u16,
}

#[derive(Clone, Debug)]
pub struct CompiledRule {
    pub left: Vec<Pattern>,
    pub right: Vec<Pattern>,
    pub cond: Option<Code>,
    /// Stochastic weight; rules with the same `group` are alternatives.
    pub weight: Option<Code>,
    pub group: u32,
    pub succ: Vec<Emit>,
    /// Parameter slots the rule binds (predecessor first, then contexts).
    pub slots: u16,
    pub span: Span,
}

/// An element: a terminal that prints SVG path data, a 3D organ (`sphere`,
/// `disk`, `mesh`, `patch`) or selects a branch contour (`contour`).
#[derive(Clone, Debug)]
pub struct ElementDef {
    pub name: String,
    pub path: String,
    pub fill: Option<String>,
    pub stroke: Option<String>,
    pub width: Option<f64>,
    /// A 3D organ's mesh in the element's local frame (for `mesh`, once the
    /// file is read: see `mesh`).
    pub solid: Option<Arc<organ::Solid>>,
    /// `mesh "FILE.obj"`: the file as written and the span of the string,
    /// read by the run (relative to the program's directory).
    pub mesh: Option<(String, Span)>,
    /// `contour "…"`: a closed profile for the branches that follow.
    pub contour: Option<Arc<Vec<glam::DVec2>>>,
}

/// A colour of the program's `palette`.
#[derive(Clone, Debug, PartialEq)]
pub struct PaletteColor {
    pub index: u32,
    pub rgb: [u8; 3],
    /// The material name of OBJ and glTF, if the palette gives one.
    pub name: Option<String>,
}

impl ElementDef {
    /// Whether printing the element selects a contour instead of drawing.
    pub fn is_contour(&self) -> bool {
        self.contour.is_some()
    }
}

/// One lsystem, ready to derive and interpret.
#[derive(Clone, Debug)]
pub struct Program {
    pub name: String,
    pub name_span: Span,
    pub symbols: Symbols,
    pub chunk: Chunk,
    /// The axiom, evaluated once (it may use the lsystem's parameters).
    pub axiom: Vec<Emit>,
    /// Derivation rules per symbol, in source order.
    pub rules: Vec<Vec<CompiledRule>>,
    /// Interpretation (homomorphism) rules per symbol.
    pub interpret: Vec<Vec<CompiledRule>>,
    /// Decomposition rules per symbol, applied after each derivation step.
    pub decompose: Vec<Vec<CompiledRule>>,
    /// `tropism (x, y, z) e;`: the vector T and the starting elasticity.
    pub tropism: Option<([f64; 3], f64)>,
    /// For D0L programs: the fixed successor of every symbol.
    pub d0l: Option<Vec<Vec<Sym>>>,
    /// Symbols skipped when matching context.
    pub ignore: Vec<bool>,
    pub has_context: bool,
    pub has_cut: bool,
    pub angle: f64,
    pub step: f64,
    pub derive: u32,
    pub params: Vec<String>,
    pub elements: Vec<ElementDef>,
    /// Whether any 3D symbol (& ^ \ / | $) appears.
    pub is_3d: bool,
    /// The file's `palette`, by index (empty: the built-in colours).
    pub palette: Vec<PaletteColor>,
}

impl Program {
    /// Whether the program draws random numbers while deriving (a random
    /// function, or a choice between weighted rules): then the same string may
    /// rewrite differently at each step.
    pub fn draws_random(&self) -> bool {
        self.chunk
            .code
            .iter()
            .any(|op| matches!(op, Op::Rand | Op::Uniform | Op::Normal))
            || self.rules.iter().flatten().any(|r| r.weight.is_some())
    }
}

/// Why a checked file could not be compiled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CompileError {
    #[error("the file has no lsystem to run")]
    NoLsystem,
    #[error("there is no lsystem `{name}`; the file has: {}", available.join(", "))]
    UnknownSystem {
        name: String,
        available: Vec<String>,
    },
    #[error("`{module}` has more than 255 parameters")]
    TooManyParameters { module: String, span: Span },
    #[error("the program uses more than 65535 distinct modules")]
    TooManySymbols { span: Span },
    #[error(transparent)]
    Expr(#[from] ExprError),
}

impl CompileError {
    /// The error as a diagnostic pointing into the program.
    pub fn diagnostic(&self) -> Diagnostic {
        match self {
            CompileError::NoLsystem => Diagnostic::error(DiagCode::NoLsystem, self.to_string())
                .primary(Span::default(), "the file holds no `lsystem` item")
                .help("add one, e.g. `lsystem Koch { axiom F; F -> F+F-F-F+F; }`"),
            CompileError::UnknownSystem { .. } => {
                Diagnostic::error(DiagCode::UnknownSystem, self.to_string())
            }
            CompileError::TooManyParameters { span, .. } => {
                Diagnostic::error(DiagCode::TooManyParameters, self.to_string())
                    .primary(*span, "this module has too many parameters")
                    .help("pass fewer values: a module takes at most 255 parameters")
            }
            CompileError::TooManySymbols { span } => Diagnostic::error(
                DiagCode::TooManySymbols,
                self.to_string(),
            )
            .primary(*span, "this is module number 65536")
            .help("a program may use at most 65535 distinct modules (name and parameter count)"),
            CompileError::Expr(e) => e.diagnostic(),
        }
    }
}

/// Compiles the lsystem called `name` (or the first one) of a checked file.
pub fn compile(
    file: &File,
    checked: &Checked,
    name: Option<&str>,
) -> Result<Program, CompileError> {
    let systems: Vec<&Lsystem> = file
        .items
        .stmts
        .iter()
        .filter_map(|i| match &i.node {
            Item::Lsystem(l) => Some(l),
            _ => None,
        })
        .collect();
    let ls = match name {
        Some(n) => systems
            .iter()
            .find(|l| l.name.name == n)
            .copied()
            .ok_or_else(|| CompileError::UnknownSystem {
                name: n.to_string(),
                available: systems.iter().map(|l| l.name.name.clone()).collect(),
            })?,
        None => *systems.first().ok_or(CompileError::NoLsystem)?,
    };
    Compiler::new(file, checked).lsystem(ls)
}

struct Compiler<'a> {
    checked: &'a Checked,
    symbols: Symbols,
    chunk: Chunk,
    elements: Vec<ElementDef>,
    palette: Vec<PaletteColor>,
    element_index: HashMap<String, u16>,
    /// Declared arity of query modules' outputs, to pad successors.
    group: u32,
}

fn action_of(name: &ModName, element: Option<u16>) -> Action {
    match name {
        ModName::Name(n) if n == "F" => Action::Draw,
        ModName::Name(n) if n == "f" => Action::Move,
        ModName::Name(n) if n == "tropism" => Action::Elasticity,
        ModName::Name(_) => element.map_or(Action::None, Action::Element),
        ModName::Symbol(c) => match c {
            '+' => Action::TurnLeft,
            '-' => Action::TurnRight,
            '&' => Action::PitchDown,
            '^' => Action::PitchUp,
            '\\' => Action::RollLeft,
            '/' => Action::RollRight,
            '|' => Action::TurnAround,
            '$' => Action::RollHorizontal,
            '*' => Action::Scale,
            '[' => Action::Push,
            ']' => Action::Pop,
            '{' => Action::PolygonStart,
            '}' => Action::PolygonEnd,
            '.' => Action::Vertex,
            '!' => Action::Width,
            '\'' => Action::Color,
            '%' => Action::Cut,
            _ => Action::None,
        },
        ModName::Cut => Action::Cut,
        ModName::Query(q) => crate::query::QUERIES
            .iter()
            .position(|x| x.name == q)
            .map_or(Action::None, |i| Action::Query(i as u8)),
    }
}

impl<'a> Compiler<'a> {
    fn new(file: &'a File, checked: &'a Checked) -> Compiler<'a> {
        let mut elements = Vec::new();
        let mut element_index = HashMap::new();
        for item in &file.items.stmts {
            if let Item::Element(e) = &item.node {
                let mut def = ElementDef {
                    name: e.name.name.clone(),
                    path: String::new(),
                    fill: None,
                    stroke: None,
                    width: None,
                    solid: None,
                    mesh: None,
                    contour: None,
                };
                for p in &e.props.stmts {
                    match (&p.node.key.name[..], &p.node.value) {
                        ("path", crate::ast::PropValue::Str(s, _)) => def.path = s.clone(),
                        ("fill", crate::ast::PropValue::Str(s, _)) => def.fill = Some(s.clone()),
                        ("stroke", crate::ast::PropValue::Str(s, _)) => {
                            def.stroke = Some(s.clone())
                        }
                        ("width", crate::ast::PropValue::Expr(x)) => {
                            def.width = checked.value_of(x)
                        }
                        ("sphere", crate::ast::PropValue::Expr(x)) => {
                            def.solid = checked.value_of(x).map(|r| Arc::new(organ::sphere(r)))
                        }
                        ("disk", crate::ast::PropValue::Expr(x)) => {
                            def.solid = checked.value_of(x).map(|r| Arc::new(organ::disk(r)))
                        }
                        ("patch", crate::ast::PropValue::Str(s, _)) => {
                            def.solid = organ::patch_numbers(s)
                                .ok()
                                .map(|n| Arc::new(organ::patches(&n)))
                        }
                        ("mesh", crate::ast::PropValue::Str(s, span)) => {
                            def.mesh = Some((s.clone(), *span))
                        }
                        ("contour", crate::ast::PropValue::Str(s, _)) => {
                            def.contour = organ::contour_from_path(s).ok().map(Arc::new)
                        }
                        _ => {}
                    }
                }
                element_index.insert(def.name.clone(), elements.len() as u16);
                elements.push(def);
            }
        }
        let mut palette: Vec<PaletteColor> = Vec::new();
        for item in &file.items.stmts {
            if let Item::Palette(p) = &item.node {
                for e in &p.body.stmts {
                    let e = &e.node;
                    let (Some(index), Ok(c)) = (
                        checked.value_of(&e.index),
                        e.color.parse::<svgtypes::Color>(),
                    ) else {
                        continue;
                    };
                    if palette.iter().any(|p| p.index == index as u32) {
                        continue;
                    }
                    palette.push(PaletteColor {
                        index: index as u32,
                        rgb: [c.red, c.green, c.blue],
                        name: e.name.as_ref().map(|n| n.name.clone()),
                    });
                }
                // One palette per file (a second is an error).
                break;
            }
        }
        palette.sort_by_key(|p| p.index);
        Compiler {
            checked,
            symbols: Symbols::default(),
            chunk: Chunk::default(),
            elements,
            palette,
            element_index,
            group: 0,
        }
    }

    /// The symbol of a module as it appears in a string (queries with outputs padded).
    fn intern(&mut self, name: &ModName, arity: usize, span: Span) -> Result<Sym, CompileError> {
        let name = match name {
            ModName::Cut => ModName::Symbol('%'),
            n => n.clone(),
        };
        let a = u8::try_from(arity).map_err(|_| CompileError::TooManyParameters {
            module: name.text().to_string(),
            span,
        })?;
        if let Some(&s) = self.symbols.map.get(&(name.clone(), a)) {
            return Ok(s);
        }
        if self.symbols.info.len() >= MAX_SYMBOLS {
            return Err(CompileError::TooManySymbols { span });
        }
        let element = match &name {
            ModName::Name(n) => self.element_index.get(n).copied(),
            _ => None,
        };
        let s = self.symbols.info.len() as Sym;
        self.symbols.info.push(SymbolInfo {
            action: action_of(&name, element),
            name: name.clone(),
            arity: a,
        });
        self.symbols.map.insert((name, a), s);
        Ok(s)
    }

    /// Full arity of a module written in a successor or axiom (queries gain their outputs).
    fn written_arity(m: &Module) -> usize {
        match &m.name {
            ModName::Query(q) => crate::query::lookup(q).map_or(0, |q| q.outputs.len()) + m.arity(),
            _ => m.arity(),
        }
    }

    fn emit_list(
        &mut self,
        ms: &[Module],
        env: &HashMap<String, u16>,
    ) -> Result<Vec<Emit>, CompileError> {
        let mut out = Vec::with_capacity(ms.len());
        for m in ms {
            let sym = self.intern(&m.name, Self::written_arity(m), m.span)?;
            let checked = self.checked;
            let mut args = Vec::new();
            if let ModName::Query(q) = &m.name {
                let k = crate::query::lookup(q).map_or(0, |q| q.outputs.len());
                for _ in 0..k {
                    let start = self.chunk.len();
                    self.chunk.push(Op::Const(0.0), m.span);
                    args.push(Code::new(&self.chunk, start, start + 1));
                }
            }
            for a in m.args.iter().flatten() {
                args.push(
                    ExprCompiler::new(&mut self.chunk, &|n| checked.lookup(n), env).compile(a)?,
                );
            }
            out.push(Emit { sym, args });
        }
        Ok(out)
    }

    fn rule(&mut self, r: &Rule) -> Result<(Sym, CompiledRule), CompileError> {
        let mut env: HashMap<String, u16> = HashMap::new();
        let mut slot: u16 = 0;
        let mut bind = |m: &Module, env: &mut HashMap<String, u16>| -> u16 {
            let first = slot;
            for a in m.args.iter().flatten() {
                if let crate::ast::ExprKind::Var(n) = &a.kind
                    && n != "_"
                {
                    env.insert(n.clone(), slot);
                }
                slot += 1;
            }
            first
        };
        bind(&r.pred, &mut env);
        let mut left = Vec::new();
        for m in r.left.iter().flatten() {
            let s = bind(m, &mut env);
            left.push((m, s));
        }
        let mut right = Vec::new();
        for m in r.right.iter().flatten() {
            let s = bind(m, &mut env);
            right.push((m, s));
        }
        let pred = self.intern(&r.pred.name, r.pred.arity(), r.pred.span)?;
        let mut lp = Vec::new();
        for (m, s) in left {
            lp.push(Pattern {
                sym: self.intern(&m.name, m.arity(), m.span)?,
                slot: s,
            });
        }
        let mut rp = Vec::new();
        for (m, s) in right {
            rp.push(Pattern {
                sym: self.intern(&m.name, m.arity(), m.span)?,
                slot: s,
            });
        }
        let checked = self.checked;
        let cond = r
            .cond
            .as_ref()
            .map(|c| ExprCompiler::new(&mut self.chunk, &|n| checked.lookup(n), &env).compile(c))
            .transpose()?;
        let weight = r
            .weight
            .as_ref()
            .map(|w| ExprCompiler::new(&mut self.chunk, &|n| checked.lookup(n), &env).compile(w))
            .transpose()?;
        let succ = self.emit_list(&r.succ, &env)?;
        Ok((
            pred,
            CompiledRule {
                left: lp,
                right: rp,
                cond,
                weight,
                group: 0,
                succ,
                slots: slot,
                span: r
                    .pred
                    .span
                    .to(r.succ.last().map_or(r.pred.span, |m| m.span)),
            },
        ))
    }

    fn lsystem(mut self, ls: &Lsystem) -> Result<Program, CompileError> {
        let mut angle = 90.0;
        let mut step = 1.0;
        let mut derive = 1u32;
        let mut axiom_mods: &[Module] = &[];
        let mut ignore_mods: Vec<&Module> = Vec::new();
        let mut consider_mods: Option<Vec<&Module>> = None;
        let mut tropism = None;
        for s in &ls.body.stmts {
            match &s.node {
                Stmt::Angle(e) => angle = self.checked.value_of(e).unwrap_or(angle),
                Stmt::Step(e) => step = self.checked.value_of(e).unwrap_or(step),
                Stmt::Derive(e) => derive = self.checked.value_of(e).map_or(derive, |v| v as u32),
                Stmt::Axiom(ms) => axiom_mods = ms,
                Stmt::Ignore(ms) => ignore_mods.extend(ms.iter()),
                Stmt::Consider(ms) => consider_mods.get_or_insert_default().extend(ms.iter()),
                Stmt::Tropism(t) => {
                    let v = |e| self.checked.value_of(e).unwrap_or(0.0);
                    tropism = Some(([v(&t.dir[0]), v(&t.dir[1]), v(&t.dir[2])], v(&t.elasticity)));
                }
                _ => {}
            }
        }
        let axiom_env: HashMap<String, u16> = ls
            .params
            .iter()
            .enumerate()
            .map(|(i, p)| (p.name.clone(), i as u16))
            .collect();
        let axiom = self.emit_list(axiom_mods, &axiom_env)?;
        let mut rules: Vec<(Sym, CompiledRule, u8)> = Vec::new();
        let mut prev: Option<(Sym, u8, bool)> = None;
        for s in &ls.body.stmts {
            let Stmt::Rule(r) = &s.node else { continue };
            let (sym, mut cr) = self.rule(r)?;
            // Consecutive weighted rules for one symbol form one stochastic group.
            let weighted = cr.weight.is_some();
            let kind = if r.interpret {
                1
            } else if r.decompose {
                2
            } else {
                0
            };
            let continues = weighted && prev == Some((sym, kind, true));
            if !continues {
                self.group += 1;
            }
            cr.group = self.group;
            prev = Some((sym, kind, weighted));
            rules.push((sym, cr, kind));
        }
        let n = self.symbols.len();
        let mut by_sym: Vec<Vec<CompiledRule>> = vec![Vec::new(); n];
        let mut interp: Vec<Vec<CompiledRule>> = vec![Vec::new(); n];
        let mut decomp: Vec<Vec<CompiledRule>> = vec![Vec::new(); n];
        let mut has_context = false;
        for (sym, cr, kind) in rules {
            match kind {
                1 => interp[sym as usize].push(cr),
                2 => decomp[sym as usize].push(cr),
                _ => {
                    has_context |= !cr.left.is_empty() || !cr.right.is_empty();
                    by_sym[sym as usize].push(cr);
                }
            }
        }
        let mut ignore = vec![false; n];
        if let Some(consider) = &consider_mods {
            // `consider` is the complement of `ignore`: context sees only these.
            for (i, info) in self.symbols.info.iter().enumerate() {
                let named = consider.iter().any(|m| {
                    m.name == info.name
                        || (m.name == ModName::Cut && info.name == ModName::Symbol('%'))
                });
                ignore[i] = !named && !matches!(info.action, Action::Push | Action::Pop);
            }
        }
        for m in ignore_mods {
            for (i, info) in self.symbols.info.iter().enumerate() {
                if info.name == m.name
                    || (m.name == ModName::Cut && info.name == ModName::Symbol('%'))
                {
                    ignore[i] = true;
                }
            }
        }
        let has_cut = self.symbols.info.iter().any(|i| i.action == Action::Cut);
        let is_3d = self.symbols.info.iter().any(|i| {
            matches!(
                i.action,
                Action::PitchDown
                    | Action::PitchUp
                    | Action::RollLeft
                    | Action::RollRight
                    | Action::TurnAround
                    | Action::RollHorizontal
            )
        }) || tropism.is_some_and(|(t, _)| t[2] != 0.0)
            || self.symbols.info.iter().any(|i| match i.action {
                // A 3D organ shows its depth only in the oblique view.
                Action::Element(e) => self
                    .elements
                    .get(e as usize)
                    .is_some_and(|d| d.solid.is_some() || d.mesh.is_some()),
                _ => false,
            });
        let d0l = d0l_table(&self.symbols, &by_sym, &self.chunk);
        Ok(Program {
            name: ls.name.name.clone(),
            name_span: ls.name.span,
            symbols: self.symbols,
            chunk: self.chunk,
            axiom,
            rules: by_sym,
            interpret: interp,
            decompose: decomp,
            tropism,
            d0l,
            ignore,
            has_context,
            has_cut,
            angle,
            step,
            derive,
            params: ls.params.iter().map(|p| p.name.clone()).collect(),
            elements: self.elements,
            is_3d,
            palette: self.palette,
        })
    }
}

/// A D0L program: every symbol has no parameters, and every rule is
/// unconditional, context-free and not stochastic (the first rule wins).
fn d0l_table(
    symbols: &Symbols,
    rules: &[Vec<CompiledRule>],
    _chunk: &Chunk,
) -> Option<Vec<Vec<Sym>>> {
    if symbols.info.iter().any(|i| i.arity != 0) {
        return None;
    }
    let mut table = Vec::with_capacity(symbols.len());
    for (s, rs) in rules.iter().enumerate() {
        match rs.first() {
            None => table.push(vec![s as Sym]),
            Some(r) => {
                if r.cond.is_some()
                    || r.weight.is_some()
                    || !r.left.is_empty()
                    || !r.right.is_empty()
                {
                    return None;
                }
                table.push(r.succ.iter().map(|e| e.sym).collect());
            }
        }
    }
    Some(table)
}

impl Program {
    /// A listing of every compiled expression: the axiom's parameters, then each
    /// rule's condition, weight and successor parameters, with source spans.
    pub fn disassemble(&self) -> String {
        use std::fmt::Write;
        let mut out = String::new();
        let name = |s: Sym| {
            let i = &self.symbols.info[s as usize];
            if i.arity == 0 {
                i.name.text().into_owned()
            } else {
                format!("{}:{}", i.name.text(), i.arity)
            }
        };
        let _ = writeln!(
            out,
            "lsystem {}: {} symbols, {} instructions",
            self.name,
            self.symbols.len(),
            self.chunk.len()
        );
        for (k, e) in self.axiom.iter().enumerate() {
            for (a, code) in e.args.iter().enumerate() {
                let _ = writeln!(out, "axiom module {k} {} parameter {a}:", name(e.sym));
                self.chunk.disassemble(*code, &mut out);
            }
        }
        for (kind, table) in [
            ("rule", &self.rules),
            ("interpret", &self.interpret),
            ("decompose", &self.decompose),
        ] {
            for (s, rules) in table.iter().enumerate() {
                for (k, r) in rules.iter().enumerate() {
                    let _ = writeln!(
                        out,
                        "{kind} {} #{k} (group {}, {} slots) @{}..{}",
                        name(s as Sym),
                        r.group,
                        r.slots,
                        r.span.start,
                        r.span.end
                    );
                    if let Some(c) = r.cond {
                        let _ = writeln!(out, "  condition:");
                        self.chunk.disassemble(c, &mut out);
                    }
                    if let Some(w) = r.weight {
                        let _ = writeln!(out, "  weight:");
                        self.chunk.disassemble(w, &mut out);
                    }
                    for (m, e) in r.succ.iter().enumerate() {
                        for (a, code) in e.args.iter().enumerate() {
                            let _ = writeln!(out, "  successor {m} {} parameter {a}:", name(e.sym));
                            self.chunk.disassemble(*code, &mut out);
                        }
                    }
                }
            }
        }
        out
    }
}
