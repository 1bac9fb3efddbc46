//! Real art (tests/data/art/: public-domain and CC0 icons, patterns written
//! for lsyc; see its SOURCES.md) through `lsyc infer` and back: every drawing
//! infers, and the program draws every element again within 1 % of the
//! drawing's bounding-box diagonal (symmetric Hausdorff distance between the
//! sampled outlines). The measurement is the one `cargo run --example
//! infer_table` prints; a failure shows its whole table.
//!
//! Also `lsyc infer --stats`: the sizes it reports are those of the drawing
//! read and the program written.

#[path = "../../examples/infer_table/measure.rs"]
mod measure;

use crate::support::root;
use measure::{Row, measure, median, table};
use std::path::PathBuf;
use std::process::Command;

/// Largest Hausdorff distance of a redraw, over the drawing's diagonal.
const LIMIT: f64 = 0.01;

/// Drawings that are known not to draw back within `LIMIT`, with the reason
/// (a cause in the inference, not in the drawing). None at present.
const KNOWN: &[(&str, &str)] = &[];

fn art() -> Vec<PathBuf> {
    let dir = root().join("tests/data/art");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/data/art")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "svg"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_drawing_infers_and_draws_back() {
    let files = art();
    assert!(
        files.len() >= 10,
        "{} drawings in tests/data/art",
        files.len()
    );
    let rows: Vec<Result<Row, (String, String)>> = files
        .iter()
        .map(|f| {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            measure(f).map_err(|why| (name, why))
        })
        .collect();
    let shown = table(&rows);
    let ratios: Vec<f64> = rows.iter().flatten().map(Row::size_ratio).collect();
    println!("{shown}\nmedian size ratio {:.2}", median(ratios));
    let mut failures = Vec::new();
    for r in &rows {
        match r {
            Err((name, why)) => failures.push(format!("{name}: {why}")),
            Ok(r) => {
                let known = KNOWN.iter().find(|(n, _)| *n == r.name);
                let within = r.hausdorff.is_finite() && r.hausdorff <= LIMIT;
                let bad = !within || r.drawn != r.elements;
                match (bad, known) {
                    (true, None) => failures.push(format!(
                        "{}: Hausdorff {:.3} % of the diagonal, {} of {} elements drawn",
                        r.name,
                        r.hausdorff * 100.0,
                        r.drawn,
                        r.elements
                    )),
                    (false, Some((n, _))) => {
                        failures.push(format!("{n} draws back now: take it off KNOWN"))
                    }
                    _ => {}
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}\n{shown}");
}

#[test]
fn stats_report_the_sizes() {
    let svg = root().join("tests/data/art/lsyc-flower.svg");
    let out = Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .arg("infer")
        .arg(&svg)
        .arg("--stats")
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = stderr
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON on stderr: {stderr}"));
    let v: serde_json::Value = serde_json::from_str(line).expect("JSON");
    let svg_bytes = std::fs::metadata(&svg).expect("svg").len();
    assert_eq!(v["svg_bytes"].as_u64(), Some(svg_bytes), "{line}");
    assert_eq!(
        v["program_bytes"].as_u64(),
        Some(out.stdout.len() as u64),
        "{line}"
    );
    let ratio = v["size_ratio"].as_f64().expect("size_ratio");
    assert!(
        (ratio - out.stdout.len() as f64 / svg_bytes as f64).abs() < 1e-12,
        "{line}"
    );
}
