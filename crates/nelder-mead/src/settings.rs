//! Validated settings: coefficients, initial steps, tolerances, limits.

use super::Bounds;

/// Why a setting was rejected. Carries the parameter's name and the offending value.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A value that must be finite is NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NonFinite {
        /// Parameter.
        name: &'static str,
        /// Value given.
        value: f64,
    },
    /// A value that must be positive is zero, negative or NaN.
    #[error("{name} must be > 0, got {value}")]
    NotPositive {
        /// Parameter.
        name: &'static str,
        /// Value given.
        value: f64,
    },
    /// A value that must be non-zero is zero.
    #[error("{name} must not be zero")]
    Zero {
        /// Parameter.
        name: &'static str,
    },
    /// A value lies outside its allowed interval.
    #[error("{name} = {value} is outside {allowed}")]
    OutOfRange {
        /// Parameter.
        name: &'static str,
        /// Value given.
        value: f64,
        /// The allowed interval, e.g. `"(0, 1)"`.
        allowed: &'static str,
    },
    /// The expansion coefficient does not exceed the reflection coefficient.
    #[error("expansion ({expansion}) must be greater than reflection ({reflection})")]
    ExpansionNotAboveReflection {
        /// Reflection coefficient given.
        reflection: f64,
        /// Expansion coefficient given.
        expansion: f64,
    },
    /// Lower and upper bound vectors differ in length.
    #[error("bounds: {lower} lower values but {upper} upper values")]
    BoundsLength {
        /// Number of lower bounds.
        lower: usize,
        /// Number of upper bounds.
        upper: usize,
    },
    /// A bound pair is NaN, not strictly ordered, or has an infinite finite-looking width.
    #[error(
        "bounds of x[{index}]: [{lower}, {upper}] is not an interval lower < upper of finite width"
    )]
    BadBounds {
        /// Coordinate.
        index: usize,
        /// Lower bound given.
        lower: f64,
        /// Upper bound given.
        upper: f64,
    },
}

/// Nelder-Mead coefficients, validated as Lagarias et al. (1998) require:
/// `reflection > 0`, `expansion > 1`, `expansion > reflection`, `0 < contraction < 1`,
/// `0 < shrink < 1`.
///
/// Symbols: reflection α (Lagarias ρ), expansion γ (Lagarias χ), contraction ρ (Lagarias γ),
/// shrink σ. With the worst vertex `x_w` and the centroid `c` of the others, the trial points are
/// `c + α(c − x_w)` (reflection), `c + αγ(c − x_w)` (expansion), `c + ρα(c − x_w)` (outside
/// contraction), `c − ρ(c − x_w)` (inside contraction); a shrink moves every vertex `x_i` to
/// `x_best + σ(x_i − x_best)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    reflection: f64,
    expansion: f64,
    contraction: f64,
    shrink: f64,
}

impl Coefficients {
    /// The standard choice α = 1, γ = 2, ρ = 0.5, σ = 0.5.
    pub const STANDARD: Self = Self {
        reflection: 1.0,
        expansion: 2.0,
        contraction: 0.5,
        shrink: 0.5,
    };

    /// Checked coefficients (see the type's documentation for the rules).
    pub fn new(
        reflection: f64,
        expansion: f64,
        contraction: f64,
        shrink: f64,
    ) -> Result<Self, SettingsError> {
        for (name, value) in [
            ("reflection", reflection),
            ("expansion", expansion),
            ("contraction", contraction),
            ("shrink", shrink),
        ] {
            if !value.is_finite() {
                return Err(SettingsError::NonFinite { name, value });
            }
        }
        if reflection <= 0.0 {
            return Err(SettingsError::NotPositive {
                name: "reflection",
                value: reflection,
            });
        }
        if expansion <= 1.0 {
            return Err(SettingsError::OutOfRange {
                name: "expansion",
                value: expansion,
                allowed: "(1, inf)",
            });
        }
        if expansion <= reflection {
            return Err(SettingsError::ExpansionNotAboveReflection {
                reflection,
                expansion,
            });
        }
        for (name, value) in [("contraction", contraction), ("shrink", shrink)] {
            if value <= 0.0 || value >= 1.0 {
                return Err(SettingsError::OutOfRange {
                    name,
                    value,
                    allowed: "(0, 1)",
                });
            }
        }
        Ok(Self {
            reflection,
            expansion,
            contraction,
            shrink,
        })
    }

