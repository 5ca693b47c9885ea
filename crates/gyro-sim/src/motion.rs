//! True motion for the simulator: bench-like hand rotations, or a recorded trajectory.
//!
//! Both give the angle and the rate at any instant, which the latency and clock-error
//! effects need (they sample the motion off the nominal grid).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One rotation with a minimum-jerk profile (smooth start and stop, as a hand turns).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Rotation {
    /// Start (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Angle turned (deg), signed.
    pub angle_deg: f64,
}

impl Rotation {
    fn fraction(&self, time_s: f64) -> f64 {
        ((time_s - self.start_s) / self.duration_s).clamp(0.0, 1.0)
    }
    fn angle_at(&self, time_s: f64) -> f64 {
        let s = self.fraction(time_s);
        self.angle_deg * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
    }
    fn rate_at(&self, time_s: f64) -> f64 {
        if time_s <= self.start_s || time_s >= self.start_s + self.duration_s {
            return 0.0;
        }
        let s = self.fraction(time_s);
        self.angle_deg / self.duration_s * 30.0 * s * s * (1.0 - s) * (1.0 - s)
    }
}

/// Settings of the bench-like profile generator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchProfile {
    /// Total duration (s); the run starts and ends at rest.
    pub duration_s: f64,
    /// Rotation angle magnitude (deg).
    pub angle_deg: f64,
    /// Shortest and longest rotation (s).
    pub rotation_s: (f64, f64),
    /// Shortest and longest rest between rotations (s).
    pub rest_s: (f64, f64),
}

impl Default for BenchProfile {
    /// 90 s of 90° rotations lasting 0.8–4 s separated by rests of 3–15 s.
    fn default() -> Self {
        Self {
            duration_s: 90.0,
            angle_deg: 90.0,
            rotation_s: (0.8, 4.0),
            rest_s: (3.0, 15.0),
        }
    }
}

/// The true motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Rotations (sorted, non-overlapping), at rest in between; angle 0 at the start.
    Rotations {
        /// The rotations.
        rotations: Vec<Rotation>,
        /// Angle before each rotation (deg).
        before_deg: Vec<f64>,
        /// Duration of the motion (s).
        duration_s: f64,
    },
    /// A sampled trajectory (e.g. a log's reference), uniformly spaced, starting at 0.
    Trajectory {
        /// Time of the first sample (s).
        start_s: f64,
        /// Sample period (s).
        period_s: f64,
        /// Angle (deg), relative to the first sample.
        angle_deg: Vec<f64>,
        /// Rate at each sample (deg/s): see [`Motion::rate_dps`].
        rate_dps: Vec<f64>,
        /// The acceleration steps between samples, in order ([`AccelerationStep`]).
        steps: Vec<AccelerationStep>,
    },
}

/// A step of the acceleration between samples `index` and `index + 1` of a sampled
/// trajectory (where a raised-cosine turn or a trapezoidal rate profile starts or ends),
/// and the motion on either side of it.
///
/// Read between those two samples (a clock or a latency moves the sampling off the
/// grid), a smooth interpolant would round the step off over the whole interval; a gyro
/// sampled there reads one side's rate. The step's place within the interval is read from
/// the reference's third differences (`at`), and each side is the least-squares
/// polynomial of its own samples, the ones its one-sided rate is taken from.
#[derive(Clone, Debug, PartialEq)]
pub struct AccelerationStep {
    /// The sample before the step.
    index: usize,
    /// Where in the interval the step lies (0 at `index`, 1 at the next sample).
    at: f64,
    /// Each side's polynomial (angle, deg, in powers of samples from the step), before and
    /// after it.
    sides: [[f64; STEP_POLY_TERMS]; 2],
}

/// Terms of a side's polynomial: up to a quartic ([`ONE_SIDED_QUARTIC_FROM`]).
const STEP_POLY_TERMS: usize = 5;

impl AccelerationStep {
    /// The polynomial of the side `x` lies on (samples from the step) and its value or
    /// derivative `order` (0–2) there, per sample.
    fn side_at(&self, x: f64, order: usize) -> f64 {
        let c = &self.sides[usize::from(x >= 0.0)];
        (order..STEP_POLY_TERMS)
            .map(|p| {
                let falling: f64 = (p + 1 - order..=p).map(|q| q as f64).product();
                c[p] * falling * x.powi((p - order) as i32)
            })
            .sum()
    }
}

/// Smallest third difference taken for an acceleration step, in units of the
/// reference's resolution. Rounding alone makes up to 4 (the stencil's weights 1, 3, 3, 1
/// times half a step); the one-sided derivative adds the rounding of 1.1 steps per
/// period, and a step's centred error is about its third difference over 4 periods, so
/// from 10 the one-sided rate is the better by twice its rounding.
const STEP_FLOOR: f64 = 10.0;
/// An acceleration step's third difference is at least this many times any of those
/// three to five samples away on either side (the smooth motion's, or the noise's).
const STEP_RATIO: f64 = 4.0;
/// Beside an acceleration step of a printed reference, the one-sided rate is the slope of
/// a least-squares polynomial through the smoothing's half width plus this many samples of
/// its own side, not the exact four-point derivative: that one carries 3.8 times the
/// rounding's per-sample noise into the re-simulated gyro (0.11 °/s at 100 Hz and
/// 0.001°), which the real gyro never saw
/// (`one_sided_rate_of_a_print_averages_its_rounding`).
const PRINT_ONE_SIDED_EXTRA: usize = 4;
/// A one-sided fit through this many samples or more is a quartic, below a cubic: on
/// raised-cosine turns printed to 0.001° at 100 Hz, 12 samples of a quartic leave
/// 0.027 °/s rms of the exact rate beside the steps, 7 of a cubic 0.034, and a cubic
/// through more follows the turn less well.
const ONE_SIDED_QUARTIC_FROM: usize = 10;

impl Motion {
    /// Motion made of `rotations` over `duration_s`.
    pub fn from_rotations(mut rotations: Vec<Rotation>, duration_s: f64) -> Self {
        rotations.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        let mut before_deg = Vec::with_capacity(rotations.len());
        let mut total = 0.0;
        for r in &rotations {
            before_deg.push(total);
            total += r.angle_deg;
        }
        Motion::Rotations {
            rotations,
            before_deg,
            duration_s,
        }
    }

