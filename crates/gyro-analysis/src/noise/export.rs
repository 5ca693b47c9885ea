//! Gyro noise as the IMU noise YAML of Kalibr, OpenVINS and VINS-Fusion: the two
//! continuous-time numbers such a filter takes for a gyroscope, with their units and their
//! provenance written out in comments.
//!
//! | key | unit | what | from |
//! |---|---|---|---|
//! | `gyroscope_noise_density` (VINS: `gyr_n`) | rad/s/√Hz | white rate noise, the angle random walk N | N[rad/s/√Hz] = N[deg/√h] · π/180 / 60 |
//! | `gyroscope_random_walk` (VINS: `gyr_w`) | rad/s²/√Hz | bias random walk, the rate random walk K | K[rad/s²/√Hz] = K[deg/s/√s] · π/180 |
//! | `update_rate` | Hz | sample rate, with which the filter discretises the two | |
//!
//! The key names and conventions are those of:
//! - Kalibr, `working_directory/imu.yaml` of ethz-asl/kalibr: a flat file with
//!   `accelerometer_noise_density`, `accelerometer_random_walk`, `gyroscope_noise_density`,
//!   `gyroscope_random_walk` ("Noise density (continuous-time)", "Bias random walk"),
//!   `rostopic` and `update_rate` ("Hz (for discretization of the values above)");
//! - OpenVINS, `config/euroc_mav/kalibr_imu_chain.yaml` of rpng/open_vins: the same four
//!   noise keys under `imu0:` in a file that starts with the OpenCV directive `%YAML:1.0`
//!   (OpenVINS reads it with `cv::FileStorage`); `ov_msckf/src/core/VioManagerOptions.h`
//!   parses `imu0/gyroscope_noise_density` and `imu0/gyroscope_random_walk` as
//!   "continuous-time IMU noise";
//! - VINS-Fusion, `config/euroc/euroc_mono_imu_config.yaml` of
//!   HKUST-Aerial-Robotics/VINS-Fusion: `acc_n`, `gyr_n`, `acc_w`, `gyr_w` in its one config
//!   file (also `%YAML:1.0`). Its `vins_estimator/src/factor/integration_base.h` uses them
//!   per reading (the rotation covariance grows by `gyr_n² dt²/2` per mid-point step, the
//!   bias covariance by `gyr_w² dt²`), i.e. as discrete standard deviations; the tool its
//!   authors point to (imu_utils) reports the continuous values, which is what is written
//!   here, with the per-reading equivalents (× √update_rate) in a comment.
//!
//! A single-axis gyro measures no acceleration: only the gyroscope keys are written; the
//! accelerometer keys the formats need are left as comments for the user to fill in, never
//! given a value.
//!
//! **Where the numbers come from.**
//! - [`NoiseParams::from_allan`] (`gyro-cli noise`): static data. N is the fitted −½ term
//!   of the Allan deviation (its value at τ = 1 s), K the fitted +½ term (read at τ = 3 s)
//!   together with the random walk equivalent of a fitted Gauss-Markov bias (below); both
//!   from [`super::fit`] (IEEE Std 952), nothing refitted. A term the fit dropped is
//!   replaced by its upper bound: the −½ (+½) line that stays under the Allan deviation's
//!   upper confidence bound at every τ. A fitted Gauss-Markov term of correlation time
//!   under [`BANDWIDTH_GM_MAX_S`] is the sensor's low-pass on its white noise (a MEMS
//!   gyro's digital filter makes the Allan deviation rise, then fall as white noise): N is
//!   then read from τ = 1 s to 10 s as on moving data ([`white_bound`]), and the term is
//!   not counted in K.
//! - [`NoiseParams::from_residual`] (`gyro-cli diagnose`, measured on moving data): the
//!   Allan deviation of what the deterministic terms leave of gyro minus reference
//!   (`diagnose::effective`); N the largest white noise its Allan deviation allows from
//!   τ = 1 s to 10 s ([`white_bound`]), K as for static data.
//! - [`NoiseParams::effective`] (`gyro-cli diagnose` when the runs are too short to
//!   measure it): the sensor model the diagnosis selected on moving data. N from its white noise plus the white noise the output
//!   rounding adds in motion (lsb²/12 per sample for the nominal step and any named
//!   `quantization`); K from its Gauss-Markov bias, a named `rate_random_walk` and a named
//!   `bias_instability` (its six Gauss-Markov processes).
//!
//! **One reading of K for every bias wander.** K is what the +½ line reads at
//! τ = [`RANDOM_WALK_TAU_S`] (3 s, IEEE Std 952): a wander term whose Allan variance at
//! 3 s is σ²_A counts as K² = 3 σ²_A / τ = σ²_A. A rate random walk gives back its own K
//! exactly. A first-order Gauss-Markov bias (σ, T) counts as the random walk with the same
//! Allan variance at 3 s: for T ≫ 3 s that is K ≈ σ·√(2/T), the random walk with the same
//! short-lag increments (1.1% less at T = 100 s); a Gauss-Markov bias of T ≲ 3 s is
//! mostly white at 3 s and adds little. The approximation overstates the wander at lags
//! beyond T, where a Gauss-Markov bias stays within ±σ. The simulator's
//! `bias_instability` is six such processes. Independent sources add in K².

use super::fit::{gauss_markov_avar_continuous, FLICKER_ADEV_PER_B};
use super::Characterization;
use gyro_sim::{Effect, SensorModel};
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Radians per degree.
const RAD_PER_DEG: f64 = PI / 180.0;

/// The continuous-time white rate noise density (rad/s/√Hz) of an angle random walk
/// `arw_deg_per_rt_h` (deg/√h): N · π/180 / 60.
pub fn noise_density_from_arw(arw_deg_per_rt_h: f64) -> f64 {
    arw_deg_per_rt_h * RAD_PER_DEG / 60.0
}

/// The continuous-time white rate noise density (rad/s/√Hz) of an angle random walk
/// `n_dps_per_rt_hz` given in deg/s/√Hz (the same as deg/√s).
pub fn noise_density_from_dps_per_rt_hz(n_dps_per_rt_hz: f64) -> f64 {
    n_dps_per_rt_hz * RAD_PER_DEG
}

