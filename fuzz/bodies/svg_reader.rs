//! The SVG reader of `lsyc infer` on arbitrary bytes: the raw-text pre-pass
//! (`svg::scan`), the checks before usvg and usvg itself (`svg::parse`), the
//! element reader (`elements::read`, on the tree parsed once: `read` is
//! `svg::parse` then `read::from_tree`) and the line-drawing reader
//! (`lines::read::polylines`, which parses for itself). Any input must be
//! read or refused with a reason, never a panic, a hang or an allocation the
//! limits should have prevented; what is read must hold finite numbers.
//!
//! Shared by the cargo-fuzz target `svg_reader` and the smoke test
//! (tests/it/fuzz_smoke.rs), which replays the seed corpus through it.

use lsyc::infer::elements::read;
use lsyc::infer::lines::read::polylines;
use lsyc::infer::svg::{self, scan};

/// The largest input the fuzz target passes on (see docs/fuzzing.md): it
/// holds a nesting or an attribute count over the limits, and an entity
/// bomb, so every refusal stays reachable.
#[allow(dead_code)]
pub const MAX_INPUT: usize = 8 * 1024;

pub fn run(data: &[u8]) {
    // The pre-pass alone, on the text as any reader would see it.
    let _ = scan::scan(&String::from_utf8_lossy(data));
    let Ok(tree) = svg::parse(data) else {
        // A refused document is refused by the line reader too.
        assert!(
            polylines(data).is_err(),
            "polylines accept what parse refuses"
        );
        return;
    };
    let _ = read::from_tree(data, &tree);
    if let Ok(lines) = polylines(data) {
        for line in &lines {
            assert!(
                line.iter().all(|p| p.is_finite()),
                "a polyline holds a number that is not finite: {line:?}"
            );
        }
    }
}
