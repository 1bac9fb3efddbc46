//! Expressions to bytecode, with constant folding; and the value of an
//! expression that has no parameters.
//!
//! Owns: the one way an expression is evaluated. Rule bodies are compiled here
//! and run by the VM; the checker asks `evaluate` for the value of every
//! constant and every setting, so a check-time value and a run-time value can
//! never disagree. Names are resolved when compiled (a parameter slot, or a
//! constant's value); a name or function that does not exist is an error, never
//! a silent 0. Must not know about modules, rules or the checker's types.

use super::{Chunk, Code, Fault, Op, Random, VmError};
use crate::ast::{BinOp, Expr, ExprKind, UnOp};
use crate::builtins;
use crate::diagnostic::{Code as DiagCode, Diagnostic};
use crate::span::Span;
use std::collections::HashMap;

/// What the compiler knows of a constant: its value and whether it was drawn
/// from the run's generator (then it is not known before derivation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Known {
    pub value: f64,
    pub random: bool,
}

/// The constants in scope, by name.
pub type ConstLookup<'a> = &'a dyn Fn(&str) -> Option<Known>;

/// Why an expression could not be compiled or evaluated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExprError {
    #[error("unknown name `{name}`")]
    UnknownName { name: String, span: Span },
    #[error("unknown function `{name}`")]
    UnknownFunction { name: String, span: Span },
    /// The parser's placeholder for an expression it could not read.
    #[error("an expression that could not be read")]
    Malformed { span: Span },
    #[error("{0}")]
    Vm(VmError),
}

impl ExprError {
    /// The error as a diagnostic. After a successful check only a failed
    /// evaluation can happen; the others are the checker's E0302, E0303 and
    /// the parser's E0201.
    pub fn diagnostic(&self) -> Diagnostic {
        match self {
            ExprError::UnknownName { span, .. } => {
                Diagnostic::error(DiagCode::UnknownName, self.to_string())
                    .primary(*span, "not a parameter or constant")
            }
            ExprError::UnknownFunction { span, .. } => {
                Diagnostic::error(DiagCode::UnknownFunction, self.to_string())
                    .primary(*span, "no built-in function has this name")
            }
            ExprError::Malformed { span } => {
                Diagnostic::error(DiagCode::UnexpectedToken, self.to_string())
                    .primary(*span, "the parser could not read this")
            }
            ExprError::Vm(e) => Diagnostic::error(
                match e.fault {
                    Fault::DivisionByZero => DiagCode::DivisionByZero,
                    Fault::NotFinite => DiagCode::NotFinite,
                },
                self.to_string(),
            )
            .primary(e.span, e.fault.label()),
        }
    }
}

/// The value of a parameterless expression, and whether it drew random numbers
/// (directly, or through a random constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluated {
    pub value: f64,
    pub random: bool,
}

/// Evaluates an expression that has no parameters: compiled against `consts`
/// and run once by the VM, drawing from `rng`.
pub fn evaluate(e: &Expr, consts: ConstLookup, rng: &mut Random) -> Result<Evaluated, ExprError> {
    let mut chunk = Chunk::default();
    let env = HashMap::new();
    let mut c = ExprCompiler::new(&mut chunk, consts, &env);
    let code = c.compile(e)?;
    let random = c.random;
    let value = chunk
        .eval(code, &[], rng, &mut Vec::new())
        .map_err(ExprError::Vm)?;
    Ok(Evaluated { value, random })
}

/// Compiles expressions of one scope (parameter slots by name) into a chunk.
pub struct ExprCompiler<'a> {
    chunk: &'a mut Chunk,
    consts: ConstLookup<'a>,
    env: &'a HashMap<String, u16>,
    /// Whether anything compiled so far draws random numbers.
    random: bool,
}

