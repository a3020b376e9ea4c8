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
