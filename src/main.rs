//! The `fbakit` command line: a thin layer over the library (see `src/cli/`).

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    restore_default_sigpipe();
    let args = cli::Cli::parse();
    cli::run(args)
}

/// Rust ignores SIGPIPE, which turns `fbakit ... | head` into a "failed printing" panic; a
/// command-line tool should simply stop when its reader goes away.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called once at start-up before any thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
