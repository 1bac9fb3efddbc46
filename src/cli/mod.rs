//! Command-line parsing (clap) and the commands.
//!
//! Owns: arguments, exit statuses (0 success, 1 an error in the input, 2 a usage
//! error) and where output goes: results on stdout, diagnostics on stderr.

mod check;
mod docs;
mod edit;
mod fmt;
mod infer;
mod lsp;
mod overwrite;
mod run;
mod studio;

use clap::{Parser, Subcommand, ValueEnum};
use lsyc::diagnostic::{self, Diagnostic, Format};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

const EXAMPLES: &str = "\
Examples:
  lsyc run lang-examples/koch-island.lsy -o koch.svg
  lsyc run lang-examples/plant-e.lsy -o plant.png --stats
  lsyc run lang-examples/palm.lsy -o palm.svg --guides
  lsyc run lang-examples/plant-e.lsy -o - | gzip > plant.svgz   # -o -: stdout
  lsyc completions bash > ~/.local/share/bash-completion/completions/lsyc
  lsyc man run | man -l -
  lsyc edit lang-examples/palm.lsy --by trunk3.v2=30,-5 --pin trunk2 --write
  lsyc infer art.svg -o art.lsy
  lsyc infer --skeleton sketch.svg -o tree.lsy
  lsyc check lang-examples/koch-island.lsy
  lsyc check tree.lsy -D depth=9 --error-format json
  lsyc fmt tree.lsy                 # print the canonical form
  lsyc fmt --write tree.lsy         # rewrite the file in place (atomically)
  lsyc fmt --check lang-examples/*.lsy";

/// lsyc: parametric Open L-systems — write .lsy programs, check, format and run them.
#[derive(Parser, Debug)]
#[command(name = "lsyc", version, about, after_help = EXAMPLES)]
pub struct Cli {
    /// When to colour diagnostics.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto, global = true)]
    pub color: ColorChoice,

    /// How to write diagnostics: for people, or one JSON object per line.
    #[arg(long, value_enum, default_value_t = ErrorFormat::Human, global = true)]
    pub error_format: ErrorFormat,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorChoice {
    Auto,
    Always,
    Never,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ErrorFormat {
    Human,
    Json,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Check a program and report every problem found (nothing is run).
    #[command(
        after_help = "Examples:\n  lsyc check plant.lsy\n  lsyc check plant.lsy -D delta=25\n  lsyc check plant.lsy --error-format json"
    )]
    Check(check::Args),
    /// Derive and draw a program: SVG, PNG, OBJ or text by the output's extension.
    #[command(
        after_help = "Examples:\n  lsyc run lang-examples/koch-island.lsy -o koch.svg\n  lsyc run lang-examples/plant-e.lsy -n 6 -o plant.png --size 800\n  lsyc run lang-examples/monopodial-tree.lsy -D r2=0.7 --stats\n  lsyc run lang-examples/hilbert-3d.lsy -o hilbert.obj\n  lsyc run lang-examples/stochastic-plant.lsy --seed 7 -o plant.svg"
    )]
    Run(run::Args),
    /// Print a program in canonical form (comments kept).
    #[command(
        after_help = "Examples:\n  lsyc fmt plant.lsy > tidy.lsy\n  lsyc fmt --write plant.lsy\n  lsyc fmt --check lang-examples/*.lsy"
    )]
    Fmt(fmt::Args),
    /// Infer a program from a drawing: a line drawing becomes the D0L system that draws it, repeated elements become sequence and branching rules; `--skeleton SKETCH.svg` turns a tree sketch into a recursive L-system.
    #[command(
        after_help = "Examples:\n  lsyc infer koch.svg -o koch.lsy        # a line drawing: its D0L system\n  lsyc infer windows.svg -o windows.lsy\n  lsyc infer noisy.svg --symmetrize -o regular.lsy\n  lsyc infer --skeleton sketch.svg -o tree.lsy\n  lsyc infer --skeleton sketch.svg --3d --seed 7 -o tree3d.lsy"
    )]
    Infer(infer::Args),
    /// Edit a scene's guides with a mass-spring system: drag vertices, move, rotate, scale guides.
    #[command(
        after_help = "Examples:\n  lsyc edit palm.lsy --move frond4.v4=100,480 --pin trunk1\n  lsyc edit palm.lsy --by trunk3.v2=30,-5 --pin trunk2\n  lsyc edit palm.lsy --pin trunk1 --translate frond1=10,0 --rotate frond1=15 --write"
    )]
    Edit(edit::Args),
    /// Print a shell completion script: bash, zsh, fish, elvish or powershell.
    #[command(
        after_help = "Examples:\n  lsyc completions bash > ~/.local/share/bash-completion/completions/lsyc\n  lsyc completions zsh > ~/.zfunc/_lsyc\n  lsyc completions fish > ~/.config/fish/completions/lsyc.fish"
    )]
    Completions(docs::CompletionsArgs),
    /// Print a manual page (roff), generated from this command line's own help.
    #[command(
        after_help = "Examples:\n  lsyc man | man -l -\n  lsyc man run | man -l -\n  lsyc man > lsyc.1"
    )]
    Man(docs::ManArgs),
    /// A Language Server on stdin and stdout, for editors (docs/lsp.md).
    #[command(
        after_help = "Examples:\n  lsyc lsp       # started by an editor's LSP client; see editors/README.md"
    )]
    Lsp(lsp::Args),
    /// A live editor in the browser: edit, slide constants, step through growth, drag guides.
    #[command(
        after_help = "Examples:\n  lsyc studio lang-examples/palm.lsy\n  lsyc studio plant.lsy --port 0 --no-open"
    )]
    Studio(studio::Args),
}

/// Where diagnostics go and how they look; remembers a failed write, so that
/// a command whose messages or results could not be written never exits 0.
pub struct Reporter {
    format: Format,
    failed: std::cell::Cell<bool>,
}

impl Reporter {
    fn new(cli: &Cli) -> Reporter {
        let format = match cli.error_format {
            ErrorFormat::Json => Format::Json,
            ErrorFormat::Human => Format::Human {
                color: match cli.color {
                    ColorChoice::Always => true,
                    ColorChoice::Never => false,
                    ColorChoice::Auto => {
                        std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
                    }
                },
            },
        };
        Reporter {
            format,
            failed: std::cell::Cell::new(false),
        }
    }

    /// Whether a write to stdout or stderr has failed (a full disk, a closed
    /// pipe): the exit status is then 1 whatever the command did.
    pub fn write_failed(&self) -> bool {
        self.failed.get()
    }

    /// Writes `text` to stderr; a failure is remembered, never a panic.
    pub fn stderr(&self, text: &str) {
        let mut err = std::io::stderr().lock();
        if err
            .write_all(text.as_bytes())
            .and_then(|()| err.flush())
            .is_err()
        {
            self.failed.set(true);
        }
    }

    /// Writes a result to stdout and flushes it; on failure says so on
    /// stderr (where that still works) and returns false.
    pub fn stdout(&self, bytes: &[u8]) -> bool {
        let mut out = std::io::stdout().lock();
        match out.write_all(bytes).and_then(|()| out.flush()) {
            Ok(()) => true,
            Err(e) => {
                self.failed.set(true);
                self.error(&format!("cannot write to stdout: {e}"), None);
                false
            }
        }
    }

    /// Writes diagnostics about `source` (named `file`) to stderr.
    pub fn emit(&self, diags: &[Diagnostic], file: &str, source: &str) {
        if diags.is_empty() {
            return;
        }
        let text = diagnostic::render(diags, file, source, self.format);
        self.stderr(&text);
    }

    pub fn is_json(&self) -> bool {
        self.format == Format::Json
    }

    /// An error without a place in a program (a usage error, a file that
    /// cannot be read or written), with an optional hint.
    pub fn error(&self, msg: &str, help: Option<&str>) {
        self.line(Line::Error, msg, help);
    }

    pub fn warning(&self, msg: &str) {
        self.line(Line::Warning, msg, None);
    }

    pub fn note(&self, msg: &str) {
        self.line(Line::Note, msg, None);
    }

    /// A summary of what a command did ("koch.lsy: no problems found").
    pub fn info(&self, msg: &str) {
        self.line(Line::Info, msg, None);
    }

    /// One line on stderr: `error: …` for a person, one JSON object per line
    /// (`{"severity": …, "message": …, "help": …}`) for a tool, so that every
    /// line a command writes to stderr honours `--error-format json`.
    fn line(&self, kind: Line, msg: &str, help: Option<&str>) {
        if self.is_json() {
            let mut v = serde_json::json!({ "severity": kind.name(), "message": msg });
            if let Some(h) = help {
                v["help"] = serde_json::Value::from(h);
            }
            self.stderr(&format!("{v}\n"));
            return;
        }
        let mut text = match kind {
            Line::Info => format!("{msg}\n"),
            _ => format!("{}: {msg}\n", kind.name()),
        };
        if let Some(h) = help {
            text.push_str(&format!("  help: {h}\n"));
        }
        self.stderr(&text);
    }
}

/// The kinds of one-line messages.
#[derive(Clone, Copy)]
enum Line {
    Error,
    Warning,
    Note,
    Info,
}

impl Line {
    fn name(self) -> &'static str {
        match self {
            Line::Error => "error",
            Line::Warning => "warning",
            Line::Note => "note",
            Line::Info => "info",
        }
    }
}

pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            let shown = matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion);
            if !shown && json_requested() {
                // A usage error honours `--error-format json` too: one object.
                let text = e.to_string();
                let mut lines = text.lines().filter(|l| !l.trim().is_empty());
                let message = lines
                    .next()
                    .unwrap_or("")
                    .trim_start_matches("error: ")
                    .to_string();
                let rest: Vec<&str> = lines.map(str::trim).collect();
                let v = serde_json::json!({
                    "severity": "error",
                    "message": message,
                    "help": rest.join(" "),
                });
                let _ = writeln!(std::io::stderr(), "{v}");
                return ExitCode::from(2);
            }
            // `--help > /dev/full` is a failed write, not a success.
            let printed = e.print().and_then(|()| std::io::stdout().flush());
            return match (shown, printed) {
                (true, Ok(())) => ExitCode::SUCCESS,
                (true, Err(_)) => ExitCode::from(1),
                (false, _) => ExitCode::from(2),
            };
        }
    };
    let reporter = Reporter::new(&cli);
    if matches!(
        cli.command,
        Command::Run(_) | Command::Fmt(_) | Command::Infer(_) | Command::Edit(_)
    ) {
        remove_temp_files_on_interrupt();
    }
    let status = match &cli.command {
        Command::Check(args) => check::run(args, &reporter),
        Command::Fmt(args) => fmt::run(args, &reporter),
        Command::Run(args) => run::run(args, &reporter),
        Command::Infer(args) => infer::run(args, &reporter),
        Command::Edit(args) => edit::run(args, &reporter),
        Command::Completions(args) => docs::completions(args, &reporter),
        Command::Man(args) => docs::man(args, &reporter),
        Command::Lsp(args) => lsp::run(args),
        Command::Studio(args) => studio::run(args, &reporter),
    };
    if status == 0 && reporter.write_failed() {
        return ExitCode::from(1);
    }
    ExitCode::from(status)
}

/// Ctrl-C (and SIGTERM, SIGHUP) during a write: the temporary files of the
/// writes under way are removed and lsyc exits with status 130, so that an
/// interrupted `-o` leaves the old file and nothing else. (The studio and the
/// language server handle their own ending.)
fn remove_temp_files_on_interrupt() {
    let _ = ctrlc::set_handler(|| {
        lsyc::write::remove_temp_files();
        std::process::exit(130);
    });
}

/// Whether the raw arguments ask for JSON messages (read before clap has
/// understood them, for clap's own usage errors).
fn json_requested() -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter().enumerate().any(|(i, a)| {
        a == "--error-format=json"
            || (a == "--error-format" && args.get(i + 1).is_some_and(|v| v == "json"))
    })
}

/// Counts for a summary line: "2 errors, 1 warning".
pub fn summary(diags: &[Diagnostic]) -> String {
    let errors = diags.iter().filter(|d| d.is_error()).count();
    let warnings = diags.len() - errors;
    let part = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    match (errors, warnings) {
        (0, 0) => "no problems found".to_string(),
        (0, w) => part(w, "warning"),
        (e, 0) => part(e, "error"),
        (e, w) => format!("{}, {}", part(e, "error"), part(w, "warning")),
    }
}

/// Reads a program for `run`, `check` and `fmt`, reporting why not (exit 1):
/// a file that cannot be read, or a drawing given where a program belongs (one
/// clear error pointing at `lsyc infer`, not a cascade of parse errors).
pub fn read_program(path: &std::path::Path, reporter: &Reporter) -> Option<lsyc::source::Source> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("svg" | "svgz")) {
        refuse_drawing(&name, reporter);
        return None;
    }
    let src = match lsyc::source::read(path) {
        Ok(s) => s,
        Err(d) => {
            reporter.emit(&[d], &name, "");
            return None;
        }
    };
    if looks_like_svg(&src.text) {
        refuse_drawing(&name, reporter);
        return None;
    }
    Some(src)
}

/// Whether a text is an SVG document: it starts (after a byte-order mark and
/// blank space) with an XML declaration, an SVG doctype or an `<svg` element.
fn looks_like_svg(text: &str) -> bool {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    t.starts_with("<?xml") || t.starts_with("<svg") || t.starts_with("<!DOCTYPE svg")
}

fn refuse_drawing(name: &str, reporter: &Reporter) {
    let path = std::path::Path::new(name);
    let stem = path
        .file_stem()
        .map_or("art".into(), |s| s.to_string_lossy());
    // Never suggest writing over the drawing itself.
    let out = if path.extension().is_some_and(|e| e == "lsy") {
        format!("{stem}-inferred.lsy")
    } else {
        format!("{stem}.lsy")
    };
    reporter.error(
        &format!("`{name}` is a drawing (SVG), not an .lsy program"),
        Some(&format!(
            "to turn a drawing into a program, run `lsyc infer {name} -o {out}`"
        )),
    );
}
