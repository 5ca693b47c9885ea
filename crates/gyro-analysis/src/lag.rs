//! The gyro's lag behind its reference, measured from a run's output series one point at a
//! time: the peak of the cross-correlation of the gyro's rate with the reference's rate
//! within ±[`SEARCH_S`], in memory bounded by the search.
//!
//! Scored against a reference that leads or lags the gyro, every error during a turn is
//! the rate times the lag: a logger that stamps rows on arrival, or a pose sent on its own
//! path, then looks like a bad sensor. `run` measures the lag on every log with a
//! reference and says so when it is at least [`NOTABLE_S`].

use crate::diagnose::stats::{is_at_edge_of, residuals, xcorr_peak_lag_within, Overlap};
use gyro_log::RegularLog;
use std::collections::VecDeque;

/// Half-width of the search (s): a gyro's latency of a few milliseconds and a logger's
/// arrival delay of a hundred both fall inside.
pub const SEARCH_S: f64 = 0.5;

/// A lag at least this long (s) is said in every output: scored against such a reference,
/// the errors during turns are mostly the lag's.
pub const NOTABLE_S: f64 = 0.02;

/// Smallest correlation coefficient of the rates at the peak for a lag to be reported: a
/// still run, or one whose reference moves unlike the gyro, has no lag to speak of.
pub const MIN_CORRELATION: f64 = 0.5;

/// The lag of a whole log (s; positive: the gyro lags): the peak of the cross-correlation
/// of its gyro rate with its reference rate on the grid within ±[`SEARCH_S`], normalised
/// by the log's length (motion inside the log does not lean it towards longer lags).
/// `None` without a reference or a peak, or with the peak on the edge of the search: a
/// bound, not a measurement (a reference that turns against the gyro puts it there).
pub fn log_lag_s(log: &RegularLog) -> Option<f64> {
    let r = residuals(log).ok()?;
    xcorr_peak_lag_within(
        &r.rate_dps,
        &r.reference_rate_dps,
        r.sample_rate_hz,
        SEARCH_S,
        Overlap::Whole,
    )
    .filter(|lag| lag.is_finite() && !is_at_edge_of(*lag, r.sample_rate_hz, SEARCH_S))
}