    /// A bench-like run: rest, rotations of random duration and direction, rests.
    pub fn bench(profile: &BenchProfile, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut rotations = Vec::new();
        let mut time_s = rng.random_range(3.0..6.0);
        loop {
            let duration_s = rng.random_range(profile.rotation_s.0..=profile.rotation_s.1);
            if time_s + duration_s + profile.rest_s.0.min(3.0) > profile.duration_s {
                break;
            }
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            rotations.push(Rotation {
                start_s: time_s,
                duration_s,
                angle_deg: sign * profile.angle_deg,
            });
            time_s += duration_s + rng.random_range(profile.rest_s.0..=profile.rest_s.1);
        }
        Self::from_rotations(rotations, profile.duration_s)
    }

    /// A trajectory from uniformly sampled reference angles (deg). The angle is smoothed
    /// with a centred moving average of `smooth_samples` (encoders are quantised; their
    /// raw differences would be spikes), which keeps the total angle.
    pub fn from_reference(
        start_s: f64,
        period_s: f64,
        reference_deg: &[f64],
        smooth_samples: usize,
    ) -> Self {
        let (angle_deg, rate_dps) = smoothed(period_s, reference_deg, smooth_samples);
        Motion::Trajectory {
            start_s,
            period_s,
            angle_deg,
            rate_dps,
            steps: Vec::new(),
        }
    }

    /// [`Motion::from_reference`], with the rate beside each step of the acceleration
    /// that `reference_deg` (on a grid of `resolution_deg`, 0 when exact) shows taken
    /// from that sample's own side of the step.
    ///
    /// A turn whose angle is a raised cosine, or a trapezoidal rate profile, changes its
    /// acceleration at once where it starts and ends. A gyro sampled there reads the
    /// rate of its own side of the step; a centred derivative of the reference mixes both
    /// sides, several deg/s off at 100 Hz for a sample or two. A step between samples `m`
    /// and `m + 1` shows as a peak of the third difference `d3[m]` (the stencil
    /// `m − 1 … m + 2`, weights `(1 − ε)²/2`, `(1 + 2ε − 2ε²)/2`, `ε²/2` of the step times
    /// the period squared at `m − 1`, `m`, `m + 1` for a step at `m + ε`): its neighbours
    /// `d3[m ± 1]` of the same sign or within what the smooth motion and rounding make (a
    /// step of the rate itself, a kink of the angle, gives neighbours of the other sign
    /// as large as the peak and is left alone), [`STEP_RATIO`] times those three samples
    /// to five samples away (the smooth motion's) and [`STEP_FLOOR`] steps of the
    /// resolution.
    /// The samples whose centred stencil (and smoothing) reaches across it take a
    /// four-point one-sided derivative of `reference_deg` (third order) on their own
    /// side, when that side holds four samples clear of another step. Smooth motion
    /// (a minimum-jerk turn, whose acceleration is continuous) is left as it was.
    pub fn from_reference_with_steps(
        start_s: f64,
        period_s: f64,
        reference_deg: &[f64],
        smooth_samples: usize,
        resolution_deg: f64,
    ) -> Self {
        let (angle_deg, rate_dps) = smoothed(period_s, reference_deg, smooth_samples);
        trajectory_with_steps(
            start_s,
            period_s,
            angle_deg,
            rate_dps,
            reference_deg,
            smooth_samples / 2,
            resolution_deg,
            4,
        )
    }

    /// A trajectory from reference angles printed on a grid of `resolution_deg` (a log
    /// written with few decimals): the angle kept as recorded, less its first sample; the
    /// rate the centred five-point derivative of the angle smoothed by a quintic
    /// Savitzky-Golay filter of half width `half_width` samples
    /// ([`print_smoothing_weights`]: exact on quintics, so a turn's rate and curvature pass, while the rounding's noise, which grows with
    /// frequency once differentiated, is cut; [`rounding_noise_dps`]); beside each step
    /// of the acceleration a one-sided rate as in [`Motion::from_reference_with_steps`],
    /// the slope of a least-squares polynomial through `half_width` + [`PRINT_ONE_SIDED_EXTRA`]
    /// samples of its own side, which averages the rounding down as the smoothing does.
    ///
    /// A gyro does not see the rounding of the reference it is compared with. Kept in
    /// the angle and out of the rate, the re-simulated residual, gyro less the reference's
    /// rate, holds the same rounding as the real one.
    pub fn from_rounded_reference(
        start_s: f64,
        period_s: f64,
        reference_deg: &[f64],
        half_width: usize,
        resolution_deg: f64,
    ) -> Self {
        let origin = reference_deg.first().copied().unwrap_or(0.0);
        let angle_deg: Vec<f64> = reference_deg.iter().map(|r| r - origin).collect();
        let smooth = print_smoothed(&angle_deg, half_width);
        let rate_dps: Vec<f64> = (0..smooth.len())
            .map(|k| centred_rate(&smooth, period_s, k))
            .collect();
        trajectory_with_steps(
            start_s,
            period_s,
            angle_deg,
            rate_dps,
            reference_deg,
            half_width,
            resolution_deg,
            half_width + PRINT_ONE_SIDED_EXTRA,
        )
    }

    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        match self {
            Motion::Rotations { duration_s, .. } => *duration_s,
            Motion::Trajectory {
                period_s,
                angle_deg,
                ..
            } => period_s * angle_deg.len().saturating_sub(1) as f64,
        }
    }

    /// The rotations, if this is a rotation profile.
    pub fn rotations(&self) -> &[Rotation] {
        match self {
            Motion::Rotations { rotations, .. } => rotations,
            Motion::Trajectory { .. } => &[],
        }
    }

    /// Angle (deg) at `time_s` (s from the start of the motion).
    pub fn angle_deg(&self, time_s: f64) -> f64 {
        match self {
            Motion::Rotations {
                rotations,
                before_deg,
                ..
            } => {
                let i = rotations.partition_point(|r| r.start_s <= time_s);
                if i == 0 {
                    0.0
                } else {
                    before_deg[i - 1] + rotations[i - 1].angle_at(time_s)
                }
            }
            Motion::Trajectory {
                start_s,
                period_s,
                angle_deg,
                rate_dps,
                steps,
            } => {
                let samples = Samples {
                    period_s: *period_s,
                    angle_deg,
                    rate_dps,
                    steps,
                };
                samples.angle_deg(time_s - start_s)
            }
        }
    }

    /// Rate (deg/s) at `time_s`.
    pub fn rate_dps(&self, time_s: f64) -> f64 {
        match self {
            Motion::Rotations { rotations, .. } => {
                let i = rotations.partition_point(|r| r.start_s <= time_s);
                if i == 0 {
                    0.0
                } else {
                    rotations[i - 1].rate_at(time_s)
                }
            }
            Motion::Trajectory {
                start_s,
                period_s,
                angle_deg,
                rate_dps,
                steps,
            } => {
                let samples = Samples {
                    period_s: *period_s,
                    angle_deg,
                    rate_dps,
                    steps,
                };
                samples.rate_dps(time_s - start_s)
            }
        }
    }
}

