//! The bias through a log, smoothed from its rests on both sides: a random walk read at rest
//! blocks (Rauch–Tung–Striebel), its rate fitted to the readings by maximum likelihood.
//!
//! Each reading is the mean rate of a block at rest, the bias there plus white noise of a
//! known variance, and a jitter of the bias from block to block (fitted, often none).
//! Between readings the bias walks: its variance grows by `walk` (deg²/s³) per second. A
//! bias that holds still fits a walk near zero, and every rest of the log then
//! counts for every movement; one that drifts fits a larger walk, and each movement's bias
//! comes from the rests next to it. The walk and the jitter are the ones under which the
//! readings are the most likely, so the log, not a prior, says which.
//!
//! ```
//! use gyro_analysis::bias_path::{BiasPath, Reading};
//! // A bias of 0.2 deg/s read at four rests, each to 0.01 deg/s.
//! let readings: Vec<Reading> = [0.0, 5.0, 10.0, 15.0]
//!     .iter()
//!     .zip([0.21, 0.19, 0.2, 0.2])
//!     .map(|(&time_s, bias_dps)| Reading { time_s, bias_dps, variance: 1e-4 })
//!     .collect();
//! let path = BiasPath::fit(&readings).expect("four readings");
//! // A still bias: the walk fitted is small, every reading counts alike.
//! let (bias_dps, variance) = path.at(7.5);
//! assert!((bias_dps - 0.2).abs() < 0.002 && variance < 1e-4);
//! // A movement from 6 s to 8 s: the bias integrated over it, with its variance.
//! let (angle_deg, _) = path.integral(6.0, 8.0);
//! assert!((angle_deg - 0.4).abs() < 0.004);
//! ```

/// One reading of the bias: a block's mean rate at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// The block's middle (s).
    pub time_s: f64,
    /// Its mean rate (deg/s).
    pub bias_dps: f64,
    /// The variance of that mean about the bias (deg²/s²): the white noise over the block.
    pub variance: f64,
}

/// The walk rates (deg²/s³) the fit compares, a factor of √10 apart: from a bias that holds
/// to 10⁻⁵ deg/s over an hour to one that moves by 1 deg/s in a second.
pub const WALK_GRID: (f64, f64) = (1e-14, 1.0);

/// The bias smoothed through the readings: at each, its mean and variance, and the
/// covariance with the next.
#[derive(Clone, Debug, PartialEq)]
pub struct BiasPath {
    times_s: Vec<f64>,
    means_dps: Vec<f64>,
    variances: Vec<f64>,
    /// Covariance of reading k's smoothed bias with reading k + 1's.
    next_covariances: Vec<f64>,
    walk: f64,
    jitter: f64,
    /// What the bias's variances are multiplied by ([`BiasPath::calibrated`]).
    variance_scale: f64,
}

/// The forward (filtered) pass at each reading: the prediction made before it and the
/// estimate after it.
struct Forward {
    predicted: Vec<(f64, f64)>,
    filtered: Vec<(f64, f64)>,
    log_likelihood: f64,
}

/// The Kalman filter over `readings` (in time order) for a walk of `walk` deg²/s³; the first
/// reading starts it (a diffuse prior), so the likelihood is of the others given it.
fn forward(readings: &[Reading], walk: f64, jitter: f64) -> Forward {
    let mut predicted = Vec::with_capacity(readings.len());
    let mut filtered = Vec::with_capacity(readings.len());
    let mut log_likelihood = 0.0;
    let mut state: Option<(f64, f64, f64)> = None;
    for r in readings {
        let (mean, variance) = match state {
            None => {
                predicted.push((r.bias_dps, f64::INFINITY));
                (r.bias_dps, r.variance + jitter)
            }
            Some((mean, variance, time_s)) => {
                let p = variance + walk * (r.time_s - time_s).max(0.0);
                predicted.push((mean, p));
                let s = p + r.variance + jitter;
                let innovation = r.bias_dps - mean;
                log_likelihood -= 0.5 * (s.ln() + innovation * innovation / s);
                let gain = p / s;
                (mean + gain * innovation, (1.0 - gain) * p)
            }
        };
        filtered.push((mean, variance));
        state = Some((mean, variance, r.time_s));
    }
    Forward {
        predicted,
        filtered,
        log_likelihood,
    }
}

/// The log-likelihood of `readings` under a walk of `walk` deg²/s³ and a jitter of
/// `jitter` deg²/s² (white from reading to reading, beside each reading's own variance).
pub fn log_likelihood(readings: &[Reading], walk: f64, jitter: f64) -> f64 {
    forward(readings, walk, jitter).log_likelihood
}

