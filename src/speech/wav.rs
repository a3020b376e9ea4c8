//! The synthesised speech as a WAV file (mono, 16-bit PCM), written atomically.

use std::path::Path;

use super::espeak::Utterance;
use crate::error::{EncodeError, Error, Result};

/// The WAV bytes of `utterance`.
pub fn wav_bytes(utterance: &Utterance) -> Result<Vec<u8>> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: utterance.sample_rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut cursor = std::io::Cursor::new(Vec::with_capacity(44 + 2 * utterance.samples.len()));
    let encode = |e: hound::Error| -> Error { EncodeError::new("WAV", e).into() };
    let mut w = hound::WavWriter::new(&mut cursor, spec).map_err(encode)?;
    for &s in &utterance.samples {
        w.write_sample(s).map_err(encode)?;
    }
    w.finalize().map_err(encode)?;
    Ok(cursor.into_inner())
}

/// Writes `utterance` to `path` as a WAV file (atomically).
pub fn write_wav(path: &Path, utterance: &Utterance) -> Result<()> {
    crate::io::write_atomic(path, &wav_bytes(utterance)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wav_round_trips() {
        let u = Utterance {
            sample_rate: 22_050,
            samples: vec![0, 1, -1, i16::MAX, i16::MIN],
            phonemes: Vec::new(),
            words: Vec::new(),
        };
        let bytes = wav_bytes(&u).unwrap();
        let mut r = hound::WavReader::new(std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(r.spec().sample_rate, 22_050);
        assert_eq!(r.spec().channels, 1);
        let back: Vec<i16> = r.samples::<i16>().map(|s| s.unwrap()).collect();
        assert_eq!(back, u.samples);
    }
}
