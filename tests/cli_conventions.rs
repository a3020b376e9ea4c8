//! The command line follows the conventions a careful user expects: help with examples, man
//! pages and completions, `--json` everywhere (errors included), warnings once on stderr,
//! timings only on request, exit code 2 for bad usage or input, messages that name the
//! file or the option.

use std::path::Path;

mod support;
use support::cli::{fbakit, text};

/// The subcommand names listed under `Commands:` in a help text (without `help`).
fn subcommands(help: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut inside = false;
    for line in help.lines() {
        if line.trim_end() == "Commands:" {
            inside = true;
            continue;
        }
        if inside {
            if !line.starts_with("  ") {
                break;
            }
            if let Some(name) = line.split_whitespace().next() {
                if name != "help" && !line.starts_with("   ") {
                    names.push(name.to_string());
                }
            }
        }
    }
    names
}

/// Every leaf command as its word path (`["face", "info"]`).
fn leaf_commands() -> Vec<Vec<String>> {
    let mut leaves = Vec::new();
    let mut todo = vec![Vec::<String>::new()];
    while let Some(path) = todo.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let help = text(&fbakit(&args).stdout);
        let subs = subcommands(&help);
        if subs.is_empty() {
            leaves.push(path);
        } else {
            for s in subs {
                let mut p = path.clone();
                p.push(s);
                todo.push(p);
            }
        }
    }
    leaves.sort();
    leaves
}

#[test]
fn top_level_help_describes_the_toolkit_with_examples() {
    let out = fbakit(&["--help"]);
    assert!(out.status.success());
    let help = text(&out.stdout);
    assert!(help.contains("Examples:"), "{help}");
    for needle in [
        "clones",
        "fbakit demo",
        "fbakit play",
        "fbakit view",
        "fbakit speak",
        "fbakit render",
        "fbakit completions",
        "--json",
    ] {
        assert!(help.contains(needle), "{needle} missing from\n{help}");
    }
}

#[test]
fn every_command_has_examples_and_json() {
    let leaves = leaf_commands();
    assert!(leaves.len() >= 25, "{leaves:?}");
    for path in &leaves {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let help = text(&fbakit(&args).stdout);
        assert!(help.contains("--json"), "{path:?} has no --json:\n{help}");
        // Examples sit on the command itself or, for subcommands, on their group.
        let group_help = text(&fbakit(&[path[0].as_str(), "--help"]).stdout);
        assert!(
            help.contains("Example") || group_help.contains("Example"),
            "{path:?} has no example"
        );
    }
}