/// The continuous-time bias random walk (rad/s²/√Hz) of a rate random walk
/// `k_dps_per_rt_s` (deg/s/√s).
pub fn random_walk_from_dps_per_rt_s(k_dps_per_rt_s: f64) -> f64 {
    k_dps_per_rt_s * RAD_PER_DEG
}

/// The averaging time (s) at which a +½ Allan line is read as a rate random walk K.
pub const RANDOM_WALK_TAU_S: f64 = 3.0;

/// The rate random walk (deg/s/√s) that has the same Allan variance at
/// [`RANDOM_WALK_TAU_S`] as a first-order Gauss-Markov bias of standard deviation
/// `sigma_dps` and correlation time `corr_time_s` (module docs; ≈ σ·√(2/T) for T ≫ 3 s);
/// 0 for a zero σ or a non-positive T.
pub fn gauss_markov_random_walk(sigma_dps: f64, corr_time_s: f64) -> f64 {
    if sigma_dps > 0.0 && corr_time_s > 0.0 {
        let tau = RANDOM_WALK_TAU_S;
        (3.0 / tau * gauss_markov_avar_continuous(tau, sigma_dps, corr_time_s)).sqrt()
    } else {
        0.0
    }
}

/// The rate random walk (deg/s/√s) of the simulator's `bias_instability` of standard
/// deviation `sigma_dps`: its six Gauss-Markov processes, each by
/// [`gauss_markov_random_walk`], added in K².
pub fn bias_instability_random_walk(sigma_dps: f64) -> f64 {
    gyro_sim::bias_instability_components(sigma_dps)
        .iter()
        .map(|&(s, t)| gauss_markov_random_walk(s, t).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Which tool's YAML to write.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum YamlFormat {
    /// Kalibr's `imu.yaml` (flat keys; Kalibr also needs the accelerometer keys, left as
    /// comments to fill in).
    #[default]
    Kalibr,
    /// OpenVINS's `kalibr_imu_chain.yaml` (`%YAML:1.0`, keys under `imu0:`).
    #[cfg_attr(feature = "clap", value(name = "openvins"))]
    OpenVins,
    /// The IMU lines of a VINS-Fusion config (`gyr_n`, `gyr_w`), to paste into it.
    Vins,
}

/// Why noise parameters cannot be written.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// A value is NaN, infinite or negative.
    #[error("{name} is {value}: not a finite number >= 0")]
    Invalid {
        /// The value's name.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// The sample rate is not a positive number.
    #[error("update rate {0} Hz is not a positive number")]
    UpdateRate(f64),
}

/// A gyro's continuous-time noise parameters, ready to be written as YAML.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseParams {
    /// White rate noise density N (rad/s/√Hz): `gyroscope_noise_density`.
    pub noise_density_rad_s_rt_hz: f64,
    /// Bias random walk K (rad/s²/√Hz): `gyroscope_random_walk`.
    pub random_walk_rad_s2_rt_hz: f64,
    /// Sample rate (Hz): `update_rate`.
    pub update_rate_hz: f64,
    /// Where the values come from (the header's `source:` line).
    pub source: String,
    /// How each value was obtained, one comment line each.
    pub notes: Vec<String>,
}

impl NoiseParams {
    /// Checked parameters: both noise values finite and >= 0, the rate positive.
    pub fn new(
        noise_density_rad_s_rt_hz: f64,
        random_walk_rad_s2_rt_hz: f64,
        update_rate_hz: f64,
        source: String,
        notes: Vec<String>,
    ) -> Result<Self, ExportError> {
        for (name, value) in [
            ("gyroscope_noise_density", noise_density_rad_s_rt_hz),
            ("gyroscope_random_walk", random_walk_rad_s2_rt_hz),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ExportError::Invalid { name, value });
            }
        }
        if !(update_rate_hz.is_finite() && update_rate_hz > 0.0) {
            return Err(ExportError::UpdateRate(update_rate_hz));
        }
        Ok(Self {
            noise_density_rad_s_rt_hz,
            random_walk_rad_s2_rt_hz,
            update_rate_hz,
            source,
            notes,
        })
    }

    /// The static values of a noise characterisation (module docs): N and K from its
    /// fit, the update rate its sample rate.
    pub fn from_allan(c: &Characterization, source: String) -> Result<Self, ExportError> {
        let fit = &c.fit;
        let mut notes = Vec::new();
        let low_pass = bandwidth_term(c);
        let n_dps = if let (Some((sigma, t)), Some(bound)) = (low_pass, white_bound(c)) {
            notes.push(format!(
                "gyroscope_noise_density: the fitted Gauss-Markov term (sigma {} deg/s, T {:.4} s, under {} s) is white noise through the sensor's own low-pass (fitted as first order: 1/(2 pi T) = {:.1} Hz), white at every tau from 1 s, so N is the -1/2 line under the Allan deviation's upper bound from 1 to 10 s, {} deg/s/sqrt(Hz) ({:.4} deg/sqrt(h)); the fitted N ({:.4} deg/sqrt(h)) is not used: the low-pass took the top of the band from it",
                sci(sigma),
                t,
                BANDWIDTH_GM_MAX_S,
                1.0 / (std::f64::consts::TAU * t),
                sci(bound),
                bound * 60.0,
                fit.arw_deg_per_rt_h
            ));
            bound
        } else if fit.arw_dps_per_rt_hz.significant {
            notes.push(format!(
                "gyroscope_noise_density: the fitted angle random walk N = {:.4} deg/sqrt(h) = {} deg/s/sqrt(Hz) (the -1/2 line of the Allan deviation at tau = 1 s)",
                fit.arw_deg_per_rt_h,
                sci(fit.arw_dps_per_rt_hz.value)
            ));
            fit.arw_dps_per_rt_hz.value
        } else {
            let bound = allan_bound(c, -0.5);
            notes.push(format!(
                "gyroscope_noise_density: UPPER BOUND: no -1/2 slope resolved; the -1/2 line under the Allan deviation's upper bound at every tau, {} deg/s/sqrt(Hz)",
                sci(bound)
            ));
            bound
        };
        let min_gm_tau_s = if low_pass.is_some() {
            BANDWIDTH_GM_MAX_S
        } else {
            0.0
        };
        let (k_dps, _) = random_walk(c, min_gm_tau_s, &mut notes);
        if fit.bias_instability_dps.significant {
            notes.push(format!(
                "not included: the bias instability B = {} deg/s (a flat Allan floor of {} deg/s, not a random walk)",
                sci(fit.bias_instability_dps.value),
                sci(fit.bias_instability_dps.value * FLICKER_ADEV_PER_B)
            ));
        }
        Self::of_dps(n_dps, k_dps, c.sample_rate_hz, source, notes)
    }

    /// [`Self::new`] from N in deg/s/√Hz and K in deg/s/√s.
    fn of_dps(
        n_dps: f64,
        k_dps: f64,
        update_rate_hz: f64,
        source: String,
        notes: Vec<String>,
    ) -> Result<Self, ExportError> {
        Self::new(
            noise_density_from_dps_per_rt_hz(n_dps),
            random_walk_from_dps_per_rt_s(k_dps),
            update_rate_hz,
            source,
            notes,
        )
    }

    /// The effective values on moving data (`gyro-cli diagnose`): `c` characterises
    /// what the deterministic terms leave of gyro minus reference (the runs' regression
    /// residual). Its Allan deviation is seldom a clean −½ line (periodic motion leaves
    /// bumps), so N is the largest white noise it allows from 1 to 10 s
    /// ([`white_bound`]), not the fitted line; K as in [`Self::from_allan`].
    /// `notes` (e.g. the ratio to the model's values) go first in the comments.
    pub fn from_residual(
        c: &Characterization,
        source: String,
        mut notes: Vec<String>,
    ) -> Result<Self, ExportError> {
        let n_dps = white_bound(c).ok_or(ExportError::Invalid {
            name: "gyroscope_noise_density",
            value: f64::NAN,
        })?;
        notes.push(format!(
            "gyroscope_noise_density: the largest white noise the residual's Allan deviation allows at every tau from 1 to 10 s (the fitted rate random walk taken off), N = {} deg/s/sqrt(Hz) ({:.4} deg/sqrt(h))",
            sci(n_dps),
            n_dps * 60.0
        ));
        let (k_dps, _) = random_walk(c, RANDOM_WALK_TAU_S, &mut notes);
        Self::of_dps(n_dps, k_dps, c.sample_rate_hz, source, notes)
    }
}

