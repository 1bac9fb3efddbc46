//! The held-out classic set (`tests/data/lines/classic/`, see its README):
//! 15 classic line drawings beyond the Koch family, drawn by an independent
//! Python turtle in five variants, each with its next level in the same
//! coordinates. A drawing counts as **exact** when `lsyc infer` gives a
//! grammar (not the element fallback) whose program, derived and drawn by
//! lsyc, draws the drawing's unit steps at its own depth and the next
//! level's one step further.
//!
//! This set is a held-out check, never a list to tune to: the test prints
//! the table and holds each variant to a floor, the count reached so far (a
//! ratchet: raise a floor when the count rises).
//!
//! In a debug build the stroke-graph search gets an eighth of its default
//! work (it runs about ten times slower there); optimized builds
//! (`cargo test --profile fast lines_classic`) use the defaults.

use crate::lines_gen::check;
use crate::support::root;
use glam::DVec2;
use lsyc::infer::lines::{self, Lines};

/// Exact drawings so far, per variant (of 15), in a debug build, less one
/// for the shared machines' timing (a debug build counted 13, 13, 10, 13,
/// 8 in session 14).
const FLOORS: [(&str, usize); 5] = [
    ("clean", 12),
    ("rotated", 12),
    ("jittered", 9),
    ("split", 12),
    ("shuffled", 7),
];

fn segments(svg: &[u8]) -> Vec<(DVec2, DVec2)> {
    let lines = lines::read::polylines(svg).expect("a line drawing");
    lines
        .iter()
        .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
        .collect()
}

/// Whether the drawing in `dir` named `file` (`NAME-VARIANT`) comes back
/// exact; the reason when not.
fn exact(dir: &std::path::Path, file: &str, step: f64, tolerance: f64) -> Result<(), String> {
    let n = std::fs::read(dir.join(format!("{file}-n.svg"))).expect("reads");
    let next = std::fs::read(dir.join(format!("{file}-next.svg"))).expect("reads");
    let mut opts = lines::Options::default();
    if cfg!(debug_assertions) {
        opts.graph.total /= 8;
    }
    let text = match lines::from_svg(&n, "classic.svg", &opts) {
        Lines::Found(f) => f.text,
        Lines::NotLines(what) => return Err(format!("not lines: {what}")),
        Lines::Unexplained { why, .. } => return Err(format!("no grammar: {why}")),
    };
    let (level, more) = check::redraw(&text)?;
    let at_n = check::compare_within(&segments(&n), &level, step, tolerance);
    if at_n != (0, 0) {
        return Err(format!("at n: {at_n:?} (missing, extra)\n{text}"));
    }
    let at_next = check::compare_within(&segments(&next), &more, step, tolerance);
    // Steps in any order and direction no longer say where the drawing
    // starts: the next level counts up to where it is drawn (see
    // docs/inference.md, "Variants").
    let lost_start = file.ends_with("-shuffled");
    if at_next != (0, 0) && !(lost_start && check::congruent(&segments(&next), &more, step)) {
        return Err(format!("next level: {at_next:?} (missing, extra)\n{text}"));
    }
    Ok(())
}

#[test]
fn classic_drawings_come_back_as_grammars_that_predict_the_next_level() {
    let dir = root().join("tests/data/lines/classic");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).expect("manifest"))
            .expect("json");
    let systems = manifest["systems"].as_array().expect("systems");
    assert_eq!(systems.len(), 15);
    let mut table = String::new();
    let mut below = Vec::new();
    for (variant, floor) in FLOORS {
        let mut hits = Vec::new();
        for s in systems {
            let name = s["name"].as_str().expect("name");
            let v = &s["variants"][variant];
            let m = v["world_matrix"].as_array().expect("matrix");
            let (a, b) = (m[0].as_f64().expect("a"), m[1].as_f64().expect("b"));
            // The file's step: a turtle step of 1 through the matrix.
            let step = a.hypot(b);
            // Jittered points lie up to their radius away (at most a
            // quarter step); both levels' own jitter.
            let radius = ["n", "next"]
                .iter()
                .filter_map(|l| v["jitter_radius"].get(l).and_then(|r| r.as_f64()))
                .fold(v["jitter_radius"].as_f64().unwrap_or(0.0), f64::max);
            let tolerance = 0.2 + 2.0 * radius / step;
            match exact(&dir, &format!("{name}-{variant}"), step, tolerance) {
                Ok(()) => hits.push(name.to_string()),
                Err(why) => eprintln!("{name}-{variant}: {}", why.lines().next().unwrap_or("")),
            }
        }
        table.push_str(&format!(
            "{variant:>9}: {:>2}/15  {}\n",
            hits.len(),
            hits.join(", ")
        ));
        if hits.len() < floor {
            below.push(format!("{variant}: {} < floor {floor}", hits.len()));
        }
    }
    eprintln!("{table}");
    assert!(below.is_empty(), "{below:?}\n{table}");
}
