//! `fbakit speak` and `fbakit::speech` with espeak-ng installed: stream timing against the
//! WAV, visemes in a plausible order for known words, the audio equal to what the
//! `espeak-ng` program writes, and the talking-head MP4 of the README. Each test prints a
//! skip note when espeak-ng (or, for the video, ffmpeg) is not installed.

use std::path::Path;
use std::process::{Command, Output};

use fbakit::fap::{read_fap_file, ReadOptions};
use fbakit::speech::{espeak_available, say, SpeechOptions};

mod support;
use support::cli::fbakit_in as fbakit;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn skip(test: &str) -> bool {
    if espeak_available() {
        return false;
    }
    eprintln!("skip {test}: espeak-ng is not installed (apt-get install espeak-ng)");
    true
}

fn wav_seconds(path: &Path) -> (f64, Vec<i16>) {
    let mut r = hound::WavReader::open(path).unwrap();
    let rate = f64::from(r.spec().sample_rate);
    let samples: Vec<i16> = r.samples::<i16>().map(|s| s.unwrap()).collect();
    (samples.len() as f64 / rate, samples)
}

/// The stream kinds (`codec_type=...` lines) and the duration of a media file, by ffprobe.
fn probe(dir: &Path, file: &str) -> (String, f64) {
    let p = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-show_entries",
            "stream=codec_type:format=duration",
            "-of",
            "default=nw=1",
            file,
        ])
        .current_dir(dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&p.stdout).into_owned();
    let duration = text
        .lines()
        .find_map(|l| l.strip_prefix("duration="))
        .and_then(|d| d.parse().ok())
        .unwrap_or_else(|| panic!("no duration in {text}"));
    (text, duration)
}

/// The visemes a word shows, in order, without rest and without repeats.
fn viseme_sequence(text: &str) -> Vec<u8> {
    let (_, anim) = say(text, "en", &SpeechOptions::default()).unwrap();
    let mut seq: Vec<u8> = Vec::new();
    for k in &anim.keys {
        let n = k.viseme.number();
        if n != 0 && seq.last() != Some(&n) {
            seq.push(n);
        }
    }
    seq
}

