//! Measures `fbakit::speech::lipsync` on recordings with known phone times: espeak-ng
//! renditions of sentences in other voices and at other rates, resampled, padded and
//! with noise, aligned against their transcripts; prints issue 22's three figures per
//! condition, the same figures for stretching the transcript's rendition over the
//! recording's speech (the baseline the issue measured), the figures without a transcript
//! (PocketSphinx phone recognition, when installed), and the real-time factor. One
//! condition is the recording encoded as MP3 at 64 kbit/s (with ffmpeg, when installed).
//!
//! espeak-ng's formant voices sound unlike people. So that the figures are not only theirs,
//! more conditions are "recorded" by Festival's voices built from real speakers' recordings
//! (a diphone voice concatenates a speaker's recorded diphones, an HTS voice is a statistical
//! model trained on a speaker's hours of speech); Festival reports the times of the phones
//! it says. Festival is for this evaluation only: the conditions are skipped, with a note,
//! when it or a voice is not installed.
//!
//! `LIPSYNC_EVAL_LONG=SECONDS` measures long recordings instead: each condition's voice says
//! the sentences in turn, joined with pauses, for about that long (`LIPSYNC_EVAL_KEEP=DIR`
//! keeps each recording, its transcript and its phones there; `LIPSYNC_EVAL_VOICE=NAME`
//! measures one voice's conditions).
//!
//! Run: `cargo run --release --example lipsync_eval` (`LIPSYNC_WARP_ONLY=1` measures the
//! transcript path without PocketSphinx's forced alignment; needs espeak-ng; ffmpeg and
//! pocketsphinx + pocketsphinx-en-us for the MP3 condition and the recognition figures;
//! festival festvox-kallpc16k festvox-kdlpc16k festvox-us-slt-hts for the Festival ones).
//! `LIPSYNC_EVAL_RECOGNISE=phones|words|words-aligned|words-mixed` chooses how the figures
//! without a transcript recognise speech (`speech::lipsync::words` has the figures of each).
#![allow(dead_code)] // Also included as a module by the tests, which do not call `main`.

use std::time::Instant;

use fbakit::fap::VisemeParams;
use fbakit::speech::espeak::{speak_at, TimedPhoneme, Utterance};
use fbakit::speech::lipsync::coarticulation::lipsync_keys;
use fbakit::speech::lipsync::evaluation::{degrade, score, Degradation, LipsyncScore};
use fbakit::speech::lipsync::recognition::{
    arpabet_to_espeak, recognise_file_with, recognition_available, Recognise,
};
use fbakit::speech::lipsync::words::WordPhones;
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

/// The synthesiser that "records" a condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Synth {
    /// espeak-ng (formant voices).
    Espeak,
    /// Festival (voices built from a speaker's recordings).
    Festival,
}

/// One recording condition: the voice that "records", its rate, and the degradation.
pub struct Condition {
    /// A name for the report.
    pub name: &'static str,
    /// Which synthesiser speaks.
    pub synth: Synth,
    /// Its voice: espeak-ng's name, or the Festival voice (`voice_NAME` selects it).
    pub voice: &'static str,
    /// espeak-ng's rate, words per minute (Festival's voices keep their own).
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
            synth: Synth::Espeak,
            voice: "en-us",
            rate: 140,
            degradation: Degradation::default(),
            mp3: false,
        },
        Condition {
            name: "en-us+f3, 200 wpm, 48 kHz, 15 dB SNR",
            synth: Synth::Espeak,
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
            synth: Synth::Espeak,
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
            synth: Synth::Espeak,
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
        Condition {
            name: "Festival kal (diphone), 44.1 kHz stereo, 20 dB SNR",
            synth: Synth::Festival,
            voice: "kal_diphone",
            rate: 0,
            degradation: Degradation::default(),
            mp3: false,
        },
        Condition {
            name: "Festival slt (HTS), 48 kHz, 15 dB SNR",
            synth: Synth::Festival,
            voice: "cmu_us_slt_arctic_hts",
            rate: 0,
            degradation: Degradation {
                sample_rate: 48_000,
                channels: 1,
                snr_db: Some(15.0),
                lead_in: 0.5,
                seed: 12,
            },
            mp3: false,
        },
        Condition {
            name: "Festival ked (diphone), 8 kHz, 25 dB SNR",
            synth: Synth::Festival,
            voice: "ked_diphone",
            rate: 0,
            degradation: Degradation {
                sample_rate: 8_000,
                channels: 1,
                snr_db: Some(25.0),
                lead_in: 0.2,
                seed: 13,
            },
            mp3: false,
        },
        Condition {
            name: "Festival slt (HTS), 44.1 kHz stereo, 20 dB SNR, MP3 64 kbit/s",
            synth: Synth::Festival,
            voice: "cmu_us_slt_arctic_hts",
            rate: 0,
            degradation: Degradation {
                sample_rate: 44_100,
                channels: 2,
                snr_db: Some(20.0),
                lead_in: 0.4,
                seed: 14,
            },
            mp3: true,
        },
    ]
}

