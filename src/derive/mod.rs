//! The derivation engine: parallel rewriting of a flat module string.
//!
//! Owns: the module string (symbol ids and one flat parameter array — a module's
//! parameters are found by summing arities, so a parameterless module costs two
//! bytes), the D0L fast path, parametric/stochastic/context-sensitive rewriting,
//! `cut`, and the limits that stop an explosion before it allocates. Results are
//! the same on any number of threads: random choices are keyed by
//! (seed, step, position). Must not draw.

mod context;
pub mod decompose;

use crate::compile::{Action, CompiledRule, Program, Sym};
use crate::diagnostic::{Code, Diagnostic};
use crate::vm::{Fault, Random, VmError};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Modules per parallel work unit.
const CHUNK: usize = 1 << 15;

/// The widest D0L successor copied as a fixed-size block.
const PAD: usize = 16;

/// A derived string: `syms[i]` is module i; its parameters follow those of the
/// modules before it in `params` (each symbol has a fixed arity).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModString {
    pub syms: Vec<Sym>,
    pub params: Vec<f64>,
}

impl ModString {
    pub fn len(&self) -> usize {
        self.syms.len()
    }

    pub fn is_empty(&self) -> bool {
        self.syms.is_empty()
    }

    /// Bytes held by the string.
    pub fn bytes(&self) -> usize {
        self.syms.len() * std::mem::size_of::<Sym>() + self.params.len() * 8
    }
}

/// Limits that end a derivation with a message instead of exhausting memory.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_modules: usize,
    pub max_bytes: usize,
    /// When set (by another thread), the next derivation step (or the
    /// turtle, every few thousand modules) stops with `DeriveError::Cancelled`: `lsyc studio` stops a run that a newer edit
    /// replaced. `None` everywhere else.
    pub cancel: Option<&'static std::sync::atomic::AtomicBool>,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_modules: 250_000_000,
            max_bytes: 4 << 30,
            cancel: None,
        }
    }
}

/// The most derivation steps a run may take (`derive` and `-n` alike).
pub const MAX_STEPS: u32 = 1_000_000;

/// Why deriving or interpreting stopped. Every variant says the same thing on
/// every run and thread count: a count is given only where it is exact.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DeriveError {
    /// Step `step` would produce `modules` modules (when known exactly: the
    /// D0L forecast), over the limit.
    #[error("{}", too_many_modules(*.step, *.modules, *.limit))]
    TooManyModules {
        step: u32,
        modules: Option<usize>,
        limit: usize,
    },
    /// Step `step` would need about `bytes` bytes (when known exactly), over the limit.
    #[error("{}", too_much_memory(*.step, *.bytes, *.limit))]
    TooMuchMemory {
        step: u32,
        bytes: Option<usize>,
        limit: usize,
    },
    /// An expression failed while deriving step `step` (0: the axiom;
    /// `u32::MAX`: while interpreting).
    #[error("{error} {}", when(*.step))]
    Vm { step: u32, error: VmError },
    /// Interpretation rules expanded into each other `depth` times.
    #[error("interpretation rules expand `{module}` more than {depth} levels deep")]
    InterpretTooDeep { module: String, depth: usize },
    /// Interpretation rules expanded into more modules than the limit (of the
    /// whole drawing, or of one `module` of the string).
    #[error("{}", too_much_drawing(*.limit, .module.as_deref()))]
    TooMuchDrawing {
        limit: usize,
        module: Option<String>,
    },
    /// Decomposition rules expanded into each other `depth` times; `chain` holds
    /// the modules decomposed, outermost first, and `span` the last rule.
    #[error("decomposition rules expand {} more than {depth} levels deep", chain_text(.chain))]
    DecomposeTooDeep {
        chain: Vec<String>,
        depth: usize,
        span: crate::span::Span,
    },
    /// The run was stopped from outside before step `step` (`Limits::cancel`;
    /// `u32::MAX`: while drawing).
    #[error("the run was stopped {}: a newer request replaced it", stopped_at(*.step))]
    Cancelled { step: u32 },
    /// More steps were asked for than `MAX_STEPS`.
    #[error("{steps} derivation steps were asked for; the most is {limit}")]
    TooManySteps { steps: u64, limit: u32 },
}

/// The first interpretation rule of the module named `module`.
fn interpret_rule_span(prog: &Program, module: &str) -> Option<crate::span::Span> {
    prog.symbols
        .info
        .iter()
        .enumerate()
        .filter(|(_, i)| i.name.text() == module)
        .find_map(|(s, _)| prog.interpret[s].first().map(|r| r.span))
}

/// `A → B → A → …`: the first modules of a decomposition chain and its end.
fn chain_text(chain: &[String]) -> String {
    let shown: Vec<String> = if chain.len() > 8 {
        let mut v: Vec<String> = chain[..6].iter().map(|m| format!("`{m}`")).collect();
        v.push("…".to_string());
        v.extend(chain[chain.len() - 2..].iter().map(|m| format!("`{m}`")));
        v
    } else {
        chain.iter().map(|m| format!("`{m}`")).collect()
    };
    shown.join(" → ")
}

fn stopped_at(step: u32) -> String {
    match step {
        u32::MAX => "while drawing".to_string(),
        s => format!("before step {s}"),
    }
}

fn when(step: u32) -> String {
    match step {
        0 => "while evaluating the axiom".to_string(),
        u32::MAX => "while drawing (in an interpretation rule)".to_string(),
        s => format!("in derivation step {s}"),
    }
}