/// A fitted Gauss-Markov term whose correlation time is under this (s) is the sensor's own
/// low-pass on its white noise (a MEMS gyro's digital filter), not a bias wander: at every
/// τ from 1 s, where N is read, it is white (its Allan variance 2σ²T/τ), and read as a
/// random walk at 3 s it would count white noise as K.
pub const BANDWIDTH_GM_MAX_S: f64 = 0.1;

/// The fitted Gauss-Markov term of `c` as (σ, T) when it is a low-pass on the white noise
/// ([`BANDWIDTH_GM_MAX_S`]).
pub fn bandwidth_term(c: &Characterization) -> Option<(f64, f64)> {
    let gm = &c.fit.gauss_markov;
    match (gm.significant, gm.corr_time_s) {
        (true, Some(t)) if t < BANDWIDTH_GM_MAX_S => Some((gm.sigma_dps, t)),
        _ => None,
    }
}

/// The averaging times over which the effective white noise is read (s): from 1 s, where
/// the convention reads N, to 10 s, the length of a long movement.
pub const WHITE_TAUS_S: (f64, f64) = (1.0, 10.0);

/// The computed Allan points of `c` whose τ lies in [`WHITE_TAUS_S`] (ends included).
fn white_points(c: &Characterization) -> impl Iterator<Item = &crate::noise::AllanPoint> {
    band_points(c, WHITE_TAUS_S)
}

/// The computed Allan points of `c` whose τ lies in `(lo, hi)` s (ends included).
fn band_points(
    c: &Characterization,
    (lo, hi): (f64, f64),
) -> impl Iterator<Item = &crate::noise::AllanPoint> {
    c.allan
        .points
        .iter()
        .filter(move |p| p.tau_s >= lo * (1.0 - 1e-9) && p.tau_s <= hi * (1.0 + 1e-9))
}

/// The white level that the Allan points of `c` with τ in `band` (s, ends included) read:
/// N² (deg²/s² per Hz), their τ·AVAR(τ) with the fitted rate random walk taken off,
/// averaged with their equivalent degrees of freedom as weights; and the largest of
/// those degrees of freedom (the points share their data, so the average is about as
/// precise as its best point: N² to a relative standard error of about √(2/edf)).
/// `None` when no computed τ lies in the band.
pub fn band_white_variance(c: &Characterization, band: (f64, f64)) -> Option<(f64, f64)> {
    let walk = c.fit.rate_random_walk_dps_per_rt_s.value.powi(2) / 3.0;
    let (sum, weights, best) =
        band_points(c, band).fold((0.0, 0.0, 0.0f64), |(sum, weights, best), p| {
            let w = if p.edf.is_finite() && p.edf > 0.0 {
                p.edf
            } else {
                1.0
            };
            (
                sum + w * (p.avar() - walk * p.tau_s) * p.tau_s,
                weights + w,
                best.max(w),
            )
        });
    (weights > 0.0).then(|| ((sum / weights).max(0.0), best))
}

/// N (deg/s/√Hz): the largest white noise the Allan deviation of `c` allows at every
/// computed τ in [`WHITE_TAUS_S`]: the −½ line under its upper confidence bound (68%)
/// there, after taking off the fitted rate random walk's K²·τ/3 (the point estimates'
/// minimum over a dozen τ would sit below N by their scatter). For white noise it is N
/// or a little above; a
/// bounded error (periodic motion the model does not follow, whose Allan deviation falls
/// as 1/τ) shows at 1 s but does not accumulate into angle, and is not counted as a walk.
/// (A fitted Gauss-Markov term is not taken off: one with a correlation time near 1 s is
/// the same curve as white noise there.) `None` when no computed τ lies in the range.
pub fn white_bound(c: &Characterization) -> Option<f64> {
    let walk = c.fit.rate_random_walk_dps_per_rt_s.value.powi(2) / 3.0;
    white_points(c)
        .map(|p| {
            let upper = if p.upper_dps.is_finite() {
                p.upper_dps
            } else {
                p.adev_dps
            };
            ((upper.powi(2) - walk * p.tau_s).max(0.0) * p.tau_s).sqrt()
        })
        .min_by(f64::total_cmp)
}

