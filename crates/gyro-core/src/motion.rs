//! Static/dynamic motion detection with hysteresis and minimum dwell times.
//!
//! Works on the filtered, decimated rate minus the bias reference (the mean rate of the
//! last rest). A sample is *quiet* if `|rate - bias| ≤ exit_dps`.
//!
//! - Static → dynamic: a run of non-quiet samples lasting `min_motion_s` that reaches
//!   `|rate - bias| > enter_dps` at least once.
//! - A run that returns to quiet before that is dropped; if it never reached `enter_dps` it
//!   is folded into the rest (a small excursion of the rest level), otherwise its samples
//!   are discarded: a knock must not move the bias reference.
//! - A run that never reaches `enter_dps` but settles at a new level (`min_rest_s` of
//!   samples within `2 × exit_dps` of each other) is a bias change, not motion: that level
//!   becomes the rest. A slow movement, whose rate keeps rising by more than that per
//!   `min_rest_s` until it passes `enter_dps`, is not mistaken for one, however long its
//!   onset.
//! - Dynamic → static: `min_rest_s` of consecutive quiet samples.
//!
//! A movement spans from the last quiet sample before its run to the first quiet sample
//! after it; [`Phase`] tells an integrator, sample by sample, what to do so that exactly
//! that span is integrated, although both ends are only confirmed later.

use crate::error::{check_range, Error};
use crate::kahan::KahanSum;

/// Motion detector settings, in physical units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct MotionConfig {
    /// A movement must exceed this |rate − bias| (deg/s) at least once.
    pub enter_dps: f32,
    /// At or below this |rate − bias| (deg/s) a sample is quiet (≤ `enter_dps`).
    pub exit_dps: f32,
    /// Minimum duration of a run of non-quiet samples to count as a movement (s).
    pub min_motion_s: f32,
    /// Quiet time that ends a movement (s).
    pub min_rest_s: f32,
    /// Bias reference (deg/s) used until the first rest of `min_rest_s` has been seen.
    pub initial_bias_dps: f32,
}

impl Default for MotionConfig {
    /// Tuned for a CRM100 at 1 kHz, decimated to 50 Hz and low-passed at 12.5 Hz (the
    /// default [`crate::Config`]; white noise of 0.05–0.1 deg/s rms per input sample leaves
    /// 0.008–0.016 deg/s rms at the output, measured with `gyro-cli run --out` on a static
    /// log of that noise):
    ///
    /// - `exit_dps` 0.08 (above 4 σ of that noise): a smooth rotation starts and ends where
    ///   its rate crosses this level, so a lower level finds its ends closer to the truth.
    ///   A 90° rotation in 4 s with a raised-cosine rate is still below 0.1 deg/s for
    ///   60 ms after it started; at the former 0.3 deg/s the ends of such rotations were
    ///   missed by up to 0.11 s (the pipeline tests see at most 55 ms).
    /// - `enter_dps` 2.0: above the sensor's bias (up to ±1 deg/s) with margin. At
    ///   power-up, before a rest has measured the bias, the reference is
    ///   `initial_bias_dps`; with the former 1.0 a bias of 1 deg/s was taken for a
    ///   movement, and since no sample was then quiet, the movement never ended.
    fn default() -> Self {
        Self {
            enter_dps: 2.0,
            exit_dps: 0.08,
            min_motion_s: 0.06,
            min_rest_s: 0.2,
            initial_bias_dps: 0.0,
        }
    }
}

/// Whether the sensor is at rest or moving (confirmed state).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum MotionState {
    /// At rest: the angle is held.
    Static,
    /// Moving: the rate is integrated.
    Dynamic,
}

/// What one sample means for integration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Static and quiet: not integrated; a rest (bias) observation.
    Rest,
    /// Static, inside a run that may become a movement: integrate tentatively.
    Onset,
    /// The run is confirmed as a movement: integrate, keep everything tentative.
    /// `run` samples (this one included) belong to the movement.
    Started {
        /// Length of the confirming run in samples.
        run: u16,
    },
    /// The run was not a movement: drop what was integrated tentatively.
    Aborted,
    /// Dynamic and not quiet: integrate, keep everything tentative.
    Moving,
    /// Dynamic, first quiet sample: integrate and keep (a movement may end here).
    SettleFirst,
    /// Dynamic, further quiet samples: integrate tentatively.
    Settling,
    /// Rest confirmed: drop what was integrated since the first quiet sample.
    /// The movement ended `quiet - 1` samples ago.
    Ended {
        /// Length of the confirming quiet run in samples.
        quiet: u16,
    },
}