fn too_many_modules(step: u32, modules: Option<usize>, limit: usize) -> String {
    match modules {
        Some(n) => format!(
            "derivation step {step} would produce {n} modules, more than the limit of {limit}"
        ),
        None => {
            format!("derivation step {step} would produce more than {limit} modules, the limit")
        }
    }
}

fn too_much_drawing(limit: usize, module: Option<&str>) -> String {
    match module {
        Some(m) => format!("interpretation rules expand one `{m}` into more than {limit} modules"),
        None => {
            format!("interpretation rules would draw more than {limit} modules, the module limit")
        }
    }
}

fn too_much_memory(step: u32, bytes: Option<usize>, limit: usize) -> String {
    match bytes {
        Some(b) => format!(
            "derivation step {step} would need about {} MiB, more than the limit of {} MiB",
            b >> 20,
            limit >> 20
        ),
        None => format!(
            "derivation step {step} would need more than {} MiB, the limit",
            limit >> 20
        ),
    }
}

impl DeriveError {
    /// The failure as a diagnostic pointing into the program: at the
    /// expression that failed, or at the lsystem's name for a limit.
    pub fn diagnostic(&self, prog: &Program) -> Diagnostic {
        let msg = self.to_string();
        match self {
            DeriveError::Vm { error, .. } => {
                let code = match error.fault {
                    Fault::DivisionByZero => Code::DivisionByZero,
                    Fault::NotFinite => Code::NotFinite,
                };
                let help = match error.fault {
                    Fault::DivisionByZero => {
                        "guard the rule with a condition, e.g. `A(x) : x != 0 -> …`"
                    }
                    Fault::NotFinite => {
                        "check the operands: a square root or logarithm of a negative number, or a value that overflows"
                    }
                };
                Diagnostic::error(code, msg)
                    .primary(error.span, error.fault.label())
                    .help(help)
            }
            DeriveError::TooManyModules { .. } => Diagnostic::error(Code::TooManyModules, msg)
                .primary(prog.name_span, "this lsystem grows too fast")
                .help("derive fewer steps with -n, or raise the limit with --max-modules"),
            DeriveError::TooMuchMemory { .. } => Diagnostic::error(Code::TooMuchMemory, msg)
                .primary(prog.name_span, "this lsystem grows too fast")
                .help("derive fewer steps with -n, or raise the limit with --max-memory"),
            DeriveError::InterpretTooDeep { module, .. } => Diagnostic::error(Code::InterpretTooDeep, msg)
                .primary(
                    interpret_rule_span(prog, module).unwrap_or(prog.name_span),
                    "an `interpret` rule produces a module that is interpreted again, endlessly",
                )
                .help("interpretation rules must end in modules that draw; a rule like `interpret A -> B; interpret B -> A;` never does"),
            DeriveError::TooMuchDrawing { module, .. } => Diagnostic::error(Code::TooMuchDrawing, msg)
                .primary(prog.name_span, "its `interpret` rules expand modules into more and more modules")
                .help(if module.is_some() {
                    "an interpretation rule should draw a bounded figure (a leaf, a flower): end its recursion with a condition on a parameter that decreases"
                } else {
                    "derive fewer steps, or raise the limit with --max-modules"
                }),
            DeriveError::DecomposeTooDeep { span, .. } => {
                Diagnostic::error(Code::DecomposeTooDeep, msg)
                    .primary(*span, "this `decompose` rule keeps producing modules that decompose again")
                    .help("decomposition must end in modules that no `decompose` rule matches; end the recursion with a condition on a parameter that decreases")
            }
            DeriveError::Cancelled { .. } => Diagnostic::error(Code::Cancelled, msg)
                .primary(prog.name_span, "this lsystem was being derived"),
            DeriveError::TooManySteps { limit, .. } => Diagnostic::error(Code::TooManySteps, msg)
                .primary(prog.name_span, "this lsystem would be derived that often")
                .help(format!("ask for at most {limit} steps with -n")),
        }
    }
}

/// Appends a successor (or the axiom) with its parameters evaluated on `slots`.
#[inline]
fn emit(
    prog: &Program,
    succ: &[crate::compile::Emit],
    slots: &[f64],
    rng: &mut Random,
    stack: &mut Vec<f64>,
    syms: &mut Vec<Sym>,
    params: &mut Vec<f64>,
) -> Result<(), VmError> {
    for e in succ {
        syms.push(e.sym);
        for code in &e.args {
            params.push(prog.chunk.eval(*code, slots, rng, stack)?);
        }
    }
    Ok(())
}

/// Evaluates the axiom with the lsystem's parameters.
pub fn axiom(prog: &Program, args: &[f64], seed: u64) -> Result<ModString, DeriveError> {
    let mut out = ModString::default();
    let mut rng = Random::new(seed, 0, u64::MAX);
    let mut stack = Vec::new();
    emit(
        prog,
        &prog.axiom,
        args,
        &mut rng,
        &mut stack,
        &mut out.syms,
        &mut out.params,
    )
    .map_err(|error| DeriveError::Vm { step: 0, error })?;
    if prog.has_cut {
        out = apply_cut(prog, out);
    }
    Ok(out)
}

/// Runs `steps` derivation steps from `start`; `progress(step)` is called after each.
pub fn derive(
    prog: &Program,
    start: ModString,
    steps: u32,
    seed: u64,
    limits: Limits,
    progress: &(dyn Fn(u32, usize) + Sync),
) -> Result<ModString, DeriveError> {
    derive_with(prog, start, steps, seed, limits, progress, &mut |_, _| {
        Ok(())
    })
}

