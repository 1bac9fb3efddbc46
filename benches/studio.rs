//! `lsyc studio`'s two latencies, server side, for the palm, the guided tree
//! and the urban layout of the gallery (the files as they are):
//! - **edit → drawing**: one edit of the text, answered as the page gets it:
//!   parse, check, run the scene, write the SVG with its guide layers
//!   (`protocol::run`, the path of `lsyc run -o x.svg --guides`);
//! - **drag → redraw**: one move of a dragged guide vertex: the mass-spring
//!   relaxation and write-back of `lsyc edit`, a check of the moved text, the
//!   incremental scene runner (only the guides whose polygon changed and their
//!   dependents run again), the SVG, and the reply as the page gets it: JSON
//!   with only the guide layers that changed (`DragSession::drag` with the
//!   page's layer hashes). Each iteration moves the vertex to the other of two
//!   places, so every one is a real move.
//!
//! The browser adds its own time (the request, parsing and painting the SVG);
//! `tests/browser/studio.mjs` prints the round trips it measured.
//!
//! `cargo bench --bench studio`.

use criterion::{Criterion, SamplingMode, criterion_group};
use lsyc::studio::protocol::{self, Drag, DragSession, Program};
use std::hint::black_box;
use std::time::Duration;

/// (file, the vertex dragged, two places it is dragged to in turn, the guides
/// pinned: the base of the palm's trunk, the tree's trunk, the urban middle
/// district, as a person holds them)
type Case = (
    &'static str,
    &'static str,
    [[f64; 2]; 2],
    &'static [&'static str],
);
const SCENES: &[Case] = &[
    (
        "palm.lsy",
        "trunk3.v2",
        [[95.0, 336.0], [105.0, 332.0]],
        &["trunk1"],
    ),
    (
        "tree.lsy",
        "limbR1.v2",
        [[104.0, 102.0], [96.0, 98.0]],
        &["trunk"],
    ),
    (
        "urban.lsy",
        "north.v2",
        [[130.0, 130.0], [124.0, 126.0]],
        &["middle"],
    ),
];

fn studio(c: &mut Criterion) {
    for (file, vertex, places, pins) in SCENES {
        let path = format!("{}/lang-examples/{file}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).expect("the gallery file");
        let p = Program {
            source: text,
            ..Program::default()
        };
        let first = protocol::run(&p, file);
        assert!(first.ok, "{file}: {:?}", first.diagnostics);
        let stats = first.stats.unwrap_or_default();
        eprintln!(
            "{file}: {} systems, {} modules, {} segments, {} elements; SVG {} bytes",
            stats["systems"],
            stats["modules"],
            stats["segments"],
            stats["elements"],
            first.svg.map_or(0, |s| s.len())
        );
        let name = file.trim_end_matches(".lsy");
        let mut g = c.benchmark_group(format!("studio/{name}"));
        g.sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3));
        g.bench_function("edit to drawing", |b| {
            b.iter(|| black_box(protocol::run(black_box(&p), file)))
        });
        let mut session = DragSession::new(&p).expect("a scene");
        let drag = |k: usize, have: &std::collections::BTreeMap<String, String>| Drag {
            program: p.clone(),
            vertex: vertex.to_string(),
            x: places[k][0],
            y: places[k][1],
            pins: pins.iter().map(|p| p.to_string()).collect(),
            have: Some(have.clone()),
            ..Drag::default()
        };
        // The first move runs every guide (the session's cache is empty); the
        // second shows what a move recomputes.
        let first = session.drag(&drag(1, &first.layers), file).expect("drags");
        let warm = session.drag(&drag(0, &first.layers), file).expect("drags");
        let patch = warm.patch.as_ref().expect("a patch");
        let sent = patch.layers.iter().filter(|(_, t)| t.is_some()).count();
        eprintln!(
            "{file}: dragging {vertex} recomputes {} of {} guides, sends {sent} of {} layers ({} bytes of JSON)",
            warm.recomputed.len(),
            warm.guides.len(),
            patch.layers.len(),
            serde_json::to_string(&warm).map_or(0, |j| j.len())
        );
        // Where a move's time goes: the reply's own timings, the mean of ten
        // moves.
        let mut k = 0;
        let mut have = warm.layers.clone();
        let mut parts = [0.0; 5];
        for _ in 0..10 {
            k ^= 1;
            let reply = session.drag(&drag(k, &have), file).expect("drags");
            let st = reply.stats.clone().unwrap_or_default();
            let keys = [
                "solve_ms",
                "check_ms",
                "derive_ms",
                "interpret_ms",
                "total_ms",
            ];
            for (p, key) in parts.iter_mut().zip(keys) {
                *p += st[key].as_f64().unwrap_or(0.0) / 10.0;
            }
            have = reply.layers;
        }
        eprintln!(
            "{file}: a move: springs {:.1} ms, check {:.1} ms, scene run {:.1} ms, drawing {:.1} ms; {:.1} ms to the reply (without its JSON)",
            parts[0], parts[1], parts[2], parts[3], parts[4]
        );
        g.bench_function("drag to redraw", |b| {
            b.iter(|| {
                k ^= 1;
                let reply = session.drag(&drag(k, &have), file).expect("drags");
                let json = serde_json::to_string(&reply).expect("json");
                have = reply.layers;
                black_box(json)
            })
        });
        g.finish();
    }
}

criterion_group!(benches, studio);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
