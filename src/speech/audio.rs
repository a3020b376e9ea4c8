//! Recordings in: WAV through `hound` (8/16/24/32-bit integer and float, any channel count),
//! MP3, FLAC, Ogg Vorbis and M4A/MP4 (AAC) through `symphonia` ([`super::decode`]), told
//! apart by their first bytes, mixed down to mono, decoded a chunk at a time and resampled to [`ANALYSIS_RATE`] for
//! analysis, so a long recording never has to be in memory whole.
//!
//! Every problem names the file: a 0-byte or truncated file, a format not read, a
//! sample rate outside [`MIN_SAMPLE_RATE`]..=[`MAX_SAMPLE_RATE`] or a recording longer than
//! [`MAX_AUDIO_SECONDS`].

use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::decode::CompressedSource;
pub use super::decode::Container;
use super::SpeechError;
use crate::error::{Error, Result};

/// The rate recordings are analysed at: speech has what lip shapes need below 8 kHz.
pub const ANALYSIS_RATE: u32 = 16_000;
/// Lowest sample rate accepted (telephone speech is 8 kHz).
pub const MIN_SAMPLE_RATE: u32 = 4_000;
/// Highest sample rate accepted.
pub const MAX_SAMPLE_RATE: u32 = 384_000;
/// Longest recording accepted, in seconds (two hours).
pub const MAX_AUDIO_SECONDS: f64 = 7_200.0;
/// Input frames decoded per chunk.
const CHUNK_FRAMES: usize = 8_192;
/// Most channels accepted.
const MAX_CHANNELS: u16 = 64;

/// What a recording is.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AudioInfo {
    /// The file.
    pub path: PathBuf,
    /// Container and sample format, e.g. `WAV 16-bit integer`.
    pub format: String,
    /// Samples per second per channel in the file.
    pub sample_rate: u32,
    /// Channels in the file (mixed down to one).
    pub channels: u16,
    /// Length in seconds, from the header when it says (0 when unknown).
    pub seconds: f64,
}

/// A recording read a chunk at a time as mono samples in `[-1, 1]` at [`ANALYSIS_RATE`].
pub struct AudioReader {
    info: AudioInfo,
    source: Source,
    resampler: Resampler,
    /// Input frames read so far.
    frames_read: u64,
    done: bool,
}

/// Where the samples come from.
enum Source {
    Wav {
        wav: Box<hound::WavReader<Box<dyn Read + Send>>>,
        spec: hound::WavSpec,
    },
    Compressed(Box<CompressedSource>),
}

impl std::fmt::Debug for AudioReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AudioReader")
            .field("info", &self.info)
            .finish()
    }
}

/// A recording that cannot be read (one error for WAV and compressed files alike).
pub(super) fn bad(path: &Path, detail: impl Into<String>) -> Error {
    SpeechError::BadRecording {
        path: path.to_path_buf(),
        detail: detail.into(),
    }
    .into()
}

/// Opens the recording at `path`: WAV, MP3, FLAC, Ogg Vorbis or M4A/MP4 (AAC), told apart by
/// their first bytes.
pub fn open_audio(path: &Path) -> Result<AudioReader> {
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    if len == 0 {
        return Err(bad(path, "the file is empty (0 bytes)"));
    }
    let mut head = [0u8; 12];
    let n = read_up_to(&mut file, &mut head).map_err(|e| Error::io(path, e))?;
    file.seek(SeekFrom::Start(0))
        .map_err(|e| Error::io(path, e))?;
    match Container::sniff(&head[..n]) {
        Some(Container::Wav) => AudioReader::from_wav(Box::new(BufReader::new(file)), path),
        Some(c) => AudioReader::from_compressed(Box::new(file), c, path),
        None => Err(unknown(path, &head[..n])),
    }
}

/// A recording held in memory (`path` names it in errors), told apart as [`open_audio`] does.
pub fn audio_from_bytes(bytes: Vec<u8>, path: &Path) -> Result<AudioReader> {
    if bytes.is_empty() {
        return Err(bad(path, "the file is empty (0 bytes)"));
    }
    let head = &bytes[..bytes.len().min(12)];
    match Container::sniff(head) {
        Some(Container::Wav) => AudioReader::from_wav(Box::new(std::io::Cursor::new(bytes)), path),
        Some(c) => AudioReader::from_compressed(Box::new(std::io::Cursor::new(bytes)), c, path),
        None => Err(unknown(path, head)),
    }
}

