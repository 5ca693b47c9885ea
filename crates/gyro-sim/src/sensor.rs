//! The nominal sensor model and the generator of simulated logs.
//!
//! Nominal: `rate_meas = rate_true + b_const + b_gm(t) + white noise`,
//! quantised to the output word and clipped to the range. Each [`Effect`] adds its term
//! (its table entry's, summed in [`SimTerms`]).
//! Every noise source draws from its own random stream of the seed, so switching an
//! effect on or off leaves the other sources' sequences unchanged.

use super::effects::{Effect, SimTerms};
use super::motion::Motion;
use gyro_log::{Log, Row};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Nominal sensor parameters (a CRM100 in the ±300 °/s range by default).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorModel {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Constant bias (deg/s).
    pub bias_dps: f64,
    /// Angle random walk (deg/√h): white rate noise of density ARW/60 (deg/s/√Hz).
    pub arw_deg_per_rt_h: f64,
    /// Gauss-Markov bias: stationary standard deviation (deg/s).
    pub gm_sigma_dps: f64,
    /// Gauss-Markov bias: correlation time (s).
    pub gm_tau_s: f64,
    /// Output resolution (deg/s per count); 0 for none.
    pub lsb_dps: f64,
    /// Full-scale range (deg/s); the output is clipped to ±range.
    pub range_dps: f64,
}

impl Default for SensorModel {
    fn default() -> Self {
        Self {
            sample_rate_hz: 1000.0,
            bias_dps: 0.3,
            arw_deg_per_rt_h: 0.28,
            gm_sigma_dps: 0.05,
            gm_tau_s: 100.0,
            lsb_dps: 1.0 / 24.0,
            range_dps: 300.0,
        }
    }
}

impl SensorModel {
    /// The same sensor without its random terms (white noise, Gauss-Markov bias) and
    /// output rounding: what a deterministic effect alone does to a run (the bias, range
    /// and rates stay).
    pub fn noise_free(self) -> Self {
        Self {
            arw_deg_per_rt_h: 0.0,
            gm_sigma_dps: 0.0,
            lsb_dps: 0.0,
            ..self
        }
    }

    /// White-noise standard deviation per sample (deg/s).
    pub fn white_sigma_dps(&self) -> f64 {
        self.arw_deg_per_rt_h / 60.0 * self.sample_rate_hz.sqrt()
    }

    /// Check the parameters.
    pub fn validate(&self) -> Result<(), InvalidSensorModel> {
        let checks = [
            (
                self.sample_rate_hz > 0.0 && self.sample_rate_hz <= 1e6,
                "sample_rate_hz must be in (0, 1e6]",
            ),
            (
                self.arw_deg_per_rt_h >= 0.0,
                "arw_deg_per_rt_h must be >= 0",
            ),
            (self.gm_sigma_dps >= 0.0, "gm_sigma_dps must be >= 0"),
            (self.gm_tau_s > 0.0, "gm_tau_s must be > 0"),
            (self.lsb_dps >= 0.0, "lsb_dps must be >= 0"),
            (self.range_dps > 0.0, "range_dps must be > 0"),
            (self.bias_dps.is_finite(), "bias_dps must be finite"),
        ];
        match checks.iter().find(|(ok, _)| !ok) {
            Some((_, why)) => Err(InvalidSensorModel { reason: why }),
            None => Ok(()),
        }
    }
}

/// A sensor model parameter out of its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("sensor model: {reason}")]
pub struct InvalidSensorModel {
    /// Which parameter, and the condition it must meet.
    pub reason: &'static str,
}

/// Most samples one simulated run may have: 2^26 (67 million; 18.6 h at 1 kHz), the most
/// a command holds of a log it reads (`gyro_log::MAX_HELD_SLOTS`), so that what is
/// simulated can be read back.
pub const MAX_SAMPLES: u64 = 1 << 26;

/// Memory a simulated sample takes while the run is made: its row of the log and its
/// three columns (rate, reference, temperature).
pub const BYTES_PER_SAMPLE: usize = std::mem::size_of::<Row>() + 3 * std::mem::size_of::<f64>();

