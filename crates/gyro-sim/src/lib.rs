//! The sensor simulator: the nominal sensor model ([`SensorModel`]: bias, Gauss-Markov bias,
//! white noise, output step and range), the effect table ([`EFFECTS`], [`Effect`]) that the
//! simulator, the diagnosis and the docs all read, and the true motion ([`Motion`]: bench-like
//! hand rotations, or the motion of a log's reference). `docs/effects.md` defines each term.
//! Same seed, same log.
//!
//! ```
//! use gyro_sim::{simulate, BenchProfile, Effect, Motion, SensorModel, SimOptions};
//! let motion = Motion::bench(&BenchProfile { duration_s: 20.0, ..BenchProfile::default() }, 7);
//! let effects = [Effect::parse("scale_factor:k=0.01")?];
//! let log = simulate(&SensorModel::default(), &effects, &motion, &SimOptions::default());
//! assert!(log.has_reference && log.rows.len() > 19_000);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod effects;
mod low_pass;
mod motion;
mod sensor;

pub use effects::{
    bias_instability_components, effect_info, low_pass_cutoff_hz, low_pass_delay_s, Bound,
    CoreCorrection, Effect, EffectError, EffectInfo, FitProcedure, ParamRange, ParamSpec, Reading,
    Regressor, WanderShape, EFFECTS, LOW_PASS_POLE_RATIO,
};
pub use low_pass::TwoPoleLowPass;
pub use motion::{rounding_noise_dps, AccelerationStep, BenchProfile, Motion, Rotation};
pub use sensor::{
    check_size, output_step_dps, sample_count, simulate, simulate_series, stamp_period_s,
    InvalidSensorModel, SensorModel, SimOptions, SimSeries, TooManySamples, BYTES_PER_SAMPLE,
    MAX_SAMPLES,
};
