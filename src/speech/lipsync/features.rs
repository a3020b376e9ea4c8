//! Spectral features of speech, computed a chunk at a time: MFCCs (mel-frequency cepstral
//! coefficients) and frame energy every 10 ms over 25 ms Hamming windows at
//! [`ANALYSIS_RATE`](crate::speech::audio::ANALYSIS_RATE).
//!
//! MFCCs describe the shape of the vocal tract's spectrum and little of the voice's pitch,
//! which is what lets a recording be compared with espeak-ng's rendition of the same words.
//! Each utterance is normalised to zero mean and unit variance per coefficient
//! ([`normalise`]), which removes most of the difference between microphones and voices.

/// Seconds between frames.
pub const HOP_SECONDS: f64 = 0.010;
/// Samples between frames at the analysis rate.
const HOP: usize = 160;
/// Window length in samples (25 ms).
const WINDOW: usize = 400;
/// FFT length.
const FFT: usize = 512;
/// Mel filters.
const MELS: usize = 26;
/// Cepstral coefficients kept, c0 included.
pub const CEPS: usize = 13;
/// Analysis rate in Hz.
const RATE: f64 = 16_000.0;

/// One frame's features.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureFrame {
    /// c0..c12.
    pub mfcc: [f32; CEPS],
    /// Frame energy in dB relative to full scale (≥ −120).
    pub energy_db: f32,
    /// Energy of the sample-to-sample differences, dB (≥ −120): the high frequencies
    /// weighted up, so `high_db − energy_db` is low for a dark, low-frequency sound (a nasal
    /// murmur or a voice bar behind closed lips) and high for a hiss or a burst.
    pub high_db: f32,
}

/// The time (seconds) at the middle of frame `k`.
pub fn frame_time(k: usize) -> f64 {
    k as f64 * HOP_SECONDS + 0.5 * WINDOW as f64 / RATE
}

/// The frame whose middle is nearest time `t` (seconds), clamped to `0..count`.
pub fn frame_at(t: f64, count: usize) -> usize {
    let k = ((t - 0.5 * WINDOW as f64 / RATE) / HOP_SECONDS).round();
    if k.is_nan() || k < 0.0 {
        0
    } else {
        (k as usize).min(count.saturating_sub(1))
    }
}

/// Turns samples into feature frames as they arrive.
#[derive(Clone, Debug)]
pub struct FeatureExtractor {
    pending: Vec<f32>,
    /// The last sample before `pending` (for pre-emphasis).
    previous: f32,
    window: Vec<f32>,
    filters: Vec<(usize, Vec<f32>)>,
    dct: Vec<[f32; MELS]>,
    fft: Fft,
    frames: Vec<FeatureFrame>,
}

impl Default for FeatureExtractor {
    fn default() -> Self {
        Self::new()
    }
}

impl FeatureExtractor {
    /// A new extractor.
    pub fn new() -> FeatureExtractor {
        let window = (0..WINDOW)
            .map(|n| {
                (0.54 - 0.46 * (2.0 * std::f64::consts::PI * n as f64 / (WINDOW - 1) as f64).cos())
                    as f32
            })
            .collect();
        let dct = (0..CEPS)
            .map(|c| {
                let mut row = [0f32; MELS];
                for (m, r) in row.iter_mut().enumerate() {
                    *r = (std::f64::consts::PI * c as f64 * (m as f64 + 0.5) / MELS as f64).cos()
                        as f32;
                }
                row
            })
            .collect();
        FeatureExtractor {
            pending: Vec::new(),
            previous: 0.0,
            window,
            filters: mel_filters(),
            dct,
            fft: Fft::new(FFT),
            frames: Vec::new(),
        }
    }

    /// Feeds samples at the analysis rate.
    pub fn push(&mut self, samples: &[f32]) {
        self.pending.extend_from_slice(samples);
        let mut start = 0;
        while start + WINDOW <= self.pending.len() {
            self.frame_from(start);
            start += HOP;
        }
        if start > 0 {
            self.previous = self.pending[start - 1];
            self.pending.drain(..start);
        }
    }

