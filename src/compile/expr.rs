//! Expressions to bytecode, with constant folding.

use crate::ast::{BinOp, ConstDecl, Expr, ExprKind, File, Item, UnOp};
use crate::builtins;
use crate::check::Checked;
use crate::span::Span;
use crate::vm::{Chunk, Code, Op, Random};
use std::collections::HashMap;

/// Compiles expressions of one scope (parameter slots by name) into a chunk.
pub struct ExprCompiler<'a> {
    chunk: &'a mut Chunk,
    file: &'a File,
    checked: &'a Checked,
    env: &'a HashMap<String, u16>,
    /// Constants being inlined, to stop at a cycle (the checker rejects them).
    inlining: Vec<String>,
}

impl<'a> ExprCompiler<'a> {
    pub fn new(
        chunk: &'a mut Chunk,
        file: &'a File,
        checked: &'a Checked,
        env: &'a HashMap<String, u16>,
    ) -> ExprCompiler<'a> {
        ExprCompiler {
            chunk,
            file,
            checked,
            env,
            inlining: Vec::new(),
        }
    }

    /// The value of a constant expression (constants folded), if it has one.
    pub fn fold_const(e: &Expr, checked: &Checked) -> Option<f64> {
        let mut chunk = Chunk::default();
        let env = HashMap::new();
        let file = File::default();
        let code = ExprCompiler::new(&mut chunk, &file, checked, &env).compile(e);
        code.constant(&chunk)
    }

    pub fn compile(&mut self, e: &Expr) -> Code {
        let start = self.chunk.len();
        self.expr(e);
        Code::new(self.chunk, start, self.chunk.len())
    }

    fn const_decl(&self, name: &str) -> Option<&'a ConstDecl> {
        self.file.items.stmts.iter().find_map(|i| match &i.node {
            Item::Const(c) if c.name.name == name => Some(c),
            _ => None,
        })
    }

    fn expr(&mut self, e: &Expr) {
        match &e.kind {
            ExprKind::Num(v) => {
                self.chunk.push(Op::Const(*v), e.span);
            }
            ExprKind::Bool(b) => {
                self.chunk.push(Op::Const(f64::from(u8::from(*b))), e.span);
            }
            ExprKind::Error => {
                self.chunk.push(Op::Const(0.0), e.span);
            }
            ExprKind::Var(n) => {
                if let Some(&slot) = self.env.get(n) {
                    self.chunk.push(Op::Load(slot), e.span);
                } else if let Some(&v) = self.checked.consts.get(n) {
                    self.chunk.push(Op::Const(v), e.span);
                } else if let (Some(c), false) = (self.const_decl(n), self.inlining.contains(n)) {
                    // A constant not known before the run (it draws random numbers):
                    // its expression is evaluated where it is used.
                    self.inlining.push(n.clone());
                    self.expr(&c.value);
                    self.inlining.pop();
                } else {
                    self.chunk.push(Op::Const(0.0), e.span);
                }
            }
            ExprKind::Unary(op, a) => {
                self.expr(a);
                self.emit_folded(
                    match op {
                        UnOp::Neg => Op::Neg,
                        UnOp::Not => Op::Not,
                    },
                    1,
                    e.span,
                );
            }
            ExprKind::Binary(BinOp::And, a, b) | ExprKind::Binary(BinOp::Or, a, b) => {
                let is_and = matches!(e.kind, ExprKind::Binary(BinOp::And, ..));
                let start = self.chunk.len();
                self.expr(a);
                // Fold when the left side is a known constant.
                if let [Op::Const(v)] = self.chunk.code[start as usize..] {
                    let decided = if is_and { v == 0.0 } else { v != 0.0 };
                    self.truncate(start);
                    if decided {
                        self.chunk
                            .push(Op::Const(f64::from(u8::from(!is_and))), e.span);
                    } else {
                        self.expr(b);
                        self.emit_folded(Op::Truth, 1, e.span);
                    }
                    return;
                }
                self.chunk.push(Op::Truth, a.span);
                let jump = self.chunk.push(Op::AndJump(0), e.span);
                self.expr(b);
                self.chunk.push(Op::Truth, b.span);
                let end = self.chunk.len();
                self.chunk.code[jump as usize] = if is_and {
                    Op::AndJump(end)
                } else {
                    Op::OrJump(end)
                };
            }
            ExprKind::Binary(op, a, b) => {
                self.expr(a);
                self.expr(b);
                let op = match op {
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
                    BinOp::And | BinOp::Or => unreachable!("handled above"),
                };
                self.emit_folded(op, 2, e.span);
            }
            ExprKind::Call(f, args) => {
                for a in args {
                    self.expr(a);
                }
                let span = e.span;
                match f.name.as_str() {
                    "rand" => {
                        self.chunk.push(Op::Rand, span);
                    }
                    "uniform" => {
                        self.chunk.push(Op::Uniform, span);
                    }
                    "normal" => {
                        self.chunk.push(Op::Normal, span);
                    }
                    name => {
                        let idx = builtins::BUILTINS
                            .iter()
                            .position(|b| b.name == name)
                            .unwrap_or(0);
                        self.emit_folded(Op::Call(idx as u8), args.len(), span);
                    }
                }
            }
        }
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
                fast: crate::vm::Fast::None,
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
