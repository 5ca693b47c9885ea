//! The real-time pipeline: decimate → low-pass → detect motion → integrate → compensate.

use crate::butterworth::{Butterworth, SosDesign};
use crate::correction::{Correction, Corrector};
use crate::decimator::Decimator;
use crate::decision::Tightening;
use crate::error::{check_range, Error};
use crate::gauss_markov::GaussMarkov;
use crate::integrator::Integrator;
use crate::kahan::KahanSum;
use crate::kalman::{KalmanBias, KalmanConfig};
use crate::motion::{MotionConfig, MotionDetector, MotionState, Phase};
use crate::sos::{Sos, SosState};

/// Which error compensation produces [`Output::angle_deg`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Compensation {
    /// The integrated rate as it is.
    None,
    /// The paper's error model: subtract the modelled misalignment o(t_m) per movement.
    Paper,
    /// The Kalman form: Gauss-Markov bias with zero-rate updates at rest.
    #[default]
    Kalman,
}

/// Everything the pipeline is configured by (a model file on the host).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct Config {
    /// Input sample rate (Hz).
    pub sample_rate_hz: f32,
    /// Target output rate (Hz); the decimation factor is `round(sample_rate / output_rate)`
    /// (at least 1), so the actual output rate is `sample_rate / factor`.
    pub output_rate_hz: f32,
    /// Input samples with |rate| above this (deg/s) are rejected as implausible.
    pub max_abs_rate_dps: f32,
    /// Low-pass applied at the output rate.
    pub filter: Butterworth,
    /// Motion detection.
    pub motion: MotionConfig,
    /// Which compensation gives the angle.
    pub compensation: Compensation,
    /// Parameters of the paper's error model.
    pub paper: GaussMarkov,
    /// Parameters of the Kalman form.
    pub kalman: KalmanConfig,
    /// Correction of scale and temperature errors, applied to every accepted input sample
    /// (identity by default, and when absent from a model file). Left out when serialized
    /// as the identity, so that files without a correction stay readable by builds that
    /// predate it.
    #[cfg_attr(
        feature = "serde",
        serde(skip_serializing_if = "Correction::is_exactly_identity")
    )]
    pub correction: Correction,
    /// The sensor's full-scale range (deg/s), if known: a movement during which a reading
    /// reaches it (within [`RANGE_MARGIN`]) is flagged [`Movement::saturated`]. Unknown by
    /// default (then only a clip plateau flags one; see [`Movement::saturated`]). Left out
    /// when serialized as unknown.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub range_dps: Option<f32>,
    /// The tightening window movements are judged against ([`crate::decide`]), if any.
    /// The pipeline only validates it (it keeps no state for it): whoever receives a
    /// [`Movement`] decides. Left out when serialized as none.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub tightening: Option<Tightening>,
}

/// A reading within this fraction of [`Config::range_dps`] counts as reaching the range
/// (0.5%: 36 of the CRM100's 7200 full-scale counts, far above its noise).
pub const RANGE_MARGIN: f32 = 0.005;

/// Consecutive identical readings, at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`], that make a clip
/// plateau. On the nominal CRM100 (white noise 0.15 deg/s per sample, step 1/24 deg/s) two
/// readings of a steady rate are equal with probability about 0.08, and with a 0.2 deg/s
/// step about 0.4; 16 in a row then happen about 0.4^15 ≈ 1e-6 of the time at a steady
/// peak. An output step much coarser than the noise makes a slow peak flat: set
/// [`Config::range_dps`] for such a sensor rather than rely on the plateau.
pub const CLIP_PLATEAU_SAMPLES: u8 = 16;

/// How long (s) identical readings last, at least, to make a clip plateau
/// ([`Pipeline::clip_plateau_samples`]: [`CLIP_PLATEAU_SAMPLES`] readings up to 1 kHz, 128
/// at 8 kHz). Above 1 kHz, 16 readings are shorter than the filtered rate's step from one
/// output to the next: a low-noise gyro holds a reading that long on the slope into a
/// smooth peak, while the filter is still catching up, and the lead would read that as a
/// clip (at 8 kHz a turn easing into 60 deg/s was).
pub const CLIP_PLATEAU_SHORT_S: f32 = 0.016;

/// The least |rate| (deg/s) a clip plateau sits at: far above any gyro's bias, so that a
/// rest on a quantised output (the same reading again and again) is never one.
pub const CLIP_PLATEAU_MIN_DPS: f32 = 30.0;

/// How far (deg/s) a clip plateau's level must stand beyond the pipeline's filtered rate
/// of the block before, toward the plateau's sign, for the plateau to count before it
/// lasts [`CLIP_PLATEAU_LONG_S`]: a clip cuts off a rate still on its way up, which the
/// filter, some 30 ms behind, has not caught; a gyro whose own low-pass
/// leaves its output steadier than its step (a smooth peak, a steady turn) repeats a
/// reading at the rate the filter already has. Measured on simulated 1 kHz bench runs
/// (CRM100 step 1/24 deg/s, 5 and 15 Hz low-pass, 48 runs of 60 s each): such repeats
/// stood at most 0.63 deg/s beyond the filtered rate; clips at 120 deg/s at least 2.2.
pub const CLIP_PLATEAU_LEAD_DPS: f32 = 1.0;

/// How long (s) identical readings (at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`]) last to make a
/// clip plateau whatever the filtered rate ([`Pipeline::clip_plateau_long_samples`]
/// readings). A clip reached on a slowly rising rate stands less than
/// [`CLIP_PLATEAU_LEAD_DPS`] beyond the filtered rate (on the 1 kHz runs above, 75 deg/s
/// clips of bench turns peaking up to 81 deg/s, losing up to 1.6°, stood 0.15–0.8 deg/s
/// beyond it), but it lasts: those that passed the clip by 1 deg/s lasted at least 142 ms,
/// while the low-passed repeats lasted at most 76 ms. In time rather than readings: how
/// long a smooth peak or a clip lasts is set by the motion, not by the sample rate.
pub const CLIP_PLATEAU_LONG_S: f32 = 0.128;

impl Default for Config {
    /// 1 kHz in, 50 Hz out, 2nd-order Butterworth at 12.5 Hz, Kalman compensation.
    ///
    /// The cutoff keeps hand motion (below ~5 Hz): the final angle of a 90° rotation in
    /// 0.8 s stays within 0.05° of the unfiltered one (a pipeline test checks it; about
    /// 0.001° is seen). 12.5 Hz rather than lower because a 2nd-order Butterworth rings:
    /// at 10 Hz its undershoot after a fast stop (0.4–0.5 deg/s) kept the rate outside
    /// `motion.exit_dps` long enough to find ends of fast rotations up to 64 ms late; at
    /// 12.5 Hz starts and ends stay within 55 ms on bench-like runs (a test checks 60 ms).
    /// Noise costs little: the boxcar decimation has already removed most of it.
    ///
    /// Kalman compensation by default: it needs no calibration (the bias comes from the
    /// rests), whereas the paper's model is only as good as its fitted parameters and
    /// with the default zero model equals no compensation.
    fn default() -> Self {
        Self {
            sample_rate_hz: 1000.0,
            output_rate_hz: 50.0,
            max_abs_rate_dps: 1.0e4,
            filter: Butterworth {
                order: 2,
                cutoff_hz: 12.5,
            },
            motion: MotionConfig::default(),
            compensation: Compensation::Kalman,
            paper: GaussMarkov::default(),
            kalman: KalmanConfig::default(),
            correction: Correction::IDENTITY,
            range_dps: None,
            tightening: None,
        }
    }
}