/// A sampled trajectory's columns, read between the samples.
struct Samples<'a> {
    period_s: f64,
    angle_deg: &'a [f64],
    rate_dps: &'a [f64],
    steps: &'a [AccelerationStep],
}

impl Samples<'_> {
    /// The step between samples `i` and `i + 1`, if there is one.
    fn step_after(&self, i: usize) -> Option<&AccelerationStep> {
        let k = self.steps.partition_point(|s| s.index < i);
        self.steps.get(k).filter(|s| s.index == i)
    }

    /// The angle at `offset_s` from the first sample: between two samples the cubic
    /// Hermite interpolant with the rates as slopes ([`hermite`]), across an acceleration
    /// step its sides' polynomials ([`AccelerationStep`]).
    fn angle_deg(&self, offset_s: f64) -> f64 {
        let n = self.angle_deg.len();
        let Some(&first) = self.angle_deg.first() else {
            return 0.0;
        };
        if n < 2 {
            return first;
        }
        let (i, w) = locate(offset_s, self.period_s, n);
        if let Some(k) = on_sample(i, w) {
            return self.angle_deg[k];
        }
        let ends = [self.angle_deg[i], self.angle_deg[i + 1]];
        let slope = |k: usize| self.rate_dps.get(k).copied().unwrap_or(0.0);
        match self.step_after(i) {
            Some(step) => across_step(step, w, ends, 0),
            None => hermite(ends, [slope(i), slope(i + 1)], self.period_s, w),
        }
    }

    /// The rate at `offset_s`: between two samples the cubic Hermite interpolant of the
    /// rates with each sample's acceleration as slope, across an acceleration step its
    /// sides' polynomials.
    fn rate_dps(&self, offset_s: f64) -> f64 {
        let n = self.rate_dps.len();
        if n == 0 {
            return 0.0;
        }
        let (i, w) = locate(offset_s, self.period_s, n);
        if i + 1 >= n {
            return self.rate_dps[n - 1];
        }
        if let Some(k) = on_sample(i, w) {
            return self.rate_dps[k];
        }
        let ends = [self.rate_dps[i], self.rate_dps[i + 1]];
        if let Some(step) = self.step_after(i) {
            let per_sample = ends.map(|r| r * self.period_s);
            return across_step(step, w, per_sample, 1) / self.period_s;
        }
        // No step lies between samples i and i + 1 here: only the intervals beyond them
        // can hold one.
        let before = i > 0 && self.step_after(i - 1).is_some();
        let after = self.step_after(i + 1).is_some();
        hermite(
            ends,
            [
                self.acceleration(i, before, false),
                self.acceleration(i + 1, false, after),
            ],
            self.period_s,
            w,
        )
    }

    /// The acceleration at sample `k`: the difference of the rates centred on it, or on
    /// its own side of an acceleration step just before it (`step_before`) or just after
    /// it (`step_after`) (one-sided at the ends).
    fn acceleration(&self, k: usize, step_before: bool, step_after: bool) -> f64 {
        let n = self.rate_dps.len();
        let lo = if step_before { k } else { k.saturating_sub(1) };
        let hi = if step_after { k } else { (k + 1).min(n - 1) };
        if hi == lo {
            return 0.0;
        }
        (self.rate_dps[hi] - self.rate_dps[lo]) / (self.period_s * (hi - lo) as f64)
    }
}

/// The sample that fraction `w` of the interval after sample `i` falls on, within 10⁻⁹ of
/// a period (a simulation on the trajectory's own grid reads its samples; every interpolant
/// here is exact there).
fn on_sample(i: usize, w: f64) -> Option<usize> {
    const ON_SAMPLE: f64 = 1e-9;
    if w < ON_SAMPLE {
        Some(i)
    } else if w > 1.0 - ON_SAMPLE {
        Some(i + 1)
    } else {
        None
    }
}

/// The angle (`order` 0, deg) or the rate (1, deg per sample) at fraction `w` of the
/// interval holding `step`: the polynomial of the step's side that `w` lies on, less its
/// misfit at the interval's ends (`ends`, the samples' own values) shared linearly, so
/// that the samples themselves are read unchanged.
fn across_step(step: &AccelerationStep, w: f64, ends: [f64; 2], order: usize) -> f64 {
    let x = w - step.at;
    let misfit = [
        ends[0] - step.side_at(-step.at, order),
        ends[1] - step.side_at(1.0 - step.at, order),
    ];
    step.side_at(x, order) + (1.0 - w) * misfit[0] + w * misfit[1]
}

