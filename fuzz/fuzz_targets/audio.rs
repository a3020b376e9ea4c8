//! Recording front door (`fbakit::speech::audio::audio_from_bytes`): WAV, MP3, FLAC, Ogg
//! Vorbis and M4A told apart by their first bytes. Any bytes must give samples or an error
//! naming the file, never a panic, hang or unbounded allocation; samples are finite and in
//! [-1, 1].
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(mut reader) = fbakit::speech::audio::audio_from_bytes(data.to_vec(), Path::new("fuzz.audio"))
    else {
        return;
    };
    let mut samples = 0usize;
    loop {
        match reader.next_chunk() {
            Ok(Some(chunk)) => {
                assert!(chunk.iter().all(|s| s.is_finite() && s.abs() <= 1.0 + 1e-3));
                samples += chunk.len();
                // A minute at the analysis rate is plenty for a fuzz input.
                if samples > 16_000 * 60 {
                    break;
                }
            }
            Ok(None) => break,
            Err(e) => {
                assert!(e.to_string().contains("fuzz.audio"), "{e}");
                break;
            }
        }
    }
});
