//! Compressed recordings in: MP3, FLAC, Ogg Vorbis and M4A/MP4 (AAC) through the pure-Rust
//! `symphonia` demuxers and decoders, one packet at a time, mixed down to mono at the file's
//! own rate ([`super::audio`] resamples it). What a file is comes from its first bytes
//! ([`Container::sniff`]), never from its name alone.
//!
//! A file that stops inside its data (a demuxer reading past the end, or fewer frames than its
//! header declares) is refused as truncated rather than read as a shorter recording, since
//! a transcript would then not fit it; a codec fbakit does not decode (Opus, ALAC, AC-3, …) is
//! named.

use std::path::{Path, PathBuf};

use symphonia::core::codecs::audio::AudioDecoderOptions;
use symphonia::core::codecs::audio::{well_known as codec, AudioCodecId, AudioDecoder};
use symphonia::core::errors::Error as SymphoniaError;
use symphonia::core::formats::probe::Hint;
use symphonia::core::formats::{FormatOptions, FormatReader, TrackType};
use symphonia::core::io::{MediaSource, MediaSourceStream};
use symphonia::core::meta::MetadataOptions;

use super::audio::bad;
use crate::error::Result;

/// What a recording's first bytes say it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// RIFF/WAVE (read by `hound`).
    Wav,
    /// MPEG audio (MP3) or an ADTS AAC stream, with or without an ID3v2 tag.
    Mpeg,
    /// Native FLAC.
    Flac,
    /// Ogg (Vorbis is decoded).
    Ogg,
    /// ISO base media (MP4/M4A; AAC is decoded).
    Mp4,
}

impl Container {
    /// The container of a file starting with `head` (at least 12 bytes are looked at).
    pub fn sniff(head: &[u8]) -> Option<Container> {
        if head.len() >= 12 && &head[..4] == b"RIFF" && &head[8..12] == b"WAVE" {
            Some(Container::Wav)
        } else if head.starts_with(b"fLaC") {
            Some(Container::Flac)
        } else if head.starts_with(b"OggS") {
            Some(Container::Ogg)
        } else if head.len() >= 8 && &head[4..8] == b"ftyp" {
            Some(Container::Mp4)
        } else if head.starts_with(b"ID3")
            || (head.len() >= 2 && head[0] == 0xFF && head[1] & 0xE0 == 0xE0)
        {
            Some(Container::Mpeg)
        } else {
            None
        }
    }

    /// A name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Container::Wav => "WAV",
            Container::Mpeg => "MPEG audio",
            Container::Flac => "FLAC",
            Container::Ogg => "Ogg",
            Container::Mp4 => "MP4/M4A",
        }
    }

    fn extension(self) -> &'static str {
        match self {
            Container::Wav => "wav",
            Container::Mpeg => "mp3",
            Container::Flac => "flac",
            Container::Ogg => "ogg",
            Container::Mp4 => "m4a",
        }
    }
}

/// Names of the codecs a message may need.
fn codec_name(id: AudioCodecId) -> String {
    let known = [
        (codec::CODEC_ID_MP3, "MP3"),
        (codec::CODEC_ID_MP2, "MP2"),
        (codec::CODEC_ID_MP1, "MP1"),
        (codec::CODEC_ID_AAC, "AAC"),
        (codec::CODEC_ID_FLAC, "FLAC"),
        (codec::CODEC_ID_VORBIS, "Vorbis"),
        (codec::CODEC_ID_OPUS, "Opus"),
        (codec::CODEC_ID_SPEEX, "Speex"),
        (codec::CODEC_ID_ALAC, "ALAC"),
        (codec::CODEC_ID_AC3, "AC-3"),
        (codec::CODEC_ID_EAC3, "E-AC-3"),
    ];
    known
        .iter()
        .find(|(k, _)| *k == id)
        .map_or_else(|| format!("codec {id}"), |(_, n)| (*n).to_string())
}

/// Decode errors tolerated (damaged frames are skipped) before the file is refused, and
/// above that the share of packets that may fail.
const TOLERATED_DECODE_ERRORS: u64 = 8;
/// Frames of priming assumed at the start of an AAC stream that does not say.
const AAC_PRIMING: u64 = 1_024;

/// A compressed recording decoded packet by packet.
pub struct CompressedSource {
    path: PathBuf,
    reader: Box<dyn FormatReader + 'static>,
    decoder: Box<dyn AudioDecoder>,
    track: u32,
    /// Frames the container declares (after encoder delay and padding), when it does.
    declared_frames: Option<u64>,
    /// Mono frames handed out so far.
    frames: u64,
    packets: u64,
    errors: u64,
    /// Interleaved scratch buffer for one packet.
    scratch: Vec<f32>,
    /// Leading frames still to drop (an encoder's priming the decoder does not trim).
    skip: u64,
    /// The container's name, for messages.
    container: &'static str,
    /// What the file is, e.g. `MP3 in MPEG audio`.
    pub format: String,
    /// Samples per second.
    pub sample_rate: u32,
    /// Channels.
    pub channels: u16,
}