impl Config {
    /// The decimation factor this configuration implies.
    pub fn decimation_factor(&self) -> Result<u16, Error> {
        let input = check_range("sample_rate_hz", self.sample_rate_hz.into(), 1e-3, 1e6)?;
        let output = check_range("output_rate_hz", self.output_rate_hz.into(), 1e-3, input)?;
        let factor = libm::round(input / output);
        if factor > f64::from(u16::MAX) {
            return Err(Error::OutOfRange("output_rate_hz"));
        }
        Ok((factor as u16).max(1))
    }

    /// The actual output rate (Hz): the input rate over the decimation factor.
    pub fn effective_output_rate_hz(&self) -> Result<f32, Error> {
        Ok(self.sample_rate_hz / f32::from(self.decimation_factor()?))
    }
}

/// A movement start or end, reported once at the sample that confirms it.
///
/// Movement times are on the input's time line: the time of the output sample that
/// bounds the movement minus the low-pass filter's group delay at DC
/// ([`Pipeline::filter_delay_s`]), by which the filtered rate lags the input. Movement
/// indices are those output samples themselves, counted from 0 at the pipeline's first
/// output: the samples whose angles bound the movement, so that a host holding the output
/// series needs no search by time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A movement was confirmed; it started at `start_time_s` (its last quiet sample).
    MovementStarted {
        /// Time of the movement's start (s), on the input's time line.
        start_time_s: f64,
        /// Index of the output sample the movement starts at (its last quiet sample).
        start_index: u32,
    },
    /// A rest was confirmed after a movement.
    MovementEnded(Movement),
}

/// One movement, from its last quiet sample before to its first quiet sample after.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Movement {
    /// Start time (s), on the input's time line (see [`Event`]).
    pub start_time_s: f64,
    /// End time (s), on the input's time line (see [`Event`]).
    pub end_time_s: f64,
    /// Index of the output sample the movement starts at (its last quiet sample).
    pub start_index: u32,
    /// Index of the output sample the movement ends at (its first quiet sample).
    pub end_index: u32,
    /// Angle turned, with the configured compensation (deg).
    pub angle_deg: f32,
    /// Angle turned, uncompensated (deg).
    pub raw_angle_deg: f32,
    /// A reading during the movement (its confirming run included) reached the sensor's
    /// range ([`Config::range_dps`], within [`RANGE_MARGIN`]) or sat on a clip plateau
    /// ([`Pipeline::clip_plateau_samples`] identical readings at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`],
    /// standing [`CLIP_PLATEAU_LEAD_DPS`] beyond the filtered rate, or lasting
    /// [`CLIP_PLATEAU_LONG_S`]): the angle is then a lower bound of the turn. Reaching the
    /// range does not count once a reading has gone beyond it by more than
    /// [`RANGE_MARGIN`] (since the start, up to the movement's end): a sensor reads at most
    /// its range, so that range is not this sensor's ([`Pipeline::range_contradicted`]); a
    /// clip plateau still counts.
    pub saturated: bool,
    /// Standard deviation of `angle_deg` (deg), in Kalman mode: what the filter's bias
    /// uncertainty and rate noise make of this movement's angle (the input to a
    /// guard-banded decision, [`crate::decide`]).
    pub angle_std_deg: Option<f32>,
}

/// One output sample, at the decimated rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    /// Centre of the input block this sample averages (s).
    pub time_s: f64,
    /// Decimated, filtered rate (deg/s).
    pub rate_dps: f32,
    /// Confirmed motion state.
    pub motion: MotionState,
    /// A movement start or end confirmed at this sample.
    pub event: Option<Event>,
    /// Angle with the configured compensation (deg).
    pub angle_deg: f32,
    /// Angle without compensation (deg).
    pub raw_angle_deg: f32,
    /// Standard deviation of `angle_deg` (deg), in Kalman mode.
    pub angle_std_deg: Option<f32>,
    /// Current bias estimate (deg/s): the Kalman estimate, or the rest mean otherwise.
    pub bias_dps: f32,
}

/// The movement in progress.
///
/// The first quiet sample is kept as an index and a time in separate fields rather than an
/// `Option<(u32, f64)>`, whose tag and padding cost 8 bytes of the state budget.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Track {
    start_time_s: f64,
    /// Time of the first quiet sample; meaningful only with `settle_index`.
    settle_time_s: f64,
    start_index: u32,
    /// Output index of the first quiet sample, once settling.
    settle_index: Option<u32>,
    raw_at_start_deg: f32,
    angle_at_start_deg: f32,
    /// What the clip watch saw during the movement ([`CLIP_RANGE`], [`CLIP_PLATEAU`]; in
    /// the struct's padding).
    saturation: u8,
}

impl Track {
    /// Output index and time of the first quiet sample, once settling.
    fn settle(&self) -> Option<(u32, f64)> {
        self.settle_index.map(|index| (index, self.settle_time_s))
    }

    fn set_settle(&mut self, settle: Option<(u32, f64)>) {
        self.settle_index = settle.map(|(index, _)| index);
        self.settle_time_s = settle.map_or(0.0, |(_, time_s)| time_s);
    }
}

/// Rest samples on their way to the Kalman filter's zero-rate update, held back in blocks.
///
/// The quiet samples just before a movement already carry the start of its rate (below
/// `exit_dps`, but not zero); used as bias observations they pull the bias estimate
/// towards the movement's rate, and the error is then integrated over the whole movement.
/// So rest samples are collected in blocks of `min_rest_s` (as many samples as end a
/// movement): a block is released only when the next one is complete, so every sample has
/// waited at least `min_rest_s`, and both pending blocks are dropped when a movement
/// starts. A released block is one update with its mean and R/n, which is what n updates
/// of a constant bias amount to. Two running means instead of a delay line keep the
/// pipeline's state small.
#[derive(Clone, Copy, Debug, PartialEq)]
struct RestBlocks {
    fresh_sum: KahanSum,
    aged_sum: KahanSum,
    // The counts side by side: 4 bytes less than (sum, count) pairs with their padding.
    fresh_count: u16,
    aged_count: u16,
    block: u16,
    /// No block released since the last movement (in the struct's padding).
    after_movement: bool,
}

impl RestBlocks {
    fn new(block: u16) -> Self {
        Self {
            fresh_sum: KahanSum::ZERO,
            aged_sum: KahanSum::ZERO,
            fresh_count: 0,
            aged_count: 0,
            block,
            after_movement: false,
        }
    }

    /// Add a rest sample; returns a released block's (mean, count), the mean of the block
    /// completed after it, and whether it is the first since a movement.
    fn push(&mut self, rate_dps: f32) -> Option<(f32, u16, f32, bool)> {
        self.fresh_sum.add(rate_dps);
        self.fresh_count += 1;
        if self.fresh_count < self.block.max(1) {
            return None;
        }
        let next_mean = self.fresh_sum.value() / f32::from(self.fresh_count);
        let sum = core::mem::replace(&mut self.aged_sum, self.fresh_sum);
        let count = core::mem::replace(&mut self.aged_count, self.fresh_count);
        self.fresh_sum = KahanSum::ZERO;
        self.fresh_count = 0;
        if count == 0 {
            return None;
        }
        let first = core::mem::replace(&mut self.after_movement, false);
        Some((sum.value() / f32::from(count), count, next_mean, first))
    }

    /// Drop the pending blocks (a movement starts).
    fn clear(&mut self) {
        *self = Self {
            after_movement: true,
            ..Self::new(self.block)
        };
    }

