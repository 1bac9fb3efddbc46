//! `lsyc fmt FILE [--write | --check]`: the canonical form of a program.

use super::Reporter;
use lsyc::{parser, source};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The .lsy files to format.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,

    /// Rewrite each file in place (atomically) if it is not canonical.
    #[arg(long, conflicts_with = "check")]
    pub write: bool,

    /// Print nothing; exit 1 if any file is not in canonical form.
    #[arg(long)]
    pub check: bool,
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    let mut status = 0;
    for path in &args.files {
        let Some(src) = super::read_program(path, reporter) else {
            status = 1;
            continue;
        };
        let parsed = parser::parse(&src.text);
        let mut diags = src.diagnostics;
        diags.extend(parsed.diagnostics);
        if diags.iter().any(|d| d.is_error()) {
            reporter.emit(&diags, &src.name, &src.text);
            reporter.info(&format!(
                "{}: not formatted, it has syntax errors",
                src.name
            ));
            status = 1;
            continue;
        }
        let out = lsyc::fmt::format_file(&parsed.file);
        if args.check {
            if out != src.text {
                reporter.info(&format!(
                    "{}: not in canonical form (run `lsyc fmt --write {}`)",
                    src.name, src.name
                ));
                status = 1;
            }
        } else if args.write {
            if out != src.text {
                if let Err(e) = source::write_atomic(path, out.as_bytes()) {
                    reporter.error(&format!("cannot write `{}`: {e}", src.name), None);
                    status = 1;
                } else {
                    reporter.info(&format!("{}: formatted", src.name));
                }
            }
        } else if !reporter.stdout(out.as_bytes()) {
            return 1;
        }
    }
    status
}
