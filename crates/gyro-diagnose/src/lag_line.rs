//! The gyro–reference lag through a run, window by window, and the straight line through
//! it: a sensor clock fast by ε whose rows are stamped by the sensor's own count (k / fs)
//! puts the gyro's sample of stamp t at true time t / (1 + ε), so its lag behind the
//! reference grows as ε / (1 + ε) · t. A constant delay (latency, a bandwidth) leaves the
//! line flat; a logger-stamped clock shows in the stamps instead (`StampedClock`).
//!
//! The per-sample statistics search the lag within ±`statistics.max_lag_s` and read its
//! growth as a regression linear in ε, which holds for a few hundred ppm; a clock error of
//! 1–3% moves the lag by a second over a run. The lag line tracks it, on rates
//! block-averaged to `statistics.lag_line_hz`: each window with motion is searched around
//! the last lag found carried on by the slope so far, within ±(`max_lag_s` +
//! `statistics.lag_max_clock` · the time since that lag); the line is fitted through the
//! windows near their Theil–Sen line (`gyro_analysis::lag::inliers`). The clock a
//! diagnosis holds as known takes each run's line refined over the whole run
//! ([`whole_run`]): a window's lag is where its motion lies, and a clock of percents moves
//! the lag across a window by more than the line may err.

use crate::ensemble::RealRun;
use crate::fit::{t95, Fit};
use crate::settings::{Settings, Statistics};
use gyro_analysis::lag::{inliers, parabola_offset};
use gyro_analysis::xcorr::{centred_difference, coarse_to_fine_peak};
use gyro_log::RegularLog;
use gyro_sim::Effect;

/// Fewest windows with a lag for a line.
const MIN_POINTS: usize = 3;

/// The lag's straight line through a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagLine {
    /// Growth of the lag (s per s; positive: the gyro falls further behind).
    pub slope: f64,
    /// Standard error of the slope from the points' scatter about the line (s per s).
    pub se_slope: f64,
    /// The lag at the run's start (s).
    pub intercept_s: f64,
    /// Windows whose lag was read.
    pub points: usize,
    /// Time from the first to the last of those windows' centres (s).
    pub span_s: f64,
}

impl LagLine {
    /// The sample-clock error (ppm) of a count-stamped sensor with this line: slope
    /// = ε / (1 + ε).
    pub fn clock_ppm(&self) -> f64 {
        self.slope / (1.0 - self.slope) * 1e6
    }

    /// The standard error of [`Self::clock_ppm`] (ppm).
    pub fn se_ppm(&self) -> f64 {
        self.se_slope / (1.0 - self.slope).powi(2) * 1e6
    }

    /// How far the lag moves over a run of `duration_s` (s).
    pub fn growth_s(&self, duration_s: f64) -> f64 {
        self.slope * duration_s
    }
}

/// The count-stamped clock read from the training runs' lag lines, when it moves the lag
/// beyond the per-sample statistics' search (±`statistics.max_lag_s`) over a run: the mean
/// of the runs' ppm (each line refined over its whole run, [`whole_run`]), tested against its standard error (between-run scatter and each
/// line's own), its held-out replication read alike. `None` when fewer than two training
/// runs have a line, or the growth stays within the search (the regression on time ×
/// angular acceleration reads it there).
pub(crate) fn grown_clock_fit(
    train: &[&RealRun],
    holdout: &[&RealRun],
    s: &Settings,
) -> Option<Fit> {
    let (m, se, runs) = mean_ppm(train, s)?;
    let longest_s = train.iter().map(|r| r.duration_s).fold(0.0, f64::max);
    if (m * 1e-6 * longest_s).abs() < s.statistics.max_lag_s {
        return None;
    }
    let z = m / se;
    let holdout_z = mean_ppm(holdout, s).map(|(mh, seh, _)| mh / seh);
    let half = t95(runs - 1).max(s.tests.interval_z) * se;
    Some(Fit {
        effect: Effect::ClockErrorCountStamped { ppm: m },
        ci95: vec![(Some(m - half), Some(m + half))],
        z,
        passes: z.abs() >= s.tests.z_critical,
        test: "the gyro's lag behind the reference, window by window, grows through the run (each run's line refined over the whole run)".into(),
        direct: false,
        holdout_z,
        shape_loglik: None,
    })
}