    fn is_finite(&self) -> bool {
        self.fresh_sum.is_finite() && self.aged_sum.is_finite()
    }
}

/// How many whole blocks [`Pipeline::push_block`] sums side by side (half as many when
/// fewer are at hand): 8 lanes, two 4-lane vector registers of sums, whose chains of
/// additions overlap.
const SIDE_BY_SIDE: usize = 8;

/// Clip watch flag: a reading reached the range.
const CLIP_RANGE: u8 = 1;
/// Clip watch flag: a reading completed a clip plateau.
const CLIP_PLATEAU: u8 = 2;
/// Clip watch flag: a reading went beyond the range by more than [`RANGE_MARGIN`] (kept
/// for the whole run: the range is not this sensor's).
const CLIP_BEYOND: u8 = 4;
/// Clip watch flag, never kept: a reading is the [`Pipeline::clip_plateau_samples`]-th or later of
/// identical readings at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`], which [`Pipeline::plateau`]
/// turns into [`CLIP_PLATEAU`] or drops.
const CLIP_REPEATS: u8 = 8;
/// The flags of one stretch of readings that go to the movement in progress.
const CLIP_PENDING: u8 = CLIP_RANGE | CLIP_PLATEAU;
/// |reading| beyond which the range is contradicted, as a multiple of the level at which
/// it counts as reached: `(1 + RANGE_MARGIN) / (1 − RANGE_MARGIN)`.
const BEYOND_FACTOR: f32 = (1.0 + RANGE_MARGIN) / (1.0 - RANGE_MARGIN);

/// Whether a reading of magnitude `magnitude_dps` goes beyond a sensor range of
/// `range_dps` by more than [`RANGE_MARGIN`]: a sensor reads at most its range, so such a
/// reading shows the range is not this sensor's ([`Pipeline::range_contradicted`]). The
/// pipeline's own test, in its arithmetic.
pub fn beyond_range(range_dps: f32, magnitude_dps: f32) -> bool {
    let levels = ClipLevels::at(range_dps * (1.0 - RANGE_MARGIN), u16::MAX);
    range_flags(levels, magnitude_dps) & CLIP_BEYOND != 0
}

/// The |reading| levels the clip watch compares with, worked out once per call rather
/// than per reading.
#[derive(Clone, Copy)]
struct ClipLevels {
    /// A reading at or above it reaches the range.
    reach_dps: f32,
    /// A reading above it goes beyond the range.
    beyond_dps: f32,
    /// Identical readings in a row that may make a clip plateau.
    plateau_samples: u16,
}

impl ClipLevels {
    /// The levels of a range reached at `reach_dps` (infinite: no range), with plateaus of
    /// `plateau_samples` readings.
    #[inline(always)]
    fn at(reach_dps: f32, plateau_samples: u16) -> Self {
        Self {
            reach_dps,
            beyond_dps: reach_dps * BEYOND_FACTOR,
            plateau_samples,
        }
    }
}

/// Readings at `input_rate_hz` that last `duration_s`, at least [`CLIP_PLATEAU_SAMPLES`]
/// and at most 65 535 (the run counter's limit).
fn plateau_samples(duration_s: f32, input_rate_hz: f32) -> u16 {
    // `as` saturates at 65 535 (and takes NaN, which a validated rate never is, to 0).
    (libm::roundf(duration_s * input_rate_hz) as u16).max(u16::from(CLIP_PLATEAU_SAMPLES))
}

/// Whether flags `seen` during a movement make it saturated: a clip plateau, or the range
/// reached while no reading has gone beyond it.
#[inline(always)]
fn saturated_by(seen: u8) -> bool {
    (seen & CLIP_PLATEAU != 0) | ((seen & CLIP_RANGE != 0) & (seen & CLIP_BEYOND == 0))
}

/// The range flags of a reading of magnitude `magnitude`: [`CLIP_RANGE`] if it reaches
/// the range, and [`CLIP_BEYOND`] too if it goes beyond it by more than the margin.
#[inline(always)]
fn range_flags(levels: ClipLevels, magnitude: f32) -> u8 {
    u8::from(magnitude >= levels.reach_dps) | (u8::from(magnitude > levels.beyond_dps) << 2)
}

/// One reading through the clip watch: `last` and `run` (the last reading and how many
/// times in a row it came, up to 65 535) move on; its flags:
/// whether it reaches the range or goes beyond it ([`range_flags`]), or is one of enough
/// identical readings to make a clip plateau ([`CLIP_REPEATS`], for
/// [`Pipeline::plateau`]). Judged on the reading, before correction.
#[inline(always)]
fn clip_seen(levels: ClipLevels, last: &mut f32, run: &mut u16, reading_dps: f32) -> u8 {
    // Without branches: whether a reading repeats is a coin toss on a quantised sensor.
    let repeat = u16::from(reading_dps == *last);
    *run = (run.saturating_add(1) & 0_u16.wrapping_sub(repeat)) | (1 - repeat);
    *last = reading_dps;
    let magnitude = libm::fabsf(reading_dps);
    range_flags(levels, magnitude)
        | (u8::from((*run >= levels.plateau_samples) & (magnitude >= CLIP_PLATEAU_MIN_DPS)) << 3)
}

/// Where the clip watch ends over readings none of which repeats the one before it (the
/// first may repeat the watch's `last_dps`): the first reading's plateau flag (its run
/// of repeats is the only one that may reach [`CLIP_PLATEAU_SAMPLES`]), the last reading
/// and its run. `None` if some reading after the first repeats the one before, or if
/// there are none.
#[inline(always)]
fn distinct_run(
    rates_dps: &[f32],
    last_dps: f32,
    run: u16,
    plateau_samples: u16,
) -> Option<DistinctRun> {
    let (&first, rest) = rates_dps.split_first()?;
    // Without early exit, so that the comparisons go in vector lanes.
    let distinct = rates_dps
        .iter()
        .zip(rest)
        .fold(true, |distinct, (&before, &x)| distinct & (x != before));
    if !distinct {
        return None;
    }
    let (mut last, mut run) = (last_dps, run);
    let levels = ClipLevels::at(f32::INFINITY, plateau_samples);
    let first_clipped = clip_seen(levels, &mut last, &mut run, first);
    Some(DistinctRun {
        first_clipped,
        last_dps: rates_dps[rates_dps.len() - 1],
        run: if rest.is_empty() { run } else { 1 },
    })
}

/// The sums of `f` of the samples of whole blocks (`rows`, of the first's length), side by
/// side, each in its samples' order. The samples are read 4 of a block at a time: one
/// load for 4 values, which shuffles then turn into 4 columns of the lanes. The rows cut
/// to one length up front leave no bounds check in the loop.
#[inline(always)]
fn column_sums<const LANES: usize>(rows: &[&[f32]; LANES], f: impl Fn(f32) -> f32) -> [f32; LANES] {
    let factor = rows.first().map_or(0, |row| row.len());
    let rows: [&[f32]; LANES] = core::array::from_fn(|k| &rows[k][..factor]);
    let mut sums = [0.0_f32; LANES];
    let whole = factor / 4;
    for q in 0..whole {
        let quads: [[f32; 4]; LANES] = core::array::from_fn(|k| {
            let quad = &rows[k][4 * q..4 * q + 4];
            [quad[0], quad[1], quad[2], quad[3]]
        });
        for j in 0..4 {
            for (sum, quad) in sums.iter_mut().zip(&quads) {
                *sum += f(quad[j]);
            }
        }
    }
    for i in 4 * whole..factor {
        for (sum, row) in sums.iter_mut().zip(&rows) {
            *sum += f(row[i]);
        }
    }
    sums
}

