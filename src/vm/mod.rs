//! The expression VM: a small stack machine over `f64`, with booleans as 0 and 1.
//!
//! Owns: the instruction set (`Op`), code chunks with their debug table (which
//! source span each instruction came from), evaluation, and the disassembler.
//! Must not know about modules or rules: the compiler hands it parameter slots.

pub mod expr;

pub use expr::{ConstLookup, ExprCompiler, ExprError};

use crate::span::Span;
use std::fmt::Write;

/// One instruction. Each documents its stack effect as `[before] -> [after]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// `[] -> [v]`: push a constant.
    Const(f64),
    /// `[] -> [p]`: push parameter slot `n` of the current match.
    Load(u16),
    /// `[a] -> [-a]`
    Neg,
    /// `[a] -> [a == 0]`: logical not.
    Not,
    /// `[a, b] -> [a + b]`
    Add,
    /// `[a, b] -> [a - b]`
    Sub,
    /// `[a, b] -> [a * b]`
    Mul,
    /// `[a, b] -> [a / b]`; division by zero is a runtime error.
    Div,
    /// `[a, b] -> [a % b]` (sign of `a`); modulo by zero is a runtime error.
    Rem,
    /// `[a, b] -> [a ^ b]`
    Pow,
    /// `[a, b] -> [a == b]`
    Eq,
    /// `[a, b] -> [a != b]`
    Ne,
    /// `[a, b] -> [a < b]`
    Lt,
    /// `[a, b] -> [a <= b]`
    Le,
    /// `[a, b] -> [a > b]`
    Gt,
    /// `[a, b] -> [a >= b]`
    Ge,
    /// `[args…] -> [f(args…)]`: a deterministic built-in (index into `builtins::BUILTINS`).
    Call(u8),
    /// `[] -> [u]`: uniform in [0, 1) from the run's generator.
    Rand,
    /// `[a, b] -> [u]`: uniform in [a, b).
    Uniform,
    /// `[m, s] -> [x]`: Gaussian with mean m and deviation s.
    Normal,
    /// `[c] -> [c]`: if c is 0 jump to the instruction index, else pop c.
    /// Used for `&&`: the left value stays as the result when it is false.
    AndJump(u32),
    /// `[c] -> [c]`: if c is not 0 jump, else pop c. Used for `||`.
    OrJump(u32),
    /// `[a] -> [a != 0]`: turns a number into 0 or 1 (the right side of `&&`/`||`).
    Truth,
}

/// What a runtime error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Fault {
    #[error("division by zero")]
    DivisionByZero,
    /// The result is NaN or infinite.
    #[error("an expression is not a finite number")]
    NotFinite,
}

impl Fault {
    /// The label under the expression that failed.
    pub fn label(self) -> &'static str {
        match self {
            Fault::DivisionByZero => "this divides by zero",
            Fault::NotFinite => "this gives infinity or NaN",
        }
    }
}

/// A runtime error with the source span of the instruction that caused it.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{fault}")]
pub struct VmError {
    pub fault: Fault,
    pub span: Span,
}

/// Instructions of many expressions, each a range, with a span per instruction.
#[derive(Clone, Debug, Default)]
pub struct Chunk {
    pub code: Vec<Op>,
    pub spans: Vec<Span>,
}

/// Where one compiled expression lives in a chunk, and its shape when it is one
/// of the few shapes most successor parameters have (`x`, `2`, `l * 0.7`), which
/// `eval` computes without running the loop.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Code {
    pub start: u32,
    pub end: u32,
    pub fast: Fast,
}

/// A shortcut for a common expression shape; `None` runs the instructions.
/// Shapes are recognised after constant folding, so `l * r2` with a constant
/// `r2` is `LoadOp`, and `x > 3` a comparison the same way.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Fast {
    #[default]
    None,
    Const(f64),
    Load(u16),
    /// `$n op c`: op is arithmetic (+ - * /, and / only by a constant that is
    /// not 0) or a comparison; c a constant.
    LoadOp(u16, Op, f64),
    /// `c op $n`, with the same ops (/ only when it cannot fail: never here).
    ConstOp(f64, Op, u16),
    /// `$a op $b`, op one of + - * or a comparison.
    LoadLoad(u16, Op, u16),
}

/// Whether `op` is one of the binary ops the shortcuts compute (none of them
/// can fail except by giving a value that is not finite).
fn plain_binary(op: Op) -> bool {
    matches!(
        op,
        Op::Add | Op::Sub | Op::Mul | Op::Eq | Op::Ne | Op::Lt | Op::Le | Op::Gt | Op::Ge
    )
}

