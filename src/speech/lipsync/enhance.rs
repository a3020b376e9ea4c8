//! The recording made easier for the phone recogniser before it hears it: steady noise
//! reduced (a Wiener gain per frequency from the quietest frames' spectrum) and, for
//! band-limited audio (telephone rates), the empty band above the source's Nyquist
//! frequency filled with a mirror image of the band below it, since the acoustic model was
//! trained on 16 kHz speech and reads an empty top band as a dark sound.
//!
//! Both work on a short-time spectrum: 32 ms frames every 16 ms under a square-root Hann
//! window, put back together by overlap-add (analysis and synthesis windows multiply to a
//! Hann window, whose half-overlapped copies sum to one, so a gain of one gives the input
//! back).
//!
//! Measured on `examples/lipsync_eval.rs` without a transcript (`LIPSYNC_EVAL_NOSCRIPT_ONLY=1`;
//! closures / agreement / false closures, %; espeak-ng voices | Festival's degraded
//! conditions | Festival clean 16 kHz), the phone loop as before: 57.7 / 66.4 / 3.2 | 44.4 /
//! 59.9 / 1.3 | 86.4 / 80.1 / 3.8.
//! - The top band mirrored for audio sampled below 16 kHz (at 0.95 of its Nyquist
//!   frequency, half the amplitude): 58.7 / 68.9 / 3.2 | 56.6 / 65.2 / 1.5 | unchanged
//!   (Festival ked at 8 kHz 18.4 / 42.2 / 1.2 → 67.3 / 63.6 / 2.1). The recogniser's default
//!   ([`super::recognition`]). It also puts more PP on other consonants (espeak-ng's 8 kHz
//!   voice 12.9 → 17.0 %; all espeak-ng voices 10.9 → 12.0 %, Festival's 12.1 → 13.5 %).
//! - Noise reduced, gain floor 0.1 (−20 dB): 54.1 / 58.7 / 2.4 | 58.2 / 65.2 / 1.5 | 83.0 /
//!   80.1 / 3.7; floor 0.3: 58.2 / 61.7 / 2.9 | 56.1 / 62.5 / 1.8 | 85.7 / 79.8 / 4.0. Festival's
//!   noisy voices gain (slt at 15 dB closures 26.5 → 53.1 %) but espeak-ng's lose up to 13
//!   points of agreement (en-us at 20 dB 70.4 → 57.5 %) and the clean voices lose closures,
//!   so it is not applied by default; [`enhance`] with a floor below one does it.

use super::features::Fft;

/// Frame length, samples at 16 kHz.
const FRAME: usize = 512;
/// Hop between frames.
const HOP: usize = FRAME / 2;
/// Share of the frames, the quietest, whose mean spectrum is taken as the noise's.
const NOISE_SHARE: f64 = 0.1;
/// Weight of the last frame's clean estimate in the a-priori SNR (the decision-directed
/// rule: smoothing it keeps the gain from flickering, which would leave "musical" tones).
const DIRECTED: f32 = 0.98;

/// What is done to the audio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Enhance {
    /// Lowest Wiener gain (noise is reduced by at most this much; 1 leaves it).
    pub floor: f32,
    /// Fill the band above this frequency (Hz) with the mirror image of the band below it
    /// (`None`: leave it); the level of the image is `mirror_gain`.
    pub mirror_above: Option<f64>,
    /// Amplitude of the mirrored band relative to its source.
    pub mirror_gain: f32,
}

impl Default for Enhance {
    fn default() -> Self {
        Enhance {
            floor: 1.0,
            mirror_above: None,
            mirror_gain: 0.5,
        }
    }
}

impl Enhance {
    /// Whether it changes anything.
    pub fn is_identity(&self) -> bool {
        self.floor >= 1.0 && self.mirror_above.is_none()
    }
}