/// See [`distinct_run`].
struct DistinctRun {
    first_clipped: u8,
    last_dps: f32,
    run: u16,
}

/// Group delay at DC of a cascade (output samples): for each section `B/A`,
/// `Σ k b_k / Σ b_k − Σ k a_k / Σ a_k`. Zero if not finite (no DC gain).
fn dc_group_delay_samples(design: &SosDesign) -> f64 {
    let delay: f64 = design
        .sections()
        .iter()
        .map(|&[b0, b1, b2, a0, a1, a2]| {
            (b1 + 2.0 * b2) / (b0 + b1 + b2) - (a1 + 2.0 * a2) / (a0 + a1 + a2)
        })
        .sum();
    if delay.is_finite() {
        delay
    } else {
        0.0
    }
}

/// The pipeline. Push input samples; every `decimation_factor`-th push returns an output.
/// [`Pipeline::push_block`] takes them in blocks, with the same outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Pipeline {
    max_abs_rate_dps: f32,
    /// |reading| at which the range counts as reached (infinite if unknown).
    clip_level_dps: f32,
    /// The last accepted reading and how many times in a row it came (up to the plateau).
    clip_last_dps: f32,
    clip_run: u16,
    /// Identical readings that make a clip plateau ([`Self::clip_plateau_samples`]).
    clip_plateau_samples: u16,
    /// The clip watch's flags: [`CLIP_RANGE`] and [`CLIP_PLATEAU`] seen since the last
    /// output step, or during the run that may become a movement; [`CLIP_BEYOND`] once
    /// seen, for good.
    clip_flags: u8,
    corrector: Corrector,
    /// The correction is not the identity: with the identity (the default) the per-sample
    /// path skips it, since it would return every accepted reading unchanged (in the one
    /// byte the state's alignment leaves free).
    corrects: bool,
    compensation: Compensation,
    paper: GaussMarkov,
    filter_delay_s: f64,
    decimator: Decimator,
    sos: Sos,
    sos_state: SosState,
    detector: MotionDetector,
    raw: Integrator,
    corrected: Integrator,
    kalman: KalmanBias,
    rest_blocks: RestBlocks,
    kalman_correction: KahanSum,
    paper_total: KahanSum,
    track: Option<Track>,
    block_start_time_s: f64,
    last_time_s: f64,
    /// The previous output step's rate and corrected rate; meaningful from index 1 on
    /// (a tuple rather than an `Option`, whose tag costs 4 bytes of the state budget).
    previous: (f32, f32),
    index: u32,
    rejected: u32,
}

impl Pipeline {
    /// Build a pipeline from a validated `config`.
    pub fn try_new(config: &Config) -> Result<Self, Error> {
        let factor = config.decimation_factor()?;
        check_range(
            "max_abs_rate_dps",
            config.max_abs_rate_dps.into(),
            1e-3,
            1e30,
        )?;
        let output_rate_hz = config.effective_output_rate_hz()?;
        let design = config.filter.design(output_rate_hz.into())?;
        let sos = design.to_sos();
        config.paper.validate()?;
        let output_period_s = 1.0 / output_rate_hz;
        let detector = MotionDetector::try_new(&config.motion, output_rate_hz)?;
        if let Some(tightening) = &config.tightening {
            tightening.validate()?;
        }
        // As `clip_plateau_long_samples` works it out, from the factor and the period.
        let input_rate_hz = f32::from(factor) / output_period_s;
        let clip_level_dps = match config.range_dps {
            Some(range_dps) => {
                check_range("range_dps", range_dps.into(), 1e-3, 1e30)?;
                range_dps * (1.0 - RANGE_MARGIN)
            }
            None => f32::INFINITY,
        };
        Ok(Self {
            max_abs_rate_dps: config.max_abs_rate_dps,
            clip_level_dps,
            clip_last_dps: f32::NAN,
            clip_run: 0,
            clip_plateau_samples: plateau_samples(CLIP_PLATEAU_SHORT_S, input_rate_hz),
            clip_flags: 0,
            corrector: Corrector::try_new(&config.correction)?,
            corrects: !config.correction.is_identity(),
            compensation: config.compensation,
            paper: config.paper,
            filter_delay_s: dc_group_delay_samples(&design) * f64::from(output_period_s),
            decimator: Decimator::try_new(factor)?,
            sos,
            sos_state: SosState::new(),
            detector,
            raw: Integrator::new(),
            corrected: Integrator::new(),
            kalman: KalmanBias::try_new(&config.kalman, output_period_s)?,
            rest_blocks: RestBlocks::new(detector.min_rest_samples()),
            kalman_correction: KahanSum::ZERO,
            paper_total: KahanSum::ZERO,
            track: None,
            block_start_time_s: f64::NAN,
            last_time_s: f64::NAN,
            previous: (0.0, 0.0),
            index: 0,
            rejected: 0,
        })
    }

    /// The compensation producing [`Output::angle_deg`].
    pub const fn compensation(&self) -> Compensation {
        self.compensation
    }

    /// Output sample period (s).
    pub const fn output_period_s(&self) -> f32 {
        // The Kalman filter's step: one copy of the period in the state.
        self.kalman.dt_s()
    }

    /// Group delay of the low-pass filter at DC (s): how far the filtered rate, and the
    /// movement boundaries found on it, lag the input. Movement times are corrected by it.
    pub const fn filter_delay_s(&self) -> f64 {
        self.filter_delay_s
    }

    /// Input samples rejected so far (non-finite or implausible), each replaced by the
    /// last valid rate so that timing and block sizes stay intact.
    pub const fn rejected_samples(&self) -> u32 {
        self.rejected
    }

    /// True if all internal state is finite (it always should be).
    pub fn is_finite(&self) -> bool {
        self.sos_state.is_finite()
            && self.detector.is_finite()
            && self.raw.is_finite()
            && self.corrected.is_finite()
            && self.kalman.is_finite()
            && self.kalman_correction.is_finite()
            && self.paper_total.is_finite()
            && self.rest_blocks.is_finite()
    }

    /// The correction in use, with its temperature state.
    pub const fn corrector(&self) -> &Corrector {
        &self.corrector
    }

    /// Push one input sample: `time_s` (s) and `rate_dps` (deg/s).
    ///
    /// The configured [`Correction`]'s scale and asymmetry are applied; its temperature
    /// terms are not (as if ΔT were 0): use [`Self::push_with_temperature`] where the
    /// sensor's temperature is known. [`Self::push_block`] takes many samples at once, with
    /// the same outputs.
    #[inline(always)]
    pub fn push(&mut self, time_s: f64, rate_dps: f32) -> Option<Output> {
        self.segment::<false>(&[time_s], &[rate_dps], &[])
    }

    /// Push one input sample with the sensor's temperature `temperature_c` (°C): the whole
    /// [`Correction`] is applied, its temperature terms included.
    ///
    /// A temperature that is not finite or not plausible (outside
    /// [`crate::TEMPERATURE_RANGE_C`]) is ignored: the last valid one stays in use, and until
    /// one has been seen the temperature terms are 0. The first valid temperature is the
    /// reference of ΔT unless the correction sets one (`temperature_ref_c`). With the identity
    /// correction this gives exactly what [`Self::push`] gives.
    #[inline(always)]
    pub fn push_with_temperature(
        &mut self,
        time_s: f64,
        rate_dps: f32,
        temperature_c: f32,
    ) -> Option<Output> {
        self.segment::<true>(&[time_s], &[rate_dps], &[temperature_c])
    }

