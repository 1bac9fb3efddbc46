//! Decomposition (`decompose A -> B C;`): after each derivation step, every
//! module with decomposition rules is replaced by the successor of the first
//! rule that applies, and the modules it produces are decomposed in turn, until
//! none matches (as L-Py's and cpfg's decomposition rules do). Rules have
//! conditions and weights but no context. A chain deeper than
//! `MAX_DECOMPOSE_DEPTH` ends with an error naming the modules of the chain.

use super::{DeriveError, Limits, ModString, check_limits};
use crate::compile::{CompiledRule, Program, Sym};
use crate::vm::{Random, VmError};

/// How deep decomposition rules may expand into each other.
pub const MAX_DECOMPOSE_DEPTH: usize = 64;

/// Whether the program has decomposition rules.
pub fn has_rules(prog: &Program) -> bool {
    prog.decompose.iter().any(|r| !r.is_empty())
}

/// Decomposes string `s` (derived at `step`) until no decomposition rule applies.
pub fn decompose(
    prog: &Program,
    s: ModString,
    step: u32,
    seed: u64,
    limits: Limits,
) -> Result<ModString, DeriveError> {
    let mut d = Decomposer {
        prog,
        step,
        seed,
        limits,
        out: ModString {
            syms: Vec::with_capacity(s.len()),
            params: Vec::with_capacity(s.params.len()),
        },
        stack: Vec::new(),
        chain: Vec::new(),
    };
    let mut p = 0;
    for (i, &sym) in s.syms.iter().enumerate() {
        let n = prog.symbols.arity(sym);
        let params = &s.params[p..p + n];
        p += n;
        d.module(sym, params, i as u64, 0)?;
        if (i + 1).is_multiple_of(1024) {
            check_limits(step, d.out.len(), d.out.params.len(), limits, false)?;
        }
    }
    check_limits(step, d.out.len(), d.out.params.len(), limits, false)?;
    Ok(d.out)
}

struct Decomposer<'a> {
    prog: &'a Program,
    step: u32,
    seed: u64,
    limits: Limits,
    out: ModString,
    stack: Vec<f64>,
    /// The modules being decomposed, outermost first (for the error message).
    chain: Vec<Sym>,
}

impl Decomposer<'_> {
    fn module(
        &mut self,
        sym: Sym,
        params: &[f64],
        position: u64,
        depth: usize,
    ) -> Result<(), DeriveError> {
        let prog = self.prog;
        let rules = &prog.decompose[sym as usize];
        if rules.is_empty() {
            self.out.syms.push(sym);
            self.out.params.extend_from_slice(params);
            return Ok(());
        }
        let step = self.step;
        let vm = |error: VmError| DeriveError::Vm { step, error };
        let mut rng = Random::new(
            self.seed ^ 0xdec0_4b05,
            step,
            position ^ ((depth as u64) << 48),
        );
        let Some(rule) = choose(prog, rules, params, &mut rng, &mut self.stack).map_err(vm)? else {
            self.out.syms.push(sym);
            self.out.params.extend_from_slice(params);
            return Ok(());
        };
        if depth >= MAX_DECOMPOSE_DEPTH {
            self.chain.push(sym);
            let names = self
                .chain
                .iter()
                .map(|&s| prog.symbols.info[s as usize].name.text().into_owned())
                .collect();
            return Err(DeriveError::DecomposeTooDeep {
                chain: names,
                depth,
                span: rule.span,
            });
        }
        if self.out.len() + rule.succ.len() > self.limits.max_modules {
            check_limits(
                step,
                self.out.len() + rule.succ.len(),
                0,
                self.limits,
                false,
            )?;
        }
        self.chain.push(sym);
        for e in &rule.succ {
            let mut args = Vec::with_capacity(e.args.len());
            for code in &e.args {
                args.push(
                    prog.chunk
                        .eval(*code, params, &mut rng, &mut self.stack)
                        .map_err(vm)?,
                );
            }
            self.module(e.sym, &args, position, depth + 1)?;
        }
        self.chain.pop();
        Ok(())
    }
}

/// The first rule (or weighted choice) whose condition holds.
fn choose<'r>(
    prog: &Program,
    rules: &'r [CompiledRule],
    params: &[f64],
    rng: &mut Random,
    stack: &mut Vec<f64>,
) -> Result<Option<&'r CompiledRule>, VmError> {
    let mut k = 0;
    while k < rules.len() {
        let group = rules[k].group;
        let end = k + rules[k..].iter().take_while(|r| r.group == group).count();
        let mut cands: Vec<(usize, f64)> = Vec::new();
        for (idx, r) in rules[k..end].iter().enumerate() {
            let ok = match r.cond {
                Some(c) => prog.chunk.eval(c, params, rng, stack)? != 0.0,
                None => true,
            };
            if !ok {
                continue;
            }
            match r.weight {
                None => return Ok(Some(r)),
                Some(w) => {
                    let w = prog.chunk.eval(w, params, rng, stack)?;
                    if w > 0.0 {
                        cands.push((k + idx, w));
                    }
                }
            }
        }
        if let Some(pick) = rng.pick(&cands) {
            return Ok(Some(&rules[pick]));
        }
        k = end;
    }
    Ok(None)
}
