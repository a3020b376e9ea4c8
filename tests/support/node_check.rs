//! Running a `tests/support/*.mjs` browser check under `node`: npm prefix directories
//! defaulted to `target/…` where they exist, exit code 3 (a package or the browser missing)
//! turned into a skip note, unless the environment variable `required` is set (CI sets it
//! once it installed the tools), in which case a missing tool fails the test.

use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;

/// The check's stdout, or `None` (with a note naming `what`) when a tool is missing.
/// `dirs`: `(environment variable, default under the checkout)` for each npm prefix.
pub fn run_node_check<I, S>(
    script: &str,
    args: I,
    dirs: &[(&str, &str)],
    required: &str,
    what: &str,
) -> Option<String>
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let required = std::env::var_os(required).is_some();
    let skip = |why: String| {
        assert!(!required, "{what} test required but: {why}");
        eprintln!("note: skipping {what} test: {why}");
        None
    };
    let mut cmd = Command::new("node");
    cmd.arg(root.join("tests/support").join(script)).args(args);
    for (var, local) in dirs {
        if std::env::var_os(var).is_none() && root.join(local).is_dir() {
            cmd.env(var, root.join(local));
        }
    }
    let out = match cmd.output() {
        Ok(o) => o,
        Err(e) => return skip(format!("cannot run node ({e})")),
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.code() == Some(3) {
        return skip(stderr.trim().to_string());
    }
    assert!(out.status.success(), "{what} check failed: {stderr}");
    Some(String::from_utf8(out.stdout).expect("the check prints UTF-8"))
}