/// Like `derive`, with `after(string, step)` called on the start string (step 0)
/// and after each step, before the next: the turtle answers query modules there.
pub fn derive_with(
    prog: &Program,
    start: ModString,
    steps: u32,
    seed: u64,
    limits: Limits,
    progress: &(dyn Fn(u32, usize) + Sync),
    after: &mut dyn FnMut(&mut ModString, u32) -> Result<(), DeriveError>,
) -> Result<ModString, DeriveError> {
    if steps > MAX_STEPS {
        return Err(DeriveError::TooManySteps {
            steps: u64::from(steps),
            limit: MAX_STEPS,
        });
    }
    if let Some(table) = &prog.d0l
        && !prog.has_cut
        && !decompose::has_rules(prog)
    {
        d0l_forecast(table, &start, steps, limits)?;
    }
    let settles = !prog.draws_random();
    let mut s = start;
    after(&mut s, 0)?;
    for k in 1..=steps {
        let mut next = step(prog, &s, k, seed, limits)?;
        after(&mut next, k)?;
        // A program without random draws that rewrites a string into itself
        // does so at every later step: stop deriving, the string is final.
        let fixed = settles && next == s;
        s = next;
        progress(k, s.len());
        if fixed {
            progress(steps, s.len());
            break;
        }
    }
    Ok(s)
}

/// A D0L string's length is known before deriving it: the symbol counts of the
/// next step are a linear function of the current ones. An explosion is found
/// here, before any step allocates.
fn d0l_forecast(
    table: &[Vec<Sym>],
    start: &ModString,
    steps: u32,
    limits: Limits,
) -> Result<(), DeriveError> {
    let n = table.len();
    let mut counts = vec![0u128; n];
    for &x in &start.syms {
        counts[x as usize] += 1;
    }
    let mut next = vec![0u128; n];
    for step in 1..=steps {
        next.iter_mut().for_each(|c| *c = 0);
        for (s, succ) in table.iter().enumerate() {
            if counts[s] == 0 {
                continue;
            }
            for &t in succ {
                next[t as usize] = next[t as usize].saturating_add(counts[s]);
            }
        }
        std::mem::swap(&mut counts, &mut next);
        let total = counts.iter().fold(0u128, |a, &c| a.saturating_add(c));
        let total = usize::try_from(total).unwrap_or(usize::MAX);
        check_limits(step, total, 0, limits, true)?;
        // Once every count is 0 or fixed, later steps cannot grow: stop early.
        if counts == next {
            break;
        }
    }
    Ok(())
}

/// One parallel rewriting step (step numbers start at 1).
pub fn step(
    prog: &Program,
    s: &ModString,
    step: u32,
    seed: u64,
    limits: Limits,
) -> Result<ModString, DeriveError> {
    if limits.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return Err(DeriveError::Cancelled { step });
    }
    let out = match &prog.d0l {
        Some(table) => d0l_step(table, s, step, limits)?,
        None => parametric_step(
            prog,
            &Plan::new(prog),
            s,
            Place::default(),
            step,
            seed,
            limits,
        )?,
    };
    let out = if prog.has_cut {
        apply_cut(prog, out)
    } else {
        out
    };
    if decompose::has_rules(prog) {
        decompose::decompose(prog, out, step, seed, limits)
    } else {
        Ok(out)
    }
}

/// Whether `step_piece` serves the program: each module is rewritten on its
/// own (no context, no `cut`, no decomposition), so a string can be stepped
/// piece by piece, and a piece that holds no module with rules is copied
/// unchanged by a step.
pub fn piecewise(prog: &Program) -> bool {
    prog.d0l.is_none() && !prog.has_context && !prog.has_cut && !decompose::has_rules(prog)
}

/// Where a piece of a string is: the place of its first module in the whole
/// string (random draws are made by place), and how many modules and
/// parameters the rest of the string holds (counted against the limits).
#[derive(Clone, Copy, Debug, Default)]
pub struct Place {
    pub origin: usize,
    pub other_modules: usize,
    pub other_params: usize,
}

/// What `step` makes of the piece `s` of a string (see `Place`), for a
/// program `piecewise` serves: the pieces' results, in order, are `step`'s
/// result. An error here may name the piece's places, not the string's: step
/// the whole string for the message.
pub fn step_piece(
    prog: &Program,
    plan: &Plan,
    s: &ModString,
    at: Place,
    step_no: u32,
    seed: u64,
    limits: Limits,
) -> Result<ModString, DeriveError> {
    if limits.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return Err(DeriveError::Cancelled { step: step_no });
    }
    parametric_step(prog, plan, s, at, step_no, seed, limits)
}

/// What a chunk of modules holds and makes, by the plan's table.
fn count(table: &[Entry], chunk: &[Sym]) -> Counts {
    let mut n = Counts::default();
    for &x in chunk {
        let e = &table[x as usize];
        n.params_in += e.arity as usize;
        n.mods += e.mods as usize;
        n.params += e.params as usize;
        n.choose |= e.kind == Kind::Choose;
    }
    n
}

/// Checks a step's size against the limits. `exact`: the counts are the
/// step's whole output (then the message gives them); otherwise they are a
/// running total that depends on how threads interleave, and it does not.
fn check_limits(
    step: u32,
    modules: usize,
    params: usize,
    limits: Limits,
    exact: bool,
) -> Result<(), DeriveError> {
    if modules > limits.max_modules {
        return Err(DeriveError::TooManyModules {
            step,
            modules: exact.then_some(modules),
            limit: limits.max_modules,
        });
    }
    let bytes = modules
        .saturating_mul(std::mem::size_of::<Sym>())
        .saturating_add(params.saturating_mul(8));
    if bytes > limits.max_bytes {
        return Err(DeriveError::TooMuchMemory {
            step,
            bytes: exact.then_some(bytes),
            limit: limits.max_bytes,
        });
    }
    Ok(())
}