    /// Gao & Han (2012) dimension-adaptive coefficients for `dimension` = n ≥ 2:
    /// α = 1, γ = 1 + 2/n, ρ = 0.75 − 1/(2n), σ = 1 − 1/n (the standard ones at n = 2).
    ///
    /// For n ≤ 1 the formula gives σ = 0 (a shrink would collapse the simplex onto one point),
    /// so [`Coefficients::STANDARD`] is returned instead. (scipy's `adaptive=True` uses the
    /// formula as is.)
    pub fn adaptive(dimension: usize) -> Self {
        if dimension < 2 {
            return Self::STANDARD;
        }
        // Written exactly as scipy computes them, so both runs see the same numbers.
        let n = dimension as f64;
        Self {
            reflection: 1.0,
            expansion: 1.0 + 2.0 / n,
            contraction: 0.75 - 1.0 / (2.0 * n),
            shrink: 1.0 - 1.0 / n,
        }
    }

    /// Reflection coefficient α.
    pub const fn reflection(&self) -> f64 {
        self.reflection
    }

    /// Expansion coefficient γ.
    pub const fn expansion(&self) -> f64 {
        self.expansion
    }

    /// Contraction coefficient ρ (used for both outside and inside contraction).
    pub const fn contraction(&self) -> f64 {
        self.contraction
    }

    /// Shrink coefficient σ.
    pub const fn shrink(&self) -> f64 {
        self.shrink
    }
}

impl Default for Coefficients {
    fn default() -> Self {
        Self::STANDARD
    }
}

/// Which coefficients a run uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoefficientRule {
    /// The same coefficients whatever the dimension.
    Fixed(Coefficients),
    /// [`Coefficients::adaptive`] for the problem's dimension (Gao & Han 2012).
    Adaptive,
}

impl CoefficientRule {
    /// The coefficients for a problem of `dimension` coordinates.
    pub fn for_dimension(&self, dimension: usize) -> Coefficients {
        match *self {
            Self::Fixed(c) => c,
            Self::Adaptive => Coefficients::adaptive(dimension),
        }
    }
}

impl Default for CoefficientRule {
    fn default() -> Self {
        Self::Fixed(Coefficients::STANDARD)
    }
}

/// How the initial simplex is built around a start point `x0` (vertex 0 is `x0`; vertex
/// `k + 1` is `x0` with coordinate `k` moved). With [`Bounds`], a step that crosses a bound is
/// reflected back into the box. A simplex that comes out degenerate is refused.
#[derive(Clone, Debug, PartialEq)]
pub enum InitialSteps {
    /// Coordinate `k` becomes `(1 + fraction)·x0[k]` if `x0[k] ≠ 0`, else `zero_step`.
    /// [`InitialSteps::SCIPY`] (`fraction` 0.05, `zero_step` 0.00025) is the default, as in
    /// `scipy.optimize.minimize(method='Nelder-Mead')`.
    Relative {
        /// Relative move of a non-zero coordinate.
        fraction: f64,
        /// Value given to a zero coordinate.
        zero_step: f64,
    },
    /// Coordinate `k` becomes `x0[k] + steps[k]` (one non-zero step per coordinate).
    Absolute(Vec<f64>),
}

impl InitialSteps {
    /// scipy's rule: 5 % of non-zero coordinates, 0.00025 for zero ones.
    pub const SCIPY: Self = Self::Relative {
        fraction: 0.05,
        zero_step: 0.00025,
    };

    fn validate(&self) -> Result<(), SettingsError> {
        let check = |name: &'static str, value: f64| {
            if !value.is_finite() {
                Err(SettingsError::NonFinite { name, value })
            } else if value == 0.0 {
                Err(SettingsError::Zero { name })
            } else {
                Ok(())
            }
        };
        match self {
            Self::Relative {
                fraction,
                zero_step,
            } => {
                check("initial step fraction", *fraction)?;
                check("initial zero step", *zero_step)
            }
            Self::Absolute(steps) => steps
                .iter()
                .try_for_each(|&s| check("initial absolute step", s)),
        }
    }
}

impl Default for InitialSteps {
    fn default() -> Self {
        Self::SCIPY
    }
}

/// Nelder-Mead settings; [`NelderMead::minimize`](super::NelderMead::minimize) runs them.
///
/// Defaults (scipy's): standard coefficients, [`InitialSteps::SCIPY`], `x_tolerance` and
/// `f_tolerance` 1e-4, no bounds; the limits follow scipy: if neither is set both are
/// 200·n (n = dimension), if only one is set the other is unlimited.
#[derive(Clone, Debug, PartialEq)]
pub struct NelderMead {
    pub(super) coefficients: CoefficientRule,
    pub(super) initial_steps: InitialSteps,
    pub(super) x_tolerance: f64,
    pub(super) f_tolerance: f64,
    pub(super) max_iterations: Option<usize>,
    pub(super) max_evaluations: Option<usize>,
    pub(super) bounds: Option<Bounds>,
}

impl Default for NelderMead {
    fn default() -> Self {
        Self {
            coefficients: CoefficientRule::default(),
            initial_steps: InitialSteps::SCIPY,
            x_tolerance: 1e-4,
            f_tolerance: 1e-4,
            max_iterations: None,
            max_evaluations: None,
            bounds: None,
        }
    }
}

