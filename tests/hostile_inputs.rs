//! Hostile inputs against the real binary: garbage, truncations of every sample format,
//! absurd numbers, deep nesting, DEF/USE and entity bombs, a gzip bomb, a huge sparse file,
//! control characters, directories and missing files as inputs, unwritable outputs.
//!
//! Every case asserts the exit code (2 bad input, 1 output failure; a few truncations may
//! still be readable and exit 0), one `error:` line naming the file or option, no raw control
//! bytes on stdout or stderr, nothing left in the output directory, and a wall time under
//! 5 s.

use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const SAMPLES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/samples");
/// A hang guard, not a speed target (those are divan benches): generous enough for a
/// debug-profile clone on a loaded 2-core machine.
const LIMIT: Duration = Duration::from_secs(60);

/// What a case must end with.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// Exit 2 with one error line.
    BadInput,
    /// Exit 1 with one error line.
    Failure,
    /// Exit 0 (the input is odd but readable), or 2 with one error line.
    ReadOrRefuse,
}

struct Outcome {
    stdout: Vec<u8>,
    stderr: String,
    code: i32,
    /// Peak resident set in kB when `/usr/bin/time` is available.
    peak_kb: Option<u64>,
}

struct Lab {
    dir: tempfile::TempDir,
}

impl Lab {
    fn new() -> Lab {
        Lab {
            dir: tempfile::tempdir().unwrap(),
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    /// A fresh, empty output directory for one case.
    fn out(&self, case: &str) -> PathBuf {
        let p = self.path(&format!("out-{case}"));
        std::fs::create_dir_all(&p).unwrap();
        p
    }
}

fn run(args: &[OsString], measure: bool) -> (Outcome, Duration) {
    let time = Path::new("/usr/bin/time");
    let mut cmd = if measure && time.exists() {
        let mut c = Command::new(time);
        c.arg("-f")
            .arg("PEAK_KB=%M")
            .arg(env!("CARGO_BIN_EXE_fbakit"));
        c
    } else {
        Command::new(env!("CARGO_BIN_EXE_fbakit"))
    };
    cmd.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    let start = Instant::now();
    let out = cmd.output().expect("run fbakit");
    let took = start.elapsed();
    let mut stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let mut peak_kb = None;
    if let Some(i) = stderr.rfind("PEAK_KB=") {
        peak_kb = stderr[i + 8..].trim().parse().ok();
        stderr.truncate(i);
        // `time` adds a line when the command exits non-zero.
        let lines: Vec<&str> = stderr
            .lines()
            .filter(|l| !l.starts_with("Command exited with non-zero status"))
            .collect();
        stderr = lines.join("\n");
        if !stderr.is_empty() {
            stderr.push('\n');
        }
    }
    (
        Outcome {
            stdout: out.stdout,
            stderr,
            code: out.status.code().unwrap_or(-1),
            peak_kb,
        },
        took,
    )
}

fn no_control_bytes(what: &str, bytes: &[u8], case: &str) {
    if let Some(b) = bytes
        .iter()
        .find(|&&b| (b < 0x20 && b != b'\n' && b != b'\t') || b == 0x7f)
    {
        panic!(
            "{case}: raw control byte 0x{b:02x} on {what}: {}",
            String::from_utf8_lossy(bytes)
        );
    }
}

/// Runs one case and checks everything the suite promises; returns the outcome.
fn case(
    case: &str,
    args: &[&dyn AsRef<std::ffi::OsStr>],
    expect: Expect,
    names: &str,
    out: Option<&Path>,
) -> Outcome {
    case_measured(case, args, expect, names, out, false)
}

fn case_measured(
    case: &str,
    args: &[&dyn AsRef<std::ffi::OsStr>],
    expect: Expect,
    names: &str,
    out: Option<&Path>,
    measure: bool,
) -> Outcome {
    let args: Vec<OsString> = args.iter().map(|a| a.as_ref().to_os_string()).collect();
    let (o, took) = run(&args, measure);
    assert!(took < LIMIT, "{case}: took {took:?}");
    assert!(
        !o.stderr.contains("panicked"),
        "{case}: panic\n{}",
        o.stderr
    );
    no_control_bytes("stdout", &o.stdout, case);
    no_control_bytes("stderr", o.stderr.as_bytes(), case);
    let errors: Vec<&str> = o
        .stderr
        .lines()
        .filter(|l| l.starts_with("error:"))
        .collect();
    let ok = match expect {
        Expect::BadInput => o.code == 2,
        Expect::Failure => o.code == 1,
        Expect::ReadOrRefuse => o.code == 0 || o.code == 2,
    };
    assert!(ok, "{case}: exit {} ({expect:?})\n{}", o.code, o.stderr);
    if o.code != 0 {
        assert_eq!(errors.len(), 1, "{case}: one error line\n{}", o.stderr);
        assert!(
            errors[0].contains(names),
            "{case}: the error names `{names}`: {}",
            errors[0]
        );
    }
    if let Some(dir) = out {
        if o.code != 0 {
            let left: Vec<_> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect();
            assert!(left.is_empty(), "{case}: left behind {left:?}");
        }
    }
    o
}

/// Deterministic garbage: every byte value, control characters included.
fn garbage(n: usize, seed: u64) -> Vec<u8> {
    let mut x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 33) as u8
        })
        .collect()
}