/// The trajectory of `angle_deg` and `rate_dps`, where the rate of each sample whose
/// centred stencil (two samples) and smoothing (`smooth_half` samples) reach across a
/// step of the acceleration of `reference_deg` (on a grid of `resolution_deg`;
/// [`acceleration_steps`]) is replaced by a one-sided derivative of the reference on its
/// own side: the slope at that sample of the least-squares polynomial through up to
/// `one_sided_len` samples (at least four, the exact four-point derivative) clear of
/// another step ([`Motion::from_reference_with_steps`]).
#[allow(clippy::too_many_arguments)] // one private helper of the two constructors above
fn trajectory_with_steps(
    start_s: f64,
    period_s: f64,
    angle_deg: Vec<f64>,
    mut rate_dps: Vec<f64>,
    reference_deg: &[f64],
    smooth_half: usize,
    resolution_deg: f64,
    one_sided_len: usize,
) -> Motion {
    let n = reference_deg.len().min(rate_dps.len());
    let raw = &reference_deg[..n];
    let steps = acceleration_steps(raw, resolution_deg);
    let reach = 2 + smooth_half;
    let origin = raw.first().copied().unwrap_or(0.0);
    let mut models = Vec::with_capacity(steps.len());
    for (i, &m) in steps.iter().enumerate() {
        let previous = if i > 0 { steps[i - 1] + 1 } else { 0 };
        let next = steps.get(i + 1).copied().unwrap_or(n);
        models.extend(step_model(
            raw,
            origin,
            m,
            (previous, next.min(n - 1)),
            one_sided_len,
        ));
        // Left of the step: samples m − reach + 1 ..= m, stencils k − len + 1 ..= k.
        for k in m.saturating_sub(reach - 1)..=m.min(n.saturating_sub(1)) {
            let len = one_sided_len.min(k + 1 - previous.min(k + 1));
            if len >= 4 {
                let w = end_slope_weights(len);
                let slope: f64 = w.iter().enumerate().map(|(j, w)| w * raw[k - j]).sum();
                rate_dps[k] = -slope / period_s;
            }
        }
        // Right of it: samples m + 1 ..= m + reach, stencils k ..= k + len − 1.
        let last = next.min(n - 1);
        for k in m + 1..=(m + reach).min(last) {
            let len = one_sided_len.min(last + 1 - k);
            if len >= 4 {
                let w = end_slope_weights(len);
                let slope: f64 = w.iter().enumerate().map(|(j, w)| w * raw[k + j]).sum();
                rate_dps[k] = slope / period_s;
            }
        }
    }
    Motion::Trajectory {
        start_s,
        period_s,
        angle_deg,
        rate_dps,
        steps: models,
    }
}

/// The step of the acceleration of `raw` between samples `m` and `m + 1`, its sides
/// reaching from `bounds.0` to `bounds.1` (the samples clear of the steps before and
/// after): its place from the third differences `d3` about it (a step at `m + ε` puts
/// `(1 − ε)²/2`, `(1 + 2ε − 2ε²)/2` and `ε²/2` of itself into `d3[m − 1]`, `d3[m]`,
/// `d3[m + 1]`, whose first moment is `ε − 1/2`; the smooth motion's share is taken as the
/// mean of `d3[m ± 3]`), and each side's least-squares polynomial of the samples its
/// one-sided rate is taken from (up to `one_sided_len`, less the origin `origin`). `None`
/// when a side holds fewer than four samples.
fn step_model(
    raw: &[f64],
    origin: f64,
    m: usize,
    bounds: (usize, usize),
    one_sided_len: usize,
) -> Option<AccelerationStep> {
    let d3 = |j: usize| raw[j + 2] - 3.0 * raw[j + 1] + 3.0 * raw[j] - raw[j - 1];
    let smooth = 0.5 * (d3(m - 3) + d3(m + 3));
    let [before, here, after] = [d3(m - 1), d3(m), d3(m + 1)].map(|d| d - smooth);
    let size = before + here + after;
    let at = if size.abs() > 0.0 {
        (0.5 + (after - before) / size).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let (previous, last) = bounds;
    let left_len = one_sided_len.min(m + 1 - previous.min(m + 1));
    let right_len = one_sided_len.min((last + 1).saturating_sub(m + 1));
    if left_len < 4 || right_len < 4 {
        return None;
    }
    let fit = |first: usize, len: usize| {
        let offsets: Vec<f64> = (first..first + len)
            .map(|k| k as f64 - (m as f64 + at))
            .collect();
        let degree = if len >= ONE_SIDED_QUARTIC_FROM { 4 } else { 3 };
        let mut c = [0.0; STEP_POLY_TERMS];
        for (p, c) in c.iter_mut().enumerate().take(degree + 1) {
            let w = least_squares_weights(&offsets, degree, p);
            *c = w
                .iter()
                .zip(&raw[first..first + len])
                .map(|(w, r)| w * (r - origin))
                .sum();
        }
        c
    };
    Some(AccelerationStep {
        index: m,
        at,
        sides: [fit(m + 1 - left_len, left_len), fit(m + 1, right_len)],
    })
}

/// The weights `w` of the slope at `x = 0` of the least-squares polynomial through samples
/// `x = 0, 1, …, len − 1` (per sample: `Σ w[j]·y[j]`), `len` at least 4: a cubic, or from
/// [`ONE_SIDED_QUARTIC_FROM`] samples a quartic. Four samples give the exact four-point
/// derivative `(−11, 18, −9, 2)/6`; more average the rounding of a printed reference down
/// while the polynomial still follows a turn's own side of a step.
fn end_slope_weights(len: usize) -> Vec<f64> {
    let offsets: Vec<f64> = (0..len).map(|j| j as f64).collect();
    let degree = if len >= ONE_SIDED_QUARTIC_FROM { 4 } else { 3 };
    least_squares_weights(&offsets, degree, 1)
}

/// The weights of the coefficient of `x^derivative` (the value for 0, the slope for 1) at
/// offset 0 of the least-squares polynomial of `degree` through samples at `offsets` (per
/// sample, in sample units). Solved on offsets scaled to ±1 so that long windows stay well
/// conditioned.
fn least_squares_weights(offsets: &[f64], degree: usize, derivative: usize) -> Vec<f64> {
    let scale = offsets.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    let terms = degree + 1;
    let powers = |x: f64| -> Vec<f64> {
        (0..terms)
            .scan(1.0, |p, _| {
                let now = *p;
                *p *= x / scale;
                Some(now)
            })
            .collect()
    };
    // Normal equations (VᵀV) c = Vᵀy; the wanted coefficient is c[derivative]: solve
    // (VᵀV) r = e_derivative, and w[j] = Σ_p r[p]·(x_j/scale)^p.
    let mut a = vec![vec![0.0_f64; terms + 1]; terms];
    for &x in offsets {
        let v = powers(x);
        for (p, row) in a.iter_mut().enumerate() {
            for q in 0..terms {
                row[q] += v[p] * v[q];
            }
        }
    }
    a[derivative][terms] = 1.0;
    for col in 0..terms {
        let pivot = (col..terms)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        let d = a[col][col];
        for v in a[col].iter_mut() {
            *v /= d;
        }
        let pivot_row = a[col].clone();
        for (row, r) in a.iter_mut().enumerate() {
            if row != col {
                let f = r[col];
                for (v, p) in r.iter_mut().zip(&pivot_row) {
                    *v -= f * p;
                }
            }
        }
    }
    let r: Vec<f64> = a.iter().map(|row| row[terms]).collect();
    let unit = scale.powi(derivative as i32);
    offsets
        .iter()
        .map(|&x| powers(x).iter().zip(&r).map(|(v, r)| v * r).sum::<f64>() / unit)
        .collect()
}

/// `angle_deg` smoothed by the Savitzky-Golay filter of [`print_smoothing_weights`] of
/// half width `half_width` samples, narrowed to what the ends hold; a half width under 2
/// is the identity.
fn print_smoothed(angle_deg: &[f64], half_width: usize) -> Vec<f64> {
    let n = angle_deg.len();
    let full = print_smoothing_weights(half_width.max(2));
    (0..n)
        .map(|i| {
            let m = half_width.min(i).min(n - 1 - i);
            if m < 2 {
                return angle_deg[i];
            }
            let narrowed;
            let weights = if m == half_width {
                &full
            } else {
                narrowed = print_smoothing_weights(m);
                &narrowed
            };
            weights
                .iter()
                .zip(&angle_deg[i - m..=i + m])
                .map(|(w, a)| w * a)
                .sum()
        })
        .collect()
}

/// The centre weights of the Savitzky-Golay smoothing of a printed reference, half width
/// `m` (at least 2): quintic from three samples on (a cubic's error on a turn, which grows
/// with the fifth derivative of its angle, is a share of the rate that a real gyro does
/// not show: 0.08% at 2.5 Hz with half width 4 at 100 Hz, against 0.009% for the
/// quintic of half width 7, whose rounding noise is the lower too), cubic at two.
fn print_smoothing_weights(m: usize) -> Vec<f64> {
    let offsets: Vec<f64> = (0..=2 * m).map(|j| j as f64 - m as f64).collect();
    least_squares_weights(&offsets, if m >= 3 { 5 } else { 3 }, 0)
}

/// Standard deviation (deg/s) of the noise that rounding a reference to `step_deg`
/// (uniform, `step/√12` per sample) puts into the rate of
/// [`Motion::from_rounded_reference`] at `fs` Hz with a smoothing of half width
/// `half_width`: the rounding through the five-point derivative of the smoothed angle.
/// Unsmoothed (half width under 2) it is `0.274 · step · fs`: 0.27 °/s for a reference
/// printed to 0.001° at 1 kHz.
pub fn rounding_noise_dps(step_deg: f64, fs: f64, half_width: usize) -> f64 {
    const DERIVATIVE: [f64; 5] = [1.0, -8.0, 0.0, 8.0, -1.0];
    let smooth = if half_width < 2 {
        vec![1.0]
    } else {
        print_smoothing_weights(half_width)
    };
    let mut kernel = vec![0.0; smooth.len() + DERIVATIVE.len() - 1];
    for (i, s) in smooth.iter().enumerate() {
        for (j, d) in DERIVATIVE.iter().enumerate() {
            kernel[i + j] += s * d / 12.0;
        }
    }
    let gain: f64 = kernel.iter().map(|k| k * k).sum::<f64>().sqrt();
    step_deg / 12f64.sqrt() * gain * fs
}

/// The angle of `reference_deg` less its first sample, smoothed by a centred moving
/// average of `smooth_samples` ([`Motion::from_reference`]), and its rate at each sample
/// ([`centred_rate`]).
fn smoothed(period_s: f64, reference_deg: &[f64], smooth_samples: usize) -> (Vec<f64>, Vec<f64>) {
    let origin = reference_deg.first().copied().unwrap_or(0.0);
    let half = smooth_samples / 2;
    let n = reference_deg.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for r in reference_deg {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + (r - origin));
    }
    let smoothed: Vec<f64> = (0..n)
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(n);
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect();
    let start = smoothed.first().copied().unwrap_or(0.0);
    let angle_deg: Vec<f64> = smoothed.iter().map(|a| a - start).collect();
    let rate_dps = (0..n)
        .map(|k| centred_rate(&angle_deg, period_s, k))
        .collect();
    (angle_deg, rate_dps)
}

