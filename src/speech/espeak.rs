//! Speech audio and phoneme timing from the espeak-ng library (`libespeak-ng.so.1`), loaded
//! at run time so fbakit builds and runs without it (only speaking needs it).
//!
//! One synthesis gives both: espeak-ng in synchronous mode hands every block of 16-bit
//! samples to a callback together with its events, and with
//! `espeakINITIALIZE_PHONEME_EVENTS` those include one `espeakEVENT_PHONEME` per phoneme
//! with its start in milliseconds of the output and its mnemonic (`h`, `@`, `l`, `oU`, …).
//! Text is synthesised with `espeakENDPAUSE`, as the `espeak-ng` program does, so the
//! samples are the ones `espeak-ng -v VOICE -w out.wav TEXT` writes (checked sample for
//! sample by `tests/speech.rs`).
//!
//! The library keeps global state, so calls are serialised by a process-wide lock.

use std::ffi::{c_char, c_int, c_short, c_uint, c_void, CString};
use std::sync::{Mutex, OnceLock};

use super::SpeechError;
use crate::error::{Error, Result};

/// Longest text accepted, in bytes (a few minutes of speech).
pub const MAX_TEXT_BYTES: usize = 64 * 1024;
/// Longest synthesised audio kept, in samples (10 minutes at 22 050 Hz).
const MAX_SAMPLES: usize = 22_050 * 600;

/// A phoneme with its place in the audio.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimedPhoneme {
    /// espeak-ng's mnemonic, e.g. `oU` (`_` and `_:` are pauses).
    pub symbol: String,
    /// Start in seconds from the beginning of the audio.
    pub start: f64,
    /// End in seconds (the next phoneme's start, or the end of the audio).
    pub end: f64,
}

/// A word's start in the audio and in the text.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TimedWord {
    /// Start in seconds from the beginning of the audio.
    pub start: f64,
    /// Byte offset of the word in the text spoken.
    pub text_start: usize,
}

/// Synthesised speech: mono 16-bit samples and the phonemes in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Utterance {
    /// Samples per second.
    pub sample_rate: u32,
    /// Mono signed 16-bit samples.
    pub samples: Vec<i16>,
    /// Phonemes, in time order, covering the audio from the first phoneme on.
    pub phonemes: Vec<TimedPhoneme>,
    /// Where each word espeak-ng spoke starts, in time order (empty when not known).
    pub words: Vec<TimedWord>,
}

impl Utterance {
    /// Length of the audio in seconds.
    pub fn duration(&self) -> f64 {
        self.samples.len() as f64 / f64::from(self.sample_rate.max(1))
    }
}

// The parts of `speak_lib.h` used here.
const AUDIO_OUTPUT_SYNCHRONOUS: c_int = 2;
const INITIALIZE_PHONEME_EVENTS: c_int = 0x0001;
const INITIALIZE_DONT_EXIT: c_int = 0x8000;
const POS_CHARACTER: c_int = 1;
const CHARS_UTF8: c_uint = 1;
const ENDPAUSE: c_uint = 0x1000;
const EVENT_LIST_TERMINATED: c_int = 0;
const EVENT_WORD: c_int = 1;
const EVENT_PHONEME: c_int = 7;
const EE_OK: c_int = 0;

#[repr(C)]
#[derive(Clone, Copy)]
union EventId {
    number: c_int,
    name: *const c_char,
    string: [c_char; 8],
}

#[repr(C)]
struct Event {
    kind: c_int,
    unique_identifier: c_uint,
    text_position: c_int,
    length: c_int,
    audio_position: c_int,
    sample: c_int,
    user_data: *mut c_void,
    id: EventId,
}

