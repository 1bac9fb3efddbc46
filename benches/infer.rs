//! Inference speed: `lsyc infer ART.svg` on drawings of 300 to 100,800 elements,
//! to show how time grows with the element count (the paper: 72 elements in
//! 16 s, 500 in 209 s, 1,184 in 1,215 s, about n^1.55).
//!
//! The drawings are made here, in memory, as SVG text, so every run infers
//! the same input:
//!
//! - `grid`: blocks of 5 × 4 windows (a square with four panes as holes, the
//!   paper's Fig. 10), the blocks themselves on a square grid: a three-level
//!   hierarchy of sequences;
//! - `rings`: rings of 12 leaves each turned towards the ring's centre, the
//!   rings on a square grid;
//! - `clutter`: one leaf at random positions, turns and sizes (a fixed
//!   generator): no regularity, the worst case, coded as pairs. At 100,800
//!   leaves it is over the rule search's work limit (`rules::MAX_WORK`): the
//!   time measured is how long inference takes to stop with that error.
//!
//! Each measurement is the whole pipeline from SVG bytes to the program text,
//! on rayon's global pool (`RAYON_NUM_THREADS=1` for one thread). The
//! 100,800-element drawings (5,040 blocks of windows, 8,400 rings) are timed
//! in a group of their own with the fewest samples criterion takes.
//!
//! `cargo bench --bench infer` (`-- infer-100k` for the largest only).

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, SamplingMode, criterion_group};
use lsyc::infer::elements::{self, Options};
use std::fmt::Write;
use std::hint::black_box;
use std::time::Duration;

const LEAF: &str = "M0 0 C6 4 7 14 1 20 C-3 14 -5 9 -2 6 L-4 3 Z";
const WINDOW: &str = "M-4 -4 H4 V4 H-4 Z M-3 -3 V-0.5 H-0.5 V-3 Z M0.5 -3 V-0.5 H3 V-3 Z \
                      M-3 0.5 V3 H-0.5 V0.5 Z M0.5 0.5 V3 H3 V0.5 Z";

/// A small deterministic generator (SplitMix64) for the clutter.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn drawing(kind: &str, n: usize) -> String {
    let mut s =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="-100 -100 4000 4000">"#);
    let side = |per: usize| ((n as f64 / per as f64).sqrt().ceil() as usize).max(1);
    match kind {
        "grid" => {
            let side = side(20);
            for k in 0..n {
                let (b, i) = (k / 20, k % 20);
                let (bx, by) = ((b % side) * 80, (b / side) * 60);
                let (x, y) = (bx + 13 * (i % 5), by + 10 * (i / 5));
                let _ = write!(
                    s,
                    r##"<path d="{WINDOW}" fill="#345" fill-rule="evenodd" transform="translate({x} {y})"/>"##
                );
            }
        }
        "rings" => {
            let side = side(12);
            for k in 0..n {
                let (r, i) = (k / 12, k % 12);
                let (cx, cy) = ((r % side) * 110, (r / side) * 110);
                let _ = write!(
                    s,
                    r##"<path d="{LEAF}" fill="#3b7d3b" transform="translate({cx} {cy}) rotate({}) translate(0 -40)"/>"##,
                    30 * i
                );
            }
        }
        _ => {
            let mut rng = Rng(1);
            for _ in 0..n {
                let (x, y) = (rng.unit() * 3000.0, rng.unit() * 3000.0);
                let (a, sc) = (rng.unit() * 360.0, 0.5 + rng.unit() * 1.5);
                let _ = write!(
                    s,
                    r##"<path d="{LEAF}" fill="#3b7d3b" transform="translate({x:.2} {y:.2}) rotate({a:.1}) scale({sc:.3})"/>"##
                );
            }
        }
    }
    s.push_str("</svg>");
    s
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("infer");
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    for kind in ["grid", "rings", "clutter"] {
        for n in [300, 1200, 3000, 10_000] {
            measure(&mut group, kind, n);
        }
    }
    group.finish();
    let mut group = c.benchmark_group("infer-100k");
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    // Not the grid: its windows have five subpaths each, and 504,000 subpaths are
    // over the reader's limit (`elements::read::MAX_SUBPATHS`), so it ends with an error.
    for kind in ["rings", "clutter"] {
        measure(&mut group, kind, 100_800);
    }
    group.finish();
}

/// Infers `kind` of `n` elements once and says what it found (or why it
/// stopped: the largest clutter is over the rule search's work limit,
/// `rules::MAX_WORK`, and then the time is how long it takes to say so), and
/// times it.
fn measure(group: &mut BenchmarkGroup<WallTime>, kind: &str, n: usize) {
    let svg = drawing(kind, n);
    let name = format!("{kind}-{n}.svg");
    match elements::from_svg(svg.as_bytes(), &name, &Options::default(), &mut |_| {}) {
        Ok(first) => eprintln!(
            "{name}: {} elements, {} kinds, {} rules in {} rounds",
            first.stats.elements, first.stats.kinds, first.stats.rules, first.stats.rounds
        ),
        Err(e) => eprintln!("{name}: stops: {e}"),
    }
    if n > 10_000 {
        // Ten runs of one sample each.
        group.measurement_time(Duration::from_secs(1));
    } else if n >= 3000 {
        group.measurement_time(Duration::from_secs(30));
    } else {
        group.measurement_time(Duration::from_secs(5));
    }
    group.bench_function(&name, |b| {
        b.iter(|| {
            elements::from_svg(
                black_box(svg.as_bytes()),
                &name,
                &Options::default(),
                &mut |_| {},
            )
            .map(|i| i.text.len())
        })
    });
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
