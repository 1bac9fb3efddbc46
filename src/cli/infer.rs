//! `lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] [--3d]`: a tree sketch to a
//! recursive L-system (see `lsyc::infer`).
//!
//! Owns: the options, reading the sketch, where the program goes (stdout, or a
//! file written atomically, never over the sketch) and the exit statuses.

use super::Reporter;
use lsyc::infer::{self, MAX_SVG_BYTES, Options};
use lsyc::source;
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A drawing whose repeated elements to infer (not available yet; see --skeleton).
    #[arg(value_name = "ART.svg")]
    pub art: Option<PathBuf>,

    /// A tree sketch (SVG): each path, line or polyline is a branch, the first the trunk.
    #[arg(long, value_name = "SKETCH.svg")]
    pub skeleton: Option<PathBuf>,

    /// Where to write the program (default: stdout).
    #[arg(short = 'o', long = "output", value_name = "OUT.lsy")]
    pub output: Option<PathBuf>,

    /// Emit a 3D tree: children spread around their parent.
    #[arg(long = "3d")]
    pub three_d: bool,

    /// Douglas–Peucker tolerance in drawing units (default: 1.5% of the drawing's diagonal).
    #[arg(long, value_name = "E")]
    pub epsilon: Option<f64>,

    /// Seed of the random perturbation of the 3D spread.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    let Some(sketch) = &args.skeleton else {
        reporter.say(
            "error: `lsyc infer` needs --skeleton SKETCH.svg (a tree sketch): inferring repeated \
             elements from a drawing is a separate feature that is not available yet\n\
             usage: lsyc infer --skeleton SKETCH.svg [-o TREE.lsy] [--3d] [--epsilon E] [--seed N]",
        );
        return 2;
    };
    if let Some(art) = &args.art {
        reporter.say(&format!(
            "error: give the sketch once, after --skeleton (`{}` is extra): inferring repeated \
             elements from a drawing is a separate feature that is not available yet",
            art.display()
        ));
        return 2;
    }
    if let Some(e) = args.epsilon
        && !(e.is_finite() && e >= 0.0)
    {
        reporter.say(&format!(
            "error: --epsilon must be a distance of 0 or more, not {e}"
        ));
        return 2;
    }
    if let Some(out) = &args.output {
        let same = match (std::fs::canonicalize(out), std::fs::canonicalize(sketch)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if same {
            reporter.say(&format!(
                "error: the output `{}` is the sketch; choose another file",
                out.display()
            ));
            return 2;
        }
    }
    let name = sketch.display().to_string();
    let too_large = std::fs::metadata(sketch).is_ok_and(|m| m.len() > MAX_SVG_BYTES as u64);
    if too_large {
        reporter.say(&format!(
            "error: `{name}` is larger than {} MiB",
            MAX_SVG_BYTES >> 20
        ));
        return 1;
    }
    let data = match std::fs::read(sketch) {
        Ok(d) => d,
        Err(e) => {
            let why = match e.kind() {
                std::io::ErrorKind::NotFound => "no such file".to_string(),
                std::io::ErrorKind::IsADirectory => "it is a directory".to_string(),
                _ => e.to_string(),
            };
            reporter.say(&format!("error: cannot read `{name}`: {why}"));
            return 1;
        }
    };
    let opts = Options {
        epsilon: args.epsilon,
        three_d: args.three_d,
        seed: args.seed,
    };
    let inferred = match infer::skeleton_from_svg(&data, &name, &opts) {
        Ok(i) => i,
        Err(e) => {
            reporter.say(&format!("error: {e}"));
            return 1;
        }
    };
    match &args.output {
        Some(out) => {
            if let Err(e) = source::write_atomic(out, inferred.text.as_bytes()) {
                reporter.say(&format!("error: cannot write `{}`: {e}", out.display()));
                return 1;
            }
            reporter.say(&format!(
                "{name}: {} strokes, {} productions after reduction, wrote {}",
                inferred.skeleton.branches.len(),
                inferred.analysis.reduced.len().max(1),
                out.display()
            ));
        }
        None => {
            let _ = std::io::stdout().write_all(inferred.text.as_bytes());
        }
    }
    0
}
