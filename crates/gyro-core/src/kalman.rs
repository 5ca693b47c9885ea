//! Kalman form of the error model: angle and Gauss-Markov bias, zero-rate updates at rest.
//!
//! State `x = [θ, b]`: angle (deg) and gyro bias (deg/s). The bias is the one the sensor
//! came up with (unknown, standard deviation `initial_bias_sigma_dps` about
//! `bias_mean_dps`) plus a first-order Gauss-Markov wander with correlation time `1/β` and
//! stationary standard deviation `bias_sigma_dps`. Between rests the estimate holds (the
//! wander has no known direction, and the turn-on bias does not revert to the mean of other
//! power-ups) while its variance grows as the wander's would. While moving, the angle
//! integrates `rate − b̂`, so its error grows with the bias error (the covariance couples
//! them). At rest the measured rate is an observation of the bias (the true rate is zero);
//! the update corrects the bias and, through the coupling, the angle accumulated during the
//! last movement.

use crate::error::{check_range, Error};
use nalgebra::{Matrix2, RowVector2, Vector2};

/// Settings of the Kalman form.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct KalmanConfig {
    /// Inverse correlation time β of the bias (1/s), ≥ 0.
    pub beta_per_s: f32,
    /// Stationary standard deviation of the bias's wander within a run (deg/s): with
    /// `beta_per_s` it sets how fast the filter forgets older rests. Not the spread of the
    /// bias between power-ups, which is `initial_bias_sigma_dps`.
    pub bias_sigma_dps: f32,
    /// The bias expected at power-up (deg/s): the estimate before the first rest.
    pub bias_mean_dps: f32,
    /// White rate noise, standard deviation per output sample (deg/s).
    pub rate_noise_dps: f32,
    /// Standard deviation of the initial bias estimate (deg/s): the spread of the bias
    /// between power-ups.
    pub initial_bias_sigma_dps: f32,
}

impl Default for KalmanConfig {
    /// A CRM100-class gyro: a bias anywhere within about ±1 deg/s at power-up
    /// (`initial_bias_sigma_dps` 1), which then wanders by σ 0.05 deg/s over τ 300 s (a
    /// random walk of about 0.004 deg/s/√s over a run's minutes).
    ///
    /// The wander sets how much the filter trusts the rest it is in over the older ones. A
    /// prior as wide as the turn-on spread (σ 0.5 deg/s) makes the last second of each rest
    /// outweigh the rest of it, and the filter loses to a plain mean of the rest before each
    /// movement on sensors whose bias holds still (1.3–1.45× its error on simulated CRM100
    /// bench runs); the wander scale the rests adapt ([`KalmanBias`]) grows quickly where
    /// the bias does drift. Measured with
    /// `cargo run --release -p gyro-analysis --example bench_kinds` (docs/figures.md).
    fn default() -> Self {
        Self {
            beta_per_s: 1.0 / 300.0,
            bias_sigma_dps: 0.05,
            bias_mean_dps: 0.0,
            rate_noise_dps: 0.05,
            initial_bias_sigma_dps: 1.0,
        }
    }
}

impl KalmanConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), Error> {
        check_range("kalman.beta_per_s", self.beta_per_s.into(), 0.0, 1e6)?;
        check_range(
            "kalman.bias_sigma_dps",
            self.bias_sigma_dps.into(),
            0.0,
            1e4,
        )?;
        check_range("kalman.bias_mean_dps", self.bias_mean_dps.into(), -1e4, 1e4)?;
        check_range(
            "kalman.rate_noise_dps",
            self.rate_noise_dps.into(),
            1e-9,
            1e4,
        )?;
        check_range(
            "kalman.initial_bias_sigma_dps",
            self.initial_bias_sigma_dps.into(),
            0.0,
            1e4,
        )?;
        Ok(())
    }
}