fn sample(rel: &str) -> Vec<u8> {
    std::fs::read(Path::new(SAMPLES).join(rel)).unwrap()
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::MultiGzDecoder::new(bytes), &mut out).unwrap();
    out
}

/// A small valid FAP stream (lowlevel sample) with its header replaced by `header`.
fn fap_with_header(header: &str) -> Vec<u8> {
    let text = String::from_utf8(sample("lowlevel.fap")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    lines.next();
    let mut out = format!("{header}\n");
    for l in lines {
        out.push_str(l);
        out.push('\n');
    }
    out.into_bytes()
}

/// A two-frame stream: the lowlevel sample's mask and values at frames 0 and `last`, with
/// `value` in place of the first FAP value.
fn two_frames(last: &str, value: &str, rate: &str) -> Vec<u8> {
    let text = String::from_utf8(sample("lowlevel.fap")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    lines.next();
    let mask = lines.next().unwrap();
    let values = lines.next().unwrap();
    let mut rest = values.split_whitespace();
    rest.next();
    rest.next();
    let rest: Vec<&str> = rest.collect();
    format!(
        "2.1 two {rate} 2\n{mask}\n0 {value} {r}\n{mask}\n{last} {value} {r}\n",
        r = rest.join(" ")
    )
    .into_bytes()
}

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// 68 vertices in iBUG-68 order, roughly where the landmarks sit on a face (jaw contour,
/// brows, nose, eyes, lips; centimetres), with a fan of triangles so it reads as a mesh.
fn ibug68_obj() -> String {
    let mut v: Vec<[f32; 3]> = Vec::new();
    for k in 0..17 {
        let a = std::f32::consts::PI * (k as f32 / 16.0);
        v.push([-7.0 * a.cos(), -2.0 - 7.0 * a.sin(), 0.0]);
    }
    for k in 0..10 {
        let x = -6.0 + 12.0 * (k as f32 + (k / 5) as f32) / 10.0;
        v.push([x, 4.0, 1.0]);
    }
    for k in 0..4 {
        v.push([0.0, 2.0 - 1.2 * k as f32, 1.0 + 0.6 * k as f32]);
    }
    for k in 0..5 {
        v.push([-1.6 + 0.8 * k as f32, -3.0, 1.5]);
    }
    for side in [-1.0f32, 1.0] {
        for k in 0..6 {
            let a = std::f32::consts::TAU * k as f32 / 6.0;
            v.push([side * 3.0 + 1.2 * a.cos(), 2.0 + 0.5 * a.sin(), 0.5]);
        }
    }
    for k in 0..12 {
        let a = std::f32::consts::TAU * k as f32 / 12.0;
        v.push([-2.5 * a.cos(), -6.0 + 1.2 * a.sin(), 1.0]);
    }
    for k in 0..8 {
        let a = std::f32::consts::TAU * k as f32 / 8.0;
        v.push([-1.8 * a.cos(), -6.0 + 0.5 * a.sin(), 0.9]);
    }
    let mut text: String = v
        .iter()
        .map(|p| format!("v {} {} {}\n", p[0], p[1], p[2]))
        .collect();
    for k in 2..68 {
        text.push_str(&format!("f 1 {k} {}\n", k + 1));
    }
    text
}

#[test]
fn garbage_inputs_are_refused_by_every_reader() {
    let lab = Lab::new();
    let junk = garbage(4096, 7);
    for (n, ext, cmd) in [
        (0, "fap", &["fap", "info"][..]),
        (1, "fap", &["fap", "validate"][..]),
        (2, "wrl", &["face", "info"][..]),
        (3, "wrl.gz", &["face", "info"][..]),
        (4, "obj", &["face", "info"][..]),
        (5, "glb", &["rig", "info"][..]),
        (6, "xml", &["fapu"][..]),
        (7, "csv", &["fapu"][..]),
        (8, "fdp", &["fapu"][..]),
    ] {
        let name = format!("garbage{n}.{ext}");
        let p = lab.file(&name, &junk);
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = cmd.iter().map(|c| c as _).collect();
        args.push(&p);
        case(
            &format!("garbage {cmd:?} .{ext}"),
            &args,
            Expect::BadInput,
            &name,
            None,
        );
    }
    // Garbage through the commands that write.
    let p = lab.file("junk.fap", &junk);
    let out = lab.out("junk-play");
    let glb = out.join("x.glb");
    case(
        "play garbage stream",
        &[&"play", &"alma", &p, &"-o", &glb],
        Expect::BadInput,
        "junk.fap",
        Some(&out),
    );
    let p = lab.file("junk.wrl", &junk);
    let out = lab.out("junk-clone");
    let wrl = out.join("x.wrl");
    case(
        "clone garbage target",
        &[&"clone", &"alma", &p, &"-o", &wrl],
        Expect::BadInput,
        "junk.wrl",
        Some(&out),
    );
    let mesh = lab.file("junk.obj", &junk);
    let ids = lab.file("ids.json", b"[1, 2, 3]");
    let out = lab.out("junk-landmarks");
    let csv = out.join("fp.csv");
    case(
        "fp from-landmarks garbage mesh",
        &[
            &"fp",
            &"from-landmarks",
            &mesh,
            &"--ibug68",
            &ids,
            &"-o",
            &csv,
        ],
        Expect::BadInput,
        "junk.obj",
        Some(&out),
    );
}

#[test]
fn truncated_samples_are_read_or_refused() {
    let lab = Lab::new();
    let wrl_gz = sample("faces/alma.wrl.gz");
    let wrl = gunzip(&wrl_gz);
    let inputs: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "speech.fap",
            sample("speech.fap"),
            &["fap", "info", "--strict"],
        ),
        ("alma.wrl", wrl.clone(), &["face", "info"]),
        ("alma.wrl.gz", wrl_gz, &["face", "info"]),
        (
            "head.obj",
            TRIANGLE_OBJ.as_bytes().to_vec(),
            &["face", "info"],
        ),
        (
            "ict-head.glb",
            sample("faces/ict-head/ict-head.glb"),
            &["rig", "info"],
        ),
        ("fp.xml", sample("feature-points-example.xml"), &["fapu"]),
        (
            "ict-fp.csv",
            sample("faces/ict-head/ict-head-fp.csv"),
            &["fapu"],
        ),
    ];
    for (name, bytes, cmd) in &inputs {
        for (k, cut) in [bytes.len() / 3, bytes.len() / 2, bytes.len() - 7]
            .into_iter()
            .enumerate()
        {
            let file = format!("cut{k}-{name}");
            let p = lab.file(&file, &bytes[..cut.min(bytes.len())]);
            let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = cmd.iter().map(|c| c as _).collect();
            args.push(&p);
            let expect =
                if name.ends_with(".gz") || name.ends_with(".glb") || name.ends_with(".xml") {
                    // Compressed, binary and XML inputs cannot be complete when cut.
                    Expect::BadInput
                } else {
                    Expect::ReadOrRefuse
                };
            case(&format!("truncated {file}"), &args, expect, &file, None);
        }
    }
    // A wrl cut inside its first node is never a face.
    let p = lab.file("head-cut.wrl", &wrl[..200]);
    case(
        "truncated wrl header",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "head-cut.wrl",
        None,
    );
}

