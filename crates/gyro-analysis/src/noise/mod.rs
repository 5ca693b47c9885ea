//! Noise characterisation of static gyro data: overlapping Allan deviation with confidence
//! bounds, the IEEE 952 noise terms and a Gauss-Markov bias fitted to it, and a Welch PSD.
//!
//! ```no_run
//! use gyro_analysis::noise;
//! use gyro_log as log;
//! let raw = log::read_csv("static.csv".as_ref(), &log::ColumnOptions::default())?;
//! let regular = log::regularize(&raw, &log::GridOptions::default())?;
//! let rate: Vec<f64> = regular.slots.iter().map(|s| s.rate_dps).collect();
//! let result = noise::characterize(&[&rate], regular.sample_rate_hz, &noise::NoiseOptions::default())?;
//! println!("ARW {:.3} deg/√h", result.fit.arw_deg_per_rt_h);
//! let sensor = result.sensor_model(); // for `gyro-cli simulate --model`
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! - [`allan`]: the overlapping Allan deviation (as `allantools.oadev` on rate data),
//!   pooled over segments, with chi-squared bounds from NIST SP 1065 degrees of freedom.
//! - [`mod@fit`]: Q, N, B, K and a Gauss-Markov (σ, T) by weighted non-negative least squares
//!   on the Allan variance, with backward elimination of insignificant terms; the Allan
//!   bounds then use the noise type the fitted model has at each τ.
//! - [`psd`]: Welch PSD (Hann, 50% overlap, one-sided) and the white density.
//! - [`rest`]: rest stretches found by the gyro-core motion detector (`--static-only`).
//! - [`characterize_logs`]: several logs, each and pooled.
//! - [`export`]: the fitted noise as the YAML of Kalibr, OpenVINS and VINS-Fusion
//!   ([`NoiseParams`]; also the effective values of a diagnosis's model).
//!
//! The table, the JSON and the PSD CSV are rendered by `gyro_report::noise`.
//!
//! Data comes in *segments* (contiguous runs of samples at one rate): a whole static log
//! is one segment; rest stretches of a log with motion, or several logs, are several.
//! Statistics pool what lies within segments and never bridge two.

pub mod allan;
mod chi2;
pub mod export;
pub mod fft;
pub mod fit;
mod logs;
pub mod psd;
pub mod rest;

pub use allan::{AllanDeviation, AllanPoint, NoiseType, TauGrid, ONE_SIGMA};
pub use chi2::chi2_quantile;
pub use export::{ExportError, NoiseParams, YamlFormat};
pub use fit::{fit, AllanFloor, FitOptions, FitTerm, GaussMarkovFit, NoiseFit};
pub use logs::{
    characterize_logs, moving_warning, NoiseLog, NoiseLogsError, NoiseRun, MOVING_SHARE_LIMIT,
};
pub use psd::{welch, Psd, PsdBand, PsdOptions};
pub use rest::rest_segments;

use crate::model::ModelFile;
use gyro_sim::{Effect, SensorModel};
use serde::Serialize;

/// Fewest samples (in the longest segment) worth characterising: 4 τ points.
pub const MIN_SAMPLES: usize = 16;

/// Why data cannot be characterised.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoiseError {
    /// No samples at all.
    #[error("no samples to characterise")]
    Empty,
    /// Too few samples for the Allan deviation.
    #[error(
        "too short for any averaging time: {samples} samples in the longest stretch, at least {MIN_SAMPLES} needed"
    )]
    TooShort {
        /// Samples in the longest segment.
        samples: usize,
    },
    /// A rate is NaN or infinite.
    #[error("non-finite rate at sample {index}")]
    NonFinite {
        /// Index over all segments, in order.
        index: usize,
    },
    /// The sample rate is not a positive number.
    #[error("sample rate {0} Hz is not a positive number")]
    SampleRate(f64),
    /// The rates are so large that their variance overflows.
    #[error(
        "rates up to {largest_dps:e} deg/s: too large to characterise (their variance overflows); is the rate column in deg/s?"
    )]
    Overflow {
        /// The largest |rate| (deg/s).
        largest_dps: f64,
    },
    /// The confidence level is not in (0, 1).
    #[error("confidence {0} is not in (0, 1)")]
    Confidence(f64),
}

