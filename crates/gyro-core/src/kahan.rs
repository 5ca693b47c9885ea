//! Compensated (Kahan) summation in f32.
//!
//! Long sums of small increments (an angle after 90 s at 50 Hz is 4500 of them) lose the
//! low bits of each addend in plain f32; the compensation term keeps them, so the f32 sum
//! tracks an f64 sum to a few ulps of the total.

/// An f32 sum with its running compensation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KahanSum {
    sum: f32,
    compensation: f32,
}

impl KahanSum {
    /// Zero.
    pub const ZERO: Self = Self {
        sum: 0.0,
        compensation: 0.0,
    };

    /// Add `x`.
    #[inline]
    pub fn add(&mut self, x: f32) {
        (self.sum, self.compensation) = step(self.sum, self.compensation, x);
    }

    /// The sum.
    #[inline]
    pub fn value(&self) -> f32 {
        self.sum - self.compensation
    }

    /// True if the sum and its compensation are finite.
    pub fn is_finite(&self) -> bool {
        self.sum.is_finite() && self.compensation.is_finite()
    }
}

/// One compensated addition: `(sum, compensation)` with `x` added.
#[inline(always)]
fn step(sum: f32, compensation: f32, x: f32) -> (f32, f32) {
    let y = x - compensation;
    let t = sum + y;
    (t, (t - sum) - y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_small_addends() {
        let mut k = KahanSum::ZERO;
        let mut plain = 0.0_f32;
        k.add(1.0e4);
        plain += 1.0e4;
        for _ in 0..100_000 {
            k.add(1.0e-4);
            plain += 1.0e-4;
        }
        let exact = 1.0e4 + 10.0;
        assert!((k.value() - exact).abs() < 1e-3, "{}", k.value());
        // Plain f32 loses the addends entirely: the test would pass vacuously otherwise.
        assert!((plain - exact).abs() > 1.0);
    }
}
