//! `lsyc infer ART.svg [-o OUT.lsy]`: a line drawing to the D0L system that
//! draws it (see `lsyc::infer::lines`), or, when it is not a line drawing or
//! no D0L system is found within `--budget-ms`, a drawing of repeated
//! elements to sequence and branching rules (see `lsyc::infer::elements`), and
//! `lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] [--3d]`: a tree sketch to a
//! recursive L-system (see `lsyc::infer::sketch`).
//!
//! Owns: the options, reading the sketch, where the program goes (stdout, or a
//! file written atomically, never over the sketch) and the exit statuses.

use super::Reporter;
use lsyc::infer::MAX_SVG_BYTES;
use lsyc::infer::elements::{self, rules::Weights};
use lsyc::infer::lines::{self, Lines};
use lsyc::infer::sketch::{self, Options};
use lsyc::source;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A drawing (SVG) to turn into an lsystem: a line drawing into the D0L system that draws it, else its repeated elements into sequence and branching rules.
    #[arg(value_name = "ART.svg")]
    pub art: Option<PathBuf>,

    /// A tree sketch (SVG): each path, line or polyline is a branch, the first the trunk.
    #[arg(long, value_name = "SKETCH.svg", conflicts_with = "art")]
    pub skeleton: Option<PathBuf>,

    /// Where to write the program (default, or `-o -`: stdout).
    #[arg(short = 'o', long = "output", value_name = "OUT.lsy")]
    pub output: Option<PathBuf>,

    /// Sketch: emit a 3D tree, children spread around their parent.
    #[arg(long = "3d", requires = "skeleton")]
    pub three_d: bool,

    /// Sketch: Douglas–Peucker tolerance in drawing units (default: 1.5% of the drawing's diagonal).
    #[arg(long, value_name = "E", requires = "skeleton")]
    pub epsilon: Option<f64>,

    /// Sketch: seed of the random perturbation of the 3D spread.
    #[arg(long, default_value_t = 0, requires = "skeleton")]
    pub seed: u64,

    /// Art: weights of cluster importance w = wn·n + wh·h + wφ·φ + wl·l (count, proximity, similarity, length).
    #[arg(long, value_name = "WN,WH,WPHI,WL", conflicts_with = "skeleton")]
    pub weights: Option<String>,

    /// Art: relaxed tolerances, so a noisy drawing comes out as a regular one.
    #[arg(long, conflicts_with = "skeleton")]
    pub symmetrize: bool,

    /// Art: how different two elements may be and still be one kind (mean misfit relative to size).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 0.02,
        conflicts_with = "skeleton"
    )]
    pub similarity: f64,

    /// Art: emit the transforms of repeated structures as random values, turns ±30·J degrees, steps and scales ±J (`lsyc run --seed` picks the variation).
    #[arg(long, value_name = "J", conflicts_with = "skeleton")]
    pub jitter: Option<f64>,

    /// Art: a mirror image of an element is that element mirrored (one outline draws both).
    #[arg(long, conflicts_with = "skeleton")]
    pub reflect: bool,

    /// Print what was found as JSON: on stdout, or on stderr when the program itself goes to stdout (no -o, or -o -) (line drawings: steps, angle, candidates, rules, times; elements: elements, kinds, clusters, rules, time per phase, program size over SVG size).
    #[arg(long)]
    pub stats: bool,

    /// Line drawings: how long the search for a D0L system may take (milliseconds) before inferring elements instead.
    #[arg(long, value_name = "MS", default_value_t = lines::DEFAULT_BUDGET_MS, conflicts_with = "skeleton")]
    pub budget_ms: u64,

    /// Line drawings: do not search for a D0L system; infer elements.
    #[arg(long, conflicts_with = "skeleton")]
    pub no_lines: bool,
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    if let Some(sketch) = &args.skeleton {
        return run_sketch(args, sketch, reporter);
    }
    let Some(art) = &args.art else {
        reporter.error(
            "give a drawing to infer from",
            Some("lsyc infer ART.svg [-o OUT.lsy] (repeated elements), or lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] (a tree sketch)"),
        );
        return 2;
    };
    let mut opts = elements::Options {
        symmetrize: args.symmetrize,
        reflect: args.reflect,
        ..elements::Options::default()
    };
    if !(args.similarity.is_finite() && args.similarity > 0.0 && args.similarity < 1.0) {
        reporter.error(
            &format!(
                "--similarity must be between 0 and 1 (a misfit relative to the element's size), not {}",
                args.similarity
            ),
            None,
        );
        return 2;
    }
    opts.similarity = args.similarity;
    if let Some(j) = args.jitter {
        if !(j.is_finite() && j > 0.0 && j < 1.0) {
            reporter.error(
                &format!(
                    "--jitter must be between 0 and 1 (0.1: turns vary by ±3°, steps by ±10%), not {j}"
                ),
                None,
            );
            return 2;
        }
        opts.jitter = Some(j);
    }
    if let Some(w) = &args.weights {
        match parse_weights(w) {
            Ok(w) => opts.weights = w,
            Err(why) => {
                reporter.error(&format!("--weights {w}: {why}"), None);
                return 2;
            }
        }
    }
    if let Some(code) = same_as_input(args.output.as_deref(), art, "drawing", reporter) {
        return code;
    }
    let name = art.display().to_string();
    let data = match read_input(art, &name, reporter) {
        Ok(d) => d,
        Err(code) => return code,
    };
    if !args.no_lines {
        let opts = lines::Options {
            budget: std::time::Duration::from_millis(args.budget_ms),
            ..lines::Options::default()
        };
        match lines::from_svg(&data, &name, &opts) {
            Lines::Found(found) => {
                if args.stats {
                    print_stats(args, &found.stats);
                }
                let g = &found.grammar;
                let summary = format!(
                    "{name}: a line drawing of {} steps, drawn by a D0L system of {} rule{} at derive {}",
                    found.redraw.steps,
                    found.stats.rules,
                    if found.stats.rules == 1 { "" } else { "s" },
                    g.depth
                );
                return write_program(args.output.as_deref(), &found.text, &summary, reporter);
            }
            Lines::Unexplained {
                why,
                steps,
                timed_out,
                stats,
            } => {
                if args.stats {
                    print_stats(args, &stats);
                }
                let what = if steps > 0 {
                    format!("a line drawing of {steps} steps")
                } else {
                    "a line drawing".to_string()
                };
                let how = if timed_out {
                    format!(
                        "no D0L system found within {} ms (--budget-ms)",
                        args.budget_ms
                    )
                } else {
                    why
                };
                reporter.note(&format!(
                    "{name}: {what}, but {how}; inferring its elements instead"
                ));
            }
            Lines::NotLines(_) => {}
        }
    }
    let bar = std::io::stderr()
        .is_terminal()
        .then(|| indicatif::ProgressBar::new(0));
    if let Some(b) = &bar
        && let Ok(style) = indicatif::ProgressStyle::with_template("inferring {bar:30} {msg}")
    {
        b.set_style(style);
    }
    let mut first = None;
    let mut progress = |left: usize| {
        if let Some(b) = &bar {
            let total = *first.get_or_insert(left);
            if total >= 1000 {
                b.set_length(total as u64);
                b.set_position((total - left) as u64);
                b.set_message(format!("{left} instances left"));
            }
        }
    };
    let result = elements::from_svg(&data, &name, &opts, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let inferred = match result {
        Ok(i) => i,
        Err(e) => {
            reporter.error(&e.to_string(), None);
            return 1;
        }
    };
    for s in &inferred.skipped {
        reporter.warning(&format!(
            "{name}: skipped {s} (only paths and shapes are elements)"
        ));
    }
    if args.stats {
        print_stats(args, &inferred.stats);
    }
    let st = &inferred.stats;
    let summary = format!(
        "{name}: {} elements of {} kind{}, {} rule{}",
        st.elements,
        st.kinds,
        if st.kinds == 1 { "" } else { "s" },
        st.rules,
        if st.rules == 1 { "" } else { "s" },
    );
    write_program(args.output.as_deref(), &inferred.text, &summary, reporter)
}

