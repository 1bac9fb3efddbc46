//! Random line-drawing programs as the test method for line-drawing
//! inference (issue 32): a generator of D0L programs by class (`programs`), an
//! independent drawer and SVG writer (`draw`), and the check that counts a
//! drawing as exact (`check`). Used by `lines_random` (a fixed seed, in
//! `cargo test`) and by `benches/lines_rate.rs` (the large run).

pub mod check;
pub mod draw;
pub mod programs;
pub mod rng;

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
}

/// Infers `per_class` programs of each class (seeds `first..first +
/// per_class`) in each variant; `each` sees every outcome as it comes.
pub fn run(r: &Run, each: &mut dyn FnMut(&Case, Variant, &check::Outcome)) -> Table {
    let mut table = Table::default();
    for &class in r.classes {
        let mut rejections = Rejections::default();
        for seed in r.first..r.first + r.per_class {
            let Some(case) = Case::new(class, seed, &mut rejections) else {
                *table.ungenerated.entry(class).or_default() += 1;
                continue;
            };
            for &v in r.variants {
                let o = check::check(&case, v, r.budget);
                each(&case, v, &o);
                table.add(&case, v, &o);
            }
        }
        table.rejections.insert(class, rejections);
    }
    table
}
