//! Measures `fbakit::speech::lipsync` on recordings with known phone times: espeak-ng
//! renditions of sentences in other voices and at other rates, resampled, padded and
//! with noise, aligned against their transcripts; prints issue 22's three figures per
//! condition, the same figures for stretching the transcript's rendition over the
//! recording's speech (the baseline the issue measured), the figures without a transcript
//! (PocketSphinx phone recognition, when installed), and the real-time factor. One
//! condition is the recording encoded as MP3 at 64 kbit/s (with ffmpeg, when installed).
//!
//! Run: `cargo run --release --example lipsync_eval` (needs espeak-ng; ffmpeg and
//! pocketsphinx + pocketsphinx-en-us for the MP3 condition and the recognition figures).
#![allow(dead_code)] // Also included as a module by the tests, which do not call `main`.

use std::time::Instant;

use fbakit::fap::VisemeParams;
use fbakit::speech::espeak::{speak_at, TimedPhoneme};
use fbakit::speech::lipsync::coarticulation::lipsync_keys;
use fbakit::speech::lipsync::evaluation::{degrade, score, Degradation, LipsyncScore};
use fbakit::speech::lipsync::recognition::{recognise_file, recognition_available};
use fbakit::speech::lipsync::{
    analyse_file, lipsync_recognised, lipsync_transcript_at, render_transcript, LipsyncOptions,
};
use fbakit::speech::{animation::key_frame, MouthFaps};

/// Sentences rich in lip closures and rounded vowels.
pub const SENTENCES: [&str; 8] = [
    "My mother bought a map of Bombay.",
    "Peter Piper picked a peck of pickled peppers.",
    "The quick brown fox jumps over the lazy dog.",
    "Bob brought a big blue balloon to the beach.",
    "We remember Mary's famous lemon pie.",
    "Please open the window before the meeting begins.",
    "A number of people moved to the mountains in May.",
    "Thomas wrote a book about the moon and the sun.",
];

/// One recording condition: the voice that "records", its rate, and the degradation.
pub struct Condition {
    /// A name for the report.
    pub name: &'static str,
    /// espeak-ng voice of the recording.
    pub voice: &'static str,
    /// Its rate, words per minute.
    pub rate: u32,
    /// What is done to the audio.
    pub degradation: Degradation,
    /// Whether the recording is then encoded as MP3 at 64 kbit/s.
    pub mp3: bool,
}

/// The conditions measured.
pub fn conditions() -> Vec<Condition> {
    vec![
        Condition {
            name: "en-us, 140 wpm, 44.1 kHz stereo, 20 dB SNR",
            voice: "en-us",
            rate: 140,
            degradation: Degradation::default(),
            mp3: false,
        },
        Condition {
            name: "en-us+f3, 200 wpm, 48 kHz, 15 dB SNR",
            voice: "en-us+f3",
            rate: 200,
            degradation: Degradation {
                sample_rate: 48_000,
                channels: 1,
                snr_db: Some(15.0),
                lead_in: 0.5,
                seed: 2,
            },
            mp3: false,
        },
        Condition {
            name: "en-gb-x-rp+m3, 120 wpm, 8 kHz, 25 dB SNR",
            voice: "en-gb-x-rp+m3",
            rate: 120,
            degradation: Degradation {
                sample_rate: 8_000,
                channels: 1,
                snr_db: Some(25.0),
                lead_in: 0.2,
                seed: 3,
            },
            mp3: false,
        },
        Condition {
            name: "en-us+m2, 160 wpm, 44.1 kHz stereo, 20 dB SNR, MP3 64 kbit/s",
            voice: "en-us+m2",
            rate: 160,
            degradation: Degradation {
                sample_rate: 44_100,
                channels: 2,
                snr_db: Some(20.0),
                lead_in: 0.4,
                seed: 4,
            },
            mp3: true,
        },
    ]
}