/// Whether the program goes to stdout (no `-o`, or `-o -`).
fn program_on_stdout(out: Option<&std::path::Path>) -> bool {
    out.is_none_or(|p| p.as_os_str() == "-")
}

/// `--stats` as one JSON object, by the rule `lsyc run` follows too: on
/// stdout, unless stdout carries the result itself (then on stderr, where it
/// is the same line in either error format).
fn print_stats(args: &Args, stats: &impl serde::Serialize) {
    let Ok(json) = serde_json::to_string(stats) else {
        return;
    };
    if program_on_stdout(args.output.as_deref()) {
        eprintln!("{json}");
    } else {
        println!("{json}");
    }
}

fn parse_weights(text: &str) -> Result<Weights, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        return Err("give four numbers, wn,wh,wphi,wl (for example 1,1,0.5,1)".into());
    }
    let mut v = [0.0; 4];
    for (k, p) in parts.iter().enumerate() {
        v[k] = p
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && (0.0..=1.0).contains(x))
            .ok_or_else(|| format!("`{p}` is not a weight between 0 and 1"))?;
    }
    Ok(Weights {
        n: v[0],
        h: v[1],
        phi: v[2],
        l: v[3],
    })
}

/// Refuses to write the program over its input: `Some(exit status)` if it would.
fn same_as_input(
    out: Option<&std::path::Path>,
    input: &std::path::Path,
    what: &str,
    reporter: &Reporter,
) -> Option<u8> {
    let out = out.filter(|p| !program_on_stdout(Some(p)))?;
    let same = match (std::fs::canonicalize(out), std::fs::canonicalize(input)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same {
        reporter.error(
            &format!("the output `{}` is the {what}", out.display()),
            Some("choose another file: lsyc never writes over its input"),
        );
        return Some(2);
    }
    None
}

fn read_input(path: &std::path::Path, name: &str, reporter: &Reporter) -> Result<Vec<u8>, u8> {
    let too_large = std::fs::metadata(path).is_ok_and(|m| m.len() > MAX_SVG_BYTES as u64);
    if too_large {
        reporter.error(
            &format!("`{name}` is larger than {} MiB", MAX_SVG_BYTES >> 20),
            None,
        );
        return Err(1);
    }
    std::fs::read(path).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::IsADirectory => "it is a directory".to_string(),
            _ => e.to_string(),
        };
        reporter.error(&format!("cannot read `{name}`: {why}"), None);
        1
    })
}

