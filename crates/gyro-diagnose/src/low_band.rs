//! The low band: gyro and reference rate low-passed alike, without phase, where a gain is
//! read.
//!
//! A scale factor is a gain at the rates a sensor is calibrated at: constant rate, or
//! motion slow against its dynamics (IEEE Std 952 measures it on a rate table). Above a
//! few hertz a real gyro's response departs from a pure delay (the MPU6050 of the ssong
//! recordings passes 0.99 of the encoder's rate at 1–4 Hz but 0.93–0.95 at the rig's
//! 12.8 Hz stepper line, with the same 12 ms phase lag), and a regression over the whole
//! band reads that roll-off, amplified by the jerk column, as tens of percent of scale.
//! So the gain-type regression columns and the gain statistics are taken on both signals
//! low-passed by the same zero-phase Butterworth at `statistics.low_band_hz`
//! ([`crate::settings::Statistics::low_band_hz`]): the band of a
//! tightening's turn, where any latency is a small phase the acceleration column
//! absorbs.
//!
//! The filter is scipy's `sosfiltfilt` (odd extension of `3 · (2 · sections + 1)` samples,
//! each pass started in its steady state at the first padded value), per stretch of
//! samples where both signals are finite; `fixtures/filters/low_band.csv` holds scipy's
//! output for a test of it.

use gyro_core::Butterworth;

/// Order of the Butterworth run forwards and backwards (the pair is of twice the order).
pub const LOW_BAND_ORDER: u8 = 2;

/// The low-band cut-off used at `sample_rate_hz`: `low_band_hz`, raised to the lowest
/// ratio the Butterworth design accepts; `None` when the rate is too low for a low band.
pub fn cutoff_hz(sample_rate_hz: f64, low_band_hz: f64) -> Option<f64> {
    let cutoff = low_band_hz.max(Butterworth::MIN_CUTOFF_RATIO * sample_rate_hz);
    (sample_rate_hz.is_finite() && cutoff <= Butterworth::MAX_CUTOFF_RATIO * sample_rate_hz)
        .then_some(cutoff)
}

/// Zero-phase low-pass of `x` at `cutoff_hz` (scipy's `sosfiltfilt` with the default
/// odd padding), each maximal stretch where `keep(i)` holds filtered on its own; NaN
/// elsewhere and in stretches shorter than the padding.
pub fn zero_phase(
    x: &[f64],
    sample_rate_hz: f64,
    cutoff_hz: f64,
    keep: impl Fn(usize) -> bool,
) -> Vec<f64> {
    let mut out = vec![f64::NAN; x.len()];
    let design = Butterworth {
        order: LOW_BAND_ORDER,
        cutoff_hz: cutoff_hz as f32,
    }
    .design(sample_rate_hz);
    let Ok(design) = design else {
        return out;
    };
    let sections = design.sections();
    let pad = 3 * (2 * sections.len() + 1);
    for run in super::stats::stretches(x.len(), |i| keep(i) && x[i].is_finite()) {
        if run.len() <= pad {
            continue;
        }
        let y = filtfilt(sections, &x[run.clone()], pad);
        out[run].copy_from_slice(&y);
    }
    out
}

/// `sosfiltfilt` of one finite stretch longer than `pad`.
fn filtfilt(sections: &[[f64; 6]], x: &[f64], pad: usize) -> Vec<f64> {
    let n = x.len();
    let (first, last) = (x[0], x[n - 1]);
    let mut ext = Vec::with_capacity(n + 2 * pad);
    ext.extend((1..=pad).rev().map(|k| 2.0 * first - x[k]));
    ext.extend_from_slice(x);
    ext.extend((1..=pad).map(|k| 2.0 * last - x[n - 1 - k]));
    let forward = sosfilt_steady(sections, &ext);
    let backward: Vec<f64> = forward.into_iter().rev().collect();
    let mut y = sosfilt_steady(sections, &backward);
    y.reverse();
    y[pad..pad + n].to_vec()
}

