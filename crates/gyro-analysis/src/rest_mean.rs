//! The plainest honest estimator of each movement's angle, as a yardstick: integrate the
//! rate minus the mean rate of the whole rest before the movement, from the end of that
//! rest to the start of the next. The pipeline is held to it (never worse on bench runs).
//!
//! Rests are given, not detected (on simulated runs: the true rotations), so the yardstick
//! measures the estimator, not a detector.
//!
//! ```
//! use gyro_analysis::rest_mean::{per_rest_angles, Rest};
//! // 1 Hz: a bias of 0.5 deg/s, a rest, a 10 deg turn over two samples, a rest.
//! let rates = [0.5, 0.5, 5.5, 5.5, 0.5, 0.5];
//! let rests = [Rest { start: 0, end: 1 }, Rest { start: 4, end: 5 }];
//! // Slots 2, 3 and 4 (the next rest's first) less the bias: 5 + 5 + 0 deg.
//! assert_eq!(per_rest_angles(&rates, 1.0, &rests), vec![0.0, 10.0]);
//! ```

pub mod bench;

/// A rest: the slots `start..=end` (indices into the rate series).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rest {
    /// First slot of the rest.
    pub start: usize,
    /// Last slot of the rest.
    pub end: usize,
}

/// The angle (deg) at each rest, relative to the first: for the movement between rests `i`
/// and `i + 1`, the sum of `(rate − mean_i) · period_s` over the slots after rest `i` up to
/// and including the first slot of rest `i + 1`, where `mean_i` is the mean rate over rest
/// `i`. Rests must be in order and within `rates_dps`.
pub fn per_rest_angles(rates_dps: &[f64], period_s: f64, rests: &[Rest]) -> Vec<f64> {
    rest_angles(rates_dps, period_s, rests, |quiet| {
        quiet.iter().sum::<f64>() / quiet.len() as f64
    })
}

/// [`per_rest_angles`] with the bias of each movement given by `bias_dps` from the rates
/// of the rest before it: their mean for the per-rest estimator, zero for a bias known
/// exactly on a run without one (the floor the white noise alone sets).
pub fn rest_angles(
    rates_dps: &[f64],
    period_s: f64,
    rests: &[Rest],
    bias_dps: impl Fn(&[f64]) -> f64,
) -> Vec<f64> {
    let mut angles = Vec::with_capacity(rests.len());
    let mut angle_deg = 0.0;
    for (i, rest) in rests.iter().enumerate() {
        if i > 0 {
            let before = rests[i - 1];
            let mean_dps = bias_dps(&rates_dps[before.start..=before.end]);
            angle_deg += rates_dps[before.end + 1..=rest.start]
                .iter()
                .map(|r| (r - mean_dps) * period_s)
                .sum::<f64>();
        }
        angles.push(angle_deg);
    }
    angles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bias_of_the_rest_before_is_removed_from_the_movement() {
        // 1 Hz: bias 0.5 deg/s; movement slots 2, 3 (rate 5 deg/s each above the bias) and
        // the next rest's first slot (the bias only).
        let rates = [0.5, 0.5, 5.5, 5.5, 0.5, 0.5];
        let rests = [Rest { start: 0, end: 1 }, Rest { start: 4, end: 5 }];
        assert_eq!(per_rest_angles(&rates, 1.0, &rests), vec![0.0, 10.0]);
        // A second movement uses the mean of the second rest (here a new bias of 1.0; the
        // first movement ends on that rest's first slot, 0.5 above the old mean).
        let rates = [0.5, 0.5, 5.5, 5.5, 1.0, 1.0, -4.0, 1.0];
        let rests = [
            Rest { start: 0, end: 1 },
            Rest { start: 4, end: 5 },
            Rest { start: 7, end: 7 },
        ];
        assert_eq!(per_rest_angles(&rates, 1.0, &rests), vec![0.0, 10.5, 5.5]);
        // A bias known to be zero keeps the whole rate of the movements.
        assert_eq!(
            rest_angles(&rates, 1.0, &rests, |_| 0.0),
            vec![0.0, 12.0, 9.0]
        );
    }
}

/// The rests around `rotations` (sorted, non-overlapping, times in s) as slot ranges of a
/// grid whose slot `k` is at `times_s[k]`: before the first rotation, between each two, and
/// after the last. Rests without a slot are left out.
pub fn rests_between(rotations: &[(f64, f64)], times_s: &[f64]) -> Vec<Rest> {
    let mut bounds = Vec::with_capacity(rotations.len() + 1);
    let mut rest_start_s = f64::NEG_INFINITY;
    for &(start_s, end_s) in rotations {
        bounds.push((rest_start_s, start_s));
        rest_start_s = end_s;
    }
    bounds.push((rest_start_s, f64::INFINITY));
    bounds
        .into_iter()
        .filter_map(|(from_s, to_s)| {
            let start = times_s.partition_point(|t| *t < from_s);
            let end = times_s.partition_point(|t| *t < to_s);
            (end > start).then(|| Rest {
                start,
                end: end - 1,
            })
        })
        .collect()
}

/// A run scored at its rests: the accumulated angle error (deg) at the middle of each rest,
/// relative to the first rest, of the pipeline and of the per-rest estimator.
#[derive(Clone, Debug, PartialEq)]
pub struct RestErrors {
    /// The pipeline's compensated angle minus the reference.
    pub pipeline_deg: Vec<f64>,
    /// The per-rest estimator's angle minus the reference.
    pub oracle_deg: Vec<f64>,
}

