//! How quickly the limits stop a runaway program: `F -> FFFFFFFFFF` asked for
//! 40 steps would hold 10^40 modules; the module limit must end it with a
//! clear error (E0903) after a moment, not after the machine runs out of
//! memory. Timed here, not asserted in a test: a shared machine's clock says
//! nothing about the code. (The test `an_explosion_stops_with_a_clear_error`
//! checks the error itself.)
//!
//! `cargo bench --bench limits`.

use criterion::{Criterion, criterion_group, criterion_main};
use lsyc::frontend;
use lsyc::run::{self, Options};
use std::hint::black_box;

fn explosion(c: &mut Criterion) {
    let src = "lsystem Boom { axiom F; F -> FFFFFFFFFF; }";
    let fe = frontend::run(src, Vec::new(), &[]);
    let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) else {
        panic!("the benchmark's program does not check");
    };
    let opts = Options {
        steps: Some(40),
        ..Options::default()
    };
    c.bench_function("explosion_stops_at_the_module_limit", |b| {
        b.iter(|| {
            let result = run::derive(&fe.file, checked, &opts, &|_, _| {});
            assert!(result.is_err(), "the module limit must stop it");
            black_box(result.is_err())
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = explosion
}
criterion_main!(benches);