fn unknown(path: &Path, head: &[u8]) -> Error {
    bad(
        path,
        format!(
            "{}; fbakit reads WAV, MP3, FLAC, Ogg Vorbis and M4A/MP4 (AAC) recordings",
            sniff(head)
        ),
    )
}

fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

/// A name for what a file that is no recording fbakit reads looks like, from its first bytes.
fn sniff(head: &[u8]) -> String {
    let what = if head.starts_with(b"RIFF") {
        "a RIFF file that is not WAVE"
    } else if head.starts_with(&[0x1A, 0x45, 0xDF, 0xA3]) {
        "a Matroska/WebM file"
    } else if head.starts_with(b"FORM") {
        "an AIFF/IFF file"
    } else if head.starts_with(b"#!AMR") {
        "an AMR file"
    } else if head.len() >= 4 && &head[..4] == b"caff" {
        "a Core Audio file"
    } else if head.len() < 12 {
        "too short to be a recording (truncated?)"
    } else {
        "not a recording fbakit knows"
    };
    format!("it is {what}")
}

fn check_rate(path: &Path, rate: u32) -> Result<()> {
    if !(MIN_SAMPLE_RATE..=MAX_SAMPLE_RATE).contains(&rate) {
        return Err(SpeechError::BadSampleRate {
            path: path.to_path_buf(),
            rate,
            min: MIN_SAMPLE_RATE,
            max: MAX_SAMPLE_RATE,
        }
        .into());
    }
    Ok(())
}

fn check_length(path: &Path, seconds: f64) -> Result<()> {
    if seconds > MAX_AUDIO_SECONDS {
        return Err(SpeechError::RecordingTooLong {
            path: path.to_path_buf(),
            seconds,
            limit: MAX_AUDIO_SECONDS,
        }
        .into());
    }
    Ok(())
}

impl AudioReader {
    /// A WAV recording from `reader`; `path` names it in errors.
    pub fn from_wav(reader: Box<dyn Read + Send>, path: &Path) -> Result<AudioReader> {
        let wav = hound::WavReader::new(reader).map_err(|e| bad(path, wav_detail(&e)))?;
        let spec = wav.spec();
        if spec.channels == 0 || spec.channels > MAX_CHANNELS {
            return Err(bad(
                path,
                format!("{} channels (1 to {MAX_CHANNELS} accepted)", spec.channels),
            ));
        }
        check_rate(path, spec.sample_rate)?;
        let frames = u64::from(wav.duration());
        let seconds = frames as f64 / f64::from(spec.sample_rate);
        check_length(path, seconds)?;
        let kind = match spec.sample_format {
            hound::SampleFormat::Int => "integer",
            hound::SampleFormat::Float => "float",
        };
        if spec.sample_format == hound::SampleFormat::Float && spec.bits_per_sample != 32 {
            return Err(bad(
                path,
                format!(
                    "{}-bit float samples (32-bit float accepted)",
                    spec.bits_per_sample
                ),
            ));
        }
        Ok(AudioReader {
            info: AudioInfo {
                path: path.to_path_buf(),
                format: format!("WAV {}-bit {kind}", spec.bits_per_sample),
                sample_rate: spec.sample_rate,
                channels: spec.channels,
                seconds,
            },
            source: Source::Wav {
                wav: Box::new(wav),
                spec,
            },
            resampler: Resampler::new(spec.sample_rate, ANALYSIS_RATE),
            frames_read: 0,
            done: false,
        })
    }

    /// A compressed recording (MP3, FLAC, Ogg Vorbis, M4A) from `source`, whose first bytes
    /// said `container`; `path` names it in errors.
    pub fn from_compressed(
        source: Box<dyn symphonia::core::io::MediaSource>,
        container: Container,
        path: &Path,
    ) -> Result<AudioReader> {
        let c = CompressedSource::open(source, container, path)?;
        if c.channels > MAX_CHANNELS {
            return Err(bad(
                path,
                format!("{} channels (1 to {MAX_CHANNELS} accepted)", c.channels),
            ));
        }
        check_rate(path, c.sample_rate)?;
        let seconds = c
            .declared_frames()
            .map_or(0.0, |f| f as f64 / f64::from(c.sample_rate));
        check_length(path, seconds)?;
        Ok(AudioReader {
            info: AudioInfo {
                path: path.to_path_buf(),
                format: c.format.clone(),
                sample_rate: c.sample_rate,
                channels: c.channels,
                seconds,
            },
            resampler: Resampler::new(c.sample_rate, ANALYSIS_RATE),
            source: Source::Compressed(Box::new(c)),
            frames_read: 0,
            done: false,
        })
    }

