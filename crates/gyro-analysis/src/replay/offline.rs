//! The offline mode of a replay (`run --offline`): each movement's angle read after the rest
//! that follows it, its bias from the rests of the whole log on both sides.
//!
//! Two passes. The first reads every rest in blocks of about [`NOISE_BLOCK`] outputs
//! ([`REST_MARGIN`] in from each movement) and fits the bias through the log to them
//! ([`Smoother::bias_path`], [`crate::bias_path`]: a random walk smoothed by
//! Rauch–Tung–Striebel, its rate the most likely for these readings). A bias that holds still
//! fits a walk near zero, and every rest counts for every movement; one that drifts, a larger
//! walk, and each movement's bias comes from the rests next to it. The second pass
//! ([`Smoother::with_path`]) gives each movement its uncompensated angle less that bias
//! integrated over it, and a variance of the white noise integrated over the movement (from
//! consecutive rest blocks) plus the path's own over the movement.
//!
//! Without a path (a single pass, as a streaming caller that cannot read the log twice
//! has), a movement's angle is the causal angle at the start of the next movement less the
//! causal angle at the start of this one: the Kalman form's zero-rate updates in the rest
//! after the movement correct its bias and, through the angle–bias correlation, the angle
//! it added, so the bias comes from the rest before (the filter's prior) and the rest after
//! (its updates). Its variance is then measured from the log's own rests: the white noise
//! integrated over the movement, the bias error at the movement's two ends interpolated
//! through it, and the wander within it (a random walk pinned by the rests on both sides),
//! the last two from the change of the bias estimate across each movement so far
//! ([`BiasSteps`]).
//!
//! The series is smoothed alike: within a movement, the uncompensated angle since its start
//! less the path's bias (without a path, the correction the rest after made spread in
//! proportion to the elapsed time); over a rest, the angle is the smoothed one at its end.
//! That needs the outputs from a movement's start to the next movement's start: memory holds
//! one movement and the rest after it, and the first pass's rest blocks (three numbers per
//! block of rest), not the log.

use super::SeriesPoint;
use crate::bias_path::{BiasPath, Reading};
use std::collections::VecDeque;

/// A movement waiting for the rest after it.
#[derive(Clone, Copy, Debug)]
struct Pending {
    /// Its place in the report's movements, once it has ended.
    movement: Option<usize>,
    /// Output index of its start (last quiet sample before).
    start_index: usize,
    /// Output index of its end (first quiet sample after), once ended.
    end_index: Option<usize>,
}

/// A movement's angle and variance from the rests on both sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Smoothed {
    /// The movement's place in the report's movements.
    pub movement: usize,
    /// Its angle (deg).
    pub angle_deg: f32,
    /// Its standard deviation (deg), when the causal series has one.
    pub angle_std_deg: Option<f32>,
}

/// The offline smoothing of one replay's output series, fed the causal outputs in order.
#[derive(Debug, Default)]
pub(super) struct Smoother {
    /// Causal outputs not yet smoothed: output indices `first..first + held.len()`.
    held: VecDeque<SeriesPoint>,
    first: usize,
    /// The movement whose rest after is being read.
    pending: Option<Pending>,
    /// Smoothed angle (deg) and variance (deg²) at the start of the pending movement, less the
    /// causal ones there: what a smoothed output adds to its causal angle.
    offset_deg: f64,
    variance_offset: f64,
    /// The smoothed angle and variance are set (a movement has started).
    anchored: bool,
    /// Smoothed points ready for the caller.
    ready: Vec<SeriesPoint>,
    /// The most outputs held at once.
    most_held: usize,
    /// The filter's prior for the white rate noise integrated over one output step (deg²),
    /// until the rests have measured it.
    prior_step_variance: f64,
    /// The white rate noise integrated over one output step as the rests show it (deg²):
    /// half the mean square of the difference of consecutive rest blocks' mean rates,
    /// times the block's length and the step squared.
    block_pairs: (f64, usize),
    /// The rest block being summed: (sum of rates, samples), and the last complete one's mean.
    block: (f64, usize),
    last_block_mean: Option<f64>,
    /// The last pair's half squared difference, counted once a further rest block follows.
    pair_pending: Option<f64>,
    /// Output step (s).
    step_s: f64,
    /// The bias's change across each smoothed movement so far.
    bias_steps: BiasSteps,
    /// The rests' blocks read so far: what [`Smoother::bias_path`] is fitted to.
    rest_blocks: Vec<RestBlock>,
    /// The index of the first output after the last movement's end, where the next rest's
    /// blocks start (0: from the log's start).
    rest_from: usize,
    /// The bias through the whole log from a first pass ([`Smoother::with_path`]): each
    /// movement's bias from it, in place of the causal filter's.
    path: Option<BiasPath>,
}