    /// Push a block of input samples, `times_s[i]` (s) and `rates_dps[i]` (deg/s), handing
    /// each output to `sink` as it comes (one per completed decimation block; a block may
    /// span calls).
    ///
    /// The outputs and the state left are those of [`Self::push`] on the same samples one
    /// by one, bit for bit, however the samples are split into calls. What differs is the
    /// cost: the decimator's sum and the per-sample checks stay in registers through the
    /// block, the block's times and counters are kept once per block, and runs of 4 or 8
    /// whole decimation blocks of plausible samples have their sums added side by side
    /// (each in its own order, so that the bits stay those of one sum at a time). Longer
    /// calls gain more: a call of fewer than 4 blocks goes sample by sample.
    ///
    /// Refused, with nothing pushed, if the slices' lengths differ
    /// ([`Error::LengthMismatch`]`("rates_dps")`).
    ///
    /// ```
    /// use gyro_core::{Config, Pipeline};
    ///
    /// let config = Config::default(); // 1 kHz in, 50 Hz out
    /// let times_s: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
    /// let rates_dps = vec![0.5_f32; 1000];
    ///
    /// let mut by_block = Pipeline::try_new(&config)?;
    /// let mut outputs = Vec::new();
    /// // Blocks of any length: here 300 samples, 15 outputs per full call.
    /// for (times, rates) in times_s.chunks(300).zip(rates_dps.chunks(300)) {
    ///     by_block.push_block(times, rates, |out| outputs.push(out))?;
    /// }
    ///
    /// let mut one_by_one = Pipeline::try_new(&config)?;
    /// let expected: Vec<_> = (0..1000)
    ///     .filter_map(|i| one_by_one.push(times_s[i], rates_dps[i]))
    ///     .collect();
    /// assert_eq!(outputs.len(), 50);
    /// assert_eq!(outputs, expected);
    /// # Ok::<(), gyro_core::Error>(())
    /// ```
    pub fn push_block(
        &mut self,
        times_s: &[f64],
        rates_dps: &[f32],
        mut sink: impl FnMut(Output),
    ) -> Result<(), Error> {
        same_lengths(times_s, rates_dps, None)?;
        self.run::<false>(times_s, rates_dps, &[], &mut sink);
        Ok(())
    }

    /// [`Self::push_block`] with the sensor's temperature per sample, `temperatures_c[i]`
    /// (°C), as [`Self::push_with_temperature`] takes it.
    ///
    /// Refused, with nothing pushed, if the slices' lengths differ
    /// ([`Error::LengthMismatch`] naming `rates_dps` or `temperatures_c`).
    pub fn push_block_with_temperature(
        &mut self,
        times_s: &[f64],
        rates_dps: &[f32],
        temperatures_c: &[f32],
        mut sink: impl FnMut(Output),
    ) -> Result<(), Error> {
        same_lengths(times_s, rates_dps, Some(temperatures_c))?;
        self.run::<true>(times_s, rates_dps, temperatures_c, &mut sink);
        Ok(())
    }

    // The input path. Per sample it does only what each sample needs: plausibility, the clip
    // watch, the correction and the decimator's sum, all in registers through a block
    // (`segment`), or for whole blocks side by side (`sums`). The block's times and the
    // output step run once per block (`end_block`, `step`).

    /// Push samples (with their temperatures if `TEMPERATURE`; the slices' lengths agree).
    #[inline(always)]
    fn run<const TEMPERATURE: bool>(
        &mut self,
        times_s: &[f64],
        rates_dps: &[f32],
        temperatures_c: &[f32],
        sink: &mut impl FnMut(Output),
    ) {
        let factor = usize::from(self.decimator.factor());
        let mut start = 0;
        while start < rates_dps.len() {
            let left = rates_dps.len() - start;
            // Whole blocks side by side, when the temperature changes no rate: as many as
            // the lanes hold, else fewer.
            if self.decimator.pending() == 0 && !(TEMPERATURE && self.corrects) {
                let lanes = if left >= SIDE_BY_SIDE * factor {
                    SIDE_BY_SIDE
                } else {
                    SIDE_BY_SIDE / 2
                };
                let end = start + lanes * factor;
                if left >= lanes * factor {
                    let temperatures = if TEMPERATURE {
                        &temperatures_c[start..end]
                    } else {
                        &[]
                    };
                    let (times, rates) = (&times_s[start..end], &rates_dps[start..end]);
                    let pushed = if lanes == SIDE_BY_SIDE {
                        self.sums::<SIDE_BY_SIDE>(times, rates, temperatures, sink)
                    } else {
                        self.sums::<{ SIDE_BY_SIDE / 2 }>(times, rates, temperatures, sink)
                    };
                    if pushed {
                        start = end;
                        continue;
                    }
                }
            }
            let end = start + left.min(usize::from(self.decimator.remaining()));
            let temperatures = if TEMPERATURE {
                &temperatures_c[start..end]
            } else {
                &[]
            };
            if let Some(output) = self.segment::<TEMPERATURE>(
                &times_s[start..end],
                &rates_dps[start..end],
                temperatures,
            ) {
                sink(output);
            }
            start = end;
        }
    }

    /// Push the samples of one block's run (at most the block's remaining samples, at least
    /// one), one after the other; the output if they complete the block.
    #[inline(always)]
    fn segment<const TEMPERATURE: bool>(
        &mut self,
        times_s: &[f64],
        rates_dps: &[f32],
        temperatures_c: &[f32],
    ) -> Option<Output> {
        let first_s = self.time_of(times_s, 0);
        if self.decimator.pending() == 0 {
            self.block_start_time_s = first_s;
        }
        let last_s = self.time_of_last(times_s, first_s);
        self.last_time_s = last_s;

        let mut block = self.decimator.run();
        let (mut clip_last, mut clip_run) = (self.clip_last_dps, self.clip_run);
        let levels = ClipLevels::at(self.clip_level_dps, self.clip_plateau_samples);
        let mut clipped = 0;
        for (i, &reading) in rates_dps.iter().enumerate() {
            if TEMPERATURE {
                self.corrector.observe_temperature(temperatures_c[i]);
            }
            let rate = if self.plausible(reading) {
                let rate = self.corrected::<TEMPERATURE>(reading);
                let seen = clip_seen(levels, &mut clip_last, &mut clip_run, reading);
                clipped |= if seen & CLIP_REPEATS == 0 {
                    seen
                } else {
                    seen & !CLIP_REPEATS | self.plateau(rate, clip_run)
                };
                rate
            } else {
                // Replaced by the last rate the decimator took (0 before the first).
                self.reject();
                block.last()
            };
            block.add(rate);
        }
        (self.clip_last_dps, self.clip_run) = (clip_last, clip_run);
        self.clip_flags |= clipped;
        let mean_dps = self.decimator.close(block)?;
        Some(self.end_block(last_s, mean_dps))
    }

