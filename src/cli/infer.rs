//! `lsyc infer ART.svg [-o OUT.lsy]`: a line drawing to the D0L system that
//! draws it, or, when it is not a line drawing or no D0L system is found
//! within `--budget-ms`, a drawing of repeated elements to sequence and
//! branching rules (see `lsyc::infer::from_svg`, which chooses), and
//! `lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] [--3d]`: a tree sketch to a
//! recursive L-system (see `lsyc::infer::sketch`).
//!
//! Owns: the arguments and their checks (into one `infer::Options`), reading
//! the drawing, printing what inference tells (notes, warnings, `--stats`),
//! where the program goes (stdout, or a file written atomically, never over
//! the drawing) and the exit statuses. Must not choose what a drawing is:
//! `lsyc::infer` does.

use super::{Reporter, overwrite};
use lsyc::infer::elements::{self, rules::Weights};
use lsyc::infer::{self, MAX_SVG_BYTES, Options, Outcome, lines, sketch};
use lsyc::source;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

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

    /// The largest drawing read, in MiB (1 to 64: the readers are bounded for 64 MiB at most); a larger one is refused before it is read.
    #[arg(
        long,
        value_name = "N",
        default_value_t = MAX_INPUT_MIB,
        value_parser = clap::value_parser!(u64).range(1..=MAX_INPUT_MIB)
    )]
    pub max_input_mib: u64,
}

/// The most `--max-input-mib` allows (and its default): the readers' own limit.
const MAX_INPUT_MIB: u64 = (MAX_SVG_BYTES >> 20) as u64;

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    let (input, what) = match (&args.skeleton, &args.art) {
        (Some(sketch), _) => (sketch, "sketch"),
        (None, Some(art)) => (art, "drawing"),
        (None, None) => {
            reporter.error(
                "give a drawing to infer from",
                Some("lsyc infer ART.svg [-o OUT.lsy] (repeated elements), or lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] (a tree sketch)"),
            );
            return 2;
        }
    };
    let opts = match options(args) {
        Ok(o) => o,
        Err(why) => {
            reporter.error(&why, None);
            return 2;
        }
    };
    if let Some(code) = same_as_input(args.output.as_deref(), input, what, reporter) {
        return code;
    }
    let name = input.display().to_string();
    let data = match read_input(input, &name, args.max_input_mib, reporter) {
        Ok(d) => d,
        Err(code) => return code,
    };
    let inferred = if args.skeleton.is_some() {
        infer_sketch(&data, &name, &opts, reporter)
    } else {
        infer_drawing(args, &data, &name, &opts, reporter)
    };
    match inferred {
        Ok((text, summary)) => write_program(args.output.as_deref(), &text, &summary, reporter),
        Err(code) => code,
    }
}

/// The one `Options` of inference from the arguments, or what is wrong with
/// them.
fn options(args: &Args) -> Result<Options, String> {
    if let Some(e) = args.epsilon
        && !(e.is_finite() && e >= 0.0)
    {
        return Err(format!(
            "--epsilon must be a distance of 0 or more, not {e}"
        ));
    }
    if !(args.similarity.is_finite() && args.similarity > 0.0 && args.similarity < 1.0) {
        return Err(format!(
            "--similarity must be between 0 and 1 (a misfit relative to the element's size), not {}",
            args.similarity
        ));
    }
    if let Some(j) = args.jitter
        && !(j.is_finite() && j > 0.0 && j < 1.0)
    {
        return Err(format!(
            "--jitter must be between 0 and 1 (0.1: turns vary by ±3°, steps by ±10%), not {j}"
        ));
    }
    let weights = match &args.weights {
        Some(w) => parse_weights(w).map_err(|why| format!("--weights {w}: {why}"))?,
        None => Weights::default(),
    };
    Ok(Options {
        sketch: sketch::Options {
            epsilon: args.epsilon,
            three_d: args.three_d,
            seed: args.seed,
        },
        elements: elements::Options {
            weights,
            symmetrize: args.symmetrize,
            similarity: args.similarity,
            jitter: args.jitter,
            reflect: args.reflect,
        },
        lines: (!args.no_lines).then(|| lines::Options {
            budget: Duration::from_millis(args.budget_ms),
            ..lines::Options::default()
        }),
    })
}

