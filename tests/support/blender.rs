//! Blender (`$BLENDER` or `blender` on the path, with numpy) run in the background on a test
//! script from `tests/support/`. Without it a test prints a note and skips, unless
//! `$BLENDER_REQUIRED` is set (as `.ci/run` does once it installed Blender).

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// Runs `blender -b --factory-startup --python tests/support/SCRIPT -- ARGS...` and returns its
/// standard output, or `None` (with a note) when Blender or numpy is missing.
pub fn run_script(script: &str, args: &[&Path]) -> Option<String> {
    let required = std::env::var_os("BLENDER_REQUIRED").is_some();
    let blender = std::env::var_os("BLENDER").unwrap_or_else(|| "blender".into());
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/support")
        .join(script);
    let out = Command::new(&blender)
        .args([
            "-b",
            "--factory-startup",
            "--python-exit-code",
            "1",
            "--python",
        ])
        .arg(script)
        .arg("--")
        .args(args)
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            assert!(
                !required,
                "Blender required but cannot run {blender:?} ({e})"
            );
            eprintln!("note: skipping the Blender part: cannot run {blender:?} ({e})");
            return None;
        }
    };
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if out.status.code() == Some(3) {
        let why = String::from_utf8_lossy(&out.stderr);
        assert!(!required, "Blender required but: {why}");
        eprintln!("note: skipping the Blender part: {}", why.trim());
        return None;
    }
    assert!(
        out.status.success(),
        "Blender failed: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(stdout)
}

/// Blender's report per file (`blender_import.py`: objects, vertex counts, shape keys, bones,
/// actions, images), or `None` (with a note) when Blender is missing.
pub fn import_in_blender(files: &[&PathBuf]) -> Option<Vec<Value>> {
    let paths: Vec<&Path> = files.iter().map(|f| f.as_path()).collect();
    let stdout = run_script("blender_import.py", &paths)?;
    let reports: Vec<Value> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("FBAKIT_JSON "))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), files.len(), "{stdout}");
    for r in &reports {
        assert!(r.get("error").is_none(), "{}: {}", r["file"], r["error"]);
        eprintln!("{}", summary(r));
    }
    Some(reports)
}

/// One line per file (shown with `--nocapture` or on failure).
pub fn summary(r: &Value) -> String {
    let objects: Vec<String> = r["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| match o["type"].as_str().unwrap() {
            "MESH" => format!(
                "{} {} v/{} keys",
                o["name"],
                o["vertices"],
                o["shapeKeys"].as_array().map_or(0, Vec::len)
            ),
            "ARMATURE" => format!("{} ({} bones)", o["name"], o["bones"]),
            t => format!("{} {t}", o["name"]),
        })
        .collect();
    let actions: Vec<&str> = r["actions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    format!(
        "{}: [{}]; actions {actions:?}",
        r["file"],
        objects.join(", ")
    )
}