#[test]
fn absurd_numbers_are_refused_or_named() {
    let lab = Lab::new();
    for (k, v) in ["nan", "inf", "-inf", "1e39", "99999999999999999999999"]
        .iter()
        .enumerate()
    {
        let name = format!("value{k}.fap");
        let p = lab.file(&name, &two_frames("1", v, "25"));
        case(
            &format!("FAP value {v}"),
            &[&"fap", &"info", &"--strict", &p],
            Expect::BadInput,
            &name,
            None,
        );
    }
    for (k, rate) in ["nan", "inf", "1e39", "0", "-25"].iter().enumerate() {
        let name = format!("rate{k}.fap");
        let p = lab.file(&name, &two_frames("1", "0", rate));
        let out = lab.out(&format!("rate{k}"));
        let glb = out.join("x.glb");
        case(
            &format!("frame rate {rate}"),
            &[&"play", &"alma", &p, &"-o", &glb],
            Expect::BadInput,
            &name,
            Some(&out),
        );
    }
    let p = lab.file(
        "count.fap",
        &fap_with_header("2.1 big 25 99999999999999999999999"),
    );
    case(
        "frame count overflow",
        &[&"fap", &"info", &"--strict", &p],
        Expect::BadInput,
        "count.fap",
        None,
    );
    for (k, v) in ["nan", "inf", "1e39"].iter().enumerate() {
        let name = format!("coord{k}.obj");
        let p = lab.file(
            &name,
            format!("v {v} 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").as_bytes(),
        );
        case(
            &format!("OBJ coordinate {v}"),
            &[&"face", &"info", &p],
            Expect::BadInput,
            &name,
            None,
        );
    }
    let p = lab.file(
        "coord.wrl",
        b"#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 nan 0, 0 1 1e39 ] } coordIndex [ 0 1 2 -1 ] } }\n",
    );
    case(
        "VRML coordinate nan",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "coord.wrl",
        None,
    );
}