/// N (deg/s/√Hz): the white noise the Allan deviation of `c` reads over [`WHITE_TAUS_S`],
/// as an estimate rather than a bound ([`white_bound`] is the largest the curve allows,
/// which over-reads pure white noise by the upper bound's margin, several percent on
/// minutes of data): the points' τ·AVAR(τ), the fitted rate random walk taken off,
/// averaged with their equivalent degrees of freedom as weights, and never above
/// [`white_bound`] (a bounded error, whose Allan deviation falls as 1/τ, raises the mean
/// over the range but not the bound at its far end). `None` when no computed τ lies in
/// the range.
pub fn white_level(c: &Characterization) -> Option<f64> {
    let bound = white_bound(c)?;
    let (variance, _) = band_white_variance(c, WHITE_TAUS_S)?;
    Some(variance.sqrt().min(bound))
}

/// K (deg/s/√s) of a residual's characterisation `c` ([`NoiseParams::from_residual`]) and
/// whether the fit resolved it (else it is the +½ upper bound).
pub fn residual_random_walk(c: &Characterization) -> (f64, bool) {
    random_walk(c, RANDOM_WALK_TAU_S, &mut Vec::new())
}

/// K (deg/s/√s) of `c` with its note, and whether the fit resolved it: the fitted rate
/// random walk and Gauss-Markov bias read at τ = 3 s, else the +½ upper bound. A Gauss-Markov term whose correlation time
/// is under `min_gm_tau_s` is left out: on a residual in motion the fit takes the
/// motion's short bumps for one, and at the τ of a movement it is white, which the
/// white bound already holds.
fn random_walk(c: &Characterization, min_gm_tau_s: f64, notes: &mut Vec<String>) -> (f64, bool) {
    let fit = &c.fit;
    let k_fit = fit.rate_random_walk_dps_per_rt_s.value;
    let gm = &fit.gauss_markov;
    let k_gm = match (gm.significant, gm.corr_time_s) {
        (true, Some(t)) if t >= min_gm_tau_s => gauss_markov_random_walk(gm.sigma_dps, t),
        _ => 0.0,
    };
    if k_fit > 0.0 || k_gm > 0.0 {
        let mut parts = Vec::new();
        if k_fit > 0.0 {
            parts.push(format!(
                "the fitted rate random walk K = {} deg/s/sqrt(s) (the +1/2 line at tau = 3 s)",
                sci(k_fit)
            ));
        }
        if let (true, Some(t)) = (k_gm > 0.0, gm.corr_time_s) {
            parts.push(format!(
                "the fitted Gauss-Markov bias (sigma {} deg/s, T {:.4} s) read at tau = 3 s, K = {} deg/s/sqrt(s)",
                sci(gm.sigma_dps),
                t,
                sci(k_gm)
            ));
        }
        notes.push(format!("gyroscope_random_walk: {}", parts.join(" + ")));
        (k_fit.hypot(k_gm), true)
    } else {
        let bound = allan_bound(c, 0.5);
        notes.push(format!(
            "gyroscope_random_walk: UPPER BOUND: no +1/2 slope (rate random walk, Gauss-Markov bias) resolved up to tau = {:.4} s; the +1/2 line under the Allan deviation's upper bound at every tau, {} deg/s/sqrt(s)",
            c.allan.points.last().map_or(0.0, |p| p.tau_s),
            sci(bound)
        ));
        (bound, false)
    }
}

/// The effective white noise density (deg/s/√Hz) of `sensor` with the `effects` at `fs`
/// Hz: its white noise per sample and the output rounding steps (lsb²/12 per sample), and
/// the note saying so.
fn model_noise_density(sensor: &SensorModel, effects: &[Effect], fs: f64) -> (f64, String) {
    // White noise per sample, and the rounding steps that add lsb²/12 in motion.
    let white = sensor.white_sigma_dps();
    let steps: Vec<f64> = std::iter::once(sensor.lsb_dps)
        .chain(effects.iter().filter_map(|e| match *e {
            Effect::Quantization { lsb_dps } => Some(lsb_dps),
            _ => None,
        }))
        .filter(|&lsb| lsb > 0.0)
        .collect();
    let rounding: f64 = steps.iter().map(|lsb| lsb * lsb / 12.0).sum();
    let n_dps = ((white * white + rounding) / fs).sqrt();
    let mut text = format!(
        "gyroscope_noise_density: white noise ARW {:.4} deg/sqrt(h) ({} deg/s per sample at {} Hz)",
        sensor.arw_deg_per_rt_h,
        sci(white),
        fs
    );
    for lsb in &steps {
        let _ = write!(
            text,
            " + output rounding to {} deg/s (lsb^2/12 per sample)",
            sci(*lsb)
        );
    }
    let _ = write!(
        text,
        " = {} deg/s/sqrt(Hz) ({:.4} deg/sqrt(h))",
        sci(n_dps),
        n_dps * 60.0
    );
    (n_dps, text)
}

/// The effective rate random walk K (deg/s/√s) of `sensor` with the `effects`: its
/// Gauss-Markov bias, rate random walk and bias instability read at τ = 3 s, added in
/// quadrature; the notes on each, and on the biases left out, go to `notes`.
fn model_random_walk(sensor: &SensorModel, effects: &[Effect], notes: &mut Vec<String>) -> f64 {
    let mut parts = Vec::new();
    let mut k2 = 0.0;
    let k_gm = gauss_markov_random_walk(sensor.gm_sigma_dps, sensor.gm_tau_s);
    if k_gm > 0.0 {
        k2 += k_gm * k_gm;
        parts.push(format!(
            "the model's Gauss-Markov bias (sigma {} deg/s, T {} s) read at tau = 3 s, K = {} deg/s/sqrt(s)",
            sci(sensor.gm_sigma_dps),
            sensor.gm_tau_s,
            sci(k_gm)
        ));
    }
    let mut left_out = Vec::new();
    for e in effects {
        match *e {
            Effect::RateRandomWalk { k_dps_per_rt_s } if k_dps_per_rt_s > 0.0 => {
                k2 += k_dps_per_rt_s * k_dps_per_rt_s;
                parts.push(format!(
                    "rate_random_walk K = {} deg/s/sqrt(s)",
                    sci(k_dps_per_rt_s)
                ));
            }
            Effect::BiasInstability { sigma_dps } if sigma_dps > 0.0 => {
                let k = bias_instability_random_walk(sigma_dps);
                k2 += k * k;
                parts.push(format!(
                    "bias_instability sigma {} deg/s (six Gauss-Markov processes, T 1-1000 s) read at tau = 3 s, K = {} deg/s/sqrt(s)",
                    sci(sigma_dps),
                    sci(k)
                ));
            }
            Effect::TurnOnBias { .. } | Effect::TemperatureBias { .. } => {
                left_out.push(e.id());
            }
            _ => {}
        }
    }
    let k_dps = k2.sqrt();
    notes.push(if parts.is_empty() {
        "gyroscope_random_walk: 0: the model has no bias wander (no Gauss-Markov bias, rate random walk or bias instability)".to_string()
    } else {
        format!("gyroscope_random_walk: {}", parts.join(" + "))
    });
    if !left_out.is_empty() {
        notes.push(format!(
            "not included: {} (a constant or temperature-driven bias, not a random walk)",
            left_out.join(", ")
        ));
    }
    k_dps
}

