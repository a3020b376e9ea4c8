//! `fbakit render`: MP4 (probed with ffprobe), GIF (decoded back) and PNG folders of a short
//! stream, and failures that leave nothing behind. MP4 tests print a skip note when ffmpeg
//! is not installed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use fbakit::export::video::ffmpeg_available;
use fbakit::fap::{read_fap_file, write_fap_file, ReadOptions};

mod support;
use support::cli::fbakit;

/// Frames of the short test stream (the first 12 of `samples/speech.fap`, at 25 fps).
const FRAMES: u64 = 12;
const FPS: f64 = 25.0;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A short speech stream in `dir`.
fn short_stream(dir: &Path) -> PathBuf {
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
    let (mut stream, _) = read_fap_file(&samples, &ReadOptions::lenient()).unwrap();
    stream.frames.retain(|f| f.number < FRAMES);
    let path = dir.join("short.fap");
    write_fap_file(&path, &stream).unwrap();
    path
}

/// A mono 16-bit WAV of `seconds` of a 440 Hz tone.
fn tone(path: &Path, seconds: f64) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 22_050,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    let n = (seconds * 22_050.0) as usize;
    for i in 0..n {
        let t = i as f64 / 22_050.0;
        w.write_sample((8000.0 * (t * 440.0 * std::f64::consts::TAU).sin()) as i16)
            .unwrap();
    }
    w.finalize().unwrap();
}

/// `ffprobe` entries `key=value` of the streams and the container.
fn probe(path: &Path) -> Vec<(String, String)> {
    let o = Command::new("ffprobe")
        .args(["-v", "error", "-show_entries"])
        .arg("stream=codec_type,codec_name,width,height,pix_fmt,nb_frames,duration:format=duration")
        .args(["-of", "default=nw=1"])
        .arg(path)
        .output()
        .expect("ffprobe runs where ffmpeg does");
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

fn values<'a>(p: &'a [(String, String)], key: &str) -> Vec<&'a str> {
    p.iter()
        .filter(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .collect()
}

/// Entries of `dir` other than `keep` (temporary leftovers would show here).
fn others(dir: &Path, keep: &[&str]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect()
}

fn skip_without_ffmpeg(test: &str) -> bool {
    if ffmpeg_available() {
        return false;
    }
    eprintln!("skip {test}: ffmpeg is not installed (apt-get install ffmpeg)");
    true
}

