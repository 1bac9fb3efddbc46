//! The `lsyc` command line. All work happens in the library; this file only
//! hands the arguments to `cli`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