impl NoiseParams {
    /// The effective values of a sensor model and the effects selected with it (module
    /// docs), e.g. a diagnosis's `selected_sensor` and `model.effects`; `provenance` (the
    /// diagnosis's notes on where the model's values came from) is kept in the comments.
    pub fn effective(
        sensor: &SensorModel,
        effects: &[Effect],
        provenance: &[String],
        source: String,
    ) -> Result<Self, ExportError> {
        let fs = sensor.sample_rate_hz;
        if !(fs.is_finite() && fs > 0.0) {
            return Err(ExportError::UpdateRate(fs));
        }
        let mut notes = Vec::new();
        let (n_dps, density_note) = model_noise_density(sensor, effects, fs);
        notes.push(density_note);
        let k_dps = model_random_walk(sensor, effects, &mut notes);
        notes.extend(provenance.iter().map(|p| format!("model: {p}")));
        Self::of_dps(n_dps, k_dps, fs, source, notes)
    }

    /// The YAML of `format`.
    pub fn to_yaml(&self, format: YamlFormat) -> String {
        match format {
            YamlFormat::Kalibr => self.to_kalibr_yaml(),
            YamlFormat::OpenVins => self.to_openvins_yaml(),
            YamlFormat::Vins => self.to_vins_yaml(),
        }
    }

    /// Kalibr's `imu.yaml`: the gyroscope keys and `update_rate`; the accelerometer keys
    /// and `rostopic`, which Kalibr also needs, as comments to fill in.
    pub fn to_kalibr_yaml(&self) -> String {
        let mut y = String::new();
        self.header(&mut y, "Kalibr imu.yaml");
        y.push_str(
            "# Accelerometer: none on a single-axis gyro. Kalibr needs both keys: fill them in\n\
             # from your accelerometer's own characterisation.\n\
             # accelerometer_noise_density:     # m/s^2/sqrt(Hz), continuous time\n\
             # accelerometer_random_walk:       # m/s^3/sqrt(Hz), continuous time\n",
        );
        self.gyro_keys(
            &mut y,
            "",
            "gyroscope_noise_density",
            "gyroscope_random_walk",
        );
        y.push_str("# rostopic: /imu0                  # the IMU's ROS topic: set it\n");
        let _ = writeln!(
            y,
            "update_rate: {}  # Hz (Kalibr discretises the values above with it)",
            decimal(self.update_rate_hz)
        );
        y
    }

    /// OpenVINS's `kalibr_imu_chain.yaml`: `%YAML:1.0` (OpenCV), `imu0:` with the
    /// gyroscope keys and `update_rate`; the accelerometer keys and `rostopic` as comments.
    pub fn to_openvins_yaml(&self) -> String {
        let mut y = String::from("%YAML:1.0 # OpenCV FileStorage, as OpenVINS reads it\n");
        self.header(&mut y, "OpenVINS kalibr_imu_chain.yaml");
        y.push_str(
            "# The rest of the imu0 block (T_i_b, time_offset, model, intrinsics) is not a\n\
             # noise value: take it from your Kalibr calibration or leave OpenVINS's defaults.\n\
             imu0:\n  \
               # Accelerometer: none on a single-axis gyro. OpenVINS reads both keys: fill\n  \
               # them in from your accelerometer's own characterisation.\n  \
               # accelerometer_noise_density:     # [ m / s^2 / sqrt(Hz) ]\n  \
               # accelerometer_random_walk:       # [ m / s^3 / sqrt(Hz) ]\n",
        );
        self.gyro_keys(
            &mut y,
            "  ",
            "gyroscope_noise_density",
            "gyroscope_random_walk",
        );
        y.push_str("  # rostopic: /imu0                # the IMU's ROS topic: set it\n");
        let _ = writeln!(y, "  update_rate: {}  # Hz", decimal(self.update_rate_hz));
        y
    }

    /// The IMU noise lines of a VINS-Fusion config (`gyr_n`, `gyr_w`), to paste into it;
    /// `acc_n`, `acc_w` as comments; the per-reading equivalents in a comment.
    pub fn to_vins_yaml(&self) -> String {
        let mut y = String::new();
        self.header(&mut y, "VINS-Fusion config (its IMU noise lines)");
        let root = self.update_rate_hz.sqrt();
        let _ = write!(
            y,
            "# Paste into your VINS-Fusion config (an OpenCV FileStorage file that starts with\n\
             # %YAML:1.0), replacing its gyr_n and gyr_w. VINS-Fusion takes the IMU rate from the\n\
             # message stamps (no key); at the {} Hz of these data, the per-reading standard\n\
             # deviations its integration_base.h applies would be gyr_n*sqrt(rate) = {} rad/s\n\
             # and gyr_w*sqrt(rate) = {} rad/s^2.\n\
             # Accelerometer: none on a single-axis gyro; keep your config's own values.\n\
             # acc_n:       # m/s^2/sqrt(Hz)\n\
             # acc_w:       # m/s^3/sqrt(Hz)\n",
            decimal(self.update_rate_hz),
            sci(self.noise_density_rad_s_rt_hz * root),
            sci(self.random_walk_rad_s2_rt_hz * root)
        );
        self.gyro_keys(&mut y, "", "gyr_n", "gyr_w");
        y
    }