#[test]
fn mp4_has_the_stream_duration_frames_and_size() {
    if skip_without_ffmpeg("mp4_has_the_stream_duration_frames_and_size") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let out = dir.path().join("talk.mp4");
    // An odd width: padded to even for 4:2:0.
    let o = fbakit(&[
        "render",
        "alma",
        fap.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "95x64",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = probe(&out);
    assert_eq!(values(&p, "codec_type"), vec!["video"]);
    assert_eq!(values(&p, "codec_name"), vec!["h264"]);
    assert_eq!(values(&p, "pix_fmt"), vec!["yuv420p"]);
    assert_eq!(values(&p, "width"), vec!["96"]);
    assert_eq!(values(&p, "height"), vec!["64"]);
    assert_eq!(values(&p, "nb_frames"), vec![FRAMES.to_string().as_str()]);
    let duration: f64 = values(&p, "duration")[1].parse().unwrap();
    assert!(
        (duration - FRAMES as f64 / FPS).abs() < 1e-3,
        "{duration} s"
    );
    assert_eq!(
        others(dir.path(), &["short.fap", "talk.mp4"]),
        Vec::<String>::new()
    );
}

#[test]
fn mp4_with_audio_carries_aac_and_lasts_as_long_as_the_video() {
    if skip_without_ffmpeg("mp4_with_audio_carries_aac_and_lasts_as_long_as_the_video") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let video_seconds = FRAMES as f64 / FPS;
    // One soundtrack longer than the video (cut), one shorter (padded with silence).
    for (name, audio_seconds) in [("long", 2.0), ("short", 0.2)] {
        let wav = dir.path().join(format!("{name}.wav"));
        tone(&wav, audio_seconds);
        let out = dir.path().join(format!("{name}.mp4"));
        let o = fbakit(&[
            "render",
            "bruno",
            fap.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--size",
            "64x64",
            "--audio",
            wav.to_str().unwrap(),
            "--json",
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["frames"], FRAMES);
        let p = probe(&out);
        assert_eq!(values(&p, "codec_type"), vec!["video", "audio"], "{name}");
        assert_eq!(values(&p, "codec_name"), vec!["h264", "aac"], "{name}");
        let container: f64 = values(&p, "duration").last().unwrap().parse().unwrap();
        // AAC frames are 1024 samples (46 ms at 22.05 kHz): the audio may run that much over.
        assert!(
            (container - video_seconds).abs() < 0.1,
            "{name}: container {container} s, video {video_seconds} s"
        );
    }
}

#[test]
fn gif_decodes_to_every_frame_with_the_frame_rate_delays() {
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let out = dir.path().join("talk.gif");
    // 30 fps: delays alternate 3 and 4 hundredths, summing to the duration.
    let o = fbakit(&[
        "render",
        "alma",
        fap.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "48x40",
        "--fps",
        "30",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(std::fs::File::open(&out).unwrap()).unwrap();
    assert_eq!((d.width(), d.height()), (48, 40));
    let mut delays = Vec::new();
    let mut distinct = std::collections::HashSet::new();
    while let Some(f) = d.read_next_frame().unwrap() {
        delays.push(u32::from(f.delay));
        distinct.insert(f.buffer.to_vec());
    }
    // 12 frames at 25 fps resampled to 30 fps: frames 0..=13.
    let expected = ((FRAMES - 1) as f64 * 30.0 / FPS).round() as usize + 1;
    assert_eq!(delays.len(), expected);
    assert!(delays.iter().all(|&d| d == 3 || d == 4), "{delays:?}");
    let total: u32 = delays.iter().sum();
    let want = expected as f64 * 100.0 / 30.0;
    assert!((f64::from(total) - want).abs() <= 1.0, "{total} vs {want}");
    assert!(distinct.len() > 1, "the face moves");
}

#[test]
fn png_folder_holds_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let out = dir.path().join("frames");
    let o = fbakit(&[
        "render",
        "alma",
        fap.to_str().unwrap(),
        "-o",
        &format!("{}/", out.display()),
        "--size",
        "40x32",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> = others(&out, &[]);
    names.sort();
    let want: Vec<String> = (0..FRAMES).map(|k| format!("frame_{k:05}.png")).collect();
    assert_eq!(names, want);
    for n in &names {
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(out.join(n)).unwrap(),
        ));
        let r = decoder.read_info().unwrap();
        assert_eq!((r.info().width, r.info().height), (40, 32));
    }
    assert_eq!(
        others(dir.path(), &["short.fap", "frames"]),
        Vec::<String>::new()
    );
}

#[test]
fn failures_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let fap = fap.to_str().unwrap();
    let path = |n: &str| dir.path().join(n).to_string_lossy().into_owned();
    // A stream that does not parse: bad input, nothing written.
    std::fs::write(dir.path().join("bad.fap"), "2.1 x 25 1\n1 1\n").unwrap();
    let o = fbakit(&[
        "render",
        "alma",
        &path("bad.fap"),
        "-o",
        &path("a.gif"),
        "--strict",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // Audio for a GIF, an unknown extension: refused before anything is written.
    let o = fbakit(&["render", "alma", fap, "-o", &path("b.gif"), "--audio", fap]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = fbakit(&["render", "alma", fap, "-o", &path("c.avi")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains(".avi"), "{}", stderr(&o));
    // A missing soundtrack is bad input.
    let o = fbakit(&[
        "render",
        "alma",
        fap,
        "-o",
        &path("d.mp4"),
        "--audio",
        &path("none.wav"),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // A folder that holds other files is not overwritten.
    std::fs::create_dir(dir.path().join("mine")).unwrap();
    std::fs::write(dir.path().join("mine/notes.txt"), "keep").unwrap();
    let o = fbakit(&["render", "alma", fap, "-o", &path("mine")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("mine/notes.txt")).unwrap(),
        "keep"
    );
    if ffmpeg_available() {
        // ffmpeg itself fails (the "audio" is a FAP file): exit 1 and no mp4.
        let o = fbakit(&["render", "alma", fap, "-o", &path("e.mp4"), "--audio", fap]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("ffmpeg: failed"), "{}", stderr(&o));
    } else {
        eprintln!("skip the ffmpeg failure case: ffmpeg is not installed");
    }
    assert_eq!(
        others(dir.path(), &["short.fap", "bad.fap", "mine"]),
        Vec::<String>::new()
    );
}

#[test]
fn without_ffmpeg_mp4_says_what_to_install() {
    let dir = tempfile::tempdir().unwrap();
    let fap = short_stream(dir.path());
    let out = dir.path().join("x.mp4");
    let empty = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args([
            "render",
            "alma",
            fap.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .env("PATH", empty.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("apt-get install ffmpeg"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
    assert!(!out.exists());
    assert_eq!(others(dir.path(), &["short.fap"]), Vec::<String>::new());
}
