//! Line-drawing inference speed: `lsyc infer` on the turtle's trace of a
//! gallery system, from a few thousand to over a hundred thousand steps, to
//! show how time grows with the drawing (the goal: seconds, not minutes, for
//! 10⁴–10⁵ segments).
//!
//! Each drawing is made here, in memory, as `lsyc run -o X.svg` would write
//! it (the library's own derivation and SVG writer); each measurement is the
//! whole pipeline from SVG bytes to the program text (reading, the grammar
//! search, and the library's derivation and redraw that check the result).
//!
//! `cargo bench --bench lines`.

use criterion::{Criterion, SamplingMode, criterion_group};
use lsyc::infer::lines::{self, Lines};
use lsyc::run::{self, Format, Picture};
use std::hint::black_box;
use std::time::Duration;

/// `lang-examples/NAME.lsy` drawn at `depth` as SVG bytes.
fn drawing(name: &str, depth: u32) -> Vec<u8> {
    let path = format!("{}/lang-examples/{name}.lsy", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("reads the example");
    let fe = lsyc::frontend::run(&text, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("checks");
    let opts = run::Options {
        steps: Some(depth),
        ..run::Options::default()
    };
    let derived = run::derive(&fe.file, checked, &opts, &|_, _| {}).expect("derives");
    let mut out = Vec::new();
    if run::write_output(&derived, Format::Svg, Picture::default(), 0, &mut out).is_err() {
        panic!("{name}: cannot draw");
    }
    out
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("lines");
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    for (name, depths) in [
        ("koch-curve-a", &[3u32, 4, 5][..]),
        ("dragon-curve", &[11, 14, 17][..]),
        ("hexagonal-gosper-curve", &[4, 5, 6][..]),
        ("sierpinski-gasket", &[7, 10][..]),
        ("plant-a", &[5, 6, 7][..]),
        ("plant-d", &[7, 9][..]),
    ] {
        for &depth in depths {
            let svg = drawing(name, depth);
            let file = format!("{name}-{depth}.svg");
            let opts = lines::Options {
                budget: Duration::from_secs(60),
                ..lines::Options::default()
            };
            // Check once that it works and say what it found.
            match lines::from_svg(&svg, &file, &opts) {
                Lines::Found(f) => eprintln!(
                    "{file}: {} steps, {} ({} rule symbols), derive {}",
                    f.stats.steps,
                    f.grammar.describe(),
                    f.stats.rule_symbols,
                    f.grammar.depth
                ),
                _ => panic!("{file}: no grammar"),
            }
            group.measurement_time(Duration::from_secs(if svg.len() > 1_000_000 {
                30
            } else {
                5
            }));
            group.bench_function(&file, |b| {
                b.iter(|| match lines::from_svg(black_box(&svg), &file, &opts) {
                    Lines::Found(f) => f.text.len(),
                    _ => 0,
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
