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
    /// is not yet in `sum` (see [`Decimator::run`]).
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
    /// One sample is a run of one: [`Self::run`], [`BlockRun::add`], [`Self::close`].
    #[inline]
    pub fn push(&mut self, x: f32) -> Option<f32> {
        let mut run = self.run();
        run.add(x);
        self.close(run)
    }

    /// How many more samples complete the current block.
    #[inline]
    pub const fn remaining(&self) -> u16 {
        self.factor - self.count
    }

    /// Open the current block for a run of samples, to be added with [`BlockRun::add`]
    /// (at most [`Self::remaining`] of them) and handed back with [`Self::close`].
    ///
    /// A run keeps the sum in registers from one sample to the next; between calls the
    /// decimator keeps it in memory. The samples go into the compensated sum one at a time
    /// in their order, so that any split of a block into runs gives the same sum, bit for
    /// bit. Stored, a block of odd count leaves its latest sample out of the sum (it goes
    /// in with the next one): a run of one sample then trips the sum through memory only
    /// every other sample.
    #[inline(always)]
    pub fn run(&self) -> BlockRun {
        let mut sum = self.sum;
        if self.count % 2 == 1 {
            sum.add(self.last);
        }
        BlockRun {
            sum,
            before: sum,
            last: self.last,
            count: self.count,
        }
    }

    /// Take back a run: its samples stay in the block; returns the block's mean and starts
    /// the next block if the run completed it.
    #[inline(always)]
    pub fn close(&mut self, run: BlockRun) -> Option<f32> {
        self.last = run.last;
        if run.count < self.factor {
            self.count = run.count;
            self.sum = if run.count % 2 == 1 {
                run.before
            } else {
                run.sum
            };
            return None;
        }
        let mean = run.sum.value() / f32::from(self.factor);
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

/// The current block of a [`Decimator`] while a run of samples is added to it
/// ([`Decimator::run`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockRun {
    /// Every sample of the block so far.
    sum: KahanSum,
    /// The sum before the latest sample.
    before: KahanSum,
    last: f32,
    count: u16,
}

impl BlockRun {
    /// Add one sample.
    #[inline(always)]
    pub fn add(&mut self, x: f32) {
        self.before = self.sum;
        self.sum.add(x);
        self.last = x;
        self.count += 1;
    }

    /// The latest sample added (the decimator's [`Decimator::last`] before any).
    #[inline(always)]
    pub const fn last(&self) -> f32 {
        self.last
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