    /// Push `LANES` whole blocks starting at a block boundary: first the
    /// plausibility test, the clip watch (and the temperatures) over all samples in order,
    /// then the blocks' sums side by side, each in its samples' order (the sums are
    /// independent: interleaved, they keep the floating-point units busy rather than wait
    /// on one sum's chain of additions), then the output steps in order. False, with
    /// nothing pushed, if a sample is implausible: its replacement depends on the sample
    /// before, so those blocks go one sample after the other (`segment`).
    #[inline(never)]
    fn sums<const LANES: usize>(
        &mut self,
        times_s: &[f64],
        rates_dps: &[f32],
        temperatures_c: &[f32],
        sink: &mut impl FnMut(Output),
    ) -> bool {
        let factor = usize::from(self.decimator.factor());
        debug_assert_eq!(self.decimator.pending(), 0);
        if rates_dps.len() != LANES * factor {
            return false;
        }
        let mut rows = [&rates_dps[..0]; LANES];
        for (row, block) in rows.iter_mut().zip(rates_dps.chunks_exact(factor)) {
            *row = block;
        }
        let Some(clipped) = self.clip_watch::<LANES>(rates_dps, factor) else {
            return false;
        };
        for &temperature_c in temperatures_c {
            self.corrector.observe_temperature(temperature_c);
        }

        let sums = self.block_sums(&rows);

        for (k, row) in rows.into_iter().enumerate() {
            let sum = sums[k];
            let times_s = &times_s[k * factor..(k + 1) * factor];
            self.block_start_time_s = self.time_of(times_s, 0);
            self.last_time_s = self.time_of_last(times_s, self.block_start_time_s);
            self.clip_flags |= clipped[k];
            let last = self.corrected::<false>(row[factor - 1]);
            let mean_dps = self.decimator.complete(sum, last);
            sink(self.end_block(self.last_time_s, mean_dps));
        }
        true
    }

    /// The sums of whole blocks (`rows`, of one length), side by side, each in its
    /// samples' order (as [`Decimator`] sums them).
    #[inline(always)]
    fn block_sums<const LANES: usize>(&self, rows: &[&[f32]; LANES]) -> [f32; LANES] {
        // Without temperature: a temperature that would change the rate keeps the blocks
        // out of here. The identity's loop apart, so that no sample tests for it.
        if self.corrects {
            column_sums(rows, |x| self.corrector.correct(x))
        } else {
            column_sums(rows, |x| x)
        }
    }

    /// The plausibility test and the clip watch over whole blocks of `factor` samples in
    /// order: each block's clip flags ([`clip_seen`]), or `None` (and nothing changed) if a
    /// sample is implausible or may complete a clip plateau: whether it does depends on the
    /// filtered rate of the block before its own ([`Self::plateau`]), which blocks side by
    /// side do not have yet, so those blocks go one after the other (`segment`).
    ///
    /// Blocks that stay below both the clip plateau's level and the range, as rests do,
    /// need no watch sample by sample: their test reads all samples at once, and the watch
    /// moves on to their last reading and its run of repeats.
    #[inline(always)]
    fn clip_watch<const LANES: usize>(
        &mut self,
        rates_dps: &[f32],
        factor: usize,
    ) -> Option<[u8; LANES]> {
        let quiet_dps = self.clip_level_dps.min(CLIP_PLATEAU_MIN_DPS);
        let max_dps = self.max_abs_rate_dps;
        // Below both levels, as rests are, the samples are quiet and plausible: one
        // comparison a sample. Else each level on its own. NaN fails every test.
        let low_dps = quiet_dps.min(max_dps);
        let low = rates_dps
            .iter()
            .fold(true, |low, &x| low & (libm::fabsf(x) < low_dps));
        let (quiet, plausible) = if low {
            (true, true)
        } else {
            rates_dps
                .iter()
                .fold((true, true), |(quiet, plausible), &x| {
                    let magnitude = libm::fabsf(x);
                    (
                        quiet & (magnitude < quiet_dps),
                        plausible & (magnitude <= max_dps),
                    )
                })
        };
        if !plausible {
            return None;
        }
        let mut clipped = [0; LANES];
        if quiet {
            let (&last, before) = rates_dps.split_last()?;
            let repeats = before.iter().rev().take_while(|&&x| x == last).count();
            self.clip_run = if repeats == before.len() && last == self.clip_last_dps {
                self.clip_run
                    .saturating_add(u16::try_from(rates_dps.len()).unwrap_or(u16::MAX))
            } else {
                u16::try_from(repeats + 1).unwrap_or(u16::MAX)
            };
            self.clip_last_dps = last;
        } else if let Some(distinct) = distinct_run(
            rates_dps,
            self.clip_last_dps,
            self.clip_run,
            self.clip_plateau_samples,
        ) {
            // No reading repeats the one before it, but perhaps the first: a plateau can
            // only complete there, and the watch ends on a run of one (or the first's).
            if distinct.first_clipped & CLIP_REPEATS != 0 {
                return None;
            }
            // Without a known range (an infinite level) no plausible reading reaches it:
            // the blocks' range flags stay 0.
            if self.clip_level_dps < f32::INFINITY {
                let levels = ClipLevels::at(self.clip_level_dps, self.clip_plateau_samples);
                for (block, clipped) in rates_dps.chunks_exact(factor).zip(&mut clipped) {
                    *clipped = block
                        .iter()
                        .fold(0, |seen, &x| seen | range_flags(levels, libm::fabsf(x)));
                }
            }
            clipped[0] |= distinct.first_clipped;
            (self.clip_last_dps, self.clip_run) = (distinct.last_dps, distinct.run);
        } else {
            let (mut clip_last, mut clip_run) = (self.clip_last_dps, self.clip_run);
            let levels = ClipLevels::at(self.clip_level_dps, self.clip_plateau_samples);
            for (block, clipped) in rates_dps.chunks_exact(factor).zip(&mut clipped) {
                for &reading in block {
                    *clipped |= clip_seen(levels, &mut clip_last, &mut clip_run, reading);
                }
            }
            if clipped.iter().any(|&seen| seen & CLIP_REPEATS != 0) {
                return None;
            }
            (self.clip_last_dps, self.clip_run) = (clip_last, clip_run);
        }
        Some(clipped)
    }

    /// Whether a reading, the `run`-th identical one in a row ([`CLIP_REPEATS`]), whose
    /// corrected rate is `level_dps`, completes a clip plateau: [`CLIP_PLATEAU`] if that
    /// level stands at least [`CLIP_PLATEAU_LEAD_DPS`] beyond the filtered rate of the last
    /// output step, toward its sign, or if the run has lasted
    /// [`Self::clip_plateau_long_samples`] readings; else 0.
    #[cold]
    #[inline(never)]
    fn plateau(&self, level_dps: f32, run: u16) -> u8 {
        let lead_dps = libm::copysignf(1.0, level_dps) * (level_dps - self.previous.0);
        if lead_dps >= CLIP_PLATEAU_LEAD_DPS || run >= self.clip_plateau_long_samples() {
            CLIP_PLATEAU
        } else {
            0
        }
    }

    /// Identical readings that make a clip plateau whatever the filtered rate:
    /// [`CLIP_PLATEAU_LONG_S`] at the input rate (128 at 1 kHz), at least
    /// [`CLIP_PLATEAU_SAMPLES`] (below 125 Hz every plateau counts, as 16 readings then
    /// last longer) and at most 65 535, the run counter's limit (1024 at 8 kHz; only
    /// above 512 kHz a shorter time).
    pub fn clip_plateau_long_samples(&self) -> u16 {
        let input_rate_hz = f32::from(self.decimator.factor()) / self.output_period_s();
        plateau_samples(CLIP_PLATEAU_LONG_S, input_rate_hz)
    }

    /// Identical readings (at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`]) that may make a clip
    /// plateau: [`CLIP_PLATEAU_SHORT_S`] at the input rate, at least
    /// [`CLIP_PLATEAU_SAMPLES`] (16 up to 1 kHz, 128 at 8 kHz).
    pub const fn clip_plateau_samples(&self) -> u16 {
        self.clip_plateau_samples
    }