/// The rate at sample `k` of `angle_deg` (period `period_s`): a centred five-point
/// derivative, so the rate at a sample is centred on it (the slope of the segment after
/// it would lead the angle by half a sample), its sum over the samples telescopes to the
/// angle change (up to the ends), and its truncation error is O(h⁴). The simulated gyro
/// measures the motion's rate, not the ±1-sample difference that `diagnose` takes of the
/// reference: with the same difference in both, a re-simulation would lack the
/// difference's own error (−h²·ω‴/6), which a real gyro against a 100 Hz reference shows
/// where turns start and end. Three points at the ends.
fn centred_rate(angle_deg: &[f64], period_s: f64, k: usize) -> f64 {
    let n = angle_deg.len();
    if n < 2 {
        return 0.0;
    }
    if k >= 2 && k + 2 < n {
        let near = angle_deg[k + 1] - angle_deg[k - 1];
        let far = angle_deg[k + 2] - angle_deg[k - 2];
        return (8.0 * near - far) / (12.0 * period_s);
    }
    let (lo, hi) = (k.saturating_sub(1), (k + 1).min(n - 1));
    (angle_deg[hi] - angle_deg[lo]) / (period_s * (hi - lo) as f64)
}

/// The acceleration steps of `raw` (on a grid of `resolution_deg`): each `m` such that a
/// step lies between samples `m` and `m + 1` ([`Motion::from_reference_with_steps`]), in
/// order.
fn acceleration_steps(raw: &[f64], resolution_deg: f64) -> Vec<usize> {
    let n = raw.len();
    if n < 16 {
        return Vec::new();
    }
    // d3[j] = x[j+2] − 3x[j+1] + 3x[j] − x[j−1], for j in 1 ..= n − 3.
    let d3 = |j: usize| raw[j + 2] - 3.0 * raw[j + 1] + 3.0 * raw[j] - raw[j - 1];
    let floor = STEP_FLOOR * resolution_deg.max(0.0);
    (6..n - 8)
        .filter(|&m| {
            let (here, before, after) = (d3(m), d3(m - 1), d3(m + 1));
            let smooth = (3..=5)
                .map(|o| d3(m - o).abs().max(d3(m + o).abs()))
                .fold(0.0, f64::max);
            // A neighbour of the other sign is the smooth motion's or the rounding's.
            let beside = |x: f64| here * x >= 0.0 || x.abs() <= floor + smooth;
            here.abs() > floor
                && here.abs() >= before.abs()
                && here.abs() >= after.abs()
                && beside(before)
                && beside(after)
                && here.abs() > STEP_RATIO * smooth
        })
        .collect()
}

