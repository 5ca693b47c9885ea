//! What a run's figures and verdicts mean less than they seem, one list per run: each
//! finding with a stable code, a sentence, and where it lies (movement, time). Every
//! output of `run` shows the same list (the table, the JSON's `warnings` and `findings`,
//! the series CSV's header comments, stderr), so nothing found is said in one place only.
//!
//! The rules are here, once: the log reader's notices ([`LOG`]), a log too short to say
//! anything ([`SHORT_LOG`]), a log run slower than the
//! configured rate ([`OUTPUT_RATE_LOWERED`]), saturated movements ([`SATURATED`]), movements
//! across interpolated samples ([`GAP`]), movements longer than the bias can be trusted
//! ([`BIAS_UNOBSERVABLE`]), movements the reference does not follow ([`NOT_FOLLOWED`],
//! the rule `diagnose`'s turns use too: [`not_followed`]), readings beyond the range in use
//! ([`RANGE_CONTRADICTED`]), verdicts without a σ or without a scale uncertainty
//! ([`VERDICTS_WITHOUT_SIGMA`], [`GUARD_BAND_WITHOUT_SCALE`]), a gyro–reference lag
//! ([`REFERENCE_LAG`]) and a lag that changes through the run ([`LAG_DRIFT`]).

use crate::replay::{MovementResult, RunReport};
use gyro_core::Compensation;
use serde::Serialize;

/// A notice of the log reader (a reference that jumps, a sense that turns the other way,
/// irregular time stamps…), passed on as it was given.
pub const LOG: &str = "log";
/// The log is shorter than [`SHORT_LOG_S`]: no rest can estimate the bias, no movement
/// can be told from a start-up transient.
pub const SHORT_LOG: &str = "short_log";
/// Shortest log (s of output) whose figures mean anything: the motion detector needs
/// quiet blocks before it trusts a rest, and a movement needs a rest on each side.
pub const SHORT_LOG_S: f64 = 1.0;
/// The log is slower than the configured output rate and ran at its own rate.
pub const OUTPUT_RATE_LOWERED: &str = "output_rate_lowered";
/// A movement reached the sensor's range or a clip plateau: its angle is a lower bound.
pub const SATURATED: &str = "saturated";
/// A movement spans interpolated input samples: its angle across them is a guess.
pub const GAP: &str = "gap";
/// A movement longer than the bias's correlation time: the bias cannot be estimated
/// during it, and the angle error grows with it.
pub const BIAS_UNOBSERVABLE: &str = "bias_unobservable";
/// A movement the gyro turns while the reference stays (nearly) still.
pub const NOT_FOLLOWED: &str = "reference_does_not_follow";
/// Readings beyond the sensor range in use.
pub const RANGE_CONTRADICTED: &str = "range_contradicted";
/// Tightening verdicts without a σ (a compensation other than the Kalman form).
pub const VERDICTS_WITHOUT_SIGMA: &str = "verdicts_without_sigma";
/// Tightening verdicts whose guard band leaves the scale error out.
pub const GUARD_BAND_WITHOUT_SCALE: &str = "guard_band_without_scale";
/// The gyro lags or leads the scored reference by [`crate::lag::NOTABLE_S`] or more.
pub const REFERENCE_LAG: &str = "reference_lag";
/// The gyro–reference lag changes through the run by [`crate::lag::NOTABLE_S`] or more.
pub const LAG_DRIFT: &str = "lag_drift";

/// A movement the gyro makes while the reference turns less than this fraction of it is
/// not followed by the reference.
pub const UNTRACKED_FRACTION: f64 = 0.5;
/// Smallest gyro angle (deg) of a movement listed as not followed by the reference: below
/// it a bias wander over a long movement could make it.
pub const UNTRACKED_MIN_DEG: f64 = 2.0;

/// Whether a movement the gyro turns by `gyro_deg` while the reference turns by
/// `reference_deg` is one the reference does not follow: a turn about another axis seen
/// through a mount off the reference's axis, or motion the reference misses.
pub fn not_followed(gyro_deg: f64, reference_deg: f64) -> bool {
    gyro_deg.abs() >= UNTRACKED_MIN_DEG && reference_deg.abs() < UNTRACKED_FRACTION * gyro_deg.abs()
}

/// One finding.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// Stable code (the constants of this module).
    pub code: &'static str,
    /// What it is and what to do, in a sentence.
    pub message: String,
    /// The movement it concerns (1-based), if one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub movement: Option<usize>,
    /// When it starts (s, the log's time), if it has a time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
}

impl Finding {
    fn new(code: &'static str, message: String) -> Self {
        Self {
            code,
            message,
            movement: None,
            time_s: None,
        }
    }

    fn at(mut self, m: &MovementResult) -> Self {
        self.movement = Some(m.index);
        self.time_s = Some(m.start_time_s);
        self
    }
}