impl BiasPath {
    /// The path through `readings` (in time order, each variance positive) with the most
    /// likely walk rate and jitter ([`fit_walk`]). `None` without a reading.
    pub fn fit(readings: &[Reading]) -> Option<Self> {
        let (walk, jitter) = fit_walk(readings)?;
        Self::with_walk(readings, walk, jitter)
    }

    /// The path through `readings` for a walk of `walk` deg²/s³ and a jitter of `jitter`
    /// deg²/s². `None` without a reading.
    pub fn with_walk(readings: &[Reading], walk: f64, jitter: f64) -> Option<Self> {
        if readings.is_empty() {
            return None;
        }
        let f = forward(readings, walk, jitter);
        let n = readings.len();
        let mut means_dps = vec![0.0; n];
        let mut variances = vec![0.0; n];
        let mut next_covariances = vec![0.0; n];
        let (m, p) = f.filtered[n - 1];
        means_dps[n - 1] = m;
        variances[n - 1] = p;
        for k in (0..n - 1).rev() {
            let (m, p) = f.filtered[k];
            let (m_next, p_next) = f.predicted[k + 1];
            let gain = if p_next > 0.0 { p / p_next } else { 0.0 };
            means_dps[k] = m + gain * (means_dps[k + 1] - m_next);
            variances[k] = p + gain * gain * (variances[k + 1] - p_next);
            next_covariances[k] = gain * variances[k + 1];
        }
        Some(Self {
            times_s: readings.iter().map(|r| r.time_s).collect(),
            means_dps,
            variances,
            next_covariances,
            walk,
            jitter,
            variance_scale: 1.0,
        })
    }

    /// The path with its variances scaled so that they hold the changes the bias shows
    /// across the gaps between `readings` (the path's own) at `across` (each `i`: readings
    /// `i − 1` and `i`, a movement between them): the mean of the squared changes over
    /// their mean variance under the walk and the readings' noise, when above 1. A walk
    /// fitted over every lag can understate the wander at a movement's (a 1/f bias's
    /// is larger at short lags than a walk's); the rests on both sides of each movement
    /// say how much.
    pub fn calibrated(self, readings: &[Reading], across: &[usize]) -> Self {
        let (mut observed, mut predicted) = (0.0, 0.0);
        for &i in across {
            let (Some(a), Some(b)) = (
                i.checked_sub(1).and_then(|j| readings.get(j)),
                readings.get(i),
            ) else {
                continue;
            };
            let change = b.bias_dps - a.bias_dps;
            observed += change * change;
            predicted += self.walk * (b.time_s - a.time_s).abs()
                + a.variance
                + b.variance
                + 2.0 * self.jitter;
        }
        let scale = if predicted > 0.0 && observed.is_finite() {
            (observed / predicted).max(1.0)
        } else {
            1.0
        };
        Self {
            variance_scale: scale,
            ..self
        }
    }

    /// What the variances are multiplied by ([`BiasPath::calibrated`]; 1 otherwise).
    pub fn variance_scale(&self) -> f64 {
        self.variance_scale
    }

    /// The walk rate (deg²/s³) the path was smoothed with.
    pub fn walk(&self) -> f64 {
        self.walk
    }

    /// The jitter (deg²/s²) the path was smoothed with.
    pub fn jitter(&self) -> f64 {
        self.jitter
    }

    /// The readings on either side of `time_s`: (k, k + 1), or one reading twice before
    /// the first and after the last.
    fn around(&self, time_s: f64) -> (usize, usize) {
        let n = self.times_s.len();
        let k = self.times_s.partition_point(|t| *t <= time_s);
        match k {
            0 => (0, 0),
            k if k >= n => (n - 1, n - 1),
            k => (k - 1, k),
        }
    }