/// `runs` without their last rows whose gyro sample, under a count-stamped clock slow by
/// `ppm` (< 0), was taken after the run's last reference: the row stamped `t` holds the
/// rate of true time `t / (1 + ε)`, so only the first `(1 + ε)` of a run lies within its
/// reference. Each run is prepared again from its shortened log.
pub(crate) fn within_reference(
    runs: &[RealRun],
    ppm: f64,
) -> Result<Vec<RealRun>, crate::DiagnoseError> {
    let keep_share = (1.0 + ppm * 1e-6).clamp(0.0, 1.0);
    runs.iter()
        .map(|run| {
            let mut log = run.log.clone();
            let keep = ((log.slots.len().saturating_sub(1)) as f64 * keep_share).floor() as usize + 1;
            log.slots.truncate(keep);
            RealRun::prepare_with(run.name.clone(), log, &run.settings())
                .map(|mut shortened| {
                    // The kept rows' gyro reads the motion up to the reference's end: the
                    // whole run's motion, which the re-simulation samples as the clock does.
                    shortened.motion = run.motion.clone();
                    shortened
                })
                .map_err(|e| crate::DiagnoseError::Run {
                    name: run.name.clone(),
                    message: format!("shortened to where its reference reaches under a count-stamped clock {ppm:.0} ppm slow: {e}"),
                })
        })
        .collect()
}

/// Mean clock ppm of `runs`' lag lines, each refined over its whole run ([`whole_run`]),
/// its standard error (at least 1 ppm) and the number of runs with a line (at least 2).
fn mean_ppm(runs: &[&RealRun], settings: &Settings) -> Option<(f64, f64, usize)> {
    let lines: Vec<LagLine> = runs
        .iter()
        .filter_map(|r| of_log(&r.log, &settings.statistics).map(|l| whole_run(r, l)))
        .filter(|l| l.se_slope.is_finite())
        .collect();
    if lines.len() < 2 {
        return None;
    }
    let n = lines.len() as f64;
    let ppm: Vec<f64> = lines.iter().map(LagLine::clock_ppm).collect();
    let m = ppm.iter().sum::<f64>() / n;
    let between = ppm.iter().map(|p| (p - m).powi(2)).sum::<f64>() / (n - 1.0);
    let within = lines.iter().map(|l| l.se_ppm().powi(2)).sum::<f64>() / n;
    Some((m, ((between + within) / n).sqrt().max(1.0), lines.len()))
}

/// Gauss–Newton steps at most of [`whole_run`].
const WHOLE_RUN_STEPS: usize = 20;
/// [`whole_run`] has converged when a step moves the lag by less than this anywhere in
/// the run (s).
const WHOLE_RUN_TOL_S: f64 = 1e-7;

/// `line` refined over the whole of `run`: the lag's start and slope whose reading of the
/// run's motion, ω(t − lag(t)) plus a constant bias, leaves the least squares to the
/// gyro's rows (Gauss–Newton from the windows' line, the rows whose motion time lies
/// within the reference). The windows read the lag where each holds its motion, over
/// `statistics.lag_window_s` across which a clock 3% off moves it by 120 ms: one run's
/// line errs by hundreds of ppm and more, beyond what its points' scatter says, and a
/// re-simulation with the mean of such lines leaves its lag growing. The slope's
/// standard error is the least-squares one (the rows' residuals taken as independent).
/// `line` as it is when the steps do not converge or leave more squares than it.
pub(crate) fn whole_run(run: &RealRun, line: LagLine) -> LagLine {
    let rows: Vec<(f64, f64)> = run
        .log
        .slots
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.filled && s.rate_dps.is_finite())
        .map(|(k, s)| (run.motion_time_s(k), s.rate_dps))
        .collect();
    let Some(mid_s) = rows
        .first()
        .zip(rows.last())
        .map(|(a, b)| 0.5 * (a.0 + b.0))
    else {
        return line;
    };
    // The lag at the run's middle and its slope: uncorrelated steps.
    let start = [line.intercept_s + line.slope * mid_s, line.slope];
    let Some(mut step) = gauss_newton_step(run, &rows, mid_s, start) else {
        return line;
    };
    let half_span_s = rows.iter().map(|r| (r.0 - mid_s).abs()).fold(0.0, f64::max);
    let mut lag = start;
    for _ in 0..WHOLE_RUN_STEPS {
        lag = [lag[0] + step.change[0], lag[1] + step.change[1]];
        let Some(next) = gauss_newton_step(run, &rows, mid_s, lag) else {
            return line;
        };
        let converged = step.change[0].abs() + step.change[1].abs() * half_span_s < WHOLE_RUN_TOL_S;
        step = next;
        if converged {
            let [at_start, at_end] = squares_of(run, &rows, mid_s, [start, lag]);
            if at_end.is_nan() || at_end > at_start {
                return line;
            }
            return LagLine {
                slope: lag[1],
                se_slope: step.se_slope,
                intercept_s: lag[0] - lag[1] * mid_s,
                ..line
            };
        }
    }
    line
}