/// Writes the program to `out` (atomically) with a summary on stderr, or to stdout.
fn write_program(
    out: Option<&std::path::Path>,
    text: &str,
    summary: &str,
    reporter: &Reporter,
) -> u8 {
    match out.filter(|p| !program_on_stdout(Some(p))) {
        Some(out) => {
            if let Err(e) = source::write_atomic(out, text.as_bytes()) {
                reporter.error(&format!("cannot write `{}`: {e}", out.display()), None);
                return 1;
            }
            reporter.info(&format!("{summary}, wrote {}", out.display()));
        }
        None => {
            let _ = std::io::stdout().write_all(text.as_bytes());
        }
    }
    0
}

fn run_sketch(args: &Args, sketch: &std::path::Path, reporter: &Reporter) -> u8 {
    if let Some(e) = args.epsilon
        && !(e.is_finite() && e >= 0.0)
    {
        reporter.error(
            &format!("--epsilon must be a distance of 0 or more, not {e}"),
            None,
        );
        return 2;
    }
    if let Some(code) = same_as_input(args.output.as_deref(), sketch, "sketch", reporter) {
        return code;
    }
    let name = sketch.display().to_string();
    let data = match read_input(sketch, &name, reporter) {
        Ok(d) => d,
        Err(code) => return code,
    };
    let opts = Options {
        epsilon: args.epsilon,
        three_d: args.three_d,
        seed: args.seed,
    };
    let inferred = match sketch::from_svg(&data, &name, &opts) {
        Ok(i) => i,
        Err(e) => {
            reporter.error(&e.to_string(), None);
            return 1;
        }
    };
    let summary = format!(
        "{name}: {} strokes, {} productions after reduction",
        inferred.skeleton.branches.len(),
        inferred.analysis.reduced.len().max(1)
    );
    write_program(args.output.as_deref(), &inferred.text, &summary, reporter)
}