/// Running mean with compensated summation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Mean {
    sum: KahanSum,
    count: u32,
}

impl Mean {
    fn add(&mut self, x: f32) {
        self.sum.add(x);
        self.count = self.count.saturating_add(1);
    }
    fn merge(&mut self, other: &Mean) {
        self.sum.add(other.sum.value());
        self.count = self.count.saturating_add(other.count);
    }
    fn mean(&self) -> Option<f32> {
        (self.count > 0).then(|| self.sum.value() / self.count as f32)
    }
}

/// Motion detector state (settings converted to samples at the output rate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionDetector {
    enter_dps: f32,
    exit_dps: f32,
    min_motion: u16,
    min_rest: u16,
    state: MotionState,
    run: u16,
    run_reached_enter: bool,
    rest: Mean,
    run_mean: Mean,
    /// The latest stretch of the run within the level band (a candidate new rest level).
    level: Mean,
    level_min: f32,
    level_max: f32,
    bias_dps: f32,
    /// Mean |difference| of successive samples near the bias (deg/s): the rest noise the
    /// level band scales with (exponential average over about `1/NOISE_WEIGHT` samples).
    noise_dps: f32,
    /// The previous sample (deg/s), for `noise_dps`.
    previous_dps: f32,
}

/// Weight of one sample in the running `noise_dps`.
const NOISE_WEIGHT: f32 = 1.0 / 32.0;
/// The level band is at least this many `noise_dps` wide (for white noise low-passed like
/// the default pipeline, about 3.5 standard deviations each side).
const BAND_PER_NOISE: f32 = 8.0;
/// A level is never steady in fewer samples than this (a one-sample `min_rest` says
/// nothing about steadiness).
const MIN_LEVEL_SAMPLES: u16 = 3;
/// Before any rest has been seen, a steady level up to this many `enter_dps` from zero is
/// taken for the power-up bias rather than a movement.
const POWER_UP_BIAS_PER_ENTER: f32 = 5.0;

/// Whole samples covering `seconds` at `rate_hz`, at least 1.
fn samples(seconds: f32, rate_hz: f32) -> u16 {
    let n = libm::ceilf(seconds * rate_hz - 1e-3);
    if n < 1.0 {
        1
    } else if n > f32::from(u16::MAX) {
        u16::MAX
    } else {
        n as u16
    }
}

impl MotionDetector {
    /// Detector for samples arriving at `rate_hz`.
    pub fn try_new(config: &MotionConfig, rate_hz: f32) -> Result<Self, Error> {
        let exit = check_range("motion.exit_dps", config.exit_dps.into(), 0.0, 1e4)?;
        check_range("motion.enter_dps", config.enter_dps.into(), exit, 1e4)?;
        check_range("motion.min_motion_s", config.min_motion_s.into(), 0.0, 60.0)?;
        check_range("motion.min_rest_s", config.min_rest_s.into(), 0.0, 60.0)?;
        check_range(
            "motion.initial_bias_dps",
            config.initial_bias_dps.into(),
            -1e4,
            1e4,
        )?;
        check_range("output_rate_hz", rate_hz.into(), 1e-3, 1e6)?;
        Ok(Self {
            enter_dps: config.enter_dps,
            exit_dps: config.exit_dps,
            min_motion: samples(config.min_motion_s, rate_hz),
            min_rest: samples(config.min_rest_s, rate_hz),
            state: MotionState::Static,
            run: 0,
            run_reached_enter: false,
            rest: Mean::default(),
            run_mean: Mean::default(),
            level: Mean::default(),
            level_min: 0.0,
            level_max: 0.0,
            bias_dps: config.initial_bias_dps,
            noise_dps: 0.0,
            previous_dps: f32::NAN,
        })
    }

    /// The confirmed state.
    pub const fn state(&self) -> MotionState {
        self.state
    }

    /// The bias reference (deg/s) the thresholds are applied around.
    pub const fn bias_dps(&self) -> f32 {
        self.bias_dps
    }

    /// Quiet samples that end a movement (`min_rest_s` at the sample rate).
    pub(crate) const fn min_rest_samples(&self) -> u16 {
        self.min_rest
    }

