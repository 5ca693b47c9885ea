//! "Where" statistics: named scalars of the residual rate per segment and stratum, and
//! their z-scores against an ensemble of simulated runs.
//!
//! Definitions (every number below is a constant of this module or a setting of
//! [`crate::settings::Statistics`], carried by [`Residuals::statistics`]):
//! - **Reference rate**: the centred difference `(θ[i+h] − θ[i−h]) / (2h·dt)` of the
//!   reference angle with `h = max(1, round(fs · W / 2))`, W =
//!   [`gyro_analysis::xcorr::SMOOTH_WINDOW_S`] ([`gyro_analysis::xcorr::centred_difference`]). This is exactly
//!   the derivative of the reference angle averaged over a boxcar of `2h` samples
//!   (≈ 20 ms), centred, so it adds no lag. Samples whose `i ± h` neighbours lack a
//!   reference (or lie outside the log) get no reference rate and are left out of every
//!   statistic.
//! - **Residual rate**: gyro rate − reference rate (deg/s); the gyro rate is not smoothed.
//! - **Segments**: `static` = runs of consecutive samples with |reference rate| <
//!   `statistics.static_rate_dps` lasting at least `statistics.static_min_s`; `dynamic` = every other
//!   sample that has a residual. The white-noise features use the static samples at
//!   rest for the gyro too ([`Residuals::is_rest`]): a board tilted on a robot sees part
//!   of the other axes' turns while this axis's reference rests.
//! - **Strata** of `dynamic`: by |reference rate| ([`RATE_BINS_DPS`], segment
//!   `dynamic/rate_<lo>_<hi>`, the last `dynamic/rate_300_inf`; a bin without samples
//!   gives no statistic), by sign (`dynamic/positive`, `dynamic/negative`). Of both
//!   `static` and `dynamic`: by temperature tercile of the run (`<seg>/temperature_1..3`,
//!   only if the log has temperatures) and by time since start in thirds of the run
//!   (`<seg>/time_1..3`).
//!
//! A statistic is keyed by its [`Segment`] and its [`Statistic`] (enums); the names below
//! are theirs as written (`Display`, and the strings of the JSON).
//!
//! Statistics (name: segment(s)):
//! - `residual_mean`, `residual_std` (deg/s): every segment and stratum with ≥ 2 samples.
//! - `slope_vs_rate` (1): least-squares slope of residual on reference rate, with
//!   intercept: `dynamic`, `dynamic/positive`, `dynamic/negative`.
//! - `low_band_slope_vs_rate` (1): the same slope with gyro and reference rate both in
//!   the low band (zero-phase Butterworth at `statistics.low_band_hz`), the sign strata by
//!   the low-band reference rate: `dynamic`, `dynamic/positive`, `dynamic/negative`. A
//!   gain read where a sensor's dynamics (a latency's phase, a roll-off above a few hertz)
//!   leave it alone: the signature of `scale_factor` and `scale_asymmetry`.
//! - `slope_vs_acceleration` (s): least-squares slope of residual on reference angular
//!   acceleration (the same centred difference, applied to the reference rate), with
//!   intercept: `dynamic`. A gyro lagging the reference by `d` gives ≈ −`d`.
//! - `cubic_vs_rate` (1/(deg/s)²), `quadratic_vs_rate` (1/(deg/s)): cubic and quadratic
//!   coefficients of a least-squares cubic polynomial of residual on reference rate:
//!   `dynamic`.
//! - `allan_log10_adev_<lo>_<hi>s` (log10 deg/s): mean log10 of the overlapping Allan
//!   deviation of the static residual (each static run its own segment, mean removed) at
//!   [`ALLAN_FACTORS_PER_BAND`] log-spaced τ in each band of [`ALLAN_BANDS_S`]: `static`.
//!   Left out when no τ of the band fits in the static runs.
//! - `lag1_autocorrelation` (1): pooled lag-1 autocorrelation of the residual, mean
//!   removed per contiguous run (whiteness; 0 for white noise): `static`, `dynamic`.
//! - `xcorr_peak_lag_s` (s): lag of the peak of the cross-correlation of gyro rate and
//!   reference rate (means removed) within ±`statistics.max_lag_s`, refined by a parabola through
//!   the peak and its neighbours; positive when the gyro lags the reference: `all`.
//! - `xcorr_lag_trend` (s/s): the slope of the lag line ([`crate::lag_line`]): the lag
//!   read window by window through the run, tracked beyond ±`statistics.max_lag_s` (a sample clock
//!   stamped by its own count lags more and more, up to seconds at 1–3%): `all`; left out
//!   when fewer than three windows have motion.
//! - `angle_error_rms_<H>s` (deg): RMS over non-overlapping windows of `H` s
//!   ([`HORIZONS_S`]) of the residual integrated over the window, after removing the
//!   static residual mean (the bias; the mean over all samples when there is no static
//!   run); windows with a sample lacking a residual are skipped: `all`.

use crate::lag_line::lag_line;
use crate::settings::Statistics;
use gyro_analysis::noise::{AllanDeviation, ONE_SIGMA};
pub use gyro_analysis::xcorr::{
    centred_difference, is_at_edge_of, smooth_half_width, xcorr_peak_lag_within, Overlap,
    MIN_SAMPLES,
};
use gyro_log::RegularLog;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;

/// Bins of |reference rate| of the dynamic samples (deg/s): `[lo, hi)`.
pub const RATE_BINS_DPS: [(f64, f64); 4] = [
    (0.0, 30.0),
    (30.0, 100.0),
    (100.0, 300.0),
    (300.0, f64::INFINITY),
];
/// τ bands of the static Allan deviation (s).
pub const ALLAN_BANDS_S: [(f64, f64); 3] = [(0.01, 0.1), (0.1, 1.0), (1.0, 10.0)];
/// Averaging factors tried per Allan band (log-spaced, duplicates dropped).
pub const ALLAN_FACTORS_PER_BAND: usize = 5;
/// Horizons of the angle error growth (s).
pub const HORIZONS_S: [f64; 3] = [1.0, 5.0, 20.0];
/// Absolute floor of the ensemble standard deviation in [`z_scores`].
pub const STD_FLOOR_ABS: f64 = 1e-12;
/// Relative floor of the ensemble standard deviation in [`z_scores`], times
/// max(|ensemble mean|, |real|).
pub const STD_FLOOR_REL: f64 = 1e-3;

