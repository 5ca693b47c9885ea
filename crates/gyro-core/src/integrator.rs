//! Trapezoidal integration of a rate into an angle, with a tentative part.
//!
//! Movement boundaries are confirmed a few samples after the fact (see [`crate::Phase`]),
//! so increments first go into a *pending* sum that is later kept ([`Integrator::commit`])
//! or dropped ([`Integrator::discard`]). Both sums are compensated ([`KahanSum`]).

use crate::kahan::KahanSum;

/// Angle accumulator (degrees) for samples `dt_s` apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrator {
    half_dt_s: f32,
    committed: KahanSum,
    pending: KahanSum,
}

impl Integrator {
    /// Integrator for a fixed sample period `dt_s` (seconds).
    pub const fn new(dt_s: f32) -> Self {
        Self {
            half_dt_s: 0.5 * dt_s,
            committed: KahanSum::ZERO,
            pending: KahanSum::ZERO,
        }
    }

    /// Add the trapezoid between consecutive rates `previous_dps` and `rate_dps` to the
    /// pending part.
    #[inline]
    pub fn step(&mut self, previous_dps: f32, rate_dps: f32) {
        self.pending.add(self.half_dt_s * (previous_dps + rate_dps));
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
        let mut i = Integrator::new(0.1);
        let mut prev = 0.0;
        for k in 1..=10 {
            let rate = k as f32; // rate = 10 t
            i.step(prev, rate);
            prev = rate;
        }
        i.commit();
        // ∫0^1 10 t dt = 5
        assert!((i.committed_deg() - 5.0).abs() < 1e-5);
    }

    #[test]
    fn pending_is_kept_or_dropped() {
        let mut i = Integrator::new(1.0);
        i.step(1.0, 1.0);
        assert_eq!(i.angle_deg(), 1.0);
        assert_eq!(i.committed_deg(), 0.0);
        i.discard();
        assert_eq!(i.angle_deg(), 0.0);
        i.step(2.0, 2.0);
        i.commit();
        assert_eq!(i.committed_deg(), 2.0);
    }
}