#[test]
fn stream_lasts_as_long_as_the_wav() {
    if skip("stream_lasts_as_long_as_the_wav") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for text in [
        "Hello world",
        "The quick brown fox jumps over the lazy dog.",
    ] {
        let o = fbakit(
            dir.path(),
            &["speak", text, "-o", "s.fap", "--wav", "s.wav"],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let (audio, _) = wav_seconds(&dir.path().join("s.wav"));
        let (stream, warnings) =
            read_fap_file(&dir.path().join("s.fap"), &ReadOptions::strict()).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        let video = stream.frames.len() as f64 / stream.frame_rate;
        assert_eq!(stream.frame_rate, 25.0);
        // Within half a frame (20 ms) of the audio.
        assert!(
            (video - audio).abs() <= 0.5 / 25.0 + 1e-9,
            "{text}: stream {video} s, wav {audio} s"
        );
        assert!(audio > 0.5, "{text}: {audio} s");
    }
}

#[test]
fn known_words_show_visemes_in_order() {
    if skip("known_words_show_visemes_in_order") {
        return;
    }
    // "Bob": lips closed, open rounded o, lips closed.
    assert_eq!(viseme_sequence("Bob"), vec![1, 13, 1]);
    // "Sue": s then rounded u.
    assert_eq!(viseme_sequence("Sue"), vec![7, 14]);
    // "fish": f, I, sh.
    assert_eq!(viseme_sequence("fish"), vec![2, 12, 6]);
    // "Hello world": h takes the vowel's shape; l; the oU glide; w is rounded like U.
    let hello = viseme_sequence("Hello world");
    assert_eq!(&hello[..4], &[11, 8, 13, 14], "{hello:?}");
    assert_eq!(hello.last(), Some(&4), "ends on d: {hello:?}");
}

#[test]
fn frames_follow_the_keys() {
    if skip("frames_follow_the_keys") {
        return;
    }
    let (_, anim) = say("Bob", "en", &SpeechOptions::default()).unwrap();
    let fps = anim.stream.frame_rate;
    // At the frame nearest each key the key's viseme dominates the blend.
    for k in anim.keys.iter().filter(|k| k.viseme.number() != 0) {
        let n = (k.time * fps).round() as usize;
        let v = anim.stream.frames[n].viseme().unwrap();
        let weight = |which| {
            let w1 = f64::from(v.blend) / 63.0;
            if v.select1 == v.select2 {
                1.0
            } else if which {
                w1
            } else {
                1.0 - w1
            }
        };
        let share = if v.select1 == k.viseme {
            weight(true)
        } else if v.select2 == k.viseme {
            weight(false)
        } else {
            0.0
        };
        assert!(share > 0.5, "key {k:?} at frame {n}: {v:?}");
    }
    // The stream starts and ends at rest.
    let first = anim.stream.frames[0].viseme().unwrap();
    assert_eq!(first.select1.number(), 0);
    assert_eq!(first.blend, 63);
}

#[test]
fn audio_equals_the_espeak_ng_program() {
    if skip("audio_equals_the_espeak_ng_program") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cli = Command::new("espeak-ng")
        .args(["-v", "en", "-w"])
        .arg(dir.path().join("cli.wav"))
        .arg("Hello world")
        .output();
    let Ok(cli) = cli else {
        eprintln!("skip audio_equals_the_espeak_ng_program: no espeak-ng program on PATH");
        return;
    };
    assert!(cli.status.success());
    let o = fbakit(
        dir.path(),
        &["speak", "Hello world", "-o", "h.fap", "--wav", "h.wav"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, ours) = wav_seconds(&dir.path().join("h.wav"));
    let (_, theirs) = wav_seconds(&dir.path().join("cli.wav"));
    assert_eq!(ours.len(), theirs.len());
    assert!(ours == theirs, "same synthesis, same samples");
}

#[test]
fn bad_input_is_exit_2_and_writes_nothing() {
    if skip("bad_input_is_exit_2_and_writes_nothing") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = fbakit(dir.path(), &["speak", "  ", "-o", "x.fap"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = fbakit(
        dir.path(),
        &["speak", "hi", "-o", "x.fap", "--voice", "no-such-voice"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no-such-voice"), "{}", stderr(&o));
    let o = fbakit(
        dir.path(),
        &["speak", "hi", "-o", "x.fap", "--wav", "x.fap"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn low_level_mouth_moves_the_jaw() {
    if skip("low_level_mouth_moves_the_jaw") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = fbakit(
        dir.path(),
        &["speak", "Papa", "-o", "p.fap", "--mouth", "faps", "--json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["mouth"], "low-level");
    let (stream, _) = read_fap_file(&dir.path().join("p.fap"), &ReadOptions::strict()).unwrap();
    let jaw: Vec<f64> = stream
        .frames
        .iter()
        .map(|f| f.value(fbakit::spec::FapId::OPEN_JAW).unwrap())
        .collect();
    let max = jaw.iter().copied().fold(0.0, f64::max);
    assert!(max > 150.0, "the a of papa opens the jaw: {jaw:?}");
    assert!(stream.frames.iter().all(|f| f.viseme().is_none()));
}

#[test]
fn talking_head_mp4_from_typed_text() {
    if skip("talking_head_mp4_from_typed_text") {
        return;
    }
    if !fbakit::export::video::ffmpeg_available() {
        eprintln!("skip talking_head_mp4_from_typed_text: ffmpeg is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = fbakit(
        dir.path(),
        &[
            "speak",
            "Hello world",
            "-o",
            "hello.fap",
            "--wav",
            "hello.wav",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = fbakit(
        dir.path(),
        &[
            "render",
            "alma",
            "hello.fap",
            "--audio",
            "hello.wav",
            "-o",
            "hello.mp4",
            "--size",
            "96x96",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (text, duration) = probe(dir.path(), "hello.mp4");
    assert!(text.contains("codec_type=video"), "{text}");
    assert!(text.contains("codec_type=audio"), "{text}");
    let (audio, _) = wav_seconds(&dir.path().join("hello.wav"));
    assert!(
        (duration - audio).abs() < 0.1,
        "mp4 {duration} s, wav {audio} s"
    );
}

#[test]
fn one_command_from_typed_text_to_a_talking_head() {
    if skip("one_command_from_typed_text_to_a_talking_head") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // A page: the bundled real head (the default face) says it; the page plays on load.
    let o = fbakit(
        dir.path(),
        &["speak", "Good morning", "-o", "hi.html", "--json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["talking_head"]["face"], "ict");
    let frames = r["frames"].as_u64().unwrap();
    assert_eq!(r["talking_head"]["frames"].as_u64().unwrap(), frames);
    let html = std::fs::read_to_string(dir.path().join("hi.html")).unwrap();
    assert!(html.contains("<html") && html.len() > 100_000);
    // A GIF on another face (no ffmpeg needed); refusing to overwrite that face's file.
    let o = fbakit(
        dir.path(),
        &[
            "speak", "Hi", "-o", "hi.gif", "--face", "alma", "--size", "64x64",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::metadata(dir.path().join("hi.gif")).unwrap().len() > 1000);
    let o = fbakit(
        dir.path(),
        &["speak", "Hi", "-o", "hi.gif", "--face", "hi.gif"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("hi.gif"), "{}", stderr(&o));
    if !fbakit::export::video::ffmpeg_available() {
        eprintln!("skip the mp4 part: ffmpeg is not installed");
        return;
    }
    // An mp4 whose soundtrack is the speech: as long as the stream.
    let o = fbakit(
        dir.path(),
        &[
            "speak",
            "Hello world",
            "-o",
            "hi.mp4",
            "--size",
            "96x96",
            "--json",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(r["talking_head"]["audio"].is_string(), "{r:#}");
    let audio = r["audio_seconds"].as_f64().unwrap();
    let (text, duration) = probe(dir.path(), "hi.mp4");
    assert!(text.contains("codec_type=audio"), "{text}");
    assert!(
        (duration - audio).abs() < 0.1,
        "mp4 {duration} s, speech {audio} s"
    );
}