    /// True if the state is finite (it always is for finite input).
    pub fn is_finite(&self) -> bool {
        self.bias_dps.is_finite()
            && self.noise_dps.is_finite()
            && self.rest.sum.is_finite()
            && self.run_mean.sum.is_finite()
            && self.level.sum.is_finite()
    }

    /// Mean rate over the current rest (deg/s) and its sample count, while static.
    pub fn rest_mean_dps(&self) -> Option<(f32, u32)> {
        match self.state {
            MotionState::Static => self.rest.mean().map(|m| (m, self.rest.count)),
            MotionState::Dynamic => None,
        }
    }

    /// Classify one (finite) sample.
    ///
    /// Besides the thresholds around the bias reference: a *level* (a stretch whose samples
    /// all lie within a band of `max(2 × exit_dps, 8 × noise)`) lasting `min_rest` samples
    /// (at least 3) is a rest if its mean is within `near` (`max(enter_dps / 4,
    /// 2 × exit_dps)`, at most `enter_dps`) of the
    /// bias (a bias that moved, or a noisier sensor than `exit_dps` allows for) and a slow
    /// movement if it is further (1–3 deg/s at the end of a tightening); before the first
    /// rest the bias is unknown, so a steady level up to `5 × enter_dps` is the rest (the
    /// power-up bias), not a movement.
    #[inline(always)]
    pub fn update(&mut self, rate_dps: f32) -> Phase {
        let deviation = libm::fabsf(rate_dps - self.bias_dps);
        let quiet = deviation <= self.exit_dps;
        let near_dps = self.near_dps();
        if deviation <= near_dps {
            self.observe_noise(rate_dps);
        }
        self.previous_dps = rate_dps;
        let bias_known = self.rest.count >= u32::from(self.min_rest);
        match self.state {
            MotionState::Static if quiet => self.static_quiet(rate_dps),
            MotionState::Static => self.static_run(rate_dps, deviation, near_dps, bias_known),
            MotionState::Dynamic if quiet => self.dynamic_quiet(rate_dps),
            MotionState::Dynamic => self.dynamic_moving(rate_dps, near_dps),
        }
    }

    /// A quiet sample while static: a rest sample, ending a run that was not a movement.
    #[inline(always)]
    fn static_quiet(&mut self, rate_dps: f32) -> Phase {
        let aborted = self.run > 0;
        if aborted {
            self.end_run();
        }
        self.add_rest(rate_dps);
        if aborted {
            Phase::Aborted
        } else {
            Phase::Rest
        }
    }

    /// A sample beyond `exit_dps` (by `deviation`) while static: the run goes on, and may
    /// turn out a bias change (a steady level within `near_dps`, or the power-up bias
    /// while the bias is not `bias_known`) or a movement.
    #[inline(always)]
    fn static_run(
        &mut self,
        rate_dps: f32,
        deviation: f32,
        near_dps: f32,
        bias_known: bool,
    ) -> Phase {
        self.run = self.run.saturating_add(1);
        self.run_reached_enter |= deviation > self.enter_dps;
        self.run_mean.add(rate_dps);
        self.track_level(rate_dps);
        let steady = self.level.count >= self.steady_samples();
        let level_dps = self.level.mean().unwrap_or(rate_dps);
        let level_near = libm::fabsf(level_dps - self.bias_dps) <= near_dps;
        let power_up =
            !bias_known && libm::fabsf(level_dps) <= POWER_UP_BIAS_PER_ENTER * self.enter_dps;
        // Before the first rest a run that is one steady level so far may still be
        // the power-up bias: it is not confirmed as a movement yet.
        let may_be_bias = power_up && self.level.count == u32::from(self.run);
        if steady && (level_near && !self.run_reached_enter || power_up) {
            // A bias change (or the power-up bias), not a movement: the new level
            // is the rest.
            self.rest = self.level;
            self.clear_run();
            self.refresh_bias();
            Phase::Aborted
        } else if self.run >= self.min_motion
            && (self.run_reached_enter && !may_be_bias || steady && !level_near)
        {
            let run = self.run;
            self.state = MotionState::Dynamic;
            self.clear_run();
            Phase::Started { run }
        } else {
            Phase::Onset
        }
    }

    /// A quiet sample while moving: the quiet run goes on, and ends the movement once it
    /// is `min_rest` long.
    #[inline(always)]
    fn dynamic_quiet(&mut self, rate_dps: f32) -> Phase {
        self.run = self.run.saturating_add(1);
        self.run_mean.add(rate_dps);
        self.track_level(rate_dps);
        if self.run >= self.min_rest {
            let quiet = self.run;
            self.state = MotionState::Static;
            self.rest = self.run_mean;
            self.clear_run();
            self.refresh_bias();
            Phase::Ended { quiet }
        } else if self.run == 1 {
            Phase::SettleFirst
        } else {
            Phase::Settling
        }
    }

