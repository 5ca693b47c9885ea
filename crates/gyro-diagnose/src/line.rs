//! A narrow line in the residual's spectrum (`vibration`): a stepper motor, a fan or a
//! mount resonance that the gyro sees and the reference does not.
//!
//! The statistic is the **line ratio** of a bin: the pooled incoherent PSD (mean over
//! the runs of [`Features::incoherent_psd`]: the gyro's spectrum not explained by the
//! reference rate, so that a line of the motion itself, seen through a latency, is not a
//! vibration) over its local floor, the median of the bins [`GUARD_BINS`] + 1 to
//! [`FLOOR_BINS`] away on either side. A broad mismatch of the spectrum (a noisier
//! sensor, a differentiated encoder) moves the floor with it; a sinusoid stands above it. The search runs from [`MIN_LINE_HZ`] (below it the motion's
//! own harmonics, times any scale error, make lines of their own) to 95% of the Nyquist
//! frequency; the strongest ratio is tested against the same search on each null replica
//! (the largest ratio a nominal sensor shows by chance), so the look-elsewhere effect is
//! in the null distribution. A line must also stand [`LINE_MIN_RATIO`] times above its
//! floor, on the training runs and again on the held-out runs.
//!
//! A sinusoid of amplitude A has power A²/2: the excess over the floor, summed over the
//! line's bins (the Hann window spreads it over ±[`GUARD_BINS`]) times the bin width,
//! gives A; its frequency is the excess-weighted centroid of those bins.

use super::ensemble::{Member, RealRun};
use super::features::{line_resolution_hz, Features};
use super::fit::mean_sd;
use gyro_analysis::median;

/// A line must also stand this many times above its local floor (on the training runs to
/// be found, on the held-out runs to replicate): the null replicas' spectra are smooth,
/// a real sensor's have texture (an encoder's steps, the motion), so a ratio of 1.1 can
/// be many null standard deviations without being a line.
/// The default `statistics.line_min_ratio` ([`crate::Settings`]), where the settings do not reach yet.
pub const LINE_MIN_RATIO: f64 = crate::Settings::DEFAULT.statistics.line_min_ratio;
/// A line of the motion is reported when it stands this many times above its floor.
/// The default `statistics.motion_line_ratio` ([`crate::Settings`]), where the settings do not reach yet.
pub const MOTION_LINE_RATIO: f64 = crate::Settings::DEFAULT.statistics.motion_line_ratio;
/// Lowest frequency searched for a line (Hz).
/// The default `statistics.min_line_hz` ([`crate::Settings`]), where the settings do not reach yet.
pub const MIN_LINE_HZ: f64 = crate::Settings::DEFAULT.statistics.min_line_hz;
/// Bins on either side of a line that belong to it (Hann main lobe).
/// The default `statistics.guard_bins` ([`crate::Settings`]), where the settings do not reach yet.
pub const GUARD_BINS: usize = crate::Settings::DEFAULT.statistics.guard_bins;
/// Bins on either side whose median is the local floor.
/// The default `statistics.floor_bins` ([`crate::Settings`]), where the settings do not reach yet.
pub const FLOOR_BINS: usize = crate::Settings::DEFAULT.statistics.floor_bins;

/// The pooled incoherent PSD of `features` (mean over those with a spectrum of the
/// common length).
fn pooled<'a>(features: impl Iterator<Item = &'a Features>) -> Vec<f64> {
    pooled_with(features, |f| &f.incoherent_psd)
}

/// The pooled spectrum `which` of `features`.
fn pooled_with<'a>(
    features: impl Iterator<Item = &'a Features>,
    which: fn(&Features) -> &Vec<f64>,
) -> Vec<f64> {
    let spectra: Vec<&Vec<f64>> = features.map(which).filter(|p| !p.is_empty()).collect();
    let Some(len) = spectra.first().map(|p| p.len()) else {
        return Vec::new();
    };
    let same: Vec<&&Vec<f64>> = spectra.iter().filter(|p| p.len() == len).collect();
    (0..len)
        .map(|k| same.iter().map(|p| p[k]).sum::<f64>() / same.len() as f64)
        .collect()
}

/// The local floor of bin `k` (NaN when too close to an end).
fn floor(psd: &[f64], k: usize) -> f64 {
    if k < FLOOR_BINS || k + FLOOR_BINS >= psd.len() {
        return f64::NAN;
    }
    let around: Vec<f64> = (GUARD_BINS + 1..=FLOOR_BINS)
        .flat_map(|d| [psd[k - d], psd[k + d]])
        .collect();
    median(&around).unwrap_or(f64::NAN)
}

/// The bins searched for a line in a spectrum of `len` bins at `resolution_hz`.
fn search_range(len: usize, resolution_hz: f64) -> std::ops::Range<usize> {
    let lo = ((MIN_LINE_HZ / resolution_hz).ceil() as usize).max(FLOOR_BINS);
    let hi =
        ((0.95 * (len.saturating_sub(1)) as f64) as usize).min(len.saturating_sub(FLOOR_BINS + 1));
    lo..hi.max(lo)
}