/// Clean real-speaker conditions (Festival voices, no noise, 16 kHz mono): the held-out
/// check is clean read speech, so these are reported on their own, apart from the degraded
/// conditions' totals.
pub fn clean_conditions() -> Vec<Condition> {
    let clean = |seed| Degradation {
        sample_rate: 16_000,
        channels: 1,
        snr_db: None,
        lead_in: 0.3,
        seed,
    };
    vec![
        Condition {
            name: "Festival kal (diphone), 16 kHz, clean",
            synth: Synth::Festival,
            voice: "kal_diphone",
            rate: 0,
            degradation: clean(21),
            mp3: false,
        },
        Condition {
            name: "Festival slt (HTS), 16 kHz, clean",
            synth: Synth::Festival,
            voice: "cmu_us_slt_arctic_hts",
            rate: 0,
            degradation: clean(22),
            mp3: false,
        },
        Condition {
            name: "Festival ked (diphone), 16 kHz, clean",
            synth: Synth::Festival,
            voice: "ked_diphone",
            rate: 0,
            degradation: clean(23),
            mp3: false,
        },
    ]
}

/// Whether Festival and its voice `voice` are installed.
pub fn festival_voice_available(voice: &str) -> bool {
    festival_run(&format!("(voice_{voice})\n(format t \"ready\\n\")\n"))
        .is_ok_and(|out| out.contains("ready"))
}

