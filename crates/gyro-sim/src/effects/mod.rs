//! The unmodelled effects: one table shared by the simulator and the diagnosis.
//!
//! Each effect is a term the simulator can add to the nominal sensor model, with named
//! parameters in stated units and ranges, the procedure the diagnosis fits it with and
//! what the core can compensate. Adding an effect is one variant in the `effect_enum!`
//! invocation (its JSON shape) and one entry of [`EFFECTS`] (everything else). Ids are
//! the fixed vocabulary; JSON is `{"id": "scale_factor", "params": {"k": 0.01}}`.

mod error;
mod spec;
mod term;

pub use error::EffectError;
pub use spec::{
    Bound, CoreCorrection, FitProcedure, ParamRange, ParamSpec, Reading, Regressor, WanderShape,
};
pub(crate) use term::SimTerms;

use crate::sensor::SensorModel;
use serde::{Deserialize, Serialize};
use Bound::{Exclusive, Inclusive, Unbounded};

/// Defines [`Effect`] (its variants and their `f64` fields, the JSON shape) and the
/// accessors that map it to the table's parameter order: one line per effect. The table
/// [`EFFECTS`] lists the effects in the same order (checked by a test).
macro_rules! effect_enum {
    ($(
        $(#[$variant_doc:meta])*
        $variant:ident { $( $(#[$field_doc:meta])* $field:ident ),+ $(,)? }
    ),+ $(,)?) => {
        /// An effect with its parameters.
        #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(
            tag = "id",
            content = "params",
            rename_all = "snake_case",
            deny_unknown_fields
        )]
        pub enum Effect {
            $( $(#[$variant_doc])* $variant { $( $(#[$field_doc])* $field: f64 ),+ }, )+
        }

        /// The effect kinds in table order (their discriminants index [`EFFECTS`]).
        #[derive(Clone, Copy)]
        enum Kind {
            $( $variant, )+
        }

        impl Effect {
            /// Index of this effect's kind in [`EFFECTS`].
            fn index(&self) -> usize {
                match self {
                    $( Effect::$variant { .. } => Kind::$variant as usize, )+
                }
            }

            /// Parameter values in the order of [`EffectInfo::params`].
            pub fn params(&self) -> Vec<f64> {
                match *self {
                    $( Effect::$variant { $( $field ),+ } => vec![$( $field ),+], )+
                }
            }

            /// The effect of table entry `index` with `values` (table order); `None` if
            /// the index or the count is wrong.
            fn from_values(index: usize, values: &[f64]) -> Option<Effect> {
                $(
                    if index == Kind::$variant as usize {
                        let mut next = values.iter().copied();
                        let effect = Effect::$variant { $( $field: next.next()? ),+ };
                        return next.next().is_none().then_some(effect);
                    }
                )+
                None
            }

            /// Field names of each kind, in table order (for the consistency test).
            #[cfg(test)]
            fn field_names() -> Vec<Vec<&'static str>> {
                vec![$( vec![$( stringify!($field) ),+], )+]
            }
        }
    };
}

effect_enum! {
    /// Scale error: rate × (1 + k).
    ScaleFactor {
        /// Relative scale error (1 = 100%).
        k,
    },
    /// Scale differs by sign: rate × (1 + k·sign(rate)).
    ScaleAsymmetry {
        /// Half the difference between the positive and negative scales.
        k,
    },
    /// Cubic (odd) nonlinearity: rate + k3·rate³.
    Nonlinearity {
        /// Cubic coefficient (1/(deg/s)²).
        k3_per_dps2,
    },
    /// Quadratic (even) nonlinearity: rate + k2·rate², the same sign in both directions.
    NonlinearityEven {
        /// Quadratic coefficient (1/(deg/s)).
        k2_per_dps,
    },
    /// Output clipped at ±limit.
    Saturation {
        /// Clip level (deg/s).
        limit_dps,
    },
    /// Output rounded to a step.
    Quantization {
        /// Step (deg/s).
        lsb_dps,
    },
    /// The gyro lags the true motion (and the reference) by `delay_s`; a negative delay
    /// is a gyro ahead of the reference (a reference that lags).
    Latency {
        /// Delay (s).
        delay_s,
    },
    /// The sensor's sample clock runs fast by `ppm`: sample k is taken at k/(fs(1+ε)), and
    /// the log stamps it with that time (a logger's accurate clock) while `sample_rate_hz`
    /// stays the nominal fs the firmware integrates with. The rate is right at its stamp;
    /// integrated over nominal periods, the angle gains ε × the angle turned.
    ClockError {
        /// Clock error (parts per million).
        ppm,
    },
    /// The sensor's sample clock runs fast by `ppm` and the rows are stamped by the
    /// sensor's own sample count (k / fs): sample k is taken at k/(fs(1+ε)) but logged at
    /// k/fs beside a reference sampled at k/fs. The gyro's time base stretches against the
    /// reference: it lags by ε·t, a lag growing linearly over the run.
    ClockErrorCountStamped {
        /// Clock error (parts per million).
        ppm,
    },
    /// Lost samples: rows missing from the log.
    Dropouts {
        /// Dropout events per second.
        rate_per_s,
        /// Mean number of consecutive samples lost per event.
        mean_samples,
    },
    /// Bias proportional to the temperature change from the start.
    TemperatureBias {
        /// Bias change per °C (deg/s/°C).
        dps_per_c,
    },
    /// Scale proportional to the temperature change: rate × (1 + s·ΔT).
    TemperatureScale {
        /// Relative scale change per °C (1/°C).
        per_c,
    },
    /// Flicker-like bias wander (sum of Gauss-Markov processes with τ from 1 to 1000 s),
    /// giving a flat Allan deviation floor at long τ.
    BiasInstability {
        /// Standard deviation of the wander (deg/s).
        sigma_dps,
    },
    /// Bias random walk: Allan slope +½ at long τ.
    RateRandomWalk {
        /// Random walk coefficient (deg/s/√s).
        k_dps_per_rt_s,
    },
    /// A constant bias drawn anew for every run (power cycle).
    TurnOnBias {
        /// Standard deviation across runs (deg/s).
        sigma_dps,
    },
    /// The sensor's own low-pass (2nd-order, critically damped) on the true rate.
    Bandwidth {
        /// -3 dB bandwidth (Hz).
        cutoff_hz,
    },
    /// A vibration the reference does not see (a stepper motor, a fan): a sinusoid of
    /// `amplitude_dps` at `frequency_hz` added to the gyro's rate.
    Vibration {
        /// Peak amplitude (deg/s).
        amplitude_dps,
        /// Frequency (Hz).
        frequency_hz,
    },
}

/// A two-pole (critically damped) low-pass of cutoff f_c has its poles at this multiple
/// of f_c, `1/√(√2 − 1)`; it delays slow motion by 2/(2π · ratio · f_c).
pub const LOW_PASS_POLE_RATIO: f64 = 1.553_773_974_030_037_1;

/// The delay (s) by which the `bandwidth` low-pass of `cutoff_hz` holds back slow
/// motion: 2/(2π · [`LOW_PASS_POLE_RATIO`] · f_c), its two stages' time constants.
pub fn low_pass_delay_s(cutoff_hz: f64) -> f64 {
    1.0 / (std::f64::consts::PI * LOW_PASS_POLE_RATIO * cutoff_hz)
}

/// The cutoff (Hz) of the `bandwidth` low-pass that holds back slow motion by `delay_s`:
/// the inverse of [`low_pass_delay_s`].
pub fn low_pass_cutoff_hz(delay_s: f64) -> f64 {
    low_pass_delay_s(1.0) / delay_s
}

/// The `bias_instability` effect of standard deviation `sigma_dps` as the sum of its six
/// first-order Gauss-Markov processes: `(σ_i, τ_i)` with τ_i = 10^(0.6 i) s, i = 0..5
/// (1 s to 1000 s), each σ_i = σ/√6, so that the variances add up to σ².
pub fn bias_instability_components(sigma_dps: f64) -> [(f64, f64); 6] {
    let each = sigma_dps / 6f64.sqrt();
    core::array::from_fn(|i| (each, 10f64.powf(0.6 * i as f64)))
}

/// Static description of an effect kind: everything the simulator, the diagnosis, the
/// self-test and the command line know about it.
#[derive(Clone, Copy, Debug)]
pub struct EffectInfo {
    /// The id (JSON and CLI).
    pub id: &'static str,
    /// Parameters with their units and valid ranges.
    pub params: &'static [ParamSpec],
    /// What the effect does and the signature it leaves in data.
    pub signature: &'static str,
    /// A realistic magnitude for a low-cost MEMS gyro (used by tests and the self-check).
    pub typical: Effect,
    /// The magnitude the diagnosis self-test injects.
    pub self_test: Effect,
    /// The magnitudes the self-check's matrix injects (`diagnose --self-test --matrix`),
    /// smallest first: from near what a bench run can show to the top of the realistic
    /// range for a low-cost MEMS or CRM100-class gyro.
    pub range: &'static [Effect],
    /// Where that range comes from (datasheet figures, the bench's motion).
    pub range_source: &'static str,
    /// How the diagnosis fits it.
    pub fit: FitProcedure,
    /// What the core can compensate of it.
    pub correction: CoreCorrection,
    /// Adds the effect's term (parameters in table order) to the simulator's terms.
    pub(crate) term: fn(&[f64], &mut SimTerms),
    /// True if these parameters change no simulated sample of a sensor with this model
    /// (a zero-size wander, the nominal grid again, a clip above the range).
    pub(crate) neutral: fn(&[f64], &SensorModel) -> bool,
}

/// A parameter that must be >= 0.
const fn non_negative(name: &'static str, unit: &'static str) -> ParamSpec {
    ParamSpec::within(name, unit, Inclusive(0.0), Unbounded)
}

/// A parameter that must be > 0.
const fn positive(name: &'static str, unit: &'static str) -> ParamSpec {
    ParamSpec::within(name, unit, Exclusive(0.0), Unbounded)
}

/// A regression-fitted effect read directly from its coefficient.
const fn regression(regressor: Regressor, test: &'static str) -> FitProcedure {
    FitProcedure::Regression {
        regressor,
        reading: Reading::Coefficient,
        needs_temperature: false,
        test,
    }
}

/// All effects, in the order of the vocabulary.
pub const EFFECTS: &[EffectInfo] = &[
    EffectInfo {
        id: "scale_factor",
        params: &[ParamSpec::any("k", "1")],
        signature: "only in motion, residual proportional to rate",
        typical: Effect::ScaleFactor { k: 0.01 },
        self_test: Effect::ScaleFactor { k: 0.01 },
        range: &[
            Effect::ScaleFactor { k: 0.002 },
            Effect::ScaleFactor { k: -0.01 },
            Effect::ScaleFactor { k: 0.03 },
        ],
        range_source: "sensitivity tolerance: ±3% (MPU-6050, BMI160 datasheets), ±1% class (CRM100, ADXRS450)",
        fit: regression(Regressor::Rate, "straight-line slope on rate in the 2 Hz low band vs null replicas"),
        correction: CoreCorrection::ScaleK { per_unit: 1.0 },
        term: |p, t| t.scale_k += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "scale_asymmetry",
        params: &[ParamSpec::any("k", "1")],
        signature: "scale error that differs by the sign of the rate",
        typical: Effect::ScaleAsymmetry { k: 0.005 },
        self_test: Effect::ScaleAsymmetry { k: 0.005 },
        range: &[
            Effect::ScaleAsymmetry { k: 0.002 },
            Effect::ScaleAsymmetry { k: -0.006 },
            Effect::ScaleAsymmetry { k: 0.02 },
        ],
        range_source: "a share of the sensitivity tolerance that differs by direction; up to 2%",
        fit: regression(Regressor::AbsRate, "regression slope on |rate| vs null replicas"),
        correction: CoreCorrection::AsymmetryK,
        term: |p, t| t.asymmetry_k += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "nonlinearity",
        params: &[ParamSpec::any("k3_per_dps2", "1/(deg/s)^2")],
        signature: "residual curved (cubic) in the rate",
        typical: Effect::Nonlinearity { k3_per_dps2: 2e-7 },
        self_test: Effect::Nonlinearity { k3_per_dps2: 2e-7 },
        range: &[
            Effect::Nonlinearity { k3_per_dps2: 5e-8 },
            Effect::Nonlinearity { k3_per_dps2: 2e-7 },
            Effect::Nonlinearity { k3_per_dps2: 8e-7 },
        ],
        range_source: "nonlinearity 0.1–0.5% of full scale (MPU-6050 0.2%, ADXRS450 0.05%): 0.05–0.8% of the rate at 100 °/s",
        fit: FitProcedure::Regression {
            regressor: Regressor::RateCubed,
            reading: Reading::CubicCoefficient,
            needs_temperature: false,
            test: "regression on rate^3 vs null replicas",
        },
        correction: CoreCorrection::None,
        term: |p, t| t.k3_per_dps2 += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "nonlinearity_even",
        params: &[ParamSpec::any("k2_per_dps", "1/(deg/s)")],
        signature: "residual curved (quadratic, the same sign both ways) in the rate",
        typical: Effect::NonlinearityEven { k2_per_dps: 2e-5 },
        self_test: Effect::NonlinearityEven { k2_per_dps: 2e-5 },
        range: &[
            Effect::NonlinearityEven { k2_per_dps: 5e-6 },
            Effect::NonlinearityEven { k2_per_dps: 2e-5 },
            Effect::NonlinearityEven { k2_per_dps: 8e-5 },
        ],
        range_source: "the same nonlinearity budget with an even shape: 0.05–0.8% of the rate at 100 °/s",
        fit: FitProcedure::Regression {
            regressor: Regressor::RateSquared,
            reading: Reading::SquareCoefficient,
            needs_temperature: false,
            test: "regression on rate^2 vs null replicas",
        },
        correction: CoreCorrection::None,
        term: |p, t| t.k2_per_dps += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "saturation",
        params: &[positive("limit_dps", "deg/s")],
        signature: "raw values clipped at a level",
        typical: Effect::Saturation { limit_dps: 120.0 },
        self_test: Effect::Saturation { limit_dps: 120.0 },
        range: &[
            Effect::Saturation { limit_dps: 150.0 },
            Effect::Saturation { limit_dps: 120.0 },
            Effect::Saturation { limit_dps: 80.0 },
        ],
        range_source: "a range set below the bench's peak rates (about 150–200 °/s): ±75 to ±150 °/s settings",
        fit: FitProcedure::Plateau,
        correction: CoreCorrection::None,
        term: |p, t| t.limit_dps = t.limit_dps.min(p[0]),
        neutral: |p, model| p[0] >= model.range_dps,
    },
    EffectInfo {
        id: "quantization",
        params: &[non_negative("lsb_dps", "deg/s")],
        signature: "raw values on a grid (rounding each rate sample adds white rate noise of lsb^2/12: a higher -1/2 Allan slope, not -1)",
        typical: Effect::Quantization { lsb_dps: 0.2 },
        self_test: Effect::Quantization { lsb_dps: 0.2 },
        range: &[
            Effect::Quantization { lsb_dps: 0.1 },
            Effect::Quantization { lsb_dps: 0.2 },
            Effect::Quantization { lsb_dps: 0.3 },
        ],
        range_source: "output steps of coarse ranges and 12-bit paths: 0.1–0.3 °/s",
        fit: FitProcedure::OutputGrid,
        correction: CoreCorrection::None,
        term: |p, t| t.extra_lsb_dps = p[0],
        neutral: |p, model| p[0] == 0.0 || (p[0] - model.lsb_dps).abs() <= 1e-3 * model.lsb_dps,
    },
    EffectInfo {
        id: "latency",
        params: &[ParamSpec::within("delay_s", "s", Inclusive(-1.0), Inclusive(1.0))],
        signature: "residual proportional to angular acceleration; cross-correlation peak off zero (either side)",
        typical: Effect::Latency { delay_s: 0.005 },
        self_test: Effect::Latency { delay_s: 0.005 },
        range: &[
            Effect::Latency { delay_s: 0.002 },
            Effect::Latency { delay_s: -0.01 },
            Effect::Latency { delay_s: 0.05 },
        ],
        range_source: "logger and bus delays of 1–50 ms, either side of the reference",
        fit: FitProcedure::Regression {
            regressor: Regressor::Acceleration,
            reading: Reading::Delay,
            needs_temperature: false,
            test: "regression on angular acceleration vs null replicas",
        },
        correction: CoreCorrection::ReferenceDelay,
        term: |p, t| t.delay_s += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "clock_error",
        params: &[ParamSpec::within("ppm", "ppm", Exclusive(-1e5), Exclusive(1e5))],
        signature: "time stamps drift from the nominal rate; angle error proportional to total angle; rate residual clean at the stamps",
        typical: Effect::ClockError { ppm: 5000.0 },
        self_test: Effect::ClockError { ppm: 5000.0 },
        range: &[
            Effect::ClockError { ppm: 500.0 },
            Effect::ClockError { ppm: -5000.0 },
            Effect::ClockError { ppm: 30_000.0 },
        ],
        range_source: "internal RC oscillators: ±1–3% (MPU-6050/6500, BMI160 datasheets); crystals 0.005–0.05%",
        fit: FitProcedure::StampedClock,
        // Integrated over nominal periods, a clock fast by ε gives 1 + ε times the angle,
        // exactly like a scale factor.
        correction: CoreCorrection::ScaleK { per_unit: 1e-6 },
        term: |p, t| t.clock_ppm += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "clock_error_count_stamped",
        params: &[ParamSpec::within("ppm", "ppm", Exclusive(-1e5), Exclusive(1e5))],
        signature: "rows stamped by the sensor's sample count: stamps on the nominal grid, the lag behind the reference growing linearly over the run (residual proportional to time x angular acceleration)",
        typical: Effect::ClockErrorCountStamped { ppm: 500.0 },
        self_test: Effect::ClockErrorCountStamped { ppm: 500.0 },
        range: &[
            Effect::ClockErrorCountStamped { ppm: 500.0 },
            Effect::ClockErrorCountStamped { ppm: -5000.0 },
            Effect::ClockErrorCountStamped { ppm: 30_000.0 },
        ],
        range_source: "internal RC oscillators: ±1–3% (MPU-6050/6500, BMI160 datasheets); crystals 0.005–0.05%",
        fit: FitProcedure::Regression {
            regressor: Regressor::TimeAcceleration,
            reading: Reading::ClockPpm,
            needs_temperature: false,
            test: "regression on time x angular acceleration vs null replicas",
        },
        // Integrated over nominal periods, the angle of a movement is 1 + ε times the
        // true one, as with the logger-stamped clock; and its lag grows through the run.
        correction: CoreCorrection::CountClock,
        term: |p, t| t.count_clock_ppm += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "dropouts",
        params: &[
            non_negative("rate_per_s", "1/s"),
            ParamSpec::within("mean_samples", "samples", Inclusive(1.0), Unbounded),
        ],
        signature: "missing samples; angle lost during motion",
        typical: Effect::Dropouts {
            rate_per_s: 0.5,
            mean_samples: 5.0,
        },
        self_test: Effect::Dropouts {
            rate_per_s: 0.5,
            mean_samples: 5.0,
        },
        range: &[
            Effect::Dropouts {
                rate_per_s: 0.1,
                mean_samples: 2.0,
            },
            Effect::Dropouts {
                rate_per_s: 0.5,
                mean_samples: 5.0,
            },
            Effect::Dropouts {
                rate_per_s: 2.0,
                mean_samples: 10.0,
            },
        ],
        range_source: "a busy USB or serial link: 0.1–2 losses per second of 2–10 samples",
        fit: FitProcedure::Gaps,
        correction: CoreCorrection::None,
        term: |p, t| t.dropouts = Some((p[0], p[1])),
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "temperature_bias",
        params: &[ParamSpec::any("dps_per_c", "deg/s/degC")],
        signature: "static bias tracks temperature",
        typical: Effect::TemperatureBias { dps_per_c: 0.05 },
        self_test: Effect::TemperatureBias { dps_per_c: 0.05 },
        range: &[
            Effect::TemperatureBias { dps_per_c: 0.02 },
            Effect::TemperatureBias { dps_per_c: -0.05 },
            Effect::TemperatureBias { dps_per_c: 0.15 },
        ],
        range_source: "bias temperature coefficients 0.01–0.2 °/s/°C (CRM100 class to MPU-6050's ±20 °/s over −40…85 °C)",
        fit: FitProcedure::Regression {
            regressor: Regressor::DeltaT,
            reading: Reading::Coefficient,
            needs_temperature: true,
            test: "regression on temperature change vs null replicas",
        },
        correction: CoreCorrection::BiasPerC,
        term: |p, t| t.bias_dps_per_c += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "temperature_scale",
        params: &[ParamSpec::any("per_c", "1/degC")],
        signature: "scale error tracks temperature",
        typical: Effect::TemperatureScale { per_c: 1e-3 },
        self_test: Effect::TemperatureScale { per_c: 2e-3 },
        range: &[
            Effect::TemperatureScale { per_c: 5e-4 },
            Effect::TemperatureScale { per_c: -2e-3 },
            Effect::TemperatureScale { per_c: 5e-3 },
        ],
        range_source: "sensitivity temperature drift 0.05–0.5% per °C (MPU-6050 ±2% over −40…85 °C; BMI160)",
        fit: FitProcedure::Regression {
            regressor: Regressor::RateDeltaT,
            reading: Reading::Coefficient,
            needs_temperature: true,
            test: "regression on rate x temperature change vs null replicas",
        },
        correction: CoreCorrection::ScalePerC,
        term: |p, t| t.scale_per_c += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "bias_instability",
        params: &[non_negative("sigma_dps", "deg/s")],
        signature: "Allan deviation flat (slope 0) at long tau",
        typical: Effect::BiasInstability { sigma_dps: 0.05 },
        self_test: Effect::BiasInstability { sigma_dps: 0.05 },
        range: &[
            Effect::BiasInstability { sigma_dps: 0.003 },
            Effect::BiasInstability { sigma_dps: 0.0125 },
            Effect::BiasInstability { sigma_dps: 0.05 },
        ],
        range_source: "bias instability 5–200 °/h (CRM100 class 10–50 °/h; consumer MEMS 20–200 °/h): a wander of σ 11, 45 and 180 °/h",
        fit: FitProcedure::Wander(WanderShape::Flicker),
        correction: CoreCorrection::None,
        term: |p, t| t.flicker_sigma_dps = Some(p[0]),
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "rate_random_walk",
        params: &[non_negative("k_dps_per_rt_s", "deg/s/sqrt(s)")],
        signature: "Allan slope +1/2 at long tau",
        typical: Effect::RateRandomWalk {
            k_dps_per_rt_s: 0.005,
        },
        self_test: Effect::RateRandomWalk {
            k_dps_per_rt_s: 0.02,
        },
        range: &[
            Effect::RateRandomWalk {
                k_dps_per_rt_s: 0.005,
            },
            Effect::RateRandomWalk {
                k_dps_per_rt_s: 0.02,
            },
            Effect::RateRandomWalk {
                k_dps_per_rt_s: 0.05,
            },
        ],
        range_source: "rate random walk of low-cost MEMS, 0.005–0.05 °/s/√s",
        fit: FitProcedure::Wander(WanderShape::RandomWalk),
        correction: CoreCorrection::None,
        term: |p, t| t.walk_dps_per_rt_s += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "turn_on_bias",
        params: &[non_negative("sigma_dps", "deg/s")],
        signature: "between-run spread of static means much larger than within-run",
        typical: Effect::TurnOnBias { sigma_dps: 0.5 },
        self_test: Effect::TurnOnBias { sigma_dps: 0.5 },
        range: &[
            Effect::TurnOnBias { sigma_dps: 0.1 },
            Effect::TurnOnBias { sigma_dps: 0.3 },
            Effect::TurnOnBias { sigma_dps: 1.0 },
        ],
        range_source: "run-to-run bias repeatability 0.1–1 °/s (CRM100 class to consumer MEMS)",
        fit: FitProcedure::BetweenRunSpread,
        correction: CoreCorrection::KalmanBias,
        term: |p, t| t.turn_on_sigma_dps += p[0],
        neutral: |p, _| p[0] == 0.0,
    },
    EffectInfo {
        id: "bandwidth",
        params: &[positive("cutoff_hz", "Hz")],
        signature: "high-band PSD attenuated, lag",
        typical: Effect::Bandwidth { cutoff_hz: 15.0 },
        self_test: Effect::Bandwidth { cutoff_hz: 15.0 },
        range: &[
            Effect::Bandwidth { cutoff_hz: 80.0 },
            Effect::Bandwidth { cutoff_hz: 30.0 },
            Effect::Bandwidth { cutoff_hz: 10.0 },
        ],
        range_source: "selectable digital low-pass settings 10–100 Hz (MPU-6050 DLPF, BMI160 ODR filter; CRM100 77 Hz)",
        fit: FitProcedure::Regression {
            regressor: Regressor::Acceleration,
            reading: Reading::LowPassDelay,
            needs_temperature: false,
            test: "delay from the acceleration regression vs null replicas (one-sided)",
        },
        correction: CoreCorrection::LowPassReferenceDelay,
        term: |p, t| t.bandwidth_hz = Some(p[0]),
        // The fit's stand-in for "no limit".
        neutral: |p, model| p[0] >= 0.5 * model.sample_rate_hz,
    },
    EffectInfo {
        id: "vibration",
        params: &[
            non_negative("amplitude_dps", "deg/s"),
            positive("frequency_hz", "Hz"),
        ],
        signature: "a narrow line in the part of the gyro's spectrum not coherent with the reference rate, which the nominal sensor does not have",
        typical: Effect::Vibration {
            amplitude_dps: 0.5,
            frequency_hz: 13.0,
        },
        self_test: Effect::Vibration {
            amplitude_dps: 0.2,
            frequency_hz: 37.0,
        },
        range: &[
            Effect::Vibration {
                amplitude_dps: 0.05,
                frequency_hz: 37.0,
            },
            Effect::Vibration {
                amplitude_dps: 0.2,
                frequency_hz: 13.0,
            },
            Effect::Vibration {
                amplitude_dps: 1.0,
                frequency_hz: 150.0,
            },
        ],
        range_source: "a motor or tool on the bench: 0.05–1 °/s lines between 10 and 150 Hz",
        fit: FitProcedure::SpectralLine,
        correction: CoreCorrection::None,
        term: |p, t| t.vibration = Some((p[0], p[1])),
        neutral: |p, _| p[0] == 0.0,
    },
];

/// The table entry of `id`.
pub fn effect_info(id: &str) -> Option<&'static EffectInfo> {
    EFFECTS.iter().find(|e| e.id == id)
}

impl Effect {
    /// The effect's id.
    pub fn id(&self) -> &'static str {
        self.info().id
    }

    /// The table entry of this effect's kind.
    pub fn info(&self) -> &'static EffectInfo {
        &EFFECTS[self.index()]
    }

    /// The same kind of effect with other parameter values (order of [`Self::params`]);
    /// `None` if the count is wrong.
    pub fn with_params(&self, values: &[f64]) -> Option<Effect> {
        Self::from_values(self.index(), values)
    }

    /// True if adding this effect to a sensor with `model` changes no simulated sample
    /// (its ensemble is the nominal one, seed for seed).
    pub fn is_neutral(&self, model: &SensorModel) -> bool {
        (self.info().neutral)(&self.params(), model)
    }

    /// The effect as [`Self::parse`] reads it: `id:name=value,name=value`.
    pub fn spec(&self) -> String {
        let pairs: Vec<String> = self
            .info()
            .params
            .iter()
            .zip(self.params())
            .map(|(p, v)| format!("{}={v}", p.name))
            .collect();
        format!("{}:{}", self.id(), pairs.join(","))
    }

    /// Parse `id` or `id:name=value,name=value` (missing parameters take the typical value).
    pub fn parse(spec: &str) -> Result<Effect, EffectError> {
        let (id, rest) = spec.split_once(':').unwrap_or((spec, ""));
        let info = effect_info(id.trim()).ok_or_else(|| EffectError::UnknownEffect {
            id: id.to_string(),
            known: EFFECTS.iter().map(|e| e.id).collect(),
        })?;
        let mut values = info.typical.params();
        for pair in rest.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (name, value) =
                pair.split_once('=')
                    .ok_or_else(|| EffectError::ExpectedNameValue {
                        id: id.to_string(),
                        pair: pair.to_string(),
                    })?;
            let index = info
                .params
                .iter()
                .position(|p| p.name == name.trim())
                .ok_or_else(|| EffectError::UnknownParam {
                    id: id.to_string(),
                    name: name.to_string(),
                    names: info.params.iter().map(|p| p.name).collect(),
                })?;
            values[index] = value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| EffectError::NotANumber {
                    id: id.to_string(),
                    value: value.to_string(),
                })?;
        }
        let effect = info
            .typical
            .with_params(&values)
            .ok_or(EffectError::ParamCount { id: info.id })?;
        effect.validate()?;
        Ok(effect)
    }

    /// Check the parameters are finite and within their ranges.
    pub fn validate(&self) -> Result<(), EffectError> {
        let info = self.info();
        let values = self.params();
        if values.iter().any(|v| !v.is_finite()) {
            return Err(EffectError::NotFinite { id: info.id });
        }
        match info
            .params
            .iter()
            .zip(values)
            .find(|(spec, v)| !spec.range.contains(*v))
        {
            Some((spec, _)) => Err(EffectError::OutOfRange {
                id: info.id,
                param: spec.name,
                range: spec.range,
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_complete_and_consistent() {
        let ids = [
            "scale_factor",
            "scale_asymmetry",
            "nonlinearity",
            "nonlinearity_even",
            "saturation",
            "quantization",
            "latency",
            "clock_error",
            "clock_error_count_stamped",
            "dropouts",
            "temperature_bias",
            "temperature_scale",
            "bias_instability",
            "rate_random_walk",
            "turn_on_bias",
            "bandwidth",
            "vibration",
        ];
        assert_eq!(EFFECTS.len(), ids.len());
        for (info, id) in EFFECTS.iter().zip(ids) {
            assert_eq!(info.id, id);
            assert_eq!(info.typical.id(), id);
            assert_eq!(info.typical.params().len(), info.params.len());
            assert!(info.typical.validate().is_ok());
            assert_eq!(info.self_test.id(), id);
            assert!(info.self_test.validate().is_ok());
            // The matrix: three magnitudes or more, each a valid, non-neutral effect.
            assert!(info.range.len() >= 3, "{id}");
            for e in info.range {
                assert_eq!(e.id(), id);
                assert!(e.validate().is_ok(), "{id}");
                assert!(
                    !(info.neutral)(&e.params(), &SensorModel::default()),
                    "{id}"
                );
            }
            assert!(!info.range_source.is_empty());
            assert_eq!(Effect::parse(&info.self_test.spec()), Ok(info.self_test));
            // JSON uses the same id.
            let json = serde_json::to_value(info.typical).unwrap();
            assert_eq!(json["id"], id);
            let back: Effect = serde_json::from_value(json).unwrap();
            assert_eq!(back, info.typical);
        }
    }

    #[test]
    fn table_names_the_enum_fields() {
        for (info, fields) in EFFECTS.iter().zip(Effect::field_names()) {
            let names: Vec<&str> = info.params.iter().map(|p| p.name).collect();
            assert_eq!(names, fields, "{}", info.id);
        }
    }

    #[test]
    fn ranges_read_as_conditions() {
        let check = |spec: &str, text: &str| {
            assert_eq!(Effect::parse(spec).unwrap_err().to_string(), text);
        };
        check(
            "saturation:limit_dps=0",
            "effect `saturation`: limit_dps must be > 0",
        );
        check(
            "latency:delay_s=2",
            "effect `latency`: delay_s must be in [-1, 1]",
        );
        check(
            "dropouts:mean_samples=0.5",
            "effect `dropouts`: mean_samples must be >= 1",
        );
        check(
            "clock_error:ppm=-2e5",
            "effect `clock_error`: ppm must be in (-100000, 100000)",
        );
    }

    #[test]
    fn parse_specs() {
        assert_eq!(
            Effect::parse("scale_factor:k=0.02"),
            Ok(Effect::ScaleFactor { k: 0.02 })
        );
        assert_eq!(
            Effect::parse("latency"),
            Ok(Effect::Latency { delay_s: 0.005 })
        );
        assert_eq!(
            Effect::parse("dropouts:mean_samples=2"),
            Ok(Effect::Dropouts {
                rate_per_s: 0.5,
                mean_samples: 2.0
            })
        );
        assert!(Effect::parse("scale:k=1")
            .unwrap_err()
            .to_string()
            .contains("unknown effect"));
        assert!(Effect::parse("latency:delay=1")
            .unwrap_err()
            .to_string()
            .contains("no parameter `delay`"));
        assert!(Effect::parse("latency:delay_s=x")
            .unwrap_err()
            .to_string()
            .contains("not a finite number"));
        assert!(Effect::parse("saturation:limit_dps=-1").is_err());
    }
}
