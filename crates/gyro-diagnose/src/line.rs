//! A narrow line in the residual's spectrum (`vibration`): a stepper motor, a fan or a
//! mount resonance that the gyro sees and the reference does not.
//!
//! The statistic is the **line ratio** of a bin: the pooled incoherent PSD (mean over
//! the runs of [`Features::incoherent_psd`]: the gyro's spectrum not explained by the
//! reference rate, so that a line of the motion itself, seen through a latency, is not a
//! vibration) over its local floor, the median of the bins `statistics.guard_bins` + 1 to
//! `statistics.floor_bins` away on either side. A broad mismatch of the spectrum (a noisier
//! sensor, a differentiated encoder) moves the floor with it; a sinusoid stands above it. The search runs from `statistics.min_line_hz` (below it the motion's
//! own harmonics, times any scale error, make lines of their own) to 95% of the Nyquist
//! frequency; the strongest ratio is tested against the same search on each null replica
//! (the largest ratio a nominal sensor shows by chance), so the look-elsewhere effect is
//! in the null distribution. A line must also stand `statistics.line_min_ratio` times above its
//! floor, on the training runs and again on the held-out runs.
//!
//! A sinusoid of amplitude A has power A²/2: the excess over the floor, summed over the
//! line's bins (the Hann window spreads it over ±`statistics.guard_bins`) times the bin width,
//! gives A; its frequency is the excess-weighted centroid of those bins.

use super::ensemble::{Member, RealRun};
use super::features::{line_resolution_hz, Features};
use super::fit::mean_sd;
use crate::settings::Statistics;
use gyro_analysis::median;

/// The spectrum grid a line is searched on, and the search's settings
/// (`statistics.guard_bins`, `floor_bins`, `min_line_hz`, `line_segment_s`).
#[derive(Clone, Copy, Debug)]
struct Grid {
    /// Bin width (Hz).
    resolution_hz: f64,
    /// Bins on either side of a line that belong to it (Hann main lobe).
    guard_bins: usize,
    /// Bins on either side whose median is the local floor.
    floor_bins: usize,
    /// Lowest frequency searched (Hz).
    min_line_hz: f64,
}

impl Grid {
    /// The grid of runs at `fs` Hz measured with `statistics`.
    fn of(fs: f64, statistics: &Statistics) -> Self {
        Self {
            resolution_hz: line_resolution_hz(fs, statistics.line_segment_s),
            guard_bins: statistics.guard_bins,
            floor_bins: statistics.floor_bins,
            min_line_hz: statistics.min_line_hz,
        }
    }
}

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
fn floor(psd: &[f64], k: usize, g: &Grid) -> f64 {
    if k < g.floor_bins || k + g.floor_bins >= psd.len() {
        return f64::NAN;
    }
    let around: Vec<f64> = (g.guard_bins + 1..=g.floor_bins)
        .flat_map(|d| [psd[k - d], psd[k + d]])
        .collect();
    median(&around).unwrap_or(f64::NAN)
}

/// The bins searched for a line in a spectrum of `len` bins on `g`.
fn search_range(len: usize, g: &Grid) -> std::ops::Range<usize> {
    let lo = ((g.min_line_hz / g.resolution_hz).ceil() as usize).max(g.floor_bins);
    let hi = ((0.95 * (len.saturating_sub(1)) as f64) as usize)
        .min(len.saturating_sub(g.floor_bins + 1));
    lo..hi.max(lo)
}

/// The line ratio of bin `k`.
fn ratio(psd: &[f64], k: usize, g: &Grid) -> f64 {
    psd[k] / floor(psd, k, g)
}

