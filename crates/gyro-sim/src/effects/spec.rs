//! Descriptors of an effect in the table: its parameters with their valid ranges, the
//! fitting procedure the diagnosis uses for it, and what the core can compensate.

use std::fmt;

/// One parameter of an effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// Name (the JSON key and the `--effect id:name=value` name).
    pub name: &'static str,
    /// Unit, as printed.
    pub unit: &'static str,
    /// Values that are physically meaningful.
    pub range: ParamRange,
}

impl ParamSpec {
    /// A parameter that takes any finite value.
    pub const fn any(name: &'static str, unit: &'static str) -> Self {
        Self {
            name,
            unit,
            range: ParamRange {
                min: Bound::Unbounded,
                max: Bound::Unbounded,
            },
        }
    }

    /// A parameter bounded by `min` and `max`.
    pub const fn within(name: &'static str, unit: &'static str, min: Bound, max: Bound) -> Self {
        Self {
            name,
            unit,
            range: ParamRange { min, max },
        }
    }
}

/// One end of a [`ParamRange`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// No limit on this side.
    Unbounded,
    /// The value itself is allowed.
    Inclusive(f64),
    /// Only values strictly beyond it are allowed.
    Exclusive(f64),
}

/// The valid values of a parameter (always finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamRange {
    /// Lower end.
    pub min: Bound,
    /// Upper end.
    pub max: Bound,
}

impl ParamRange {
    /// True if `value` is within the range.
    pub fn contains(&self, value: f64) -> bool {
        let above = match self.min {
            Bound::Unbounded => true,
            Bound::Inclusive(lo) => value >= lo,
            Bound::Exclusive(lo) => value > lo,
        };
        let below = match self.max {
            Bound::Unbounded => true,
            Bound::Inclusive(hi) => value <= hi,
            Bound::Exclusive(hi) => value < hi,
        };
        above && below
    }

    /// `value` moved into the closed part of the range (an open end is left as it is).
    pub fn clamp(&self, value: f64) -> f64 {
        let value = match self.min {
            Bound::Inclusive(lo) => value.max(lo),
            _ => value,
        };
        match self.max {
            Bound::Inclusive(hi) => value.min(hi),
            _ => value,
        }
    }
}

/// Reads as the condition a value must meet: `> 0`, `in [0, 1]`, `finite`.
impl fmt::Display for ParamRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use Bound::{Exclusive as Ex, Inclusive as In, Unbounded as Un};
        match (self.min, self.max) {
            (Un, Un) => write!(f, "finite"),
            (In(lo), Un) => write!(f, ">= {lo}"),
            (Ex(lo), Un) => write!(f, "> {lo}"),
            (Un, In(hi)) => write!(f, "<= {hi}"),
            (Un, Ex(hi)) => write!(f, "< {hi}"),
            (lo, hi) => {
                let (open, lo) = match lo {
                    In(v) => ('[', v),
                    Ex(v) => ('(', v),
                    Un => ('(', f64::NEG_INFINITY),
                };
                let (close, hi) = match hi {
                    In(v) => (']', v),
                    Ex(v) => (')', v),
                    Un => (')', f64::INFINITY),
                };
                write!(f, "in {open}{lo}, {hi}{close}")
            }
        }
    }
}

/// The regressor of the residual regression an effect's parameter is read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Regressor {
    /// Reference rate.
    Rate,
    /// |reference rate|.
    AbsRate,
    /// (rate / 100 deg/s)³.
    RateCubed,
    /// (rate / 100 deg/s)².
    RateSquared,
    /// Angular acceleration.
    Acceleration,
    /// Time from the middle of the run × angular acceleration.
    TimeAcceleration,
    /// Temperature change from the start of the run.
    DeltaT,
    /// Rate × temperature change.
    RateDeltaT,
}

/// How a regression coefficient maps to the effect's (single) parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reading {
    /// The coefficient is the parameter (two-sided test).
    Coefficient,
    /// The coefficient of (rate / scale)³: the parameter is it over scale³ (two-sided).
    CubicCoefficient,
    /// The coefficient of (rate / scale)²: the parameter is it over scale² (two-sided).
    SquareCoefficient,
    /// Minus the coefficient is a delay (s), the parameter (two-sided: either sign).
    Delay,
    /// Minus the coefficient is a clock error (×10⁶: ppm), the parameter (two-sided).
    ClockPpm,
    /// Minus the coefficient is the low-frequency delay of a two-pole low-pass whose
    /// cutoff (Hz) is the parameter (one-sided test).
    LowPassDelay,
}

/// The fitting procedure the diagnosis uses for an effect (shared between effects).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitProcedure {
    /// The excess of a residual-regression coefficient over the null replicas, calibrated
    /// by noise-free simulation; refitted jointly with the other effects of a set.
    Regression {
        /// What the residual is regressed on.
        regressor: Regressor,
        /// How the coefficient maps to the parameter.
        reading: Reading,
        /// Needs a temperature column that varies in every training run.
        needs_temperature: bool,
        /// The test, as reported.
        test: &'static str,
    },
    /// The time stamps' period against the nominal sample rate.
    StampedClock,
    /// The between-run variance of the bias against the null replicas (chi-square);
    /// significant when it replicates on the held-out runs.
    BetweenRunSpread,
    /// The Allan variance of the residual at long τ against the null replicas.
    Wander(WanderShape),
    /// Samples on a plateau at the largest |rate| (seen directly in the data).
    Plateau,
    /// The output grid step (seen directly in the data).
    OutputGrid,
    /// Gaps in the time stamps (seen directly in the data).
    Gaps,
    /// A narrow line in the residual's spectrum against the null replicas (its
    /// frequency and amplitude), replicated on the held-out runs.
    SpectralLine,
}

/// The Allan-variance shape of a bias wander per unit of its parameter squared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WanderShape {
    /// Flat floor: six Gauss-Markov processes with τ from 1 s to 1000 s.
    Flicker,
    /// Random walk: τ/3.
    RandomWalk,
}

/// What the core pipeline (or the model file) can do to compensate an effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoreCorrection {
    /// No correction in the core.
    None,
    /// `correction.scale_k` += parameter × `per_unit`.
    ScaleK {
        /// Scale change per unit of the parameter.
        per_unit: f64,
    },
    /// `correction.asymmetry_k` += parameter.
    AsymmetryK,
    /// `correction.bias_dps_per_c` += parameter.
    BiasPerC,
    /// `correction.scale_per_c` += parameter.
    ScalePerC,
    /// The model file's `reference_delay_s` += parameter (s).
    ReferenceDelay,
    /// A sample clock in a log stamped by the sensor's count: `correction.scale_k` +=
    /// parameter × 1e-6 (integrated over nominal periods a movement's angle is 1 + ε times
    /// the true one) and the model file's `count_clock_ppm` += parameter (scoring reads the
    /// reference at the gyro's own time).
    CountClock,
    /// `reference_delay_s` += the low-frequency delay of a two-pole low-pass of this
    /// cutoff (Hz).
    LowPassReferenceDelay,
    /// Kalman compensation (the bias estimated at every rest).
    KalmanBias,
}
