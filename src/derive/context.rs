//! Bracket-aware context matching (as in ABOP and cpfg): the left context is
//! searched towards the root, skipping sibling branches; the right context is
//! searched forward, skipping branches that the pattern does not enter; symbols
//! on the ignore list are passed over.

use super::View;
use crate::compile::{Action, Pattern};

/// Matches `pats` (in written order) ending just before module `i`.
pub(crate) fn left(view: &View, pats: &[Pattern], i: usize, slots: &mut [f64]) -> bool {
    let syms = &view.s.syms;
    let mut j = i;
    for pat in pats.iter().rev() {
        let pat_action = view.prog.symbols.info[pat.sym as usize].action;
        let literal = matches!(pat_action, Action::Push | Action::Pop);
        loop {
            if j == 0 {
                return false;
            }
            j -= 1;
            if literal {
                break;
            }
            match view.action(j) {
                Action::Pop => {
                    // A sibling branch: skip back to its `[`.
                    let mut depth = 1usize;
                    while depth > 0 {
                        if j == 0 {
                            return false;
                        }
                        j -= 1;
                        match view.action(j) {
                            Action::Pop => depth += 1,
                            Action::Push => depth -= 1,
                            _ => {}
                        }
                    }
                }
                Action::Push => {}
                _ if view.prog.ignore[syms[j] as usize] => {}
                _ => break,
            }
        }
        if syms[j] != pat.sym {
            return false;
        }
        let params = view.params_at(j);
        slots[pat.slot as usize..pat.slot as usize + params.len()].copy_from_slice(params);
    }
    true
}

/// Matches `pats` starting just after module `i`.
pub(crate) fn right(view: &View, pats: &[Pattern], i: usize, slots: &mut [f64]) -> bool {
    let syms = &view.s.syms;
    let n = syms.len();
    let mut j = i + 1;
    for pat in pats {
        match view.prog.symbols.info[pat.sym as usize].action {
            Action::Push => {
                while j < n && view.prog.ignore[syms[j] as usize] {
                    j += 1;
                }
                if j >= n || view.action(j) != Action::Push {
                    return false;
                }
                j += 1;
                continue;
            }
            Action::Pop => {
                // Skip to the end of the current branch.
                let mut depth = 0usize;
                loop {
                    if j >= n {
                        return false;
                    }
                    match view.action(j) {
                        Action::Push => depth += 1,
                        Action::Pop if depth == 0 => break,
                        Action::Pop => depth -= 1,
                        _ => {}
                    }
                    j += 1;
                }
                j += 1;
                continue;
            }
            _ => {}
        }
        loop {
            if j >= n {
                return false;
            }
            match view.action(j) {
                Action::Push => {
                    // A branch the pattern does not enter: skip it.
                    let mut depth = 1usize;
                    while depth > 0 {
                        j += 1;
                        if j >= n {
                            return false;
                        }
                        match view.action(j) {
                            Action::Push => depth += 1,
                            Action::Pop => depth -= 1,
                            _ => {}
                        }
                    }
                    j += 1;
                }
                Action::Pop => return false,
                _ if view.prog.ignore[syms[j] as usize] => j += 1,
                _ => break,
            }
        }
        if syms[j] != pat.sym {
            return false;
        }
        let params = view.params_at(j);
        slots[pat.slot as usize..pat.slot as usize + params.len()].copy_from_slice(params);
        j += 1;
    }
    true
}