/// Every finding of a run, in the order outputs give them: the log reader's `notices`,
/// the run's rate, each movement's (in order), then the whole run's.
pub fn of_run(report: &RunReport, notices: &[String]) -> Vec<Finding> {
    let mut out: Vec<Finding> = notices
        .iter()
        .map(|n| Finding::new(LOG, n.clone()))
        .collect();
    let covered_s = report.summary.outputs as f64 / f64::from(report.output_rate_hz);
    if covered_s < SHORT_LOG_S {
        out.push(Finding::new(
            SHORT_LOG,
            format!(
                "the log gives {} output samples ({covered_s:.2} s at {} Hz), under {SHORT_LOG_S} s: too short for a rest to estimate the bias or a movement to be told from the start, so its figures say nothing; log at least a few seconds with a rest at the start",
                report.summary.outputs, report.output_rate_hz
            ),
        ));
    }
    if let Some(configured_hz) = report.output_rate_lowered_from_hz {
        out.push(Finding::new(
            OUTPUT_RATE_LOWERED,
            crate::replay::lowered_rate_note(
                report.sample_rate_hz,
                configured_hz,
                report.config.filter.cutoff_hz,
            ),
        ));
    }
    for m in &report.movements {
        out.extend(of_movement(report, m));
    }
    out.extend(range(report));
    out.extend(unguarded(report));
    out.extend(scale(report));
    out.extend(lag(report));
    out.extend(lag_drift(report));
    out
}

/// The findings of movement `m`.
fn of_movement(report: &RunReport, m: &MovementResult) -> Vec<Finding> {
    let mut out = Vec::new();
    if m.saturated {
        out.push(Finding::new(SATURATED, saturation(m.index, report.config.range_dps)).at(m));
    }
    if m.filled_samples > 0 {
        out.push(
            Finding::new(
                GAP,
                format!(
                    "movement {} spans {} interpolated input samples (a gap or missing rates in the log): its angle across them is a guess",
                    m.index, m.filled_samples
                ),
            )
            .at(m),
        );
    }
    let beta = f64::from(report.config.kalman.beta_per_s);
    if beta > 0.0 && m.duration_s > 1.0 / beta {
        let grows = match m.angle_std_deg {
            Some(std) if m.duration_s > 0.0 => format!(
                "the angle error may grow by about {:.2} deg/s (σ {:.1} deg by its end)",
                f64::from(std) / m.duration_s,
                std
            ),
            _ => format!(
                "the angle error may grow by about {:.2} deg/s (the bias's σ)",
                report.config.kalman.bias_sigma_dps
            ),
        };
        out.push(
            Finding::new(
                BIAS_UNOBSERVABLE,
                format!(
                    "no rest for {:.0} s (movement {}{}): longer than the bias's correlation time ({:.0} s), so the bias cannot be estimated during it; {grows}; rest the gyro at least every {:.0} s, or read the angle with its σ",
                    m.duration_s,
                    m.index,
                    if m.complete { "" } else { ", to the log's end" },
                    1.0 / beta,
                    1.0 / beta
                ),
            )
            .at(m),
        );
    }
    if let Some(reference_deg) = m.reference_deg {
        let gyro_deg = f64::from(m.angle_deg);
        if not_followed(gyro_deg, reference_deg) {
            out.push(
                Finding::new(
                    NOT_FOLLOWED,
                    format!(
                        "movement {}{}: the gyro turns {gyro_deg:.2} deg while the reference turns {reference_deg:.2} deg: a turn about another axis seen through a mount off the reference's axis (cross-axis sensitivity), or motion the reference misses; its error is not the gyro's",
                        m.index,
                        if m.complete { "" } else { " (to the log's end)" }
                    ),
                )
                .at(m),
            );
        }
    }
    out
}

/// Why movement `index` is flagged saturated, and what that means for its angle.
fn saturation(index: usize, range_dps: Option<f32>) -> String {
    let what = match range_dps {
        Some(r) => format!("reached the sensor range ({r} deg/s) or clipped below it"),
        None => format!(
            "clipped ({} or more identical readings, and {} ms or more of them, at >= {} \
             deg/s, {} deg/s ahead of the filtered rate or lasting {} ms; sensor range \
             unknown)",
            gyro_core::CLIP_PLATEAU_SAMPLES,
            gyro_core::CLIP_PLATEAU_SHORT_S * 1000.0,
            gyro_core::CLIP_PLATEAU_MIN_DPS,
            gyro_core::CLIP_PLATEAU_LEAD_DPS,
            gyro_core::CLIP_PLATEAU_LONG_S * 1000.0
        ),
    };
    format!("movement {index} {what}: its angle is a lower bound")
}