/// The cubic Hermite interpolant at fraction `w` of an interval `period_s` long between
/// `values` with the slopes `slopes` (per second).
///
/// A sampled trajectory is read between its samples whenever a clock or a latency moves
/// the sampling off its grid. Linear interpolation there errs by up to `h²/8` times the
/// curvature: at 100 Hz, on a wrench's turn (1 850 °/s² of acceleration), 0.023° of angle,
/// twenty times a 0.001° print; its centred difference changes the reference's own
/// differencing error by up to three quarters, so the moving residual of a re-simulation
/// with a clock error differed from the real one's by its interpolation alone. The cubic
/// errs by `h⁴/384` times the fourth derivative.
fn hermite(values: [f64; 2], slopes: [f64; 2], period_s: f64, w: f64) -> f64 {
    let (w2, w3) = (w * w, w * w * w);
    let h00 = 2.0 * w3 - 3.0 * w2 + 1.0;
    let h10 = w3 - 2.0 * w2 + w;
    let h01 = -2.0 * w3 + 3.0 * w2;
    let h11 = w3 - w2;
    h00 * values[0] + h10 * period_s * slopes[0] + h01 * values[1] + h11 * period_s * slopes[1]
}

/// Segment index and weight of `offset_s` in a uniform series of `n` samples.
fn locate(offset_s: f64, period_s: f64, n: usize) -> (usize, f64) {
    if n < 2 || offset_s <= 0.0 {
        return (0, 0.0);
    }
    let x = offset_s / period_s;
    let i = (x.floor() as usize).min(n - 2);
    (i, (x - i as f64).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_jerk_rotation_integrates_to_its_angle() {
        let m = Motion::from_rotations(
            vec![Rotation {
                start_s: 1.0,
                duration_s: 0.8,
                angle_deg: 90.0,
            }],
            3.0,
        );
        let dt = 1e-4;
        let integral: f64 = (0..30_000).map(|k| m.rate_dps(k as f64 * dt) * dt).sum();
        assert!((integral - 90.0).abs() < 1e-3, "{integral}");
        assert_eq!(m.angle_deg(0.5), 0.0);
        assert!((m.angle_deg(1.4) - 45.0).abs() < 1e-9);
        assert_eq!(m.angle_deg(2.5), 90.0);
    }

    #[test]
    fn bench_profile_is_seeded_and_bench_like() {
        let p = BenchProfile::default();
        let a = Motion::bench(&p, 3);
        assert_eq!(a, Motion::bench(&p, 3));
        assert_ne!(a, Motion::bench(&p, 4));
        let r = a.rotations();
        assert!(r.len() >= 4, "{}", r.len());
        for w in r.windows(2) {
            let rest = w[1].start_s - (w[0].start_s + w[0].duration_s);
            assert!((3.0..=15.0).contains(&rest), "{rest}");
        }
        for x in r {
            assert!((0.8..=4.0).contains(&x.duration_s));
            assert_eq!(x.angle_deg.abs(), 90.0);
            assert!(x.start_s + x.duration_s <= p.duration_s);
        }
    }

    #[test]
    fn trajectory_rate_integrates_to_the_smoothed_angle() {
        let reference: Vec<f64> = (0..1000)
            .map(|k| (k as f64 * 0.01).sin() * 50.0 + 10.0)
            .collect();
        let m = Motion::from_reference(0.0, 0.01, &reference, 5);
        let integral: f64 = (0..999)
            .map(|k| m.rate_dps(k as f64 * 0.01 + 0.005) * 0.01)
            .sum();
        // Telescoping up to the ends, where the stencil changes.
        assert!(
            (integral - m.angle_deg(9.99)).abs() < 1e-2,
            "{integral} {}",
            m.angle_deg(9.99)
        );
        assert!((m.angle_deg(9.99) - (reference[999] - reference[0])).abs() < 0.2);
    }

    #[test]
    fn trajectory_rate_is_the_motions_rate_not_a_centred_difference() {
        // A 2 Hz swing sampled at 100 Hz: a ±1-sample difference is 2.6% short of the
        // peak rate (sin(x)/x at x = 2π·2/100); the five-point one is within 0.02%.
        let (f_hz, period_s) = (2.0, 0.01);
        let reference: Vec<f64> = (0..500)
            .map(|k| (std::f64::consts::TAU * f_hz * k as f64 * period_s).sin() * 30.0)
            .collect();
        let m = Motion::from_reference(0.0, period_s, &reference, 1);
        let worst = (5..495)
            .map(|k| {
                let t = k as f64 * period_s;
                let truth =
                    30.0 * std::f64::consts::TAU * f_hz * (std::f64::consts::TAU * f_hz * t).cos();
                (m.rate_dps(t) - truth).abs()
            })
            .fold(0.0, f64::max);
        let peak = 30.0 * std::f64::consts::TAU * f_hz;
        assert!(worst < 2e-4 * peak, "{worst} of {peak}");
    }
    /// Raised-cosine turns sampled at 100 Hz (the rate a half sine, the acceleration
    /// stepping where a turn starts and ends), and the exact rate at the samples.
    fn raised_cosine_turns(round_deg: f64) -> (Vec<f64>, Vec<f64>) {
        let fs = 100.0;
        let turns = [
            (1.003, 0.4, 120.0),
            (3.0571, 0.55, -80.0),
            (5.5, 0.37, 135.0),
        ];
        let (mut angle, mut rate) = (Vec::new(), Vec::new());
        for k in 0..800 {
            let (a, r) = turns_at(&turns, k as f64 / fs);
            angle.push(if round_deg > 0.0 {
                (a / round_deg).round() * round_deg
            } else {
                a
            });
            rate.push(r);
        }
        (angle, rate)
    }

    /// The largest error of `m`'s rate within four samples of a turn's start or end.
    fn worst_error(m: &Motion, rate: &[f64]) -> f64 {
        let moving = |k: usize| rate[k] != 0.0;
        (4..rate.len() - 4)
            .filter(|&k| (k - 4..=k + 4).any(|j| moving(j) != moving(k)))
            .map(|k| (m.rate_dps(k as f64 * 0.01) - rate[k]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn rounding_noise_is_what_a_rounded_reference_leaves_in_the_rate() {
        // A turn at 37.3 °/s with a slow swing, sampled at 1 kHz and printed to 0.001°:
        // the rounding is spread uniformly, and the rate read from it holds the noise
        // predicted.
        let (fs, step) = (1000.0, 0.001);
        let omega = 2.0 * std::f64::consts::PI * 0.37;
        let angle = |t: f64| 37.3 * t + 3.0 * (omega * t).sin();
        let rate = |t: f64| 37.3 + 3.0 * omega * (omega * t).cos();
        let printed: Vec<f64> = (0..30_000)
            .map(|k| (angle(k as f64 / fs) / step).round() * step)
            .collect();
        for half_width in [0, 4, 40] {
            let motion = Motion::from_rounded_reference(0.0, 1.0 / fs, &printed, half_width, step);
            let errors: Vec<f64> = (100..29_900)
                .map(|k| motion.rate_dps(k as f64 / fs) - rate(k as f64 / fs))
                .collect();
            let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
            let predicted = rounding_noise_dps(step, fs, half_width);
            assert!(
                (rms / predicted - 1.0).abs() < 0.1,
                "half width {half_width}: {rms} against {predicted}"
            );
        }
        assert!((rounding_noise_dps(step, fs, 0) - 0.2743).abs() < 1e-4);
        // The angle is kept as printed.
        let motion = Motion::from_rounded_reference(0.0, 1.0 / fs, &printed, 40, step);
        assert_eq!(motion.angle_deg(0.5), printed[500] - printed[0]);
    }

    /// The one-sided slope of a least-squares polynomial: through four samples it is the
    /// exact four-point derivative, and through more it is still exact on a cubic.
    #[test]
    fn end_slope_weights_are_exact_on_cubics() {
        let four = end_slope_weights(4);
        for (w, exact) in four.iter().zip([-11.0 / 6.0, 3.0, -1.5, 1.0 / 3.0]) {
            assert!((w - exact).abs() < 1e-12, "{four:?}");
        }
        for len in 4..12 {
            let w = end_slope_weights(len);
            let y: Vec<f64> = (0..len)
                .map(|x| {
                    let x = x as f64;
                    2.0 - 0.7 * x + 0.3 * x * x - 0.05 * x * x * x
                })
                .collect();
            let slope: f64 = w.iter().zip(&y).map(|(w, y)| w * y).sum();
            assert!((slope + 0.7).abs() < 1e-9, "{len}: {slope}");
        }
    }

    /// `count` turns (start s, duration s, angle deg) of alternating sign, the `i`-th
    /// starting at `start.0 + i·start.1`, lasting `duration.0 + i·duration.1` and turning by
    /// `angle.0 + i·angle.1` degrees.
    fn alternating_turns(
        count: i32,
        start: (f64, f64),
        duration: (f64, f64),
        angle: (f64, f64),
    ) -> Vec<(f64, f64, f64)> {
        (0..count)
            .map(|i| {
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                let i = f64::from(i);
                (
                    start.0 + start.1 * i,
                    duration.0 + duration.1 * i,
                    sign * (angle.0 + angle.1 * i),
                )
            })
            .collect()
    }

    /// The exact angle (deg) and rate (deg/s) at `t` of raised-cosine `turns`, whose
    /// acceleration steps where each starts and ends.
    fn turns_at(turns: &[(f64, f64, f64)], t: f64) -> (f64, f64) {
        let pi = std::f64::consts::PI;
        let (mut a, mut r) = (0.0, 0.0);
        for &(start, d, turn) in turns {
            a += turn * (1.0 - (pi * ((t - start) / d).clamp(0.0, 1.0)).cos()) / 2.0;
            if t > start && t < start + d {
                r += turn * pi / (2.0 * d) * (pi * (t - start) / d).sin();
            }
        }
        (a, r)
    }

    /// Beside the acceleration steps of raised-cosine turns printed to 0.001° at 100 Hz,
    /// the re-simulated rate of a print ([`Motion::from_rounded_reference`], half width 4)
    /// is within 0.05 °/s rms of the exact rate; the four-point derivative there carries
    /// the rounding at 0.08 °/s, which a real gyro never saw ([`PRINT_ONE_SIDED_EXTRA`]).
    #[test]
    fn one_sided_rate_of_a_print_averages_its_rounding() {
        let (fs, step, half_width) = (100.0, 0.001, 4);
        let turns = alternating_turns(24, (1.0, 2.6137), (0.6, 0.035), (45.0, 3.9));
        let n = 6500;
        let (mut printed, mut rate) = (Vec::new(), Vec::new());
        for k in 0..n {
            let (a, r) = turns_at(&turns, k as f64 / fs);
            printed.push((a / step).round() * step);
            rate.push(r);
        }
        // The samples within six of a turn's start or end: where the one-sided rate acts.
        let beside: Vec<usize> = (6..n - 6)
            .filter(|&k| (k - 6..=k + 6).any(|j| (rate[j] != 0.0) != (rate[k] != 0.0)))
            .collect();
        let rms = |m: &Motion| {
            let sum: f64 = beside
                .iter()
                .map(|&k| (m.rate_dps(k as f64 / fs) - rate[k]).powi(2))
                .sum();
            (sum / beside.len() as f64).sqrt()
        };
        let print = Motion::from_rounded_reference(0.0, 1.0 / fs, &printed, half_width, step);
        let origin = printed[0];
        let angle: Vec<f64> = printed.iter().map(|r| r - origin).collect();
        let smooth = print_smoothed(&angle, half_width);
        let centred: Vec<f64> = (0..n).map(|k| centred_rate(&smooth, 1.0 / fs, k)).collect();
        let four =
            trajectory_with_steps(0.0, 1.0 / fs, angle, centred, &printed, half_width, step, 4);
        let (now, four_point) = (rms(&print), rms(&four));
        assert!(now < 0.05, "{now} deg/s rms beside the steps");
        assert!(
            four_point > 1.5 * now,
            "four-point {four_point} against {now}"
        );
    }

    /// Read between its samples (a clock error or a latency), a printed reference's
    /// trajectory follows the turns' rate and angle where they start and end, at the
    /// step's own place within the interval: a rounded-off step there would shrink the
    /// residual spikes a real gyro shows beside it.
    #[test]
    fn a_trajectory_read_between_samples_keeps_its_acceleration_steps() {
        let (fs, step, half_width) = (100.0, 0.001, 8);
        // Turns starting at every place within a sample interval.
        let turns = alternating_turns(20, (1.0, 2.3771), (0.5, 0.03), (60.0, 3.7));
        let exact = |t: f64| turns_at(&turns, t);
        let n = 5000;
        let printed: Vec<f64> = (0..n)
            .map(|k| (exact(k as f64 / fs).0 / step).round() * step)
            .collect();
        let motion = Motion::from_rounded_reference(0.0, 1.0 / fs, &printed, half_width, step);
        let Motion::Trajectory {
            steps, rate_dps, ..
        } = &motion
        else {
            panic!("a trajectory");
        };
        assert_eq!(
            steps.len(),
            2 * turns.len(),
            "every start and end is a step"
        );
        // Each step's place: within 0.05 of a sample of the turn's own.
        for (s, edge) in steps
            .iter()
            .zip(turns.iter().flat_map(|&(t0, d, _)| [t0, t0 + d]))
        {
            let place = (s.index as f64 + s.at) / fs;
            assert!(
                (place - edge).abs() < 0.05 / fs,
                "step at {place} s, edge at {edge} s"
            );
        }
        // Times a third and two thirds into the intervals within three samples of a step.
        let times: Vec<f64> = steps
            .iter()
            .flat_map(|s| {
                (s.index - 3..=s.index + 3).flat_map(|k| [k as f64 + 0.33, k as f64 + 0.67])
            })
            .map(|x| x / fs)
            .collect();
        let rms = |f: &dyn Fn(f64) -> f64| {
            (times.iter().map(|&t| f(t).powi(2)).sum::<f64>() / times.len() as f64).sqrt()
        };
        let rate_error = rms(&|t| motion.rate_dps(t) - exact(t).1);
        let angle_error = rms(&|t| motion.angle_deg(t) - (exact(t).0 - printed[0]));
        // What the samples' rates linearly interpolated give there.
        let linear_error = rms(&|t| {
            let (i, w) = locate(t, 1.0 / fs, n);
            rate_dps[i] + w * (rate_dps[i + 1] - rate_dps[i]) - exact(t).1
        });
        assert!(rate_error < 0.1, "{rate_error} deg/s rms beside the steps");
        assert!(
            linear_error > 5.0 * rate_error,
            "linear {linear_error} against {rate_error}"
        );
        assert!(
            angle_error < 0.001,
            "{angle_error} deg rms beside the steps"
        );
        // On the samples it reads the samples.
        for k in [0, 100, 2501, n - 1] {
            let t = k as f64 / fs;
            assert!((motion.angle_deg(t) - (printed[k] - printed[0])).abs() < 1e-9);
            assert!((motion.rate_dps(t) - rate_dps[k]).abs() < 1e-9);
        }
    }

    /// Where a turn's acceleration steps, the centred derivative is several deg/s off
    /// the gyro's rate at 100 Hz; the one-sided one is within 0.5 deg/s (exact angles,
    /// and angles printed to 0.001 deg and smoothed over three samples as an encoder's),
    /// within four samples of a turn's start or end.
    #[test]
    fn acceleration_steps_take_the_rate_of_their_own_side() {
        for (round_deg, smooth) in [(0.0, 1), (0.001, 3)] {
            let (angle, rate) = raised_cosine_turns(round_deg);
            let centred = Motion::from_reference(0.0, 0.01, &angle, smooth);
            let sided = Motion::from_reference_with_steps(0.0, 0.01, &angle, smooth, round_deg);
            let (before, after) = (worst_error(&centred, &rate), worst_error(&sided, &rate));
            assert!(before > 3.0, "{round_deg}: {before}");
            assert!(after < 0.5, "{round_deg}: {before} -> {after}");
            // The angle is the smoothed reference's either way.
            assert_eq!(centred.angle_deg(3.3), sided.angle_deg(3.3));
        }
    }

    /// Smooth motion is left as it was: minimum-jerk turns at 1 kHz (the acceleration
    /// continuous, its derivative stepping; within 0.01 deg/s, a fifteenth of the CRM100's
    /// white noise per sample), and a piecewise-linear angle (a step of the rate itself,
    /// which no derivative of the samples resolves) exactly.
    #[test]
    fn smooth_turns_and_rate_steps_are_left_alone() {
        let m = Motion::bench(&BenchProfile::default(), 11);
        let angle: Vec<f64> = (0..60_000)
            .map(|k| (m.angle_deg(k as f64 * 1e-3) * 1e6).round() / 1e6)
            .collect();
        let centred = Motion::from_reference(0.0, 1e-3, &angle, 1);
        let sided = Motion::from_reference_with_steps(0.0, 1e-3, &angle, 1, 0.0);
        let (mut worst, mut changed) = (0.0f64, 0);
        for k in 0..60_000 {
            let d = (centred.rate_dps(k as f64 * 1e-3) - sided.rate_dps(k as f64 * 1e-3)).abs();
            worst = worst.max(d);
            changed += usize::from(d > 0.0);
        }
        // Rounding to 1e-6 deg can make a third difference peak where the turn's jerk
        // passes zero; the rate there moves by a few thousandths of a deg/s.
        assert!(worst < 0.01, "{worst} deg/s at {changed} samples");
        let ramps: Vec<f64> = (0..400)
            .map(|k| match k {
                0..=99 => 0.0,
                100..=199 => (k - 100) as f64 * 0.5,
                _ => 50.0 - (k as f64 - 200.0).min(100.0) * 0.5,
            })
            .collect();
        assert!(
            Motion::from_reference(0.0, 0.01, &ramps, 1)
                == Motion::from_reference_with_steps(0.0, 0.01, &ramps, 1, 0.0),
            "a rate step was taken for an acceleration step"
        );
    }
}