/// Festival's output for the Scheme `script`, run in batch mode.
fn festival_run(script: &str) -> fbakit::error::Result<String> {
    let dir = tempfile::tempdir().map_err(|e| fbakit::error::Error::io("tempdir", e))?;
    let path = dir.path().join("script.scm");
    std::fs::write(&path, script).map_err(|e| fbakit::error::Error::io(&path, e))?;
    let out = std::process::Command::new("festival")
        .arg("--batch")
        .arg(&path)
        .output()
        .map_err(|e| fbakit::error::Error::MissingTool(format!("festival: {e}")))?;
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// `text` spoken by Festival's `voice`, with the times of its phones (mapped to espeak-ng's
/// mnemonics, which the scoring knows).
pub fn festival_speak(text: &str, voice: &str) -> fbakit::error::Result<Utterance> {
    let dir = tempfile::tempdir().map_err(|e| fbakit::error::Error::io("tempdir", e))?;
    let wav = dir.path().join("festival.wav");
    let quoted: String = text.chars().filter(|c| !matches!(c, '"' | '\\')).collect();
    // Each segment is printed as its name and end time; it starts where the last ended.
    let out = festival_run(&format!(
        "(voice_{voice})\n\
         (set! utt (utt.synth (eval (list 'Utterance 'Text \"{quoted}\"))))\n\
         (utt.save.wave utt \"{}\" 'riff)\n\
         (mapcar (lambda (s) (format t \"seg %s %f\\n\" (item.name s) (item.feat s \"end\"))) \
         (utt.relation.items utt 'Segment))\n",
        wav.display()
    ))?;
    let failed = || {
        fbakit::error::Error::MissingTool(format!("festival could not say {text:?} with {voice}"))
    };
    let mut phonemes: Vec<TimedPhoneme> = Vec::new();
    for l in out.lines() {
        let f: Vec<&str> = l.split_whitespace().collect();
        if let ["seg", name, end] = f.as_slice() {
            let end: f64 = end.parse().map_err(|_| failed())?;
            let start = phonemes.last().map_or(0.0, |p| p.end);
            phonemes.push(TimedPhoneme {
                symbol: festival_to_espeak(name).to_string(),
                start,
                end: end.max(start),
            });
        }
    }
    let mut reader = hound::WavReader::open(&wav).map_err(|_| failed())?;
    let spec = reader.spec();
    let samples: Vec<i16> = reader
        .samples::<i16>()
        .step_by(usize::from(spec.channels.max(1)))
        .collect::<Result<_, _>>()
        .map_err(|_| failed())?;
    if phonemes.is_empty() || samples.is_empty() {
        return Err(failed());
    }
    Ok(Utterance {
        sample_rate: spec.sample_rate,
        samples,
        phonemes,
        words: Vec::new(),
    })
}

/// The espeak-ng mnemonic of a phone of Festival's English voices (the "radio" phone set:
/// ARPAbet in lower case, with a few more).
pub fn festival_to_espeak(phone: &str) -> &'static str {
    match phone {
        "ax" => "@",
        "axr" => "3",
        "ix" => "I",
        "dx" => "t",
        "el" => "@L",
        "em" => "m",
        "en" | "nx" => "n",
        "hv" => "h",
        p => arpabet_to_espeak(&p.to_ascii_uppercase()),
    }
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
    let recording = match c.synth {
        Synth::Espeak => speak_at(text, c.voice, c.rate)?,
        Synth::Festival => festival_speak(text, c.voice)?,
    };
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
    let phones = recognise_file_with(&path, recogniser(), &mut |_| {})?;
    let sync = lipsync_recognised(&rec, phones, fps)?;
    Ok(score(&truth, &frames_of(&sync.keys, rec.seconds, fps), fps))
}