/// The bias wander during a movement that its σ counts, as a multiple of the filter's own
/// (`q_b`, scaled by the rests): the filter's gain is set for the wander the rests show,
/// which misses the fast components a bias instability adds and what a few rests tell of a
/// random walk early in a run, and a guard band must hold for those too. Measured on
/// simulated CRM100 bench runs (`rest_mean_bench 100 101` and `100 2001`, 4 494 and 4 506
/// movements): with 1, four and three movements got a wrong `ok` (2.6–3.7 σ off); with 3,
/// none and three; with 10, none in either, 48–50% `recheck`.
const GUARD_WANDER: f32 = 10.0;
/// Weight of a new pair of rest-block means in the block-mean variance estimate.
const BLOCK_VARIANCE_WEIGHT: f32 = 1.0 / 16.0;
/// Share of the movement bias-error variance kept at each movement (the largest one seen
/// fades over some tens of movements).
const MOVEMENT_VARIANCE_RETAIN: f32 = 0.95;
/// Step γ of the bias-wander scale per rest update: α ← α·exp(γ·(NIS − 1)).
const WANDER_SCALE_STEP: f32 = 0.05;
/// A normalised innovation above this counts as this (one disturbed block moves α little).
const NIS_CAP: f32 = 10.0;
/// The bias-wander scale stays within these bounds.
const WANDER_SCALE_RANGE: (f32, f32) = (1e-4, 1e2);

/// The filter's state for a fixed step `dt_s`.
///
/// The configured noise levels are a prior; the rests correct them. The variance of a rest
/// block's mean is measured from consecutive block means (half the mean square of their
/// difference, which holds for correlated, low-passed noise too) and replaces `R/n` once
/// known; the bias wander `q` is scaled by α, which follows the normalised innovations of
/// the rest updates (α grows when the rests disagree with the prediction more than its
/// variance says, shrinks when they agree better), so that `angle_std_deg` is calibrated
/// by the log's own rests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanBias {
    dt_s: f32,
    /// β·dt: the bias's mean reversion per step (before the wander scale).
    beta_dt: f32,
    /// Stationary variance of the bias about its mean (deg/s)².
    sigma_b2: f32,
    r_rate: f32,
    bias_dps: f32,
    p: Matrix2<f32>,
    /// Variance of a rest block's mean (deg/s)², NaN until a pair of blocks was seen.
    block_variance: f32,
    /// Variance of the bias error a movement leaves (deg/s)², from the first rest block
    /// after each movement; NaN until one was seen.
    movement_bias_variance: f32,
    /// α: the scale of the bias's wander rate (β·α, so `q` scales by about α while the
    /// bias keeps its stationary spread).
    wander_scale: f32,
    /// φ = e^(−β·α·dt), the bias's transition per step: set with α, which changes only at
    /// rest updates, so that a step computes no exponential.
    phi: f32,
}

impl KalmanBias {
    /// Filter for samples `dt_s` apart.
    pub fn try_new(config: &KalmanConfig, dt_s: f32) -> Result<Self, Error> {
        config.validate()?;
        let sigma_b2 = config.bias_sigma_dps * config.bias_sigma_dps;
        let noise2 = config.rate_noise_dps * config.rate_noise_dps;
        let p0 = config.initial_bias_sigma_dps * config.initial_bias_sigma_dps;
        Ok(Self {
            dt_s,
            beta_dt: config.beta_per_s * dt_s,
            sigma_b2,
            r_rate: noise2,
            bias_dps: config.bias_mean_dps,
            p: Matrix2::new(0.0, 0.0, 0.0, p0),
            block_variance: f32::NAN,
            movement_bias_variance: f32::NAN,
            wander_scale: 1.0,
            phi: transition_of(config.beta_per_s * dt_s, 1.0),
        })
    }

    /// The step `dt_s` the filter was built for (s).
    pub const fn dt_s(&self) -> f32 {
        self.dt_s
    }

    /// Current bias estimate (deg/s).
    pub const fn bias_dps(&self) -> f32 {
        self.bias_dps
    }

    /// Standard deviation of the angle (deg).
    pub fn angle_std_deg(&self) -> f32 {
        libm::sqrtf(self.p[(0, 0)].max(0.0))
    }