/// The cascade in transposed direct form II, each section started in the steady state
/// of a constant input equal to `x[0]` (scipy's `sosfilt_zi · x[0]`).
fn sosfilt_steady(sections: &[[f64; 6]], x: &[f64]) -> Vec<f64> {
    let mut y = x.to_vec();
    let mut level = x.first().copied().unwrap_or(0.0);
    for &[b0, b1, b2, a0, a1, a2] in sections {
        let (b0, b1, b2, a1, a2) = (b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0);
        let gain = (b0 + b1 + b2) / (1.0 + a1 + a2);
        let out_level = gain * level;
        let mut z2 = b2 * level - a2 * out_level;
        let mut z1 = b1 * level - a1 * out_level + z2;
        for v in y.iter_mut() {
            let input = *v;
            let output = b0 * input + z1;
            z1 = b1 * input - a1 * output + z2;
            z2 = b2 * input - a2 * output;
            *v = output;
        }
        level = out_level;
    }
    y
}

/// The centred difference of `x` over ±1 sample, per second (NaN at the ends and next to
/// a NaN).
pub fn derivative(x: &[f64], sample_rate_hz: f64) -> Vec<f64> {
    let n = x.len();
    let mut d = vec![f64::NAN; n];
    for i in 1..n.saturating_sub(1) {
        d[i] = (x[i + 1] - x[i - 1]) * 0.5 * sample_rate_hz;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    const LOW_BAND_HZ: f64 = crate::Settings::DEFAULT.statistics.low_band_hz;

    /// scipy's `sosfiltfilt(butter(2, 2, fs=1000, output="sos"), x)` on the fixture's input
    /// (`fixtures/filters/low_band.py`).
    #[test]
    fn matches_scipy_sosfiltfilt() {
        let text = include_str!("../../../fixtures/filters/low_band.csv");
        let rows: Vec<(f64, f64)> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("x"))
            .map(|l| {
                let mut f = l.split(',').map(|v| v.trim().parse::<f64>().unwrap());
                (f.next().unwrap(), f.next().unwrap())
            })
            .collect();
        let x: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let y = zero_phase(&x, 1000.0, 2.0, |_| true);
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, ((_, want), got)) in rows.iter().zip(&y).enumerate() {
            assert!(
                (want - got).abs() <= 1e-9 * scale,
                "sample {i}: {got} against scipy's {want}"
            );
        }
    }

    #[test]
    fn passes_a_slow_ramp_and_removes_a_fast_line_without_lag() {
        let fs = 1000.0;
        let x: Vec<f64> = (0..5000)
            .map(|i| {
                let t = i as f64 / fs;
                10.0 * t + 5.0 * (2.0 * std::f64::consts::PI * 12.8 * t).sin()
            })
            .collect();
        let y = zero_phase(&x, fs, LOW_BAND_HZ, |_| true);
        for (i, v) in y.iter().enumerate().take(4000).skip(1000) {
            let t = i as f64 / fs;
            assert!((v - 10.0 * t).abs() < 0.05, "sample {i}: {v}");
        }
    }

    #[test]
    fn stretches_are_filtered_apart_and_gaps_stay_nan() {
        let mut x = vec![1.0; 200];
        x[100] = f64::NAN;
        let y = zero_phase(&x, 1000.0, 20.0, |i| i != 50);
        assert!(y[50].is_nan() && y[100].is_nan());
        assert!(y
            .iter()
            .filter(|v| v.is_finite())
            .all(|v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn the_cutoff_follows_the_design_limits() {
        assert_eq!(cutoff_hz(1000.0, LOW_BAND_HZ), Some(2.0));
        assert_eq!(cutoff_hz(10_000.0, LOW_BAND_HZ), Some(10.0));
        assert_eq!(cutoff_hz(3.0, LOW_BAND_HZ), None);
    }
}