fn positive_tolerance(name: &'static str, value: f64) -> Result<f64, SettingsError> {
    // `!(value > 0.0)` also rejects NaN. +inf is allowed: it switches that criterion off.
    if value > 0.0 {
        Ok(value)
    } else {
        Err(SettingsError::NotPositive { name, value })
    }
}

impl NelderMead {
    /// Default settings (see the type's documentation).
    pub fn new() -> Self {
        Self::default()
    }

    /// Use fixed coefficients (already validated by [`Coefficients::new`]).
    pub fn with_coefficients(mut self, coefficients: Coefficients) -> Self {
        self.coefficients = CoefficientRule::Fixed(coefficients);
        self
    }

    /// Use Gao & Han's dimension-adaptive coefficients ([`Coefficients::adaptive`]).
    pub fn with_adaptive_coefficients(mut self) -> Self {
        self.coefficients = CoefficientRule::Adaptive;
        self
    }

    /// How the initial simplex is built from a start point. Every step must be finite and
    /// non-zero; the number of absolute steps is checked against the start point when the
    /// run begins.
    pub fn with_initial_steps(mut self, steps: InitialSteps) -> Result<Self, SettingsError> {
        steps.validate()?;
        self.initial_steps = steps;
        Ok(self)
    }

    /// Absolute x tolerance (scipy's `xatol`): converged when every coordinate of every vertex
    /// is within this of the best vertex (measured in the original, bounded coordinates) and
    /// the f criterion holds too. Must be > 0; `f64::INFINITY` switches the criterion off.
    pub fn with_x_tolerance(mut self, x_tolerance: f64) -> Result<Self, SettingsError> {
        self.x_tolerance = positive_tolerance("x_tolerance", x_tolerance)?;
        Ok(self)
    }

    /// Absolute f tolerance (scipy's `fatol`): converged when every vertex's value is within
    /// this of the best value and the x criterion holds too. Must be > 0; `f64::INFINITY`
    /// switches the criterion off.
    pub fn with_f_tolerance(mut self, f_tolerance: f64) -> Result<Self, SettingsError> {
        self.f_tolerance = positive_tolerance("f_tolerance", f_tolerance)?;
        Ok(self)
    }

    /// Stop after this many iterations (complete Nelder-Mead steps). Must be ≥ 1.
    ///
    /// scipy counts from 1, so its `maxiter = k` allows k − 1 steps; here k means k steps.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Result<Self, SettingsError> {
        if max_iterations == 0 {
            return Err(SettingsError::Zero {
                name: "max_iterations",
            });
        }
        self.max_iterations = Some(max_iterations);
        Ok(self)
    }

    /// Never call the objective more than this many times (including the n + 1 calls on the
    /// initial simplex). Must be ≥ 1; a run whose initial simplex needs more is rejected.
    pub fn with_max_evaluations(mut self, max_evaluations: usize) -> Result<Self, SettingsError> {
        if max_evaluations == 0 {
            return Err(SettingsError::Zero {
                name: "max_evaluations",
            });
        }
        self.max_evaluations = Some(max_evaluations);
        Ok(self)
    }

    /// Box bounds (already validated by [`Bounds::new`]); see [`Bounds`] for the transformation.
    pub fn with_bounds(mut self, bounds: Bounds) -> Self {
        self.bounds = Some(bounds);
        self
    }

    /// The coefficient rule.
    pub fn coefficients(&self) -> CoefficientRule {
        self.coefficients
    }

    /// The initial-step rule.
    pub fn initial_steps(&self) -> &InitialSteps {
        &self.initial_steps
    }

    /// Absolute x tolerance.
    pub fn x_tolerance(&self) -> f64 {
        self.x_tolerance
    }

    /// Absolute f tolerance.
    pub fn f_tolerance(&self) -> f64 {
        self.f_tolerance
    }

    /// Iteration limit as set (`None`: see the type's documentation for the default).
    pub fn max_iterations(&self) -> Option<usize> {
        self.max_iterations
    }

    /// Evaluation limit as set (`None`: see the type's documentation for the default).
    pub fn max_evaluations(&self) -> Option<usize> {
        self.max_evaluations
    }

    /// The bounds, if any.
    pub fn bounds(&self) -> Option<&Bounds> {
        self.bounds.as_ref()
    }

    /// The limits in effect for a problem of `dimension` coordinates:
    /// `(max_iterations, max_evaluations)`, `usize::MAX` meaning unlimited.
    pub fn limits_for(&self, dimension: usize) -> (usize, usize) {
        let default = dimension.saturating_mul(200);
        match (self.max_iterations, self.max_evaluations) {
            (None, None) => (default, default),
            (Some(i), None) => (i, usize::MAX),
            (None, Some(e)) => (usize::MAX, e),
            (Some(i), Some(e)) => (i, e),
        }
    }
}