type SynthCallback = unsafe extern "C" fn(*mut c_short, c_int, *mut Event) -> c_int;
type InitializeFn = unsafe extern "C" fn(c_int, c_int, *const c_char, c_int) -> c_int;
type SetCallbackFn = unsafe extern "C" fn(Option<SynthCallback>);
type SetVoiceFn = unsafe extern "C" fn(*const c_char) -> c_int;
type SynthFn = unsafe extern "C" fn(
    *const c_void,
    usize,
    c_uint,
    c_int,
    c_uint,
    c_uint,
    *mut c_uint,
    *mut c_void,
) -> c_int;
type SynchronizeFn = unsafe extern "C" fn() -> c_int;
type SetParameterFn = unsafe extern "C" fn(c_int, c_int, c_int) -> c_int;

/// `espeakRATE`: speaking rate in words per minute.
const PARAMETER_RATE: c_int = 1;
/// espeak-ng's default speaking rate, words per minute.
pub const DEFAULT_RATE: u32 = 175;

/// The loaded library and its sample rate.
struct Engine {
    // Kept so the function pointers stay valid.
    _lib: libloading::Library,
    set_voice: SetVoiceFn,
    synth: SynthFn,
    synchronize: SynchronizeFn,
    set_parameter: SetParameterFn,
    sample_rate: u32,
}

// The raw function pointers are only called under `ENGINE`'s lock.
unsafe impl Send for Engine {}

/// What the callback gathers during one synthesis.
#[derive(Default)]
struct Collector {
    samples: Vec<i16>,
    /// (milliseconds, mnemonic)
    phonemes: Vec<(i64, String)>,
    /// (milliseconds, 1-based character position in the text)
    words: Vec<(i64, i64)>,
}

static ENGINE: OnceLock<std::result::Result<Mutex<Engine>, String>> = OnceLock::new();
static COLLECTOR: Mutex<Option<Collector>> = Mutex::new(None);

/// File names tried, in order.
const LIBRARY_NAMES: [&str; 4] = [
    "libespeak-ng.so.1",
    "libespeak-ng.so",
    "libespeak-ng.1.dylib",
    "libespeak-ng.dylib",
];

fn missing(detail: &str) -> Error {
    Error::MissingTool(format!(
        "espeak-ng is not installed ({detail}): `fbakit speak` uses its library \
         libespeak-ng (Debian/Ubuntu: apt-get install espeak-ng)"
    ))
}

fn load() -> std::result::Result<Mutex<Engine>, String> {
    let mut last = String::from("libespeak-ng not found");
    for name in LIBRARY_NAMES {
        // Loading runs the library's initialisers; espeak-ng's only set up its tables.
        let lib = match unsafe { libloading::Library::new(name) } {
            Ok(l) => l,
            Err(e) => {
                last = e.to_string();
                continue;
            }
        };
        return unsafe { engine_from(lib) }.map(Mutex::new);
    }
    Err(last)
}

/// Looks up the functions and initialises synchronous synthesis with phoneme events.
unsafe fn engine_from(lib: libloading::Library) -> std::result::Result<Engine, String> {
    let sym = |e: libloading::Error| format!("libespeak-ng lacks a function: {e}");
    let initialize: InitializeFn = *lib.get(b"espeak_Initialize\0").map_err(sym)?;
    let set_callback: SetCallbackFn = *lib.get(b"espeak_SetSynthCallback\0").map_err(sym)?;
    let set_voice: SetVoiceFn = *lib.get(b"espeak_SetVoiceByName\0").map_err(sym)?;
    let synth: SynthFn = *lib.get(b"espeak_Synth\0").map_err(sym)?;
    let synchronize: SynchronizeFn = *lib.get(b"espeak_Synchronize\0").map_err(sym)?;
    let set_parameter: SetParameterFn = *lib.get(b"espeak_SetParameter\0").map_err(sym)?;
    let rate = initialize(
        AUDIO_OUTPUT_SYNCHRONOUS,
        0,
        std::ptr::null(),
        INITIALIZE_PHONEME_EVENTS | INITIALIZE_DONT_EXIT,
    );
    if rate <= 0 {
        return Err("espeak_Initialize failed (is espeak-ng-data installed?)".into());
    }
    set_callback(Some(callback));
    Ok(Engine {
        _lib: lib,
        set_voice,
        synth,
        synchronize,
        set_parameter,
        sample_rate: rate as u32,
    })
}