    /// A sample beyond `exit_dps` while moving: still moving, unless the level has been
    /// steady within `near_dps` of the bias long enough to be the rest after it.
    #[inline(always)]
    fn dynamic_moving(&mut self, rate_dps: f32, near_dps: f32) -> Phase {
        self.run = 0;
        self.run_mean = Mean::default();
        self.track_level(rate_dps);
        let level_dps = self.level.mean().unwrap_or(rate_dps);
        if self.level.count >= self.steady_samples()
            && libm::fabsf(level_dps - self.bias_dps) <= near_dps
        {
            // A steady level near the bias, though not within `exit_dps` of it:
            // the rest after the movement, on a bias that moved or a noisy sensor.
            // This sample is the movement's end (the level was integrated: its
            // residual is small by `near`).
            self.state = MotionState::Static;
            self.rest = self.level;
            self.clear_run();
            self.refresh_bias();
            Phase::Ended { quiet: 1 }
        } else {
            Phase::Moving
        }
    }

    /// How far from the bias a steady level is still a rest (deg/s).
    fn near_dps(&self) -> f32 {
        // Comparisons rather than `max` and `min`, which also test for NaN: the settings
        // are finite (validated). Where the two forms could differ, in a zero's sign,
        // every use of this level is a comparison or the cap of a non-negative step (which
        // the noise average gives the same value either way).
        let (quarter, double) = (0.25 * self.enter_dps, 2.0 * self.exit_dps);
        let wider = if quarter > double { quarter } else { double };
        if wider < self.enter_dps {
            wider
        } else {
            self.enter_dps
        }
    }

    /// Samples a level must last to count as steady: `min_rest`, and at least a few.
    fn steady_samples(&self) -> u32 {
        u32::from(self.min_rest.max(MIN_LEVEL_SAMPLES))
    }

    /// Width of the level band (deg/s).
    fn band_dps(&self) -> f32 {
        (2.0 * self.exit_dps).max(BAND_PER_NOISE * self.noise_dps)
    }

    /// Update the running rest noise with a sample near the bias.
    fn observe_noise(&mut self, rate_dps: f32) {
        let step = libm::fabsf(rate_dps - self.previous_dps);
        if step.is_finite() {
            // One outlier (a knock) moves the average by a bounded amount.
            // `step.min(cap)` without its NaN test: the step is finite.
            let cap = 4.0 * self.near_dps();
            let step = if step < cap { step } else { cap };
            self.noise_dps += NOISE_WEIGHT * (step - self.noise_dps);
        }
    }

    fn add_rest(&mut self, rate_dps: f32) {
        self.rest.add(rate_dps);
        self.refresh_bias();
    }

    /// A run returned to quiet: fold a small excursion into the rest, drop a knock.
    fn end_run(&mut self) {
        if !self.run_reached_enter {
            self.rest.merge(&self.run_mean);
        }
        self.clear_run();
        self.refresh_bias();
    }

    fn clear_run(&mut self) {
        self.run = 0;
        self.run_reached_enter = false;
        self.run_mean = Mean::default();
        self.level = Mean::default();
    }

    /// Extend the current level by `rate_dps`, or start a new one if it would span more
    /// than the band.
    fn track_level(&mut self, rate_dps: f32) {
        let low = self.level_min.min(rate_dps);
        let high = self.level_max.max(rate_dps);
        if self.level.count == 0 || high - low > self.band_dps() {
            self.level = Mean::default();
            self.level_min = rate_dps;
            self.level_max = rate_dps;
        } else {
            self.level_min = low;
            self.level_max = high;
        }
        self.level.add(rate_dps);
    }