    /// The comment block every format starts with: what, from where, the units.
    fn header(&self, y: &mut String, what: &str) {
        let _ = writeln!(
            y,
            "# Gyroscope noise for {what}, written by gyro-cli.\n\
             # Single-axis gyro: gyroscope keys only.\n\
             # Source: {}\n\
             # Continuous time. Noise density N in rad/s/sqrt(Hz) (white rate noise; from an\n\
             # angle random walk in deg/sqrt(h): N = ARW * pi/180 / 60). Random walk K in\n\
             # rad/s^2/sqrt(Hz) (bias random walk; from deg/s/sqrt(s): K * pi/180).",
            one_line(&self.source)
        );
        for note in &self.notes {
            let _ = writeln!(y, "# - {}", one_line(note));
        }
    }

    /// The two gyroscope lines under `keys`, indented by `indent`.
    fn gyro_keys(&self, y: &mut String, indent: &str, density: &str, walk: &str) {
        let _ = writeln!(
            y,
            "{indent}{density}: {}  # rad/s/sqrt(Hz), continuous-time white noise (angle random walk)",
            sci(self.noise_density_rad_s_rt_hz)
        );
        let _ = writeln!(
            y,
            "{indent}{walk}: {}  # rad/s^2/sqrt(Hz), continuous-time bias random walk (rate random walk)",
            sci(self.random_walk_rad_s2_rt_hz)
        );
    }
}

/// The smallest slope-`slope` line `c·τ^slope` (σ in deg/s) that stays at or under the
/// Allan deviation's upper bound at every τ: an upper bound for a term of that slope
/// (the terms' variances add). `c` is N (deg/s/√Hz) for slope −½ and K/√3 for +½, so
/// the value returned is N, or K = √3·c.
pub(crate) fn allan_bound(c: &Characterization, slope: f64) -> f64 {
    let line = c
        .allan
        .points
        .iter()
        .map(|p| p.upper_dps / p.tau_s.powf(slope))
        .fold(f64::INFINITY, f64::min);
    let line = if line.is_finite() { line } else { 0.0 };
    if slope > 0.0 {
        line * 3f64.sqrt()
    } else {
        line
    }
}

/// `v` as C's `%.6e` (`8.144869e-05`): a float to YAML 1.1 readers (PyYAML, as Kalibr
/// uses) too, which need the dot and the exponent's sign.
pub fn sci(v: f64) -> String {
    let s = format!("{v:.6e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => {
            let (sign, digits) = match exp.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', exp),
            };
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => s,
    }
}

/// `v` with a decimal point (`1000.0`, `99.5`): a float, not an integer, to YAML readers.
fn decimal(v: f64) -> String {
    let s = format!("{v}");
    if s.contains('.') || s.contains('e') || !v.is_finite() {
        s
    } else {
        format!("{s}.0")
    }
}

