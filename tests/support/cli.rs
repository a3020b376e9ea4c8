//! Running the real `fbakit` binary from a test, in the crate's directory (so `samples/...`
//! paths work).

use std::process::{Command, Output};

/// Runs `fbakit ARGS` and returns its output.
pub fn fbakit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run fbakit")
}

/// Output bytes as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs `fbakit ARGS` in `dir` (for commands that read or write relative paths there).
pub fn fbakit_in(dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run fbakit")
}

/// The `fbakit` binary as a [`Command`] in the crate's directory, for arguments that are
/// paths rather than text.
pub fn command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_fbakit"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}
