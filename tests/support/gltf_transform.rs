//! The `gltf-transform` command line (npm `@gltf-transform/cli`), which rewrites test assets
//! the way users' tools do (quantize, meshopt, draco, weld, reorder). Found through
//! `$GLTF_TRANSFORM_DIR` (an `npm install --prefix DIR @gltf-transform/cli` folder), else on
//! `PATH`; absent, tests print a note and skip, unless `FBAKIT_REQUIRE_GLTF_TRANSFORM=1`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The program to run, or `None` (with a note) when it is not installed.
pub fn find() -> Option<PathBuf> {
    let candidates = std::env::var_os("GLTF_TRANSFORM_DIR")
        .map(|d| PathBuf::from(d).join("node_modules/.bin/gltf-transform"))
        .into_iter()
        .chain(std::iter::once(PathBuf::from("gltf-transform")));
    for c in candidates {
        if Command::new(&c)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Some(c);
        }
    }
    let why = "gltf-transform not found (set GLTF_TRANSFORM_DIR to an \
               `npm install --prefix DIR @gltf-transform/cli` folder)";
    assert!(
        std::env::var_os("FBAKIT_REQUIRE_GLTF_TRANSFORM").is_none(),
        "FBAKIT_REQUIRE_GLTF_TRANSFORM is set but {why}"
    );
    eprintln!("note: skipping: {why}");
    None
}

/// Runs `gltf-transform COMMAND INPUT OUTPUT ARGS…` and returns `output`.
pub fn run(program: &Path, command: &str, input: &Path, output: &Path, args: &[&str]) -> PathBuf {
    let out = Command::new(program)
        .arg(command)
        .arg(input)
        .arg(output)
        .args(args)
        .output()
        .expect("run gltf-transform");
    assert!(
        out.status.success(),
        "gltf-transform {command} failed: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    output.to_path_buf()
}