/// `a op b` for the ops of `plain_binary` and `/`; comparisons give 0 or 1.
#[inline(always)]
fn apply(op: Op, a: f64, b: f64) -> f64 {
    match op {
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Mul => a * b,
        Op::Div => a / b,
        Op::Eq => f64::from(a == b),
        Op::Ne => f64::from(a != b),
        Op::Lt => f64::from(a < b),
        Op::Le => f64::from(a <= b),
        Op::Gt => f64::from(a > b),
        Op::Ge => f64::from(a >= b),
        _ => unreachable!("not a shortcut op"),
    }
}

impl Code {
    /// The code of instructions `start..end` of `chunk`, with its shortcut.
    pub fn new(chunk: &Chunk, start: u32, end: u32) -> Code {
        let fast = match chunk.code[start as usize..end as usize] {
            [Op::Const(v)] => Fast::Const(v),
            [Op::Load(n)] => Fast::Load(n),
            [Op::Load(n), Op::Const(c), op] if plain_binary(op) => Fast::LoadOp(n, op, c),
            // Division by a constant: the constant is not 0 (else it fails at
            // run time, with its span: the loop handles that).
            [Op::Load(n), Op::Const(c), Op::Div] if c != 0.0 => Fast::LoadOp(n, Op::Div, c),
            [Op::Const(c), Op::Load(n), op] if plain_binary(op) => Fast::ConstOp(c, op, n),
            [Op::Load(a), Op::Load(b), op] if plain_binary(op) => Fast::LoadLoad(a, op, b),
            _ => Fast::None,
        };
        Code { start, end, fast }
    }

    /// A constant expression is a single `Const`.
    pub fn constant(self, chunk: &Chunk) -> Option<f64> {
        match &chunk.code[self.start as usize..self.end as usize] {
            [Op::Const(v)] => Some(*v),
            _ => None,
        }
    }
}

/// The generator behind `rand`, `uniform` and `normal`: a pure function of
/// (seed, step, position, draw), so results do not depend on thread count.
#[derive(Clone, Copy, Debug)]
pub struct Random {
    pub seed: u64,
    pub step: u32,
    pub position: u64,
    pub draw: u32,
}

/// SplitMix64's finaliser: a good 64-bit mix.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Random {
    pub fn new(seed: u64, step: u32, position: u64) -> Random {
        Random {
            seed,
            step,
            position,
            draw: 0,
        }
    }

    /// The next uniform number in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        let h = mix(mix(mix(self.seed ^ 0x5eed) ^ u64::from(self.step)) ^ self.position)
            ^ u64::from(self.draw).wrapping_mul(0xd6e8_feb8_6659_fd93);
        self.draw += 1;
        (mix(h) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// One of weighted candidates `(index, weight > 0)`, with probability in
    /// proportion to its weight (one draw); `None` when the weights sum to 0.
    pub fn pick(&mut self, cands: &[(usize, f64)]) -> Option<usize> {
        let sum: f64 = cands.iter().map(|c| c.1).sum();
        if sum <= 0.0 {
            return None;
        }
        let mut x = self.uniform() * sum;
        for &(idx, w) in cands {
            if x < w {
                return Some(idx);
            }
            x -= w;
        }
        cands.last().map(|c| c.0)
    }
}

impl Chunk {
    /// Appends an instruction with its span; returns its index.
    pub fn push(&mut self, op: Op, span: Span) -> u32 {
        self.code.push(op);
        self.spans.push(span);
        (self.code.len() - 1) as u32
    }

    pub fn len(&self) -> u32 {
        self.code.len() as u32
    }

    pub fn is_empty(&self) -> bool {
        self.code.is_empty()
    }

    /// Evaluates one expression. `stack` is scratch space reused between calls.
    /// The common shapes are computed here, inline; others run the loop.
    #[inline(always)]
    pub fn eval(
        &self,
        code: Code,
        params: &[f64],
        rng: &mut Random,
        stack: &mut Vec<f64>,
    ) -> Result<f64, VmError> {
        let load = |n: u16| params.get(n as usize).copied().unwrap_or(0.0);
        let v = match code.fast {
            Fast::None => return self.run(code, params, rng, stack),
            Fast::Const(v) => return Ok(v),
            Fast::Load(n) => return Ok(load(n)),
            Fast::LoadOp(n, op, c) => apply(op, load(n), c),
            Fast::ConstOp(c, op, n) => apply(op, c, load(n)),
            Fast::LoadLoad(a, op, b) => apply(op, load(a), load(b)),
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(VmError {
                fault: Fault::NotFinite,
                span: self.spans[code.end as usize - 1],
            })
        }
    }