/// The strongest line of `psd`: (bin, ratio).
fn strongest(psd: &[f64], g: &Grid) -> Option<(usize, f64)> {
    search_range(psd.len(), g)
        .map(|k| (k, ratio(psd, k, g)))
        .filter(|(_, r)| r.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The largest line ratio within ±`guard_bins` of bin `k`.
fn ratio_near(psd: &[f64], k: usize, g: &Grid) -> f64 {
    (k.saturating_sub(g.guard_bins)..=k + g.guard_bins)
        .filter(|&i| i < psd.len())
        .map(|i| ratio(psd, i, g))
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
fn measure(psd: &[f64], k: usize, g: &Grid) -> (f64, f64) {
    let resolution_hz = g.resolution_hz;
    let base = floor(psd, k, g);
    let (mut power, mut moment) = (0.0, 0.0);
    let first = k.saturating_sub(g.guard_bins);
    let last = (k + g.guard_bins).min(psd.len() - 1);
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
    let first = runs.first()?;
    let g = Grid::of(first.sample_rate_hz, &first.statistics);
    let psd = pooled(runs.iter().map(|r| &r.features));
    let (k, ratio) = strongest(&psd, &g)?;
    let members = null.iter().map(Vec::len).min().unwrap_or(0);
    let maxima: Vec<f64> = (0..members)
        .filter_map(|j| strongest(&replica(null, j), &g).map(|x| x.1))
        .collect();
    judged(&psd, k, ratio, &maxima, &g)
}

/// The line at bin `k` of `psd`, of line ratio `ratio`, with its z-score against the
/// null replicas' values of the same statistic; `None` if either is not a number.
fn judged(psd: &[f64], k: usize, ratio: f64, null: &[f64], g: &Grid) -> Option<Line> {
    let (m0, s0) = mean_sd(null);
    if !(m0.is_finite() && ratio.is_finite()) {
        return None;
    }
    let (frequency_hz, amplitude_dps) = measure(psd, k, g);
    Some(Line {
        frequency_hz,
        amplitude_dps,
        ratio,
        z: (ratio - m0) / s0.max(1e-3 * m0),
        resolution_hz: g.resolution_hz,
    })
}

/// The line ratio of `runs` near `frequency_hz` against their `null` ensembles' ratio
/// there: the held-out replication of a line found on the training runs.
pub fn at(runs: &[&RealRun], null: &[Vec<Member>], frequency_hz: f64) -> Option<Line> {
    let first = runs.first()?;
    let g = Grid::of(first.sample_rate_hz, &first.statistics);
    let psd = pooled(runs.iter().map(|r| &r.features));
    let k = (frequency_hz / g.resolution_hz).round() as usize;
    if !search_range(psd.len(), &g).contains(&k) {
        return None;
    }
    let ratio = ratio_near(&psd, k, &g);
    let members = null.iter().map(Vec::len).min().unwrap_or(0);
    let replicas: Vec<f64> = (0..members)
        .map(|j| {
            let p = replica(null, j);
            if p.len() == psd.len() {
                ratio_near(&p, k, &g)
            } else {
                f64::NAN
            }
        })
        .collect();
    judged(&psd, k, ratio, &replicas, &g)
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

/// The strongest line of the motion of `runs` above `statistics.min_line_hz`, if it
/// stands `statistics.motion_line_ratio` times above its floor.
pub fn motion_line(runs: &[&RealRun], label: &'static str) -> Option<MotionLine> {
    let first = runs.first()?;
    let fs = first.sample_rate_hz;
    let g = Grid::of(fs, &first.statistics);
    let psd = pooled_with(runs.iter().map(|r| &r.features), |f| &f.reference_psd);
    let (k, ratio) = strongest(&psd, &g)?;
    let (frequency_hz, amplitude_dps) = measure(&psd, k, &g);
    if ratio < first.statistics.motion_line_ratio {
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
            let g = Grid::of(r.sample_rate_hz, &r.statistics);
            let k = (frequency_hz / g.resolution_hz).round() as usize;
            search_range(psd.len(), &g)
                .contains(&k)
                .then(|| measure(psd, k, &g).1)
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
            segment_len: Some(super::super::features::line_segment_len(
                fs,
                crate::Settings::DEFAULT.statistics.line_segment_s,
            )),
            ..PsdOptions::default()
        };
        let psd = welch(&[&x], fs, &options).unwrap().psd_dps2_per_hz;
        let g = Grid::of(fs, &crate::Settings::DEFAULT.statistics);
        let res = g.resolution_hz;
        let (k, r) = strongest(&psd, &g).unwrap();
        assert!(r > 100.0, "{r}");
        let (f, a) = measure(&psd, k, &g);
        assert!((f - 37.0).abs() < res, "{f}");
        assert!((a - 0.2).abs() < 0.02, "{a}");
    }
}
