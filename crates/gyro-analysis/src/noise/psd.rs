//! Welch power spectral density of the rate, and the white-noise density read from it.
//!
//! As `scipy.signal.welch(y, fs, window="hann", nperseg=L, noverlap=L/2,
//! detrend="constant", scaling="density")`: segments of `L` samples (a power of two) with
//! 50% overlap, each with its mean removed and a periodic Hann window applied; the
//! one-sided PSD ((deg/s)²/Hz) is `2 |X_k|² / (fs Σ w²)` (DC and Nyquist not doubled),
//! averaged over all segments of all rest stretches. Default `L`: the largest power of two
//! ≤ a quarter of the longest segment (≥ 7 averaged segments), between 16 and 16384.
//!
//! White rate noise of density N (deg/s/√Hz, the Allan N) has a one-sided PSD of 2N².
//! The white density is read as √(mean PSD / 2) over a band near the top of the spectrum
//! (by default 40–90% of Nyquist), where white noise dominates unless the sensor's own
//! bandwidth is lower; compare it with the Allan fit's N.

use super::fft::fft_in_place;
use serde::Serialize;

/// Settings of the PSD.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PsdOptions {
    /// Segment length (a power of two); `None`: the default (module docs).
    pub segment_len: Option<usize>,
    /// Band for the white density, as fractions of the Nyquist frequency.
    pub white_band: (f64, f64),
}

impl Default for PsdOptions {
    fn default() -> Self {
        Self {
            segment_len: None,
            white_band: (0.4, 0.9),
        }
    }
}

/// The PSD averaged over a frequency band.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PsdBand {
    /// Lower edge (Hz).
    pub low_hz: f64,
    /// Upper edge (Hz).
    pub high_hz: f64,
    /// Mean PSD over the band's bins ((deg/s)²/Hz).
    pub psd_dps2_per_hz: f64,
    /// Bins averaged.
    pub bins: usize,
}

/// A Welch PSD.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Psd {
    /// Segment length (samples).
    pub segment_len: usize,
    /// Segments averaged.
    pub segments: usize,
    /// Frequency resolution (Hz).
    pub resolution_hz: f64,
    /// White-noise density √(PSD/2) over the white band (deg/s/√Hz).
    pub white_density_dps_per_rt_hz: f64,
    /// The same as an angle random walk (deg/√h) = 60 × density.
    pub white_arw_deg_per_rt_h: f64,
    /// The band the white density was read over (Hz).
    pub white_band_hz: (f64, f64),
    /// The PSD averaged over ten bands per decade (from the first non-zero frequency).
    pub bands: Vec<PsdBand>,
    /// Bin frequencies (Hz), 0 to Nyquist.
    #[serde(skip)]
    pub frequency_hz: Vec<f64>,
    /// One-sided PSD per bin ((deg/s)²/Hz).
    #[serde(skip)]
    pub psd_dps2_per_hz: Vec<f64>,
}

/// The default segment length for segments whose longest has `longest` samples.
pub fn default_segment_len(longest: usize) -> usize {
    let target = (longest / 4).clamp(16, 16_384).min(longest.max(2));
    1usize << (usize::BITS - 1 - target.leading_zeros())
}

/// The periodic Hann window of `len` samples (Welch's segments).
pub fn hann(len: usize) -> Vec<f64> {
    (0..len)
        .map(|n| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * n as f64 / len as f64).cos())
        .collect()
}

/// Welch PSD of rate `segments` (deg/s) at `sample_rate_hz`; `None` if no segment holds
/// one window (or the length is not a power of two ≥ 2).
pub fn welch(segments: &[&[f64]], sample_rate_hz: f64, options: &PsdOptions) -> Option<Psd> {
    let longest = segments.iter().map(|s| s.len()).max()?;
    let len = options
        .segment_len
        .unwrap_or_else(|| default_segment_len(longest));
    if len < 2 || !len.is_power_of_two() || len > longest {
        return None;
    }
    let (psd, count) = welch_average(segments, len, sample_rate_hz);
    let resolution_hz = sample_rate_hz / len as f64;
    let frequency_hz: Vec<f64> = (0..len / 2 + 1).map(|k| k as f64 * resolution_hz).collect();

    let nyquist = 0.5 * sample_rate_hz;
    let band = (
        options.white_band.0 * nyquist,
        options.white_band.1 * nyquist,
    );
    let mean_over = |lo: f64, hi: f64| {
        let (sum, n) = frequency_hz
            .iter()
            .zip(&psd)
            .filter(|(f, _)| **f > 0.0 && **f >= lo && **f <= hi)
            .fold((0.0, 0usize), |(s, n), (_, p)| (s + p, n + 1));
        (n > 0).then(|| (sum / n as f64, n))
    };
    let (white, white_band_hz) = match mean_over(band.0, band.1) {
        Some((p, _)) => (p, band),
        None => (
            mean_over(resolution_hz, nyquist).map_or(0.0, |(p, _)| p),
            (resolution_hz, nyquist),
        ),
    };
    let white_density = (white / 2.0).sqrt();
    let bands = decade_bands(&frequency_hz, &psd, resolution_hz, nyquist);
    Some(Psd {
        segment_len: len,
        segments: count,
        resolution_hz,
        white_density_dps_per_rt_hz: white_density,
        white_arw_deg_per_rt_h: 60.0 * white_density,
        white_band_hz,
        bands,
        frequency_hz,
        psd_dps2_per_hz: psd,
    })
}

