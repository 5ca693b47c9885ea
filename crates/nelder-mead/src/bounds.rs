//! Box bounds, handled by a change of variables.

use super::SettingsError;

/// Box bounds `lower[i] ≤ x[i] ≤ upper[i]`; `-inf` / `+inf` leave a side open.
///
/// The simplex lives in an unconstrained space `u` and every point is mapped to the original
/// space before the objective sees it (the transformation of D'Errico's `fminsearchbnd`):
///
/// | bounds of `x[i]` | `x = g(u)` | `u = g⁻¹(x)` |
/// |---|---|---|
/// | none | `u` | `x` |
/// | lower only | `lo + u²` | `√(x − lo)` |
/// | upper only | `hi − u²` | `√(hi − x)` |
/// | both | `lo + (hi − lo)·(sin u + 1)/2` | `asin(2(x − lo)/(hi − lo) − 1)` |
///
/// Each map covers its whole interval *including* the bound itself (at `u = 0`, `u = ±π/2`), so
/// an optimum on a bound is reached at a finite `u` with a flat (quadratic) approach — unlike a
/// logistic map, which only gets there as `u → ∞`. The two-sided map is clamped to
/// `[lo, hi]` after rounding, so the objective never sees an infeasible point. Unbounded
/// coordinates pass through untouched (bit for bit); a bounded vertex may come back from the
/// round trip `g(g⁻¹(x))` off by rounding. Tolerances, results and the reported simplex are all
/// in the original coordinates.
///
/// The start point (or every vertex of a given simplex) must lie inside the bounds (bounds
/// included), else the run is refused with
/// [`ProblemError::OutsideBounds`](super::ProblemError::OutsideBounds). An initial step that
/// crosses a bound is reflected back into the box (as scipy does) and clamped to it.
#[derive(Clone, Debug, PartialEq)]
pub struct Bounds {
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// The change of variables of one coordinate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Map {
    Free,
    Lower(f64),
    Upper(f64),
    Both(f64, f64),
}

impl Map {
    /// Unconstrained → original.
    pub(super) fn to_outer(self, u: f64) -> f64 {
        match self {
            Self::Free => u,
            Self::Lower(lo) => lo + u * u,
            Self::Upper(hi) => hi - u * u,
            Self::Both(lo, hi) => (lo + (hi - lo) * ((u.sin() + 1.0) / 2.0)).clamp(lo, hi),
        }
    }

    /// Original (inside the bounds) → unconstrained.
    pub(super) fn to_inner(self, x: f64) -> f64 {
        match self {
            Self::Free => x,
            Self::Lower(lo) => (x - lo).max(0.0).sqrt(),
            Self::Upper(hi) => (hi - x).max(0.0).sqrt(),
            Self::Both(lo, hi) => (2.0 * (x - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0).asin(),
        }
    }
}

impl Bounds {
    /// Bounds from per-coordinate lower and upper limits (use `f64::NEG_INFINITY` /
    /// `f64::INFINITY` for an open side). Rejects different lengths, NaN, `lower ≥ upper` and
    /// intervals whose width overflows. To fix a parameter, leave it out of the problem.
    pub fn new(lower: Vec<f64>, upper: Vec<f64>) -> Result<Self, SettingsError> {
        if lower.len() != upper.len() {
            return Err(SettingsError::BoundsLength {
                lower: lower.len(),
                upper: upper.len(),
            });
        }
        for (index, (&lo, &hi)) in lower.iter().zip(&upper).enumerate() {
            let width_ok = !(lo.is_finite() && hi.is_finite()) || (hi - lo).is_finite();
            // False for NaN, equal and reversed bounds, lo = +inf and hi = -inf.
            let ordered = lo < hi;
            if !ordered || !width_ok {
                return Err(SettingsError::BadBounds {
                    index,
                    lower: lo,
                    upper: hi,
                });
            }
        }
        Ok(Self { lower, upper })
    }

    /// Lower limits.
    pub fn lower(&self) -> &[f64] {
        &self.lower
    }

    /// Upper limits.
    pub fn upper(&self) -> &[f64] {
        &self.upper
    }

    /// Number of coordinates.
    pub fn len(&self) -> usize {
        self.lower.len()
    }

    /// True for bounds on zero coordinates.
    pub fn is_empty(&self) -> bool {
        self.lower.is_empty()
    }

    /// True if `x` has the bounds' length and lies inside them (bounds included).
    pub fn contains(&self, x: &[f64]) -> bool {
        x.len() == self.len()
            && x.iter()
                .zip(self.lower.iter().zip(&self.upper))
                .all(|(&v, (&lo, &hi))| lo <= v && v <= hi)
    }

    pub(super) fn maps(&self) -> Vec<Map> {
        self.lower
            .iter()
            .zip(&self.upper)
            .map(|(&lo, &hi)| match (lo.is_finite(), hi.is_finite()) {
                (false, false) => Map::Free,
                (true, false) => Map::Lower(lo),
                (false, true) => Map::Upper(hi),
                (true, true) => Map::Both(lo, hi),
            })
            .collect()
    }
}
