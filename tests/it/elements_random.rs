//! Element inference on random designs (issue 33, item 5): a few designs of
//! each declared class (`elements_gen::programs`) from a fixed seed, written
//! by the tests' own SVG writer in every encoding, inferred, and counted
//! exact only when the inferred program redraws the drawing and predicts
//! the design's next (`elements_gen::check`).
//!
//! The floors are what inference reached when they were written: a ratchet,
//! rates may only go up (raise a floor when they do). A failing design is
//! printed with its (class, seed) when its class and variant fall below the
//! floor; `cargo bench --bench elements_rate -- --class CLASS --first SEED
//! --per-class 1 --show` infers it again and shows the program. The large
//! run is `benches/elements_rate.rs`.

use crate::elements_gen::{self, check::Case, draw::Variant, programs::Class};
use crate::support::against_floor;
use std::collections::BTreeMap;
use std::time::Instant;

/// Designs per class.
const PER_CLASS: u64 = 20;

/// Exact drawings of `PER_CLASS`, per class, in the order of `Variant::ALL`
/// (use, plain, prim, shuffled, jittered). Inference of elements is not
/// timed, so these are the counts of the run that set them.
const FLOORS: &[(Class, [usize; 5])] = &[
    (Class::Row, [20, 20, 20, 20, 20]),
    (Class::Ring, [20, 20, 20, 20, 20]),
    (Class::Spiral, [20, 20, 20, 20, 20]),
    (Class::Period, [20, 20, 20, 20, 20]),
    (Class::Grid, [20, 20, 20, 20, 19]),
    (Class::Linear, [20, 20, 20, 20, 17]),
    (Class::Tree, [20, 20, 19, 20, 19]),
];

/// Jittered drawings, per class in the order of `FLOORS`, whose
/// `--symmetrize` program is no farther from the clean design than the
/// drawing (`Cell::closer`): a ratchet on "--symmetrize only regularizes".
const CLOSER: [usize; 7] = [20, 20, 20, 19, 20, 19, 15];

#[test]
fn random_designs_are_inferred_at_least_as_often_as_before() {
    let start = Instant::now();
    let run = elements_gen::Run {
        classes: &Class::ALL,
        variants: &Variant::ALL,
        first: 0,
        per_class: PER_CLASS,
        threads: 2,
    };
    let mut failed: BTreeMap<(Class, Variant), Vec<String>> = BTreeMap::new();
    let table = elements_gen::run(&run, &mut |case, v, o| {
        if let Some(f) = &o.fail {
            failed.entry((case.class, v)).or_default().push(format!(
                "{} seed {} {}: {}: {} | {}",
                case.class.name(),
                case.seed,
                v.name(),
                f.kind,
                f.detail,
                case.design.text
            ));
        }
    });
    eprintln!("{}", table.render());
    eprintln!("{:.1} s", start.elapsed().as_secs_f64());
    let mut below = Vec::new();
    for (&(class, floors), closer) in FLOORS.iter().zip(CLOSER) {
        let cell = table.get(class, Variant::Jittered);
        if cell.closer < closer {
            below.push(format!(
                "{} jittered: --symmetrize programs no farther from the clean design than the drawing in {}/{}, floor {closer}",
                class.name(),
                cell.closer,
                cell.measured
            ));
        }
        for (v, floor) in Variant::ALL.into_iter().zip(floors) {
            let cell = table.get(class, v);
            against_floor(
                &mut below,
                &format!("{} {}", class.name(), v.name()),
                (cell.exact, cell.total),
                floor,
                failed.get(&(class, v)),
            );
        }
    }
    assert!(below.is_empty(), "below the floor:\n{}", below.join("\n"));
}

/// The tests' SVG writer writes what the design says in every encoding:
/// lsyc's reader finds the design's copies in each (the hand-placed ones
/// within their jitter).
#[test]
fn every_encoding_of_a_design_holds_its_copies() {
    for class in Class::ALL {
        for seed in 0..4 {
            let case = Case::new(class, seed);
            for v in Variant::ALL {
                let svg = case.svg(v);
                if let Err(e) = case.holds(svg.as_bytes(), v) {
                    panic!("{} seed {seed} {}: {e}\n{svg}", class.name(), v.name());
                }
            }
        }
    }
}

/// The "clean numbers" figure: a number the drawing's rounding left near a
/// short decimal is blurred; a measured number of three places is not.
#[test]
fn blurred_numbers_are_short_decimals_the_drawing_rounded() {
    let program = "lsystem D {\n    axiom -(24.97) f(111.331)+(89.999) A f(15.0003) *(0.99998) f(0.2501) f(66.483);\n}\n";
    let found = elements_gen::check::blurred(program);
    assert_eq!(found, ["89.999", "15.0003", "0.99998", "0.2501"]);
}
