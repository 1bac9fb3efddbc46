//! `lsyc check FILE`: diagnostics only.

use super::{Reporter, summary};
use lsyc::check::Override;
use lsyc::diagnostic::{Code, Diagnostic};
use lsyc::frontend;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The .lsy files to check.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,

    /// Override a constant: -D NAME=VALUE (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    pub define: Vec<String>,
}

/// Parses the `-D` values; malformed ones are reported as E0506.
pub fn overrides(define: &[String]) -> Result<Vec<Override>, Diagnostic> {
    define
        .iter()
        .map(|d| {
            Override::parse(d).map_err(|msg| {
                Diagnostic::error(Code::BadOverride, msg)
                    .help("write it as -D NAME=VALUE, e.g. -D depth=7")
            })
        })
        .collect()
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    let ovr = match overrides(&args.define) {
        Ok(o) => o,
        Err(d) => {
            reporter.emit(&[d], "<command line>", "");
            return 2;
        }
    };
    let mut status = 0;
    for path in &args.files {
        let Some(src) = super::read_program(path, reporter) else {
            status = 1;
            continue;
        };
        let fe = frontend::run(&src.text, src.diagnostics, &ovr);
        reporter.emit(&fe.diagnostics, &src.name, &src.text);
        if fe.has_errors() {
            status = 1;
        }
        reporter.info(&format!("{}: {}", src.name, summary(&fe.diagnostics)));
    }
    status
}
