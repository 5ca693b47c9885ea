//! Averaging (boxcar) decimation by an integer factor.
//!
//! The output is the mean of each block of `factor` input samples. Because
//! `mean × factor × dt_in = Σ x × dt_in`, the rectangle-rule integral of the rate is the
//! same before and after decimation: the angle survives decimation exactly (up to
//! rounding). The boxcar is also a (weak) anti-alias filter with nulls at multiples of
//! the output rate.

use crate::error::Error;
use crate::kahan::KahanSum;

/// Averaging decimator state. The factor is its only setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decimator {
    factor: u16,
    count: u16,
    sum: KahanSum,
    /// The latest sample pushed (0 before the first); while the block's count is odd, it
    /// is not yet in `sum`.
    last: f32,
}

impl Decimator {
    /// Decimator by `factor` (≥ 1). `factor` = 1 passes samples through.
    pub const fn try_new(factor: u16) -> Result<Self, Error> {
        if factor == 0 {
            return Err(Error::OutOfRange("decimation_factor"));
        }
        Ok(Self {
            factor,
            count: 0,
            sum: KahanSum::ZERO,
            last: 0.0,
        })
    }

    /// The decimation factor.
    pub const fn factor(&self) -> u16 {
        self.factor
    }

    /// The latest sample pushed (0 before the first), whether its block is complete or not.
    #[inline]
    pub const fn last(&self) -> f32 {
        self.last
    }

    /// How many samples of the current block have been pushed.
    #[inline]
    pub const fn pending(&self) -> u16 {
        self.count
    }

    /// Push one input sample; returns the block mean after every `factor`-th sample.
    ///
    /// The samples go into the compensated sum in pairs, in their order: the same sum, bit
    /// for bit, as one at a time, with half the trips of the sum through memory from one
    /// call to the next (a store and a reload on the sum's dependency chain each).
    #[inline]
    pub fn push(&mut self, x: f32) -> Option<f32> {
        self.count += 1;
        let pair_ends = self.count % 2 == 0;
        if self.count < self.factor {
            if pair_ends {
                self.sum.add(self.last);
                self.sum.add(x);
            }
            self.last = x;
            return None;
        }
        if pair_ends {
            self.sum.add(self.last);
        }
        self.sum.add(x);
        self.last = x;
        let mean = self.sum.value() / f32::from(self.factor);
        self.reset();
        Some(mean)
    }

    /// Drop the partial block (the latest sample stays known).
    #[inline]
    pub fn reset(&mut self) {
        self.count = 0;
        self.sum = KahanSum::ZERO;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_factor_is_refused() {
        assert_eq!(
            Decimator::try_new(0),
            Err(Error::OutOfRange("decimation_factor"))
        );
    }

    #[test]
    fn averages_blocks() {
        let mut d = Decimator::try_new(4).unwrap();
        let out: Vec<f32> = [1.0, 2.0, 3.0, 6.0, 10.0, 10.0, 10.0, 10.0, 5.0]
            .iter()
            .filter_map(|&x| d.push(x))
            .collect();
        assert_eq!(out, [3.0, 10.0]);
        assert_eq!(d.pending(), 1);
    }

    #[test]
    fn factor_one_passes_through() {
        let mut d = Decimator::try_new(1).unwrap();
        assert_eq!(d.push(2.5), Some(2.5));
        assert_eq!(d.push(-1.0), Some(-1.0));
    }
}