/// Scores of one case: the aligner's and the stretched rendition's; and seconds of audio and
/// of work.
pub struct CaseResult {
    /// The aligner.
    pub aligned: LipsyncScore,
    /// The baseline.
    pub stretched: LipsyncScore,
    /// Length of the recording.
    pub audio_seconds: f64,
    /// Time to analyse and align (no video).
    pub work_seconds: f64,
    /// Overall confidence.
    pub confidence: f64,
    /// Without the transcript (PocketSphinx), when asked for and installed.
    pub recognised: Option<LipsyncScore>,
    /// Time to analyse and recognise without the transcript (no video), wall clock.
    pub recognised_seconds: f64,
}

fn frames_of(keys: &[fbakit::speech::VisemeKey], duration: f64, fps: f64) -> Vec<VisemeParams> {
    let count = (duration * fps).round() as u64;
    (0..count)
        .filter_map(|n| key_frame(keys, n, fps, MouthFaps::Visemes).viseme())
        .collect()
}

/// Whether ffmpeg can be run (for the MP3 condition).
pub fn ffmpeg_available() -> bool {
    std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Runs one sentence under one condition (with the transcript only).
pub fn run_case(text: &str, c: &Condition, fps: f64) -> fbakit::error::Result<CaseResult> {
    run_case_with(text, c, fps, false)
}

/// A recording of `text` under condition `c` in a temporary directory: the directory (kept
/// while the file is used), the file, and its phones with their times.
pub fn make_recording(
    text: &str,
    c: &Condition,
) -> fbakit::error::Result<(tempfile::TempDir, std::path::PathBuf, Vec<TimedPhoneme>)> {
    let recording = speak_at(text, c.voice, c.rate)?;
    let (wav, truth) = degrade(&recording, &c.degradation)?;
    let dir = tempfile::tempdir().map_err(|e| fbakit::error::Error::io("tempdir", e))?;
    let mut path = dir.path().join("case.wav");
    std::fs::write(&path, wav).map_err(|e| fbakit::error::Error::io(&path, e))?;
    if c.mp3 {
        let mp3 = dir.path().join("case.mp3");
        let ok = std::process::Command::new("ffmpeg")
            .args(["-v", "error", "-y", "-i"])
            .arg(&path)
            .args(["-b:a", "64k"])
            .arg(&mp3)
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            return Err(fbakit::error::Error::MissingTool(
                "ffmpeg (apt-get install ffmpeg) encodes the MP3 condition".into(),
            ));
        }
        path = mp3;
    }
    Ok((dir, path, truth))
}

/// The score of one sentence under one condition without its transcript (PocketSphinx must
/// be installed).
pub fn run_recognised(text: &str, c: &Condition, fps: f64) -> fbakit::error::Result<LipsyncScore> {
    let (_dir, path, truth) = make_recording(text, c)?;
    let rec = analyse_file(&path, &mut |_| {})?;
    let phones = recognise_file(&path, &mut |_| {})?;
    let sync = lipsync_recognised(&rec, phones, fps)?;
    Ok(score(&truth, &frames_of(&sync.keys, rec.seconds, fps), fps))
}

/// Runs one sentence under one condition; also without the transcript when `recognise`.
pub fn run_case_with(
    text: &str,
    c: &Condition,
    fps: f64,
    recognise: bool,
) -> fbakit::error::Result<CaseResult> {
    let (_dir, path, truth) = make_recording(text, c)?;
    let started = Instant::now();
    let rec = analyse_file(&path, &mut |_| {})?;
    let sync = lipsync_transcript_at(&rec, text, &LipsyncOptions::default(), fps)?;
    let work_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let recognised = if recognise && recognition_available() {
        let rec = analyse_file(&path, &mut |_| {})?;
        let phones = recognise_file(&path, &mut |_| {})?;
        let sync = lipsync_recognised(&rec, phones, fps)?;
        Some(score(&truth, &frames_of(&sync.keys, rec.seconds, fps), fps))
    } else {
        None
    };
    let recognised_seconds = started.elapsed().as_secs_f64();
    let aligned = score(&truth, &frames_of(&sync.keys, rec.seconds, fps), fps);
    // Baseline: the rendition's phones stretched linearly over the recording's speech.
    let rendition = render_transcript(text, "en")?;
    let spoken: Vec<&TimedPhoneme> = rendition
        .phonemes
        .iter()
        .filter(|p| !p.symbol.starts_with('_'))
        .collect();
    let (r0, r1) = (
        spoken.first().map_or(0.0, |p| p.start),
        spoken.last().map_or(1.0, |p| p.end),
    );
    let (s0, s1) = rec.activity.speech_span;
    let scale = (s1 - s0) / (r1 - r0).max(1e-6);
    let stretched: Vec<TimedPhoneme> = rendition
        .phonemes
        .iter()
        .map(|p| TimedPhoneme {
            symbol: p.symbol.clone(),
            start: (s0 + (p.start - r0) * scale).max(0.0),
            end: (s0 + (p.end - r0) * scale).max(0.0),
        })
        .collect();
    let (keys, _) = lipsync_keys(&stretched, rec.seconds, &[], fps);
    let stretched = score(&truth, &frames_of(&keys, rec.seconds, fps), fps);
    Ok(CaseResult {
        aligned,
        stretched,
        audio_seconds: rec.seconds,
        work_seconds,
        confidence: sync.confidence,
        recognised,
        recognised_seconds,
    })
}

