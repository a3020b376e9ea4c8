//! What can go wrong turning text into speech and a FAP stream. A missing espeak-ng is
//! [`crate::error::Error::MissingTool`] (an environment problem, exit code 1).

/// A speech problem. Every variant is classified as bad input (exit code 2), as before the
/// typed errors: the text, the voice or the options are what the user can change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpeechError {
    /// Blank text.
    #[error("nothing to say: the text is empty")]
    EmptyText,
    /// Text longer than accepted.
    #[error("the text has {bytes} bytes, more than the {limit} accepted")]
    TextTooLong {
        /// The text's length.
        bytes: usize,
        /// The limit.
        limit: usize,
    },
    /// A NUL byte in the text.
    #[error("the text contains a NUL byte")]
    NulInText,
    /// A NUL byte in the voice name.
    #[error("the voice name contains a NUL byte")]
    NulInVoice,
    /// The engine panicked or failed earlier in this process and cannot be used again.
    #[error("espeak-ng failed earlier in this process")]
    EngineFailed,
    /// espeak-ng does not know the voice.
    #[error("espeak-ng has no voice `{voice}` (`espeak-ng --voices` lists them)")]
    UnknownVoice {
        /// The voice asked for.
        voice: String,
    },
    /// espeak-ng returned an error status.
    #[error("espeak-ng could not synthesise the text (error {status})")]
    SynthesisFailed {
        /// espeak-ng's status code.
        status: i32,
    },
    /// The speech would last longer than 10 minutes.
    #[error("the speech is longer than 10 minutes; split the text")]
    TooLong,
    /// A frame rate out of range.
    #[error("frame rate {fps} is not between 0 and 1000")]
    BadFrameRate {
        /// The rate.
        fps: f64,
    },
    /// A negative or non-finite duration.
    #[error("speech duration {duration} s")]
    BadDuration {
        /// The duration in seconds.
        duration: f64,
    },
    /// More frames than a stream may hold.
    #[error("{count} frames of speech is more than {limit}")]
    TooManyFrames {
        /// Frames the speech would need.
        count: u64,
        /// [`crate::fap::MAX_RESAMPLED_FRAMES`].
        limit: u64,
    },
    /// A recording that cannot be read: empty, truncated, not WAV, odd sample format.
    #[error("cannot read recording {}: {detail}", path.display())]
    BadRecording {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A recording's sample rate out of range.
    #[error("recording {}: sample rate {rate} Hz is outside {min}..={max} Hz", path.display())]
    BadSampleRate {
        /// The file.
        path: std::path::PathBuf,
        /// Its rate.
        rate: u32,
        /// Lowest accepted.
        min: u32,
        /// Highest accepted.
        max: u32,
    },
    /// A recording longer than accepted.
    #[error("recording {} lasts {seconds:.0} s, more than the {limit:.0} s accepted; split it", path.display())]
    RecordingTooLong {
        /// The file.
        path: std::path::PathBuf,
        /// Its length (as far as read).
        seconds: f64,
        /// The limit.
        limit: f64,
    },
    /// A recording with no speech in it (silence, or too short).
    #[error("recording {}: {detail}", path.display())]
    NoSpeech {
        /// The file.
        path: std::path::PathBuf,
        /// What was found instead.
        detail: String,
    },
    /// A transcript that cannot be aligned with the recording at all.
    #[error("the transcript cannot be aligned with recording {}: {detail}", path.display())]
    CannotAlign {
        /// The recording.
        path: std::path::PathBuf,
        /// Why.
        detail: String,
    },
    /// The phone recogniser failed.
    #[error("PocketSphinx failed: {detail}")]
    RecognitionFailed {
        /// Its last message.
        detail: String,
    },
    /// The speech engine a command needs is not installed.
    #[error("{engine} is not installed: {why} (Debian/Ubuntu: apt-get install {package})")]
    EngineMissing {
        /// The engine.
        engine: String,
        /// What needs it.
        why: String,
        /// The Debian package(s) to install.
        package: String,
    },
}

impl SpeechError {
    /// True but for an engine failure; a missing engine is reported as exit code 2 as
    /// well, as `lipsync` promises, with the package to install.
    /// The recogniser failing is the exception (exit code 1).
    pub fn is_input_error(&self) -> bool {
        !matches!(self, SpeechError::RecognitionFailed { .. })
    }
}