/// `text` on one line (a comment cannot span lines).
fn one_line(text: &str) -> String {
    text.replace(['\n', '\r'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A characterisation to put synthetic Allan points into (no fitted random walk).
    fn synthetic() -> Characterization {
        let mut c = crate::noise::characterize(
            &[&(0..4000)
                .map(|k| ((k * 7919) % 13) as f64)
                .collect::<Vec<_>>()],
            100.0,
            &crate::noise::NoiseOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        c.fit.rate_random_walk_dps_per_rt_s.value = 0.0;
        c
    }

    /// Allan points (`template` otherwise) at 0.5–20 s of the Allan variance `avar(τ)`: the point estimate and
    /// the upper bound `adev_ratio` and `upper_ratio` times its square root, 1000/τ degrees
    /// of freedom.
    fn on_curve(
        template: crate::noise::AllanPoint,
        adev_ratio: f64,
        upper_ratio: f64,
        avar: &dyn Fn(f64) -> f64,
    ) -> Vec<crate::noise::AllanPoint> {
        [0.5, 1.0, 2.0, 5.0, 10.0, 20.0]
            .iter()
            .map(|&tau_s| crate::noise::AllanPoint {
                tau_s,
                adev_dps: adev_ratio * avar(tau_s).sqrt(),
                upper_dps: upper_ratio * avar(tau_s).sqrt(),
                edf: 1000.0 / tau_s,
                ..template
            })
            .collect()
    }

    /// The white bound is the −½ line under the curve's upper bound from 1 s to 10 s
    /// (here 1/0.9 of the point estimates, which it does not read): exact for white
    /// noise; a bounded error (Allan deviation ∝ 1/τ) counts only as much as it still
    /// shows at 10 s; a fitted random walk is taken off; τ outside the range is ignored.
    #[test]
    fn white_bound_is_the_half_line_under_the_curve() {
        let mut c = synthetic();
        let template = c.allan.points[0];
        let curve = |avar: &dyn Fn(f64) -> f64| on_curve(template, 0.9, 1.0, avar);
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12);
        // White noise alone, with a deeper dip at 0.5 s and 20 s (outside the range).
        c.allan.points = curve(&|t| {
            if (1.0..=10.0).contains(&t) {
                0.09 / t
            } else {
                0.01 / t
            }
        });
        assert!(close(white_bound(&c), 0.3), "{:?}", white_bound(&c));
        // Plus a bounded error of 1 deg/s at 1 s, falling as 1/τ: what is left at 10 s.
        c.allan.points = curve(&|t| 0.09 / t + 1.0 / (t * t));
        assert!(close(white_bound(&c), (0.09f64 + 0.1).sqrt()));
        // Plus a random walk the fit resolved: taken off.
        c.allan.points = curve(&|t| 0.09 / t + 0.04 * t / 3.0);
        c.fit.rate_random_walk_dps_per_rt_s.value = 0.2;
        assert!(close(white_bound(&c), 0.3), "{:?}", white_bound(&c));
        // Nothing computed in the range.
        c.allan.points.retain(|p| p.tau_s < 1.0);
        assert_eq!(white_bound(&c), None);
        assert_eq!(white_level(&c), None);
    }

    /// The white level reads the points, not their upper bound: exact for white noise;
    /// with a bounded error it is the bound; a random walk the fit resolved is taken off.
    #[test]
    fn white_level_is_the_estimate_under_the_bound() {
        let mut c = synthetic();
        let template = c.allan.points[0];
        let curve = |avar: &dyn Fn(f64) -> f64| on_curve(template, 1.0, 1.1, avar);
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        c.allan.points = curve(&|t| 0.09 / t);
        assert!(close(white_level(&c), 0.3), "{:?}", white_level(&c));
        assert!(close(white_bound(&c), 0.33), "{:?}", white_bound(&c));
        // A bounded error: the bound at the range's far end, under the mean.
        c.allan.points = curve(&|t| 0.09 / t + 1.0 / (t * t));
        assert_eq!(white_level(&c), white_bound(&c));
        assert!(close(white_bound(&c), 1.1 * (0.09f64 + 0.1).sqrt()));
        c.allan.points = curve(&|t| 0.09 / t + 0.04 * t / 3.0);
        c.fit.rate_random_walk_dps_per_rt_s.value = 0.2;
        assert!(close(white_level(&c), 0.3), "{:?}", white_level(&c));
        // A curve rising with τ (a wander the fit did not resolve) reads its mean level,
        // never above the bound.
        c.fit.rate_random_walk_dps_per_rt_s.value = 0.0;
        assert!(white_level(&c) <= white_bound(&c));
    }

    /// Static white noise of 3.0 deg/√h through a one-pole low-pass at 10 Hz (a MEMS
    /// gyro's digital filter) on 100 Hz samples: the Allan fit takes the filter for a
    /// short Gauss-Markov term, and the export reads N from 1 to 10 s instead of the
    /// fitted N (within 10% of 3.0 deg/√h), and does not count the term as a random walk
    /// (K stays the upper bound, far under the term read at 3 s).
    #[test]
    fn a_low_pass_on_the_noise_is_not_read_as_a_bias_wander() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let fs = 100.0;
        let sigma = 3.0 / 60.0 * f64::sqrt(fs);
        let alpha = 1.0 - (-std::f64::consts::TAU * 10.0 / fs).exp();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut y = 0.0;
        let x: Vec<f64> = (0..120_000)
            .map(|_| {
                let w: f64 = StandardNormal.sample(&mut rng);
                y += alpha * (sigma * w - y);
                y
            })
            .collect();
        let c = crate::noise::characterize(&[&x], fs, &crate::noise::NoiseOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let (gm_sigma, t) = bandwidth_term(&c).unwrap_or_else(|| panic!("{:?}", c.fit));
        let p = NoiseParams::from_allan(&c, "test".into()).unwrap_or_else(|e| panic!("{e}"));
        let n_deg_per_rt_h = p.noise_density_rad_s_rt_hz / noise_density_from_arw(1.0);
        assert!(
            (2.7..3.3).contains(&n_deg_per_rt_h),
            "{n_deg_per_rt_h} {:?}",
            c.fit
        );
        let k_gm = gauss_markov_random_walk(gm_sigma, t);
        let k = p.random_walk_rad_s2_rt_hz / random_walk_from_dps_per_rt_s(1.0);
        assert!(k < 0.1 * k_gm, "{k} against {k_gm}");
        assert!(p
            .notes
            .iter()
            .any(|n| n.contains("the sensor's own low-pass")));
        // The model file's sensor: the same white noise, no bias wander.
        let model = c.sensor_model();
        assert!(
            (model.arw_deg_per_rt_h - n_deg_per_rt_h).abs() < 1e-9,
            "{model:?}"
        );
        assert_eq!(model.gm_sigma_dps, 0.0);
    }

    #[test]
    fn unit_conversions_against_hand_computed_values() {
        // 0.28 deg/√h · π/180 / 60 = 0.28 · 0.0174532925 / 60 = 8.1448699e-5 rad/s/√Hz.
        let n = noise_density_from_arw(0.28);
        assert!((n - 8.144_869_9e-5).abs() < 1e-12, "{n}");
        // 1 deg/√h = 1/60 deg/√s: the same through deg/s/√Hz.
        assert!((noise_density_from_dps_per_rt_hz(0.28 / 60.0) - n).abs() < 1e-18);
        // 0.02 deg/s/√s · π/180 = 3.4906585e-4 rad/s²/√Hz.
        let k = random_walk_from_dps_per_rt_s(0.02);
        assert!((k - 3.490_658_5e-4).abs() < 1e-12, "{k}");
        // Gauss-Markov σ 0.05 deg/s, T 100 s, at τ = 3 s: x = τ/T = 0.03,
        // σ²_A = (2σ²T²/τ²)(x − 3/2 + 2e^{−x} − ½e^{−2x}) = σ² · 0.0195562 → K = 0.1398436 σ
        // = 6.99218e-3 deg/s/√s, 1.1% under σ·√(2/T) = 7.07107e-3.
        let g = gauss_markov_random_walk(0.05, 100.0);
        assert!((g - 6.992_18e-3).abs() < 1e-8, "{g}");
        assert_eq!(gauss_markov_random_walk(0.0, 100.0), 0.0);
        assert_eq!(gauss_markov_random_walk(0.05, 0.0), 0.0);
        // bias_instability σ: six processes of σ²/6 with T = 1, 10^0.6, ... 10^3 s, each
        // read at τ = 3 s as above: K = 0.3655695 σ.
        let b = bias_instability_random_walk(0.3);
        assert!((b - 0.109_670_85).abs() < 1e-8, "{b}");
    }

    #[test]
    fn numbers_are_floats_to_yaml_1_1_readers() {
        assert_eq!(sci(8.144_869_9e-5), "8.144870e-05");
        assert_eq!(sci(0.0), "0.000000e+00");
        assert_eq!(sci(1234.5), "1.234500e+03");
        assert_eq!(sci(1.0), "1.000000e+00");
        assert_eq!(decimal(1000.0), "1000.0");
        assert_eq!(decimal(99.5), "99.5");
    }

    fn params() -> NoiseParams {
        NoiseParams::new(
            noise_density_from_arw(0.28),
            random_walk_from_dps_per_rt_s(0.02),
            1000.0,
            "static Allan deviation of a.csv: with a # and\na newline".into(),
            vec!["a note".into()],
        )
        .unwrap()
    }

    /// The value of `key:` in `yaml` (first occurrence), as written.
    fn value<'a>(yaml: &'a str, key: &str) -> Option<&'a str> {
        yaml.lines().find_map(|l| {
            let rest = l.trim_start().strip_prefix(key)?.strip_prefix(':')?;
            rest.split('#').next().map(str::trim)
        })
    }

    /// PyYAML's (YAML 1.1) float pattern, which Kalibr's reader applies.
    fn yaml11_float(s: &str) -> bool {
        let s = s.strip_prefix(['-', '+']).unwrap_or(s);
        let (mantissa, exp) = match s.split_once(['e', 'E']) {
            Some((m, e)) => (m, Some(e)),
            None => (s, None),
        };
        let exp_ok = exp.is_none_or(|e| {
            e.len() >= 2 && e.starts_with(['-', '+']) && e[1..].chars().all(|c| c.is_ascii_digit())
        });
        let dot = mantissa.contains('.');
        let digits = mantissa.chars().all(|c| c.is_ascii_digit() || c == '.');
        dot && digits && exp_ok
    }

    #[test]
    fn every_format_parses_and_holds_the_values() {
        let p = params();
        for (format, keys, nested) in [
            (
                YamlFormat::Kalibr,
                ["gyroscope_noise_density", "gyroscope_random_walk"],
                false,
            ),
            (
                YamlFormat::OpenVins,
                ["gyroscope_noise_density", "gyroscope_random_walk"],
                true,
            ),
            (YamlFormat::Vins, ["gyr_n", "gyr_w"], false),
        ] {
            let text = p.to_yaml(format);
            // The OpenCV directive is not standard YAML: a standard reader parses the rest.
            let body = text
                .strip_prefix("%YAML:1.0")
                .map_or(text.as_str(), |rest| {
                    rest.split_once('\n').map_or("", |r| r.1)
                });
            assert_eq!(format == YamlFormat::OpenVins, body.len() < text.len());
            let doc: serde_yaml::Value =
                serde_yaml::from_str(body).unwrap_or_else(|e| panic!("{format:?}: {e}\n{text}"));
            let map = if nested { &doc["imu0"] } else { &doc };
            let got = |k: &str| {
                map[k]
                    .as_f64()
                    .unwrap_or_else(|| panic!("{format:?} {k}:\n{text}"))
            };
            assert!((got(keys[0]) / p.noise_density_rad_s_rt_hz - 1.0).abs() < 1e-6);
            assert!((got(keys[1]) / p.random_walk_rad_s2_rt_hz - 1.0).abs() < 1e-6);
            if format != YamlFormat::Vins {
                assert_eq!(got("update_rate"), 1000.0);
                assert!(yaml11_float(value(body, "update_rate").unwrap()));
            }
            for key in keys {
                assert!(yaml11_float(value(body, key).unwrap()), "{format:?} {key}");
            }
            // Gyroscope keys only: no accelerometer value, the comment kept on one line.
            for acc in [
                "accelerometer_noise_density",
                "accelerometer_random_walk",
                "acc_n",
                "acc_w",
            ] {
                assert!(map.get(acc).is_none(), "{format:?} has {acc}");
            }
            assert!(text
                .contains("# Source: static Allan deviation of a.csv: with a # and a newline\n"));
            assert!(text.contains("# - a note\n"));
            assert!(text.contains("Single-axis gyro"));
        }
    }

    #[test]
    fn bad_values_are_refused() {
        let bad = |n: f64, k: f64, r: f64| NoiseParams::new(n, k, r, String::new(), vec![]);
        assert!(matches!(
            bad(f64::NAN, 0.0, 100.0),
            Err(ExportError::Invalid {
                name: "gyroscope_noise_density",
                ..
            })
        ));
        assert!(matches!(
            bad(1e-4, -1.0, 100.0),
            Err(ExportError::Invalid {
                name: "gyroscope_random_walk",
                ..
            })
        ));
        assert_eq!(bad(1e-4, 0.0, 0.0), Err(ExportError::UpdateRate(0.0)));
        assert!(bad(1e-4, 0.0, 100.0).is_ok());
    }

    #[test]
    fn effective_values_add_the_sources() {
        let sensor = SensorModel {
            sample_rate_hz: 100.0,
            arw_deg_per_rt_h: 0.3,
            gm_sigma_dps: 0.05,
            gm_tau_s: 100.0,
            lsb_dps: 0.0,
            ..SensorModel::default()
        };
        let effects = [
            Effect::RateRandomWalk {
                k_dps_per_rt_s: 0.01,
            },
            Effect::TurnOnBias { sigma_dps: 0.5 },
            Effect::Latency { delay_s: 0.01 },
        ];
        let p =
            NoiseParams::effective(&sensor, &effects, &["prior".into()], "diag".into()).unwrap();
        // White only: 0.3 deg/√h.
        assert!((p.noise_density_rad_s_rt_hz / noise_density_from_arw(0.3) - 1.0).abs() < 1e-12);
        // K² = (0.1398436 · 0.05)² + 0.01².
        let k = (0.139_843_6f64 * 0.05).hypot(0.01);
        assert!((p.random_walk_rad_s2_rt_hz / random_walk_from_dps_per_rt_s(k) - 1.0).abs() < 1e-6);
        assert_eq!(p.update_rate_hz, 100.0);
        assert!(p.notes.iter().any(|n| n.contains("turn_on_bias")));
        assert!(p.notes.iter().any(|n| n == "model: prior"));

        // Output rounding to 0.2 deg/s adds 0.04/12 (deg/s)² per sample.
        let rounded = [Effect::Quantization { lsb_dps: 0.2 }];
        let q = NoiseParams::effective(&sensor, &rounded, &[], "diag".into()).unwrap();
        let white = sensor.white_sigma_dps();
        let n = ((white * white + 0.04 / 12.0) / 100.0).sqrt();
        assert!(
            (q.noise_density_rad_s_rt_hz / noise_density_from_dps_per_rt_hz(n) - 1.0).abs() < 1e-12
        );

        // No wander at all: K = 0, said so.
        let still = SensorModel {
            gm_sigma_dps: 0.0,
            ..sensor
        };
        let z = NoiseParams::effective(&still, &[], &[], "diag".into()).unwrap();
        assert_eq!(z.random_walk_rad_s2_rt_hz, 0.0);
        assert!(z.notes.iter().any(|n| n.contains("no bias wander")));
    }
}