    /// Standard deviation (deg) of the angle gained over a movement of `samples` steps that
    /// has just ended (before the rest after it updates the bias): the bias error at its
    /// start times the duration, the white rate noise integrated over it, and the bias's
    /// own wander during it, `(n·dt)²·V_b + n·q_θ + g·q_b·dt²·n³/3` (`g`: [`GUARD_WANDER`]).
    ///
    /// `V_b` is the largest of the filter's bias variance at the movement's start (the one
    /// at its end less the `n·q_b` the movement added: that wander is the `n³` term, which
    /// the variance at the end would count again, twice over), the largest bias error
    /// movements have left lately ([`Self::observe_after_movement`]), and the variance of a
    /// rest block's mean (the bias moves from block to block by as much as the rests show,
    /// some of which the updates take for noise). Until a rest has followed a movement,
    /// nothing has shown how far the bias moves over one: `V_b` is then at least the
    /// prior's whole wander spread `bias_sigma_dps²`. The filter's own gain assumes a bias
    /// that holds still; a guard band must not (on simulated CRM100 bench runs with a bias
    /// instability of 0.05 deg/s, without these two the first movements of some runs were
    /// 3–4 σ off, and the 95% intervals covered 89% of the movements).
    pub fn movement_std_deg(&self, samples: u32) -> f32 {
        let n = samples as f32;
        let duration_s = n * self.dt_s;
        let q_bias = self.transition().1;
        let start_variance = (self.p[(1, 1)] - n * q_bias).max(0.0);
        let mut bias_variance = if self.movement_bias_variance > start_variance {
            self.movement_bias_variance
        } else {
            start_variance
        };
        if self.block_variance > bias_variance {
            bias_variance = self.block_variance;
        }
        if self.movement_bias_variance.is_nan() && self.sigma_b2 > bias_variance {
            bias_variance = self.sigma_b2;
        }
        let variance = duration_s * duration_s * bias_variance
            + n * self.q_angle()
            + GUARD_WANDER * q_bias * self.dt_s * self.dt_s * n * n * n / 3.0;
        libm::sqrtf(variance)
    }

    /// Standard deviation of the bias estimate (deg/s).
    pub fn bias_std_dps(&self) -> f32 {
        libm::sqrtf(self.p[(1, 1)].max(0.0))
    }

    /// Process noise of the angle per moving step: the rate noise integrated over `dt`.
    fn q_angle(&self) -> f32 {
        self.r_rate * self.dt_s * self.dt_s
    }

    /// The bias's transition φ = e^(−β·α·dt) and its process noise σ_b²·(1 − φ²) per step.
    /// Discrete GM: var(b) stays σ_b² with that q. At β = 0 the bias is a constant and
    /// only its initial uncertainty remains.
    fn transition(&self) -> (f32, f32) {
        let phi = self.phi;
        (phi, self.sigma_b2 * (1.0 - phi * phi))
    }

    /// Propagate one step; `moving` if the angle integrates this step.
    ///
    /// The bias estimate holds: the wander is as likely either way, and pulling the
    /// estimate towards the configured mean (as a Gauss-Markov bias about a known mean
    /// would) pulls it away from this power-up's own bias, the more so as the rests raise
    /// the wander scale: on simulated CRM100 bench runs with the default prior, doing so
    /// gives 1.28 times the per-rest mean's error with a turn-on bias of σ 0.3 deg/s
    /// (1.05 holding it) and 1.77 times with a bias instability of 0.05 deg/s (0.75).
    #[inline]
    pub fn predict(&mut self, moving: bool) {
        let (phi, q_bias) = self.transition();
        self.p = if moving {
            propagate(&self.p, -self.dt_s, phi, self.q_angle(), q_bias)
        } else {
            propagate_static(&self.p, phi, q_bias)
        };
    }