/// A run too long to simulate (more than [`MAX_SAMPLES`]), refused before anything is
/// allocated.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error(
    "{duration_s} s at {sample_rate_hz} Hz would be {samples} samples ({:.1} GiB), more than the limit of {MAX_SAMPLES} samples ({:.1} GiB)",
    gib(*samples),
    gib(MAX_SAMPLES as f64)
)]
pub struct TooManySamples {
    /// Duration of the motion (s).
    pub duration_s: f64,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Samples the run would have.
    pub samples: f64,
}

fn gib(samples: f64) -> f64 {
    samples * BYTES_PER_SAMPLE as f64 / f64::from(1_u32 << 30)
}

/// The samples [`simulate`] makes of `motion` at `model`'s rate.
pub fn sample_count(model: &SensorModel, motion: &Motion) -> f64 {
    (motion.duration_s() * model.sample_rate_hz).floor() + 1.0
}

/// Refuse a run of more than [`MAX_SAMPLES`] samples (or of a duration that is not a
/// finite number), before [`simulate`] allocates them.
pub fn check_size(model: &SensorModel, motion: &Motion) -> Result<(), TooManySamples> {
    let samples = sample_count(model, motion);
    if samples.is_finite() && samples <= MAX_SAMPLES as f64 {
        Ok(())
    } else {
        Err(TooManySamples {
            duration_s: motion.duration_s(),
            sample_rate_hz: model.sample_rate_hz,
            samples,
        })
    }
}

/// Conditions of a simulated run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Seed of every random stream.
    pub seed: u64,
    /// Temperature at the start (°C).
    pub temperature_start_c: f64,
    /// Warm-up: temperature rises by this much (°C)...
    pub temperature_rise_c: f64,
    /// ...with this time constant (s).
    pub temperature_tau_s: f64,
    /// Quantise the reference like an encoder with this many counts per revolution.
    pub encoder_counts: Option<u32>,
    /// Quantise the reference to this step (deg); takes precedence over `encoder_counts`
    /// (a re-simulated real log keeps its encoder's step, which need not divide 360°).
    pub reference_step_deg: Option<f64>,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            seed: 1,
            temperature_start_c: 25.0,
            temperature_rise_c: 5.0,
            temperature_tau_s: 120.0,
            encoder_counts: None,
            reference_step_deg: None,
        }
    }
}

/// Random streams, one per noise source.
#[derive(Clone, Copy)]
enum Stream {
    White = 0,
    GaussMarkov = 1,
    Flicker = 2,
    RandomWalk = 3,
    TurnOn = 4,
    Dropout = 5,
    Temperature = 6,
}

fn stream(seed: u64, which: Stream) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(which as u64);
    rng
}

/// A first-order Gauss-Markov process sampled every `dt_s`.
struct GaussMarkovProcess {
    phi: f64,
    drive: f64,
    value: f64,
}

impl GaussMarkovProcess {
    fn new(sigma: f64, tau_s: f64, dt_s: f64, rng: &mut ChaCha8Rng) -> Self {
        let phi = (-dt_s / tau_s).exp();
        let start: f64 = StandardNormal.sample(rng);
        Self {
            phi,
            drive: sigma * (1.0 - phi * phi).sqrt(),
            value: sigma * start,
        }
    }
    fn step(&mut self, rng: &mut ChaCha8Rng) -> f64 {
        let w: f64 = StandardNormal.sample(rng);
        self.value = self.phi * self.value + self.drive * w;
        self.value
    }
}

/// A simulated run as columns on the nominal grid (sample `k` at `k / fs`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimSeries {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Measured rate (deg/s), NaN where the sample was dropped.
    pub rate_dps: Vec<f64>,
    /// Reference angle (deg).
    pub reference_deg: Vec<f64>,
    /// Temperature (°C).
    pub temperature_c: Vec<f64>,
    /// Number of dropped samples (NaN in `rate_dps`).
    pub dropped: usize,
}