/// Settings of [`characterize`].
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseOptions {
    /// The τ grid.
    pub taus: TauGrid,
    /// Confidence of the Allan bounds (default 1σ, 68.27%).
    pub confidence: f64,
    /// The fit.
    pub fit: FitOptions,
    /// The PSD.
    pub psd: PsdOptions,
}

impl Default for NoiseOptions {
    fn default() -> Self {
        Self {
            taus: TauGrid::default(),
            confidence: ONE_SIGMA,
            fit: FitOptions::default(),
            psd: PsdOptions::default(),
        }
    }
}

/// The characterisation of one data set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Characterization {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Samples used.
    pub samples: usize,
    /// Segments (rest stretches, logs) pooled.
    pub segments: usize,
    /// Time covered by the samples used (s).
    pub duration_s: f64,
    /// Mean rate: the bias at rest (deg/s).
    pub mean_rate_dps: f64,
    /// Standard deviation of the rate samples (deg/s).
    pub std_rate_dps: f64,
    /// The output's resolution, if every rate lies on a grid (deg/s).
    pub rate_step_dps: Option<f64>,
    /// Allan deviation; bounds use the fitted model's noise type per τ.
    pub allan: AllanDeviation,
    /// Fitted noise terms.
    pub fit: NoiseFit,
    /// Welch PSD, if a window fits in a segment.
    pub psd: Option<Psd>,
    /// Simulator effects for the significant terms the sensor model lacks.
    pub suggested_effects: Vec<Effect>,
}

/// The step of the grid all `values` lie on (a multiple of it, within 5% of a step), if
/// there is one and it is coarse (fewer distinct values than half the samples). The
/// tolerance admits values written with a few decimals (a log's 1/24 deg/s step as
/// `0.04167`): the step is the least-squares fit through the origin of the values within
/// 50 steps of zero, starting from the smallest difference between distinct values.
pub fn rate_step(values: &[f64]) -> Option<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    if sorted.len() < 2 || sorted.len() * 2 > values.len() {
        return None;
    }
    let first = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    if first <= 0.0 || !first.is_finite() {
        return None;
    }
    let (mut vk, mut kk) = (0.0, 0.0);
    for v in &sorted {
        let k = (v / first).round();
        if k.abs() <= 50.0 {
            vk += v * k;
            kk += k * k;
        }
    }
    let step = if kk > 0.0 { vk / kk } else { first };
    let on_grid = sorted.iter().all(|v| {
        let k = v / step;
        (k - k.round()).abs() < 0.05
    });
    on_grid.then_some(step)
}

/// The simulator's `bias_instability` σ (deg/s) whose Allan floor matches a bias
/// instability `b_dps`: that effect is six Gauss-Markov processes of equal variance
/// ([`gyro_sim::bias_instability_components`]); its Allan deviation's minimum over
/// 1–1000 s, per unit σ, is computed from the Gauss-Markov formula.
pub fn bias_instability_effect_sigma(b_dps: f64) -> f64 {
    let per_unit = (0..=60)
        .map(|k| 10f64.powf(f64::from(k) / 20.0))
        .map(|tau| {
            gyro_sim::bias_instability_components(1.0)
                .iter()
                .map(|&(sigma, t)| fit::gauss_markov_avar_continuous(tau, sigma, t))
                .sum::<f64>()
                .sqrt()
        })
        .fold(f64::INFINITY, f64::min);
    b_dps * fit::FLICKER_ADEV_PER_B / per_unit
}

