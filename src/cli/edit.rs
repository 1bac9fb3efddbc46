//! `lsyc edit SCENE.lsy --move GUIDE.vK=X,Y …`: mass-spring editing of guides.
//!
//! The operations apply in the order given (clap's argument indices keep it, so
//! `Args` implements clap's traits by hand). The updated program goes to stdout,
//! or `--write` rewrites the file atomically; a one-line summary goes to stderr.

use super::Reporter;
use clap::{Arg, ArgAction, ArgMatches, Command};
use lsyc::edit::{self, EditError, Op};
use lsyc::{frontend, source};
use std::path::PathBuf;

#[derive(Debug)]
pub struct Args {
    pub file: PathBuf,
    pub write: bool,
    pub scene: Option<String>,
    pub move_seeds: bool,
    /// The operations, in command-line order.
    pub ops: Vec<Op>,
}

type Parser = fn(&str) -> Result<Op, String>;

/// The operation flags: id, value name, help, parser.
const OPS: &[(&str, &str, &str, Parser)] = &[
    (
        "move",
        "GUIDE.vK=X,Y",
        "Drag vertex K (from 0) of a guide to (X, Y)",
        edit::parse_move,
    ),
    (
        "by",
        "GUIDE.vK=DX,DY",
        "Drag vertex K of a guide by (DX, DY)",
        edit::parse_by,
    ),
    (
        "translate",
        "GUIDE=DX,DY",
        "Move a whole guide by (DX, DY)",
        edit::parse_translate,
    ),
    (
        "rotate",
        "GUIDE=DEG",
        "Rotate a guide counter-clockwise by DEG degrees about its centroid",
        edit::parse_rotate,
    ),
    (
        "scale",
        "GUIDE=K",
        "Scale a guide by K (> 0) about its centroid",
        edit::parse_scale,
    ),
    (
        "pin",
        "GUIDE[.vK]",
        "Hold a vertex (or a whole guide) where it is while the rest relaxes",
        edit::parse_pin,
    ),
    (
        "stiff",
        "A.vI=B.vJ",
        "Add a stiff spring between two vertices (of the same or different guides)",
        edit::parse_stiff,
    ),
];

impl clap::FromArgMatches for Args {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let file = m
            .get_one::<PathBuf>("file")
            .cloned()
            .ok_or_else(|| clap::Error::new(clap::error::ErrorKind::MissingRequiredArgument))?;
        let mut ops: Vec<(usize, Op)> = Vec::new();
        for (id, ..) in OPS {
            if let (Some(values), Some(indices)) = (m.get_many::<Op>(id), m.indices_of(id)) {
                ops.extend(indices.zip(values.cloned()));
            }
        }
        ops.sort_by_key(|(i, _)| *i);
        Ok(Args {
            file,
            write: m.get_flag("write"),
            scene: m.get_one::<String>("scene").cloned(),
            move_seeds: m.get_flag("move-seeds"),
            ops: ops.into_iter().map(|(_, op)| op).collect(),
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for Args {
    fn augment_args(cmd: Command) -> Command {
        let mut cmd = cmd
            .arg(
                Arg::new("file")
                    .value_name("SCENE.lsy")
                    .required(true)
                    .value_parser(clap::value_parser!(PathBuf))
                    .help("The program holding the scene"),
            )
            .arg(
                Arg::new("write")
                    .long("write")
                    .action(ArgAction::SetTrue)
                    .help("Rewrite the file in place (atomically) instead of printing it"),
            )
            .arg(
                Arg::new("scene")
                    .long("scene")
                    .value_name("NAME")
                    .help("Which scene of the file to edit (default: the first)"),
            )
            .arg(
                Arg::new("move-seeds")
                    .long("move-seeds")
                    .action(ArgAction::SetTrue)
                    .help("Carry the seeds of a moved guide along (position and heading)"),
            );
        for &(id, value_name, help, parser) in OPS {
            cmd = cmd.arg(
                Arg::new(id)
                    .long(id)
                    .value_name(value_name)
                    .action(ArgAction::Append)
                    .allow_hyphen_values(true)
                    .value_parser(parser)
                    .help(help),
            );
        }
        cmd
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    let src = match source::read(&args.file) {
        Ok(s) => s,
        Err(d) => {
            reporter.emit(&[d], &args.file.display().to_string(), "");
            return 1;
        }
    };
    let fe = frontend::run(&src.text, src.diagnostics, &[]);
    let checked = match fe.checked.as_ref() {
        Some(c) if !fe.has_errors() => c,
        _ => {
            reporter.emit(&fe.diagnostics, &src.name, &src.text);
            reporter.info(&format!("{}: not edited, it has errors", src.name));
            return 1;
        }
    };
    let mut file = fe.file.clone();
    let options = edit::Options {
        scene: args.scene.clone(),
        move_seeds: args.move_seeds,
    };
    let outcome = match edit::edit(&mut file, checked, &args.ops, &options) {
        Ok(o) => o,
        Err(EditError::Input(msg)) => {
            reporter.error(&format!("{}: {msg}", src.name), None);
            return 1;
        }
        Err(EditError::Usage(msg, hint)) => {
            reporter.error(&msg, hint.as_deref());
            return 2;
        }
    };
    for r in &outcome.replaced {
        reporter.note(&format!("{r} (its expression was replaced by the number)"));
    }
    for w in &outcome.warnings {
        reporter.warning(w);
    }
    if !outcome.converged {
        reporter.warning(&format!(
            "the spring system did not settle in {} iteration{}; the positions are the last ones",
            outcome.iterations,
            if outcome.iterations == 1 { "" } else { "s" }
        ));
    }
    let out = lsyc::fmt::format_file(&file);
    let changed = if outcome.changed.is_empty() {
        "no guide changed".to_string()
    } else {
        let list: Vec<String> = outcome
            .changed
            .iter()
            .map(|(g, n)| format!("{g} ({n} vert{})", if *n == 1 { "ex" } else { "ices" }))
            .collect();
        const SHOWN: usize = 8;
        if list.len() > SHOWN {
            format!(
                "changed {} and {} more guides",
                list[..SHOWN].join(", "),
                list.len() - SHOWN
            )
        } else {
            format!("changed {}", list.join(", "))
        }
    };
    let changed = match outcome.seeds_moved {
        0 => changed,
        1 => format!("{changed}, 1 seed carried along"),
        n => format!("{changed}, {n} seeds carried along"),
    };
    let summary = format!(
        "{}: scene {}: {changed}; {} particles, {} springs, {} relaxed in {} iteration{}",
        src.name,
        outcome.scene,
        outcome.particles,
        outcome.springs,
        outcome.free,
        outcome.iterations,
        if outcome.iterations == 1 { "" } else { "s" }
    );
    if args.write {
        if out != src.text
            && let Err(e) = source::write_atomic(&args.file, out.as_bytes())
        {
            reporter.error(&format!("cannot write `{}`: {e}", src.name), None);
            return 1;
        }
        reporter.info(&summary);
    } else {
        if !reporter.stdout(out.as_bytes()) {
            return 1;
        }
        reporter.info(&summary);
    }
    0
}
