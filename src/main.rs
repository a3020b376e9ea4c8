//! The `fbakit` command line: a thin layer over the library (see `src/cli/`).

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    restore_default_sigpipe();
    let argv: Vec<std::ffi::OsString> = std::env::args_os().collect();
    let json = cli::wants_json(&argv);
    match cli::Cli::try_parse_from(&argv) {
        Ok(args) => cli::run(args, json),
        // --help and --version are not errors: clap prints them and exits 0.
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) if json => {
            let text = e.to_string();
            let first = text
                .lines()
                .map(|l| l.trim_start_matches("error:").trim())
                .find(|l| !l.is_empty())
                .unwrap_or("bad usage")
                .to_string();
            cli::print_error(&first, cli::EXIT_BAD_INPUT, true)
        }
        Err(e) => e.exit(),
    }
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