    /// Plausible: finite and within `max_abs_rate_dps`.
    #[inline(always)]
    fn plausible(&self, reading_dps: f32) -> bool {
        // `max_abs_rate_dps` is finite (validated): NaN and the infinities fail this test.
        libm::fabsf(reading_dps) <= self.max_abs_rate_dps
    }

    /// A plausible reading corrected (with the temperature change in use if `TEMPERATURE`).
    #[inline(always)]
    fn corrected<const TEMPERATURE: bool>(&self, reading_dps: f32) -> f32 {
        // The identity returns the reading, a zero's sign aside (−0 − 0·ΔT may give +0),
        // which the decimator's sum does not see: both zeros leave it the same.
        if !self.corrects {
            reading_dps
        } else if TEMPERATURE {
            self.corrector.correct_at_temperature(reading_dps)
        } else {
            self.corrector.correct(reading_dps)
        }
    }

    /// Count a rejected reading (its replacement is the caller's).
    #[cold]
    #[inline(never)]
    fn reject(&mut self) {
        self.rejected = self.rejected.saturating_add(1);
    }

    /// The time of `times_s[i]` (s), the stamps before it taken one after the other from
    /// the last time: the stamp if finite, else [`Self::substitute_time`] of the one before.
    #[inline(always)]
    fn time_of(&self, times_s: &[f64], i: usize) -> f64 {
        let time_s = times_s[i];
        if time_s.is_finite() {
            time_s
        } else {
            self.time_walked(times_s, i)
        }
    }

    /// The time of the last of `times_s` (non-empty), the first's being `first_s`.
    #[inline(always)]
    fn time_of_last(&self, times_s: &[f64], first_s: f64) -> f64 {
        let last = times_s.len() - 1;
        if last == 0 {
            first_s
        } else {
            self.time_of(times_s, last)
        }
    }

    /// [`Self::time_of`] for a stamp that is not finite: walk from the last time.
    #[cold]
    #[inline(never)]
    fn time_walked(&self, times_s: &[f64], i: usize) -> f64 {
        times_s[..=i]
            .iter()
            .fold(self.last_time_s, |before_s, &time_s| {
                if time_s.is_finite() {
                    time_s
                } else {
                    self.substitute_time(before_s)
                }
            })
    }

    /// The time of a sample whose stamp is not finite: one input period on from the time
    /// before it (the output period over the factor), or 0 if there is none.
    fn substitute_time(&self, before_s: f64) -> f64 {
        if before_s.is_finite() {
            before_s + f64::from(self.output_period_s()) / f64::from(self.decimator.factor())
        } else {
            0.0
        }
    }

    /// The output step of a completed block whose last sample came at `time_s`.
    #[inline(never)]
    fn end_block(&mut self, time_s: f64, mean_dps: f32) -> Output {
        // Halves first: the sum of two huge times would overflow.
        let centre_s = 0.5 * self.block_start_time_s + 0.5 * time_s;
        self.step(centre_s, mean_dps)
    }

    /// The pending clip flags, cleared ([`CLIP_BEYOND`] stays).
    #[inline(always)]
    fn take_pending(&mut self) -> u8 {
        let pending = self.clip_flags & CLIP_PENDING;
        self.clip_flags &= CLIP_BEYOND;
        pending
    }

    /// Whether an accepted reading has gone beyond [`Config::range_dps`] by more than
    /// [`RANGE_MARGIN`]: the configured range is not this sensor's, and reaching it no
    /// longer makes a movement saturated (a clip plateau still does).
    pub fn range_contradicted(&self) -> bool {
        self.clip_flags & CLIP_BEYOND != 0
    }

    /// The standard deviation (deg) of the angle the movement in progress has gained so
    /// far, as [`Movement::angle_std_deg`] would give it were it to end now (Kalman form
    /// only; `None` at rest or in another compensation). For a host whose log ends while
    /// moving: the angle of a movement that never rests still has a σ, and it tells how far
    /// the bias estimated at the last rest can have carried it.
    pub fn movement_std_deg(&self) -> Option<f32> {
        let track = self.track.as_ref()?;
        (self.compensation == Compensation::Kalman).then(|| {
            self.kalman
                .movement_std_deg(self.index.saturating_sub(track.start_index))
        })
    }

    /// Whether the movement in progress (its confirming run included) is saturated so far;
    /// `false` at rest. For a host whose log ends while moving.
    pub fn movement_saturated(&self) -> bool {
        self.saturated(self.track.as_ref().map_or(0, |track| track.saturation))
    }

    /// Whether a movement whose clip flags are `seen` is saturated, with the flags not yet
    /// handed to it and whether the range has been contradicted ([`saturated_by`]).
    #[inline(always)]
    fn saturated(&self, seen: u8) -> bool {
        saturated_by(seen | self.clip_flags)
    }

    /// One step at the output rate.
    fn step(&mut self, time_s: f64, mean_dps: f32) -> Output {
        if self.index == 0 {
            // Start the filter in steady state: no start-up transient to mistake for motion.
            self.sos.settle(&mut self.sos_state, mean_dps);
        }
        let rate_dps = self.sos.process(&mut self.sos_state, mean_dps);
        let phase = self.detector.update(rate_dps);
        self.integrate(phase, rate_dps);
        self.hand_over_saturation(phase);
        let event = match phase {
            Phase::Rest => {
                self.observe_rest(rate_dps);
                None
            }
            Phase::Onset | Phase::Settling => None,
            Phase::Aborted => {
                self.discard();
                None
            }
            Phase::Started { run } => Some(self.start_movement(run, time_s)),
            Phase::Moving => {
                self.commit();
                if let Some(track) = self.track.as_mut() {
                    track.set_settle(None);
                }
                None
            }
            Phase::SettleFirst => {
                self.commit();
                if let Some(track) = self.track.as_mut() {
                    track.set_settle(Some((self.index, time_s)));
                }
                None
            }
            Phase::Ended { quiet } => self.end_movement(quiet, time_s),
        };
        let output = self.output(time_s, rate_dps, event);
        self.index = self.index.saturating_add(1);
        output
    }

    /// Predict the filter over this step, and integrate `rate_dps` (raw and corrected)
    /// if `phase` integrates.
    #[inline(always)]
    fn integrate(&mut self, phase: Phase, rate_dps: f32) {
        // With `min_rest` of one sample, `Ended` comes on the first quiet sample, which is
        // the movement's last: it is integrated like `SettleFirst`.
        let integrates = match phase {
            Phase::Rest | Phase::Aborted => false,
            Phase::Ended { quiet } => quiet <= 1,
            _ => true,
        };
        // An onset may still turn out not to be a movement: its samples are propagated as
        // static, and their share of the angle's uncertainty is added once the movement is
        // confirmed. Propagating them as moving coupled angle and bias for samples that
        // were then discarded, and the next rest updates "corrected" an angle that had not
        // moved (0.08 deg at power-up with an unknown bias).
        self.kalman.predict(integrates && phase != Phase::Onset);
        let corrected_dps = rate_dps - self.kalman.bias_dps();
        // The first sample has no interval before it: nothing to integrate (a log that starts
        // in motion would otherwise gain a whole step of T × rate).
        if integrates && self.index > 0 {
            let (previous_rate, previous_corrected) = self.previous;
            let half_dt_s = 0.5 * self.output_period_s();
            self.raw.step(half_dt_s, previous_rate, rate_dps);
            self.corrected
                .step(half_dt_s, previous_corrected, corrected_dps);
        }
        self.previous = (rate_dps, corrected_dps);
    }