/// D0L: every symbol has one fixed successor. Count, check, then fill in place.
fn d0l_step(
    table: &[Vec<Sym>],
    s: &ModString,
    step: u32,
    limits: Limits,
) -> Result<ModString, DeriveError> {
    let lens: Vec<usize> = table.iter().map(Vec::len).collect();
    let counts: Vec<usize> = s
        .syms
        .par_chunks(CHUNK)
        .map(|c| c.iter().map(|&x| lens[x as usize]).sum())
        .collect();
    let total = counts
        .iter()
        .try_fold(0usize, |a, &c| a.checked_add(c))
        .unwrap_or(usize::MAX);
    check_limits(step, total, 0, limits, true)?;
    let mut out = vec![0 as Sym; total];
    let mut slices = Vec::with_capacity(counts.len());
    let mut rest: &mut [Sym] = &mut out;
    for &c in &counts {
        let (a, b) = rest.split_at_mut(c);
        slices.push(a);
        rest = b;
    }
    // Successors padded to a fixed width are copied as one fixed-size block (no
    // call to memcpy per module); the block may run past the module's share and
    // is overwritten by the next one, except at the end of a slice.
    let padded: Option<Vec<[Sym; PAD]>> = table
        .iter()
        .map(|succ| {
            let mut block = [0 as Sym; PAD];
            block.get_mut(..succ.len())?.copy_from_slice(succ);
            Some(block)
        })
        .collect();
    s.syms
        .par_chunks(CHUNK)
        .zip(slices.into_par_iter())
        .for_each(|(inp, outp)| {
            let mut k = 0;
            for &x in inp {
                let n = lens[x as usize];
                match &padded {
                    Some(blocks) if k + PAD <= outp.len() => {
                        outp[k..k + PAD].copy_from_slice(&blocks[x as usize]);
                    }
                    _ => outp[k..k + n].copy_from_slice(&table[x as usize]),
                }
                k += n;
            }
        });
    Ok(ModString {
        syms: out,
        params: Vec::new(),
    })
}

/// Where each chunk's parameters start, and (for context) every module's offset.
fn param_offsets(prog: &Program, s: &ModString, all: bool) -> (Vec<usize>, Vec<u32>) {
    let arity: Vec<usize> = prog.symbols.info.iter().map(|i| i.arity as usize).collect();
    let sums: Vec<usize> = s
        .syms
        .par_chunks(CHUNK)
        .map(|c| c.iter().map(|&x| arity[x as usize]).sum())
        .collect();
    let mut starts = Vec::with_capacity(sums.len());
    let mut acc = 0usize;
    for c in sums {
        starts.push(acc);
        acc += c;
    }
    let offsets = if all {
        let mut off = vec![0u32; s.len()];
        off.par_chunks_mut(CHUNK)
            .zip(s.syms.par_chunks(CHUNK))
            .zip(starts.par_iter())
            .for_each(|((o, c), &start)| {
                let mut p = start as u32;
                for (oi, &x) in o.iter_mut().zip(c) {
                    *oi = p;
                    p += arity[x as usize] as u32;
                }
            });
        off
    } else {
        Vec::new()
    };
    (starts, offsets)
}

/// The string being rewritten, with what context matching needs.
pub(crate) struct View<'a> {
    pub prog: &'a Program,
    pub s: &'a ModString,
    /// Parameter offset of every module (only for context-sensitive programs).
    pub offsets: Vec<u32>,
    /// Per symbol, the most modules and parameters one rewrite of it produces, so
    /// that output buffers are allocated once.
    pub growth: Vec<(usize, usize)>,
}

/// The most modules and parameters any rule of each symbol produces (the symbol
/// itself when it has no rule).
fn growth(prog: &Program) -> Vec<(usize, usize)> {
    prog.rules
        .iter()
        .enumerate()
        .map(|(s, rules)| {
            let own = (1, prog.symbols.arity(s as Sym));
            rules.iter().fold(own, |(m, p), r| {
                let rm = r.succ.len();
                let rp = r.succ.iter().map(|e| e.args.len()).sum();
                (m.max(rm), p.max(rp))
            })
        })
        .collect()
}

impl View<'_> {
    pub fn params_at(&self, i: usize) -> &[f64] {
        let start = self.offsets[i] as usize;
        let n = self.prog.symbols.arity(self.s.syms[i]);
        &self.s.params[start..start + n]
    }

    pub fn action(&self, i: usize) -> Action {
        self.prog.symbols.info[self.s.syms[i] as usize].action
    }
}

struct ChunkOut {
    syms: Vec<Sym>,
    params: Vec<f64>,
}

/// How a symbol rewrites, as far as is known before a step.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// No rule: the module is copied.
    Keep,
    /// One rule that always applies and binds only the predecessor's parameters.
    Fixed,
    /// Conditions, weights or context decide, module by module.
    Choose,
}

/// What the counting pass reads per symbol: its arity and, unless it must
/// choose, how many modules and parameters one of it becomes.
#[derive(Clone, Copy, Debug)]
struct Entry {
    arity: u32,
    mods: u32,
    params: u32,
    kind: Kind,
}

/// A rule's successor flattened: its symbols (padded to `PAD` when it fits, so
/// they are copied as one fixed-size block) and the code of its parameters.
struct Flat {
    syms: Vec<Sym>,
    block: Option<[Sym; PAD]>,
    args: Vec<crate::vm::Code>,
}