    /// The smoothed bias at `time_s` (deg/s) and its variance: linear between the two
    /// readings around it, the walk pinned at both (a Brownian bridge); held from the
    /// first and the last reading beyond them, the walk growing.
    pub fn at(&self, time_s: f64) -> (f64, f64) {
        let (a, b) = self.around(time_s);
        if a == b {
            let gap = (time_s - self.times_s[a]).abs();
            return (
                self.means_dps[a],
                self.variance_scale * (self.variances[a] + self.walk * gap),
            );
        }
        let (t0, t1) = (self.times_s[a], self.times_s[b]);
        let w = ((time_s - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let mean = (1.0 - w) * self.means_dps[a] + w * self.means_dps[b];
        let variance = (1.0 - w).powi(2) * self.variances[a]
            + w * w * self.variances[b]
            + 2.0 * w * (1.0 - w) * self.next_covariances[a]
            + self.walk * (time_s - t0) * (t1 - time_s) / (t1 - t0);
        (mean, self.variance_scale * variance)
    }

    /// The bias integrated from `from_s` to `to_s` (deg) and that integral's variance
    /// (deg²), when no reading lies strictly between them (a movement between rests);
    /// otherwise the integral over each stretch between readings, their variances added.
    pub fn integral(&self, from_s: f64, to_s: f64) -> (f64, f64) {
        if to_s <= from_s {
            return (0.0, 0.0);
        }
        // The readings strictly inside cut it into stretches (none for a movement between
        // two rests): walked in place, without a list.
        let first = self.times_s.partition_point(|t| *t <= from_s);
        let last = self.times_s.partition_point(|t| *t < to_s);
        let inside = self.times_s[first..last.max(first)].iter().copied();
        let mut start_s = from_s;
        let (mut angle, mut variance) = (0.0, 0.0);
        for end_s in inside.chain(std::iter::once(to_s)) {
            let (da, dv) = self.stretch(start_s, end_s);
            angle += da;
            variance += dv;
            start_s = end_s;
        }
        (angle, self.variance_scale * variance)
    }

    /// [`BiasPath::integral`] over a stretch with no reading inside.
    fn stretch(&self, s: f64, e: f64) -> (f64, f64) {
        let (a, b) = self.around(0.5 * (s + e));
        let duration = e - s;
        if a == b {
            // Beyond the readings: the bias held, its walk from the nearest reading.
            let t0 = self.times_s[a];
            let (d0, d1) = ((s - t0).abs(), (e - t0).abs());
            let (near, far) = (d0.min(d1), d0.max(d1));
            // ∫∫ walk·min(u, v) over [near, far]², u, v from the reading.
            let walk_part = self.walk * walk_integral(near, far);
            return (
                self.means_dps[a] * duration,
                duration * duration * self.variances[a] + walk_part.max(0.0),
            );
        }
        let (t0, t1) = (self.times_s[a], self.times_s[b]);
        let span = t1 - t0;
        // ∫ of the linear interpolant: weights of the two readings.
        let (u0, u1) = (s - t0, e - t0);
        let w_b = (u1 * u1 - u0 * u0) / (2.0 * span);
        let w_a = duration - w_b;
        let mean = w_a * self.means_dps[a] + w_b * self.means_dps[b];
        let variance = w_a * w_a * self.variances[a]
            + w_b * w_b * self.variances[b]
            + 2.0 * w_a * w_b * self.next_covariances[a]
            + self.walk * bridge_integral(span, u0, u1);
        (mean, variance)
    }
}

/// ∫∫ of a unit-rate random walk's covariance `min(u, v)` over `[near, far]²` (s³), u and v
/// from where the walk is pinned: the variance of the walk integrated over that stretch.
fn walk_integral(near: f64, far: f64) -> f64 {
    // 2 ∫_{near}^{far} ∫_{near}^{v} u du dv = ∫ (v² − near²) dv.
    ((far.powi(3) - near.powi(3)) / 3.0 - near * near * (far - near)).max(0.0)
}

/// ∫∫ of a unit-rate Brownian bridge's covariance `min(u,v)·(L − max(u,v))/L` over
/// `[u0, u1]²` (s³): the variance of the bridge integrated over that stretch of `[0, L]`.
fn bridge_integral(span: f64, u0: f64, u1: f64) -> f64 {
    // 2 ∫_{u0}^{u1} (L − v)/L ∫_{u0}^{v} u du dv = (1/L) ∫ (L − v)(v² − u0²) dv.
    let antiderivative = |v: f64| {
        span * v.powi(3) / 3.0 - span * u0 * u0 * v - v.powi(4) / 4.0 + u0 * u0 * v * v / 2.0
    };
    ((antiderivative(u1) - antiderivative(u0)) / span).max(0.0)
}

/// Golden-section search for the maximum of `f` on `[a, b]` ([`crate::golden`]).
fn golden_max(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    crate::golden::minimize(f, |y| -y, a, b, 30).middle()
}

/// The jitters (deg²/s²) the fit compares beside none, a factor of √10 apart.
pub const JITTER_GRID: (f64, f64) = (1e-10, 1e-2);

/// The most likely walk rate (deg²/s³) and jitter (deg²/s²) for `readings`: the best of a
/// grid a factor √10 apart over [`WALK_GRID`] and, beside none, [`JITTER_GRID`], refined
/// by golden-section search on their logarithms between the neighbours. `None` without a
/// reading.
pub fn fit_walk(readings: &[Reading]) -> Option<(f64, f64)> {
    if readings.is_empty() {
        return None;
    }
    let axis = |(lo, hi): (f64, f64)| -> Vec<f64> {
        let (lo, hi) = (lo.log10(), hi.log10());
        let steps = ((hi - lo) * 2.0).round() as usize;
        (0..=steps)
            .map(|i| lo + (hi - lo) * i as f64 / steps as f64)
            .collect()
    };
    let walks = axis(WALK_GRID);
    let mut jitters = vec![f64::NEG_INFINITY];
    jitters.extend(axis(JITTER_GRID));
    let at = |w: f64, j: f64| log_likelihood(readings, 10f64.powf(w), 10f64.powf(j));
    let (mut walk, mut jitter, _) = walks
        .iter()
        .flat_map(|&w| jitters.iter().map(move |&j| (w, j)))
        .map(|(w, j)| (w, j, at(w, j)))
        .filter(|(_, _, l)| l.is_finite())
        .max_by(|a, b| a.2.total_cmp(&b.2))?;
    let half = 0.5;
    for _ in 0..2 {
        walk = golden_max(
            |w| at(w, jitter),
            (walk - half).max(walks[0]),
            (walk + half).min(walks[walks.len() - 1]),
        );
        if jitter.is_finite() {
            jitter = golden_max(
                |j| at(walk, j),
                (jitter - half).max(jitters[1] - half),
                (jitter + half).min(jitters[jitters.len() - 1]),
            );
        }
    }
    Some((10f64.powf(walk), 10f64.powf(jitter)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn readings_of(bias: impl Fn(f64) -> f64, noise: f64, n: usize, seed: u64) -> Vec<Reading> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|i| {
                let time_s = i as f64;
                let x: f64 = StandardNormal.sample(&mut rng);
                Reading {
                    time_s,
                    bias_dps: bias(time_s) + noise * x,
                    variance: noise * noise,
                }
            })
            .collect()
    }

    /// Without a walk, the path is the readings' weighted mean everywhere.
    #[test]
    fn a_still_bias_is_the_weighted_mean_of_every_reading() {
        let readings = readings_of(|_| 0.3, 0.01, 50, 1);
        let path = BiasPath::with_walk(&readings, 0.0, 0.0).expect("readings");
        let mean = readings.iter().map(|r| r.bias_dps).sum::<f64>() / 50.0;
        for t in [0.0, 10.5, 49.0] {
            let (m, v) = path.at(t);
            assert!((m - mean).abs() < 1e-12, "{m} against {mean}");
            assert!((v - 1e-4 / 50.0).abs() < 1e-12, "{v}");
        }
    }

    /// A walk far larger than the noise: each reading stands for itself.
    #[test]
    fn a_fast_walk_follows_each_reading() {
        let readings = readings_of(|t| (t * 0.3).sin(), 1e-4, 30, 2);
        let path = BiasPath::with_walk(&readings, 1.0, 0.0).expect("readings");
        for r in &readings {
            let (m, _) = path.at(r.time_s);
            assert!((m - r.bias_dps).abs() < 1e-6);
        }
    }

    /// The fitted walk recovers the walk that made the readings, within a factor of two,
    /// over five decades.
    #[test]
    fn the_fitted_walk_is_the_one_that_made_the_readings() {
        for (i, walk) in [1e-7, 1e-5, 1e-3, 1e-2].into_iter().enumerate() {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(10 + i as u64);
            let mut b = 0.0;
            let noise = 0.003;
            let readings: Vec<Reading> = (0..2000)
                .map(|k| {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    let y: f64 = StandardNormal.sample(&mut rng);
                    b += (walk * 0.5f64).sqrt() * x;
                    Reading {
                        time_s: 0.5 * k as f64,
                        bias_dps: b + noise * y,
                        variance: noise * noise,
                    }
                })
                .collect();
            let (fitted, _) = fit_walk(&readings).expect("readings");
            assert!(
                (fitted / walk).ln().abs() < 2f64.ln(),
                "{fitted} for {walk}"
            );
        }
    }

    /// The bridge's integrated variance over its whole span is `L³/12`, and the integral
    /// over a stretch matches a direct quadrature of the covariance; so does the free
    /// walk's beyond a reading.
    #[test]
    fn the_bridge_integral_matches_quadrature() {
        assert!((bridge_integral(2.0, 0.0, 2.0) - 8.0 / 12.0).abs() < 1e-12);
        let (span, u0, u1) = (5.0, 1.0, 3.5);
        let n = 400;
        let h = (u1 - u0) / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (u, v) = (u0 + (i as f64 + 0.5) * h, u0 + (j as f64 + 0.5) * h);
                sum += u.min(v) * (span - u.max(v)) / span * h * h;
            }
        }
        assert!((bridge_integral(span, u0, u1) / sum - 1.0).abs() < 1e-3);
        // The walk beyond the last reading, the same way.
        let (near, far) = (1.0, 3.0);
        let h = (far - near) / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (u, v) = (near + (i as f64 + 0.5) * h, near + (j as f64 + 0.5) * h);
                sum += u.min(v) * h * h;
            }
        }
        assert!((walk_integral(near, far) / sum - 1.0).abs() < 1e-3);
        assert!((walk_integral(0.0, 2.0) - 8.0 / 3.0).abs() < 1e-12);
    }

    /// The integral's variance is calibrated: over simulated walks read with noise, the
    /// error of the integrated bias over a gap between readings has the stated variance.
    #[test]
    fn the_integral_variance_is_what_the_errors_show() {
        let (walk, noise): (f64, f64) = (1e-4, 0.003);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut z2 = Vec::new();
        for _ in 0..400 {
            // Readings every 0.2 s over rests of 2 s, a movement of 2 s between.
            let dt: f64 = 0.01;
            let mut b = 0.1;
            let mut path = Vec::new();
            for k in 0..800 {
                let x: f64 = StandardNormal.sample(&mut rng);
                b += (walk * dt).sqrt() * x;
                path.push((k as f64 * dt, b));
            }
            let readings: Vec<Reading> = path
                .chunks(20)
                .enumerate()
                .filter(|(i, _)| !(10..20).contains(i) && !(30..40).contains(i))
                .map(|(_, c)| {
                    let y: f64 = StandardNormal.sample(&mut rng);
                    Reading {
                        time_s: c.iter().map(|p| p.0).sum::<f64>() / c.len() as f64,
                        bias_dps: c.iter().map(|p| p.1).sum::<f64>() / c.len() as f64 + noise * y,
                        variance: noise * noise,
                    }
                })
                .collect();
            let smoothed = BiasPath::with_walk(&readings, walk, 0.0).expect("readings");
            let truth: f64 = path[200..400].iter().map(|p| p.1 * dt).sum();
            let (estimate, variance) = smoothed.integral(path[200].0, path[400].0);
            z2.push((estimate - truth).powi(2) / variance);
        }
        let mean = z2.iter().sum::<f64>() / z2.len() as f64;
        assert!((mean - 1.0).abs() < 0.2, "mean z² {mean}");
    }

    /// Where the bias jumps across the movements more than a walk fitted over every lag
    /// says, the calibration widens the variances by the jumps' share; where the walk is
    /// the truth, it leaves them within a third of one.
    #[test]
    fn the_calibration_widens_only_for_jumps_the_walk_understates() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        let noise: f64 = 0.003;
        // Rests of 10 blocks, 0.2 s apart; movements of 2 s between them.
        let mut make = |jump: f64, walk: f64| -> f64 {
            let (mut b, mut readings, mut across) = (0.0f64, Vec::new(), Vec::new());
            let mut t = 0.0f64;
            for rest in 0..40 {
                if rest > 0 {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    let w: f64 = StandardNormal.sample(&mut rng);
                    b += jump * x + (walk * 2.0f64).sqrt() * w;
                    t += 2.0;
                    across.push(readings.len());
                }
                for _ in 0..10 {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    let y: f64 = StandardNormal.sample(&mut rng);
                    b += (walk * 0.2f64).sqrt() * x;
                    readings.push(Reading {
                        time_s: t,
                        bias_dps: b + noise * y,
                        variance: noise * noise,
                    });
                    t += 0.2;
                }
            }
            let path = BiasPath::fit(&readings).expect("readings");
            path.calibrated(&readings, &across).variance_scale()
        };
        let walk_only = make(0.0, 1e-4);
        assert!((1.0..1.34).contains(&walk_only), "{walk_only}");
        let jumps = make(0.02, 1e-6);
        assert!(jumps > 2.0, "{jumps}");
    }
}