    /// Add the angle uncertainty of `samples` steps that were integrated while the motion
    /// was unconfirmed (propagated as static until then). Covariance only: the bias
    /// estimate already evolved the same way in both cases.
    pub fn add_motion(&mut self, samples: u32) {
        if samples == 0 {
            return;
        }
        let n = samples as f32;
        let g = Matrix2::new(1.0, -self.dt_s * n, 0.0, 1.0);
        self.p = g * self.p * g.transpose() + Matrix2::new(self.q_angle() * n, 0.0, 0.0, 0.0);
    }

    /// The first rest block after a movement (before its update): how far the bias the
    /// movement was integrated with is from the one the rest shows. The mean square of
    /// that innovation, less the block noise, is the bias error movements actually leave,
    /// which a model fitted within rests can miss (a bias that shifts with motion); the
    /// movement's standard deviation uses it when it exceeds the filter's own.
    pub fn observe_after_movement(&mut self, mean_rate_dps: f32) {
        let innovation = mean_rate_dps - self.bias_dps;
        let noise = if self.block_variance > 0.0 {
            self.block_variance
        } else {
            0.0
        };
        let variance = (innovation * innovation - noise).max(0.0);
        if !variance.is_finite() {
            return;
        }
        // The largest seen, forgetting slowly: a guard band must hold for the movements
        // the rests explain worst, not for the average one. A running mean instead
        // (measured on simulated CRM100 bench runs, `rest_mean_bench 50`) brings the 95%
        // intervals' coverage from 98.4–100% to 96–99%, and a movement 3.4 σ off then
        // gets a wrong `ok` among 2286.
        self.movement_bias_variance = if self.movement_bias_variance.is_nan() {
            variance
        } else {
            variance.max(self.movement_bias_variance * MOVEMENT_VARIANCE_RETAIN)
        };
    }

    /// Two consecutive rest blocks' means: their difference measures the variance of a
    /// block mean (the rest noise as the updates see it).
    pub fn observe_block_pair(&mut self, first_mean_dps: f32, second_mean_dps: f32) {
        let difference = second_mean_dps - first_mean_dps;
        let variance = 0.5 * difference * difference;
        if !variance.is_finite() {
            return;
        }
        self.block_variance = if self.block_variance.is_nan() {
            variance
        } else {
            self.block_variance + BLOCK_VARIANCE_WEIGHT * (variance - self.block_variance)
        };
    }

    /// Zero-rate update with the mean of `samples` rates measured at rest (its noise
    /// variance is the measured block variance, else R/samples). Returns the angle
    /// correction (deg).
    pub fn update_at_rest(&mut self, mean_rate_dps: f32, samples: u32) -> f32 {
        let rate_dps = mean_rate_dps;
        let r = if self.block_variance > 0.0 {
            self.block_variance
        } else {
            self.r_rate / samples.max(1) as f32
        };
        let s = self.p[(1, 1)] + r;
        if s.is_nan() || s <= 0.0 {
            return 0.0;
        }
        let h = RowVector2::new(0.0, 1.0);
        let gain: Vector2<f32> = self.p * h.transpose() / s;
        let innovation = rate_dps - self.bias_dps;
        let nis = innovation * innovation / s;
        if nis.is_finite() {
            let scaled =
                self.wander_scale * libm::expf(WANDER_SCALE_STEP * (nis.min(NIS_CAP) - 1.0));
            self.wander_scale = scaled.clamp(WANDER_SCALE_RANGE.0, WANDER_SCALE_RANGE.1);
            self.phi = transition_of(self.beta_dt, self.wander_scale);
        }
        self.bias_dps += gain[1] * innovation;
        // Joseph form keeps P symmetric and positive in f32.
        let i_kh = Matrix2::identity() - gain * h;
        self.p = i_kh * self.p * i_kh.transpose() + gain * gain.transpose() * r;
        gain[0] * innovation
    }

    /// True if the state is finite.
    pub fn is_finite(&self) -> bool {
        self.bias_dps.is_finite()
            && self.p.iter().all(|v| v.is_finite())
            && self.wander_scale.is_finite()
    }

    /// α: the scale the rests have set on the configured bias wander.
    pub const fn wander_scale(&self) -> f32 {
        self.wander_scale
    }
}