    /// Runs the instructions of one expression.
    #[inline(never)]
    fn run(
        &self,
        code: Code,
        params: &[f64],
        rng: &mut Random,
        stack: &mut Vec<f64>,
    ) -> Result<f64, VmError> {
        stack.clear();
        let mut pc = code.start as usize;
        let end = code.end as usize;
        while pc < end {
            let op = self.code[pc];
            let fault = |fault| VmError {
                fault,
                span: self.spans[pc],
            };
            match op {
                Op::Const(v) => stack.push(v),
                Op::Load(n) => stack.push(params.get(n as usize).copied().unwrap_or(0.0)),
                Op::Neg => {
                    let a = pop(stack);
                    stack.push(-a);
                }
                Op::Not => {
                    let a = pop(stack);
                    stack.push(f64::from(a == 0.0));
                }
                Op::Truth => {
                    let a = pop(stack);
                    stack.push(f64::from(a != 0.0));
                }
                Op::AndJump(to) => {
                    if top(stack) == 0.0 {
                        pc = to as usize;
                        continue;
                    }
                    stack.pop();
                }
                Op::OrJump(to) => {
                    if top(stack) != 0.0 {
                        pc = to as usize;
                        continue;
                    }
                    stack.pop();
                }
                Op::Rand => stack.push(rng.uniform()),
                Op::Uniform => {
                    let b = pop(stack);
                    let a = pop(stack);
                    stack.push(a + (b - a) * rng.uniform());
                }
                Op::Normal => {
                    let s = pop(stack);
                    let m = pop(stack);
                    // Box–Muller from two uniforms; u1 in (0, 1] keeps the log finite.
                    let u1 = 1.0 - rng.uniform();
                    let u2 = rng.uniform();
                    let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                    stack.push(m + s * z);
                }
                Op::Call(f) => {
                    let b = &crate::builtins::BUILTINS[f as usize];
                    let at = stack.len().saturating_sub(b.arity);
                    let v = (b.eval)(&stack[at..]);
                    stack.truncate(at);
                    if !v.is_finite() {
                        return Err(fault(Fault::NotFinite));
                    }
                    stack.push(v);
                }
                _ => {
                    let b = pop(stack);
                    let a = pop(stack);
                    let v = match op {
                        Op::Add => a + b,
                        Op::Sub => a - b,
                        Op::Mul => a * b,
                        Op::Div | Op::Rem if b == 0.0 => return Err(fault(Fault::DivisionByZero)),
                        Op::Div => a / b,
                        Op::Rem => a % b,
                        Op::Pow => a.powf(b),
                        Op::Eq => f64::from(a == b),
                        Op::Ne => f64::from(a != b),
                        Op::Lt => f64::from(a < b),
                        Op::Le => f64::from(a <= b),
                        Op::Gt => f64::from(a > b),
                        Op::Ge => f64::from(a >= b),
                        _ => unreachable!("unary and control ops are handled above"),
                    };
                    if !v.is_finite() {
                        return Err(fault(Fault::NotFinite));
                    }
                    stack.push(v);
                }
            }
            pc += 1;
        }
        Ok(stack.pop().unwrap_or(0.0))
    }

    /// A readable listing of one expression: index, instruction, source span.
    pub fn disassemble(&self, code: Code, out: &mut String) {
        for pc in code.start..code.end {
            let op = self.code[pc as usize];
            let span = self.spans[pc as usize];
            let text = match op {
                Op::Const(v) => format!("const {v}"),
                Op::Load(n) => format!("load ${n}"),
                Op::Call(f) => format!("call {}", crate::builtins::BUILTINS[f as usize].name),
                Op::AndJump(t) => format!("and-jump {t}"),
                Op::OrJump(t) => format!("or-jump {t}"),
                other => format!("{other:?}").to_lowercase(),
            };
            let _ = writeln!(out, "    {pc:>4}  {text:<18} @{}..{}", span.start, span.end);
        }
    }
}

fn pop(stack: &mut Vec<f64>) -> f64 {
    stack.pop().unwrap_or(0.0)
}

fn top(stack: &[f64]) -> f64 {
    stack.last().copied().unwrap_or(0.0)
}