/// The squares the gyro's `rows` leave about ω(τ) plus their mean under each of the two
/// `lags` (the lag at `mid_s` (s), its slope), over the rows whose τ lies within the motion
/// under both: a pair of lags compared on the same rows.
fn squares_of(run: &RealRun, rows: &[(f64, f64)], mid_s: f64, lags: [[f64; 2]; 2]) -> [f64; 2] {
    let end_s = run.motion.duration_s();
    let mut sums = [[0.0; 2]; 2];
    let mut n = 0usize;
    for &(t, gyro) in rows {
        let tau = lags.map(|lag| t - lag[0] - lag[1] * (t - mid_s));
        if !tau.iter().all(|tau| (0.0..=end_s).contains(tau)) {
            continue;
        }
        for (sum, tau) in sums.iter_mut().zip(tau) {
            let y = gyro - run.motion.rate_dps(tau);
            sum[0] += y;
            sum[1] += y * y;
        }
        n += 1;
    }
    sums.map(|[sum, square]| square - sum * sum / n.max(1) as f64)
}

/// One Gauss–Newton step of [`whole_run`] at `lag` (the lag at `mid_s` (s), its slope).
#[derive(Clone, Copy, Debug)]
struct GaussNewtonStep {
    /// The change of the lag at `mid_s` and of its slope.
    change: [f64; 2],
    /// The least-squares standard error of the slope at `lag`.
    se_slope: f64,
}

/// The least-squares step of the lag at `mid_s` and its slope from `lag`, over `rows`
/// ((motion time (s), gyro rate (deg/s))): the gyro less ω(τ), τ = t − lag(t), regressed on
/// a bias, α(τ) and (t − `mid_s`)·α(τ) (the motion's acceleration, its centred difference
/// over a sample). `None` when fewer than 4 rows lie within the motion or the normal
/// equations are singular.
fn gauss_newton_step(
    run: &RealRun,
    rows: &[(f64, f64)],
    mid_s: f64,
    lag: [f64; 2],
) -> Option<GaussNewtonStep> {
    let motion = &run.motion;
    let h = 1.0 / run.sample_rate_hz;
    let end_s = motion.duration_s();
    let mut xtx = [[0.0; 3]; 3];
    let mut xty = [0.0; 3];
    let (mut yy, mut n) = (0.0, 0usize);
    for &(t, gyro) in rows {
        let tau = t - lag[0] - lag[1] * (t - mid_s);
        if !(h..=end_s - h).contains(&tau) {
            continue;
        }
        let y = gyro - motion.rate_dps(tau);
        let alpha = (motion.rate_dps(tau + h) - motion.rate_dps(tau - h)) / (2.0 * h);
        let x = [1.0, alpha, (t - mid_s) * alpha];
        for i in 0..3 {
            for j in 0..3 {
                xtx[i][j] += x[i] * x[j];
            }
            xty[i] += x[i] * y;
        }
        yy += y * y;
        n += 1;
    }
    if n < 4 {
        return None;
    }
    let b = crate::stats::solve(xtx, xty)?;
    // The squares left after the step: at convergence, those at `lag`.
    let squares = yy - (0..3).map(|i| b[i] * xty[i]).sum::<f64>();
    let inverse_slope = crate::stats::solve(xtx, [0.0, 0.0, 1.0])?[2];
    let se_slope = (squares.max(0.0) / (n - 3) as f64 * inverse_slope).sqrt();
    // y ≈ bias − α·Δlag − (t − mid)·α·Δslope.
    Some(GaussNewtonStep {
        change: [-b[1], -b[2]],
        se_slope,
    })
}