impl Flat {
    fn new(r: &CompiledRule) -> Flat {
        let syms: Vec<Sym> = r.succ.iter().map(|e| e.sym).collect();
        let block = (syms.len() <= PAD).then(|| {
            let mut b = [0 as Sym; PAD];
            b[..syms.len()].copy_from_slice(&syms);
            b
        });
        Flat {
            syms,
            block,
            args: r.succ.iter().flat_map(|e| e.args.iter().copied()).collect(),
        }
    }
}

/// The step's plan: an entry per symbol and the flattened rules (made once
/// for many pieces: `Plan::new`, `step_piece`).
pub struct Plan {
    table: Vec<Entry>,
    /// `flat[sym][k]`: rule k of the symbol.
    flat: Vec<Vec<Flat>>,
}

impl Plan {
    pub fn new(prog: &Program) -> Plan {
        let table = prog
            .rules
            .iter()
            .enumerate()
            .map(|(s, rules)| {
                let arity = prog.symbols.arity(s as Sym) as u32;
                match rules.as_slice() {
                    [] => Entry {
                        arity,
                        mods: 1,
                        params: arity,
                        kind: Kind::Keep,
                    },
                    [r] if r.cond.is_none()
                        && r.weight.is_none()
                        && r.left.is_empty()
                        && r.right.is_empty() =>
                    {
                        Entry {
                            arity,
                            mods: r.succ.len() as u32,
                            params: r.succ.iter().map(|e| e.args.len() as u32).sum(),
                            kind: Kind::Fixed,
                        }
                    }
                    _ => Entry {
                        arity,
                        mods: 0,
                        params: 0,
                        kind: Kind::Choose,
                    },
                }
            })
            .collect();
        let flat = prog
            .rules
            .iter()
            .map(|rules| rules.iter().map(Flat::new).collect())
            .collect();
        Plan { table, flat }
    }
}

/// A module's choice, recorded by the counting pass for the filling pass: the
/// rule (or `NO_RULE`) and how many numbers choosing drew.
#[derive(Clone, Copy, Debug)]
struct Choice {
    rule: u32,
    draws: u32,
}

const NO_RULE: u32 = u32::MAX;

/// One chunk's counts: parameters in; modules and parameters out.
#[derive(Clone, Copy, Debug, Default)]
struct Counts {
    params_in: usize,
    mods: usize,
    params: usize,
    choose: bool,
}

/// A parametric step, counted then filled in place: a first pass sums what
/// every module becomes (choosing a rule where conditions, weights or context
/// decide, and recording the choice); the limits are checked on the exact
/// totals; then every chunk writes its share of the output directly. On an
/// expression error the step is rewritten again in module order, so the error
/// reported is the first in the string on any thread count. `s` may be a
/// piece of a string at `at` (the whole string: `Place::default()`).
fn parametric_step(
    prog: &Program,
    plan: &Plan,
    s: &ModString,
    at: Place,
    step: u32,
    seed: u64,
    limits: Limits,
) -> Result<ModString, DeriveError> {
    let table = &plan.table;
    let from = at.origin;
    let syms = &s.syms[..];
    let mut counts: Vec<Counts> = syms.par_chunks(CHUNK).map(|c| count(table, c)).collect();
    let mut starts = Vec::with_capacity(counts.len());
    let mut acc = 0;
    for c in &counts {
        starts.push(acc);
        acc += c.params_in;
    }
    let offsets = if prog.has_context {
        param_offsets(prog, s, true).1
    } else {
        Vec::new()
    };
    let view = View {
        prog,
        s,
        offsets,
        growth: Vec::new(),
    };
    // Choices, for the chunks that have modules to choose for.
    let choices: Vec<Result<Vec<Choice>, ()>> = syms
        .par_chunks(CHUNK)
        .zip(counts.par_iter_mut())
        .enumerate()
        .map(|(ci, (chunk, n))| {
            if !n.choose {
                return Ok(Vec::new());
            }
            choose_chunk(
                &view,
                plan,
                from + ci * CHUNK,
                chunk,
                starts[ci],
                step,
                seed,
                n,
            )
        })
        .collect();
    if choices.iter().any(Result::is_err) {
        return Err(first_error(&view, step, seed));
    }
    let choices: Vec<Vec<Choice>> = choices.into_iter().map(|c| c.unwrap_or_default()).collect();
    let total = counts
        .iter()
        .try_fold(0usize, |a, c| a.checked_add(c.mods))
        .unwrap_or(usize::MAX);
    let total_params = counts
        .iter()
        .try_fold(0usize, |a, c| a.checked_add(c.params))
        .unwrap_or(usize::MAX);
    // The message does not give the count, as it did not when the limit was
    // checked on running totals: it stays the same across versions.
    check_limits(
        step,
        total.saturating_add(at.other_modules),
        total_params.saturating_add(at.other_params),
        limits,
        false,
    )?;
    let mut out_syms = vec![0 as Sym; total];
    let mut params = vec![0.0; total_params];
    let mut parts = Vec::with_capacity(counts.len());
    let (mut rs, mut rp): (&mut [Sym], &mut [f64]) = (&mut out_syms, &mut params);
    for c in &counts {
        let (a, b) = rs.split_at_mut(c.mods);
        rs = b;
        let (pa, pb) = rp.split_at_mut(c.params);
        rp = pb;
        parts.push((a, pa));
    }
    let failed = syms
        .par_chunks(CHUNK)
        .zip(parts.into_par_iter())
        .zip(choices.par_iter())
        .enumerate()
        .map(|(ci, ((chunk, (out_syms, out_params)), choices))| {
            fill_chunk(
                &view,
                plan,
                from + ci * CHUNK,
                chunk,
                starts[ci],
                choices,
                step,
                seed,
                out_syms,
                out_params,
            )
        })
        .any(|ok| !ok);
    if failed {
        return Err(first_error(&view, step, seed));
    }
    Ok(ModString {
        syms: out_syms,
        params,
    })
}