/// The samples a statistic reads: a segment or a stratum of one (see the module
/// documentation). Written as its name (`Display`, and as a string in JSON): `all`,
/// `static`, `dynamic/rate_30_100`, `static/time_2`, …
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Segment {
    /// Every sample with a residual: `all`.
    All,
    /// `static`.
    Static,
    /// `dynamic`.
    Dynamic,
    /// `dynamic/rate_<lo>_<hi>`: the dynamic samples in bin `i` of [`RATE_BINS_DPS`].
    RateBin(usize),
    /// `dynamic/positive`: the reference turning positive.
    Positive,
    /// `dynamic/negative`.
    Negative,
    /// `<part>/time_<k + 1>`: third `k` (0–2) of the run.
    Time(Part, usize),
    /// `<part>/temperature_<k + 1>`: temperature tercile `k` (0–2) of the run.
    Temperature(Part, usize),
}

/// The two parts every sample with a residual falls in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Part {
    /// `static`.
    Static,
    /// `dynamic`.
    Dynamic,
}

impl Part {
    /// Both, in the order the statistics list them.
    pub const BOTH: [Part; 2] = [Part::Static, Part::Dynamic];

    fn name(self) -> &'static str {
        match self {
            Part::Static => "static",
            Part::Dynamic => "dynamic",
        }
    }
}

impl fmt::Display for Segment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Segment::All => f.write_str("all"),
            Segment::Static => f.write_str("static"),
            Segment::Dynamic => f.write_str("dynamic"),
            Segment::RateBin(b) => match RATE_BINS_DPS.get(b) {
                Some((lo, hi)) if hi.is_finite() => write!(f, "dynamic/rate_{lo}_{hi}"),
                Some((lo, _)) => write!(f, "dynamic/rate_{lo}_inf"),
                None => write!(f, "dynamic/rate_bin_{b}"),
            },
            Segment::Positive => f.write_str("dynamic/positive"),
            Segment::Negative => f.write_str("dynamic/negative"),
            Segment::Time(part, k) => write!(f, "{}/time_{}", part.name(), k + 1),
            Segment::Temperature(part, k) => write!(f, "{}/temperature_{}", part.name(), k + 1),
        }
    }
}

/// What a statistic measures (see the module documentation for each). Written as its
/// name: `residual_mean`, `allan_log10_adev_0.1_1s`, `regression_abs_rate`, …
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Statistic {
    /// `residual_mean` (deg/s).
    ResidualMean,
    /// `residual_std` (deg/s).
    ResidualStd,
    /// `slope_vs_rate` (1).
    SlopeVsRate,
    /// `low_band_slope_vs_rate` (1).
    LowBandSlopeVsRate,
    /// `slope_vs_acceleration` (s).
    SlopeVsAcceleration,
    /// `quadratic_vs_rate` (1/(deg/s)).
    QuadraticVsRate,
    /// `cubic_vs_rate` (1/(deg/s)²).
    CubicVsRate,
    /// `allan_log10_adev_<lo>_<hi>s`: band `i` of [`ALLAN_BANDS_S`].
    AllanLog10Adev(usize),
    /// `lag1_autocorrelation` (1).
    Lag1Autocorrelation,
    /// `xcorr_peak_lag_s` (s).
    XcorrPeakLag,
    /// `xcorr_lag_trend` (s/s).
    XcorrLagTrend,
    /// `angle_error_rms_<h>s` (deg): horizon `i` of [`HORIZONS_S`].
    AngleErrorRms(usize),
    /// `regression_<name>`: regressor `k` of [`crate::features::REGRESSORS`].
    Regression(usize),
    /// `wander_log10_avar_<tau>s`: τ `i` of [`crate::features::WANDER_TAUS_S`].
    WanderLog10Avar(usize),
}

impl fmt::Display for Statistic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use crate::features::{REGRESSORS, WANDER_TAUS_S};
        match *self {
            Statistic::ResidualMean => f.write_str("residual_mean"),
            Statistic::ResidualStd => f.write_str("residual_std"),
            Statistic::SlopeVsRate => f.write_str("slope_vs_rate"),
            Statistic::LowBandSlopeVsRate => f.write_str("low_band_slope_vs_rate"),
            Statistic::SlopeVsAcceleration => f.write_str("slope_vs_acceleration"),
            Statistic::QuadraticVsRate => f.write_str("quadratic_vs_rate"),
            Statistic::CubicVsRate => f.write_str("cubic_vs_rate"),
            Statistic::AllanLog10Adev(i) => match ALLAN_BANDS_S.get(i) {
                Some((lo, hi)) => write!(f, "allan_log10_adev_{lo}_{hi}s"),
                None => write!(f, "allan_log10_adev_band_{i}"),
            },
            Statistic::Lag1Autocorrelation => f.write_str("lag1_autocorrelation"),
            Statistic::XcorrPeakLag => f.write_str("xcorr_peak_lag_s"),
            Statistic::XcorrLagTrend => f.write_str("xcorr_lag_trend"),
            Statistic::AngleErrorRms(i) => match HORIZONS_S.get(i) {
                Some(h) => write!(f, "angle_error_rms_{h}s"),
                None => write!(f, "angle_error_rms_horizon_{i}"),
            },
            Statistic::Regression(k) => match REGRESSORS.get(k) {
                Some(name) => write!(f, "regression_{name}"),
                None => write!(f, "regression_{k}"),
            },
            Statistic::WanderLog10Avar(i) => match WANDER_TAUS_S.get(i) {
                Some(tau) => write!(f, "wander_log10_avar_{tau}s"),
                None => write!(f, "wander_log10_avar_tau_{i}"),
            },
        }
    }
}

/// Written as their names in JSON (the contract of `docs/diagnose-json.md`).
macro_rules! serialize_as_name {
    ($($t:ty),*) => {$(
        impl Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.collect_str(self)
            }
        }
    )*};
}
serialize_as_name!(Segment, Statistic);

