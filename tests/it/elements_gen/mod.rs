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
use std::collections::VecDeque;
use std::sync::Mutex;

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
    let mut queue = VecDeque::new();
    for &class in r.classes {
        for seed in r.first..r.first + r.per_class {
            queue.push_back((queue.len(), Case::new(class, seed)));
        }
    }
    let queue = Mutex::new(queue);
    let done = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..r.threads.max(1) {
            s.spawn(|| {
                loop {
                    let next = queue.lock().map(|mut q| q.pop_front());
                    let Ok(Some((at, case))) = next else {
                        break;
                    };
                    let outcomes: Vec<_> = r
                        .variants
                        .iter()
                        .map(|&v| (v, check::check(&case, v)))
                        .collect();
                    if let Ok(mut d) = done.lock() {
                        d.push((at, case, outcomes));
                    }
                }
            });
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|d| d.0);
    let mut table = Table::default();
    for (_, case, outcomes) in &done {
        for (v, o) in outcomes {
            each(case, *v, o);
            table.add(case, *v, o);
        }
    }
    table
}