/// Chooses the rule of every module of a chunk whose symbol must choose, and
/// adds what the choices produce to `n`. `Err` on an expression error.
#[allow(clippy::too_many_arguments)]
fn choose_chunk(
    view: &View,
    plan: &Plan,
    base: usize,
    chunk: &[Sym],
    param_start: usize,
    step: u32,
    seed: u64,
    n: &mut Counts,
) -> Result<Vec<Choice>, ()> {
    let prog = view.prog;
    let mut out = Vec::new();
    let mut p = param_start;
    let mut slots: Vec<f64> = Vec::new();
    let mut stack: Vec<f64> = Vec::new();
    let mut weights: Vec<(usize, f64)> = Vec::new();
    for (j, &sym) in chunk.iter().enumerate() {
        let e = &plan.table[sym as usize];
        let arity = e.arity as usize;
        if e.kind != Kind::Choose {
            p += arity;
            continue;
        }
        let params = &view.s.params[p..p + arity];
        p += arity;
        let i = base + j;
        let mut rng = Random::new(seed, step, i as u64);
        let rules = &prog.rules[sym as usize];
        let chosen = choose(
            view,
            rules,
            i,
            params,
            &mut slots,
            &mut stack,
            &mut rng,
            &mut weights,
        )
        .map_err(|_| ())?;
        match chosen {
            Some(k) => {
                let f = &plan.flat[sym as usize][k];
                n.mods += f.syms.len();
                n.params += f.args.len();
                out.push(Choice {
                    rule: k as u32,
                    draws: rng.draw,
                });
            }
            None => {
                n.mods += 1;
                n.params += arity;
                out.push(Choice {
                    rule: NO_RULE,
                    draws: 0,
                });
            }
        }
    }
    Ok(out)
}

/// Writes a chunk's output into its slices; false on an expression error.
#[allow(clippy::too_many_arguments)]
fn fill_chunk(
    view: &View,
    plan: &Plan,
    base: usize,
    chunk: &[Sym],
    param_start: usize,
    choices: &[Choice],
    step: u32,
    seed: u64,
    out_syms: &mut [Sym],
    out_params: &mut [f64],
) -> bool {
    let prog = view.prog;
    let code = &prog.chunk;
    let in_params = &view.s.params;
    let mut p = param_start;
    let (mut k, mut q) = (0usize, 0usize);
    let mut next_choice = choices.iter();
    let mut slots: Vec<f64> = Vec::new();
    let mut stack: Vec<f64> = Vec::new();
    for (j, &sym) in chunk.iter().enumerate() {
        let e = &plan.table[sym as usize];
        let arity = e.arity as usize;
        let params = &in_params[p..p + arity];
        p += arity;
        let (flat, args, draws) = match e.kind {
            Kind::Keep => {
                keep(sym, params, out_syms, out_params, &mut k, &mut q);
                continue;
            }
            Kind::Fixed => (&plan.flat[sym as usize][0], params, 0),
            Kind::Choose => {
                let Some(c) = next_choice.next() else {
                    return false;
                };
                if c.rule == NO_RULE {
                    keep(sym, params, out_syms, out_params, &mut k, &mut q);
                    continue;
                }
                let r = &prog.rules[sym as usize][c.rule as usize];
                // The slots as choosing bound them (the match succeeded then).
                bind(view, r, base + j, params, &mut slots);
                (
                    &plan.flat[sym as usize][c.rule as usize],
                    &slots[..],
                    c.draws,
                )
            }
        };
        let n = flat.syms.len();
        match &flat.block {
            Some(b) if k + PAD <= out_syms.len() => out_syms[k..k + PAD].copy_from_slice(b),
            _ => out_syms[k..k + n].copy_from_slice(&flat.syms),
        }
        k += n;
        let mut rng = Random::new(seed, step, (base + j) as u64);
        rng.draw = draws;
        for (slot, a) in out_params[q..q + flat.args.len()]
            .iter_mut()
            .zip(&flat.args)
        {
            match code.eval(*a, args, &mut rng, &mut stack) {
                Ok(v) => *slot = v,
                Err(_) => return false,
            }
        }
        q += flat.args.len();
    }
    true
}

/// Copies a module that no rule rewrites.
#[inline(always)]
fn keep(
    sym: Sym,
    params: &[f64],
    out_syms: &mut [Sym],
    out_params: &mut [f64],
    k: &mut usize,
    q: &mut usize,
) {
    out_syms[*k] = sym;
    *k += 1;
    match params {
        [] => {}
        [a] => out_params[*q] = *a,
        _ => out_params[*q..*q + params.len()].copy_from_slice(params),
    }
    *q += params.len();
}