#[test]
fn deep_nesting_and_bombs_are_refused_quickly() {
    let lab = Lab::new();
    let deep = 100_000;
    let mut vrml = b"#VRML V2.0 utf8\n".to_vec();
    vrml.extend(std::iter::repeat_n(b'[', deep));
    let p = lab.file("brackets.wrl", &vrml);
    case(
        "VRML 100 000 brackets",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "brackets.wrl",
        None,
    );
    let mut vrml = b"#VRML V2.0 utf8\n".to_vec();
    for _ in 0..deep {
        vrml.extend_from_slice(b"Group { children [ ");
    }
    let p = lab.file("groups.wrl", &vrml);
    case(
        "VRML 100 000 groups",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "groups.wrl",
        None,
    );
    let mut xml = b"<?xml version=\"1.0\"?>\n".to_vec();
    for _ in 0..deep {
        xml.extend_from_slice(b"<a>");
    }
    let p = lab.file("deep.xml", &xml);
    case(
        "XML 100 000 elements",
        &[&"fapu", &p],
        Expect::BadInput,
        "deep.xml",
        None,
    );
    // DEF/USE bomb: each level uses the previous one twice (2^40 shapes if expanded).
    let mut bomb = String::from(
        "#VRML V2.0 utf8\nDEF L0 Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }\n",
    );
    for k in 1..=40 {
        bomb.push_str(&format!(
            "DEF L{k} Group {{ children [ USE L{p} USE L{p} ] }}\n",
            p = k - 1
        ));
    }
    let p = lab.file("defuse.wrl", bomb.as_bytes());
    case(
        "DEF/USE bomb",
        &[&"face", &"info", &p],
        Expect::ReadOrRefuse,
        "defuse.wrl",
        None,
    );
    // Billion laughs.
    let mut laughs =
        String::from("<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [\n<!ENTITY lol \"lol\">\n");
    for k in 1..=9 {
        let prev = if k == 1 {
            "lol".to_string()
        } else {
            format!("lol{}", k - 1)
        };
        laughs.push_str(&format!(
            "<!ENTITY lol{k} \"{}\">\n",
            format!("&{prev};").repeat(10)
        ));
    }
    laughs.push_str("]>\n<feature_points>&lol9;</feature_points>\n");
    let p = lab.file("laughs.xml", laughs.as_bytes());
    case(
        "XML entity bomb",
        &[&"fapu", &p],
        Expect::BadInput,
        "laughs.xml",
        None,
    );
    // External entity: never read.
    let p = lab.file(
        "xxe.xml",
        b"<?xml version=\"1.0\"?>\n<!DOCTYPE x [<!ENTITY e SYSTEM \"file:///etc/passwd\">]>\n<feature_points>&e;</feature_points>\n",
    );
    let o = case(
        "XML external entity",
        &[&"fapu", &p],
        Expect::BadInput,
        "xxe.xml",
        None,
    );
    assert!(!o.stderr.contains("root:"), "{}", o.stderr);
}