/// One scalar statistic of one segment or stratum.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stat {
    /// Segment or stratum, e.g. `static`, `dynamic/rate_30_100`, `all`.
    pub segment: Segment,
    /// Statistic, e.g. `residual_mean`, `slope_vs_rate`.
    pub statistic: Statistic,
    /// Value (units depend on the statistic; see the module documentation).
    pub value: f64,
}

impl Stat {
    /// Whether it is `statistic` of `segment`.
    pub fn is(&self, segment: Segment, statistic: Statistic) -> bool {
        self.segment == segment && self.statistic == statistic
    }
}

/// Why the statistics cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum StatsError {
    /// The log has no reference angle.
    NoReference,
    /// Fewer samples with a residual than needed (the count found).
    TooShort(usize),
}

impl fmt::Display for StatsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StatsError::NoReference => write!(f, "the log has no reference angle"),
            StatsError::TooShort(n) => {
                write!(f, "only {n} samples have a residual rate; too few")
            }
        }
    }
}

impl std::error::Error for StatsError {}

/// The residual rate of a log, sample by sample (NaN where undefined).
#[derive(Clone, Debug, PartialEq)]
pub struct Residuals {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Time since the first slot (s).
    pub time_s: Vec<f64>,
    /// Gyro rate (deg/s).
    pub rate_dps: Vec<f64>,
    /// Reference rate (deg/s), NaN where undefined.
    pub reference_rate_dps: Vec<f64>,
    /// Reference angular acceleration (deg/s²), NaN where undefined.
    pub reference_acceleration_dps2: Vec<f64>,
    /// Gyro − reference rate (deg/s), NaN where undefined.
    pub residual_dps: Vec<f64>,
    /// Temperature (°C), NaN where absent.
    pub temperature_c: Vec<f64>,
    /// Whether the sample belongs to the static segment.
    pub is_static: Vec<bool>,
    /// Whether the sample is at rest for the gyro too: static, and the residual's mean
    /// over `statistics.gyro_still_window_s` within `statistics.static_rate_dps` of its median over the
    /// reference's rest, for at least `statistics.static_min_s` once `statistics.rest_edge_s` is left out
    /// at each end (the white-noise statistics).
    pub is_rest: Vec<bool>,
    /// Gyro rate in the low band (deg/s; [`super::low_band`]), NaN where the reference
    /// rate is undefined or the rate is too low for a low band.
    pub low_rate_dps: Vec<f64>,
    /// Reference rate in the low band (deg/s), filtered on the same stretches.
    pub low_reference_rate_dps: Vec<f64>,
    /// The settings these residuals were segmented with, and which their statistics and
    /// features read (a real run and its simulations share them).
    pub statistics: Statistics,
}

/// The gain of the reference rate's centred difference at `frequency_hz` (a boxcar of
/// `2h` samples: `sin(π f 2h / fs) / (π f 2h / fs)`, no phase). At 100 Hz (h = 1) it
/// passes 0.90 of a 12.8 Hz line and 0.22 of a 40 Hz one: a response read against the
/// reference rate is divided by it.
pub fn reference_rate_gain(sample_rate_hz: f64, frequency_hz: f64) -> f64 {
    let h = smooth_half_width(sample_rate_hz) as f64;
    let x = std::f64::consts::PI * frequency_hz * 2.0 * h / sample_rate_hz;
    if x.abs() < 1e-12 {
        1.0
    } else {
        x.sin() / x
    }
}

/// Residual rate and static/dynamic segmentation of `log` (see the module documentation).
pub fn residuals(log: &RegularLog, statistics: &Statistics) -> Result<Residuals, StatsError> {
    if !log.has_reference {
        return Err(StatsError::NoReference);
    }
    let t0 = log.slots.first().map_or(0.0, |s| s.time_s);
    let reference: Vec<f64> = log
        .slots
        .iter()
        .map(|s| s.reference_deg.unwrap_or(f64::NAN))
        .collect();
    let rate: Vec<f64> = log.slots.iter().map(|s| s.rate_dps).collect();
    let temperature: Vec<f64> = log
        .slots
        .iter()
        .map(|s| s.temperature_c.unwrap_or(f64::NAN))
        .collect();
    let time_s = log.slots.iter().map(|s| s.time_s - t0).collect();
    residuals_of(
        log.sample_rate_hz,
        time_s,
        rate,
        &reference,
        temperature,
        statistics,
    )
}

/// [`residuals`] of columns on a regular grid at `fs` (NaN where a reference is absent).
pub fn residuals_of(
    fs: f64,
    time_s: Vec<f64>,
    rate_dps: Vec<f64>,
    reference_deg: &[f64],
    temperature_c: Vec<f64>,
    statistics: &Statistics,
) -> Result<Residuals, StatsError> {
    let n = rate_dps.len();
    let reference_rate_dps = centred_difference(reference_deg, fs);
    let reference_acceleration_dps2 = centred_difference(&reference_rate_dps, fs);
    let residual_dps: Vec<f64> = rate_dps
        .iter()
        .zip(&reference_rate_dps)
        .map(|(g, r)| g - r)
        .collect();
    let valid = residual_dps.iter().filter(|r| r.is_finite()).count();
    if valid < MIN_SAMPLES {
        return Err(StatsError::TooShort(valid));
    }
    let still: Vec<bool> = reference_rate_dps
        .iter()
        .map(|r| r.abs() < statistics.static_rate_dps)
        .collect();
    let min_len = ((statistics.static_min_s * fs).ceil() as usize).max(1);
    let mut is_static = vec![false; n];
    let mut is_rest = vec![false; n];
    for run in runs(&still) {
        if run.len() < min_len {
            continue;
        }
        is_static[run.clone()].iter_mut().for_each(|s| *s = true);
        let gyro_still = gyro_still(&residual_dps[run.clone()], fs, statistics);
        let edge = (statistics.rest_edge_s * fs).round() as usize;
        for part in runs(&gyro_still) {
            if part.len() >= min_len + 2 * edge {
                let part = run.start + part.start + edge..run.start + part.end - edge;
                is_rest[part].iter_mut().for_each(|s| *s = true);
            }
        }
    }
    let (low_rate_dps, low_reference_rate_dps) =
        match super::low_band::cutoff_hz(fs, statistics.low_band_hz) {
            Some(cutoff) => {
                let both = |i: usize| rate_dps[i].is_finite() && reference_rate_dps[i].is_finite();
                (
                    super::low_band::zero_phase(&rate_dps, fs, cutoff, both),
                    super::low_band::zero_phase(&reference_rate_dps, fs, cutoff, both),
                )
            }
            None => (vec![f64::NAN; n], vec![f64::NAN; n]),
        };
    Ok(Residuals {
        sample_rate_hz: fs,
        time_s,
        rate_dps,
        reference_rate_dps,
        reference_acceleration_dps2,
        residual_dps,
        temperature_c,
        is_static,
        is_rest,
        low_rate_dps,
        low_reference_rate_dps,
        statistics: *statistics,
    })
}