/// The lag line of `log` (gyro rate against the reference angle's centred difference).
pub fn of_log(log: &RegularLog, statistics: &Statistics) -> Option<LagLine> {
    let fs = log.sample_rate_hz;
    let rate: Vec<f64> = log.slots.iter().map(|s| s.rate_dps).collect();
    let reference: Vec<f64> = log
        .slots
        .iter()
        .map(|s| s.reference_deg.unwrap_or(f64::NAN))
        .collect();
    lag_line(&rate, &centred_difference(&reference, fs), fs, statistics)
}

/// The lag line of `gyro` against `reference` (rates on one grid at `fs`; NaN where
/// undefined), or `None` when fewer than [`MIN_POINTS`] windows have motion and a lag, or
/// they span less than `statistics.lag_min_span_share` of the run.
pub fn lag_line(
    gyro: &[f64],
    reference: &[f64],
    fs: f64,
    statistics: &Statistics,
) -> Option<LagLine> {
    let fit = statistics;
    let near_s = fit.max_lag_s;
    // Block means: the motion's band lies far below the rate it is read at.
    let q = ((fs / fit.lag_line_hz).round() as usize).max(1);
    let (gyro, reference) = (&block_means(gyro, q), &block_means(reference, q));
    let fs = fs / q as f64;
    // A block's mean sits half a block after its first sample.
    let offset_s = 0.5 * (q - 1) as f64 / (fs * q as f64);
    let n = gyro.len().min(reference.len());
    let w = (fit.lag_window_s * fs).round() as usize;
    if w < 4 || n < w {
        return None;
    }
    let step = w / 2;
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut start = 0;
    while start + w <= n {
        let centre_s = (start as f64 + 0.5 * w as f64) / fs + offset_s;
        if rms(&reference[start..start + w]) >= fit.lag_min_motion_dps {
            // From the last point on the slope so far, searched wider the further it lies
            // (the clock may be as far off as `lag_max_clock`); from 0 before any point.
            let slope = line(&points).map_or(0.0, |(_, b, _)| b);
            let (predicted_s, half_s) = match points.last() {
                Some(&(t, lag)) => (
                    lag + slope * (centre_s - t),
                    near_s + fit.lag_max_clock * (centre_s - t),
                ),
                None => (0.0, near_s + fit.lag_max_clock * centre_s),
            };
            if let Some(lag) = window_lag(gyro, reference, fs, start, w, predicted_s, half_s) {
                points.push((centre_s, lag));
            }
        }
        start += step;
    }
    // A window whose peak fell on another period of the motion lies off the line.
    let points = inliers(&points)?;
    let span_s = match (points.first(), points.last()) {
        (Some(a), Some(b)) => b.0 - a.0,
        _ => 0.0,
    };
    if points.len() < MIN_POINTS || span_s < fit.lag_min_span_share * n as f64 / fs {
        return None;
    }
    let (intercept_s, slope, se_slope) = line(&points)?;
    Some(LagLine {
        slope,
        se_slope,
        intercept_s,
        points: points.len(),
        span_s,
    })
}