    /// Ends the input: the last partial window is padded with silence.
    pub fn finish(mut self) -> Vec<FeatureFrame> {
        if !self.pending.is_empty() {
            let len = self.pending.len();
            self.pending.resize(len.max(WINDOW), 0.0);
            let mut start = 0;
            while start < len {
                if start + WINDOW > self.pending.len() {
                    self.pending.resize(start + WINDOW, 0.0);
                }
                self.frame_from(start);
                start += HOP;
            }
        }
        self.frames
    }

    /// Frames made so far.
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    fn frame_from(&mut self, start: usize) {
        let mut re = [0f32; FFT];
        let mut im = [0f32; FFT];
        let mut energy = 0f64;
        let mut high = 0f64;
        for (n, (out, w)) in re.iter_mut().zip(&self.window).enumerate() {
            let x = self.pending[start + n];
            let before = if start + n == 0 {
                self.previous
            } else {
                self.pending[start + n - 1]
            };
            energy += f64::from(x) * f64::from(x);
            high += f64::from(x - before) * f64::from(x - before);
            *out = (x - 0.97 * before) * w;
        }
        self.fft.run(&mut re, &mut im);
        let mut logmel = [0f32; MELS];
        for (m, (first, weights)) in self.filters.iter().enumerate() {
            let mut e = 0f32;
            for (k, w) in weights.iter().enumerate() {
                let b = first + k;
                e += w * (re[b] * re[b] + im[b] * im[b]);
            }
            logmel[m] = (e + 1e-8).ln();
        }
        let mut mfcc = [0f32; CEPS];
        for (c, row) in self.dct.iter().enumerate() {
            mfcc[c] = row.iter().zip(&logmel).map(|(a, b)| a * b).sum();
        }
        let db = |e: f64| (10.0 * (e / WINDOW as f64 + 1e-12).log10()).max(-120.0) as f32;
        self.frames.push(FeatureFrame {
            mfcc,
            energy_db: db(energy),
            high_db: db(high),
        });
    }
}

fn hz_to_mel(f: f64) -> f64 {
    2595.0 * (1.0 + f / 700.0).log10()
}

fn mel_to_hz(m: f64) -> f64 {
    700.0 * (10f64.powf(m / 2595.0) - 1.0)
}

/// Triangular mel filters from 80 to 7600 Hz: (first FFT bin, weights).
fn mel_filters() -> Vec<(usize, Vec<f32>)> {
    let (lo, hi) = (hz_to_mel(80.0), hz_to_mel(7600.0));
    let edges: Vec<f64> = (0..MELS + 2)
        .map(|i| mel_to_hz(lo + (hi - lo) * i as f64 / (MELS + 1) as f64) * FFT as f64 / RATE)
        .collect();
    (0..MELS)
        .map(|m| {
            let (a, b, c) = (edges[m], edges[m + 1], edges[m + 2]);
            let first = a.ceil() as usize;
            let last = (c.floor() as usize).min(FFT / 2);
            let weights = (first..=last)
                .map(|k| {
                    let k = k as f64;
                    let w = if k <= b {
                        (k - a) / (b - a)
                    } else {
                        (c - k) / (c - b)
                    };
                    w.max(0.0) as f32
                })
                .collect();
            (first, weights)
        })
        .collect()
}

