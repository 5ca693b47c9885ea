//! The gyro's lag behind its reference, measured from a run's output series one point at a
//! time: the peak of the cross-correlation of the gyro's rate with the reference's rate
//! within ±[`SEARCH_S`], in memory bounded by the search.
//!
//! Scored against a reference that leads or lags the gyro, every error during a turn is
//! the rate times the lag: a logger that stamps rows on arrival, or a pose sent on its own
//! path, then looks like a bad sensor. `run` measures the lag on every log with a
//! reference and says so when it is at least [`NOTABLE_S`].

use crate::xcorr::{
    centred_difference, is_at_edge_of, xcorr_peak_lag_within, Overlap, MIN_SAMPLES,
};
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
    if !log.has_reference {
        return None;
    }
    let fs = log.sample_rate_hz;
    let reference_deg: Vec<f64> = log
        .slots
        .iter()
        .map(|s| s.reference_deg.unwrap_or(f64::NAN))
        .collect();
    let rate_dps: Vec<f64> = log.slots.iter().map(|s| s.rate_dps).collect();
    let reference_rate_dps = centred_difference(&reference_deg, fs);
    let read = rate_dps
        .iter()
        .zip(&reference_rate_dps)
        .filter(|(g, r)| (*g - *r).is_finite())
        .count();
    if read < MIN_SAMPLES {
        return None;
    }
    xcorr_peak_lag_within(&rate_dps, &reference_rate_dps, fs, SEARCH_S, Overlap::Whole)
        .filter(|lag| lag.is_finite() && !is_at_edge_of(*lag, fs, SEARCH_S))
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
        Self::with_search(period_s, SEARCH_S)
    }

    /// A meter for output points every `period_s` seconds, searching ±`search_s`.
    pub fn with_search(period_s: f64, search_s: f64) -> Self {
        let max_lag = if period_s.is_finite() && period_s > 0.0 && search_s.is_finite() {
            ((search_s / period_s).round() as usize).clamp(1, 10_000)
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

/// Length of the blocks a lag's trend is read from (s): a clock 2% off moves the lag by
/// 0.2 s within one, which its peak still finds.
pub const TREND_BLOCK_S: f64 = 10.0;

/// Half-width of each block's search (s): a clock that runs off its nominal rate carries
/// the lag well beyond [`SEARCH_S`] over a run (2% over a minute: 1.2 s).
pub const TREND_SEARCH_S: f64 = 2.0;

/// The trend reads every this many output points: its wide search costs four times the
/// whole run's lag ([`SEARCH_S`]) per point, and a trend of tens of milliseconds needs no
/// finer step than 40 ms at the usual 50 Hz (the peak is refined between steps).
pub const TREND_STRIDE: usize = 2;

/// Fewest blocks with a lag for a trend to be read.
pub const TREND_MIN_BLOCKS: usize = 4;

/// A trend's slope must be at least this many of its standard errors: block lags scatter
/// by a few milliseconds, and a run hundreds of blocks long turns that into a slope.
pub const TREND_MIN_Z: f64 = 4.0;

/// A lag that changes through a run, as a clock that runs off its nominal rate makes it
/// when rows are stamped by the sample count.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LagTrend {
    /// The fitted lag at the first and the last block's middle (s; positive: the gyro lags).
    pub first_s: f64,
    /// See `first_s`.
    pub last_s: f64,
    /// The middles of the first and last block with a lag (s, the log's time).
    pub from_s: f64,
    /// See `from_s`.
    pub to_s: f64,
    /// The lag's change per second of the run (s/s): the clock's relative rate error.
    pub per_s: f64,
}

impl LagTrend {
    /// The lag's change over the run (s).
    pub fn change_s(&self) -> f64 {
        self.last_s - self.first_s
    }

    /// Whether the change is one to say: at least [`NOTABLE_S`].
    pub fn notable(&self) -> bool {
        self.change_s().abs() >= NOTABLE_S
    }
}

/// Reads the lag block by block ([`TREND_BLOCK_S`], each searched ±[`TREND_SEARCH_S`]) and
/// fits a line through the block lags, in memory bounded by a block plus a number per
/// block.
#[derive(Clone, Debug)]
pub struct LagTrendMeter {
    /// The period of the points read ([`TREND_STRIDE`] output periods).
    period_s: f64,
    /// Output points pushed.
    pushed: usize,
    block_points: usize,
    block: LagMeter,
    in_block: usize,
    /// Time of the block's first point (s).
    block_start_s: f64,
    /// (middle of the block, its lag) for each block with a lag (s).
    lags: Vec<(f64, f64)>,
}

impl LagTrendMeter {
    /// A meter for output points every `output_period_s` seconds.
    pub fn new(output_period_s: f64) -> Self {
        let period_s = output_period_s * TREND_STRIDE as f64;
        let block_points = if period_s.is_finite() && period_s > 0.0 {
            ((TREND_BLOCK_S / period_s).round() as usize).max(8)
        } else {
            usize::MAX
        };
        Self {
            period_s,
            pushed: 0,
            block_points,
            block: LagMeter::with_search(period_s, TREND_SEARCH_S),
            in_block: 0,
            block_start_s: 0.0,
            lags: Vec::new(),
        }
    }

    /// The next output point: its time (s), gyro rate (deg/s) and reference angle (deg).
    pub fn push(&mut self, time_s: f64, rate_dps: f64, reference_deg: Option<f64>) {
        self.pushed += 1;
        if (self.pushed - 1) % TREND_STRIDE != 0 {
            return;
        }
        if self.in_block == 0 {
            self.block_start_s = time_s;
        }
        self.block.push(rate_dps, reference_deg);
        self.in_block += 1;
        if self.in_block == self.block_points {
            let middle_s = 0.5 * (self.block_start_s + time_s);
            if let Some(lag) = self.block.lag_s() {
                self.lags.push((middle_s, lag));
            }
            self.in_block = 0;
            self.block = LagMeter::with_search(self.period_s, TREND_SEARCH_S);
        }
    }

    /// The least-squares line through the block lags, if at least [`TREND_MIN_BLOCKS`]
    /// have one and its slope is at least [`TREND_MIN_Z`] standard errors from zero. A
    /// block whose peak fell on another period of a repeating motion lies far off the
    /// others: the lags more than [`TREND_OUTLIER_S`] (or five median deviations) from
    /// the median line (Theil–Sen) are left out first.
    pub fn trend(&self) -> Option<LagTrend> {
        let lags = inliers(&self.lags)?;
        let n = lags.len();
        if n < TREND_MIN_BLOCKS {
            return None;
        }
        let nf = n as f64;
        let mean_t = lags.iter().map(|p| p.0).sum::<f64>() / nf;
        let mean_l = lags.iter().map(|p| p.1).sum::<f64>() / nf;
        let stt: f64 = lags.iter().map(|p| (p.0 - mean_t).powi(2)).sum();
        let stl: f64 = lags.iter().map(|p| (p.0 - mean_t) * (p.1 - mean_l)).sum();
        if stt <= 0.0 || !stt.is_finite() {
            return None;
        }
        let slope = stl / stt;
        let residual: f64 = lags
            .iter()
            .map(|p| (p.1 - mean_l - slope * (p.0 - mean_t)).powi(2))
            .sum();
        let se = (residual / (nf - 2.0) / stt).sqrt();
        if slope.is_nan() || slope.abs() < TREND_MIN_Z * se {
            return None;
        }
        let (from_s, to_s) = (lags[0].0, lags[n - 1].0);
        Some(LagTrend {
            first_s: mean_l + slope * (from_s - mean_t),
            last_s: mean_l + slope * (to_s - mean_t),
            from_s,
            to_s,
            per_s: slope,
        })
    }
}

/// A block lag this far (s) from the median line, and beyond five median deviations, is
/// left out of the trend: a peak on another period of the motion, not the clock.
pub const TREND_OUTLIER_S: f64 = 0.05;

/// The points of `lags` near their Theil–Sen line (the median of the pairwise slopes,
/// through the median point), in time order; `None` for fewer than two. Shared by `run`'s
/// lag trend and the diagnosis's lag line.
pub fn inliers(lags: &[(f64, f64)]) -> Option<Vec<(f64, f64)>> {
    let mut slopes = Vec::new();
    for (i, a) in lags.iter().enumerate() {
        for b in &lags[i + 1..] {
            if b.0 != a.0 {
                slopes.push((b.1 - a.1) / (b.0 - a.0));
            }
        }
    }
    let slope = crate::median(&slopes)?;
    let intercept = crate::median(&lags.iter().map(|p| p.1 - slope * p.0).collect::<Vec<_>>())?;
    let off = |p: &(f64, f64)| (p.1 - intercept - slope * p.0).abs();
    let spread = crate::median(&lags.iter().map(off).collect::<Vec<_>>())?;
    let limit = TREND_OUTLIER_S.max(5.0 * 1.4826 * spread);
    Some(lags.iter().copied().filter(|p| off(p) <= limit).collect())
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

    /// Turns that do not repeat (two sines of incommensurate periods), the gyro's samples
    /// taken on a clock `1 + clock` times the nominal rate and stamped by their count: its
    /// lag grows by `clock / (1 + clock)` per second; plus a constant `lag_s`.
    fn trend_meter(clock: f64, lag_s: f64, duration_s: f64) -> LagTrendMeter {
        use std::f64::consts::TAU;
        let angle = |t: f64| 60.0 * (TAU * t / 3.0).sin() + 40.0 * (TAU * t / 7.7 + 1.0).sin();
        let rate = |t: f64| {
            60.0 * TAU / 3.0 * (TAU * t / 3.0).cos()
                + 40.0 * TAU / 7.7 * (TAU * t / 7.7 + 1.0).cos()
        };
        let period = 0.02;
        let mut m = LagTrendMeter::new(period);
        for i in 0..(duration_s / period) as usize {
            let t = i as f64 * period;
            m.push(t, rate(t / (1.0 + clock) - lag_s), Some(angle(t)));
        }
        m
    }

    #[test]
    fn a_lag_that_grows_is_read_as_a_trend() {
        for clock in [0.02, 0.005, -0.009] {
            let t = trend_meter(clock, 0.0, 90.0).trend().unwrap();
            let expected = clock / (1.0 + clock);
            assert!(
                (t.per_s - expected).abs() < 0.1 * expected.abs(),
                "{clock}: {t:?}"
            );
            assert!(t.notable(), "{t:?}");
        }
        // A constant lag, however long, has no trend to say.
        for lag_s in [0.0, 0.109, -0.3] {
            let m = trend_meter(0.0, lag_s, 90.0);
            assert!(
                m.trend().is_none_or(|t| !t.notable()),
                "{lag_s}: {:?}",
                m.trend()
            );
        }
        // Too short a run: no trend read.
        assert_eq!(trend_meter(0.02, 0.0, 30.0).trend(), None);
    }

    #[test]
    fn the_parabola_vertex() {
        assert_eq!(parabola_offset(1.0, 2.0, 1.0), 0.0);
        assert!((parabola_offset(1.0, 2.0, 1.5) - 1.0 / 6.0).abs() < 1e-12);
        assert_eq!(parabola_offset(1.0, 1.0, 1.0), 0.0);
    }
}
