//! One drawing through `lsyc infer` and back: the program inferred from an
//! SVG, drawn again through the library's run path, and how far the redraw
//! lies from the input (the Hausdorff distance between their sampled
//! outlines, relative to the input's bounding-box diagonal), with the sizes
//! and counts of the table.
//!
//! Shared by `examples/infer_table` (which prints the table) and
//! `tests/it/art_table.rs` (which holds every drawing of tests/data/art/ to
//! it). Owns the measurement only; must not print, and must not panic on a
//! drawing that fails (the failure is the row's error).

use glam::DVec2;
use lsyc::geometry::index::PointGrid;
use lsyc::infer::elements::{self, Options, read};
use lsyc::{frontend, run};
use std::path::Path;
use std::time::Instant;

/// Outline samples per bounding-box diagonal: the sampling adds at most half a
/// step, 1/3000 of the diagonal, to the distance.
const SAMPLES_PER_DIAGONAL: f64 = 1500.0;

/// What one drawing gave.
#[derive(Clone, Debug)]
pub struct Row {
    /// The file name.
    pub name: String,
    pub svg_bytes: usize,
    pub program_bytes: usize,
    /// Of the program: the bytes inside element `path "…"` strings.
    pub path_bytes: usize,
    /// Of the program: the bytes of `//` comments.
    pub comment_bytes: usize,
    pub elements: usize,
    /// Elements of the redraw (as the reader sees them), to compare.
    pub drawn: usize,
    pub kinds: usize,
    pub rules: usize,
    /// Symmetric Hausdorff distance over the input's bounding-box diagonal.
    pub hausdorff: f64,
    /// Inference, SVG bytes to program text.
    pub infer_ms: f64,
    /// Front end, derivation and drawing of the program to SVG.
    pub redraw_ms: f64,
}

impl Row {
    pub fn size_ratio(&self) -> f64 {
        self.program_bytes as f64 / self.svg_bytes.max(1) as f64
    }
}

/// Infers a program from the drawing at `path`, draws it again and compares.
pub fn measure(path: &Path) -> Result<Row, String> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let data = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let t = Instant::now();
    let inferred = elements::from_svg(&data, &name, &Options::default(), &mut |_| {})
        .map_err(|e| format!("infer: {e}"))?;
    let infer_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let redraw = redraw(&inferred.text)?;
    let redraw_ms = t.elapsed().as_secs_f64() * 1e3;
    let input = read::read(&data).map_err(|e| format!("read the input: {e}"))?;
    let output = read::read(&redraw).map_err(|e| format!("read the redraw: {e}"))?;
    let (path_bytes, comment_bytes) = parts(&inferred.text);
    let st = &inferred.stats;
    Ok(Row {
        name,
        svg_bytes: st.svg_bytes,
        program_bytes: st.program_bytes,
        path_bytes,
        comment_bytes,
        elements: st.elements,
        drawn: output.elements.len(),
        kinds: st.kinds,
        rules: st.rules,
        hausdorff: hausdorff(&input, &output),
        infer_ms,
        redraw_ms,
    })
}

/// The program drawn as SVG, as `lsyc run OUT.lsy -o back.svg` would.
fn redraw(text: &str) -> Result<Vec<u8>, String> {
    let fe = frontend::run(text, Vec::new(), &[]);
    let checked = match (&fe.checked, fe.has_errors()) {
        (Some(c), false) => c,
        _ => {
            let first = fe.diagnostics.first().map(|d| d.message.clone());
            return Err(format!("the program does not check: {first:?}"));
        }
    };
    let opts = run::Options::default();
    let derived = run::derive(&fe.file, checked, &opts, &|_, _| {})
        .map_err(|d| format!("derive: {}", d.message))?;
    let mut out = Vec::new();
    run::write_output(
        &derived,
        run::Format::Svg,
        run::Picture::default(),
        opts.seed,
        &mut out,
    )
    .map_err(|e| match e {
        run::OutputError::Diagnostic(d) => format!("draw: {}", d.message),
        run::OutputError::Io(e) => format!("draw: {e}"),
    })?;
    Ok(out)
}

/// The bytes of the program inside `path "…"` strings, and in `//` comments.
fn parts(text: &str) -> (usize, usize) {
    let mut paths = 0;
    let mut comments = 0;
    for line in text.lines() {
        let mut rest = line;
        while let Some(at) = rest.find("path \"") {
            let from = &rest[at + 6..];
            let end = from.find('"').unwrap_or(from.len());
            paths += end;
            rest = &from[end..];
        }
        if let Some(at) = line.find("//") {
            comments += line.len() - at + 1;
        }
    }
    (paths, comments)
}

/// The union of the elements' bounding boxes: its diagonal.
fn diagonal(d: &read::Drawing) -> f64 {
    let (lo, hi) = d.elements.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), e| (lo.min(e.min), hi.max(e.max)),
    );
    (hi - lo).length()
}

/// Points spread along every element outline, at most `step` apart.
fn samples(d: &read::Drawing, step: f64) -> Vec<DVec2> {
    let mut out = Vec::new();
    for e in &d.elements {
        for line in &e.outline {
            for w in line.windows(2) {
                let n = (w[0].distance(w[1]) / step).ceil().clamp(1.0, 1e6) as usize;
                for k in 0..n {
                    out.push(w[0].lerp(w[1], k as f64 / n as f64));
                }
            }
            out.extend(line.last());
        }
    }
    out
}

/// The symmetric Hausdorff distance between the sampled outlines of `a` and
/// `b`, over `a`'s diagonal; infinite if either has no outline.
fn hausdorff(a: &read::Drawing, b: &read::Drawing) -> f64 {
    let diag = diagonal(a);
    if !(diag.is_finite() && diag > 0.0) {
        return f64::INFINITY;
    }
    let step = diag / SAMPLES_PER_DIAGONAL;
    let (pa, pb) = (samples(a, step), samples(b, step));
    if pa.is_empty() || pb.is_empty() {
        return f64::INFINITY;
    }
    let one_way = |from: &[DVec2], to: &[DVec2]| {
        let grid = PointGrid::new(to);
        from.iter()
            .map(|p| {
                grid.nearest(*p, 1)
                    .first()
                    .map_or(f64::INFINITY, |&i| p.distance(to[i]))
            })
            .fold(0.0, f64::max)
    };
    one_way(&pa, &pb).max(one_way(&pb, &pa)) / diag
}

/// The median of `v` (NaN if empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// The rows as a Markdown table, one line each, failures with their reason.
pub fn table(rows: &[Result<Row, (String, String)>]) -> String {
    let mut out = String::from(
        "| drawing | elements | drawn | kinds | rules | SVG B | program B | paths B | comments B | ratio | Hausdorff % | infer ms | redraw ms |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        match r {
            Ok(r) => out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.3} | {:.0} | {:.0} |\n",
                r.name,
                r.elements,
                r.drawn,
                r.kinds,
                r.rules,
                r.svg_bytes,
                r.program_bytes,
                r.path_bytes,
                r.comment_bytes,
                r.size_ratio(),
                r.hausdorff * 100.0,
                r.infer_ms,
                r.redraw_ms,
            )),
            Err((name, why)) => out.push_str(&format!(
                "| {name} | failed: {why} | | | | | | | | | | | |\n"
            )),
        }
    }
    out
}