/// The error of a step that failed: the step rewritten chunk by chunk in
/// module order, up to the first expression that fails.
fn first_error(view: &View, step: u32, seed: u64) -> DeriveError {
    let prog = view.prog;
    let (starts, _) = param_offsets(prog, view.s, false);
    let view = View {
        prog,
        s: view.s,
        offsets: if prog.has_context {
            param_offsets(prog, view.s, true).1
        } else {
            Vec::new()
        },
        growth: growth(prog),
    };
    let unlimited = Limits {
        max_modules: usize::MAX,
        max_bytes: usize::MAX,
        cancel: None,
    };
    let produced = AtomicUsize::new(0);
    for (ci, chunk) in view.s.syms.chunks(CHUNK).enumerate() {
        if let Err(e) = rewrite_chunk(
            &view,
            ci * CHUNK,
            chunk,
            starts[ci],
            step,
            seed,
            unlimited,
            &produced,
        ) {
            return e;
        }
    }
    unreachable!("a step that failed fails again when rewritten in order")
}

#[allow(clippy::too_many_arguments)]
fn rewrite_chunk(
    view: &View,
    base: usize,
    chunk: &[Sym],
    param_start: usize,
    step: u32,
    seed: u64,
    limits: Limits,
    produced: &AtomicUsize,
) -> Result<ChunkOut, DeriveError> {
    let prog = view.prog;
    let s = view.s;
    let mut out = ChunkOut {
        syms: Vec::with_capacity(chunk.iter().map(|&x| view.growth[x as usize].0).sum()),
        params: Vec::with_capacity(chunk.iter().map(|&x| view.growth[x as usize].1).sum()),
    };
    let mut p = param_start;
    let mut slots: Vec<f64> = Vec::new();
    let mut stack: Vec<f64> = Vec::new();
    let mut weights: Vec<(usize, f64)> = Vec::new();
    let mut reported = 0usize;
    for (j, &sym) in chunk.iter().enumerate() {
        let i = base + j;
        let arity = prog.symbols.arity(sym);
        let params = &s.params[p..p + arity];
        p += arity;
        let rules = &prog.rules[sym as usize];
        if rules.is_empty() {
            out.syms.push(sym);
            out.params.extend_from_slice(params);
            continue;
        }
        let mut rng = Random::new(seed, step, i as u64);
        let vm = |error| DeriveError::Vm { step, error };
        // The common case: one rule that always applies and binds only the
        // predecessor's parameters, which are then the slots themselves.
        if let [r] = rules.as_slice()
            && r.cond.is_none()
            && r.weight.is_none()
            && r.left.is_empty()
            && r.right.is_empty()
        {
            emit(
                prog,
                &r.succ,
                params,
                &mut rng,
                &mut stack,
                &mut out.syms,
                &mut out.params,
            )
            .map_err(vm)?;
        } else {
            let chosen = choose(
                view,
                rules,
                i,
                params,
                &mut slots,
                &mut stack,
                &mut rng,
                &mut weights,
            )
            .map_err(vm)?;
            match chosen.map(|k| &rules[k]) {
                Some(r) => {
                    emit(
                        prog,
                        &r.succ,
                        &slots,
                        &mut rng,
                        &mut stack,
                        &mut out.syms,
                        &mut out.params,
                    )
                    .map_err(vm)?;
                }
                None => {
                    out.syms.push(sym);
                    out.params.extend_from_slice(params);
                }
            }
        }
        // Share progress so a runaway step stops early, not after filling memory.
        if j % 1024 == 1023 {
            let now = out.syms.len();
            let total = produced.fetch_add(now - reported, Ordering::Relaxed) + now - reported;
            reported = now;
            check_limits(step, total, out.params.len(), limits, false)?;
        }
    }
    produced.fetch_add(out.syms.len() - reported, Ordering::Relaxed);
    Ok(out)
}

/// The index of the rule that rewrites module `i`, with its parameters bound
/// in `slots`.
#[allow(clippy::too_many_arguments)]
fn choose(
    view: &View,
    rules: &[CompiledRule],
    i: usize,
    params: &[f64],
    slots: &mut Vec<f64>,
    stack: &mut Vec<f64>,
    rng: &mut Random,
    weights: &mut Vec<(usize, f64)>,
) -> Result<Option<usize>, VmError> {
    let chunk = &view.prog.chunk;
    let mut k = 0;
    while k < rules.len() {
        let group = rules[k].group;
        let end = k + rules[k..].iter().take_while(|r| r.group == group).count();
        if rules[k].weight.is_none() {
            let r = &rules[k];
            if bind(view, r, i, params, slots) && holds(chunk, r, slots, stack, rng)? {
                return Ok(Some(k));
            }
        } else {
            weights.clear();
            for (idx, r) in rules[k..end].iter().enumerate() {
                if bind(view, r, i, params, slots) && holds(chunk, r, slots, stack, rng)? {
                    let w = match r.weight {
                        Some(code) => chunk.eval(code, slots, rng, stack)?,
                        None => 1.0,
                    };
                    if w > 0.0 {
                        weights.push((k + idx, w));
                    }
                }
            }
            if let Some(pick) = rng.pick(weights) {
                let r = &rules[pick];
                // Rebind: the slots hold the last candidate's context.
                bind(view, r, i, params, slots);
                return Ok(Some(pick));
            }
        }
        k = end;
    }
    Ok(None)
}

/// Binds the predecessor's parameters and matches the context; false if it fails.
fn bind(view: &View, r: &CompiledRule, i: usize, params: &[f64], slots: &mut Vec<f64>) -> bool {
    slots.clear();
    slots.resize(r.slots as usize, 0.0);
    slots[..params.len()].copy_from_slice(params);
    if !r.left.is_empty() && !context::left(view, &r.left, i, slots) {
        return false;
    }
    if !r.right.is_empty() && !context::right(view, &r.right, i, slots) {
        return false;
    }
    true
}