    fn refresh_bias(&mut self) {
        if self.rest.count >= u32::from(self.min_rest) {
            if let Some(mean) = self.rest.mean() {
                self.bias_dps = mean;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round thresholds, so that the tests read easily (the defaults are tuned elsewhere).
    fn config() -> MotionConfig {
        MotionConfig {
            enter_dps: 1.0,
            exit_dps: 0.3,
            ..MotionConfig::default()
        }
    }

    fn detector() -> MotionDetector {
        MotionDetector::try_new(&config(), 50.0).unwrap()
    }

    #[test]
    fn dwell_times_in_samples() {
        let d = detector();
        assert_eq!(d.min_motion, 3);
        assert_eq!(d.min_rest, 10);
    }

    #[test]
    fn a_short_spike_is_not_motion() {
        let mut d = detector();
        assert_eq!(d.update(5.0), Phase::Onset);
        assert_eq!(d.update(5.0), Phase::Onset);
        assert_eq!(d.update(0.0), Phase::Aborted);
        assert_eq!(d.state(), MotionState::Static);
    }

    #[test]
    fn movement_starts_and_ends() {
        let mut d = detector();
        for _ in 0..20 {
            assert_eq!(d.update(0.1), Phase::Rest);
        }
        assert!((d.bias_dps() - 0.1).abs() < 1e-6);
        assert_eq!(d.update(10.0), Phase::Onset);
        assert_eq!(d.update(10.0), Phase::Onset);
        assert_eq!(d.update(10.0), Phase::Started { run: 3 });
        assert_eq!(d.update(10.0), Phase::Moving);
        assert_eq!(d.update(0.2), Phase::SettleFirst);
        for _ in 0..8 {
            assert_eq!(d.update(0.2), Phase::Settling);
        }
        assert_eq!(d.update(0.2), Phase::Ended { quiet: 10 });
        assert_eq!(d.state(), MotionState::Static);
        // The new rest (the quiet run) becomes the bias reference.
        assert!((d.bias_dps() - 0.2).abs() < 1e-6);
    }

    #[test]
    fn slow_drift_between_thresholds_is_folded_into_rest() {
        let mut d = detector();
        for _ in 0..9 {
            assert_eq!(d.update(0.5), Phase::Onset);
        }
        assert_eq!(d.update(0.5), Phase::Aborted);
        assert!((d.bias_dps() - 0.5).abs() < 1e-6);
        assert_eq!(d.update(0.5), Phase::Rest);
    }

    #[test]
    fn a_bias_step_becomes_the_rest() {
        let mut d = detector();
        for _ in 0..50 {
            assert_eq!(d.update(0.0), Phase::Rest);
        }
        // The bias jumps by 0.6 deg/s: between the thresholds, and steady.
        for _ in 0..9 {
            assert_eq!(d.update(0.6), Phase::Onset);
        }
        assert_eq!(d.update(0.6), Phase::Aborted);
        // The new level replaces the old rest instead of being averaged with it.
        assert!((d.bias_dps() - 0.6).abs() < 1e-6, "{}", d.bias_dps());
        assert_eq!(d.update(0.6), Phase::Rest);
    }

    #[test]
    fn a_slow_onset_is_not_taken_for_a_bias_change() {
        let mut d = MotionDetector::try_new(
            &MotionConfig {
                enter_dps: 2.0,
                ..config()
            },
            50.0,
        )
        .unwrap();
        for _ in 0..50 {
            assert_eq!(d.update(0.0), Phase::Rest);
        }
        // A slow rotation: the rate creeps up (4 deg/s², more than `2 × exit_dps` per
        // `min_rest`) for 21 samples, twice `min_rest`, before it passes `enter_dps`; it is
        // still one movement from its first non-quiet sample.
        let mut started = None;
        for k in 1..=40 {
            let phase = d.update(0.35 + 0.08 * k as f32);
            assert_ne!(phase, Phase::Aborted, "sample {k}");
            if let Phase::Started { run } = phase {
                started = Some((k, run));
                break;
            }
        }
        let (k, run) = started.expect("the slow movement starts");
        assert_eq!(u32::from(run), k);
        assert_eq!(d.bias_dps(), 0.0);
    }

    #[test]
    fn a_knock_does_not_move_the_bias() {
        let mut d = MotionDetector::try_new(
            &MotionConfig {
                min_motion_s: 0.2,
                ..config()
            },
            50.0,
        )
        .unwrap();
        for _ in 0..20 {
            assert_eq!(d.update(0.0), Phase::Rest);
        }
        // Shorter than `min_motion`: not a movement, and not part of the rest either.
        for _ in 0..5 {
            assert_eq!(d.update(50.0), Phase::Onset);
        }
        assert_eq!(d.update(0.0), Phase::Aborted);
        assert_eq!(d.bias_dps(), 0.0);
        // So a later movement still ends.
        for _ in 0..10 {
            d.update(20.0);
        }
        assert_eq!(d.state(), MotionState::Dynamic);
        for _ in 0..10 {
            d.update(0.0);
        }
        assert_eq!(d.state(), MotionState::Static);
    }

    /// Deterministic noise in [-amplitude, amplitude] (a fixed pseudo-random sequence).
    fn noise(k: u32, amplitude: f32) -> f32 {
        let x = k.wrapping_mul(2_654_435_761) >> 8;
        amplitude * ((x % 2001) as f32 / 1000.0 - 1.0)
    }

    /// The default thresholds (exit 0.08, enter 2.0 deg/s) at 50 Hz.
    fn default_detector() -> MotionDetector {
        MotionDetector::try_new(&MotionConfig::default(), 50.0).unwrap()
    }

    #[test]
    fn slow_turns_are_movements_not_bias() {
        for slow_dps in [1.0_f32, 1.5, 3.0, -1.0, -3.0] {
            let mut d = default_detector();
            for k in 0..100 {
                d.update(0.1 + noise(k, 0.02));
            }
            assert!((d.bias_dps() - 0.1).abs() < 0.01);
            // The last degrees of a tightening: a steady slow rate for 2 s.
            let mut started = false;
            for k in 0..100 {
                started |= matches!(
                    d.update(0.1 + slow_dps + noise(k, 0.02)),
                    Phase::Started { .. }
                );
            }
            assert!(started, "{slow_dps} deg/s");
            assert_eq!(d.state(), MotionState::Dynamic, "{slow_dps} deg/s");
            assert!(
                (d.bias_dps() - 0.1).abs() < 0.01,
                "{slow_dps}: bias {}",
                d.bias_dps()
            );
            // And it ends at the rest after it.
            for k in 0..30 {
                d.update(0.1 + noise(k, 0.02));
            }
            assert_eq!(d.state(), MotionState::Static, "{slow_dps} deg/s");
        }
    }

    #[test]
    fn a_power_up_bias_of_a_few_deg_per_s_is_the_rest() {
        for bias in [3.0_f32, -4.0, 8.0] {
            let mut d = default_detector();
            for k in 0..50 {
                let phase = d.update(bias + noise(k, 0.02));
                assert!(
                    !matches!(phase, Phase::Started { .. }),
                    "{bias}: sample {k}"
                );
            }
            assert_eq!(d.state(), MotionState::Static);
            assert!(
                (d.bias_dps() - bias).abs() < 0.02,
                "{bias}: {}",
                d.bias_dps()
            );
            // A movement is then found and ends.
            for _ in 0..20 {
                d.update(bias + 50.0);
            }
            assert_eq!(d.state(), MotionState::Dynamic);
            for k in 0..20 {
                d.update(bias + noise(k, 0.02));
            }
            assert_eq!(d.state(), MotionState::Static);
        }
        // Far beyond a plausible bias, a steady rate at power-up is a movement.
        let mut d = default_detector();
        for _ in 0..50 {
            d.update(40.0);
        }
        assert_eq!(d.state(), MotionState::Dynamic);
    }

    /// A sensor noisier than `exit_dps` allows for, whose rest after a movement sits 0.1
    /// deg/s off the rest before it (as on the rasteiro MPU6500 recordings): the movement
    /// still ends.
    #[test]
    fn a_noisy_rest_off_the_old_bias_ends_the_movement() {
        let mut d = default_detector();
        for k in 0..100 {
            d.update(noise(k, 0.07));
        }
        assert_eq!(d.state(), MotionState::Static);
        for _ in 0..30 {
            d.update(150.0);
        }
        assert_eq!(d.state(), MotionState::Dynamic);
        let mut ended = None;
        for k in 0..60 {
            if let Phase::Ended { quiet } = d.update(0.1 + noise(k + 7, 0.07)) {
                ended = Some((k, quiet));
                break;
            }
        }
        let (k, _) = ended.expect("the movement ends");
        assert!(k < 20, "ended after {k} samples");
        assert!((d.bias_dps() - 0.1).abs() < 0.05, "{}", d.bias_dps());
    }

    #[test]
    fn invalid_settings_refused() {
        let bad = MotionConfig {
            enter_dps: 0.1,
            exit_dps: 0.3,
            ..MotionConfig::default()
        };
        assert_eq!(
            MotionDetector::try_new(&bad, 50.0),
            Err(Error::OutOfRange("motion.enter_dps"))
        );
    }
}