/// The one-sided PSD ((deg/s)²/Hz per bin, 0 to Nyquist) averaged over every Hann-windowed,
/// half-overlapping, mean-removed window of `len` samples of the `segments`, and how many
/// windows.
fn welch_average(segments: &[&[f64]], len: usize, sample_rate_hz: f64) -> (Vec<f64>, usize) {
    let window = hann(len);
    let window_power: f64 = window.iter().map(|w| w * w).sum();
    let bins = len / 2 + 1;
    let mut acc = vec![0.0_f64; bins];
    let mut count = 0usize;
    let (mut re, mut im) = (vec![0.0; len], vec![0.0; len]);
    for seg in segments {
        if seg.len() < len {
            continue;
        }
        let mut start = 0;
        while start + len <= seg.len() {
            let chunk = &seg[start..start + len];
            let mean = chunk.iter().sum::<f64>() / len as f64;
            for i in 0..len {
                re[i] = (chunk[i] - mean) * window[i];
                im[i] = 0.0;
            }
            fft_in_place(&mut re, &mut im);
            for (k, a) in acc.iter_mut().enumerate() {
                *a += re[k] * re[k] + im[k] * im[k];
            }
            count += 1;
            start += len / 2;
        }
    }
    let scale = 1.0 / (sample_rate_hz * window_power * count as f64);
    let psd: Vec<f64> = acc
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let one_sided = if k == 0 || k == len / 2 { 1.0 } else { 2.0 };
            a * scale * one_sided
        })
        .collect();
    (psd, count)
}

/// The PSD averaged over ten bands per decade from `resolution_hz` to `nyquist` (Hz),
/// the bands holding no bin left out.
fn decade_bands(
    frequency_hz: &[f64],
    psd: &[f64],
    resolution_hz: f64,
    nyquist: f64,
) -> Vec<PsdBand> {
    let mut bands = Vec::new();
    let mut low = resolution_hz;
    while low <= nyquist {
        let high = low * 10f64.powf(0.1);
        let (sum, n) = frequency_hz
            .iter()
            .zip(psd)
            .filter(|(f, _)| **f >= low && **f < high || (high > nyquist && **f == nyquist))
            .fold((0.0, 0usize), |(s, n), (_, p)| (s + p, n + 1));
        if n > 0 {
            bands.push(PsdBand {
                low_hz: low,
                high_hz: high.min(nyquist),
                psd_dps2_per_hz: sum / n as f64,
                bins: n,
            });
        }
        low = high;
    }
    bands
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_lengths() {
        assert_eq!(default_segment_len(16), 16);
        assert_eq!(default_segment_len(100), 16);
        assert_eq!(default_segment_len(20_000), 4096);
        assert_eq!(default_segment_len(10_000_000), 16_384);
    }

    #[test]
    fn parseval_and_a_tone() {
        // A sine of amplitude A at a bin frequency: the PSD integrates to A²/2.
        let fs = 64.0;
        let y: Vec<f64> = (0..4096)
            .map(|k| 3.0 * (2.0 * std::f64::consts::PI * 8.0 * k as f64 / fs).sin())
            .collect();
        let psd = welch(&[&y], fs, &PsdOptions::default()).expect("psd");
        let power: f64 = psd.psd_dps2_per_hz.iter().sum::<f64>() * psd.resolution_hz;
        assert!((power / 4.5 - 1.0).abs() < 1e-6, "{power}");
        let peak = psd
            .psd_dps2_per_hz
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (k, p)| if *p > b.1 { (k, *p) } else { b });
        assert!((psd.frequency_hz[peak.0] - 8.0).abs() < 1e-9);
    }
}