/// 300 MB of zeros as 300 concatenated gzip members of 1 MB each (a few hundred kB).
fn gzip_bomb() -> Vec<u8> {
    let mut member = Vec::new();
    {
        let mut enc = flate2::write::GzEncoder::new(&mut member, flate2::Compression::best());
        enc.write_all(&vec![0u8; 1 << 20]).unwrap();
        enc.finish().unwrap();
    }
    member.repeat(300)
}

fn assert_peak(case: &str, o: &Outcome) {
    match o.peak_kb {
        Some(kb) => assert!(kb < 64 * 1024, "{case}: peak RSS {kb} kB"),
        None => eprintln!("{case}: /usr/bin/time not found, peak RSS not measured"),
    }
}

#[test]
fn oversized_inputs_are_refused_without_reading_them() {
    let lab = Lab::new();
    let bomb = gzip_bomb();
    assert!(bomb.len() < 1 << 20, "bomb is {} bytes", bomb.len());
    let p = lab.file("bomb.wrl.gz", &bomb);
    let o = case_measured(
        "gzip bomb",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "bomb.wrl.gz",
        None,
        true,
    );
    assert_peak("gzip bomb", &o);
    for (name, cmd) in [
        ("sparse.wrl", &["face", "info"][..]),
        ("sparse.fap", &["fap", "info"][..]),
        ("sparse.glb", &["rig", "info"][..]),
        ("sparse.xml", &["fapu"][..]),
    ] {
        let p = lab.path(name);
        std::fs::File::create(&p).unwrap().set_len(1 << 31).unwrap();
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = cmd.iter().map(|c| c as _).collect();
        args.push(&p);
        let o = case_measured(
            &format!("sparse {name}"),
            &args,
            Expect::BadInput,
            name,
            None,
            true,
        );
        assert!(o.stderr.contains("2147483648"), "size named: {}", o.stderr);
        assert_peak(name, &o);
        std::fs::remove_file(&p).unwrap();
    }
    // 1e9 NUL bytes, under the size limit: text readers stop at the first one (this read
    // 1 GB into 2 GB of memory in 28 s).
    for (name, cmd) in [
        ("zeros.wrl", &["face", "info"][..]),
        ("zeros.obj", &["face", "info"][..]),
        ("zeros.fap", &["fap", "info"][..]),
        ("zeros.csv", &["fapu"][..]),
    ] {
        let p = lab.path(name);
        std::fs::File::create(&p)
            .unwrap()
            .set_len(1_000_000_000)
            .unwrap();
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = cmd.iter().map(|c| c as _).collect();
        args.push(&p);
        let o = case_measured(
            &format!("NULs {name}"),
            &args,
            Expect::BadInput,
            name,
            None,
            true,
        );
        assert!(o.stderr.contains("NUL"), "{name}: {}", o.stderr);
        assert_peak(name, &o);
        std::fs::remove_file(&p).unwrap();
    }
}

