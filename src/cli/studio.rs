//! `lsyc studio FILE.lsy`: serve the live editor on 127.0.0.1 and print its
//! address as the first line on stdout.

use super::Reporter;
use lsyc::studio::Studio;
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The .lsy program to edit (created empty if it does not exist).
    pub file: PathBuf,

    /// The port to listen on (127.0.0.1 only); 0 picks a free one.
    #[arg(long, default_value_t = 7878)]
    pub port: u16,

    /// Stop a run with an error before a step would hold more modules than this
    /// (lower than `lsyc run`'s: every drawing goes to the browser).
    #[arg(long, default_value_t = lsyc::studio::protocol::MAX_MODULES)]
    pub max_modules: usize,

    /// Do not open a web browser.
    #[arg(long)]
    pub no_open: bool,
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    if !args.file.exists()
        && let Err(e) = lsyc::source::write_atomic(&args.file, b"")
    {
        reporter.error(
            &format!("cannot create `{}`: {e}", args.file.display()),
            None,
        );
        return 1;
    }
    if let Err(d) = lsyc::source::read(&args.file) {
        reporter.emit(&[d], &args.file.display().to_string(), "");
        return 1;
    }
    let studio = match Studio::bind(&args.file, args.port, args.max_modules) {
        Ok(s) => s,
        Err(e) => {
            reporter.error(
                &e,
                Some("choose another port with --port, or --port 0 for any free one"),
            );
            return 1;
        }
    };
    let url = studio.url();
    let mut out = std::io::stdout();
    let _ = writeln!(out, "lsyc studio: {url}");
    let _ = out.flush();
    reporter.info(&format!(
        "editing {}; stop with Ctrl-C",
        args.file.display()
    ));
    if !args.no_open {
        // Opening a browser is a convenience: the address is printed either way.
        let _ = std::process::Command::new("xdg-open")
            .arg(&url)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn();
    }
    match studio.serve() {
        Ok(()) => 0,
        Err(e) => {
            reporter.error(&e, None);
            1
        }
    }
}