fn holds(
    chunk: &crate::vm::Chunk,
    r: &CompiledRule,
    slots: &[f64],
    stack: &mut Vec<f64>,
    rng: &mut Random,
) -> Result<bool, VmError> {
    match r.cond {
        None => Ok(true),
        Some(code) => Ok(chunk.eval(code, slots, rng, stack)? != 0.0),
    }
}

/// Erases, after each `cut`, the rest of its branch (up to the `]` that closes it).
fn apply_cut(prog: &Program, s: ModString) -> ModString {
    let info = &prog.symbols.info;
    if !s
        .syms
        .iter()
        .any(|&x| info[x as usize].action == Action::Cut)
    {
        return s;
    }
    let mut out = ModString {
        syms: Vec::with_capacity(s.len()),
        params: Vec::with_capacity(s.params.len()),
    };
    let mut p = 0;
    let mut skip_depth: Option<usize> = None;
    for &x in &s.syms {
        let a = info[x as usize].arity as usize;
        let params = &s.params[p..p + a];
        p += a;
        let action = info[x as usize].action;
        if let Some(d) = skip_depth.as_mut() {
            match action {
                Action::Push => *d += 1,
                Action::Pop if *d == 0 => {
                    skip_depth = None;
                    out.syms.push(x);
                    out.params.extend_from_slice(params);
                }
                Action::Pop => *d -= 1,
                _ => {}
            }
            continue;
        }
        if action == Action::Cut {
            skip_depth = Some(0);
            continue;
        }
        out.syms.push(x);
        out.params.extend_from_slice(params);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program(text: &str) -> Program {
        let fe = crate::frontend::run(text, vec![], &[]);
        assert!(!fe.has_errors(), "{:?}", fe.diagnostics);
        let checked = fe.checked.as_ref().expect("checked");
        crate::compile::compile(&fe.file, checked, None).expect("compiles")
    }

    /// The definition a step must agree with: every module rewritten in
    /// order, one chunk for the whole string.
    fn reference_step(prog: &Program, s: &ModString, step: u32, seed: u64) -> ModString {
        let (_, offsets) = param_offsets(prog, s, true);
        let view = View {
            prog,
            s,
            offsets,
            growth: growth(prog),
        };
        let unlimited = Limits {
            max_modules: usize::MAX,
            max_bytes: usize::MAX,
            cancel: None,
        };
        let out = rewrite_chunk(
            &view,
            0,
            &s.syms,
            0,
            step,
            seed,
            unlimited,
            &AtomicUsize::new(0),
        )
        .expect("rewrites");
        ModString {
            syms: out.syms,
            params: out.params,
        }
    }

    /// Conditions (one that fails and leaves the module as it is), weights
    /// with random draws before and after the choice, context with an ignore
    /// list, fixed rules and modules without rules, over strings of several
    /// chunks: the counted-then-filled step equals the in-order rewrite on 1
    /// and 2 threads.
    #[test]
    fn counted_steps_equal_the_in_order_rewrite() {
        let prog = program(
            "lsystem Mixed {
                ignore + -;
                axiom A(1) B(2) + A(3) C(0);
                A(x) : x < 1000 -> A(x + 1) [ + B(x * 0.5) ] A(x + uniform(1, 2)) - C(x);
                A(x) : x > 100 -> F(x);
                B(y) < B(z) : z > 1 -> B(y + z);
                B(z) ->(0.5) B(z + rand()) F(z);
                B(z) ->(0.5) C(z / 2);
                C(c) : c < 3 -> C(c + 1) F(2 * c);
            }",
        );
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let seed = 11;
        let mut s = axiom(&prog, &[], seed).unwrap();
        let mut k = 0;
        while s.len() < 4 * CHUNK {
            k += 1;
            assert!(k < 40, "the test string stopped growing");
            let want = reference_step(&prog, &s, k, seed);
            let a = one
                .install(|| step(&prog, &s, k, seed, Limits::default()))
                .unwrap();
            let b = two
                .install(|| step(&prog, &s, k, seed, Limits::default()))
                .unwrap();
            assert_eq!(a, want, "step {k}, one thread");
            assert_eq!(b, want, "step {k}, two threads");
            s = a;
        }
    }

    /// An expression error in a late chunk and another in an early chunk:
    /// the early one is reported, on any thread count.
    #[test]
    fn the_first_failing_module_is_reported() {
        let prog = program(
            "lsystem Fails {
                axiom A(0) B(3) C(4);
                A(x) -> A(x + 1);
                B(x) -> B(1 / (x - 3));
                C(x) -> C(1 / (x - 4));
            }",
        );
        let start = axiom(&prog, &[], 0).unwrap();
        let (a, b, c) = (start.syms[0], start.syms[1], start.syms[2]);
        let alone = |sym: Sym, x: f64| ModString {
            syms: vec![sym],
            params: vec![x],
        };
        let err_b = step(&prog, &alone(b, 3.0), 1, 0, Limits::default()).unwrap_err();
        let err_c = step(&prog, &alone(c, 4.0), 1, 0, Limits::default()).unwrap_err();
        assert_ne!(err_b, err_c, "the two errors differ");
        let n = 3 * CHUNK;
        let mut s = ModString::default();
        for i in 0..n {
            let (sym, x) = match i {
                5 => (c, 4.0),
                _ if i == n - 5 => (b, 3.0),
                _ => (a, 0.0),
            };
            s.syms.push(sym);
            s.params.push(x);
        }
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let err = pool
                .install(|| step(&prog, &s, 1, 0, Limits::default()))
                .unwrap_err();
            assert_eq!(err, err_c, "{threads} threads");
        }
    }
}