impl std::fmt::Debug for CompressedSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompressedSource")
            .field("path", &self.path)
            .field("format", &self.format)
            .finish()
    }
}

/// A message for a demuxer or decoder error.
fn detail(container: &str, e: &SymphoniaError) -> String {
    match e {
        SymphoniaError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            format!("the {container} data ends early (truncated file)")
        }
        SymphoniaError::IoError(io) => format!("cannot read the {container} data: {io}"),
        SymphoniaError::DecodeError(m) => format!("damaged {container} data ({m})"),
        SymphoniaError::Unsupported(m) => {
            format!("a {container} feature fbakit does not read ({m})")
        }
        SymphoniaError::LimitError(m) => format!("the {container} file exceeds a limit ({m})"),
        SymphoniaError::SeekError(_) => format!("cannot seek in the {container} file"),
        SymphoniaError::ResetRequired => {
            format!(
                "the {container} stream changes its format midway (chained streams are not read)"
            )
        }
        other => format!("cannot read the {container} data: {other}"),
    }
}

impl CompressedSource {
    /// Opens `source`, whose first bytes said `container`; `path` names it in errors.
    pub fn open(
        source: Box<dyn MediaSource>,
        container: Container,
        path: &Path,
    ) -> Result<CompressedSource> {
        let stream = MediaSourceStream::new(source, Default::default());
        let mut hint = Hint::new();
        hint.with_extension(container.extension());
        let cname = container.name();
        let reader = symphonia::default::get_probe()
            .probe(
                &hint,
                stream,
                FormatOptions::default(),
                MetadataOptions::default(),
            )
            .map_err(|e| match e {
                SymphoniaError::Unsupported(_) => bad(
                    path,
                    format!("it starts like {cname} but no {cname} stream was found in it (damaged or truncated?)"),
                ),
                other => bad(path, detail(cname, &other)),
            })?;
        let track = reader
            .default_track(TrackType::Audio)
            .ok_or_else(|| bad(path, format!("the {cname} file has no audio track")))?;
        let params = track
            .codec_params
            .as_ref()
            .and_then(|p| p.audio())
            .ok_or_else(|| bad(path, format!("the {cname} file has no audio track")))?
            .clone();
        let id = track.id;
        let declared_frames = track.num_frames;
        let name = codec_name(params.codec);
        let decoder = symphonia::default::get_codecs()
            .make_audio_decoder(&params, &AudioDecoderOptions::default())
            .map_err(|_| {
                bad(
                    path,
                    format!(
                        "{name} audio in {cname}, a codec fbakit does not decode \
                         (it reads WAV, MP3, FLAC, Ogg Vorbis and AAC in M4A/MP4)"
                    ),
                )
            })?;
        let sample_rate = params.sample_rate.ok_or_else(|| {
            bad(
                path,
                format!("the {cname} file does not say its sample rate"),
            )
        })?;
        let channels = params.channels.as_ref().map_or(0, |c| c.count());
        // symphonia trims MP3, FLAC and Vorbis delay itself but not AAC's: AAC encoders prime
        // with 1024 frames (ffmpeg; Apple's 2112 is also common) that would shift every phone.
        let skip = match (track.delay, params.codec == codec::CODEC_ID_AAC) {
            (Some(d), true) => u64::from(d),
            (None, true) => AAC_PRIMING,
            _ => 0,
        };
        Ok(CompressedSource {
            path: path.to_path_buf(),
            reader,
            decoder,
            track: id,
            declared_frames,
            frames: 0,
            packets: 0,
            errors: 0,
            scratch: Vec::new(),
            skip,
            container: cname,
            format: format!("{name} in {cname}"),
            sample_rate,
            channels: u16::try_from(channels).unwrap_or(u16::MAX),
        })
    }

    /// Frames the container declares, when it does.
    pub fn declared_frames(&self) -> Option<u64> {
        self.declared_frames
    }