/// The lag (s) of the window `start..start + w` of `gyro`, searched within ±`half_s` of
/// `predicted_s`: the peak of the correlation coefficient of g[i] and r[i − d] over the
/// whole window at every lag d (the reference read beyond the window, so no lag has fewer
/// terms and none is favoured), found coarse to fine
/// ([`gyro_analysis::xcorr::coarse_to_fine_peak`]), placed by a parabola; `None` on the
/// search's edge or when the search reaches outside the run.
fn window_lag(
    gyro: &[f64],
    reference: &[f64],
    fs: f64,
    start: usize,
    w: usize,
    predicted_s: f64,
    half_s: f64,
) -> Option<f64> {
    let centre = (predicted_s * fs).round() as i64;
    let half = ((half_s * fs).round() as i64).max(1);
    // gyro(t) ≈ reference(t − d): lags centre ± half read the reference from
    // start − centre − half to start − centre + half + w.
    let first = start as i64 - centre - half;
    if first < 0 || (start as i64 - centre + half) as usize + w > reference.len() {
        return None;
    }
    let g = &gyro[start..start + w];
    let mean = |x: &[f64]| {
        let f: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
        if f.is_empty() {
            0.0
        } else {
            f.iter().sum::<f64>() / f.len() as f64
        }
    };
    let mg = mean(g);
    let g: Vec<f64> = g
        .iter()
        .map(|v| if v.is_finite() { v - mg } else { 0.0 })
        .collect();
    let span = &reference[first as usize..(start as i64 - centre + half) as usize + w];
    let mr = mean(span);
    let r: Vec<f64> = span
        .iter()
        .map(|v| if v.is_finite() { v - mr } else { 0.0 })
        .collect();
    // Lag d = centre + j, j in −half..=half: reference index start − d + i = (half − j) + i in `r`.
    // Normalised by the reference segment's variance about its own mean (Pearson's r up to
    // the gyro's constant norm): unnormalised, the sum leans towards lags whose segment
    // holds more motion. `g` has zero mean, so Σ g·r needs no mean of `r`.
    let corr = |j: i64| -> f64 {
        let off = (half - j) as usize;
        let seg = &r[off..off + w];
        let (sum, sq) = seg.iter().fold((0.0, 0.0), |(s, q), b| (s + b, q + b * b));
        let energy = sq - sum * sum / w as f64;
        let dot: f64 = g.iter().zip(seg).map(|(a, b)| a * b).sum();
        if energy > 0.0 {
            dot / energy.sqrt()
        } else {
            f64::NEG_INFINITY
        }
    };
    let best = coarse_to_fine_peak(half, &corr);
    let k = best.0;
    if !best.1.is_finite() || k <= -half || k >= half {
        return None;
    }
    // A neighbour without variance (a flat stretch) places nothing.
    let offset = parabola_offset(corr(k - 1), best.1, corr(k + 1));
    let offset = if offset.is_finite() { offset } else { 0.0 };
    Some((centre as f64 + k as f64 + offset) / fs).filter(|lag| lag.is_finite())
}

/// Means of consecutive blocks of `q` samples of `x` (their finite values; NaN when none),
/// a last partial block dropped.
fn block_means(x: &[f64], q: usize) -> Vec<f64> {
    if q == 1 {
        return x.to_vec();
    }
    x.chunks_exact(q)
        .map(|b| {
            let (sum, count) = b
                .iter()
                .filter(|v| v.is_finite())
                .fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
            if count == 0 {
                f64::NAN
            } else {
                sum / count as f64
            }
        })
        .collect()
}

/// RMS of the finite values of `x` (0 when none).
fn rms(x: &[f64]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for v in x.iter().filter(|v| v.is_finite()) {
        sum += v * v;
        count += 1;
    }
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).sqrt()
    }
}