/// Gathers samples and phoneme events; never unwinds into C.
unsafe extern "C" fn callback(wav: *mut c_short, n: c_int, events: *mut Event) -> c_int {
    let Ok(mut guard) = COLLECTOR.lock() else {
        return 1;
    };
    let Some(c) = guard.as_mut() else { return 1 };
    if !wav.is_null() && n > 0 {
        let block = std::slice::from_raw_parts(wav, n as usize);
        if c.samples.len() + block.len() > MAX_SAMPLES {
            return 1; // aborts the synthesis
        }
        c.samples.extend_from_slice(block);
    }
    if !events.is_null() {
        let mut e = events;
        // The list ends with an EVENT_LIST_TERMINATED entry.
        while (*e).kind != EVENT_LIST_TERMINATED {
            if (*e).kind == EVENT_PHONEME {
                let raw = (*e).id.string;
                let bytes: Vec<u8> = raw
                    .iter()
                    .take_while(|&&b| b != 0)
                    .map(|&b| b as u8)
                    .collect();
                c.phonemes.push((
                    i64::from((*e).audio_position),
                    String::from_utf8_lossy(&bytes).into_owned(),
                ));
            } else if (*e).kind == EVENT_WORD {
                c.words.push((
                    i64::from((*e).audio_position),
                    i64::from((*e).text_position),
                ));
            }
            e = e.add(1);
        }
    }
    0
}

/// Whether the espeak-ng library can be loaded and initialised.
pub fn espeak_available() -> bool {
    ENGINE.get_or_init(load).is_ok()
}

/// Speaks `text` with the espeak-ng voice `voice` (e.g. `en`, `en-us`, `de`; `espeak-ng
/// --voices` lists them) and returns the audio and the timed phonemes.
///
/// Errors: empty or too long text, a NUL byte in it or an unknown voice (bad input), the
/// library missing ([`Error::MissingTool`]) or failing.
pub fn speak(text: &str, voice: &str) -> Result<Utterance> {
    speak_at(text, voice, DEFAULT_RATE)
}

/// Like [`speak`] at `words_per_minute` (espeak-ng takes 80 to 450; clamped).
pub fn speak_at(text: &str, voice: &str, words_per_minute: u32) -> Result<Utterance> {
    if text.trim().is_empty() {
        return Err(SpeechError::EmptyText.into());
    }
    if text.len() > MAX_TEXT_BYTES {
        return Err(SpeechError::TextTooLong {
            bytes: text.len(),
            limit: MAX_TEXT_BYTES,
        }
        .into());
    }
    let c_text = CString::new(text).map_err(|_| SpeechError::NulInText)?;
    let c_voice = CString::new(voice).map_err(|_| SpeechError::NulInVoice)?;
    let engine = ENGINE.get_or_init(load).as_ref().map_err(|e| missing(e))?;
    let engine = engine.lock().map_err(|_| SpeechError::EngineFailed)?;
    if unsafe { (engine.set_voice)(c_voice.as_ptr()) } != EE_OK {
        return Err(SpeechError::UnknownVoice {
            voice: voice.to_string(),
        }
        .into());
    }
    let rate = words_per_minute.clamp(80, 450) as c_int;
    if unsafe { (engine.set_parameter)(PARAMETER_RATE, rate, 0) } != EE_OK {
        return Err(SpeechError::SynthesisFailed { status: -1 }.into());
    }
    *COLLECTOR.lock().map_err(|_| poisoned())? = Some(Collector::default());
    let bytes = c_text.as_bytes_with_nul();
    let status = unsafe {
        (engine.synth)(
            bytes.as_ptr().cast(),
            bytes.len(),
            0,
            POS_CHARACTER,
            0,
            CHARS_UTF8 | ENDPAUSE,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
        )
    };
    unsafe { (engine.synchronize)() };
    let collected = COLLECTOR.lock().map_err(|_| poisoned())?.take();
    let collected = collected.unwrap_or_default();
    if status != EE_OK {
        return Err(SpeechError::SynthesisFailed { status }.into());
    }
    if collected.samples.len() >= MAX_SAMPLES {
        return Err(SpeechError::TooLong.into());
    }
    let sample_rate = engine.sample_rate;
    let duration = collected.samples.len() as f64 / f64::from(sample_rate);
    Ok(Utterance {
        phonemes: timed(&collected.phonemes, duration),
        words: timed_words(&collected.words, text, duration),
        sample_rate,
        samples: collected.samples,
    })
}

