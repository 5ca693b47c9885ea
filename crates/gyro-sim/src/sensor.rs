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
        // No wander (σ 0): the value stays 0 whatever is drawn, and the stream is its own.
        if self.drive == 0.0 && self.value == 0.0 {
            return self.value;
        }
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

/// The step the simulated output is rounded to, once: a `quantization` effect's
/// `effect_lsb_dps` when positive (it replaces the model's), else the model's
/// `model_lsb_dps` (0: no rounding). Anything that re-creates the simulator's output (the
/// diagnosis matching its white noise) rounds with this.
pub fn output_step_dps(model_lsb_dps: f64, effect_lsb_dps: f64) -> f64 {
    if effect_lsb_dps > 0.0 {
        effect_lsb_dps
    } else {
        model_lsb_dps
    }
}

/// The period (s) between the time stamps of the samples of a sensor at `fs` Hz with
/// `effects`: samples are stamped when they are taken, by the logger's (accurate) clock,
/// so a sensor clock error ([`Effect::ClockError`]) shows as stamps that drift from the
/// nominal `k / fs`; `1 / fs` otherwise (a clock stamped by the sensor's own count keeps
/// the nominal grid).
pub fn stamp_period_s(effects: &[Effect], fs: f64) -> f64 {
    let clock = 1.0 + SimTerms::of(effects).clock_ppm * 1e-6;
    if clock == 1.0 {
        1.0 / fs
    } else {
        1.0 / (fs * clock)
    }
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
    let period_s = stamp_period_s(effects, fs);
    // Rounded to what a logger would keep (and what reads back short from CSV).
    let round = |x: f64, step: f64| (x / step).round() * step;
    let rows = (0..series.rate_dps.len())
        .filter(|&k| series.rate_dps[k].is_finite())
        .map(|k| Row {
            line: 0,
            time_s: if period_s == 1.0 / fs {
                k as f64 / fs
            } else {
                round(k as f64 * period_s, 1e-9)
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
    // The samples taken within the motion: a sample clock fast by ε takes 1 + ε times the
    // nominal count in its time. Stamped by its own count, the rows' reference is read
    // on the nominal grid, and a slow clock's gyro reaches the motion's end first (the
    // samples past it would read a held reference beside a held rate).
    let reach = {
        let terms = SimTerms::of(effects);
        (1.0 + terms.clock_ppm * 1e-6) * (1.0 + terms.count_clock_ppm * 1e-6).min(1.0)
    };
    // (A millionth of a sample spared: a motion read from a log at its stamps' clock ends
    // on a sample that rounding would otherwise drop.)
    let n = (motion.duration_s() * fs * reach + 1e-6).floor() as usize + 1;

    // Effect terms (identity unless present).
    let mut sensor = SimSensor::new(model, SimTerms::of(effects), motion, options.seed);
    let clock = 1.0 + sensor.terms.clock_ppm * 1e-6;
    // Rows stamped by the sensor's count: the gyro's sample k is taken earlier (a fast
    // clock) than the reference of its row.
    let count_clock = 1.0 + sensor.terms.count_clock_ppm * 1e-6;
    let temperature_c_is_recorded = temperature_c.is_some();
    let mut temperature = SimTemperature::new(temperature_c, options);

    let mut out = SimSeries {
        sample_rate_hz: fs,
        rate_dps: Vec::with_capacity(n),
        reference_deg: Vec::with_capacity(n),
        temperature_c: Vec::with_capacity(n),
        dropped: 0,
    };
    let reference_step = options.reference_step_deg.filter(|s| *s > 0.0).or(options
        .encoder_counts
        .map(|counts| 360.0 / f64::from(counts.max(1))));
    for k in 0..n {
        let label_s = k as f64 * dt;
        let true_s = label_s / clock;
        let (temperature_c, delta_c) = temperature.at(k, true_s);

        let gyro_s = true_s / count_clock;
        let mut measured = sensor.sensed_dps(gyro_s, delta_c);
        measured += sensor.bias_and_noise_dps(delta_c);
        measured = sensor.output_dps(measured);

        // A recorded temperature is taken as it is (its own stream draws nothing then).
        let temp_noise: f64 = if temperature_c_is_recorded {
            0.0
        } else {
            StandardNormal.sample(&mut sensor.streams.temperature)
        };
        let dropped = sensor.dropped();
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

/// The random streams of a run, one per noise source (see [`Stream`]).
struct Streams {
    white: ChaCha8Rng,
    gm: ChaCha8Rng,
    flicker: ChaCha8Rng,
    walk: ChaCha8Rng,
    turn_on: ChaCha8Rng,
    dropout: ChaCha8Rng,
    temperature: ChaCha8Rng,
}

impl Streams {
    /// Every stream of `seed`.
    fn new(seed: u64) -> Self {
        Self {
            white: stream(seed, Stream::White),
            gm: stream(seed, Stream::GaussMarkov),
            flicker: stream(seed, Stream::Flicker),
            walk: stream(seed, Stream::RandomWalk),
            turn_on: stream(seed, Stream::TurnOn),
            dropout: stream(seed, Stream::Dropout),
            temperature: stream(seed, Stream::Temperature),
        }
    }
}

/// The simulated sensor from sample to sample: the model, the effects' terms, the random
/// streams and the state of every process (Gauss-Markov, flicker, walk, low-passes,
/// dropouts).
struct SimSensor<'a> {
    model: &'a SensorModel,
    motion: &'a Motion,
    terms: SimTerms,
    streams: Streams,
    /// Sample period (s).
    dt_s: f64,
    white_sigma_dps: f64,
    gm: GaussMarkovProcess,
    flicker: Vec<GaussMarkovProcess>,
    rate_low_pass: Option<crate::TwoPoleLowPass>,
    noise_low_pass: Option<crate::TwoPoleLowPass>,
    /// Clip level (deg/s): the range, or an effect's lower one.
    limit_dps: f64,
    /// Per sample: the chance a dropout starts, and the chance it goes on.
    dropout: Option<(f64, f64)>,
    turn_on_dps: f64,
    walk_dps: f64,
    dropout_left: bool,
}

impl<'a> SimSensor<'a> {
    /// The sensor at the start of a run of `motion` seeded with `seed`.
    fn new(model: &'a SensorModel, terms: SimTerms, motion: &'a Motion, seed: u64) -> Self {
        let fs = model.sample_rate_hz;
        let dt = 1.0 / fs;
        let mut streams = Streams::new(seed);
        let white_sigma = model.white_sigma_dps();
        let gm = GaussMarkovProcess::new(model.gm_sigma_dps, model.gm_tau_s, dt, &mut streams.gm);
        let limit = model.range_dps.min(terms.limit_dps);
        let dropout = terms
            .dropouts
            .map(|(rate_per_s, mean_samples)| (rate_per_s / fs, 1.0 - 1.0 / mean_samples));
        // Six processes, τ from 1 s to 1000 s (half-decade steps): a flat floor.
        let flicker: Vec<GaussMarkovProcess> = terms
            .flicker_sigma_dps
            .map(|sigma_dps| {
                crate::bias_instability_components(sigma_dps)
                    .iter()
                    .map(|&(sigma_i, tau_s)| {
                        GaussMarkovProcess::new(sigma_i, tau_s, dt, &mut streams.flicker)
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
        let (rate_low_pass, noise_low_pass) =
            (low_pass(motion.rate_dps(-terms.delay_s)), low_pass(0.0));
        let turn_on_draw: f64 = StandardNormal.sample(&mut streams.turn_on);
        let turn_on = terms.turn_on_sigma_dps * turn_on_draw;
        Self {
            model,
            motion,
            terms,
            streams,
            dt_s: dt,
            white_sigma_dps: white_sigma,
            gm,
            flicker,
            rate_low_pass,
            noise_low_pass,
            limit_dps: limit,
            dropout,
            turn_on_dps: turn_on,
            walk_dps: 0.0,
            dropout_left: false,
        }
    }

    /// The rate the sensing element sees at `gyro_s` (the motion, delayed and low-passed),
    /// with its scale errors at `delta_c` from the start temperature, plus a vibration.
    fn sensed_dps(&mut self, gyro_s: f64, delta_c: f64) -> f64 {
        let terms = &self.terms;
        let (scale_k, asym_k, k3, k2) = (
            terms.scale_k,
            terms.asymmetry_k,
            terms.k3_per_dps2,
            terms.k2_per_dps,
        );
        let mut rate = self.motion.rate_dps(gyro_s - terms.delay_s);
        if let Some(filter) = self.rate_low_pass.as_mut() {
            rate = filter.step(rate);
        }
        let scale = 1.0 + scale_k + asym_k * rate.signum() + terms.scale_per_c * delta_c;
        let mut measured = rate * scale + k3 * rate * rate * rate + k2 * rate * rate;
        if let Some((amplitude_dps, frequency_hz)) = terms.vibration {
            measured += amplitude_dps * (2.0 * std::f64::consts::PI * frequency_hz * gyro_s).sin();
        }
        measured
    }

    /// The sum of the bias terms and the noise at this sample (`delta_c` from the start
    /// temperature): each process steps once.
    fn bias_and_noise_dps(&mut self, delta_c: f64) -> f64 {
        let flicker_dps: f64 = self
            .flicker
            .iter_mut()
            .map(|p| p.step(&mut self.streams.flicker))
            .sum();
        let walk_k = self.terms.walk_dps_per_rt_s;
        if walk_k > 0.0 {
            let w: f64 = StandardNormal.sample(&mut self.streams.walk);
            self.walk_dps += walk_k * self.dt_s.sqrt() * w;
        }
        let white: f64 = StandardNormal.sample(&mut self.streams.white);
        let mut white_dps = self.white_sigma_dps * white;
        if let Some(filter) = self.noise_low_pass.as_mut() {
            white_dps = filter.step(white_dps);
        }
        self.model.bias_dps
            + self.turn_on_dps
            + self.gm.step(&mut self.streams.gm)
            + self.terms.bias_dps_per_c * delta_c
            + flicker_dps
            + self.walk_dps
            + white_dps
    }

    /// `measured` as the sensor outputs it: rounded once to its output step (the
    /// `quantization` effect's when present, which replaces the model's), clipped.
    ///
    /// Once, not to the model's step and then to the effect's: rounding a value already
    /// on a grid of 1/24 °/s to a step of 0.3 °/s makes bins of uneven width (7 or 8 of
    /// the finer steps), and the mean of a gyro at rest then lies up to 0.008 °/s off its
    /// bias with the CRM100's white noise, where a single rounding stays within 0.001 °/s
    /// (`an_output_step_rounds_once`). A sensor whose word is coarse has one grid.
    fn output_dps(&self, measured: f64) -> f64 {
        let lsb = output_step_dps(self.model.lsb_dps, self.terms.extra_lsb_dps);
        let rounded = if lsb > 0.0 {
            (measured / lsb).round() * lsb
        } else {
            measured
        };
        rounded.clamp(-self.limit_dps, self.limit_dps)
    }

    /// True if this sample is dropped (a dropout starts or goes on).
    fn dropped(&mut self) -> bool {
        let mut dropped = false;
        if let Some((start_p, continue_p)) = self.dropout {
            let u: f64 = self.streams.dropout.random();
            self.dropout_left = if self.dropout_left {
                u < continue_p
            } else {
                u < start_p
            };
            dropped = self.dropout_left;
        }
        dropped
    }
}

/// The temperature at each sample: a recorded run's (a NaN entry holds the value before
/// it), or the warm-up curve of the options.
struct SimTemperature<'a> {
    recorded: Option<&'a [f64]>,
    options: &'a SimOptions,
    recorded_start_c: f64,
    recorded_last_c: f64,
}

impl<'a> SimTemperature<'a> {
    fn new(recorded: Option<&'a [f64]>, options: &'a SimOptions) -> Self {
        let recorded_start_c = recorded
            .and_then(|t| t.iter().copied().find(|v| v.is_finite()))
            .unwrap_or(options.temperature_start_c);
        Self {
            recorded,
            options,
            recorded_start_c,
            recorded_last_c: recorded_start_c,
        }
    }

    /// The temperature at sample `k` (taken at `true_s`), and its change from the start (°C).
    fn at(&mut self, k: usize, true_s: f64) -> (f64, f64) {
        let options = self.options;
        match self.recorded {
            Some(recorded) => {
                if let Some(t) = recorded.get(k).copied().filter(|t| t.is_finite()) {
                    self.recorded_last_c = t;
                }
                (
                    self.recorded_last_c,
                    self.recorded_last_c - self.recorded_start_c,
                )
            }
            None => {
                let t = options.temperature_start_c
                    + options.temperature_rise_c
                        * (1.0 - (-true_s / options.temperature_tau_s).exp());
                (t, t - options.temperature_start_c)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A recorded trajectory of 10 s at 100 Hz turning at a steady 50 °/s (its sample rate,
    /// angles and motion), and a noise-free sensor without bias at that rate.
    fn steady_turn() -> (f64, Vec<f64>, Motion, SensorModel) {
        let fs = 100.0;
        let angles: Vec<f64> = (0..1001).map(|k| 50.0 * k as f64 / fs).collect();
        let motion = Motion::from_reference(0.0, 1.0 / fs, &angles, 1);
        let model = SensorModel {
            sample_rate_hz: fs,
            bias_dps: 0.0,
            ..SensorModel::default()
        }
        .noise_free();
        (fs, angles, motion, model)
    }

    /// A recorded trajectory re-simulated with a slow sample clock (either stamping)
    /// ends where the motion ends: no sample reads the held last rate beside the held
    /// last reference angle.
    #[test]
    fn a_slow_clock_stops_at_the_motions_end() {
        let (_, angles, motion, model) = steady_turn();
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

    /// A fast sample clock takes more samples within the motion: stamped by the logger,
    /// the rows of a 10 s motion at 100 Hz with a clock 3% fast are 1 031, their stamps
    /// reach the motion's end and no further, and the last reference still moves.
    #[test]
    fn a_fast_clock_takes_more_samples_within_the_motion() {
        let (fs, _, motion, model) = steady_turn();
        let fast = [Effect::ClockError { ppm: 30_000.0 }];
        assert_eq!(stamp_period_s(&fast, fs), 1.0 / (fs * 1.03));
        assert_eq!(stamp_period_s(&[], fs), 1.0 / fs);
        let log = simulate(&model, &fast, &motion, &SimOptions::default());
        assert_eq!(log.rows.len(), 1031);
        let last = &log.rows[log.rows.len() - 1];
        assert!(
            last.time_s <= 10.0 && last.time_s > 10.0 - 1.0 / fs,
            "{}",
            last.time_s
        );
        let before = &log.rows[log.rows.len() - 2];
        let moved = last.reference_deg.unwrap_or(0.0) - before.reference_deg.unwrap_or(0.0);
        assert!(moved > 0.4, "the reference stops moving ({moved} deg)");
    }

    /// A coarse output step replaces the model's: at rest, with a bias of 0.2 °/s (where
    /// rounding the 1/24 °/s word again to 0.3 °/s puts the mean 0.006 °/s off), the mean
    /// output over 120 s stays within 0.003 °/s of the bias, as one rounding with the
    /// CRM100's white noise does (its dither leaves under 0.001 °/s).
    #[test]
    fn an_output_step_rounds_once() {
        let motion = Motion::from_rotations(Vec::new(), 120.0);
        let model = SensorModel {
            gm_sigma_dps: 0.0,
            bias_dps: 0.2,
            ..SensorModel::default()
        };
        let effects = [Effect::Quantization { lsb_dps: 0.3 }];
        let s = simulate_series(&model, &effects, &motion, &SimOptions::default(), None);
        let mean = s.rate_dps.iter().sum::<f64>() / s.rate_dps.len() as f64;
        assert!((mean - 0.2).abs() < 0.003, "mean {mean}");
        // Every output lies on the 0.3 °/s grid.
        assert!(s
            .rate_dps
            .iter()
            .all(|r| ((r / 0.3) - (r / 0.3).round()).abs() < 1e-9));
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