/// The offset (in lags, within ±½) of the vertex of the parabola through the correlation
/// at the best lag (`at`) and its neighbours; 0 when they do not bend down.
pub fn parabola_offset(before: f64, at: f64, after: f64) -> f64 {
    let denom = before - 2.0 * at + after;
    if denom < 0.0 {
        (0.5 * (before - after) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Accumulates the cross-correlation of the gyro rate with the reference rate over lags
/// of ±`max_lag` points, one output point at a time.
///
/// The reference rate is the centred difference of the reference angle, so it is aligned
/// with the gyro rate of the point before the newest. Points without a reference count as
/// zero in both series.
#[derive(Clone, Debug)]
pub struct LagMeter {
    period_s: f64,
    max_lag: usize,
    /// The last two reference angles (the newest last) and the gyro rate of the newer.
    last_reference: [Option<f64>; 2],
    last_gyro: f64,
    /// Up to `max_lag` past aligned pairs, the newest at the back.
    gyro: VecDeque<f64>,
    reference: VecDeque<f64>,
    /// Σ g[j]·r[j − lag] for lag = −max_lag ..= max_lag (index lag + max_lag).
    sums: Vec<f64>,
    gyro_sq: f64,
    reference_sq: f64,
    /// Points pushed.
    seen: usize,
}

impl LagMeter {
    /// A meter for output points every `period_s` seconds, searching ±[`SEARCH_S`].
    pub fn new(period_s: f64) -> Self {
        let max_lag = if period_s.is_finite() && period_s > 0.0 {
            ((SEARCH_S / period_s).round() as usize).clamp(1, 10_000)
        } else {
            1
        };
        Self {
            period_s,
            max_lag,
            last_reference: [None; 2],
            last_gyro: 0.0,
            gyro: VecDeque::with_capacity(max_lag + 1),
            reference: VecDeque::with_capacity(max_lag + 1),
            sums: vec![0.0; 2 * max_lag + 1],
            gyro_sq: 0.0,
            reference_sq: 0.0,
            seen: 0,
        }
    }

    /// The next output point: its gyro rate (deg/s) and reference angle (deg).
    pub fn push(&mut self, rate_dps: f64, reference_deg: Option<f64>) {
        let [older, newer] = self.last_reference;
        if self.seen > 0 {
            // The previous point: its gyro rate, and the reference rate centred on it.
            let pair = match (older, reference_deg) {
                (Some(a), Some(b)) => (self.last_gyro, (b - a) / (2.0 * self.period_s)),
                _ => (0.0, 0.0),
            };
            let (g, r) = if pair.0.is_finite() && pair.1.is_finite() {
                pair
            } else {
                (0.0, 0.0)
            };
            self.add(g, r);
        }
        self.seen += 1;
        self.last_reference = [newer, reference_deg];
        self.last_gyro = rate_dps;
    }

    fn add(&mut self, g: f64, r: f64) {
        let m = self.max_lag;
        // Lag l ≥ 0 (gyro behind): g now with r l points back; l > 0 the other way.
        self.sums[m] += g * r;
        for (l, past_r) in self.reference.iter().rev().enumerate() {
            self.sums[m + l + 1] += g * past_r;
        }
        for (l, past_g) in self.gyro.iter().rev().enumerate() {
            self.sums[m - l - 1] += past_g * r;
        }
        self.gyro_sq += g * g;
        self.reference_sq += r * r;
        if self.gyro.len() == m {
            self.gyro.pop_front();
            self.reference.pop_front();
        }
        self.gyro.push_back(g);
        self.reference.push_back(r);
    }

    /// The lag (s; positive: the gyro lags the reference) at the correlation's peak, if
    /// the rates correlate there by at least [`MIN_CORRELATION`] and the peak is inside
    /// the search.
    pub fn lag_s(&self) -> Option<f64> {
        let m = self.max_lag as i64;
        let at = |lag: i64| self.sums[(lag + m) as usize];
        let best = (-m..=m).max_by(|a, b| at(*a).total_cmp(&at(*b)))?;
        let scale = (self.gyro_sq * self.reference_sq).sqrt();
        if !(scale > 0.0 && at(best) / scale >= MIN_CORRELATION) || best.abs() == m {
            return None;
        }
        let offset = parabola_offset(at(best - 1), at(best), at(best + 1));
        Some((best as f64 + offset) * self.period_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rest, a smooth 90 degree turn and back, sampled every `period_s`, the gyro
    /// `lag_s` behind the reference.
    fn meter(lag_s: f64, period_s: f64) -> LagMeter {
        let angle = |t: f64| {
            let ramp =
                |t: f64| 90.0 * (0.5 - 0.5 * (std::f64::consts::PI * t.clamp(0.0, 1.0)).cos());
            ramp(t - 2.0) - ramp(t - 5.0)
        };
        let rate = |t: f64| (angle(t + 1e-4) - angle(t - 1e-4)) / 2e-4;
        let mut m = LagMeter::new(period_s);
        let n = (8.0 / period_s) as usize;
        for i in 0..n {
            let t = i as f64 * period_s;
            m.push(rate(t - lag_s), Some(angle(t)));
        }
        m
    }

    #[test]
    fn finds_a_lag_either_way_between_output_points() {
        for (lag, period) in [(0.097, 0.02), (-0.031, 0.02), (0.0, 0.02), (0.012, 0.005)] {
            let got = meter(lag, period).lag_s().unwrap();
            assert!(
                (got - lag).abs() < 0.15 * period,
                "{lag} at {period}: {got}"
            );
        }
    }

    #[test]
    fn no_lag_without_motion_or_beyond_the_search() {
        let mut still = LagMeter::new(0.02);
        for i in 0..500 {
            still.push(0.01 * f64::from(i % 3), Some(0.0));
        }
        assert_eq!(still.lag_s(), None);
        assert_eq!(meter(0.7, 0.02).lag_s(), None);
        let mut unreferenced = LagMeter::new(0.02);
        for i in 0..500 {
            unreferenced.push(f64::from(i), None);
        }
        assert_eq!(unreferenced.lag_s(), None);
    }

    #[test]
    fn the_parabola_vertex() {
        assert_eq!(parabola_offset(1.0, 2.0, 1.0), 0.0);
        assert!((parabola_offset(1.0, 2.0, 1.5) - 1.0 / 6.0).abs() < 1e-12);
        assert_eq!(parabola_offset(1.0, 1.0, 1.0), 0.0);
    }
}