    /// What the recording is.
    pub fn info(&self) -> &AudioInfo {
        &self.info
    }

    /// The next chunk of mono samples at [`ANALYSIS_RATE`]; `None` at the end.
    pub fn next_chunk(&mut self) -> Result<Option<Vec<f32>>> {
        if self.done {
            return Ok(None);
        }
        let path = self.info.path.clone();
        let (mono, more) = match &mut self.source {
            Source::Wav { wav, spec } => {
                let mono = wav_chunk(wav, spec, &path)?;
                let more = mono.len() >= CHUNK_FRAMES;
                (mono, more)
            }
            Source::Compressed(c) => {
                let mut mono = Vec::with_capacity(CHUNK_FRAMES + 4_096);
                let more = c.read_mono(CHUNK_FRAMES, &mut mono)?;
                (mono, more)
            }
        };
        self.frames_read += mono.len() as u64;
        let rate = f64::from(self.info.sample_rate);
        check_length(&path, self.frames_read as f64 / rate)?;
        let mut out = Vec::with_capacity(
            mono.len() * ANALYSIS_RATE as usize / self.info.sample_rate as usize + 2,
        );
        self.resampler.push(&mono, &mut out);
        if !more {
            self.done = true;
            self.resampler.finish(&mut out);
        }
        Ok(Some(out))
    }

    /// Input frames decoded so far.
    pub fn frames_read(&self) -> u64 {
        self.frames_read
    }
}