/// Word events (milliseconds, 1-based character position) as times and byte offsets in
/// `text`, in time order; positions past the text are dropped.
pub fn timed_words(events: &[(i64, i64)], text: &str, duration: f64) -> Vec<TimedWord> {
    let offsets: Vec<usize> = text.char_indices().map(|(b, _)| b).collect();
    let mut out: Vec<TimedWord> = events
        .iter()
        .filter_map(|&(ms, pos)| {
            let k = usize::try_from(pos.checked_sub(1)?).ok()?;
            Some(TimedWord {
                start: (ms as f64 / 1000.0).clamp(0.0, duration),
                text_start: *offsets.get(k)?,
            })
        })
        .collect();
    out.sort_by(|a, b| a.start.total_cmp(&b.start));
    out
}

fn poisoned() -> Error {
    SpeechError::EngineFailed.into()
}

/// Phoneme events (milliseconds, mnemonic) as intervals: each ends where the next starts,
/// the last at `duration`. Language-switch markers such as `(en)` are not sounds and are
/// dropped; events out of order are clamped so intervals never run backwards.
pub fn timed(events: &[(i64, String)], duration: f64) -> Vec<TimedPhoneme> {
    let kept: Vec<(f64, &str)> = events
        .iter()
        .filter(|(_, s)| !(s.is_empty() || s.starts_with('(')))
        .map(|(ms, s)| ((*ms as f64 / 1000.0).clamp(0.0, duration), s.as_str()))
        .collect();
    let mut out: Vec<TimedPhoneme> = Vec::with_capacity(kept.len());
    let mut floor = 0.0f64;
    for (i, (start, symbol)) in kept.iter().enumerate() {
        let start = start.max(floor);
        let end = kept
            .get(i + 1)
            .map_or(duration, |(next, _)| *next)
            .max(start);
        floor = start;
        out.push(TimedPhoneme {
            symbol: (*symbol).to_string(),
            start,
            end,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_become_intervals() {
        let ev = vec![
            (0, "(en)".to_string()),
            (11, "h".to_string()),
            (62, "@".to_string()),
            (50, "l".to_string()),
            (700, "_".to_string()),
        ];
        let t = timed(&ev, 0.734);
        let s: Vec<&str> = t.iter().map(|p| p.symbol.as_str()).collect();
        assert_eq!(s, vec!["h", "@", "l", "_"]);
        assert!((t[0].start - 0.011).abs() < 1e-12);
        assert!((t[0].end - 0.062).abs() < 1e-12);
        // The out-of-order `l` is clamped to start where `@` did.
        assert!(t[2].start >= t[1].start);
        assert!(t.iter().all(|p| p.end >= p.start));
        assert!((t[3].end - 0.734).abs() < 1e-12);
    }

    #[test]
    fn word_events_become_byte_offsets() {
        // "é" takes two bytes: the fourth character, b, starts at byte 4.
        let w = timed_words(&[(400, 4), (0, 1), (900, 0), (950, 99)], "éa bc", 0.5);
        assert_eq!(w.len(), 2);
        assert_eq!((w[0].start, w[0].text_start), (0.0, 0));
        assert_eq!((w[1].start, w[1].text_start), (0.4, 4));
    }

    #[test]
    fn bad_text_is_refused_before_the_library() {
        assert!(speak("   ", "en").is_err());
        assert!(speak("a\0b", "en").is_err());
        assert!(speak(&"a".repeat(MAX_TEXT_BYTES + 1), "en").is_err());
    }
}
