//! The whole urban scene of the guided-modeling paper (Fig. 7), at the paper's
//! size or larger: `lang-examples/urban.lsy` with `-D SIZE=0.95` (over 85,000
//! street segments, the paper's element count). One iteration is what
//! `lsyc run urban.lsy` does before writing a file: build the scene, run every
//! system (derivation, query answers through the spatial index, tokens and
//! messages), then draw every guide's systems through the centre rule (counting
//! what is kept). Parsing and checking are outside the timed region.
//!
//! The same layout at `-D SIZE=3.15`, ten times the paper's scale (851,221
//! segments), times how the run grows with the scene.
//!
//! Also the guided tree of the paper (Fig. 1, `lang-examples/tree.lsy`: about
//! 15,000 elements, segments and leaves; the paper took 2 s for it).
//!
//! Before timing, one run prints its counts (segments, elements, queries,
//! messages, systems, steps). Timed on rayon's default pool (all cores) and on
//! a one-thread pool.
//!
//! It allocates with mimalloc, as the `lsyc` binary does (a scene makes and
//! drops many lists per step on every thread).
//!
//! `cargo bench --bench scene`.

use criterion::{Criterion, SamplingMode, criterion_group};
use lsyc::check::Override;
use lsyc::frontend;
use lsyc::run::{self, Options};
use std::hint::black_box;
use std::time::Duration;

#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The size of the benchmark's layout (the gallery picture uses the file's 0.25).
const SIZE: &str = "SIZE=0.95";

/// Ten times the paper's scale: 851,221 segments (the side of every district
/// ×3.3; above SIZE=3 the systems' `derive 150` ends the streets first, so the
/// count grows unevenly with SIZE: 826,008 at 3, 811,152 at 3.1).
const SIZE_X10: &str = "SIZE=3.15";

/// Times one scene of a gallery file, whole, as `lsyc run` runs it.
fn scene(c: &mut Criterion, group: &str, file: &str, overrides: &[&str], samples: usize) {
    let path = format!("{}/lang-examples/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("the gallery file");
    let parsed: Vec<Override> = overrides
        .iter()
        .map(|o| Override::parse(o).expect("override"))
        .collect();
    let fe = frontend::run(&text, Vec::new(), &parsed);
    assert!(!fe.has_errors(), "{file} has errors");
    let checked = fe.checked.as_ref().expect("checked");
    let opts = Options::default();
    let whole = || {
        let r = run::run_scene(&fe.file, checked, None, &opts).expect("runs");
        let stats = run::write_scene(&r, None, Default::default(), 0, false, &mut std::io::sink())
            .unwrap_or_else(|_| panic!("draws"));
        (r, stats)
    };
    let (r, stats) = whole();
    eprintln!(
        "{group} {}: {} segments and {} elements kept by the centre rule, {} queries, {} messages, {} systems, {} steps, {} modules",
        overrides.join(" "),
        stats.segments,
        stats.elements,
        stats.queries,
        stats.messages,
        r.outcome.instances.len(),
        stats.steps,
        stats.modules
    );
    let mut g = c.benchmark_group(group);
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(samples)
        .measurement_time(Duration::from_secs(8));
    g.bench_function("whole scene, all threads", |b| {
        b.iter(|| black_box(whole()))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    g.bench_function("whole scene, 1 thread", |b| {
        b.iter(|| one.install(|| black_box(whole())))
    });
    g.finish();
}

fn urban(c: &mut Criterion) {
    scene(c, "urban", "urban.lsy", &[SIZE], 10);
}

/// Ten times the paper's city: over 850,000 street segments.
fn urban_x10(c: &mut Criterion) {
    scene(c, "urban x10", "urban.lsy", &[SIZE_X10], 10);
}

fn tree(c: &mut Criterion) {
    scene(c, "tree", "tree.lsy", &[], 10);
}

criterion_group!(benches, urban, urban_x10, tree);

fn main() {
    eprintln!(
        "machine: {} threads, {}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split(':').nth(1))
                    .map(|m| m.trim().to_string())
            })
            .unwrap_or_else(|| "unknown CPU".into())
    );
    benches();
    Criterion::default().configure_from_args().final_summary();
}