/// Maximal runs of consecutive `true`.
/// Per sample of a still reference's run, given the residual there (the gyro less the
/// reference rate, so that the reference's own slow edges of a turn are not counted): its
/// mean over `statistics.gyro_still_window_s` (centred, inside the run, finite samples only) is
/// within `statistics.static_rate_dps` of its median over the run. A sample whose window holds no
/// finite value shows no motion and counts as still.
fn gyro_still(rate_dps: &[f64], fs: f64, statistics: &Statistics) -> Vec<bool> {
    let mut finite: Vec<f64> = rate_dps.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return vec![true; rate_dps.len()];
    }
    finite.sort_by(f64::total_cmp);
    let median = finite[finite.len() / 2];
    let half = ((statistics.gyro_still_window_s * fs / 2.0).round() as usize).max(1);
    // Prefix sums of the finite values and of their count.
    let mut sum = vec![0.0; rate_dps.len() + 1];
    let mut count = vec![0usize; rate_dps.len() + 1];
    for (i, v) in rate_dps.iter().enumerate() {
        let ok = v.is_finite();
        sum[i + 1] = sum[i] + if ok { v - median } else { 0.0 };
        count[i + 1] = count[i] + usize::from(ok);
    }
    (0..rate_dps.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(rate_dps.len()));
            let k = count[hi] - count[lo];
            k == 0 || ((sum[hi] - sum[lo]) / k as f64).abs() < statistics.static_rate_dps
        })
        .collect()
}

fn runs(mask: &[bool]) -> Vec<std::ops::Range<usize>> {
    stretches(mask.len(), |i| mask[i])
}

/// Maximal runs of consecutive indices below `n` for which `ok` holds.
pub fn stretches(n: usize, ok: impl Fn(usize) -> bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for i in 0..n {
        match (ok(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(s..n);
    }
    out
}

/// The "where" statistics of `log` (see the module documentation).
#[cfg(test)]
pub fn where_stats(log: &RegularLog) -> Result<Vec<Stat>, StatsError> {
    Ok(stats_of(&residuals(
        log,
        &crate::Settings::DEFAULT.statistics,
    )?))
}

/// Statistics collector.
struct Out(Vec<Stat>);

impl Out {
    fn push(&mut self, segment: Segment, statistic: Statistic, value: f64) {
        if value.is_finite() {
            self.0.push(Stat {
                segment,
                statistic,
                value,
            });
        }
    }
}

fn mean_std(values: &[f64]) -> Option<(f64, f64)> {
    if values.len() < 2 {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    Some((mean, var.sqrt()))
}

/// Least-squares slope of y on x with intercept.
fn slope(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (x, y) in points {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
    }
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Solve `a x = b` (small, dense) by Gaussian elimination with partial pivoting.
pub(crate) fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col];
        for row in col + 1..N {
            let f = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let s: f64 = (row + 1..N).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// Quadratic and cubic coefficients of the least-squares cubic of y on x.
fn cubic(points: &[(f64, f64)]) -> Option<[f64; 2]> {
    if points.len() < 5 {
        return None;
    }
    // Scale x for conditioning.
    let scale = points.iter().map(|p| p.0.abs()).fold(0.0, f64::max);
    if scale <= 0.0 {
        return None;
    }
    let mut a = [[0.0; 4]; 4];
    let mut b = [0.0; 4];
    for (x, y) in points {
        let u = x / scale;
        let powers = [1.0, u, u * u, u * u * u];
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] += powers[i] * powers[j];
            }
            b[i] += powers[i] * y;
        }
    }
    solve(a, b).map(|c| [c[2] / (scale * scale), c[3] / (scale * scale * scale)])
}

/// Pooled lag-1 autocorrelation over `runs` of `x`, mean removed per run.
fn lag1(x: &[f64], runs: &[std::ops::Range<usize>]) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for run in runs {
        let seg = &x[run.clone()];
        if seg.len() < 2 {
            continue;
        }
        let mean = seg.iter().sum::<f64>() / seg.len() as f64;
        for w in seg.windows(2) {
            num += (w[0] - mean) * (w[1] - mean);
        }
        den += seg.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>();
    }
    (den > 0.0).then(|| num / den)
}

/// The lag of `stats`' cross-correlation peak (`all`/`xcorr_peak_lag_s`, at sample rate
/// `fs`) when it sits on the edge of the search (±`statistics.max_lag_s`): then the true lag is at
/// least that, and the value is cut, not measured.
pub fn lag_at_search_edge(stats: &[Stat], fs: f64, max_lag_s: f64) -> Option<f64> {
    stats
        .iter()
        .find(|s| s.is(Segment::All, Statistic::XcorrPeakLag))
        .map(|s| s.value)
        .filter(|v| is_at_search_edge(*v, fs, max_lag_s))
}

/// True if a cross-correlation peak lag `lag_s` (at sample rate `fs`) sits on the edge of
/// the search, ±`statistics.max_lag_s` rounded to whole samples: the true lag is at least that.
pub fn is_at_search_edge(lag_s: f64, fs: f64, max_lag_s: f64) -> bool {
    is_at_edge_of(lag_s, fs, max_lag_s)
}