/// Readings beyond the sensor range in use: a sensor reads at most its range, so that
/// range is not this one's. From the first such reading the core flags saturation on clip
/// plateaus only; a movement that ended before it may still be flagged for reaching it.
fn range(report: &RunReport) -> Option<Finding> {
    let range_dps = report.config.range_dps?;
    report.summary.range_contradicted.then(|| {
        Finding::new(
            RANGE_CONTRADICTED,
            format!(
                "readings reach {:.1} deg/s, beyond the sensor range of ±{range_dps} deg/s in use: that range is not this sensor's, so from the first such reading only clip plateaus flag a movement saturated (one that ended before it may still be flagged for reaching the range); give --range-dps with the sensor's full scale",
                report.summary.largest_abs_rate_dps
            ),
        )
    })
}

/// Tightening verdicts without a σ: only the Kalman form gives a movement one, so in the
/// other compensations the guard band holds only the scale term.
fn unguarded(report: &RunReport) -> Option<Finding> {
    let t = report.config.tightening.as_ref()?;
    let mode = match report.config.compensation {
        Compensation::Kalman => return None,
        Compensation::None => "none",
        Compensation::Paper => "paper",
    };
    Some(Finding::new(
        VERDICTS_WITHOUT_SIGMA,
        format!(
            "the verdicts have no σ: only the Kalman form gives a movement one, and with compensation {mode} the guard band is {}, so an `ok` does not allow for the bias; run with --compensation kalman for a guarded decision",
            if t.scale_sigma > 0.0 {
                format!("only the scale term ({}% of the angle)", 100.0 * t.scale_sigma)
            } else {
                "zero".to_string()
            }
        ),
    ))
}

/// Tightening verdicts without a scale uncertainty: σ holds the bias and the noise, not
/// the scale factor, which on an uncalibrated MEMS gyro is off by 0.5–2%.
fn scale(report: &RunReport) -> Option<Finding> {
    let t = report.config.tightening.as_ref()?;
    (t.scale_sigma == 0.0).then(|| {
        Finding::new(
            GUARD_BAND_WITHOUT_SCALE,
            "the guard band holds the bias and the noise (σ), not the gyro's scale error: uncalibrated, a MEMS gyro's scale is off by 0.5-2% (1-3 deg on a 150 deg turn), far beyond σ; give --scale-sigma (a datasheet's tolerance, e.g. 0.02) or a model from `calibrate` (its scale_sigma)".to_string(),
        )
    })
}

/// How the reference was scored, for the lag findings.
fn scored(report: &RunReport) -> String {
    if report.reference_delay_s == 0.0 {
        "the reference as logged".to_string()
    } else {
        format!(
            "the reference (shifted by {:.1} ms)",
            1e3 * report.reference_delay_s
        )
    }
}

/// A gyro that lags (or leads) the scored reference by at least
/// [`crate::lag::NOTABLE_S`]: the errors during turns are then mostly the lag's.
fn lag(report: &RunReport) -> Option<Finding> {
    let lag_s = report.summary.reference_lag_s?;
    if lag_s.abs() < crate::lag::NOTABLE_S {
        return None;
    }
    let how = if lag_s > 0.0 { "lags" } else { "leads" };
    Some(Finding::new(
        REFERENCE_LAG,
        format!(
            "the gyro {how} {} by {:.0} ms (cross-correlation of the rates): the errors against it during turns are the rate times that, not the sensor's; score with --reference-delay-s {:.3} (or a model file's reference_delay_s: `calibrate` measures and writes it)",
            scored(report),
            1e3 * lag_s.abs(),
            report.reference_delay_s + lag_s,
        ),
    ))
}

/// A lag that changes through the run by at least [`crate::lag::NOTABLE_S`]: a clock that
/// runs off its nominal rate while rows are stamped by the sample count. No constant
/// delay corrects it.
fn lag_drift(report: &RunReport) -> Option<Finding> {
    let t = report.summary.reference_lag_trend?;
    if !t.notable() {
        return None;
    }
    let mut finding = Finding::new(
        LAG_DRIFT,
        format!(
            "the gyro's lag behind {} changes through the run, from {:.0} ms to {:.0} ms ({:+.1} ms per minute): its clock runs {:.2}% {} its nominal rate and the rows are stamped by its sample count (or the logger's clock drifts); no constant delay corrects that: stamp the gyro's rows with the clock that stamps the reference",
            scored(report),
            1e3 * t.first_s,
            1e3 * t.last_s,
            6e4 * t.per_s,
            100.0 * t.per_s.abs(),
            if t.per_s > 0.0 { "above" } else { "below" }
        ),
    );
    finding.time_s = Some(t.from_s);
    Some(finding)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_movement_the_reference_does_not_follow() {
        assert!(not_followed(-9.54, 0.0));
        assert!(not_followed(9.6, 4.7));
        assert!(!not_followed(9.6, 4.9));
        assert!(!not_followed(1.9, 0.0), "below the smallest angle listed");
        assert!(!not_followed(90.0, 89.0));
    }
}