#[test]
fn control_characters_never_reach_the_terminal() {
    let lab = Lab::new();
    let p = lab.file(
        "esc.fap",
        &fap_with_header("2.1 \x1b]0;pwned\x07\x1b[2J 25 50"),
    );
    let o = case(
        "escape in header",
        &[&"fap", &"info", &p],
        Expect::ReadOrRefuse,
        "esc.fap",
        None,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(String::from_utf8_lossy(&o.stdout).contains("\\x1b"));
    let p = lab.file("esc-v.fap", &fap_with_header("\x1b[31m2.1 name 25 50"));
    case(
        "escape in version",
        &[&"fap", &"info", &p],
        Expect::ReadOrRefuse,
        "esc-v.fap",
        None,
    );
    let p = lab.file("nul.fap", b"2.1 a\x00b\x07 25 x\n");
    case(
        "NUL and BEL in an error",
        &[&"fap", &"info", &p],
        Expect::BadInput,
        "nul.fap",
        None,
    );
    let p = lab.file("bell.wrl", b"#VRML V2.0 utf8\n\x07\x1b[2J Shape {\n");
    case(
        "BEL in VRML",
        &[&"face", &"info", &p],
        Expect::BadInput,
        "bell.wrl",
        None,
    );
    let p = lab.file(
        "esc.csv",
        b"fp,vertices,combine,description\n\x1b[2J,1,,x\n",
    );
    case(
        "escape in CSV",
        &[&"fapu", &p],
        Expect::BadInput,
        "esc.csv",
        None,
    );
    let name = "\x1b[2Jmissing.fap";
    let p = lab.path(name);
    case(
        "escape in a file name",
        &[&"fap", &"info", &p],
        Expect::BadInput,
        "missing.fap",
        None,
    );
    let p = lab.file("esc.fap.json", b"{\"version\": \"\x1b[2J\"");
    case(
        "escape in JSON stream",
        &[&"fap", &"info", &p],
        Expect::BadInput,
        "esc.fap.json",
        None,
    );
}

#[test]
fn directories_and_missing_files_are_bad_input() {
    let lab = Lab::new();
    let dir = lab.path("a-dir");
    std::fs::create_dir(&dir).unwrap();
    let missing = lab.path("missing.wrl");
    for (what, cmd, target) in [
        ("directory", &["fap", "info"][..], &dir),
        ("directory", &["fap", "validate"][..], &dir),
        ("directory", &["face", "info"][..], &dir),
        ("directory", &["fapu"][..], &dir),
        ("directory", &["rig", "info"][..], &dir),
        ("missing", &["face", "info"][..], &missing),
        ("missing", &["fap", "info"][..], &missing),
        ("missing", &["fapu"][..], &missing),
        ("missing", &["rig", "info"][..], &missing),
    ] {
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = cmd.iter().map(|c| c as _).collect();
        args.push(target);
        let name = target.file_name().unwrap().to_string_lossy().into_owned();
        case(
            &format!("{what} {cmd:?}"),
            &args,
            Expect::BadInput,
            &name,
            None,
        );
    }
    let out = lab.out("clone-missing");
    let wrl = out.join("x.wrl");
    case(
        "clone missing source",
        &[&"clone", &missing, &"alma", &"-o", &wrl],
        Expect::BadInput,
        "missing.wrl",
        Some(&out),
    );
    let out = lab.out("play-dir");
    let glb = out.join("x.glb");
    case(
        "play a directory stream",
        &[&"play", &"alma", &dir, &"-o", &glb],
        Expect::BadInput,
        "a-dir",
        Some(&out),
    );
}

#[test]
fn unwritable_outputs_are_failures_that_leave_nothing() {
    let lab = Lab::new();
    let stream = Path::new(SAMPLES).join("speech.fap");
    let out = lab.out("unwritable");
    // A plain file where a directory should be: no OS lets us write under it, root included.
    let blocker = out.join("blocker");
    std::fs::write(&blocker, b"").unwrap();
    let check_only_blocker = |case: &str| {
        let left: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![OsString::from("blocker")], "{case}: left behind");
    };
    for (case_name, target, extra) in [
        ("play glb", blocker.join("x.glb"), &[][..]),
        ("play OBJ frames", blocker.join("frames/"), &[][..]),
        (
            "play PNG frames",
            blocker.join("frames"),
            &["--format", "png", "--size", "32x32"][..],
        ),
        (
            "play PNG sheet",
            blocker.join("sheet.png"),
            &["--size", "32x32"][..],
        ),
    ] {
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> =
            vec![&"play", &"alma", &stream, &"-o", &target];
        args.extend(extra.iter().map(|a| a as &dyn AsRef<std::ffi::OsStr>));
        case(case_name, &args, Expect::Failure, "blocker", None);
        check_only_blocker(case_name);
    }
    let target = blocker.join("x.wrl");
    case(
        "clone output",
        &[&"clone", &"alma", &"bruno", &"-o", &target],
        Expect::Failure,
        "blocker",
        None,
    );
    check_only_blocker("clone output");
    let target = blocker.join("man");
    case(
        "man pages folder",
        &[&"man", &"-o", &target],
        Expect::Failure,
        "blocker",
        None,
    );
    check_only_blocker("man pages folder");
    // Folders of files: each is made beside its place and renamed in, so a place that
    // cannot be written fails before the first file and leaves nothing.
    for (case_name, args) in [
        ("face morphs folder", vec!["face", "to-morphs", "alma"]),
        ("demo folder", vec!["demo", "--single", "--out"]),
    ] {
        let target = blocker.join("folder");
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = args
            .iter()
            .map(|a| a as &dyn AsRef<std::ffi::OsStr>)
            .collect();
        args.push(&target);
        case(case_name, &args, Expect::Failure, "blocker", None);
        check_only_blocker(case_name);
    }
    // Valid landmarks (68 vertices in landmark order), an output that cannot be written.
    let target = blocker.join("x.csv");
    let mesh = lab.file("ibug68.obj", ibug68_obj().as_bytes());
    let ids: Vec<String> = (0..68).map(|i| i.to_string()).collect();
    let ids = lab.file("ids68.txt", ids.join(" ").as_bytes());
    case(
        "fp from-landmarks output",
        &[
            &"fp",
            &"from-landmarks",
            &mesh,
            &"--ibug68",
            &ids,
            &"-o",
            &target,
        ],
        Expect::Failure,
        "x.csv",
        None,
    );
    check_only_blocker("fp from-landmarks output");
}