/// One block of a rest: its middle (s), mean rate (deg/s) and outputs.
#[derive(Clone, Copy, Debug)]
struct RestBlock {
    time_s: f64,
    mean_dps: f64,
    outputs: usize,
    /// The first block of a rest after a movement.
    after_movement: bool,
}

/// Outputs left out of a rest's blocks next to a movement (0.1 s at 50 Hz): the filtered
/// rate's rise into the movement, and its tail after, below the detector's levels.
const REST_MARGIN: usize = 5;

/// The bias's change Δb across each smoothed movement, from the rest before it to the end of
/// the rest after it (over Δt): what the rests say of the bias error at a movement's ends
/// and of its wander between them.
#[derive(Clone, Copy, Debug, Default)]
struct BiasSteps {
    /// Σ Δb² (deg²/s²).
    squares: f64,
    /// Σ Δb²/Δt (deg²/s³): a random-walk rate of the wander at the movements' time scale.
    rates: f64,
    count: usize,
}

impl BiasSteps {
    fn observe(&mut self, step_dps: f64, gap_s: f64) {
        self.squares += step_dps * step_dps;
        self.rates += step_dps * step_dps / gap_s;
        self.count += 1;
    }

    /// The variance (deg²) the bias adds to the angle of a movement of `duration_s`: its
    /// error at the two ends, independent, interpolated through the movement
    /// (`T²·(v₀ + v₁)/4`, with `v₀ + v₁` at most the mean Δb², which holds the wander
    /// between the rests too), and the wander within it ([`bridge_variance`]). Zero
    /// before any step.
    fn variance(&self, duration_s: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let n = self.count as f64;
        duration_s * duration_s * self.squares / n / 4.0
            + bridge_variance(self.rates / n, duration_s)
    }
}

/// Rest outputs per noise block (0.2 s at 50 Hz): a block mean against the next measures
/// the white noise the movement's angle integrates.
const NOISE_BLOCK: usize = 10;

/// The variance (deg²) that a bias wandering as a random walk of rate `k2` (deg²/s³)
/// adds to the angle integrated over `duration_s` when its value is pinned at both ends
/// (by the rests on either side): the integral of a Brownian bridge, `k2·T³/12`.
fn bridge_variance(k2: f64, duration_s: f64) -> f64 {
    k2 * duration_s.powi(3) / 12.0
}

fn variance_of(point: &SeriesPoint) -> Option<f64> {
    point.angle_std_deg.map(|s| f64::from(s) * f64::from(s))
}

impl Smoother {
    /// A smoother for outputs `step_s` apart from a filter whose white rate noise prior is
    /// `rate_noise_dps` per output.
    pub fn new(step_s: f64, rate_noise_dps: f64) -> Self {
        Self {
            prior_step_variance: (rate_noise_dps * step_s).powi(2),
            step_s,
            ..Self::default()
        }
    }

    /// The smoother with `path`, the bias through the whole log ([`Smoother::bias_path`] of a
    /// first pass over it): each movement's angle is then its uncompensated angle less the
    /// path's bias integrated over it, and its variance the white noise's and the path's.
    pub fn with_path(self, path: BiasPath) -> Self {
        Self {
            path: Some(path),
            ..self
        }
    }

