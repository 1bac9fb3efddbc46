//! The "real art" table of `lsyc infer`: every drawing of tests/data/art/
//! (public-domain and CC0 icons, and patterns written for lsyc; see
//! tests/data/art/SOURCES.md) and of tests/data/infer/ (the synthetic cases),
//! each inferred, drawn again and compared, as a Markdown table on stdout with
//! the median program-over-SVG size ratio of each set.
//!
//! `cargo run --release --example infer_table [-- DIR…]` (default: both
//! directories). Columns: elements of the input and of the redraw, kinds,
//! rules, the SVG's and the program's bytes (of which element paths and
//! comments), the size ratio, the symmetric Hausdorff distance between the
//! sampled outlines in % of the input's bounding-box diagonal, and the time to
//! infer and to redraw.

mod measure;

use measure::{Row, measure, median, table};
use std::path::PathBuf;

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let dirs = if args.is_empty() {
        vec![root.join("tests/data/art"), root.join("tests/data/infer")]
    } else {
        args
    };
    let mut status = 0;
    for dir in &dirs {
        let mut files: Vec<PathBuf> = match std::fs::read_dir(dir) {
            Ok(entries) => entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "svg"))
                .collect(),
            Err(e) => {
                eprintln!("cannot read {}: {e}", dir.display());
                status = 1;
                continue;
            }
        };
        files.sort();
        let rows: Vec<Result<Row, (String, String)>> = files
            .iter()
            .map(|f| {
                measure(f).map_err(|why| {
                    let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
                    (name.unwrap_or_default(), why)
                })
            })
            .collect();
        let ratios: Vec<f64> = rows.iter().flatten().map(Row::size_ratio).collect();
        let worst = rows
            .iter()
            .flatten()
            .map(|r| r.hausdorff)
            .fold(0.0, f64::max);
        let shown = dir.strip_prefix(&root).unwrap_or(dir);
        println!("### {}\n", shown.display());
        print!("{}", table(&rows));
        println!(
            "\n{} drawings, {} failed; median size ratio {:.2}; largest Hausdorff {:.3} % of the diagonal.\n",
            rows.len(),
            rows.iter().filter(|r| r.is_err()).count(),
            median(ratios),
            worst * 100.0,
        );
    }
    std::process::exit(status);
}
