//! The `lsyc` command line. All work happens in the library; this file only
//! hands the arguments to `cli`.

mod cli;

// Deriving and drawing make and free many small buffers from several threads
// at once (strings, drawings, pieces): mimalloc serves them faster than the
// system allocator.
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}