    /// Hand the clip flags pending from this block on, as `phase` decides.
    #[inline(always)]
    fn hand_over_saturation(&mut self, phase: Phase) {
        // Saturation seen in this block goes to the movement in progress; during a run that
        // may become one it waits; at rest, or when the run is dropped, it is forgotten.
        if !matches!(phase, Phase::Onset | Phase::Started { .. }) {
            let pending = self.take_pending();
            if let (false, Some(track)) = (
                matches!(phase, Phase::Rest | Phase::Aborted),
                self.track.as_mut(),
            ) {
                track.saturation |= pending;
            }
        }
    }

    /// A rest sample `rate_dps`: when it completes a block pair, observe the bias with it.
    #[inline(always)]
    fn observe_rest(&mut self, rate_dps: f32) {
        if let Some((mean_dps, samples, next_mean_dps, first)) = self.rest_blocks.push(rate_dps) {
            if first {
                self.kalman.observe_after_movement(mean_dps);
            }
            self.kalman.observe_block_pair(mean_dps, next_mean_dps);
            let correction = self.kalman.update_at_rest(mean_dps, u32::from(samples));
            self.kalman_correction.add(correction);
        }
    }

    /// A movement confirmed by a run of `run` samples ending at `time_s`: start tracking
    /// it from the quiet sample before the run.
    fn start_movement(&mut self, run: u16, time_s: f64) -> Event {
        self.kalman.add_motion(u32::from(run).saturating_sub(1));
        // The movement starts at the quiet sample before the run.
        let start_index = self.index.saturating_sub(u32::from(run));
        let start_time_s =
            time_s - f64::from(run) * f64::from(self.output_period_s()) - self.filter_delay_s;
        // The rest samples still held back lead into the movement: drop them.
        self.rest_blocks.clear();
        // The run so far is still pending: it belongs to the movement.
        self.track = Some(Track {
            start_time_s,
            start_index,
            raw_at_start_deg: self.raw.committed_deg(),
            angle_at_start_deg: self.committed_angle_deg(),
            settle_time_s: 0.0,
            settle_index: None,
            saturation: self.take_pending(),
        });
        self.commit();
        Event::MovementStarted {
            start_time_s,
            start_index,
        }
    }

    /// Rest confirmed after `quiet` quiet samples (the last at `time_s`): end the movement.
    fn end_movement(&mut self, quiet: u16, time_s: f64) -> Option<Event> {
        if quiet <= 1 {
            // This first quiet sample is the end (see `integrates`).
            self.commit();
            if let Some(track) = self.track.as_mut() {
                track.set_settle(Some((self.index, time_s)));
            }
        } else {
            self.discard();
        }
        self.finish_movement(time_s).map(Event::MovementEnded)
    }

    /// The output of this step: `rate_dps` at `time_s`, `event`, and the angles and bias now.
    #[inline(always)]
    fn output(&self, time_s: f64, rate_dps: f32, event: Option<Event>) -> Output {
        Output {
            time_s,
            rate_dps,
            motion: self.detector.state(),
            event,
            angle_deg: self.angle_deg(),
            raw_angle_deg: self.raw.angle_deg(),
            angle_std_deg: (self.compensation == Compensation::Kalman)
                .then(|| self.kalman.angle_std_deg()),
            bias_dps: match self.compensation {
                Compensation::Kalman => self.kalman.bias_dps(),
                _ => self.detector.bias_dps(),
            },
        }
    }

    fn commit(&mut self) {
        self.raw.commit();
        self.corrected.commit();
    }

    fn discard(&mut self) {
        self.raw.discard();
        self.corrected.discard();
    }

    /// Close the movement in progress, folding paper-mode compensation into the total.
    fn finish_movement(&mut self, time_s: f64) -> Option<Movement> {
        let track = self.track.take()?;
        let (end_index, end_time_s) = track.settle().unwrap_or((self.index, time_s));
        let raw_angle_deg = self.raw.committed_deg() - track.raw_at_start_deg;
        let duration_s = (end_index - track.start_index) as f32 * self.output_period_s();
        self.paper_total
            .add(raw_angle_deg - self.paper.misalignment_deg(duration_s));
        Some(Movement {
            start_time_s: track.start_time_s,
            end_time_s: end_time_s - self.filter_delay_s,
            start_index: track.start_index,
            end_index,
            angle_deg: self.angle_deg() - track.angle_at_start_deg,
            raw_angle_deg,
            saturated: self.saturated(track.saturation),
            angle_std_deg: (self.compensation == Compensation::Kalman)
                .then(|| self.kalman.movement_std_deg(end_index - track.start_index)),
        })
    }

    /// The angle under the configured compensation, without the pending (tentative)
    /// integration (deg). Only called while no movement is tracked.
    fn committed_angle_deg(&self) -> f32 {
        match self.compensation {
            Compensation::None => self.raw.committed_deg(),
            Compensation::Kalman => self.corrected.committed_deg() + self.kalman_correction.value(),
            Compensation::Paper => self.paper_total.value(),
        }
    }

    /// The angle under the configured compensation (deg).
    fn angle_deg(&self) -> f32 {
        match self.compensation {
            Compensation::None => self.raw.angle_deg(),
            Compensation::Kalman => self.corrected.angle_deg() + self.kalman_correction.value(),
            Compensation::Paper => {
                let total = self.paper_total.value();
                match &self.track {
                    None => total,
                    Some(track) => {
                        let elapsed = self.index.saturating_sub(track.start_index);
                        let moved = self.raw.angle_deg() - track.raw_at_start_deg;
                        let duration_s = elapsed as f32 * self.output_period_s();
                        total + moved - self.paper.misalignment_deg(duration_s)
                    }
                }
            }
        }
    }
}

/// The block inputs' slices have one entry per sample: the first that does not is named.
fn same_lengths(
    times_s: &[f64],
    rates_dps: &[f32],
    temperatures_c: Option<&[f32]>,
) -> Result<(), Error> {
    if rates_dps.len() != times_s.len() {
        return Err(Error::LengthMismatch("rates_dps"));
    }
    if temperatures_c.is_some_and(|t| t.len() != times_s.len()) {
        return Err(Error::LengthMismatch("temperatures_c"));
    }
    Ok(())
}

#[cfg(test)]
mod size_tests {
    use super::Pipeline;

    /// The firmware budget: the whole pipeline state in 512 bytes at most. It is exactly
    /// 512, all but 8 bytes of padding a field (the Kalman filter's 4 free bytes went to
    /// alignment): `Track` gave up 8 bytes of `Option` padding for the corrector, the saturation state (10 bytes) is paid for by `previous` without an
    /// `Option` tag and the sample rate kept as f32 instead of the period as f64, the
    /// last free byte says whether the correction is the identity, and the Kalman
    /// filter's cached transition φ is paid for by the output period kept once (the
    /// filter's step).
    #[test]
    fn pipeline_state_fits_in_512_bytes() {
        use core::mem::size_of;
        std::println!(
            "config {} corrector {} sos {} sos_state {} detector {} integrator {} kalman {} rest_blocks {} track {} decimator {}",
            size_of::<super::Config>(),
            size_of::<super::Corrector>(),
            size_of::<super::Sos>(),
            size_of::<super::SosState>(),
            size_of::<super::MotionDetector>(),
            size_of::<super::Integrator>(),
            size_of::<super::KalmanBias>(),
            size_of::<super::RestBlocks>(),
            size_of::<Option<super::Track>>(),
            size_of::<super::Decimator>(),
        );
        let size = core::mem::size_of::<Pipeline>();
        std::println!("size_of::<Pipeline>() = {size} bytes");
        assert!(size <= 512, "{size} bytes");
    }
}