/// The line ratio of bin `k`.
fn ratio(psd: &[f64], k: usize) -> f64 {
    psd[k] / floor(psd, k)
}

/// The strongest line of `psd`: (bin, ratio).
fn strongest(psd: &[f64], resolution_hz: f64) -> Option<(usize, f64)> {
    search_range(psd.len(), resolution_hz)
        .map(|k| (k, ratio(psd, k)))
        .filter(|(_, r)| r.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The largest line ratio within ±[`GUARD_BINS`] of bin `k`.
fn ratio_near(psd: &[f64], k: usize) -> f64 {
    (k.saturating_sub(GUARD_BINS)..=k + GUARD_BINS)
        .filter(|&i| i < psd.len())
        .map(|i| ratio(psd, i))
        .filter(|r| r.is_finite())
        .fold(f64::NAN, f64::max)
}

/// A line found in the pooled spectrum of some runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// Its amplitude (deg/s, peak).
    pub amplitude_dps: f64,
    /// Its line ratio.
    pub ratio: f64,
    /// z-score of the ratio against the null replicas' strongest (or, at a given
    /// frequency, their ratio there).
    pub z: f64,
    /// Bin width (Hz).
    pub resolution_hz: f64,
}

/// Frequency and amplitude of the line at bin `k` of `psd`.
fn measure(psd: &[f64], k: usize, resolution_hz: f64) -> (f64, f64) {
    let base = floor(psd, k);
    let (mut power, mut moment) = (0.0, 0.0);
    let first = k.saturating_sub(GUARD_BINS);
    let last = (k + GUARD_BINS).min(psd.len() - 1);
    for (i, p) in psd.iter().enumerate().take(last + 1).skip(first) {
        let excess = (p - base).max(0.0);
        power += excess * resolution_hz;
        moment += excess * i as f64;
    }
    let centre = if power > 0.0 {
        moment * resolution_hz / power
    } else {
        k as f64
    };
    (centre * resolution_hz, (2.0 * power).sqrt())
}

/// Replica `j`'s pooled spectrum of `null`.
fn replica(null: &[Vec<Member>], j: usize) -> Vec<f64> {
    pooled(null.iter().filter_map(|m| m.get(j)).map(|m| &m.features))
}

/// The strongest line of `runs` against their `null` ensembles; `None` when the runs
/// have no spectrum or the ensembles fewer than two replicas with one.
pub fn search(runs: &[&RealRun], null: &[Vec<Member>]) -> Option<Line> {
    let fs = runs.first()?.sample_rate_hz;
    let resolution_hz = line_resolution_hz(fs);
    let psd = pooled(runs.iter().map(|r| &r.features));
    let (k, ratio) = strongest(&psd, resolution_hz)?;
    let members = null.iter().map(Vec::len).min().unwrap_or(0);
    let maxima: Vec<f64> = (0..members)
        .filter_map(|j| strongest(&replica(null, j), resolution_hz).map(|x| x.1))
        .collect();
    judged(&psd, k, ratio, &maxima, resolution_hz)
}

/// The line at bin `k` of `psd`, of line ratio `ratio`, with its z-score against the
/// null replicas' values of the same statistic; `None` if either is not a number.
fn judged(psd: &[f64], k: usize, ratio: f64, null: &[f64], resolution_hz: f64) -> Option<Line> {
    let (m0, s0) = mean_sd(null);
    if !(m0.is_finite() && ratio.is_finite()) {
        return None;
    }
    let (frequency_hz, amplitude_dps) = measure(psd, k, resolution_hz);
    Some(Line {
        frequency_hz,
        amplitude_dps,
        ratio,
        z: (ratio - m0) / s0.max(1e-3 * m0),
        resolution_hz,
    })
}

/// The line ratio of `runs` near `frequency_hz` against their `null` ensembles' ratio
/// there: the held-out replication of a line found on the training runs.
pub fn at(runs: &[&RealRun], null: &[Vec<Member>], frequency_hz: f64) -> Option<Line> {
    let fs = runs.first()?.sample_rate_hz;
    let resolution_hz = line_resolution_hz(fs);
    let psd = pooled(runs.iter().map(|r| &r.features));
    let k = (frequency_hz / resolution_hz).round() as usize;
    if !search_range(psd.len(), resolution_hz).contains(&k) {
        return None;
    }
    let ratio = ratio_near(&psd, k);
    let members = null.iter().map(Vec::len).min().unwrap_or(0);
    let replicas: Vec<f64> = (0..members)
        .map(|j| {
            let p = replica(null, j);
            if p.len() == psd.len() {
                ratio_near(&p, k)
            } else {
                f64::NAN
            }
        })
        .collect();
    judged(&psd, k, ratio, &replicas, resolution_hz)
}

/// A line in the motion itself (the reference rate's spectrum), which the gyro sees with
/// the reference: a rig or a stepper motor that vibrates. Not a sensor effect, but a
/// fact of the recordings a user should know (it dominates residuals at its frequency
/// through any latency).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MotionLine {
    /// Which runs: "training" or "held-out".
    pub runs: &'static str,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// Amplitude of the motion's rate (deg/s, peak): the line in the reference rate over
    /// the reference differentiator's gain at its frequency.
    pub amplitude_dps: f64,
    /// Times its local floor.
    pub ratio: f64,
    /// The share of the line the gyro passes, `|ΣS_gr| / ΣS_rr` over the line's bin and
    /// its neighbours, pooled over the runs, times the reference differentiator's gain
    /// there (`stats::reference_rate_gain`): against the motion itself (1 for a pure
    /// delay; a roll-off passes less).
    pub gyro_gain: f64,
    /// How far the gyro lags the reference at the line (s): its cross-spectrum's phase
    /// over 2π·f (within half a period).
    pub gyro_lag_s: f64,
}

