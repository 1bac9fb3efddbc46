//! `lsyc completions SHELL` and `lsyc man`: what a shell and `man` need,
//! generated from the one clap definition of the command line (so they can
//! never disagree with `--help`).

use super::{Cli, Reporter};
use clap::CommandFactory;

#[derive(clap::Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Writes the completion script for `args.shell` to stdout.
pub fn completions(args: &CompletionsArgs, reporter: &Reporter) -> u8 {
    let mut cmd = Cli::command();
    let mut out = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, "lsyc", &mut out);
    write_stdout(&out, reporter)
}

#[derive(clap::Args, Debug)]
pub struct ManArgs {
    /// A command's own page (`lsyc man run` is lsyc-run(1)); without it, lsyc(1).
    #[arg(value_name = "COMMAND")]
    pub command: Option<String>,
}

/// Writes a manual page (roff) to stdout.
pub fn man(args: &ManArgs, reporter: &Reporter) -> u8 {
    let mut cmd = Cli::command();
    cmd.build();
    let page = match &args.command {
        None => cmd,
        Some(name) => match cmd.find_subcommand(name) {
            Some(sub) => sub.clone(),
            None => {
                let names: Vec<&str> = cmd.get_subcommands().map(|s| s.get_name()).collect();
                reporter.error(
                    &format!("lsyc has no command `{name}`"),
                    Some(&format!("the commands are: {}", names.join(", "))),
                );
                return 2;
            }
        },
    };
    let mut out = Vec::new();
    if let Err(e) = clap_mangen::Man::new(page)
        .source(format!("lsyc {}", env!("CARGO_PKG_VERSION")))
        .manual("lsyc manual")
        .render(&mut out)
    {
        reporter.error(&format!("cannot render the manual page: {e}"), None);
        return 1;
    }
    write_stdout(&out, reporter)
}

/// The page or script on stdout: exit 1 when it could not be written (a full
/// disk, a closed pipe), with a message where one can still be written.
fn write_stdout(bytes: &[u8], reporter: &Reporter) -> u8 {
    if reporter.stdout(bytes) { 0 } else { 1 }
}