/// Per-coefficient mean and variance normalisation of `frames` (c1..c12 become the
/// comparison vectors; c0, the loudness, is left out so level differences do not count).
pub fn normalise(frames: &[FeatureFrame]) -> Vec<[f32; CEPS - 1]> {
    let n = frames.len().max(1) as f64;
    let mut mean = [0f64; CEPS - 1];
    let mut var = [0f64; CEPS - 1];
    for f in frames {
        for (m, v) in mean.iter_mut().zip(&f.mfcc[1..]) {
            *m += f64::from(*v);
        }
    }
    for m in &mut mean {
        *m /= n;
    }
    for f in frames {
        for c in 0..CEPS - 1 {
            var[c] += (f64::from(f.mfcc[c + 1]) - mean[c]).powi(2);
        }
    }
    let scale: Vec<f64> = var.iter().map(|v| 1.0 / (v / n).sqrt().max(1e-6)).collect();
    frames
        .iter()
        .map(|f| {
            let mut out = [0f32; CEPS - 1];
            for c in 0..CEPS - 1 {
                out[c] = ((f64::from(f.mfcc[c + 1]) - mean[c]) * scale[c]) as f32;
            }
            out
        })
        .collect()
}

/// An in-place radix-2 complex FFT of a fixed power-of-two size.
#[derive(Clone, Debug)]
pub(super) struct Fft {
    n: usize,
    cos: Vec<f32>,
    sin: Vec<f32>,
}

impl Fft {
    pub(super) fn new(n: usize) -> Fft {
        let cos = (0..n / 2)
            .map(|k| (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos() as f32)
            .collect();
        let sin = (0..n / 2)
            .map(|k| (-2.0 * std::f64::consts::PI * k as f64 / n as f64).sin() as f32)
            .collect();
        Fft { n, cos, sin }
    }

    pub(super) fn run(&self, re: &mut [f32], im: &mut [f32]) {
        let n = self.n;
        let bits = n.trailing_zeros();
        for i in 0..n {
            let j = i.reverse_bits() >> (usize::BITS - bits);
            if j > i {
                re.swap(i, j);
                im.swap(i, j);
            }
        }
        let mut len = 2;
        while len <= n {
            let stride = n / len;
            for start in (0..n).step_by(len) {
                for k in 0..len / 2 {
                    let (wr, wi) = (self.cos[k * stride], self.sin[k * stride]);
                    let (a, b) = (start + k, start + k + len / 2);
                    let tr = re[b] * wr - im[b] * wi;
                    let ti = re[b] * wi + im[b] * wr;
                    re[b] = re[a] - tr;
                    im[b] = im[a] - ti;
                    re[a] += tr;
                    im[a] += ti;
                }
            }
            len *= 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_finds_a_tone_in_its_bin() {
        let fft = Fft::new(64);
        let mut re: Vec<f32> = (0..64)
            .map(|n| (2.0 * std::f32::consts::PI * 5.0 * n as f32 / 64.0).cos())
            .collect();
        let mut im = vec![0f32; 64];
        fft.run(&mut re, &mut im);
        let mag: Vec<f32> = re
            .iter()
            .zip(&im)
            .map(|(r, i)| (r * r + i * i).sqrt())
            .collect();
        assert!((mag[5] - 32.0).abs() < 1e-3, "{}", mag[5]);
        assert!(mag
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != 5 && *k != 59)
            .all(|(_, m)| *m < 1e-3));
    }

    #[test]
    fn chunking_does_not_change_the_features() {
        let samples: Vec<f32> = (0..16_000)
            .map(|n| ((n as f32 * 0.05).sin() * (n as f32 * 0.0007).cos()) * 0.3)
            .collect();
        let mut whole = FeatureExtractor::new();
        whole.push(&samples);
        let whole = whole.finish();
        let mut parts = FeatureExtractor::new();
        for c in samples.chunks(777) {
            parts.push(c);
        }
        let parts = parts.finish();
        assert_eq!(whole.len(), 100);
        assert_eq!(whole, parts);
        assert!(frame_at(frame_time(42), 100) == 42);
        // Silence is quiet, the signal is not.
        assert!(whole[50].energy_db > -30.0);
        let mut quiet = FeatureExtractor::new();
        quiet.push(&[0.0; 1600]);
        assert!(quiet.finish().iter().all(|f| f.energy_db <= -119.0));
    }
}