impl<'a> ExprCompiler<'a> {
    pub fn new(
        chunk: &'a mut Chunk,
        consts: ConstLookup<'a>,
        env: &'a HashMap<String, u16>,
    ) -> ExprCompiler<'a> {
        ExprCompiler {
            chunk,
            consts,
            env,
            random: false,
        }
    }

    /// Compiles one expression to the end of the chunk. On an error the chunk
    /// is left as it was.
    pub fn compile(&mut self, e: &Expr) -> Result<Code, ExprError> {
        let start = self.chunk.len();
        if let Err(err) = self.expr(e) {
            self.truncate(start);
            return Err(err);
        }
        Ok(Code::new(self.chunk, start, self.chunk.len()))
    }

    fn expr(&mut self, e: &Expr) -> Result<(), ExprError> {
        match &e.kind {
            ExprKind::Num(v) => {
                self.chunk.push(Op::Const(*v), e.span);
            }
            ExprKind::Bool(b) => {
                self.chunk.push(Op::Const(f64::from(u8::from(*b))), e.span);
            }
            ExprKind::Error => return Err(ExprError::Malformed { span: e.span }),
            ExprKind::Var(n) => {
                if let Some(&slot) = self.env.get(n) {
                    self.chunk.push(Op::Load(slot), e.span);
                } else if let Some(k) = (self.consts)(n) {
                    self.random |= k.random;
                    self.chunk.push(Op::Const(k.value), e.span);
                } else {
                    return Err(ExprError::UnknownName {
                        name: n.clone(),
                        span: e.span,
                    });
                }
            }
            ExprKind::Unary(op, a) => {
                self.expr(a)?;
                let op = match op {
                    UnOp::Neg => Op::Neg,
                    UnOp::Not => Op::Not,
                };
                self.emit_folded(op, 1, e.span);
            }
            ExprKind::Binary(op, a, b) => match arithmetic(*op) {
                Some(code) => {
                    self.expr(a)?;
                    self.expr(b)?;
                    self.emit_folded(code, 2, e.span);
                }
                None => self.logic(*op == BinOp::And, a, b, e.span)?,
            },
            ExprKind::Call(f, args) => {
                for a in args {
                    self.expr(a)?;
                }
                let span = e.span;
                match f.name.as_str() {
                    "rand" => self.random_op(Op::Rand, span),
                    "uniform" => self.random_op(Op::Uniform, span),
                    "normal" => self.random_op(Op::Normal, span),
                    name => {
                        let idx =
                            builtins::index(name).ok_or_else(|| ExprError::UnknownFunction {
                                name: name.to_string(),
                                span: f.span,
                            })?;
                        self.emit_folded(Op::Call(idx), args.len(), span);
                    }
                }
            }
        }
        Ok(())
    }

    fn random_op(&mut self, op: Op, span: Span) {
        self.random = true;
        self.chunk.push(op, span);
    }

    /// `a && b`, `a || b`: short-circuit jumps, folded when the left side is known.
    fn logic(&mut self, is_and: bool, a: &Expr, b: &Expr, span: Span) -> Result<(), ExprError> {
        let start = self.chunk.len();
        self.expr(a)?;
        if let [Op::Const(v)] = self.chunk.code[start as usize..] {
            let decided = if is_and { v == 0.0 } else { v != 0.0 };
            self.truncate(start);
            if decided {
                self.chunk
                    .push(Op::Const(f64::from(u8::from(!is_and))), span);
            } else {
                self.expr(b)?;
                self.emit_folded(Op::Truth, 1, span);
            }
            return Ok(());
        }
        self.chunk.push(Op::Truth, a.span);
        let jump = self.chunk.push(Op::AndJump(0), span);
        self.expr(b)?;
        self.chunk.push(Op::Truth, b.span);
        let end = self.chunk.len();
        self.chunk.code[jump as usize] = if is_and {
            Op::AndJump(end)
        } else {
            Op::OrJump(end)
        };
        Ok(())
    }

    fn truncate(&mut self, len: u32) {
        self.chunk.code.truncate(len as usize);
        self.chunk.spans.truncate(len as usize);
    }

    /// Emits `op`; if its `inputs` operands are the last instructions and all
    /// constants, replaces them with the result (unless evaluating would fail:
    /// then the error is left for run time, where it is reported with its step).
    fn emit_folded(&mut self, op: Op, inputs: usize, span: Span) {
        let n = self.chunk.code.len();
        if n >= inputs
            && self.chunk.code[n - inputs..]
                .iter()
                .all(|o| matches!(o, Op::Const(_)))
        {
            let start = (n - inputs) as u32;
            let at = self.chunk.push(op, span);
            let code = Code {
                start,
                end: at + 1,
                fast: super::Fast::None,
            };
            let mut rng = Random::new(0, 0, 0);
            let mut stack = Vec::new();
            if let Ok(v) = self.chunk.eval(code, &[], &mut rng, &mut stack) {
                self.truncate(start);
                self.chunk.push(Op::Const(v), span);
            }
            return;
        }
        self.chunk.push(op, span);
    }
}

/// The instruction of a binary operator; `None` for `&&` and `||`, which
/// short-circuit (see `logic`).
fn arithmetic(op: BinOp) -> Option<Op> {
    Some(match op {
        BinOp::Add => Op::Add,
        BinOp::Sub => Op::Sub,
        BinOp::Mul => Op::Mul,
        BinOp::Div => Op::Div,
        BinOp::Rem => Op::Rem,
        BinOp::Pow => Op::Pow,
        BinOp::Eq => Op::Eq,
        BinOp::Ne => Op::Ne,
        BinOp::Lt => Op::Lt,
        BinOp::Le => Op::Le,
        BinOp::Gt => Op::Gt,
        BinOp::Ge => Op::Ge,
        BinOp::And | BinOp::Or => return None,
    })
}
