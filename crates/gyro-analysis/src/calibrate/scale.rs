//! The scale factor from the movements' totals: on a bench run every completed movement
//! gives the angle the pipeline measured and the reference's; a scale error `k` (the
//! sensor reads `r·(1 + k)`) makes the difference grow in proportion to the turn, which no
//! bias estimate removes. `k` is the least-squares slope of the movement errors on the
//! reference angles, through the origin, over the movements the reference turns by at
//! least [`MIN_TURN_DEG`]: a movement the reference does not follow (a turn about another
//! axis that the gyro sees through a misaligned mount, say) says nothing about the scale,
//! and its error would only swell the standard error.

use crate::replay::RunReport;
use gyro_core::Config;
use serde::Serialize;

/// One completed movement: the reference angle change and the pipeline's error (deg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovementTotal {
    /// Reference angle change over the movement (deg).
    pub reference_deg: f64,
    /// Measured minus reference (deg).
    pub error_deg: f64,
}

/// Each completed, unsaturated movement of `report` measured rest to rest: the angle and
/// the reference at the middle of the rest before (from the previous movement's end, or the
/// log's start) and of the rest after (to the next movement's start, or the log's end).
/// A reference that leads or lags the gyro, or settles later, is then read where both
/// are still; at the movement's own ends it would still be turning.
/// Needs the report's series; a movement without a rest on either side, or without a
/// reference there, is left out.
pub fn rest_to_rest(report: &RunReport) -> Vec<MovementTotal> {
    let series = &report.series;
    let moves = &report.movements;
    let mut out = Vec::new();
    for (i, m) in moves.iter().enumerate() {
        if !m.complete || m.saturated {
            continue;
        }
        let before_from = i.checked_sub(1).map_or(0, |j| moves[j].samples.1);
        let after_to = moves
            .get(i + 1)
            .map_or(series.len().saturating_sub(1), |n| n.samples.0);
        let (start, end) = m.samples;
        if before_from > start || end > after_to || after_to >= series.len() {
            continue;
        }
        let (a, b) = (
            &series[(before_from + start) / 2],
            &series[(end + after_to) / 2],
        );
        if let (Some(r0), Some(r1)) = (a.reference_deg, b.reference_deg) {
            let reference_deg = r1 - r0;
            out.push(MovementTotal {
                reference_deg,
                error_deg: f64::from(b.angle_deg) - f64::from(a.angle_deg) - reference_deg,
            });
        }
    }
    out
}

/// Smallest reference turn (deg) a movement needs to count in the fit.
pub const MIN_TURN_DEG: f64 = 10.0;

/// True if `m` counts as a turn: the reference turns by at least [`MIN_TURN_DEG`].
fn is_turn(m: &MovementTotal) -> bool {
    m.reference_deg.abs() >= MIN_TURN_DEG
}

/// Largest |k| fitted: the core's correction accepts up to ±0.25.
const MAX_ABS_K: f64 = 0.2;

/// RMS error (deg) of the turns among `movements` (those the fit counts), rest to rest;
/// `None` without a turn.
pub fn turn_rms<'a>(movements: impl IntoIterator<Item = &'a MovementTotal>) -> Option<f64> {
    let (mut sum_sq, mut n) = (0.0, 0_usize);
    for m in movements {
        if is_turn(m) {
            sum_sq += m.error_deg * m.error_deg;
            n += 1;
        }
    }
    (n > 0).then(|| (sum_sq / n as f64).sqrt())
}

/// RMS of the turns' relative errors (error / reference turn) among `movements`, and the
/// number of turns; `None` without a turn. Left out with the scale applied, it is the
/// scale uncertainty that remains: what the tightening decision's `scale_sigma` is for.
pub fn relative_rms<'a>(
    movements: impl IntoIterator<Item = &'a MovementTotal>,
) -> Option<(f64, usize)> {
    let (mut sum_sq, mut n) = (0.0, 0_usize);
    for m in movements {
        if is_turn(m) {
            sum_sq += (m.error_deg / m.reference_deg).powi(2);
            n += 1;
        }
    }
    (n > 0).then(|| ((sum_sq / n as f64).sqrt(), n))
}