/// The strongest line of the motion of `runs` above [`MIN_LINE_HZ`], if it stands
/// [`MOTION_LINE_RATIO`] times above its floor.
pub fn motion_line(runs: &[&RealRun], label: &'static str) -> Option<MotionLine> {
    let fs = runs.first()?.sample_rate_hz;
    let resolution_hz = line_resolution_hz(fs);
    let psd = pooled_with(runs.iter().map(|r| &r.features), |f| &f.reference_psd);
    let (k, ratio) = strongest(&psd, resolution_hz)?;
    let (frequency_hz, amplitude_dps) = measure(&psd, k, resolution_hz);
    if ratio < MOTION_LINE_RATIO {
        return None;
    }
    let amplitude_dps = amplitude_dps / super::stats::reference_rate_gain(fs, frequency_hz);
    let (gyro_gain, gyro_lag_s) = response(runs, k, frequency_hz);
    Some(MotionLine {
        runs: label,
        frequency_hz,
        amplitude_dps,
        ratio,
        gyro_gain,
        gyro_lag_s,
    })
}

/// The gyro's response to the motion at bin `k` (the line at `frequency_hz`): gain and
/// lag (s) from the cross-spectrum and the reference's PSD summed over the bin and its
/// neighbours (a Hann window spreads a line over three bins) and over `runs`; NaN when
/// the runs hold no spectra.
fn response(runs: &[&RealRun], k: usize, frequency_hz: f64) -> (f64, f64) {
    let (mut re, mut im, mut srr) = (0.0, 0.0, 0.0);
    for r in runs {
        let f = &r.features;
        for j in k.saturating_sub(1)..=k + 1 {
            if let (Some(&(a, b)), Some(&w)) = (f.cross_psd.get(j), f.reference_psd.get(j)) {
                re += a;
                im += b;
                srr += w;
            }
        }
    }
    if srr.is_nan() || srr <= 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let lag_s = -im.atan2(re) / (2.0 * std::f64::consts::PI * frequency_hz);
    let fs = runs.first().map_or(f64::NAN, |r| r.sample_rate_hz);
    // Against the motion, not against the reference rate's differentiator.
    let gain =
        (re * re + im * im).sqrt() / srr * super::stats::reference_rate_gain(fs, frequency_hz);
    (gain, lag_s)
}

/// Amplitude of the line at `frequency_hz` in each run alone (for its interval).
pub fn amplitudes(runs: &[&RealRun], frequency_hz: f64) -> Vec<f64> {
    runs.iter()
        .filter_map(|r| {
            let psd = &r.features.incoherent_psd;
            let resolution_hz = line_resolution_hz(r.sample_rate_hz);
            let k = (frequency_hz / resolution_hz).round() as usize;
            search_range(psd.len(), resolution_hz)
                .contains(&k)
                .then(|| measure(psd, k, resolution_hz).1)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sinusoid_is_measured_by_frequency_and_amplitude() {
        use gyro_analysis::noise::psd::{welch, PsdOptions};
        let fs = 1000.0;
        let n = 60_000;
        // White noise from a fixed LCG, plus 0.2 deg/s at 37 Hz.
        let mut state = 12345u64;
        let x: Vec<f64> = (0..n)
            .map(|i| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                0.5 * u + 0.2 * (2.0 * std::f64::consts::PI * 37.0 * i as f64 / fs).sin()
            })
            .collect();
        let options = PsdOptions {
            segment_len: Some(super::super::features::line_segment_len(fs)),
            ..PsdOptions::default()
        };
        let psd = welch(&[&x], fs, &options).unwrap().psd_dps2_per_hz;
        let res = line_resolution_hz(fs);
        let (k, r) = strongest(&psd, res).unwrap();
        assert!(r > 100.0, "{r}");
        let (f, a) = measure(&psd, k, res);
        assert!((f - 37.0).abs() < res, "{f}");
        assert!((a - 0.2).abs() < 0.02, "{a}");
    }
}