/// [`xcorr_peak_lag_within`] ±`statistics.max_lag_s`, normalised by the overlap.
fn xcorr_peak_lag(gyro: &[f64], reference: &[f64], fs: f64, max_lag_s: f64) -> Option<f64> {
    xcorr_peak_lag_within(gyro, reference, fs, max_lag_s, Overlap::Divide)
}

/// Averaging factors for the Allan bands at `fs`.
fn allan_factors(fs: f64) -> Vec<usize> {
    let mut factors: Vec<usize> = ALLAN_BANDS_S
        .iter()
        .flat_map(|&(lo, hi)| {
            let (a, b) = ((lo * fs).max(1.0), hi * fs);
            (0..ALLAN_FACTORS_PER_BAND).map(move |i| {
                let f = i as f64 / (ALLAN_FACTORS_PER_BAND - 1).max(1) as f64;
                (a * (b / a).powf(f)).round() as usize
            })
        })
        .filter(|&m| m >= 1)
        .collect();
    factors.sort_unstable();
    factors.dedup();
    factors
}

/// Running mean and sum of squared deviations (Welford).
#[derive(Clone, Copy, Default)]
struct Welford {
    n: usize,
    mean: f64,
    m2: f64,
}

impl Welford {
    fn add(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    /// Mean and sample standard deviation (n − 1), from 2 values on.
    fn mean_std(&self) -> Option<(f64, f64)> {
        (self.n >= 2).then(|| (self.mean, (self.m2 / (self.n - 1) as f64).max(0.0).sqrt()))
    }
}

/// Welford accumulators of the residual for every segment and stratum, filled in one pass
/// over the samples.
#[derive(Default)]
struct Moments {
    all: Welford,
    /// Static, dynamic.
    parts: [Welford; 2],
    rate_bins: [Welford; RATE_BINS_DPS.len()],
    positive: Welford,
    negative: Welford,
    /// Per part, per third of the run.
    time: [[Welford; 3]; 2],
    /// Per part, per temperature tercile.
    temperature: [[Welford; 3]; 2],
}

impl Part {
    /// The segment of all its samples.
    fn segment(self) -> Segment {
        match self {
            Part::Static => Segment::Static,
            Part::Dynamic => Segment::Dynamic,
        }
    }

    fn index(self) -> usize {
        match self {
            Part::Static => 0,
            Part::Dynamic => 1,
        }
    }
}

impl Moments {
    /// The segments, in the order their statistics are listed; the temperature terciles
    /// only when the run has temperatures.
    fn segments(temperature: bool) -> Vec<Segment> {
        let mut out = vec![Segment::All, Segment::Static, Segment::Dynamic];
        out.extend((0..RATE_BINS_DPS.len()).map(Segment::RateBin));
        out.extend([Segment::Positive, Segment::Negative]);
        for part in Part::BOTH {
            for k in 0..3 {
                out.push(Segment::Time(part, k));
                if temperature {
                    out.push(Segment::Temperature(part, k));
                }
            }
        }
        out
    }

    fn get(&self, segment: Segment) -> Option<&Welford> {
        Some(match segment {
            Segment::All => &self.all,
            Segment::Static => &self.parts[0],
            Segment::Dynamic => &self.parts[1],
            Segment::RateBin(b) => self.rate_bins.get(b)?,
            Segment::Positive => &self.positive,
            Segment::Negative => &self.negative,
            Segment::Time(part, k) => self.time[part.index()].get(k)?,
            Segment::Temperature(part, k) => self.temperature[part.index()].get(k)?,
        })
    }

    fn get_mut(&mut self, segment: Segment) -> Option<&mut Welford> {
        Some(match segment {
            Segment::All => &mut self.all,
            Segment::Static => &mut self.parts[0],
            Segment::Dynamic => &mut self.parts[1],
            Segment::RateBin(b) => self.rate_bins.get_mut(b)?,
            Segment::Positive => &mut self.positive,
            Segment::Negative => &mut self.negative,
            Segment::Time(part, k) => self.time[part.index()].get_mut(k)?,
            Segment::Temperature(part, k) => self.temperature[part.index()].get_mut(k)?,
        })
    }
}

/// Tercile thresholds of the finite values.
fn terciles(values: &[f64]) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.len() < 3 {
        return None;
    }
    let (i, j) = (v.len() / 3, 2 * v.len() / 3);
    let a = *v.select_nth_unstable_by(i, f64::total_cmp).1;
    let b = *v.select_nth_unstable_by(j, f64::total_cmp).1;
    Some((a, b))
}

/// The "where" statistics of `residuals` (see the module documentation).
pub fn stats_of(r: &Residuals) -> Vec<Stat> {
    let n = r.residual_dps.len();
    let valid: Vec<bool> = r.residual_dps.iter().map(|x| x.is_finite()).collect();
    let dynamic: Vec<bool> = (0..n).map(|i| valid[i] && !r.is_static[i]).collect();
    let mut out = Out(Vec::new());

    let (moments, temp_cuts) = segment_moments(r, &valid);
    for segment in Moments::segments(temp_cuts.is_some()) {
        if let Some((mean, std)) = moments.get(segment).and_then(Welford::mean_std) {
            out.push(segment, Statistic::ResidualMean, mean);
            out.push(segment, Statistic::ResidualStd, std);
        }
    }
    push_rate_shape(r, &dynamic, &mut out);
    let static_runs: Vec<_> = runs(&r.is_static);
    push_static_allan(r, &static_runs, &mut out);
    push_whiteness(r, &static_runs, &dynamic, &mut out);
    push_angle_error_growth(r, &moments, &mut out);
    out.0
}