/// Simulate a log of `motion` as seen by `model` with `effects`.
pub fn simulate(
    model: &SensorModel,
    effects: &[Effect],
    motion: &Motion,
    options: &SimOptions,
) -> Log {
    let series = simulate_series(model, effects, motion, options, None);
    let fs = series.sample_rate_hz;
    // Samples are stamped when they are taken, by the logger's (accurate) clock: a
    // sensor clock error shows as stamps that drift from the nominal k / fs.
    let clock = 1.0 + SimTerms::of(effects).clock_ppm * 1e-6;
    // Rounded to what a logger would keep (and what reads back short from CSV).
    let round = |x: f64, step: f64| (x / step).round() * step;
    let rows = (0..series.rate_dps.len())
        .filter(|&k| series.rate_dps[k].is_finite())
        .map(|k| Row {
            line: 0,
            time_s: if clock == 1.0 {
                k as f64 / fs
            } else {
                round(k as f64 / (fs * clock), 1e-9)
            },
            rate_dps: Some(round(series.rate_dps[k], 1e-6)),
            reference_deg: Some(round(series.reference_deg[k], 1e-6)),
            temperature_c: Some(round(series.temperature_c[k], 1e-3)),
        })
        .collect();
    let mut metadata = BTreeMap::new();
    metadata.insert("sensor".into(), "simulated".into());
    metadata.insert("sample_rate_hz".into(), format!("{fs}"));
    metadata.insert("seed".into(), options.seed.to_string());
    metadata.insert(
        "effects".into(),
        serde_json::to_string(effects).unwrap_or_default(),
    );
    Log {
        path: "simulated".into(),
        metadata,
        has_reference: true,
        has_temperature: true,
        rows,
    }
}