/// `samples` (16 kHz) enhanced as `how` says; as long as the input.
pub fn enhance(samples: &[i16], how: &Enhance, rate: f64) -> Vec<i16> {
    if how.is_identity() || samples.len() < FRAME {
        return samples.to_vec();
    }
    let window: Vec<f32> = (0..FRAME)
        .map(|n| {
            let hann = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * n as f64 / FRAME as f64).cos();
            hann.sqrt() as f32
        })
        .collect();
    let fft = Fft::new(FRAME);
    // Pad by a frame on each side so every sample is covered by two frames.
    let padded: Vec<f32> = std::iter::repeat_n(0.0, FRAME)
        .chain(samples.iter().map(|&s| f32::from(s)))
        .chain(std::iter::repeat_n(0.0, 2 * FRAME))
        .collect();
    let count = (padded.len() - FRAME) / HOP + 1;
    let bins = FRAME / 2 + 1;
    let mut spectra: Vec<(Vec<f32>, Vec<f32>)> = Vec::with_capacity(count);
    for f in 0..count {
        let mut re: Vec<f32> = (0..FRAME)
            .map(|n| padded[f * HOP + n] * window[n])
            .collect();
        let mut im = vec![0.0f32; FRAME];
        fft.run(&mut re, &mut im);
        spectra.push((re, im));
    }
    if how.floor < 1.0 {
        let noise = noise_power(&spectra, bins);
        let mut last_clean = vec![0.0f32; bins];
        for (re, im) in &mut spectra {
            for k in 0..bins {
                let power = re[k] * re[k] + im[k] * im[k];
                let n = noise[k].max(1e-6);
                let posterior = power / n;
                let prior =
                    DIRECTED * last_clean[k] / n + (1.0 - DIRECTED) * (posterior - 1.0).max(0.0);
                let gain = (prior / (1.0 + prior)).max(how.floor);
                last_clean[k] = gain * gain * power;
                scale_bin(re, im, k, gain);
            }
        }
    }
    if let Some(above) = how.mirror_above {
        let edge = ((above / rate * FRAME as f64).round() as usize).clamp(1, bins - 1);
        for (re, im) in &mut spectra {
            for k in edge + 1..bins {
                let Some(from) = (2 * edge).checked_sub(k) else {
                    break;
                };
                re[k] = how.mirror_gain * re[from];
                im[k] = -how.mirror_gain * im[from];
                if k < FRAME - k {
                    re[FRAME - k] = re[k];
                    im[FRAME - k] = -im[k];
                }
            }
        }
    }
    let mut out = vec![0.0f32; padded.len()];
    for (f, (re, im)) in spectra.iter_mut().enumerate() {
        // The inverse transform through the forward one: conj(FFT(conj(X))) / N.
        for v in im.iter_mut() {
            *v = -*v;
        }
        fft.run(re, im);
        for n in 0..FRAME {
            out[f * HOP + n] += re[n] / FRAME as f32 * window[n];
        }
    }
    out[FRAME..FRAME + samples.len()]
        .iter()
        .map(|&s| s.round().clamp(-32_768.0, 32_767.0) as i16)
        .collect()
}

/// Scales bin `k` and its mirror by `gain`.
fn scale_bin(re: &mut [f32], im: &mut [f32], k: usize, gain: f32) {
    let n = re.len();
    re[k] *= gain;
    im[k] *= gain;
    if k != 0 && k != n - k {
        re[n - k] *= gain;
        im[n - k] *= gain;
    }
}

