//! Random line-drawing programs as the test method for line-drawing
//! inference (issue 32): a generator of D0L programs by class (`programs`), an
//! independent drawer and SVG writer (`draw`), and the check that counts a
//! drawing as exact (`check`). Used by `lines_random` (a fixed seed, in
//! `cargo test`) and by `benches/lines_rate.rs` (the large run).

pub mod check;
pub mod draw;
pub mod programs;
pub(crate) use crate::rng;

use check::{Case, Table};
use draw::Variant;
use programs::{Class, Rejections};
use std::time::Duration;

/// What to run.
pub struct Run<'a> {
    pub classes: &'a [Class],
    pub variants: &'a [Variant],
    /// The first seed.
    pub first: u64,
    /// Programs (seeds) per class.
    pub per_class: u64,
    /// Inference's time budget, if not its default.
    pub budget: Option<Duration>,
    /// Programs inferred at once (each on a thread of its own).
    pub threads: usize,
}

/// Infers `per_class` programs of each class (seeds `first..first +
/// per_class`) in each variant; `each` sees every outcome, in the order of
/// classes, seeds and variants, however many threads infer them.
pub fn run(r: &Run, each: &mut dyn FnMut(&Case, Variant, &check::Outcome)) -> Table {
    let mut table = Table::default();
    let mut cases = Vec::new();
    for &class in r.classes {
        let mut rejections = Rejections::default();
        for seed in r.first..r.first + r.per_class {
            match Case::new(class, seed, &mut rejections) {
                Some(case) => cases.push(case),
                None => *table.ungenerated.entry(class).or_default() += 1,
            }
        }
        table.rejections.insert(class, rejections);
    }
    let done = crate::pool::in_order(cases, r.threads, |case| {
        r.variants
            .iter()
            .map(|&v| (v, check::check(case, v, r.budget)))
            .collect::<Vec<_>>()
    });
    for (case, outcomes) in &done {
        for (v, o) in outcomes {
            each(case, *v, o);
            table.add(case, *v, o);
        }
    }
    table
}