#[test]
fn completions_and_man_pages_are_generated() {
    let bash = fbakit(&["completions", "bash"]);
    assert!(bash.status.success());
    let script = text(&bash.stdout);
    assert!(
        script.contains("_fbakit") && script.contains("complete"),
        "{script}"
    );
    assert!(
        script.contains("from-landmarks"),
        "subcommands are completed"
    );
    let zsh = text(&fbakit(&["completions", "zsh"]).stdout);
    assert!(zsh.starts_with("#compdef fbakit"), "{zsh}");
    let fish = fbakit(&["completions", "fish", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&fish.stdout).unwrap();
    assert_eq!(v["shell"], "fish");
    assert!(v["script"].as_str().unwrap().contains("complete -c fbakit"));

    let dir = tempfile::tempdir().unwrap();
    let man = dir.path().join("man");
    let out = fbakit(&["man", "-o", man.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pages = report["pages"].as_array().unwrap();
    assert!(pages.len() >= 30, "{pages:?}");
    for page in [
        "fbakit.1",
        "fbakit-play.1",
        "fbakit-face-info.1",
        "fbakit-fp-from-landmarks.1",
    ] {
        let roff = std::fs::read_to_string(man.join(page)).unwrap();
        assert!(roff.contains(".TH"), "{page}");
    }
    let play = std::fs::read_to_string(man.join("fbakit-play.1")).unwrap();
    assert!(
        play.contains("fbakit\\-play"),
        "page titled with its full name"
    );
    // A file where the directory should be is refused.
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    assert_eq!(
        fbakit(&["man", "-o", file.to_str().unwrap()]).status.code(),
        Some(2)
    );
}

#[test]
fn no_flag_that_does_nothing() {
    // `face export` writes glTF whatever it is told; a `--gltf` switch would only mislead.
    let help = text(&fbakit(&["face", "export", "--help"]).stdout);
    assert!(!help.contains("--gltf"), "{help}");
    let out = fbakit(&["face", "export", "alma", "-o", "x.glb", "--gltf"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!Path::new("x.glb").exists());
}

#[test]
fn one_default_cloning_method() {
    for args in [
        &["clone", "--help"][..],
        &["grid", "--help"],
        &["demo", "--help"],
        &["eval", "self-clone", "--help"],
    ] {
        let help = text(&fbakit(args).stdout);
        assert!(help.contains("[default: fit]"), "{args:?}:\n{help}");
    }
}

#[test]
fn errors_are_json_under_json() {
    let out = fbakit(&["fap", "info", "no-such.fap", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let v: serde_json::Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(v["error"]["exit_code"], 2);
    assert!(v["error"]["message"]
        .as_str()
        .unwrap()
        .contains("no-such.fap"));
    // Usage errors, found before any command runs, too.
    let out = fbakit(&["play", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(v["error"]["kind"], "bad-input");
    // Without --json an error is one plain line.
    let out = fbakit(&["fap", "info", "no-such.fap"]);
    let err = text(&out.stderr);
    assert!(
        err.starts_with("error: ") && err.lines().count() == 1,
        "{err}"
    );
}

#[test]
fn warnings_once_on_stderr_and_timings_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("bruno.wrl");
    let out = fbakit(&["clone", "alma", "bruno", "-o", out_path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let stderr = text(&out.stderr);
    assert!(!stdout.contains("warning"), "{stdout}");
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert!(
        !warnings.is_empty(),
        "cloning onto bruno warns about its tongue transform"
    );
    for w in &warnings {
        assert!(
            w.starts_with("warning: ") && !w.contains("warning: warning"),
            "{w}"
        );
        assert_eq!(warnings.iter().filter(|x| x == &w).count(), 1, "{w} twice");
    }
    assert!(
        !stdout.contains(" ms"),
        "no timing table without --verbose:\n{stdout}"
    );
    let out = fbakit(&[
        "clone",
        "alma",
        "bruno",
        "-o",
        out_path.to_str().unwrap(),
        "--verbose",
    ]);
    assert!(text(&out.stdout).contains(" ms"), "{}", text(&out.stdout));
}

#[test]
fn bad_input_and_values_are_exit_2_and_name_the_culprit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    // A directory where a file is expected.
    for args in [&["fap", "info", d][..], &["face", "info", d], &["fapu", d]] {
        let out = fbakit(args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            text(&out.stderr)
        );
        assert!(text(&out.stderr).contains(d), "{args:?}");
    }
    // Value errors name the option, negative numbers included.
    for bad in ["0", "-5", "NaN", "1e9"] {
        let out = fbakit(&[
            "render",
            "alma",
            "samples/speech.fap",
            "-o",
            "x.gif",
            "--fps",
            bad,
        ]);
        assert_eq!(out.status.code(), Some(2), "--fps {bad}");
        let err = text(&out.stderr);
        assert!(
            err.contains("--fps") && err.contains(bad),
            "--fps {bad}: {err}"
        );
        assert!(!Path::new("x.gif").exists());
    }
    // A gzip file given where text is expected says so.
    let out = fbakit(&["fap", "info", "samples/faces/alma.wrl.gz"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("gzip"), "{}", text(&out.stderr));
    // Unknown output extension and writing over the input are refused, nothing written.
    let xml = dir.path().join("x.xml");
    let out = fbakit(&[
        "fap",
        "convert",
        "samples/speech.fap",
        xml.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!xml.exists());
    let copy = dir.path().join("s.fap");
    std::fs::copy("samples/speech.fap", &copy).unwrap();
    let c = copy.to_str().unwrap();
    let out = fbakit(&["fap", "convert", c, c]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert_eq!(
        std::fs::read(&copy).unwrap(),
        std::fs::read("samples/speech.fap").unwrap()
    );
}

#[test]
fn output_errors_name_the_output_not_a_temporary_file() {
    let out = fbakit(&[
        "fap",
        "convert",
        "samples/speech.fap",
        "/nonexistent-dir-of-fbakit/out.fap",
    ]);
    assert_ne!(out.status.code(), Some(0));
    let err = text(&out.stderr);
    assert!(err.contains("/nonexistent-dir-of-fbakit/out.fap"), "{err}");
    assert!(!err.contains(".tmp"), "{err}");
}

#[test]
fn played_and_printed_durations_agree() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("a.glb");
    let out = fbakit(&[
        "play",
        "alma",
        "samples/speech.fap",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    // 75 frames at 25 fps: the glTF animation and the text both say 3 s.
    assert!(
        stdout.contains("75 frames") && stdout.contains("(3.000 s)"),
        "{stdout}"
    );
    let bytes = std::fs::read(&glb).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json: serde_json::Value = serde_json::from_slice(chunks.json).unwrap();
    let input = json["animations"][0]["samplers"][0]["input"]
        .as_u64()
        .unwrap() as usize;
    let max = json["accessors"][input]["max"][0].as_f64().unwrap();
    assert!((max - 3.0).abs() < 1e-6, "animation ends at {max} s");
}
