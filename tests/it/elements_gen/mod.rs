//! Random element designs as the test method for element inference (issue
//! 33): a generator of designs by class (`programs`), an independent SVG
//! writer in several encodings (`draw`), and the check that counts a
//! drawing as exact (`check`). Used by `elements_random` (a fixed seed, in
//! `cargo test`) and by `benches/elements_rate.rs` (the large run).

pub mod check;
pub mod draw;
pub mod programs;
pub(crate) use crate::rng;

use check::{Case, Outcome, Table};
use draw::Variant;
use programs::Class;

/// What to run.
pub struct Run<'a> {
    pub classes: &'a [Class],
    pub variants: &'a [Variant],
    /// The first seed.
    pub first: u64,
    /// Designs (seeds) per class.
    pub per_class: u64,
    /// Designs inferred at once (each on a thread of its own).
    pub threads: usize,
}

/// Infers `per_class` designs of each class in each variant; `each` sees
/// every outcome, in the order of classes, seeds and variants, however many
/// threads infer them.
pub fn run(r: &Run, each: &mut dyn FnMut(&Case, Variant, &Outcome)) -> Table {
    let cases: Vec<Case> = r
        .classes
        .iter()
        .flat_map(|&class| (r.first..r.first + r.per_class).map(move |seed| Case::new(class, seed)))
        .collect();
    let done = crate::pool::in_order(cases, r.threads, |case| {
        r.variants
            .iter()
            .map(|&v| (v, check::check(case, v)))
            .collect::<Vec<_>>()
    });
    let mut table = Table::default();
    for (case, outcomes) in &done {
        for (v, o) in outcomes {
            each(case, *v, o);
            table.add(case, *v, o);
        }
    }
    table
}