/// `F·P·Fᵀ + Q` for `F = [1 coupling; 0 φ]` and `Q = diag(q_angle, q_bias)`, element by
/// element in the operations nalgebra's `f * p * f.transpose() + q` performs, so the same
/// bits (each element of a product is `a(i,1)·b(1,j) + a(i,0)·b(0,j)`, products by the
/// constants 0 and 1 included, which keep a zero's sign and a non-finite element as they
/// do there), without the shuffles of its 2×2 products.
#[inline(always)]
fn propagate(p: &Matrix2<f32>, coupling: f32, phi: f32, q_angle: f32, q_bias: f32) -> Matrix2<f32> {
    let (p00, p01, p10, p11) = (p[(0, 0)], p[(0, 1)], p[(1, 0)], p[(1, 1)]);
    // A = F·P; F's 1 leaves its factor as it is (1·x = x exactly).
    let a00 = coupling * p10 + p00;
    let a01 = coupling * p11 + p01;
    let a10 = phi * p10 + 0.0 * p00;
    let a11 = phi * p11 + 0.0 * p01;
    // A·Fᵀ, Fᵀ = [1 0; coupling φ].
    let b00 = a01 * coupling + a00;
    let b01 = a01 * phi + a00 * 0.0;
    let b10 = a11 * coupling + a10;
    let b11 = a11 * phi + a10 * 0.0;
    Matrix2::new(b00 + q_angle, b01 + 0.0, b10 + 0.0, b11 + q_bias)
}

/// [`propagate`] at rest (no coupling, no angle noise), with a shorter chain of
/// operations from one step's P to the next's where that gives the same bits: for finite
/// elements the products by 0 are zeros, and adding a zero leaves a number that is not
/// zero as it is, so that `P00` stays, `P01` and `P10` are scaled by φ, and `P11` becomes
/// `φ·P11·φ + q_bias`. Where a zero or a non-finite value could make the difference, the
/// whole computation.
#[inline(always)]
fn propagate_static(p: &Matrix2<f32>, phi: f32, q_bias: f32) -> Matrix2<f32> {
    let (p00, p01, p10, p11) = (p[(0, 0)], p[(0, 1)], p[(1, 0)], p[(1, 1)]);
    let (f01, f10, f11) = (p01 * phi, phi * p10, phi * p11);
    let g11 = f11 * phi;
    if short_form_holds(p00, p01, f01, f10, f11, g11) {
        Matrix2::new(p00, f01, f10, g11 + q_bias)
    } else {
        propagate(p, 0.0, phi, 0.0, q_bias)
    }
}

/// Whether [`propagate_static`]'s short form gives the whole computation's bits: all of
/// P's elements and the products `f01 = P01·φ`, `f10 = φ·P10`, `f11 = φ·P11`,
/// `g11 = f11·φ` finite, and `P00`, `P01` and the four products not zero.
///
/// Six tests stand for those fourteen: `f10` and `f11` finite and not zero imply `P10` and
/// `P11` finite (a product with an infinite or NaN factor is infinite or NaN, or NaN when
/// the other factor is zero). Each test is one integer comparison on the magnitude's bits
/// (zero wraps to the top, infinity and NaN lie above `f32::MAX`), without early exit: it
/// is off the chain from one P to the next, and needs no f64 (software on a single
/// precision FPU).
#[inline(always)]
fn short_form_holds(p00: f32, p01: f32, f01: f32, f10: f32, f11: f32, g11: f32) -> bool {
    [p00, p01, f01, f10, f11, g11]
        .iter()
        .fold(true, |all, &v| all & finite_nonzero(v))
}

/// `v` is finite and not zero: the bits of |v|, less one, are below those of `f32::MAX`.
#[inline(always)]
fn finite_nonzero(v: f32) -> bool {
    (v.to_bits() & 0x7fff_ffff).wrapping_sub(1) < f32::MAX.to_bits()
}