#[test]
fn a_tiny_stream_with_a_huge_span_is_refused_at_once() {
    let lab = Lab::new();
    let p = lab.file("span.fap", &two_frames("9999999", "0", "25"));
    for (k, target) in ["x.glb", "x.gltf", "frames/"].iter().enumerate() {
        let out = lab.out(&format!("span{k}"));
        let o_path = out.join(target);
        let start = Instant::now();
        let o = case(
            &format!("huge span to {target}"),
            &[&"play", &"alma", &p, &"-o", &o_path],
            Expect::BadInput,
            "--frames",
            Some(&out),
        );
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "{target}: {:?}",
            start.elapsed()
        );
        assert!(
            o.stderr.contains("9999999") || o.stderr.contains("10000000"),
            "{}",
            o.stderr
        );
    }
    // A million frames (the frame limit) of glTF: refused up front by the clip's memory
    // estimate (it peaked at 3.0 GB).
    let p_m = lab.file("million.fap", &two_frames("999999", "0", "25"));
    let out = lab.out("million");
    let glb = out.join("x.glb");
    let o = case_measured(
        "a million frames to glb",
        &[&"play", &"alma", &p_m, &"-o", &glb],
        Expect::BadInput,
        "--frames",
        Some(&out),
        true,
    );
    assert!(o.stderr.contains("memory"), "{}", o.stderr);
    assert_peak("a million frames to glb", &o);
    let out = lab.out("span-view");
    let html = out.join("x.html");
    case(
        "huge span in view",
        &[&"view", &"alma", &p, &"-o", &html],
        Expect::BadInput,
        "--frames",
        Some(&out),
    );
    let out = lab.out("span-render");
    let gif = out.join("x.gif");
    case(
        "huge span in render",
        &[&"render", &"alma", &p, &"-o", &gif],
        Expect::BadInput,
        "x.gif",
        Some(&out),
    );
}