    /// The bias through the log so far, smoothed from every rest's blocks (call after
    /// [`Smoother::finish`]): the blocks' means, each with the white noise over its
    /// outputs as the rests measure it, fitted by [`BiasPath::fit`]. `None` without a rest.
    pub fn bias_path(&self) -> Option<BiasPath> {
        let per_output = self.step_variance() / (self.step_s * self.step_s);
        let (readings, after): (Vec<Reading>, Vec<bool>) = self
            .rest_blocks
            .iter()
            .map(|b| {
                let reading = Reading {
                    time_s: b.time_s,
                    bias_dps: b.mean_dps,
                    variance: per_output / b.outputs as f64,
                };
                (reading, b.after_movement)
            })
            .filter(|(r, _)| r.bias_dps.is_finite() && r.variance > 0.0)
            .unzip();
        let across: Vec<usize> = (1..readings.len()).filter(|&i| after[i]).collect();
        Some(BiasPath::fit(&readings)?.calibrated(&readings, &across))
    }

    /// Read the rest that ends at output `last` (held) into blocks: from the first output
    /// after the last movement's end, [`REST_MARGIN`] outputs in from each movement, in
    /// blocks of equal length near [`NOISE_BLOCK`] outputs, static outputs only.
    /// `after_movement` / `before_movement`: a movement lies on that side.
    fn read_rest(&mut self, last: usize, after_movement: bool, before_movement: bool) {
        let from = self.rest_from + if after_movement { REST_MARGIN } else { 0 };
        let to = if before_movement {
            last.saturating_sub(REST_MARGIN)
        } else {
            last
        };
        if to < from + 1 || from < self.first {
            return;
        }
        let len = to + 1 - from;
        let blocks = (len / NOISE_BLOCK).max(1);
        let mut read_one = false;
        for k in 0..blocks {
            let (i, j) = (from + k * len / blocks, from + (k + 1) * len / blocks);
            let (mut time, mut sum, mut n) = (0.0, 0.0, 0usize);
            for index in i..j {
                if let Some(p) = self.at(index) {
                    if p.motion == gyro_core::MotionState::Static && p.rate_dps.is_finite() {
                        time += p.time_s;
                        sum += f64::from(p.rate_dps);
                        n += 1;
                    }
                }
            }
            if n >= NOISE_BLOCK / 2 {
                self.rest_blocks.push(RestBlock {
                    time_s: time / n as f64,
                    mean_dps: sum / n as f64,
                    outputs: n,
                    after_movement: after_movement && !read_one,
                });
                read_one = true;
            }
        }
    }

    /// The white noise integrated per step as measured at rest, else the prior (deg²).
    fn step_variance(&self) -> f64 {
        match self.block_pairs {
            (sum, n) if n >= 8 => sum / n as f64 * NOISE_BLOCK as f64 * self.step_s * self.step_s,
            _ => self.prior_step_variance,
        }
    }

    /// The next causal output.
    pub fn push(&mut self, point: SeriesPoint) {
        if point.motion == gyro_core::MotionState::Static && self.pending_is_settled() {
            self.block.0 += f64::from(point.rate_dps);
            self.block.1 += 1;
            if self.block.1 == NOISE_BLOCK {
                let mean = self.block.0 / NOISE_BLOCK as f64;
                // The pair before this block counts now that a further block at rest
                // follows it: the last block before a movement is declared holds the
                // turn's first rise (below the detector's entry level, labelled static),
                // and its pair is dropped with it.
                if let Some(half_square) = self.pair_pending.take() {
                    self.block_pairs.0 += half_square;
                    self.block_pairs.1 += 1;
                }
                if let Some(last) = self.last_block_mean {
                    let d = mean - last;
                    if d.is_finite() {
                        self.pair_pending = Some(0.5 * d * d);
                    }
                }
                self.last_block_mean = Some(mean);
                self.block = (0.0, 0);
            }
        } else {
            self.block = (0.0, 0);
            self.last_block_mean = None;
            self.pair_pending = None;
        }
        self.held.push_back(point);
        self.most_held = self.most_held.max(self.held.len());
    }