/// `lsyc infer ART.svg`: the program and its summary, with what inference
/// tells printed on the way, or the exit status.
fn infer_drawing(
    args: &Args,
    data: &[u8],
    name: &str,
    opts: &Options,
    reporter: &Reporter,
) -> Result<(String, String), u8> {
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
    let outcome = infer::from_svg(data, name, opts, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let (lines, elements) = match outcome {
        Outcome::Lines(found) => {
            if args.stats {
                print_stats(args, &found.stats, reporter);
            }
            let summary = format!(
                "{name}: a line drawing of {} steps, drawn by a D0L system of {} rule{} at derive {}",
                found.redraw.steps,
                found.stats.rules,
                if found.stats.rules == 1 { "" } else { "s" },
                found.grammar.depth
            );
            return Ok((found.text, summary));
        }
        Outcome::Elements { lines, elements } => (lines, elements),
    };
    if let Some(gave_way) = lines {
        if args.stats {
            print_stats(args, &gave_way.stats, reporter);
        }
        reporter.note(&gave_way.note);
    }
    let inferred = elements.map_err(|e| {
        reporter.error(&e.to_string(), None);
        1
    })?;
    for s in &inferred.skipped {
        reporter.warning(&format!(
            "{name}: skipped {s} (only paths and shapes are elements)"
        ));
    }
    if args.stats {
        print_stats(args, &inferred.stats, reporter);
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
    Ok((inferred.text, summary))
}

/// `lsyc infer --skeleton SKETCH.svg`: the program and its summary, or the
/// exit status.
fn infer_sketch(
    data: &[u8],
    name: &str,
    opts: &Options,
    reporter: &Reporter,
) -> Result<(String, String), u8> {
    let inferred = sketch::from_svg(data, name, &opts.sketch).map_err(|e| {
        reporter.error(&e.to_string(), None);
        1
    })?;
    let summary = format!(
        "{name}: {} strokes, {} productions after reduction",
        inferred.skeleton.branches.len(),
        inferred.analysis.reduced.len().max(1)
    );
    Ok((inferred.text, summary))
}

/// Whether the program goes to stdout (no `-o`, or `-o -`).
fn program_on_stdout(out: Option<&std::path::Path>) -> bool {
    out.is_none_or(|p| p.as_os_str() == "-")
}

/// `--stats` as one JSON object, by the rule `lsyc run` follows too: on
/// stdout, unless stdout carries the result itself (then on stderr, where it
/// is the same line in either error format).
fn print_stats(args: &Args, stats: &impl serde::Serialize, reporter: &Reporter) {
    let Ok(json) = serde_json::to_string(stats) else {
        return;
    };
    if program_on_stdout(args.output.as_deref()) {
        reporter.stderr(&format!("{json}\n"));
    } else {
        reporter.stdout(format!("{json}\n").as_bytes());
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
    let mut inputs = overwrite::Inputs::default();
    inputs.add(input, format!("the {what}"));
    let clash =
        overwrite::check(out, "the output", overwrite::Made::Named, &inputs, false).err()?;
    reporter.error(&clash.to_string(), Some(clash.help()));
    Some(2)
}

/// Reads the drawing, refusing one over `max_mib` MiB: by its size before
/// reading when it has one, and in any case by reading at most one byte
/// more than the limit (a device or a pipe has no size to ask).
fn read_input(
    path: &std::path::Path,
    name: &str,
    max_mib: u64,
    reporter: &Reporter,
) -> Result<Vec<u8>, u8> {
    use std::io::Read;
    let limit = max_mib << 20;
    let cannot_read = |e: std::io::Error| {
        let why = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::IsADirectory => "it is a directory".to_string(),
            _ => e.to_string(),
        };
        reporter.error(&format!("cannot read `{name}`: {why}"), None);
        1
    };
    let too_large = |size: Option<u64>| {
        let size = size.map_or_else(String::new, |n| {
            format!("{:.1} MiB, ", n as f64 / f64::from(1 << 20))
        });
        let help = if max_mib < MAX_INPUT_MIB {
            format!("raise the limit with --max-input-mib (at most {MAX_INPUT_MIB})")
        } else {
            "lsyc infer reads drawings up to 64 MiB: infer a part of the drawing at a time"
                .to_string()
        };
        reporter.error(
            &format!("`{name}` is {size}over the {max_mib} MiB limit (--max-input-mib)"),
            Some(&help),
        );
        1
    };
    let file = std::fs::File::open(path).map_err(cannot_read)?;
    let size = file.metadata().map_err(cannot_read)?;
    if size.is_dir() {
        reporter.error(&format!("cannot read `{name}`: it is a directory"), None);
        return Err(1);
    }
    if size.len() > limit {
        return Err(too_large(Some(size.len())));
    }
    let mut data = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut data)
        .map_err(cannot_read)?;
    if data.len() as u64 > limit {
        return Err(too_large(None));
    }
    Ok(data)
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
            if !reporter.stdout(text.as_bytes()) {
                return 1;
            }
        }
    }
    0
}