/// φ = e^(−β·dt·α) for `beta_dt` = β·dt and `wander_scale` = α.
fn transition_of(beta_dt: f32, wander_scale: f32) -> f32 {
    libm::expf(-beta_dt * wander_scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic noise of standard deviation about `sigma` (uniform, a fixed sequence).
    fn noise(k: u32, sigma: f32) -> f32 {
        let x = k.wrapping_mul(2_654_435_761) >> 8;
        sigma * 1.732 * ((x % 2001) as f32 / 1000.0 - 1.0)
    }

    /// `propagate` gives nalgebra's `F·P·Fᵀ + Q` bit for bit, signed zeros and
    /// non-finite elements included.
    #[test]
    fn propagate_is_nalgebras_product() {
        let special = [
            0.0_f32,
            -0.0,
            1.0,
            -1.0,
            1e-30,
            -3.5e-8,
            f32::MIN_POSITIVE,
            7.25e3,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let mut state = 0x2545_f491_u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            if state % 4 == 0 {
                special[(state / 4) as usize % special.len()]
            } else {
                f32::from_bits(state % 0x7f00_0000) * if state % 3 == 0 { -1.0 } else { 1.0 }
            }
        };
        for _ in 0..200_000 {
            let p = Matrix2::new(next(), next(), next(), next());
            let (coupling, phi, q_angle, q_bias) = (next(), next(), next(), next());
            // φ as the filter has it, in [0, 1], and any.
            let phi_in_range = libm::fabsf(phi) / (1.0 + libm::fabsf(phi));
            for phi in [phi, phi_in_range] {
                for (coupling, q_angle) in [(coupling, q_angle), (0.0, 0.0)] {
                    let f = Matrix2::new(1.0, coupling, 0.0, phi);
                    let want = f * p * f.transpose() + Matrix2::new(q_angle, 0.0, 0.0, q_bias);
                    let mut got = [propagate(&p, coupling, phi, q_angle, q_bias)].to_vec();
                    if coupling.to_bits() == 0 && q_angle.to_bits() == 0 {
                        got.push(propagate_static(&p, phi, q_bias));
                    }
                    for got in got {
                        for (w, g) in want.iter().zip(got.iter()) {
                            assert!(
                                w.to_bits() == g.to_bits() || w.is_nan() && g.is_nan(),
                                "{p:?} {coupling} {phi} {q_angle} {q_bias}: {want:?} vs {got:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// [`short_form_holds`] is the fourteen tests it stands for, on special values and
    /// their neighbours, for any φ.
    #[test]
    fn short_form_test_is_the_full_test() {
        let special = [
            0.0_f32,
            -0.0,
            1.0,
            -0.75,
            f32::from_bits(1),
            -f32::from_bits(0x007f_ffff),
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
        ];
        for &phi in &special {
            for &p00 in &special {
                for &p01 in &special {
                    for &p10 in &special {
                        for &p11 in &special {
                            let (f01, f10, f11) = (p01 * phi, phi * p10, phi * p11);
                            let g11 = f11 * phi;
                            let values = [p00, p01, p10, p11, f01, f10, f11, g11];
                            let finite = values.iter().all(|v| v.is_finite());
                            let nonzero = [p00, p01, f01, f10, f11, g11].iter().all(|&v| v != 0.0);
                            assert_eq!(
                                short_form_holds(p00, p01, f01, f10, f11, g11),
                                finite && nonzero,
                                "{p00} {p01} {p10} {p11} {phi}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// A prior whose bias wanders as widely as a turn-on spread (σ 0.5 deg/s, β 1/300 s:
    /// about 0.04 deg/s/√s), far more than the defaults' wander.
    fn wide_prior() -> KalmanConfig {
        KalmanConfig {
            bias_sigma_dps: 0.5,
            ..KalmanConfig::default()
        }
    }

    #[test]
    fn rest_updates_converge_to_the_bias() {
        let mut kf = KalmanBias::try_new(&wide_prior(), 0.02).unwrap();
        for k in 0..500 {
            kf.predict(false);
            kf.update_at_rest(0.7 + noise(k, 0.05), 1);
        }
        // Updated sample by sample (gain about 0.1), the estimate follows the noise by
        // about 0.011 deg/s.
        assert!((kf.bias_dps() - 0.7).abs() < 0.04, "{}", kf.bias_dps());
        // A constant bias wanders less than the wide prior says: the wander scale shrinks.
        assert!(kf.wander_scale() < 0.9, "{}", kf.wander_scale());
    }

    /// The rests set the noise the filter assumes: a bias wandering much faster than the
    /// prior ([`wide_prior`]; here 0.2 deg/s per √(10 dt) per update) raises the wander
    /// scale, and a block variance measured from consecutive blocks replaces R/n.
    #[test]
    fn the_rests_calibrate_the_noise_model() {
        let dt = 0.02;
        let mut kf = KalmanBias::try_new(&wide_prior(), dt).unwrap();
        let mut bias = 0.0_f32;
        let (mut previous, block) = (f32::NAN, 10);
        for k in 0..2000_u32 {
            // A random walk of 0.2 deg/s/√s, seen through blocks of 10 samples.
            bias += noise(k + 7, 0.2 * (block as f32 * dt).sqrt());
            let mean = bias + noise(k, 0.02);
            kf.predict(false);
            if previous.is_finite() {
                kf.observe_block_pair(previous, mean);
            }
            kf.update_at_rest(mean, block);
            previous = mean;
        }
        assert!(kf.wander_scale() > 4.0, "{}", kf.wander_scale());
        assert!(
            (kf.bias_dps() - bias).abs() < 0.15,
            "{} vs {bias}",
            kf.bias_dps()
        );
    }

    /// A movement's σ is the angle variance the filter's own propagation gives a movement
    /// that starts with no angle error, but for the guard band's larger wander: the bias
    /// error at the start, the white noise and the wander, each counted once (with the
    /// bias variance at the movement's end in place of the one at its start, the wander
    /// the movement added is counted again and σ² comes out about three times too large
    /// here).
    #[test]
    fn a_movement_std_counts_the_bias_wander_once() {
        let dt = 0.02;
        let mut kf = KalmanBias::try_new(&wide_prior(), dt).unwrap();
        let start_variance = 1e-4;
        kf.p = Matrix2::new(0.0, 0.0, 0.0, start_variance);
        // A rest has followed a movement, and shown no bias error (else the prior's whole
        // spread stands in for it).
        kf.observe_after_movement(kf.bias_dps());
        let samples = 250; // 5 s
        for _ in 0..samples {
            kf.predict(true);
        }
        let n = samples as f32;
        let guard = (GUARD_WANDER - 1.0) * kf.transition().1 * dt * dt * n * n * n / 3.0;
        let propagated = kf.p[(0, 0)] + guard;
        let std = kf.movement_std_deg(samples);
        let ratio = std * std / propagated;
        assert!((ratio - 1.0).abs() < 0.05, "{} vs {propagated}", std * std);
        // The bias variance at the end is mostly the wander added on the way.
        assert!(kf.p[(1, 1)] > 50.0 * start_variance, "{}", kf.p[(1, 1)]);
    }

    #[test]
    fn angle_uncertainty_grows_while_moving_and_rest_corrects_it() {
        let mut kf = KalmanBias::try_new(&KalmanConfig::default(), 0.02).unwrap();
        for _ in 0..250 {
            kf.predict(true);
        }
        let std_after_motion = kf.angle_std_deg();
        assert!(std_after_motion > 1.0, "{std_after_motion}");
        // The true bias was 0.4 deg/s while the filter assumed 0, so the angle it integrated
        // over 5 s is 2 deg too high; the rest observations reveal it.
        let mut correction = 0.0;
        for _ in 0..200 {
            kf.predict(false);
            correction += kf.update_at_rest(0.4, 1);
        }
        assert!(kf.angle_std_deg() < std_after_motion);
        assert!(correction < -1.5 && correction > -2.5, "{correction}");
    }
}
