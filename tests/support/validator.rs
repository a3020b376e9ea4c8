//! The Khronos glTF validator (npm `gltf-validator`, found through `$GLTF_VALIDATOR_DIR` or
//! node_modules) run on written files by `tests/support/validate-gltf.mjs`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One report per file (JSON objects with `errors`, `warnings`, ...), or `None` with a note
/// when node or the validator package is not installed.
pub fn validate(files: &[PathBuf]) -> Option<Vec<serde_json::Value>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/support/validate-gltf.mjs");
    let out = match Command::new("node").arg(script).args(files).output() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("note: skipping glTF validation: cannot run node ({e})");
            return None;
        }
    };
    if out.status.code() == Some(3) {
        eprintln!(
            "note: skipping glTF validation: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
        return None;
    }
    assert!(
        out.status.success(),
        "validator script failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reports: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), files.len());
    Some(reports)
}

/// The codes of a report's errors and warnings (severities 0 and 1; infos and hints left
/// out), sorted, one entry per message.
pub fn issue_codes(r: &serde_json::Value) -> Vec<String> {
    let mut codes: Vec<String> = r["messages"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|m| {
            let mut words = m.as_str()?.split_whitespace();
            let severity: u8 = words.next()?.parse().ok()?;
            (severity <= 1).then(|| words.next().unwrap_or("").to_string())
        })
        .collect();
    codes.sort();
    codes
}