/// The mean power spectrum of the quietest [`NOISE_SHARE`] of the frames.
fn noise_power(spectra: &[(Vec<f32>, Vec<f32>)], bins: usize) -> Vec<f32> {
    let power = |(re, im): &(Vec<f32>, Vec<f32>), k: usize| re[k] * re[k] + im[k] * im[k];
    let mut by_energy: Vec<(f32, usize)> = spectra
        .iter()
        .enumerate()
        .map(|(i, s)| ((0..bins).map(|k| power(s, k)).sum(), i))
        .collect();
    by_energy.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Frames of digital silence (padding, a lead-in of zeros) say nothing of the noise.
    let live: Vec<usize> = by_energy
        .iter()
        .filter(|(e, _)| *e > 0.0)
        .map(|&(_, i)| i)
        .collect();
    let take = ((live.len() as f64 * NOISE_SHARE).ceil() as usize).clamp(1, live.len().max(1));
    let mut noise = vec![0.0f32; bins];
    for &i in live.iter().take(take) {
        for (k, v) in noise.iter_mut().enumerate() {
            *v += power(&spectra[i], k) / take as f32;
        }
    }
    noise
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone(freq: f64, amp: f64, len: usize) -> Vec<f64> {
        (0..len)
            .map(|n| amp * (2.0 * std::f64::consts::PI * freq * n as f64 / 16_000.0).sin())
            .collect()
    }

    /// A deterministic white-ish noise in [-amp, amp].
    fn noise(amp: f64, len: usize) -> Vec<f64> {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        (0..len)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                amp * ((x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0)
            })
            .collect()
    }

    fn to_i16(x: &[f64]) -> Vec<i16> {
        x.iter().map(|&v| v.round() as i16).collect()
    }

    fn rms(x: &[i16]) -> f64 {
        (x.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>() / x.len().max(1) as f64).sqrt()
    }

    #[test]
    fn a_gain_of_one_gives_the_input_back() {
        let x = to_i16(&tone(440.0, 8000.0, 5000));
        let how = Enhance {
            floor: 0.999_999,
            ..Enhance::default()
        };
        let y = enhance(&x, &how, 16_000.0);
        assert_eq!(y.len(), x.len());
        // A floor just under one keeps every gain at about one.
        let worst = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).max();
        assert!(worst <= Some(2), "{worst:?}");
        assert_eq!(enhance(&x, &Enhance::default(), 16_000.0), x);
    }

    #[test]
    fn steady_noise_is_reduced_and_a_tone_over_it_kept() {
        // Half a second of noise alone, then a tone over the same noise.
        let n = noise(600.0, 16_000);
        let mut x: Vec<f64> = n.clone();
        for (v, t) in x[8_000..].iter_mut().zip(tone(1000.0, 6000.0, 8_000)) {
            *v += t;
        }
        let x = to_i16(&x);
        let how = Enhance {
            floor: 0.1,
            ..Enhance::default()
        };
        let y = enhance(&x, &how, 16_000.0);
        // The noise alone falls by more than 10 dB.
        assert!(rms(&y[1_000..7_000]) < 0.3 * rms(&x[1_000..7_000]));
        // The tone keeps most of its level.
        let r = rms(&y[9_000..15_000]) / rms(&x[9_000..15_000]);
        assert!(r > 0.85 && r < 1.05, "{r}");
    }

    #[test]
    fn an_empty_top_band_is_filled_from_below() {
        // A 3 kHz tone in band-limited audio: its mirror about 4 kHz lands at 5 kHz.
        let x = to_i16(&tone(3000.0, 8000.0, 8_000));
        let how = Enhance {
            mirror_above: Some(4000.0),
            ..Enhance::default()
        };
        let y = enhance(&x, &how, 16_000.0);
        let level = |s: &[i16], f: f64| {
            let (mut c, mut d) = (0.0, 0.0);
            for (n, &v) in s.iter().enumerate() {
                let a = 2.0 * std::f64::consts::PI * f * n as f64 / 16_000.0;
                c += f64::from(v) * a.cos();
                d += f64::from(v) * a.sin();
            }
            (c * c + d * d).sqrt() / s.len() as f64
        };
        assert!(level(&x[1_000..7_000], 5000.0) < 50.0);
        let (kept, image) = (
            level(&y[1_000..7_000], 3000.0),
            level(&y[1_000..7_000], 5000.0),
        );
        assert!(image > 0.3 * kept && image < 0.7 * kept, "{kept} {image}");
        assert!(enhance(&[], &how, 16_000.0).is_empty());
    }
}