#[test]
fn landmark_ids_cannot_be_hostile() {
    let lab = Lab::new();
    let mesh = lab.file("tri.obj", TRIANGLE_OBJ.as_bytes());
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    for (k, ids) in [
        deep.as_bytes(),
        b"[1, 2, nan]".as_slice(),
        b"[1e39]".as_slice(),
        b"-1,2,3".as_slice(),
        b"\x1b[2J".as_slice(),
    ]
    .iter()
    .enumerate()
    {
        let name = format!("ids{k}.json");
        let ids_path = lab.file(&name, ids);
        let out = lab.out(&format!("ids{k}"));
        let csv = out.join("fp.csv");
        case(
            &format!("landmark ids {k}"),
            &[
                &"fp",
                &"from-landmarks",
                &mesh,
                &"--ibug68",
                &ids_path,
                &"-o",
                &csv,
            ],
            Expect::BadInput,
            &name,
            Some(&out),
        );
    }
}

#[test]
fn a_frame_sequence_stopped_midway_leaves_nothing() {
    // The library side of `play -o frames/`: a sequence dropped after some frames (what an
    // error in a later frame does) leaves neither the folder nor a temporary sibling.
    let face = fbakit::face::read("alma").unwrap();
    let (stream, _) = fbakit::fap::read_stream_file(
        Path::new(SAMPLES).join("speech.fap"),
        &fbakit::fap::ReadOptions::lenient(),
    )
    .unwrap();
    let mut player =
        fbakit::player::Player::new(&face, &stream, &fbakit::player::PlayOptions::default())
            .unwrap();
    let lab = Lab::new();
    let out = lab.out("midway");
    let frames = out.join("frames");
    let mut seq = fbakit::export::obj_sequence::ObjSequence::new(&face, &frames, 25.0).unwrap();
    let mut frame = player.new_frame();
    for _ in 0..3 {
        assert!(player.next_frame(&mut frame));
        seq.write_frame(&frame).unwrap();
    }
    assert!(!frames.exists(), "frames appear only when finished");
    drop(seq);
    let left: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
    assert!(left.is_empty(), "left behind {left:?}");
    // Finished, the folder is there whole.
    let mut seq = fbakit::export::obj_sequence::ObjSequence::new(&face, &frames, 25.0).unwrap();
    player.rewind();
    assert!(player.next_frame(&mut frame));
    seq.write_frame(&frame).unwrap();
    seq.finish().unwrap();
    let mut names: Vec<_> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["frame_00000.obj", "frames.json"]);
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "no temporary left"
    );
}

/// Runs `fbakit ARGS` with outputs limited to `blocks` × 512 bytes per file and SIGXFSZ
/// ignored, so a write past the limit fails with "file too large" (root cannot bypass it).
#[cfg(unix)]
fn run_with_file_limit(blocks: u32, args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run fbakit under sh")
}

#[cfg(unix)]
#[test]
fn folders_failing_while_written_leave_nothing() {
    let lab = Lab::new();
    for (case_name, args, blocks) in [
        ("face morphs folder", &["face", "to-morphs", "alma"][..], 64),
        ("man pages folder", &["man", "-o"][..], 4),
    ] {
        let out = lab.out(&case_name.replace(' ', "-"));
        let target = out.join("folder");
        let mut all: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
        all.push(target.as_os_str());
        let o = run_with_file_limit(blocks, &all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{case_name}: {err}");
        let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(errors.len(), 1, "{case_name}: {err}");
        // The error names the file at its final place, not the temporary folder.
        assert!(
            errors[0].contains("folder/") && !errors[0].contains(".fbakit-"),
            "{case_name}: {}",
            errors[0]
        );
        let left: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(left.is_empty(), "{case_name}: left behind {left:?}");
    }
}