/// The one-sided 95% upper bound of an RMS `rms` measured on `n` values: the spread is
/// known only as well as `n` turns show it, and the decision's guard band needs the
/// uncertainty it may be, not the one it was (JCGM 106's expanded uncertainty, in spirit).
/// `rms · sqrt(n / χ²₀.₀₅(n))`, with the χ² quantile by Wilson and Hilferty's cube: the
/// factor is within 4% of the exact one from n = 3 on, 14% above it at n = 2 (on the
/// safe side).
pub fn upper_95(rms: f64, n: usize) -> f64 {
    const Z_05: f64 = -1.644_853_626_951_472_2;
    let k = n.max(1) as f64;
    let c = 2.0 / (9.0 * k);
    let cube = (1.0 - c + Z_05 * c.sqrt()).max(0.05);
    rms * (k / (k * cube.powi(3))).sqrt()
}

/// Movements of `movements` that count in the fit.
pub fn turns(movements: &[MovementTotal]) -> usize {
    movements.iter().filter(|m| is_turn(m)).count()
}

/// Least-squares scale error of `movements` (the turns among them) on top of the configuration that measured
/// them: `(k, standard error)`. `None` without a turn, or beyond ±20%; the standard
/// error needs 2 movements.
pub fn fit(movements: &[MovementTotal]) -> Option<(f64, Option<f64>)> {
    let turns: Vec<MovementTotal> = movements.iter().copied().filter(is_turn).collect();
    let movements = turns.as_slice();
    let sxx: f64 = movements.iter().map(|m| m.reference_deg.powi(2)).sum();
    let sxy: f64 = movements
        .iter()
        .map(|m| m.reference_deg * m.error_deg)
        .sum();
    if !(sxx > 0.0 && sxy.is_finite()) {
        return None;
    }
    // The pipeline measured (1 + k)·θ; its error is k·θ.
    let k = sxy / sxx;
    if k.is_nan() || k.abs() > MAX_ABS_K {
        return None;
    }
    let n = movements.len();
    let se = (n >= 2).then(|| {
        let ss: f64 = movements
            .iter()
            .map(|m| (m.error_deg - k * m.reference_deg).powi(2))
            .sum();
        (ss / (n - 1) as f64 / sxx).sqrt()
    });
    Some((k, se))
}

/// Standard errors a fitted `k` must lie from zero to be written: its 95% interval
/// (±1.96 se) excludes no scale error.
pub const MIN_Z: f64 = 1.96;

/// True if `k` differs from zero beyond its noise: `|k| ≥` [`MIN_Z`] `· se`. Without a
/// standard error (one turn) nothing shows that it is not noise.
pub fn significant(k: f64, se: Option<f64>) -> bool {
    se.is_some_and(|se| se.is_finite() && k.abs() >= MIN_Z * se)
}

/// `config` with a further scale error `k` corrected: the scale it already corrects and
/// `k` compose, `(1 + k0)(1 + k) − 1`. `None` if the result is not a valid configuration.
pub fn with_scale(config: &Config, k: f64) -> Option<Config> {
    let mut out = *config;
    let k0 = f64::from(config.correction.scale_k);
    out.correction.scale_k = ((1.0 + k0) * (1.0 + k) - 1.0) as f32;
    out.correction.validate().ok().map(|()| out)
}