/// Moments of every segment and stratum of the `valid` residuals of `r`, in one pass, and
/// the temperature's tercile thresholds (None: no temperature strata).
fn segment_moments(r: &Residuals, valid: &[bool]) -> (Moments, Option<(f64, f64)>) {
    // Moments of every segment and stratum in one pass.
    let mut moments = Moments::default();
    let tercile = |x: f64, (a, b): (f64, f64)| -> usize {
        if x < a {
            0
        } else if x < b {
            1
        } else {
            2
        }
    };
    let duration = r
        .time_s
        .last()
        .copied()
        .unwrap_or(0.0)
        .max(f64::MIN_POSITIVE);
    let third = |i: usize| ((3.0 * r.time_s[i] / duration).floor() as usize).min(2);
    let temp_cuts = terciles(&r.temperature_c);
    for (i, &ok) in valid.iter().enumerate() {
        if !ok {
            continue;
        }
        let x = r.residual_dps[i];
        let mut add = |segment: Segment| {
            if let Some(a) = moments.get_mut(segment) {
                a.add(x);
            }
        };
        add(Segment::All);
        let part = if r.is_static[i] {
            Part::Static
        } else {
            Part::Dynamic
        };
        add(part.segment());
        if part == Part::Dynamic {
            let w = r.reference_rate_dps[i];
            let a = w.abs();
            if let Some(b) = RATE_BINS_DPS.iter().position(|&(lo, hi)| a >= lo && a < hi) {
                add(Segment::RateBin(b));
            }
            if w > 0.0 {
                add(Segment::Positive);
            } else if w < 0.0 {
                add(Segment::Negative);
            }
        }
        add(Segment::Time(part, third(i)));
        if let Some(cuts) = temp_cuts {
            let t = r.temperature_c[i];
            if t.is_finite() {
                add(Segment::Temperature(part, tercile(t, cuts)));
            }
        }
    }
    (moments, temp_cuts)
}

/// The residual against rate and acceleration on the `dynamic` samples: slopes in the
/// full band (all, positive, negative rates), in the low band, against acceleration, and
/// the quadratic and cubic terms.
fn push_rate_shape(r: &Residuals, dynamic: &[bool], out: &mut Out) {
    let n = r.residual_dps.len();
    // Residual against rate, in motion.
    let points = |keep: &dyn Fn(f64) -> bool| -> Vec<(f64, f64)> {
        (0..n)
            .filter(|&i| dynamic[i] && keep(r.reference_rate_dps[i]))
            .map(|i| (r.reference_rate_dps[i], r.residual_dps[i]))
            .collect()
    };
    let all_points = points(&|_| true);
    if let Some(s) = slope(&all_points) {
        out.push(Segment::Dynamic, Statistic::SlopeVsRate, s);
    }
    if let Some(s) = slope(&points(&|x| x > 0.0)) {
        out.push(Segment::Positive, Statistic::SlopeVsRate, s);
    }
    if let Some(s) = slope(&points(&|x| x < 0.0)) {
        out.push(Segment::Negative, Statistic::SlopeVsRate, s);
    }
    // The same in the low band, where a gain is read (`low_band`).
    let low_points = |keep: &dyn Fn(f64) -> bool| -> Vec<(f64, f64)> {
        (0..n)
            .filter(|&i| dynamic[i])
            .map(|i| (r.low_reference_rate_dps[i], r.low_rate_dps[i]))
            .filter(|(w, g)| w.is_finite() && g.is_finite() && keep(*w))
            .map(|(w, g)| (w, g - w))
            .collect()
    };
    for (segment, keep) in [
        (Segment::Dynamic, &(|_| true) as &dyn Fn(f64) -> bool),
        (Segment::Positive, &|w| w > 0.0),
        (Segment::Negative, &|w| w < 0.0),
    ] {
        if let Some(s) = slope(&low_points(keep)) {
            out.push(segment, Statistic::LowBandSlopeVsRate, s);
        }
    }
    let accel_points: Vec<(f64, f64)> = (0..n)
        .filter(|&i| dynamic[i] && r.reference_acceleration_dps2[i].is_finite())
        .map(|i| (r.reference_acceleration_dps2[i], r.residual_dps[i]))
        .collect();
    if let Some(s) = slope(&accel_points) {
        out.push(Segment::Dynamic, Statistic::SlopeVsAcceleration, s);
    }
    if let Some([c2, c3]) = cubic(&all_points) {
        out.push(Segment::Dynamic, Statistic::QuadraticVsRate, c2);
        out.push(Segment::Dynamic, Statistic::CubicVsRate, c3);
    }
}

/// The static residual's Allan deviation over the `static_runs`: the mean log10 deviation
/// in each τ band of [`ALLAN_BANDS_S`].
fn push_static_allan(r: &Residuals, static_runs: &[std::ops::Range<usize>], out: &mut Out) {
    let fs = r.sample_rate_hz;
    // Static Allan deviation per τ band.
    let segments: Vec<&[f64]> = static_runs
        .iter()
        .map(|run| &r.residual_dps[run.clone()])
        .collect();
    if !segments.is_empty() {
        let allan = AllanDeviation::compute(&segments, fs, &allan_factors(fs), ONE_SIGMA);
        for (band, (lo, hi)) in ALLAN_BANDS_S.into_iter().enumerate() {
            let logs: Vec<f64> = allan
                .points
                .iter()
                .filter(|p| p.tau_s >= lo * (1.0 - 1e-9) && p.tau_s <= hi * (1.0 + 1e-9))
                .filter(|p| p.adev_dps > 0.0)
                .map(|p| p.adev_dps.log10())
                .collect();
            if !logs.is_empty() {
                let mean = logs.iter().sum::<f64>() / logs.len() as f64;
                out.push(Segment::Static, Statistic::AllanLog10Adev(band), mean);
            }
        }
    }
}

/// Whiteness and timing: the residual's lag-1 autocorrelation at rest and in motion, and
/// the gyro-reference cross-correlation's peak lag (s) and its trend over the run.
fn push_whiteness(
    r: &Residuals,
    static_runs: &[std::ops::Range<usize>],
    dynamic: &[bool],
    out: &mut Out,
) {
    let fs = r.sample_rate_hz;
    // Whiteness.
    if let Some(a) = lag1(&r.residual_dps, static_runs) {
        out.push(Segment::Static, Statistic::Lag1Autocorrelation, a);
    }
    if let Some(a) = lag1(&r.residual_dps, &runs(dynamic)) {
        out.push(Segment::Dynamic, Statistic::Lag1Autocorrelation, a);
    }
    if let Some(lag) = xcorr_peak_lag(
        &r.rate_dps,
        &r.reference_rate_dps,
        fs,
        r.statistics.max_lag_s,
    ) {
        out.push(Segment::All, Statistic::XcorrPeakLag, lag);
    }
    if let Some(line) = lag_line(&r.rate_dps, &r.reference_rate_dps, fs, &r.statistics) {
        out.push(Segment::All, Statistic::XcorrLagTrend, line.slope);
    }
}