/// Simulate `motion` as seen by `model` with `effects`, as columns.
///
/// A clock error takes sample `k` at `k / (fs (1 + ε))`: on the columns' nominal grid
/// (sample `k` at `k / fs`, the period the firmware integrates with) the motion runs
/// faster by 1 + ε; [`simulate`] stamps each sample with its true time.
///
/// `temperature_c`, when given, is the temperature at each sample (a recorded run's, so
/// a re-simulation sees the same temperatures; NaN entries take the previous value);
/// otherwise the warm-up curve of `options` plus 0.02 °C of sensor noise.
pub fn simulate_series(
    model: &SensorModel,
    effects: &[Effect],
    motion: &Motion,
    options: &SimOptions,
    temperature_c: Option<&[f64]>,
) -> SimSeries {
    let fs = model.sample_rate_hz;
    let dt = 1.0 / fs;
    // A slow sample clock (either stamping) reaches the motion's end before the nominal
    // count: the samples past it would read a held reference beside a held rate.
    let slowest_clock = {
        let terms = SimTerms::of(effects);
        ((1.0 + terms.clock_ppm * 1e-6) * (1.0 + terms.count_clock_ppm * 1e-6)).min(1.0)
    };
    let n = (motion.duration_s() * fs * slowest_clock).floor() as usize + 1;

    let mut white_rng = stream(options.seed, Stream::White);
    let mut gm_rng = stream(options.seed, Stream::GaussMarkov);
    let mut flicker_rng = stream(options.seed, Stream::Flicker);
    let mut walk_rng = stream(options.seed, Stream::RandomWalk);
    let mut turn_on_rng = stream(options.seed, Stream::TurnOn);
    let mut dropout_rng = stream(options.seed, Stream::Dropout);
    let mut temp_rng = stream(options.seed, Stream::Temperature);

    let white_sigma = model.white_sigma_dps();
    let mut gm = GaussMarkovProcess::new(model.gm_sigma_dps, model.gm_tau_s, dt, &mut gm_rng);

    // Effect terms (identity unless present).
    let terms = SimTerms::of(effects);
    let limit = model.range_dps.min(terms.limit_dps);
    let dropout = terms
        .dropouts
        .map(|(rate_per_s, mean_samples)| (rate_per_s / fs, 1.0 - 1.0 / mean_samples));
    // Six processes, τ from 1 s to 1000 s (half-decade steps): a flat floor.
    let mut flicker: Vec<GaussMarkovProcess> = terms
        .flicker_sigma_dps
        .map(|sigma_dps| {
            crate::bias_instability_components(sigma_dps)
                .iter()
                .map(|&(sigma_i, tau_s)| {
                    GaussMarkovProcess::new(sigma_i, tau_s, dt, &mut flicker_rng)
                })
                .collect()
        })
        .unwrap_or_default();
    // The sensor's low-pass on the rate and on the white noise (it filters its sensing
    // element's noise as an MEMS gyro's digital low-pass does; the bias terms are slow
    // and pass it unchanged).
    let low_pass = |initial: f64| {
        terms
            .bandwidth_hz
            .map(|cutoff_hz| crate::TwoPoleLowPass::new(cutoff_hz, fs, initial))
    };
    let (mut rate_low_pass, mut noise_low_pass) =
        (low_pass(motion.rate_dps(-terms.delay_s)), low_pass(0.0));
    let (scale_k, asym_k, k3, k2) = (
        terms.scale_k,
        terms.asymmetry_k,
        terms.k3_per_dps2,
        terms.k2_per_dps,
    );
    let (temp_bias, temp_scale) = (terms.bias_dps_per_c, terms.scale_per_c);
    let (delay_s, clock_ppm) = (terms.delay_s, terms.clock_ppm);
    let (turn_on_sigma, walk_k, extra_lsb) = (
        terms.turn_on_sigma_dps,
        terms.walk_dps_per_rt_s,
        terms.extra_lsb_dps,
    );
    let turn_on_draw: f64 = StandardNormal.sample(&mut turn_on_rng);
    let turn_on = turn_on_sigma * turn_on_draw;
    let clock = 1.0 + clock_ppm * 1e-6;
    // Rows stamped by the sensor's count: the gyro's sample k is taken earlier (a fast
    // clock) than the reference of its row.
    let count_clock = 1.0 + terms.count_clock_ppm * 1e-6;
    let vibration = terms.vibration;
    let mut walk = 0.0;
    let mut dropout_left = false;
    let temperature_c_is_recorded = temperature_c.is_some();

    let mut out = SimSeries {
        sample_rate_hz: fs,
        rate_dps: Vec::with_capacity(n),
        reference_deg: Vec::with_capacity(n),
        temperature_c: Vec::with_capacity(n),
        dropped: 0,
    };
    let recorded_start_c = temperature_c
        .and_then(|t| t.iter().copied().find(|v| v.is_finite()))
        .unwrap_or(options.temperature_start_c);
    let mut recorded_last_c = recorded_start_c;
    let reference_step = options.reference_step_deg.filter(|s| *s > 0.0).or(options
        .encoder_counts
        .map(|counts| 360.0 / f64::from(counts.max(1))));
    for k in 0..n {
        let label_s = k as f64 * dt;
        let true_s = label_s / clock;
        let (temperature_c, delta_c) = match temperature_c {
            Some(recorded) => {
                if let Some(t) = recorded.get(k).copied().filter(|t| t.is_finite()) {
                    recorded_last_c = t;
                }
                (recorded_last_c, recorded_last_c - recorded_start_c)
            }
            None => {
                let t = options.temperature_start_c
                    + options.temperature_rise_c
                        * (1.0 - (-true_s / options.temperature_tau_s).exp());
                (t, t - options.temperature_start_c)
            }
        };

        let gyro_s = true_s / count_clock;
        let mut rate = motion.rate_dps(gyro_s - delay_s);
        if let Some(filter) = rate_low_pass.as_mut() {
            rate = filter.step(rate);
        }
        let scale = 1.0 + scale_k + asym_k * rate.signum() + temp_scale * delta_c;
        let mut measured = rate * scale + k3 * rate * rate * rate + k2 * rate * rate;
        if let Some((amplitude_dps, frequency_hz)) = vibration {
            measured += amplitude_dps * (2.0 * std::f64::consts::PI * frequency_hz * gyro_s).sin();
        }

        let flicker_dps: f64 = flicker.iter_mut().map(|p| p.step(&mut flicker_rng)).sum();
        if walk_k > 0.0 {
            let w: f64 = StandardNormal.sample(&mut walk_rng);
            walk += walk_k * dt.sqrt() * w;
        }
        let white: f64 = StandardNormal.sample(&mut white_rng);
        let mut white_dps = white_sigma * white;
        if let Some(filter) = noise_low_pass.as_mut() {
            white_dps = filter.step(white_dps);
        }
        measured += model.bias_dps
            + turn_on
            + gm.step(&mut gm_rng)
            + temp_bias * delta_c
            + flicker_dps
            + walk
            + white_dps;
        for lsb in [model.lsb_dps, extra_lsb] {
            if lsb > 0.0 {
                measured = (measured / lsb).round() * lsb;
            }
        }
        measured = measured.clamp(-limit, limit);

        let temp_noise: f64 = StandardNormal.sample(&mut temp_rng);
        let mut dropped = false;
        if let Some((start_p, continue_p)) = dropout {
            let u: f64 = dropout_rng.random();
            dropout_left = if dropout_left {
                u < continue_p
            } else {
                u < start_p
            };
            dropped = dropout_left;
        }
        let mut reference_deg = motion.angle_deg(true_s);
        if let Some(step) = reference_step {
            reference_deg = (reference_deg / step).round() * step;
        }
        if dropped {
            out.dropped += 1;
            measured = f64::NAN;
        }
        out.rate_dps.push(measured);
        out.reference_deg.push(reference_deg);
        out.temperature_c.push(if temperature_c_is_recorded {
            temperature_c
        } else {
            temperature_c + 0.02 * temp_noise
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A recorded trajectory re-simulated with a slow sample clock (either stamping)
    /// ends where the motion ends: no sample reads the held last rate beside the held
    /// last reference angle.
    #[test]
    fn a_slow_clock_stops_at_the_motions_end() {
        let fs = 100.0;
        let angles: Vec<f64> = (0..1001).map(|k| 50.0 * k as f64 / fs).collect();
        let motion = Motion::from_reference(0.0, 1.0 / fs, &angles, 1);
        let model = SensorModel {
            sample_rate_hz: fs,
            bias_dps: 0.0,
            ..SensorModel::default()
        }
        .noise_free();
        for effect in [
            Effect::ClockError { ppm: -5000.0 },
            Effect::ClockErrorCountStamped { ppm: -5000.0 },
        ] {
            let s = simulate_series(&model, &[effect], &motion, &SimOptions::default(), None);
            assert!(s.rate_dps.len() < angles.len(), "{effect:?}");
            let last = s.reference_deg.len() - 1;
            let step = s.reference_deg[last] - s.reference_deg[last - 1];
            assert!(
                step > 0.4,
                "{effect:?}: the reference stops moving ({step} deg)"
            );
        }
    }

    /// The sensor's bandwidth filters its white noise as it filters the rate: at rest the
    /// first differences (the top of the band) shrink, while the noise the angle
    /// integrates (0.5 s block means) keeps its density.
    #[test]
    fn the_bandwidth_filters_the_white_noise() {
        let motion = Motion::from_rotations(Vec::new(), 120.0);
        let model = SensorModel {
            gm_sigma_dps: 0.0,
            lsb_dps: 0.0,
            ..SensorModel::default()
        };
        let rest = |effects: &[Effect]| {
            let s = simulate_series(&model, effects, &motion, &SimOptions::default(), None);
            let differences = s.rate_dps.windows(2).map(|w| (w[1] - w[0]).powi(2));
            let difference_variance = differences.sum::<f64>() / (s.rate_dps.len() - 1) as f64;
            let blocks: Vec<f64> = s
                .rate_dps
                .chunks_exact(500)
                .map(|b| b.iter().sum::<f64>() / 500.0)
                .collect();
            let block_variance = blocks
                .windows(2)
                .map(|w| (w[1] - w[0]).powi(2))
                .sum::<f64>()
                / (2.0 * (blocks.len() - 1) as f64);
            (difference_variance, block_variance)
        };
        let (white_differences, white_blocks) = rest(&[]);
        let (filtered_differences, filtered_blocks) =
            rest(&[Effect::Bandwidth { cutoff_hz: 15.0 }]);
        assert!(
            filtered_differences < 0.01 * white_differences,
            "{filtered_differences} vs {white_differences}"
        );
        let ratio = filtered_blocks / white_blocks;
        assert!((0.8..1.25).contains(&ratio), "block variance ratio {ratio}");
    }
}