/// Up to [`CHUNK_FRAMES`] frames of a WAV file, mixed down.
fn wav_chunk(
    wav: &mut hound::WavReader<Box<dyn Read + Send>>,
    spec: &hound::WavSpec,
    path: &Path,
) -> Result<Vec<f32>> {
    let channels = usize::from(spec.channels);
    let want = CHUNK_FRAMES * channels;
    let mut interleaved: Vec<f32> = Vec::with_capacity(want);
    match spec.sample_format {
        hound::SampleFormat::Float => {
            for s in wav.samples::<f32>().take(want) {
                let s = s.map_err(|e| bad(path, wav_detail(&e)))?;
                interleaved.push(if s.is_finite() {
                    s.clamp(-1.0, 1.0)
                } else {
                    0.0
                });
            }
        }
        hound::SampleFormat::Int => {
            let scale = 1.0 / (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f32;
            for s in wav.samples::<i32>().take(want) {
                let s = s.map_err(|e| bad(path, wav_detail(&e)))?;
                interleaved.push(s as f32 * scale);
            }
        }
    }
    if interleaved.len() % channels != 0 {
        return Err(bad(
            path,
            "the file ends inside a sample frame (truncated?)",
        ));
    }
    Ok(interleaved
        .chunks_exact(channels)
        .map(|f| f.iter().sum::<f32>() / channels as f32)
        .collect())
}

fn wav_detail(e: &hound::Error) -> String {
    match e {
        hound::Error::IoError(io)
            if io.kind() == std::io::ErrorKind::UnexpectedEof
                || io.to_string().contains("enough bytes") =>
        {
            "the WAV data ends early (truncated file)".into()
        }
        hound::Error::IoError(io) => format!("cannot read the WAV data: {io}"),
        hound::Error::FormatError(m) => format!("not a well-formed WAV file: {m}"),
        hound::Error::Unsupported => "a WAV sample format fbakit does not read (8/16/24/32-bit PCM and 32-bit float are read)".into(),
        other => format!("cannot read the WAV file: {other}"),
    }
}

/// A streaming band-limited resampler: windowed-sinc interpolation whose cut-off follows
/// the lower of the two rates, so downsampling does not alias.
#[derive(Clone, Debug)]
pub struct Resampler {
    /// Input samples per output sample.
    step: f64,
    /// Cut-off as a fraction of the input rate's Nyquist frequency.
    cutoff: f64,
    /// Kernel half-width in input samples.
    half: usize,
    /// Input not yet consumed; `buf[0]` is input sample `offset`.
    buf: Vec<f32>,
    offset: u64,
    /// Position of the next output sample, in input samples.
    next: f64,
    /// Whether the input started (the first samples are padded with zeros before it).
    identity: bool,
    /// The normalised kernel at each of `phases + 1` fractional positions 0, 1 / phases,
    /// …, 1 (`2 × half` taps each), when the rates' ratio has few enough of them: computing the sine and cosine
    /// per tap took most of the time of reading a 44.1 kHz recording.
    table: Vec<f64>,
    phases: usize,
}

/// Most kernel values tabulated (beyond it, each is computed as needed).
const MAX_TABLE: usize = 1 << 18;

/// Kernel zero crossings on each side.
const ZEROS: f64 = 8.0;

impl Resampler {
    /// From `from` Hz to `to` Hz.
    pub fn new(from: u32, to: u32) -> Resampler {
        let step = f64::from(from) / f64::from(to.max(1));
        let cutoff = (1.0 / step).min(1.0) * 0.95;
        let half = (ZEROS / cutoff).ceil() as usize;
        let mut r = Resampler {
            step,
            cutoff,
            half,
            buf: Vec::new(),
            offset: 0,
            next: 0.0,
            identity: from == to,
            table: Vec::new(),
            phases: 0,
        };
        // Output n lies at n × from / to input samples: its fractional part is one of
        // to / gcd(from, to) values.
        let phases = (to.max(1) / gcd(from.max(1), to.max(1))) as usize;
        if !r.identity && (phases + 1) * 2 * half <= MAX_TABLE {
            // One row more, for a position that falls just short of a whole sample (its
            // taps stay on this side of it, as when computed).
            let mut table = Vec::with_capacity((phases + 1) * 2 * half);
            for j in 0..=phases {
                let kernel = r.kernel(j as f64 / phases as f64);
                let norm: f64 = kernel.iter().sum();
                let norm = if norm.abs() > 1e-12 {
                    norm
                } else {
                    f64::INFINITY
                };
                table.extend(kernel.iter().map(|h| h / norm));
            }
            r.table = table;
            r.phases = phases;
        }
        r
    }

    /// The kernel's taps for an output `frac` (0..1) of an input sample past the centre
    /// tap, from the first tap (centre − half + 1) to the last (centre + half).
    fn kernel(&self, frac: f64) -> Vec<f64> {
        (1 - self.half as i64..=self.half as i64)
            .map(|m| {
                let x = frac - m as f64;
                let arg = x * self.cutoff;
                let sinc = if arg.abs() < 1e-9 {
                    1.0
                } else {
                    let p = std::f64::consts::PI * arg;
                    p.sin() / p
                };
                // Hann window over the kernel's span.
                let w = 0.5 + 0.5 * (std::f64::consts::PI * x / (self.half as f64 + 1.0)).cos();
                sinc * w
            })
            .collect()
    }

    /// Feeds input samples; appends the outputs they complete.
    pub fn push(&mut self, input: &[f32], out: &mut Vec<f32>) {
        if self.identity {
            out.extend_from_slice(input);
            return;
        }
        self.buf.extend_from_slice(input);
        self.drain(out, false);
    }

    /// Ends the input (zeros after it); appends the remaining outputs.
    pub fn finish(&mut self, out: &mut Vec<f32>) {
        if self.identity {
            return;
        }
        self.drain(out, true);
        self.buf.clear();
    }

    fn drain(&mut self, out: &mut Vec<f32>, last: bool) {
        let end = self.offset + self.buf.len() as u64;
        loop {
            let centre = self.next.floor() as i64;
            if last {
                if self.next >= end as f64 {
                    break;
                }
            } else if centre + self.half as i64 >= end as i64 {
                break;
            }
            out.push(self.sample_at(self.next));
            self.next += self.step;
        }
        // Drop input no later output can reach.
        let keep_from =
            (self.next.floor() as i64 - self.half as i64).max(self.offset as i64) as u64;
        let drop = (keep_from - self.offset) as usize;
        if drop > 0 && drop <= self.buf.len() {
            self.buf.drain(..drop);
            self.offset = keep_from;
        }
    }

    fn sample_at(&self, t: f64) -> f32 {
        let centre = t.floor() as i64;
        let taps = 2 * self.half;
        let (kernel, norm): (std::borrow::Cow<[f64]>, f64) = if self.phases > 0 {
            // The tabulated phase nearest t's (t drifts from the exact n × from / to by the
            // rounding of its running sum only).
            let j = (((t - centre as f64) * self.phases as f64).round() as usize).min(self.phases);
            (self.table[j * taps..(j + 1) * taps].into(), 1.0)
        } else {
            let k = self.kernel(t - centre as f64);
            let norm: f64 = k.iter().sum();
            (k.into(), norm)
        };
        if norm.abs() <= 1e-12 {
            return 0.0;
        }
        let first = centre - self.half as i64 + 1;
        let mut acc = 0.0f64;
        for (m, h) in kernel.iter().enumerate() {
            let idx = first + m as i64 - self.offset as i64;
            if idx >= 0 && (idx as usize) < self.buf.len() {
                acc += h * f64::from(self.buf[idx as usize]);
            }
        }
        (acc / norm) as f32
    }
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wav(spec: hound::WavSpec, samples: &[i32]) -> Vec<u8> {
        let mut c = std::io::Cursor::new(Vec::new());
        let mut w = hound::WavWriter::new(&mut c, spec).unwrap();
        for &s in samples {
            w.write_sample(s).unwrap();
        }
        w.finalize().unwrap();
        c.into_inner()
    }

    fn read_all(bytes: Vec<u8>) -> Result<Vec<f32>> {
        let mut r =
            AudioReader::from_wav(Box::new(std::io::Cursor::new(bytes)), Path::new("x.wav"))?;
        let mut all = Vec::new();
        while let Some(c) = r.next_chunk()? {
            all.extend(c);
        }
        Ok(all)
    }

    #[test]
    fn the_tabulated_kernel_resamples_like_the_computed_one() {
        for (from, to) in [
            (44_100, 16_000),
            (8_000, 16_000),
            (22_050, 16_000),
            (48_000, 16_000),
        ] {
            let input: Vec<f32> = (0..30_000)
                .map(|i| ((i as f32 * 0.037).sin() + (i as f32 * 0.41).cos() * 0.3) * 0.5)
                .collect();
            let mut tabulated = Resampler::new(from, to);
            assert!(tabulated.phases > 0, "{from}");
            let mut computed = tabulated.clone();
            computed.phases = 0;
            computed.table.clear();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for chunk in input.chunks(1_234) {
                tabulated.push(chunk, &mut a);
                computed.push(chunk, &mut b);
            }
            tabulated.finish(&mut a);
            computed.finish(&mut b);
            assert_eq!(a.len(), b.len(), "{from}");
            let worst = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f32::max);
            assert!(worst < 1e-5, "{from}: {worst}");
        }
    }

    #[test]
    fn a_tone_keeps_its_length_and_level_through_resampling() {
        let rate = 44_100;
        let n = rate as usize; // one second
        let spec = hound::WavSpec {
            channels: 2,
            sample_rate: rate,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut s = Vec::new();
        for i in 0..n {
            let v = (0.5
                * (2.0 * std::f64::consts::PI * 440.0 * i as f64 / f64::from(rate)).sin()
                * 32767.0) as i32;
            s.push(v);
            s.push(v);
        }
        let out = read_all(wav(spec, &s)).unwrap();
        assert!((out.len() as i64 - 16_000).abs() <= 2, "{}", out.len());
        let rms = (out[1000..15000]
            .iter()
            .map(|x| f64::from(*x).powi(2))
            .sum::<f64>()
            / 14000.0)
            .sqrt();
        assert!((rms - 0.5 / 2f64.sqrt()).abs() < 0.01, "{rms}");
    }

    #[test]
    fn downsampling_removes_what_16_khz_cannot_hold() {
        let rate = 48_000;
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: rate,
            bits_per_sample: 24,
            sample_format: hound::SampleFormat::Int,
        };
        // 12 kHz is above the 8 kHz Nyquist frequency of the analysis rate.
        let s: Vec<i32> = (0..rate as usize)
            .map(|i| {
                ((2.0 * std::f64::consts::PI * 12_000.0 * i as f64 / f64::from(rate)).sin()
                    * 4_000_000.0) as i32
            })
            .collect();
        let out = read_all(wav(spec, &s)).unwrap();
        let rms = (out[1000..15000]
            .iter()
            .map(|x| f64::from(*x).powi(2))
            .sum::<f64>()
            / 14000.0)
            .sqrt();
        assert!(rms < 0.01, "{rms}");
    }

    #[test]
    fn bad_recordings_are_refused_with_a_reason() {
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: 1,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let e = read_all(wav(spec, &[0, 1, 2])).unwrap_err();
        assert!(e.to_string().contains("1 Hz"), "{e}");
        assert!(e.is_input_error());
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: 16_000,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut bytes = wav(spec, &vec![100; 10_000]);
        bytes.truncate(bytes.len() - 5_001);
        let e = read_all(bytes).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
        let e = read_all(b"RIFF\0\0\0\0WAVEjunk".to_vec()).unwrap_err();
        assert!(e.is_input_error(), "{e}");
        assert!(sniff(b"RIFF\0\0\0\0AVI LIST").contains("not WAVE"));
    }
}
