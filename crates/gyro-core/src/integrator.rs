//! Trapezoidal integration of a rate into an angle, with a tentative part.
//!
//! Movement boundaries are confirmed a few samples after the fact (see [`crate::Phase`]),
//! so increments first go into a *pending* sum that is later kept ([`Integrator::commit`])
//! or dropped ([`Integrator::discard`]). Both sums are compensated ([`KahanSum`]).

use crate::kahan::KahanSum;

/// Angle accumulator (degrees). The sample period is the caller's (the pipeline keeps one
/// for both of its integrators: 4 bytes of state each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrator {
    committed: KahanSum,
    pending: KahanSum,
}

impl Default for Integrator {
    fn default() -> Self {
        Self::new()
    }
}

impl Integrator {
    /// An empty integrator.
    pub const fn new() -> Self {
        Self {
            committed: KahanSum::ZERO,
            pending: KahanSum::ZERO,
        }
    }

    /// Add the trapezoid between consecutive rates `previous_dps` and `rate_dps`, samples
    /// `2 × half_dt_s` apart, to the pending part.
    #[inline]
    pub fn step(&mut self, half_dt_s: f32, previous_dps: f32, rate_dps: f32) {
        self.pending.add(half_dt_s * (previous_dps + rate_dps));
    }

    /// Keep the pending part.
    pub fn commit(&mut self) {
        self.committed.add(self.pending.value());
        self.pending = KahanSum::ZERO;
    }

    /// Drop the pending part.
    pub fn discard(&mut self) {
        self.pending = KahanSum::ZERO;
    }

    /// Committed plus pending angle (deg).
    pub fn angle_deg(&self) -> f32 {
        self.committed.value() + self.pending.value()
    }

    /// Committed angle (deg).
    pub fn committed_deg(&self) -> f32 {
        self.committed.value()
    }

    /// True if the sums are finite.
    pub fn is_finite(&self) -> bool {
        self.committed.is_finite() && self.pending.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_of_a_ramp_is_exact() {
        let mut i = Integrator::new();
        let mut prev = 0.0;
        for k in 1..=10 {
            let rate = k as f32; // rate = 10 t
            i.step(0.05, prev, rate);
            prev = rate;
        }
        i.commit();
        // ∫0^1 10 t dt = 5
        assert!((i.committed_deg() - 5.0).abs() < 1e-5);
    }

    #[test]
    fn pending_is_kept_or_dropped() {
        let mut i = Integrator::new();
        i.step(0.5, 1.0, 1.0);
        assert_eq!(i.angle_deg(), 1.0);
        assert_eq!(i.committed_deg(), 0.0);
        i.discard();
        assert_eq!(i.angle_deg(), 0.0);
        i.step(0.5, 2.0, 2.0);
        i.commit();
        assert_eq!(i.committed_deg(), 2.0);
    }
}