/// Least-squares line `y = a + b·x` through `points`: (a, b, standard error of b; ∞ with
/// two points).
fn line(points: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let m = points.len();
    if m < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / m as f64;
    let my = points.iter().map(|p| p.1).sum::<f64>() / m as f64;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let b = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let a = my - b * mx;
    let se = if m > 2 {
        let ss: f64 = points.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum();
        (ss / (m - 2) as f64 / sxx).sqrt()
    } else {
        f64::INFINITY
    };
    Some((a, b, se))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A band-limited motion: a sum of a few slow sines (deg/s), at time `t` (s).
    fn motion(t: f64) -> f64 {
        60.0 * (0.7 * t).sin() + 35.0 * (1.9 * t + 1.0).sin() + 20.0 * (3.3 * t + 2.0).sin()
    }

    /// Gyro sampled at stamp k/fs but taken at true time k/(fs(1+ε)) − delay; reference
    /// rate at the stamp.
    fn pair(fs: f64, seconds: f64, eps: f64, delay_s: f64) -> (Vec<f64>, Vec<f64>) {
        let n = (seconds * fs) as usize;
        let gyro = (0..n)
            .map(|k| motion(k as f64 / (fs * (1.0 + eps)) - delay_s))
            .collect();
        let reference = (0..n).map(|k| motion(k as f64 / fs)).collect();
        (gyro, reference)
    }

    #[test]
    fn the_line_reads_the_clock_of_a_count_stamped_sensor_up_to_its_largest() {
        let s = Settings::DEFAULT;
        for eps in [-0.03, -0.005, 5e-4, 0.006, 0.03] {
            let (g, r) = pair(500.0, 90.0, eps, 0.0);
            let l = lag_line(&g, &r, 500.0, &s.statistics).expect("a line");
            let ppm = eps * 1e6;
            assert!(
                (l.clock_ppm() - ppm).abs() < 0.01 * ppm.abs() + 20.0,
                "ε {eps}: read {} ppm",
                l.clock_ppm()
            );
            assert!(l.points >= 30, "{l:?}");
        }
    }

    #[test]
    fn a_constant_delay_is_a_flat_line_at_the_delay() {
        let (g, r) = pair(500.0, 60.0, 0.0, 0.02);
        let l = lag_line(&g, &r, 500.0, &Settings::DEFAULT.statistics).expect("a line");
        assert!(l.clock_ppm().abs() < 20.0, "{l:?}");
        assert!((l.intercept_s - 0.02).abs() < 1e-3, "{l:?}");
    }

    /// Bench runs of 60 s (the self-check's: CRM100 nominal, rests and turns) whose
    /// sensor clock is `ppm` off, its rows stamped by its own count.
    fn count_stamped_runs(ppm: f64, runs: u64) -> Vec<RealRun> {
        use gyro_log::{regularize, GridOptions};
        use gyro_sim::{simulate, BenchProfile, Motion, SensorModel, SimOptions};
        let profile = BenchProfile {
            duration_s: 60.0,
            ..BenchProfile::default()
        };
        (0..runs)
            .map(|i| {
                let motion = Motion::bench(&profile, 4800 + i);
                let options = SimOptions {
                    seed: 4900 + i,
                    ..SimOptions::default()
                };
                let effects = [Effect::ClockErrorCountStamped { ppm }];
                let log = simulate(&SensorModel::default(), &effects, &motion, &options);
                let regular = regularize(&log, &GridOptions::default()).expect("a regular log");
                RealRun::prepare(format!("run-{i}"), regular).expect("a prepared run")
            })
            .collect()
    }

    /// A clock 3% fast moves the lag by 120 ms across one 4 s window; the windows' lines
    /// of these runs read it at 30 052 to 30 739 ppm, their mean 30 320 [28 576, 32 064],
    /// with which a re-simulation leaves the lag growing by 19 ms through a run. Each line
    /// refined over its whole run reads it within 2 ppm, and the fit's interval holds it.
    #[test]
    fn a_grown_clock_is_read_over_the_whole_run() {
        let ppm = 30_000.0;
        let runs = count_stamped_runs(ppm, 3);
        let s = Settings::DEFAULT;
        for run in &runs {
            let window = of_log(&run.log, &s.statistics).expect("a window line");
            let whole = whole_run(run, window);
            assert!(
                (whole.clock_ppm() - ppm).abs() < 15.0,
                "{}: windows {:.0} ppm, whole run {:.1}",
                run.name,
                window.clock_ppm(),
                whole.clock_ppm()
            );
        }
        let train: Vec<&RealRun> = runs.iter().collect();
        let fit = grown_clock_fit(&train, &[], &s).expect("a grown clock");
        let Effect::ClockErrorCountStamped { ppm: fitted } = fit.effect else {
            panic!("{:?}", fit.effect);
        };
        assert!((fitted - ppm).abs() < 10.0, "{fitted}");
        let (lo, hi) = fit.ci95[0];
        assert!(
            lo.is_some_and(|lo| lo <= ppm) && hi.is_some_and(|hi| ppm <= hi),
            "{:?}",
            fit.ci95
        );
    }

    #[test]
    fn rest_gives_no_line() {
        let g = vec![0.01; 30_000];
        assert!(lag_line(&g, &g, 500.0, &Settings::DEFAULT.statistics).is_none());
        assert!(lag_line(&g[..10], &g[..10], 500.0, &Settings::DEFAULT.statistics).is_none());
    }
}