/// How the figures without a transcript recognise speech: `LIPSYNC_EVAL_RECOGNISE=phones`,
/// `words` (dictionary phones sharing each word's time), `words-aligned` or `words-mixed`
/// ([`WordPhones`]), else the library's default.
pub fn recogniser() -> Recognise {
    match std::env::var("LIPSYNC_EVAL_RECOGNISE").as_deref() {
        Ok("phones") => Recognise::Phones,
        Ok("words") => Recognise::Words(WordPhones::Shared),
        Ok("words-aligned") => Recognise::Words(WordPhones::Aligned),
        Ok("words-mixed") => Recognise::Words(WordPhones::Mixed),
        _ => Recognise::default(),
    }
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
    let opts = LipsyncOptions {
        // The warp alone, for comparison with forced alignment.
        forced: std::env::var_os("LIPSYNC_WARP_ONLY").is_none(),
        ..LipsyncOptions::default()
    };
    let sync = lipsync_transcript_at(&rec, text, &opts, fps)?;
    let work_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let recognised = if recognise && recognition_available() {
        let rec = analyse_file(&path, &mut |_| {})?;
        let phones = recognise_file_with(&path, recogniser(), &mut |_| {})?;
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

/// More sentences for the long recordings, which speak these and [`SENTENCES`] in turn.
pub const MORE_SENTENCES: [&str; 16] = [
    "Every morning the baker opens his shop at half past five.",
    "The museum will be closed for repairs until the end of March.",
    "She played the violin in a small band for many years.",
    "Before the storm, the boats were pulled up onto the beach.",
    "My brother bought a bicycle with money from his summer job.",
    "The committee met on Monday to approve the budget.",
    "Most maps of the period show the river much farther west.",
    "A warm breeze moved through the open windows of the room.",
    "He promised to bring back a book from the public library.",
    "The puppy chewed up both of my brand new boots.",
    "Members of the team will meet the mayor in the main hall.",
    "Put the blue bowl on the top shelf above the microwave.",
    "We watched the moon rise slowly over the bay.",
    "Mark the problem numbers you want to review before the exam.",
    "The old bridge was built from stone more than a hundred years ago.",
    "Many people prefer to walk when the weather is mild.",
];

/// A long recording under condition `c`: the sentences spoken one at a time in turn and
/// joined with pauses of 0.3 to 1.2 s until it lasts at least `seconds`. The temporary
/// directory (kept while the file is used), the file, its transcript and its phones.
pub fn make_long_recording(
    c: &Condition,
    seconds: f64,
) -> fbakit::error::Result<(
    tempfile::TempDir,
    std::path::PathBuf,
    String,
    Vec<TimedPhoneme>,
)> {
    let texts: Vec<&str> = SENTENCES.iter().chain(&MORE_SENTENCES).copied().collect();
    let mut said: Vec<Option<Utterance>> = vec![None; texts.len()];
    let mut whole = Utterance {
        sample_rate: 0,
        samples: Vec::new(),
        phonemes: Vec::new(),
        words: Vec::new(),
    };
    let mut transcript = String::new();
    let mut k = 0usize;
    while whole.duration() < seconds || k == 0 {
        let i = k % texts.len();
        if said[i].is_none() {
            said[i] = Some(match c.synth {
                Synth::Espeak => speak_at(texts[i], c.voice, c.rate)?,
                Synth::Festival => festival_speak(texts[i], c.voice)?,
            });
        }
        let u = said[i].as_ref().expect("spoken above");
        whole.sample_rate = u.sample_rate;
        // Pauses of several lengths, some too short to cut at.
        let pause = [0.6, 0.3, 1.2, 0.45, 0.8][k % 5];
        let gap = if k == 0 { 0.0 } else { pause };
        let offset = whole.duration() + gap;
        if gap > 0.0 {
            whole.phonemes.push(TimedPhoneme {
                symbol: "_".into(),
                start: whole.duration(),
                end: offset,
            });
        }
        whole.samples.extend(std::iter::repeat_n(
            0i16,
            (gap * f64::from(u.sample_rate)) as usize,
        ));
        whole.samples.extend_from_slice(&u.samples);
        whole
            .phonemes
            .extend(u.phonemes.iter().map(|p| TimedPhoneme {
                start: p.start + offset,
                end: p.end + offset,
                ..p.clone()
            }));
        if !transcript.is_empty() {
            transcript.push(' ');
        }
        transcript.push_str(texts[i]);
        k += 1;
    }
    let (wav, truth) = degrade(&whole, &c.degradation)?;
    let dir = tempfile::tempdir().map_err(|e| fbakit::error::Error::io("tempdir", e))?;
    let path = dir.path().join("long.wav");
    std::fs::write(&path, wav).map_err(|e| fbakit::error::Error::io(&path, e))?;
    Ok((dir, path, transcript, truth))
}

/// The score of a long recording under condition `c` with its transcript.
pub struct LongResult {
    /// The aligner's score.
    pub aligned: LipsyncScore,
    /// Length of the recording.
    pub audio_seconds: f64,
    /// Time to analyse and align (no video).
    pub work_seconds: f64,
    /// The lip sync's warnings.
    pub warnings: Vec<String>,
    /// The phones' confidences (forced ones from the recogniser's scores).
    pub confidences: Vec<f64>,
}

/// Aligns a recording of at least `seconds` made by [`make_long_recording`]; when `keep` is
/// given the recording and its transcript are copied there (`long.wav`, `long.txt`).
pub fn run_long_case(
    c: &Condition,
    seconds: f64,
    fps: f64,
    keep: Option<&std::path::Path>,
) -> fbakit::error::Result<LongResult> {
    let (_dir, path, text, truth) = make_long_recording(c, seconds)?;
    if let Some(keep) = keep {
        let io = |e| fbakit::error::Error::io(keep, e);
        std::fs::create_dir_all(keep).map_err(io)?;
        std::fs::copy(&path, keep.join("long.wav")).map_err(io)?;
        std::fs::write(keep.join("long.txt"), &text).map_err(io)?;
        let truth = serde_json::to_string(&truth).unwrap_or_default();
        std::fs::write(keep.join("truth.json"), truth).map_err(io)?;
    }
    let started = Instant::now();
    let rec = analyse_file(&path, &mut |_| {})?;
    let opts = LipsyncOptions {
        forced: std::env::var_os("LIPSYNC_WARP_ONLY").is_none(),
        ..LipsyncOptions::default()
    };
    let sync = lipsync_transcript_at(&rec, &text, &opts, fps)?;
    let work_seconds = started.elapsed().as_secs_f64();
    Ok(LongResult {
        aligned: score(&truth, &frames_of(&sync.keys, rec.seconds, fps), fps),
        audio_seconds: rec.seconds,
        work_seconds,
        warnings: sync.warnings,
        confidences: sync.phones.iter().map(|p| p.confidence).collect(),
    })
}

/// The long-recording evaluation (`LIPSYNC_EVAL_LONG=SECONDS`): each condition's sentences
/// joined into one recording of about that length.
fn long_main(seconds: f64) {
    let keep = std::env::var_os("LIPSYNC_EVAL_KEEP").map(std::path::PathBuf::from);
    // LIPSYNC_EVAL_VOICE=NAME measures only the conditions of that voice.
    let only = std::env::var("LIPSYNC_EVAL_VOICE").ok();
    let mut total = Totals::default();
    let have_ffmpeg = ffmpeg_available();
    for c in conditions() {
        if only.as_deref().is_some_and(|v| v != c.voice) {
            continue;
        }
        if c.mp3 && !have_ffmpeg {
            continue;
        }
        if c.synth == Synth::Festival && !festival_voice_available(c.voice) {
            println!(
                "{}: skipped (Festival or its voice is not installed)",
                c.name
            );
            continue;
        }
        if c.mp3 {
            // The long path reads MP3 like any file; the condition is left to the short
            // evaluation to keep this one quick.
            continue;
        }
        let keep = keep.as_ref().map(|k| k.join(c.voice));
        match run_long_case(&c, seconds, 25.0, keep.as_deref()) {
            Ok(r) => {
                println!(
                    "{}: {:.1} s in {:.2} s ({:.0}x real time)",
                    c.name,
                    r.audio_seconds,
                    r.work_seconds,
                    r.audio_seconds / r.work_seconds.max(1e-9)
                );
                line("aligned", &r.aligned);
                for w in &r.warnings {
                    println!("    warning: {w}");
                }
                if c.synth == Synth::Festival {
                    total.aligned.add(&r.aligned);
                    total.audio += r.audio_seconds;
                    total.work += r.work_seconds;
                }
            }
            Err(e) => println!("{}: {e}", c.name),
        }
    }
    total.print("all Festival conditions, long", false);
    println!(
        "{:.1} s of audio analysed and aligned in {:.2} s: {:.0}x real time",
        total.audio,
        total.work,
        total.audio / total.work.max(1e-9)
    );
}

/// The figures without a transcript only (`LIPSYNC_EVAL_NOSCRIPT_ONLY=1`): every condition,
/// the clean Festival ones apart, with the CPU time of the recognition (this process and
/// the recogniser's).
fn noscript_main() {
    let have_ffmpeg = ffmpeg_available();
    let mut groups: [(&str, Totals); 3] = [
        ("all espeak-ng conditions", Totals::default()),
        ("all Festival conditions", Totals::default()),
        ("clean Festival conditions", Totals::default()),
    ];
    let all: Vec<(usize, Condition)> = conditions()
        .into_iter()
        .map(|c| (if c.synth == Synth::Espeak { 0 } else { 1 }, c))
        .chain(clean_conditions().into_iter().map(|c| (2, c)))
        .collect();
    let tracing = std::env::var_os("LIPSYNC_EVAL_TRACE").is_some();
    let mut traces = [FalseClosureTrace::default(); 3];
    for (group, c) in all {
        if (c.mp3 && !have_ffmpeg)
            || (c.synth == Synth::Festival && !festival_voice_available(c.voice))
        {
            println!(
                "{}: skipped (ffmpeg, Festival or its voice is missing)",
                c.name
            );
            continue;
        }
        let mut sum = Totals::default();
        let mut trace = FalseClosureTrace::default();
        for text in SENTENCES {
            let made = make_recording(text, &c);
            let Ok((_dir, path, truth)) = made else {
                println!("  {text}: {:?}", made.err());
                continue;
            };
            let before = cpu_seconds();
            let result = (|| {
                let rec = analyse_file(&path, &mut |_| {})?;
                let phones = recognise_file_with(&path, recogniser(), &mut |_| {})?;
                let sync = lipsync_recognised(&rec, phones.clone(), 25.0)?;
                let frames = frames_of(&sync.keys, rec.seconds, 25.0);
                if tracing {
                    let t = trace_false_closures(&truth, &rec, &phones, &sync, &frames, 25.0);
                    trace.add(&t);
                }
                Ok::<_, fbakit::error::Error>((rec.seconds, score(&truth, &frames, 25.0)))
            })();
            match result {
                Ok((seconds, s)) => {
                    sum.recognised.add(&s);
                    sum.aligned.add(&s);
                    sum.audio += seconds;
                    sum.work_recognised += cpu_seconds() - before;
                    if std::env::var_os("VERBOSE").is_some() {
                        line(text, &s);
                    }
                }
                Err(e) => println!("  {text}: {e}"),
            }
        }
        println!("{}", c.name);
        line("recognised", &sum.recognised);
        if tracing {
            trace.print();
            traces[group].add(&trace);
        }
        groups[group].1.add(&sum);
    }
    for (k, (name, t)) in groups.iter().enumerate() {
        println!("{name}");
        line("recognised", &t.recognised);
        if tracing {
            traces[k].print();
        }
        println!(
            "  {:.1} s of audio in {:.2} s of CPU: {:.1}x real time",
            t.audio,
            t.work_recognised,
            t.audio / t.work_recognised.max(1e-9)
        );
    }
}

/// Where a stream's closure came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClosureOrigin {
    /// An m, b or p the recogniser heard.
    Heard = 0,
    /// A dark dip in the high-frequency energy (`closures::acoustic_closures`).
    Dip = 1,
    /// An f or v heard on a deep gap (`closures::fricative_closures`).
    Fricative = 2,
}

/// The false closures of streams (PP on frames of open or rounded vowels) by what put them
/// there (`LIPSYNC_EVAL_TRACE=1`; `=2` also prints each): `[origin][where][near]`, where is
/// 0 on a frame the closure holds (between its PP keys) and 1 on a frame the blend into the
/// next shape leaves PP (spread), near is 1 when a real m/b/p lies within ±40 ms (the
/// closure is real but a frame off), 0 when none does.
#[derive(Clone, Copy, Debug, Default)]
pub struct FalseClosureTrace {
    /// Counts as described above.
    pub frames: [[[usize; 2]; 2]; 3],
    /// Of the held frames, those whose closure phone is longer than 60 ms.
    pub long_phone: usize,
}

impl FalseClosureTrace {
    fn add(&mut self, o: &FalseClosureTrace) {
        for (a, b) in self
            .frames
            .iter_mut()
            .flatten()
            .zip(o.frames.iter().flatten())
        {
            a[0] += b[0];
            a[1] += b[1];
        }
        self.long_phone += o.long_phone;
    }

    fn print(&self) {
        let total: usize = self.frames.iter().flatten().flatten().sum();
        let f = |o: usize, w: usize| {
            let [far, near] = self.frames[o][w];
            format!("{} ({} near a real one)", far + near, near)
        };
        println!(
            "  false closure frames {total}: heard m/b/p held {}, spread {}; dip held {}, spread {}; f/v held {}, spread {}; held from a phone > 60 ms {}",
            f(0, 0), f(0, 1), f(1, 0), f(1, 1), f(2, 0), f(2, 1), self.long_phone
        );
    }
}

/// Traces the false closures of `frames` (the stream of `sync`, made from the recogniser's
/// `heard` phones and the recording `rec`) against `truth`.
pub fn trace_false_closures(
    truth: &[TimedPhoneme],
    rec: &fbakit::speech::lipsync::RecordingAnalysis,
    heard: &[fbakit::speech::lipsync::AlignedPhone],
    sync: &fbakit::speech::lipsync::Lipsync,
    frames: &[VisemeParams],
    fps: f64,
) -> FalseClosureTrace {
    use fbakit::speech::lipsync::closures::{acoustic_closures, fricative_closures};
    use fbakit::speech::lipsync::coarticulation::{dominant, is_closure, MouthClass};
    let dips = acoustic_closures(&rec.frames, heard);
    let fricatives = fricative_closures(&rec.frames, heard, &rec.activity.silences, &dips);
    let origin = |p: &fbakit::speech::lipsync::AlignedPhone| {
        let mid = 0.5 * (p.start + p.end);
        let at = |ts: &[f64]| ts.iter().any(|&t| (t - mid).abs() < 1e-6);
        if p.symbol == "B" && at(&dips) {
            ClosureOrigin::Dip
        } else if p.symbol == "B" && at(&fricatives) {
            ClosureOrigin::Fricative
        } else {
            ClosureOrigin::Heard
        }
    };
    let closures: Vec<&fbakit::speech::lipsync::AlignedPhone> = sync
        .phones
        .iter()
        .filter(|p| is_closure(arpabet_to_espeak(&p.symbol)))
        .collect();
    // The spans the closures hold: runs of PP keys.
    let mut held: Vec<(f64, f64)> = Vec::new();
    let mut run: Option<(f64, f64)> = None;
    for k in &sync.keys {
        if k.viseme.number() == 1 {
            run = Some(run.map_or((k.time, k.time), |(a, _)| (a, k.time)));
        } else if let Some(r) = run.take() {
            held.push(r);
        }
    }
    held.extend(run);
    let mut out = FalseClosureTrace::default();
    for (n, f) in frames.iter().enumerate() {
        let t = n as f64 / fps;
        if dominant(f).number() != 1 {
            continue;
        }
        let Some(p) = truth.iter().find(|p| p.start <= t && t < p.end) else {
            continue;
        };
        let class = match fbakit::speech::phonemes::PhonemeVisemeTable::standard().lookup(&p.symbol)
        {
            Some(fbakit::speech::phonemes::VisemeTarget::Single(v)) => MouthClass::of(v),
            Some(fbakit::speech::phonemes::VisemeTarget::Glide(a, b)) => {
                MouthClass::of(if t - p.start < 0.5 * (p.end - p.start) {
                    a
                } else {
                    b
                })
            }
            _ => continue,
        };
        if !matches!(class, MouthClass::Open | MouthClass::Rounded) {
            continue;
        }
        let distance =
            |q: &fbakit::speech::lipsync::AlignedPhone| (q.start - t).max(t - q.end).max(0.0);
        let Some(c) = closures
            .iter()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        else {
            continue;
        };
        let inside = held.iter().any(|&(a, b)| a - 1e-6 <= t && t <= b + 1e-6);
        let near = truth
            .iter()
            .any(|q| is_closure(&q.symbol) && q.start - 0.04 <= t && t <= q.end + 0.04);
        let o = origin(c);
        out.frames[o as usize][usize::from(!inside)][usize::from(near)] += 1;
        if inside && c.end - c.start > 0.06 {
            out.long_phone += 1;
        }
        if std::env::var("LIPSYNC_EVAL_TRACE").as_deref() == Ok("2") {
            let around: Vec<String> = heard
                .iter()
                .filter(|q| q.end > t - 0.15 && q.start < t + 0.15)
                .map(|q| format!("{}@{:.2}-{:.2}", q.symbol, q.start, q.end))
                .collect();
            println!(
                "    PP at {t:.2} on {} ({:.2}-{:.2}): {o:?} {}@{:.3}-{:.3}, {}, real {}; heard {}",
                p.symbol,
                p.start,
                p.end,
                c.symbol,
                c.start,
                c.end,
                if inside { "held" } else { "spread" },
                if near { "near" } else { "none" },
                around.join(" ")
            );
        }
    }
    out
}

/// CPU seconds used so far by this process and its waited-for children (the recogniser),
/// from `/proc/self/stat` (clock ticks of 10 ms); 0 where there is none.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // After the command name in parentheses: state is field 3, utime..cstime fields 14..17.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(4)
        .filter_map(|x| x.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
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

/// Running totals of a group of conditions.
#[derive(Default)]
struct Totals {
    aligned: LipsyncScore,
    stretched: LipsyncScore,
    recognised: LipsyncScore,
    audio: f64,
    work: f64,
    work_recognised: f64,
}

impl Totals {
    fn add(&mut self, o: &Totals) {
        self.aligned.add(&o.aligned);
        self.stretched.add(&o.stretched);
        self.recognised.add(&o.recognised);
        self.audio += o.audio;
        self.work += o.work;
        self.work_recognised += o.work_recognised;
    }

    fn print(&self, name: &str, recognise: bool) {
        if self.aligned.speech_frames == 0 {
            println!("{name}: none run");
            return;
        }
        println!("{name}");
        line("aligned", &self.aligned);
        line("stretched", &self.stretched);
        if recognise {
            line("recognised", &self.recognised);
        }
    }
}

fn main() {
    if !fbakit::speech::espeak_available() {
        eprintln!("espeak-ng is not installed (apt-get install espeak-ng)");
        std::process::exit(1);
    }
    if let Some(seconds) = std::env::var("LIPSYNC_EVAL_LONG")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        long_main(seconds);
        return;
    }
    if std::env::var_os("LIPSYNC_EVAL_NOSCRIPT_ONLY").is_some() {
        noscript_main();
        return;
    }
    // LIPSYNC_EVAL_TRANSCRIPT_ONLY skips the (slow) figures without a transcript.
    let recognise =
        recognition_available() && std::env::var_os("LIPSYNC_EVAL_TRANSCRIPT_ONLY").is_none();
    if !recognise && std::env::var_os("LIPSYNC_EVAL_TRANSCRIPT_ONLY").is_none() {
        println!("(PocketSphinx is not installed: no figures without a transcript)");
    }
    let have_ffmpeg = ffmpeg_available();
    let (mut espeak, mut festival) = (Totals::default(), Totals::default());
    for c in conditions() {
        if c.mp3 && !have_ffmpeg {
            println!("{}: skipped (ffmpeg is not installed)", c.name);
            continue;
        }
        if c.synth == Synth::Festival && !festival_voice_available(c.voice) {
            println!(
                "{}: skipped (Festival or its voice {} is not installed: apt-get install \
                 festival festvox-kallpc16k festvox-kdlpc16k festvox-us-slt-hts)",
                c.name, c.voice
            );
            continue;
        }
        let mut sum = Totals::default();
        let mut conf = Vec::new();
        for text in SENTENCES {
            match run_case_with(text, &c, 25.0, recognise) {
                Ok(r) => {
                    sum.aligned.add(&r.aligned);
                    sum.stretched.add(&r.stretched);
                    if let Some(s) = &r.recognised {
                        sum.recognised.add(s);
                    }
                    sum.audio += r.audio_seconds;
                    sum.work += r.work_seconds;
                    sum.work_recognised += r.recognised_seconds;
                    conf.push(r.confidence);
                    if std::env::var_os("VERBOSE").is_some() {
                        println!("    {text}: conf {:.2}", r.confidence);
                        line("aligned", &r.aligned);
                        if let Some(s) = &r.recognised {
                            line("recognised", s);
                        }
                    }
                }
                Err(e) => println!("  {text}: {e}"),
            }
        }
        sum.print(
            &format!(
                "{} (confidence {:.2}..{:.2})",
                c.name,
                conf.iter().cloned().fold(1.0, f64::min),
                conf.iter().cloned().fold(0.0, f64::max)
            ),
            recognise,
        );
        match c.synth {
            Synth::Espeak => espeak.add(&sum),
            Synth::Festival => festival.add(&sum),
        }
    }
    espeak.print("all espeak-ng conditions", recognise);
    festival.print("all Festival conditions", recognise);
    let mut all = Totals::default();
    all.add(&espeak);
    all.add(&festival);
    all.print("all conditions", recognise);
    let (audio, work, work_recognised) = (all.audio, all.work, all.work_recognised);
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