    /// The most outputs held at once so far.
    pub fn most_held(&self) -> usize {
        self.most_held
    }

    /// No movement is open (the pending one, if any, has ended).
    fn pending_is_settled(&self) -> bool {
        self.pending.is_none_or(|p| p.end_index.is_some())
    }

    /// The causal output with index `index`, if held.
    fn at(&self, index: usize) -> Option<&SeriesPoint> {
        self.held.get(index.checked_sub(self.first)?)
    }

    /// A movement started at output `start_index` (already pushed): the pending one, if any,
    /// is smoothed with the rest up to there.
    pub fn movement_started(&mut self, start_index: usize) -> Option<Smoothed> {
        let smoothed = self.close(start_index, true);
        self.pending = Some(Pending {
            movement: None,
            start_index,
            end_index: None,
        });
        smoothed
    }

    /// The pending movement ended at output `end_index`; `movement` is its place in the
    /// report's movements.
    pub fn movement_ended(&mut self, movement: usize, end_index: usize) {
        if let Some(p) = &mut self.pending {
            p.movement = Some(movement);
            p.end_index = Some(end_index);
        }
        self.rest_from = end_index + 1;
    }

    /// The log has ended: smooth what is pending with the rest up to the last output.
    pub fn finish(&mut self) -> Option<Smoothed> {
        let last = (self.first + self.held.len()).checked_sub(1)?;
        if self.pending.is_none() {
            // A log without a movement: one rest.
            self.read_rest(last, false, false);
        }
        let smoothed = match self.pending {
            Some(Pending {
                end_index: Some(_), ..
            }) => self.close(last, false),
            _ => None,
        };
        // What is left (a movement the log ends in, or a log without movements) keeps the
        // causal angles, shifted by the smoothing so far.
        let (offset, variance_offset) = (self.offset_deg, self.variance_offset);
        while let Some(p) = self.held.pop_front() {
            self.ready.push(shifted(&p, offset, variance_offset));
            self.first += 1;
        }
        smoothed
    }