/// Characterise rate `segments` (deg/s) sampled at `sample_rate_hz`.
pub fn characterize(
    segments: &[&[f64]],
    sample_rate_hz: f64,
    options: &NoiseOptions,
) -> Result<Characterization, NoiseError> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(NoiseError::SampleRate(sample_rate_hz));
    }
    if !(options.confidence > 0.0 && options.confidence < 1.0) {
        return Err(NoiseError::Confidence(options.confidence));
    }
    let samples: usize = segments.iter().map(|s| s.len()).sum();
    if samples == 0 {
        return Err(NoiseError::Empty);
    }
    if let Some(index) = segments
        .iter()
        .flat_map(|s| s.iter())
        .position(|v| !v.is_finite())
    {
        return Err(NoiseError::NonFinite { index });
    }
    let longest = segments.iter().map(|s| s.len()).max().unwrap_or(0);
    if longest < MIN_SAMPLES {
        return Err(NoiseError::TooShort { samples: longest });
    }
    let all = || segments.iter().flat_map(|s| s.iter().copied());
    let mean = all().sum::<f64>() / samples as f64;
    let var = all().map(|v| (v - mean) * (v - mean)).sum::<f64>() / samples as f64;
    if !(mean.is_finite() && var.is_finite()) {
        // Rates near f64's limit (1e300 deg/s): every square overflows.
        let largest_dps = all().map(f64::abs).fold(0.0, f64::max);
        return Err(NoiseError::Overflow { largest_dps });
    }
    let values: Vec<f64> = all().collect();

    let factors = options.taus.factors(longest);
    let mut allan = AllanDeviation::compute(segments, sample_rate_hz, &factors, options.confidence);
    let fitted = fit::fit(&allan, &options.fit);
    allan.set_bounds(|tau| fitted.noise_type(tau));
    let psd = psd::welch(segments, sample_rate_hz, &options.psd);

    let mut suggested_effects = Vec::new();
    if fitted.bias_instability_dps.significant {
        suggested_effects.push(Effect::BiasInstability {
            sigma_dps: bias_instability_effect_sigma(fitted.bias_instability_dps.value),
        });
    }
    if fitted.rate_random_walk_dps_per_rt_s.significant {
        suggested_effects.push(Effect::RateRandomWalk {
            k_dps_per_rt_s: fitted.rate_random_walk_dps_per_rt_s.value,
        });
    }
    Ok(Characterization {
        sample_rate_hz,
        samples,
        segments: segments.len(),
        duration_s: samples as f64 / sample_rate_hz,
        mean_rate_dps: mean,
        std_rate_dps: var.sqrt(),
        rate_step_dps: rate_step(&values),
        allan,
        fit: fitted,
        psd,
        suggested_effects,
    })
}

/// The Gauss-Markov bias a significant rate random walk of `c` may be on this log: over
/// averaging times up to about its correlation time T, a Gauss-Markov bias of σ has the
/// Allan variance of a rate random walk K = σ·√(2/T), so a log not several T long cannot
/// tell them apart (the nominal CRM100's own bias, σ 0.05 deg/s over T = 100 s, reads as
/// K 0.0069 deg/s/√s on 600 s at rest, its longest averaging time 126 s). Returns (the
/// longest averaging time in s, the σ in deg/s of a Gauss-Markov bias with T equal to
/// it); `None` without a significant rate random walk.
pub fn rate_random_walk_look_alike(c: &Characterization) -> Option<(f64, f64)> {
    let k = &c.fit.rate_random_walk_dps_per_rt_s;
    if !k.significant {
        return None;
    }
    let t = c.allan.points.last()?.tau_s;
    Some((t, k.value * (t / 2.0).sqrt()))
}

impl Characterization {
    /// The simulator's sensor model from this characterisation: rate, bias (the mean
    /// rate), ARW (fitted N), Gauss-Markov σ and T (σ = 0 if the term is not significant;
    /// T then stays the default), output step (if the data lies on a grid, else 0); the
    /// range stays the default. Terms the model lacks are in `suggested_effects`. A
    /// Gauss-Markov term that is the sensor's low-pass on its white noise
    /// ([`export::bandwidth_term`]) is not a bias wander: the ARW is then the white noise
    /// read from τ 1–10 s ([`export::white_bound`]) and σ = 0.
    pub fn sensor_model(&self) -> SensorModel {
        let default = SensorModel::default();
        let gm = &self.fit.gauss_markov;
        let low_pass_arw = export::bandwidth_term(self)
            .and_then(|_| export::white_bound(self))
            .map(|n_dps_per_rt_hz| 60.0 * n_dps_per_rt_hz);
        SensorModel {
            sample_rate_hz: self.sample_rate_hz,
            bias_dps: self.mean_rate_dps,
            arw_deg_per_rt_h: low_pass_arw.unwrap_or(self.fit.arw_deg_per_rt_h),
            gm_sigma_dps: if gm.significant && low_pass_arw.is_none() {
                gm.sigma_dps
            } else {
                0.0
            },
            gm_tau_s: gm.corr_time_s.unwrap_or(default.gm_tau_s),
            lsb_dps: self.rate_step_dps.unwrap_or(0.0),
            range_dps: default.range_dps,
        }
    }

    /// A model file (default pipeline configuration) whose `sensor` is [`Self::sensor_model`].
    pub fn model_file(&self) -> ModelFile {
        ModelFile {
            sensor: self.sensor_model(),
            ..ModelFile::new(gyro_core::Config::default())
        }
    }
}
