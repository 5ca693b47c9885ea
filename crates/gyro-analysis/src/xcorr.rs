//! The gyro rate against the reference rate: the reference angle's centred difference and
//! the lag of the peak of their cross-correlation. One home for `run`'s lag findings
//! ([`crate::lag`]) and the diagnosis's residuals and lag statistics.

/// Width of the boxcar over which the reference angle is differentiated (s).
pub const SMOOTH_WINDOW_S: f64 = 0.02;

/// Fewest samples with a reference rate for a residual or a lag to be read.
pub const MIN_SAMPLES: usize = 10;

/// The half-width `h` (samples) of the reference rate's centred difference at
/// `sample_rate_hz`: `max(1, round(fs · SMOOTH_WINDOW_S / 2))`.
pub fn smooth_half_width(sample_rate_hz: f64) -> usize {
    ((sample_rate_hz * SMOOTH_WINDOW_S / 2.0).round() as usize).max(1)
}

/// The centred difference `(v[i+h] − v[i−h]) / (2h·dt)` of `values` at `fs` with
/// `h = `[`smooth_half_width`]: the derivative averaged over a boxcar of `2h` samples,
/// centred, so it adds no lag. NaN within `h` of either end.
pub fn centred_difference(values: &[f64], fs: f64) -> Vec<f64> {
    let n = values.len();
    let h = smooth_half_width(fs);
    (0..n)
        .map(|i| {
            if i < h || i + h >= n {
                f64::NAN
            } else {
                (values[i + h] - values[i - h]) * fs / (2 * h) as f64
            }
        })
        .collect()
}

/// True if a cross-correlation peak lag `lag_s` (at sample rate `fs`) sits on the edge of
/// a search of ±`max_lag_s` rounded to whole samples.
pub fn is_at_edge_of(lag_s: f64, fs: f64, max_lag_s: f64) -> bool {
    let edge_s = ((max_lag_s * fs).round()).max(1.0) / fs;
    lag_s.abs() >= edge_s * (1.0 - 1e-9)
}

/// How the cross-correlation at a lag is normalised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    /// By the overlap's length (`n − |lag|`): the diagnosis's statistic, compared with
    /// simulations computed alike. It leans towards longer lags when the motion sits
    /// inside the run (the sum stays, the divisor shrinks).
    Divide,
    /// By the run's length: no lean, the peak of motion inside the run is where the
    /// signals align (a measured delay).
    Whole,
}

/// The lag (s; positive: `gyro` lags `reference`) of the peak of their cross-correlation
/// within ±`max_lag_s`, normalised as `overlap` says. Samples where either is undefined
/// count as zero after mean removal. The correlation of rates is smooth in the lag, so it
/// is searched every few lags and then refined around the best one (the same peak as an
/// exhaustive search unless two peaks lie within a few samples of each other), and the
/// peak placed by a parabola through it and its neighbours.
pub fn xcorr_peak_lag_within(
    gyro: &[f64],
    reference: &[f64],
    fs: f64,
    max_lag_s: f64,
    overlap: Overlap,
) -> Option<f64> {
    let n = gyro.len();
    let max_lag = ((max_lag_s * fs).round() as usize).max(1);
    let both = |i: usize| gyro[i].is_finite() && reference[i].is_finite();
    let count = (0..n).filter(|&i| both(i)).count();
    if count < 3 {
        return None;
    }
    let mg = (0..n).filter(|&i| both(i)).map(|i| gyro[i]).sum::<f64>() / count as f64;
    let mr = (0..n)
        .filter(|&i| both(i))
        .map(|i| reference[i])
        .sum::<f64>()
        / count as f64;
    let g: Vec<f64> = (0..n)
        .map(|i| if both(i) { gyro[i] - mg } else { 0.0 })
        .collect();
    let r: Vec<f64> = (0..n)
        .map(|i| if both(i) { reference[i] - mr } else { 0.0 })
        .collect();
    // c(lag) = Σ g[i + lag] r[i] / overlap.
    let corr = |lag: i64| -> f64 {
        let l = lag.unsigned_abs() as usize;
        if l >= n {
            return f64::NEG_INFINITY;
        }
        let (a, b) = if lag >= 0 {
            (&g[l..], &r[..n - l])
        } else {
            (&g[..n - l], &r[l..])
        };
        let mut acc = [0.0f64; 4];
        let chunks = a.len() / 4;
        for k in 0..chunks {
            for j in 0..4 {
                acc[j] += a[4 * k + j] * b[4 * k + j];
            }
        }
        let mut sum = acc.iter().sum::<f64>();
        for k in 4 * chunks..a.len() {
            sum += a[k] * b[k];
        }
        match overlap {
            Overlap::Divide => sum / (n - l) as f64,
            Overlap::Whole => sum / n as f64,
        }
    };
    let max_lag = max_lag as i64;
    let best = coarse_to_fine_peak(max_lag, &corr);
    if !best.1.is_finite() {
        return None;
    }
    let k = best.0;
    let offset = if k > -max_lag && k < max_lag {
        crate::lag::parabola_offset(corr(k - 1), best.1, corr(k + 1))
    } else {
        0.0
    };
    Some((k as f64 + offset) / fs)
}

/// The lag in ±`max_lag` (samples) where `corr` peaks, and its value: `corr` is smooth in
/// the lag (a correlation of rates), so it is read every few lags (a tenth of `max_lag`,
/// 1 to 8) and then at every lag within a step of the best; the same peak as an
/// exhaustive search unless two peaks lie within a few samples of each other. The first
/// of equal values wins; `(0, −∞)` when no value exceeds −∞.
pub fn coarse_to_fine_peak(max_lag: i64, corr: &dyn Fn(i64) -> f64) -> (i64, f64) {
    let step = (max_lag / 10).clamp(1, 8);
    let mut best = (0i64, f64::NEG_INFINITY);
    let mut lag = -max_lag;
    while lag <= max_lag {
        let c = corr(lag);
        if c > best.1 {
            best = (lag, c);
        }
        lag += step;
    }
    let (lo, hi) = ((best.0 - step).max(-max_lag), (best.0 + step).min(max_lag));
    for lag in lo..=hi {
        let c = corr(lag);
        if c > best.1 {
            best = (lag, c);
        }
    }
    best
}