    /// The smoothed points made since the last call.
    pub fn take_ready(&mut self) -> std::vec::Drain<'_, SeriesPoint> {
        self.ready.drain(..)
    }

    /// Smooth the pending movement with the rest that ends at output `until` (held), and
    /// release the outputs before `until`.
    fn close(&mut self, until: usize, before_movement: bool) -> Option<Smoothed> {
        let end = *self.at(until)?;
        self.read_rest(until, self.pending.is_some(), before_movement);
        let pending = self.pending.take();
        match pending {
            None => {
                self.close_first_rest(until, &end);
                None
            }
            Some(p) => self.close_movement(p, until, &end),
        }
    }

    /// The rest before the first movement, which ends at output `until` (the point `end`):
    /// release its outputs with the angle and variance at its end.
    fn close_first_rest(&mut self, until: usize, end: &SeriesPoint) {
        // The rest before the first movement: its smoothed angle is the one at its
        // end.
        self.offset_deg = 0.0;
        self.variance_offset = 0.0;
        let (angle, variance) = (f64::from(end.angle_deg), variance_of(end));
        while self.first < until {
            let Some(p) = self.held.pop_front() else {
                break;
            };
            let mut q = p;
            q.angle_deg = angle as f32;
            if let Some(v) = variance {
                q.angle_std_deg = Some(v.max(0.0).sqrt() as f32);
            }
            self.ready.push(q);
            self.first += 1;
        }
        // From here the smoothed angle is the causal one.
        self.anchored = true;
    }

    /// The pending movement `p` and the rest after it, which ends at output `until` (the
    /// point `end`): release their outputs smoothed (the rest's bias correction spread
    /// over the movement by time), and the movement's smoothed angle once it has ended.
    fn close_movement(&mut self, p: Pending, until: usize, end: &SeriesPoint) -> Option<Smoothed> {
        let start = *self.at(p.start_index)?;
        let (end_index, movement) = match (p.end_index, p.movement) {
            (Some(e), Some(m)) if e <= until => (e, Some(m)),
            // Not ended (cannot happen: the core ends a movement before it starts
            // another): the causal angles, shifted.
            _ => (until, None),
        };
        let moved_end = *self.at(end_index)?;
        // The angle the rest after added: the correction of the movement's bias.
        let correction = f64::from(end.angle_deg - moved_end.angle_deg);
        let angle = f64::from(end.angle_deg - start.angle_deg);
        // The movement's variance, each part as the rests measure it: the white noise
        // integrated over the movement (rest blocks), the error of the bias at its two
        // ends and the wander between them (the bias steps from the rest before to the end
        // of the rest after, over every movement so far). Not the filter's own growth: its
        // wander prior, which its rests bring down only slowly, made the interval hold 99–100%
        // where the bias holds still, and missed the fast components of a 1/f bias.
        let steps = (end_index - p.start_index) as f64;
        let white = steps * self.step_variance();
        let gap_s = end.time_s - start.time_s;
        let bias_step = f64::from(end.bias_dps - start.bias_dps);
        if gap_s > 0.0 && bias_step.is_finite() {
            self.bias_steps.observe(bias_step, gap_s);
        }
        let duration_s = moved_end.time_s - start.time_s;
        let variance = match (variance_of(&start), variance_of(end)) {
            (Some(_), Some(_)) => Some(white + self.bias_steps.variance(duration_s)),
            _ => None,
        };
        // With the bias through the whole log: the movement's uncompensated angle less
        // that bias integrated over it, its variance the white noise's and the path's.
        let path = self.path.take();
        let (angle, variance) = match &path {
            Some(path) => {
                let (bias_deg, bias_variance) = path.integral(start.time_s, moved_end.time_s);
                let raw = f64::from(moved_end.raw_angle_deg) - f64::from(start.raw_angle_deg);
                (raw - bias_deg, variance.map(|_| white + bias_variance))
            }
            None => (angle, variance),
        };
        let shift = Shift {
            path: path.as_ref(),
            raw_start_deg: f64::from(start.raw_angle_deg),
            end_index,
            t0_s: start.time_s,
            t1_s: moved_end.time_s,
            offset_deg: self.offset_deg,
            variance_offset: self.variance_offset,
            base_angle_deg: f64::from(start.angle_deg),
            base_variance: variance_of(&start).unwrap_or(0.0),
            angle_deg: angle,
            correction_deg: correction,
            variance,
        };
        while self.first < until {
            let Some(q) = self.held.pop_front() else {
                break;
            };
            let index = self.first;
            self.first += 1;
            self.ready.push(shift.smoothed(index, &q));
        }
        let (offset_deg, base_angle_deg, variance_offset, base_variance) = (
            shift.offset_deg,
            shift.base_angle_deg,
            shift.variance_offset,
            shift.base_variance,
        );
        self.path = path;
        // From `until` on the smoothed angle is the causal one plus this offset.
        self.offset_deg = offset_deg + base_angle_deg + angle - f64::from(end.angle_deg);
        if let Some(v) = variance {
            self.variance_offset =
                variance_offset + base_variance + v - variance_of(end).unwrap_or(0.0);
        }
        movement.map(|movement| Smoothed {
            movement,
            angle_deg: angle as f32,
            angle_std_deg: variance.map(|v| v.sqrt() as f32),
        })
    }
}

