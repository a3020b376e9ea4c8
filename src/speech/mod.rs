//! Text to a talking head: speech audio and phoneme timing from espeak-ng, phonemes mapped
//! to the standard's 14 visemes, and a FAP stream that blends them at 25 fps.
//!
//! ## Where the timing comes from (measured with espeak-ng 1.51)
//! - `espeak-ng --pho` writes MBROLA `.pho` data (phonemes with durations) only for MBROLA
//!   voices, which need the separate `mbrola` program and voice files; with the ordinary
//!   voices it prints nothing.
//! - `espeak-ng -x` / `-X` / `--ipa` print the phonemes (`h@l'oU w'3:ld`) without timing.
//! - The library's phoneme events (`espeakINITIALIZE_PHONEME_EVENTS`) report every phoneme
//!   with its start in milliseconds of the audio produced by the same synthesis — for
//!   "Hello world": `h` 11 ms, `@` 62, `l` 123, `oU` 196, `w` 316, `3:` 441, `l` 663, `d`
//!   687, pauses `_:` 727 and `_` 734 ms; 22 675 samples at 22 050 Hz.
//!
//! So [`espeak`] loads `libespeak-ng.so.1` (installed with the `espeak-ng` package) at run
//! time and takes audio and phoneme events from one synthesis: the timing is exact for the
//! audio written, and the samples equal those of `espeak-ng -w` (same flags). [`phonemes`]
//! maps each phoneme to a viseme with `specs/phoneme-visemes.csv`; [`animation`] turns the
//! timed visemes into a FAP stream (FAP 1 blends; optionally light jaw and lip FAPs from
//! [`articulation`]); [`wav`] writes the audio.
//!
//! ```no_run
//! use fbakit::speech::{say, SpeechOptions};
//! let (utterance, animation) = say("Hello world", "en", &SpeechOptions::default()).unwrap();
//! fbakit::speech::wav::write_wav("hello.wav".as_ref(), &utterance).unwrap();
//! fbakit::fap::write_fap_file("hello.fap".as_ref(), &animation.stream).unwrap();
//! ```

pub mod animation;
pub mod articulation;
pub mod audio;
pub mod decode;
mod error;
pub mod espeak;
pub mod lipsync;
pub mod phonemes;
pub mod wav;

pub use animation::{speech_animation, MouthFaps, SpeechAnimation, SpeechOptions, VisemeKey};
pub use error::SpeechError;
pub use espeak::{espeak_available, speak, TimedPhoneme, Utterance};
pub use phonemes::{PhonemeVisemeTable, VisemeTarget};

use crate::error::Result;

/// Speaks `text` with espeak-ng voice `voice` and builds its FAP stream.
pub fn say(text: &str, voice: &str, opts: &SpeechOptions) -> Result<(Utterance, SpeechAnimation)> {
    let utterance = speak(text, voice)?;
    let animation = speech_animation(&utterance.phonemes, utterance.duration(), opts)?;
    Ok((utterance, animation))
}