/// Angle error growth: the RMS of the bias-free residual integrated over windows of each
/// of [`HORIZONS_S`] (deg), the bias the static mean (else the mean of every sample).
fn push_angle_error_growth(r: &Residuals, moments: &Moments, out: &mut Out) {
    let fs = r.sample_rate_hz;
    // Angle error growth.
    let bias = moments
        .get(Segment::Static)
        .and_then(Welford::mean_std)
        .or_else(|| moments.get(Segment::All).and_then(Welford::mean_std))
        .map_or(0.0, |(m, _)| m);
    for (horizon, h) in HORIZONS_S.into_iter().enumerate() {
        let len = (h * fs).round() as usize;
        if len == 0 {
            continue;
        }
        let errors: Vec<f64> = r
            .residual_dps
            .chunks_exact(len)
            .filter(|w| w.iter().all(|x| x.is_finite()))
            .map(|w| w.iter().map(|x| x - bias).sum::<f64>() / fs)
            .collect();
        if !errors.is_empty() {
            let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
            out.push(Segment::All, Statistic::AngleErrorRms(horizon), rms);
        }
    }
}

/// Z-score of each `real` statistic against the `ensemble` (one `Vec<Stat>` per simulated
/// run), matched by (segment, statistic): `z = (real − mean) / std`, with the sample
/// standard deviation (n − 1) of the ensemble values.
///
/// Explicit cases:
/// - fewer than 2 ensemble runs have the statistic: z is NaN (no reference to compare to);
/// - the std is floored at max([`STD_FLOOR_ABS`], [`STD_FLOOR_REL`] · max(|mean|, |real|)),
///   so a statistic constant over the ensemble gives z = 0 when real equals it and a large
///   but finite z otherwise.
pub fn z_scores(real: &[Stat], ensemble: &[Vec<Stat>]) -> Vec<(Stat, f64)> {
    let mut values: BTreeMap<(Segment, Statistic), Vec<f64>> = BTreeMap::new();
    for run in ensemble {
        for s in run {
            if s.value.is_finite() {
                values
                    .entry((s.segment, s.statistic))
                    .or_default()
                    .push(s.value);
            }
        }
    }
    real.iter()
        .map(|s| {
            let z = match values
                .get(&(s.segment, s.statistic))
                .and_then(|v| mean_std(v))
            {
                None => f64::NAN,
                Some((mean, std)) => {
                    let floor = STD_FLOOR_ABS.max(STD_FLOOR_REL * mean.abs().max(s.value.abs()));
                    (s.value - mean) / std.max(floor)
                }
            };
            (s.clone(), z)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyro_log::{regularize, GridOptions};
    use gyro_sim::{simulate, BenchProfile, Effect, Motion, SensorModel, SimOptions};

    const FS: f64 = 200.0;
    const MAX_LAG_S: f64 = crate::Settings::DEFAULT.statistics.max_lag_s;

    fn run(effects: &[Effect], seed: u64) -> Vec<Stat> {
        let model = SensorModel {
            sample_rate_hz: FS,
            ..SensorModel::default()
        };
        let motion = Motion::bench(&BenchProfile::default(), 7);
        let options = SimOptions {
            seed,
            ..SimOptions::default()
        };
        let log = simulate(&model, effects, &motion, &options);
        let regular = regularize(&log, &GridOptions::default()).unwrap();
        where_stats(&regular).unwrap()
    }

    fn get(stats: &[Stat], segment: &str, statistic: &str) -> f64 {
        stats
            .iter()
            .find(|s| s.segment.to_string() == segment && s.statistic.to_string() == statistic)
            .map(|s| s.value)
            .unwrap_or_else(|| panic!("missing {segment} {statistic}"))
    }

    /// A reference at rest for 6 s while the gyro sees a 5 °/s turn for 1 s in the
    /// middle (a tilted board on a robot turning another axis): the turn is not a rest
    /// for the white-noise features, the rests on each side are; a lost gyro sample at
    /// rest does not split a rest.
    #[test]
    fn a_turn_the_reference_does_not_see_is_not_rest() {
        let fs = 100.0;
        let n = 600;
        let mut rate: Vec<f64> = (0..n)
            .map(|i| 0.3 + if (250..350).contains(&i) { 5.0 } else { 0.0 })
            .collect();
        rate[100] = f64::NAN;
        let time_s = (0..n).map(|i| i as f64 / fs).collect();
        let r = residuals_of(
            fs,
            time_s,
            rate,
            &vec![10.0; n],
            vec![f64::NAN; n],
            &crate::Settings::DEFAULT.statistics,
        )
        .unwrap();
        let h = smooth_half_width(fs);
        // The 70 ms mean (±3 samples) leaves the rest 2 samples into the turn's window;
        // 10 samples (0.1 s) are left out at each end of a rest.
        let rest = |range: std::ops::Range<usize>| r.is_rest[range].iter().all(|s| *s);
        assert!(rest(h + 10..238) && rest(362..n - h - 10));
        assert!(r.is_rest[238..362].iter().all(|s| !*s));
        assert!(!r.is_rest[h + 9] && !r.is_rest[n - h - 10]);
        // The static segment is the reference's rest.
        assert!(r.is_static[h..n - h].iter().all(|s| *s));
        // Without the turn, the whole reference rest is static, as before.
        let rate = vec![0.3; n];
        let time_s = (0..n).map(|i| i as f64 / fs).collect();
        let r = residuals_of(
            fs,
            time_s,
            rate,
            &vec![10.0; n],
            vec![f64::NAN; n],
            &crate::Settings::DEFAULT.statistics,
        )
        .unwrap();
        assert!(r.is_rest[h + 10..n - h - 10].iter().all(|s| *s));
    }

    #[test]
    fn nominal_statistics_are_present_and_finite() {
        let stats = run(&[], 1);
        assert!(stats.iter().all(|s| s.value.is_finite()));
        for (seg, stat) in [
            ("static", "residual_mean"),
            ("dynamic", "residual_std"),
            ("dynamic/rate_0_30", "residual_mean"),
            ("dynamic/positive", "residual_mean"),
            ("static/temperature_3", "residual_mean"),
            ("dynamic/time_2", "residual_std"),
            ("dynamic", "slope_vs_rate"),
            ("dynamic/negative", "slope_vs_rate"),
            ("dynamic", "cubic_vs_rate"),
            ("static", "allan_log10_adev_0.01_0.1s"),
            ("static", "allan_log10_adev_1_10s"),
            ("static", "lag1_autocorrelation"),
            ("all", "xcorr_peak_lag_s"),
            ("all", "angle_error_rms_20s"),
        ] {
            get(&stats, seg, stat);
        }
        // Static mean ≈ nominal bias 0.3 °/s (plus a Gauss-Markov draw of σ 0.05).
        assert!((get(&stats, "static", "residual_mean") - 0.3).abs() < 0.2);
        // White static residual.
        assert!(get(&stats, "static", "lag1_autocorrelation").abs() < 0.1);
    }

    #[test]
    fn the_reference_differentiator_passes_a_sinc() {
        // h = 1 at 100 Hz: sin(π f 0.02) / (π f 0.02).
        assert!((reference_rate_gain(100.0, 12.8) - 0.8956).abs() < 1e-4);
        assert!((reference_rate_gain(100.0, 40.5) - 0.2209).abs() < 1e-4);
        assert_eq!(reference_rate_gain(1000.0, 0.0), 1.0);
        // 1 kHz: h = 10, a 20 ms boxcar, zero at 50 Hz.
        assert!(reference_rate_gain(1000.0, 50.0).abs() < 1e-12);
    }

    #[test]
    fn slope_recovers_scale_factor() {
        let nominal = get(&run(&[], 1), "dynamic", "slope_vs_rate");
        assert!(nominal.abs() < 2e-3, "nominal slope {nominal}");
        let scaled = run(&[Effect::ScaleFactor { k: 0.01 }], 1);
        for seg in ["dynamic", "dynamic/positive", "dynamic/negative"] {
            let s = get(&scaled, seg, "slope_vs_rate");
            assert!((s - 0.01).abs() < 2e-3, "{seg} slope {s}");
        }
        // Asymmetry: the sign strata see opposite slopes.
        let asym = run(&[Effect::ScaleAsymmetry { k: 0.01 }], 1);
        let (pos, neg) = (
            get(&asym, "dynamic/positive", "slope_vs_rate"),
            get(&asym, "dynamic/negative", "slope_vs_rate"),
        );
        assert!((pos - 0.01).abs() < 2e-3, "positive slope {pos}");
        assert!((neg + 0.01).abs() < 2e-3, "negative slope {neg}");
    }

    #[test]
    fn lag_detects_latency() {
        let nominal = get(&run(&[], 1), "all", "xcorr_peak_lag_s");
        assert!(nominal.abs() < 2e-3, "nominal lag {nominal}");
        let nominal = get(&run(&[], 1), "dynamic", "slope_vs_acceleration");
        assert!(nominal.abs() < 1e-3, "nominal acceleration slope {nominal}");
        let late = run(&[Effect::Latency { delay_s: 0.01 }], 1);
        let lag = get(&late, "all", "xcorr_peak_lag_s");
        assert!((lag - 0.01).abs() < 3e-3, "lag {lag}");
        let slope = get(&late, "dynamic", "slope_vs_acceleration");
        assert!((slope + 0.01).abs() < 1e-3, "acceleration slope {slope}");
        // A lag beyond the search is cut at its edge, and said to be.
        assert_eq!(lag_at_search_edge(&late, 1000.0, MAX_LAG_S), None);
        let beyond = run(&[Effect::Latency { delay_s: 0.1 }], 1);
        let cut = lag_at_search_edge(&beyond, 1000.0, MAX_LAG_S);
        assert_eq!(
            cut,
            Some(MAX_LAG_S),
            "{:?}",
            get(&beyond, "all", "xcorr_peak_lag_s")
        );
        // The lag's trend is tracked beyond the search: a constant delay is flat.
        for lagging in [&late, &beyond] {
            let trend = get(lagging, "all", "xcorr_lag_trend");
            assert!(trend.abs() < 1e-4, "trend {trend}");
        }
    }

    #[test]
    fn z_scores_against_nominal_ensemble() {
        let ensemble: Vec<Vec<Stat>> = (100..120).map(|seed| run(&[], seed)).collect();
        let z = z_scores(&run(&[], 1), &ensemble);
        assert!(z.len() > 30);
        let within = z.iter().filter(|(_, z)| z.abs() < 3.0).count();
        assert!(
            within as f64 >= 0.9 * z.len() as f64,
            "{within} of {} within 3: {:?}",
            z.len(),
            z.iter().filter(|(_, z)| z.abs() >= 3.0).collect::<Vec<_>>()
        );
        let z = z_scores(&run(&[Effect::ScaleFactor { k: 0.01 }], 1), &ensemble);
        let slope = z
            .iter()
            .find(|(s, _)| s.is(Segment::Dynamic, Statistic::SlopeVsRate))
            .unwrap();
        assert!(slope.1.abs() > 5.0, "slope z {}", slope.1);
    }

    #[test]
    fn z_scores_explicit_cases() {
        let stat = |segment: Segment, value: f64| Stat {
            segment,
            statistic: Statistic::ResidualMean,
            value,
        };
        let (a, b, c) = (Segment::All, Segment::Static, Segment::Dynamic);
        let ensemble = vec![
            vec![stat(a, 1.0), stat(c, 2.0)],
            vec![stat(a, 3.0), stat(c, 2.0)],
        ];
        let z = z_scores(
            &[stat(a, 4.0), stat(b, 1.0), stat(c, 2.0), stat(c, 3.0)],
            &ensemble,
        );
        // mean 2, std √2.
        assert!((z[0].1 - 2.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!(z[1].1.is_nan());
        assert_eq!(z[2].1, 0.0);
        // Floor 1e-3 · 3.
        assert!((z[3].1 - 1.0 / 3e-3).abs() < 1e-6);
    }
}
