//! `lsyc lsp`: the language server on stdin and stdout (docs/lsp.md).

use std::io::{BufReader, BufWriter};

#[derive(clap::Args, Debug)]
pub struct Args {}

/// Serves one client; exits 0 after `shutdown` and `exit`, 1 otherwise.
pub fn run(_args: &Args) -> u8 {
    let stdout = std::io::stdout();
    let input = BufReader::new(std::io::stdin());
    match lsyc::lsp::serve_threaded(input, BufWriter::new(stdout.lock())) {
        Ok(lsyc::lsp::End::Clean) => 0,
        Ok(lsyc::lsp::End::Abrupt) => 1,
        Err(e) => {
            eprintln!("lsyc lsp: {e}");
            1
        }
    }
}