impl RestErrors {
    /// Max |accumulated error| over the rests: (pipeline, oracle).
    pub fn max_abs(&self) -> (f64, f64) {
        let max = |v: &[f64]| v.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
        (max(&self.pipeline_deg), max(&self.oracle_deg))
    }

    /// Each movement's own error (the change of the accumulated error over it):
    /// (pipeline, oracle) per movement.
    pub fn per_movement(&self) -> Vec<(f64, f64)> {
        (1..self.pipeline_deg.len())
            .map(|i| {
                (
                    self.pipeline_deg[i] - self.pipeline_deg[i - 1],
                    self.oracle_deg[i] - self.oracle_deg[i - 1],
                )
            })
            .collect()
    }
}

/// Score `log` (with a reference) through the pipeline configured by `config` and through
/// the per-rest estimator, at the rests around `rotations` (start, end in s).
pub fn score(
    log: &gyro_log::RegularLog,
    rotations: &[(f64, f64)],
    config: &gyro_core::Config,
) -> Result<RestErrors, gyro_core::Error> {
    Ok(score_report(
        log,
        rotations,
        &crate::replay::replay(log, config)?,
    ))
}

/// [`score`] with the pipeline's run already replayed (`report`, from `log`).
pub fn score_report(
    log: &gyro_log::RegularLog,
    rotations: &[(f64, f64)],
    report: &crate::replay::RunReport,
) -> RestErrors {
    let times_s: Vec<f64> = log.slots.iter().map(|s| s.time_s).collect();
    let rates_dps: Vec<f64> = log.slots.iter().map(|s| s.rate_dps).collect();
    let rests = rests_between(rotations, &times_s);
    let oracle = per_rest_angles(&rates_dps, 1.0 / log.sample_rate_hz, &rests);
    let series_times: Vec<f64> = report.series.iter().map(|p| p.time_s).collect();
    let angle_at = |time_s: f64| -> f64 {
        let k = series_times.partition_point(|t| *t < time_s);
        let a = &report.series[k.saturating_sub(1).min(report.series.len() - 1)];
        let b = &report.series[k.min(report.series.len() - 1)];
        if b.time_s > a.time_s {
            let w = (time_s - a.time_s) / (b.time_s - a.time_s);
            f64::from(a.angle_deg) + w * f64::from(b.angle_deg - a.angle_deg)
        } else {
            f64::from(a.angle_deg)
        }
    };
    let mut errors = RestErrors {
        pipeline_deg: Vec::with_capacity(rests.len()),
        oracle_deg: Vec::with_capacity(rests.len()),
    };
    let mut origin: Option<(f64, f64)> = None;
    for (rest, oracle_deg) in rests.iter().zip(oracle) {
        let mid = (rest.start + rest.end) / 2;
        let reference_deg = log.slots[mid].reference_deg.unwrap_or(f64::NAN);
        let pipeline_deg = angle_at(times_s[mid]);
        let (p0, r0) = *origin.get_or_insert((pipeline_deg, reference_deg));
        errors
            .pipeline_deg
            .push(pipeline_deg - p0 - (reference_deg - r0));
        errors.oracle_deg.push(oracle_deg - (reference_deg - r0));
    }
    errors
}

/// A simulated bench run: the true motion, its rotations as (start, end) in s, and the
/// log on the grid.
pub struct SimulatedRun {
    /// The true motion.
    pub motion: gyro_sim::Motion,
    /// Its rotations, (start, end) in s.
    pub rotations: Vec<(f64, f64)>,
    /// The simulated log on the grid.
    pub log: gyro_log::RegularLog,
}

impl SimulatedRun {
    /// Each true rotation (its angle, deg) with the movement of `report` that holds its
    /// middle, if any: how the pipeline's own movement events are scored against the truth.
    pub fn movements<'a>(
        &self,
        report: &'a crate::replay::RunReport,
    ) -> Vec<(f64, Option<&'a crate::replay::MovementResult>)> {
        self.motion
            .rotations()
            .iter()
            .map(|r| {
                let middle_s = r.start_s + 0.5 * r.duration_s;
                let found = report
                    .movements
                    .iter()
                    .find(|m| m.start_time_s <= middle_s && middle_s <= m.end_time_s);
                (r.angle_deg, found)
            })
            .collect()
    }
}

/// Simulate `sensor` with `effects` on the default bench motion of `seed`.
pub fn simulate_bench_run(
    sensor: &gyro_sim::SensorModel,
    effects: &[gyro_sim::Effect],
    seed: u64,
) -> Result<SimulatedRun, gyro_log::LogError> {
    let motion = gyro_sim::Motion::bench(&gyro_sim::BenchProfile::default(), seed);
    let rotations = motion
        .rotations()
        .iter()
        .map(|r| (r.start_s, r.start_s + r.duration_s))
        .collect();
    let options = gyro_sim::SimOptions {
        seed,
        ..gyro_sim::SimOptions::default()
    };
    let raw = gyro_sim::simulate(sensor, effects, &motion, &options);
    let log = gyro_log::regularize(&raw, &gyro_log::GridOptions::default())?;
    Ok(SimulatedRun {
        motion,
        rotations,
        log,
    })
}
