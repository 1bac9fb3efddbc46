//! The SVG reader of `lsyc infer` on arbitrary bytes: the raw-text pre-pass
//! (`svg::scan`), the checks before usvg and usvg itself (`svg::parse`), the
//! element reader (`elements::read`) and the line-drawing reader
//! (`lines::read::polylines`). Any input must be read or refused with a
//! reason, never a panic, a hang or an allocation the limits should have
//! prevented; what is read must hold finite numbers.
//!
//! Shared by the cargo-fuzz target `svg_reader` and the smoke test
//! (tests/it/fuzz_smoke.rs), which replays the seed corpus through it.

use lsyc::infer::elements::read;
use lsyc::infer::lines::read::polylines;
use lsyc::infer::svg::{self, scan};

pub fn run(data: &[u8]) {
    // The pre-pass alone, on the text as any reader would see it.
    let _ = scan::scan(&String::from_utf8_lossy(data));
    if svg::parse(data).is_err() {
        // A refused document is refused by every reader.
        assert!(read::read(data).is_err(), "read accepts what parse refuses");
        assert!(
            polylines(data).is_err(),
            "polylines accept what parse refuses"
        );
        return;
    }
    let _ = read::read(data);
    if let Ok(lines) = polylines(data) {
        for line in &lines {
            assert!(
                line.iter().all(|p| p.is_finite()),
                "a polyline holds a number that is not finite: {line:?}"
            );
        }
    }
}
