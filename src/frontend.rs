//! The front end as one call: parse, then check if the syntax is sound.
//!
//! Owns: the order of the front-end phases and what stops them. The checker only
//! runs on a file without syntax errors, so that one mistake is not reported
//! again as many.

use crate::ast::File;
use crate::check::{self, Checked, Override};
use crate::diagnostic::{self, Diagnostic};
use crate::parser;

pub struct Frontend {
    pub file: File,
    pub diagnostics: Vec<Diagnostic>,
    pub checked: Option<Checked>,
}

impl Frontend {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// Parses and checks a source text. `pre` are diagnostics found while reading it
/// (such as invalid UTF-8). Random constants draw from seed 0.
pub fn run(text: &str, pre: Vec<Diagnostic>, overrides: &[Override]) -> Frontend {
    run_seeded(text, pre, overrides, 0)
}

/// `run`, with random constants drawn from `seed` (the run's `--seed`).
pub fn run_seeded(text: &str, pre: Vec<Diagnostic>, overrides: &[Override], seed: u64) -> Frontend {
    let parsed = parser::parse(text);
    let mut diagnostics = pre;
    diagnostics.extend(parsed.diagnostics);
    let mut checked = None;
    if !diagnostics.iter().any(Diagnostic::is_error) {
        let c = check::check(&parsed.file, overrides, seed);
        diagnostics.extend(c.diagnostics.iter().cloned());
        checked = Some(c);
    }
    diagnostic::sort(&mut diagnostics);
    Frontend {
        file: parsed.file,
        diagnostics,
        checked,
    }
}
