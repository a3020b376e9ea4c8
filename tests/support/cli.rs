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

/// Runs `fbakit ARGS` (paths as they are), fails the test with its stderr unless it
/// succeeded, and returns that stderr (the warnings).
pub fn run_ok(args: &[&std::ffi::OsStr]) -> String {
    let out = command().args(args).output().expect("run fbakit");
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "fbakit {args:?}: {stderr}");
    stderr
}

/// `fbakit clone alma INPUT --fp-target FP -o OUT`, which must succeed; its stderr.
pub fn clone_alma_to(
    input: &std::path::Path,
    fp: &std::path::Path,
    out: &std::path::Path,
) -> String {
    run_ok(&[
        "clone".as_ref(),
        "alma".as_ref(),
        input.as_os_str(),
        "--fp-target".as_ref(),
        fp.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ])
}

/// `fbakit play FACE STREAM -o OUT`, which must succeed; its stderr.
pub fn play_to(face: &std::path::Path, stream: &std::path::Path, out: &std::path::Path) -> String {
    run_ok(&[
        "play".as_ref(),
        face.as_os_str(),
        stream.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ])
}

/// `fbakit face export INPUT -o OUT`, as it ended (for tests of refusals too).
pub fn face_export(input: &std::path::Path, out: &std::path::Path) -> Output {
    command()
        .args([
            "face".as_ref(),
            "export".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
        .output()
        .expect("run fbakit")
}
