//! Helpers shared by the integration tests.

use lsyc::diagnostic::{self, Diagnostic, Format};
use std::path::{Path, PathBuf};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.lsy` file under the given repo-relative directories, sorted.
pub fn lsy_files(dirs: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for d in dirs {
        collect(&root().join(d), &mut out);
    }
    out.sort();
    out
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out);
        } else if p.extension().is_some_and(|x| x == "lsy") {
            out.push(p);
        }
    }
}

/// The path relative to the repository, with `/` separators, for messages and snapshots.
pub fn rel(path: &Path) -> String {
    path.strip_prefix(root())
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

pub fn read_text(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", rel(path)));
    lsyc::source::from_bytes(rel(path), &bytes).text
}

pub fn render_plain(diags: &[Diagnostic], file: &str, text: &str) -> String {
    diagnostic::render(diags, file, text, Format::Human { color: false })
}

/// The errors (not warnings) of parsing `text`.
pub fn parse_errors(text: &str) -> Vec<Diagnostic> {
    lsyc::parser::parse(text)
        .diagnostics
        .into_iter()
        .filter(Diagnostic::is_error)
        .collect()
}

/// Points spread along every element outline of an SVG drawing, `step` apart.
fn drawing_samples(svg: &[u8], step: f64) -> Vec<glam::DVec2> {
    let d = lsyc::infer::elements::read::read(svg).expect("reads");
    let mut out = Vec::new();
    for e in &d.elements {
        for line in &e.outline {
            for w in line.windows(2) {
                let n = (w[0].distance(w[1]) / step).ceil().max(1.0) as usize;
                for k in 0..n {
                    out.push(w[0].lerp(w[1], k as f64 / n as f64));
                }
            }
        }
    }
    out
}

/// The diagonal of the points' bounding box.
fn diagonal(points: &[glam::DVec2]) -> f64 {
    let (lo, hi) = points.iter().fold(
        (
            glam::DVec2::splat(f64::INFINITY),
            glam::DVec2::splat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (hi - lo).length()
}

/// Symmetric Chamfer distance: the mean of both mean nearest distances.
fn chamfer(a: &[glam::DVec2], b: &[glam::DVec2]) -> f64 {
    let one_way = |from: &[glam::DVec2], to: &[glam::DVec2]| {
        let g = lsyc::geometry::index::PointGrid::new(to);
        from.iter()
            .map(|p| p.distance(to[g.nearest(*p, 1)[0]]))
            .sum::<f64>()
            / from.len() as f64
    };
    (one_way(a, b) + one_way(b, a)) / 2.0
}

/// The Chamfer distance between two SVG drawings' outlines (sampled at
/// 1/1500 of the first one's diagonal), relative to that diagonal.
pub fn drawing_distance(a: &[u8], b: &[u8]) -> f64 {
    let diag = diagonal(&drawing_samples(a, 1.0));
    let step = diag / 1500.0;
    chamfer(&drawing_samples(a, step), &drawing_samples(b, step)) / diag
}

/// One cell of a ratchet (a random generator's count held to a floor):
/// below the floor, a line for the assertion (with the failures, one a
/// line); above it, a note to raise the floor.
pub fn against_floor(
    below: &mut Vec<String>,
    cell: &str,
    (exact, total): (usize, usize),
    floor: usize,
    failed: Option<&Vec<String>>,
) {
    if exact < floor {
        below.push(format!(
            "{cell}: {exact}/{total} exact, floor {floor}; not exact:\n  {}",
            failed.map_or(String::new(), |f| f.join("\n  "))
        ));
    } else if exact > floor {
        eprintln!("{cell}: {exact}/{total} exact, above the floor {floor}: raise it");
    }
}