/// The scale factor calibration fitted, and whether it is written.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScaleFit {
    /// Scale error fitted on all training runs, on top of the starting configuration's
    /// (1 = 100%; the sensor reads `r·(1 + k)`). `None`: no turn to fit it on.
    pub k: Option<f64>,
    /// Its standard error from the movements' scatter about the line.
    pub standard_error: Option<f64>,
    /// Completed movements it was fitted on: those the reference turns by at least
    /// [`MIN_TURN_DEG`].
    pub movements: usize,
    /// The RMS error of the turns, rest to rest ([`turn_rms`]), on the left-out runs with
    /// the starting configuration, without and with the scale fitted on the other runs (deg;
    /// `None` without refits or turns). What a scale corrects is the turns' totals, so it
    /// is judged on them whatever the objective.
    pub leave_one_out_deg: Option<(f64, f64)>,
    /// Left-out runs with turns whose turn RMS is lower with the scale, of those runs.
    pub runs_better: (usize, usize),
    /// The turn RMS on the hold-out runs with the starting configuration, without and with
    /// the scale fitted on all training runs (deg; `None` without hold-out turns).
    pub holdout_deg: Option<(f64, f64)>,
    /// The scale uncertainty that remains, held out: the RMS of the left-out runs' turn
    /// errors relative to the turn, with the scale if it is written, else without
    /// ([`relative_rms`]). The movement's σ knows the bias and the noise, not this.
    pub residual_relative: Option<f64>,
    /// Its 95% upper bound from the number of left-out turns ([`upper_95`]): what the
    /// tightening decision adds as `scale_sigma` (the model file's).
    pub residual_relative_upper: Option<f64>,
    /// Written into the model file (`config.correction.scale_k`): it differs from zero
    /// beyond its noise ([`significant`]), and held out it lowers the turns' RMS error and
    /// is better on most left-out runs.
    pub written: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(reference_deg: f64, error_deg: f64) -> MovementTotal {
        MovementTotal {
            reference_deg,
            error_deg,
        }
    }

    #[test]
    fn slope_through_the_origin() {
        let (k, se) = fit(&[m(90.0, -0.9), m(-180.0, 1.8), m(45.0, -0.45)]).unwrap();
        assert!((k + 0.01).abs() < 1e-12, "{k}");
        assert!(se.unwrap() < 1e-12);
        let (k, se) = fit(&[m(90.0, -0.8), m(-90.0, 1.0)]).unwrap();
        assert!((k + 0.01).abs() < 1e-12, "{k}");
        // Residuals ±0.1 about the line: ss 0.02, n − 1 = 1, Σθ² 16200.
        assert!((se.unwrap() - (0.02 / 16200.0_f64).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn nothing_to_fit() {
        assert_eq!(fit(&[]), None);
        assert_eq!(fit(&[m(0.0, 1.0)]), None);
        assert_eq!(fit(&[m(5.0, 1.0)]), None, "under MIN_TURN_DEG");
        let (k, se) = fit(&[m(90.0, -0.9), m(0.1, 9.5), m(-180.0, 1.8)]).unwrap();
        assert!(
            (k + 0.01).abs() < 1e-12 && se.unwrap() < 1e-12,
            "a turn about another axis"
        );
        assert_eq!(fit(&[m(10.0, 5.0)]), None, "50% is no scale error");
        assert_eq!(fit(&[m(10.0, f64::NAN)]), None);
        assert_eq!(fit(&[m(10.0, 0.1)]).unwrap().1, None);
    }

    #[test]
    fn relative_errors_of_the_turns() {
        let (u, n) = relative_rms(&[m(100.0, 0.3), m(-200.0, 0.8), m(2.0, 1.0)]).unwrap();
        assert!((u - ((0.003_f64.powi(2) + 0.004_f64.powi(2)) / 2.0).sqrt()).abs() < 1e-12);
        assert_eq!(n, 2);
        assert_eq!(relative_rms(&[m(2.0, 1.0)]), None);
    }

    #[test]
    fn an_rms_from_few_turns_is_bounded_above() {
        // Exact factors sqrt(n / chi2_0.05(n)) from scipy.stats.chi2.ppf(0.05, n).
        for (n, exact, within) in [
            (2, 4.4154, 0.15),
            (3, 2.9200, 0.04),
            (5, 2.0893, 0.01),
            (20, 1.3576, 0.01),
            (100, 1.1328, 0.01),
        ] {
            let got = upper_95(1.0, n);
            assert!(got >= exact * 0.999, "{n}: {got} under {exact}");
            assert!(
                (got - exact).abs() < within * exact,
                "{n}: {got} vs {exact}"
            );
        }
    }

    #[test]
    fn noise_is_not_a_scale() {
        assert!(significant(-0.0127, Some(0.0003)));
        assert!(!significant(-0.00003, Some(0.00002)));
        assert!(!significant(0.01, None));
        assert!(!significant(0.01, Some(f64::NAN)));
    }

    #[test]
    fn scales_compose() {
        let mut base = Config::default();
        base.correction.scale_k = 0.01;
        let c = with_scale(&base, -0.02).unwrap();
        assert!((f64::from(c.correction.scale_k) - (1.01 * 0.98 - 1.0)).abs() < 1e-7);
        assert_eq!(with_scale(&Config::default(), 0.9), None);
    }
}