fn line(name: &str, s: &LipsyncScore) {
    println!(
        "  {name:<10} closures {:>5.1} % ({}/{})  agreement {:>5.1} %  false closures {:>4.1} %  ({} speech frames; PP on other consonants {:>4.1} %)",
        100.0 * s.closure_rate(),
        s.closures_shown,
        s.closures,
        100.0 * s.agreement(),
        100.0 * s.false_closure_rate(),
        s.speech_frames,
        100.0 * s.consonant_closure_rate()
    );
}

fn main() {
    if !fbakit::speech::espeak_available() {
        eprintln!("espeak-ng is not installed (apt-get install espeak-ng)");
        std::process::exit(1);
    }
    let (mut audio, mut work, mut work_recognised) = (0.0, 0.0, 0.0);
    let mut all = (LipsyncScore::default(), LipsyncScore::default());
    let mut all_recognised = LipsyncScore::default();
    let recognise = recognition_available();
    if !recognise {
        println!("(PocketSphinx is not installed: no figures without a transcript)");
    }
    let have_ffmpeg = ffmpeg_available();
    for c in conditions() {
        if c.mp3 && !have_ffmpeg {
            println!("{}: skipped (ffmpeg is not installed)", c.name);
            continue;
        }
        let mut sum = (LipsyncScore::default(), LipsyncScore::default());
        let mut recognised = LipsyncScore::default();
        let mut conf = Vec::new();
        for text in SENTENCES {
            match run_case_with(text, &c, 25.0, recognise) {
                Ok(r) => {
                    sum.0.add(&r.aligned);
                    sum.1.add(&r.stretched);
                    if let Some(s) = &r.recognised {
                        recognised.add(s);
                    }
                    audio += r.audio_seconds;
                    work += r.work_seconds;
                    work_recognised += r.recognised_seconds;
                    conf.push(r.confidence);
                    if std::env::var_os("VERBOSE").is_some() {
                        println!("    {text}: conf {:.2}", r.confidence);
                        line("aligned", &r.aligned);
                    }
                }
                Err(e) => println!("  {text}: {e}"),
            }
        }
        println!(
            "{} (confidence {:.2}..{:.2})",
            c.name,
            conf.iter().cloned().fold(1.0, f64::min),
            conf.iter().cloned().fold(0.0, f64::max)
        );
        line("aligned", &sum.0);
        line("stretched", &sum.1);
        if recognise {
            line("recognised", &recognised);
        }
        all.0.add(&sum.0);
        all.1.add(&sum.1);
        all_recognised.add(&recognised);
    }
    println!("all conditions");
    line("aligned", &all.0);
    line("stretched", &all.1);
    if recognise {
        line("recognised", &all_recognised);
    }
    println!(
        "{audio:.1} s of audio analysed and aligned in {work:.2} s: {:.0}x real time",
        audio / work.max(1e-9)
    );
    if recognise {
        println!(
            "without a transcript: {audio:.1} s of audio analysed and recognised in {work_recognised:.2} s: {:.0}x real time",
            audio / work_recognised.max(1e-9)
        );
    }
}