    /// Appends at least `want` mono frames (fewer only at the end) to `out`; false at the end.
    pub fn read_mono(&mut self, want: usize, out: &mut Vec<f32>) -> Result<bool> {
        let start = out.len();
        while out.len() - start < want {
            let packet = match self.reader.next_packet() {
                Ok(Some(p)) => p,
                Ok(None) => {
                    self.check_end()?;
                    return Ok(false);
                }
                Err(e) => return Err(bad(&self.path, detail(self.container, &e))),
            };
            if packet.track_id != self.track {
                continue;
            }
            self.packets += 1;
            let decoded = match self.decoder.decode(&packet) {
                Ok(buf) => buf,
                Err(SymphoniaError::DecodeError(m)) => {
                    self.errors += 1;
                    if self.errors > TOLERATED_DECODE_ERRORS && self.errors * 20 > self.packets {
                        return Err(bad(
                            &self.path,
                            format!(
                                "damaged {} data ({m}) in {} packets",
                                self.format, self.errors
                            ),
                        ));
                    }
                    continue;
                }
                Err(e) => return Err(bad(&self.path, detail(&self.format, &e))),
            };
            let spec = decoded.spec();
            if spec.rate() != self.sample_rate {
                return Err(bad(
                    &self.path,
                    format!(
                        "the sample rate changes from {} to {} Hz midway",
                        self.sample_rate,
                        spec.rate()
                    ),
                ));
            }
            let channels = decoded.num_planes().max(1);
            decoded.copy_to_vec_interleaved(&mut self.scratch);
            let drop = (self.skip as usize * channels).min(self.scratch.len());
            self.skip -= (drop / channels) as u64;
            self.scratch.drain(..drop);
            let scale = 1.0 / channels as f32;
            out.extend(self.scratch.chunks_exact(channels).map(|f| {
                let s = f.iter().sum::<f32>() * scale;
                if s.is_finite() {
                    s.clamp(-1.0, 1.0)
                } else {
                    0.0
                }
            }));
        }
        self.frames += (out.len() - start) as u64;
        Ok(true)
    }

    /// At the end: refuses a file with clearly fewer frames than its header declares, or
    /// with no audio at all.
    fn check_end(&self) -> Result<()> {
        if self.frames == 0 && self.packets > 0 && self.errors == self.packets {
            return Err(bad(
                &self.path,
                format!("no {} packet could be decoded", self.format),
            ));
        }
        if let Some(declared) = self.declared_frames {
            // Encoders' delay and padding differ by a few thousand frames at most.
            let slack = 8_192 + declared / 100;
            if self.frames + slack < declared {
                let rate = f64::from(self.sample_rate.max(1));
                return Err(bad(
                    &self.path,
                    format!(
                        "the audio ends at {:.1} s but the header says {:.1} s (truncated file)",
                        self.frames as f64 / rate,
                        declared as f64 / rate
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn containers_are_told_by_their_first_bytes() {
        assert_eq!(
            Container::sniff(b"RIFF\0\0\0\0WAVEfmt "),
            Some(Container::Wav)
        );
        assert_eq!(
            Container::sniff(b"ID3\x04\0\0\0\0\0\0\0\0"),
            Some(Container::Mpeg)
        );
        assert_eq!(
            Container::sniff(&[0xFF, 0xFB, 0x90, 0x64]),
            Some(Container::Mpeg)
        );
        assert_eq!(Container::sniff(b"fLaC\0\0\0\x22"), Some(Container::Flac));
        assert_eq!(Container::sniff(b"OggS\0\x02"), Some(Container::Ogg));
        assert_eq!(
            Container::sniff(b"\0\0\0\x20ftypM4A "),
            Some(Container::Mp4)
        );
        assert_eq!(Container::sniff(b"RIFF\0\0\0\0AVI LIST"), None);
        assert_eq!(Container::sniff(b"hello world!"), None);
        assert_eq!(Container::sniff(b""), None);
    }

    #[test]
    fn garbage_behind_a_magic_number_is_refused_with_the_file_name() {
        for bytes in [
            b"fLaC\0\0\0\x22junk".to_vec(),
            b"OggS\0\x02\0\0\0\0\0\0\0\0".to_vec(),
            b"\0\0\0\x20ftypM4A \0\0\0\0".to_vec(),
            b"ID3\x04\0\0\0\0\0\0junkjunkjunk".to_vec(),
            vec![0xFF, 0xFB, 0x90, 0x64, 0, 0, 0],
        ] {
            let c = Container::sniff(&bytes).unwrap();
            let r = CompressedSource::open(
                Box::new(std::io::Cursor::new(bytes.clone())),
                c,
                Path::new("x.bin"),
            )
            .and_then(|mut s| {
                let mut out = Vec::new();
                while s.read_mono(4096, &mut out)? {}
                Ok(out)
            });
            match r {
                Err(e) => {
                    assert!(e.to_string().contains("x.bin"), "{e}");
                    assert!(e.is_input_error(), "{e}");
                }
                // Junk may hold no frame at all: no audio, not made-up audio.
                Ok(out) => assert!(out.is_empty(), "{c:?}: {} samples", out.len()),
            }
        }
    }
}