/// How a movement and the rest after it are smoothed ([`Smoother::close_movement`]).
struct Shift<'a> {
    /// The bias through the whole log, if a first pass gave it: within the movement the
    /// uncompensated angle since its start less the path's bias over that time.
    path: Option<&'a BiasPath>,
    /// The uncompensated angle at the movement's start (deg).
    raw_start_deg: f64,
    /// Output index of the movement's end.
    end_index: usize,
    /// Times of the movement's start and end (s).
    t0_s: f64,
    t1_s: f64,
    /// The smoothing so far: angle (deg) and variance (deg²) offsets.
    offset_deg: f64,
    variance_offset: f64,
    /// The causal angle (deg) and variance (deg²) at the movement's start.
    base_angle_deg: f64,
    base_variance: f64,
    /// The movement's smoothed angle (deg).
    angle_deg: f64,
    /// The angle the rest after added (deg): the correction of the movement's bias.
    correction_deg: f64,
    /// The movement's variance gained (deg²), when both ends have one.
    variance: Option<f64>,
}

impl Shift<'_> {
    /// The output `q` at `index` smoothed: within the movement, the causal angle plus the
    /// correction's share by time; in the rest after, the smoothed angle at its end.
    fn smoothed(&self, index: usize, q: &SeriesPoint) -> SeriesPoint {
        let (t0, t1) = (self.t0_s, self.t1_s);
        let share = if index >= self.end_index {
            1.0
        } else if t1 > t0 {
            ((q.time_s - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let mut s = *q;
        if index > self.end_index {
            // The rest after: the smoothed angle at its end.
            s.angle_deg = (self.offset_deg + self.base_angle_deg + self.angle_deg) as f32;
        } else if let Some(path) = self.path {
            let raw = f64::from(q.raw_angle_deg) - self.raw_start_deg;
            let moved = raw - path.integral(t0, q.time_s.clamp(t0, t1)).0;
            s.angle_deg = (self.offset_deg + self.base_angle_deg + moved) as f32;
        } else {
            s.angle_deg =
                (self.offset_deg + f64::from(q.angle_deg) + share * self.correction_deg) as f32;
        }
        if let Some(v) = self.variance {
            s.angle_std_deg = Some(
                (self.variance_offset + self.base_variance + share * v)
                    .max(0.0)
                    .sqrt() as f32,
            );
        }
        s
    }
}

/// `p` with `offset` (deg) added to its angle and `variance_offset` (deg²) to its variance.
fn shifted(p: &SeriesPoint, offset: f64, variance_offset: f64) -> SeriesPoint {
    let mut s = *p;
    s.angle_deg = (offset + f64::from(p.angle_deg)) as f32;
    if let Some(v) = variance_of(p) {
        s.angle_std_deg = Some((v + variance_offset).max(0.0).sqrt() as f32);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// The angle a random-walk bias adds over a span whose both ends are pinned (a
    /// Brownian bridge, integrated): `k2·T³/12`, against 4 000 simulated bridges.
    #[test]
    fn a_pinned_random_walk_integrates_to_the_bridge_variance() {
        let (k2, duration_s, steps) = (0.004, 2.0, 400);
        let dt = duration_s / steps as f64;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let integrals: Vec<f64> = (0..4000)
            .map(|_| {
                let mut walk = vec![0.0];
                for _ in 0..steps {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    walk.push(walk[walk.len() - 1] + (k2 * dt).sqrt() * x);
                }
                // Pinned at both ends: less the straight line between them.
                let end = walk[steps];
                (0..steps)
                    .map(|i| {
                        let mid = 0.5 * (walk[i] + walk[i + 1]);
                        let line = end * (i as f64 + 0.5) / steps as f64;
                        (mid - line) * dt
                    })
                    .sum::<f64>()
            })
            .collect();
        let variance = integrals.iter().map(|x| x * x).sum::<f64>() / integrals.len() as f64;
        let predicted = bridge_variance(k2, duration_s);
        assert!(
            (variance / predicted - 1.0).abs() < 0.08,
            "{variance} against {predicted}"
        );
    }
}
