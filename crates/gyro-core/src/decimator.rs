//! Averaging (boxcar) decimation by an integer factor.
//!
//! The output is the mean of each block of `factor` input samples. Because
//! `mean × factor × dt_in = Σ x × dt_in`, the rectangle-rule integral of the rate is the
//! same before and after decimation: the angle survives decimation exactly (up to
//! rounding). The boxcar is also a (weak) anti-alias filter with nulls at multiples of
//! the output rate.
//!
//! A block's samples are summed in plain f32, in their order. Its rounding error is at
//! most (factor − 1)·2⁻²⁴ of the sum of their magnitudes: for 20 readings at 300 deg/s,
//! 3.4e-4 deg/s in the mean, a hundredth of the CRM100's output step (1/24 deg/s), and
//! about √factor·2⁻²⁵ of it in practice. The long sums, the angle's, are compensated
//! ([`crate::KahanSum`]); a compensated sum here would put four dependent operations on
//! every sample's path for nothing the sensor can show.

use crate::error::Error;

/// Averaging decimator state. The factor is its only setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decimator {
    factor: u16,
    count: u16,
    sum: f32,
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
            sum: 0.0,
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
    /// decimator keeps it in memory. The samples go into the sum in pairs, in their order:
    /// the same sum, bit for bit, as one at a time, however a block is split
    /// into runs; a run of one sample (a [`Self::push`]) then trips the sum through memory
    /// only every other sample (a store and a reload on the sum's chain of additions).
    #[inline(always)]
    pub const fn run(&self) -> BlockRun {
        BlockRun {
            sum: self.sum,
            last: self.last,
            count: self.count,
        }
    }

    /// Take back a run: its samples stay in the block; returns the block's mean and starts
    /// the next block if the run completed it.
    #[inline(always)]
    pub fn close(&mut self, run: BlockRun) -> Option<f32> {
        if run.count < self.factor {
            // Stored only if a pair went in: a run of one leaves it alone every other time,
            // and the next sample's reload then waits on no store.
            if run.count / 2 != self.count / 2 {
                self.sum = run.sum;
            }
            self.last = run.last;
            self.count = run.count;
            return None;
        }
        let mut sum = run.sum;
        if run.count % 2 == 1 {
            sum += run.last;
        }
        Some(self.complete(sum, run.last))
    }

    /// Complete a whole block summed elsewhere: `sum` of its `factor` samples, from 0 in
    /// their order, the latest `last`, in place of the current
    /// block, which must be empty (no sample pending) unless it is the one summed. Returns
    /// the block's mean, as [`Self::close`] would.
    ///
    /// For blocks summed side by side: independent sums keep the floating-point units busy
    /// rather than wait on one sum's chain of additions.
    #[inline(always)]
    pub fn complete(&mut self, sum: f32, last: f32) -> f32 {
        self.last = last;
        let mean = sum / f32::from(self.factor);
        self.reset();
        mean
    }

    /// Drop the partial block (the latest sample stays known).
    #[inline]
    pub fn reset(&mut self) {
        self.count = 0;
        self.sum = 0.0;
    }
}

/// The current block of a [`Decimator`] while a run of samples is added to it
/// ([`Decimator::run`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockRun {
    /// The block's samples but the latest while their count is odd.
    sum: f32,
    last: f32,
    count: u16,
}

impl BlockRun {
    /// Add one sample.
    #[inline(always)]
    pub fn add(&mut self, x: f32) {
        self.count += 1;
        if self.count % 2 == 0 {
            self.sum += self.last;
            self.sum += x;
        }
        self.last = x;
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
    fn runs_give_the_bits_of_pushes() {
        let xs: Vec<f32> = (0..200)
            .map(|i| (i as f32 * 0.37).sin() * 1e3 + 1e-3)
            .collect();
        let mut one = Decimator::try_new(7).unwrap();
        let expected: Vec<u32> = xs
            .iter()
            .filter_map(|&x| one.push(x))
            .map(f32::to_bits)
            .collect();
        for cut in [2, 3, 5, 7, 11] {
            let mut d = Decimator::try_new(7).unwrap();
            let mut got = Vec::new();
            let mut rest = &xs[..];
            while !rest.is_empty() {
                let take = rest.len().min(cut).min(usize::from(d.remaining()));
                let mut run = d.run();
                for &x in &rest[..take] {
                    run.add(x);
                }
                got.extend(d.close(run).map(f32::to_bits));
                rest = &rest[take..];
            }
            assert_eq!(got, expected, "runs of {cut}");
            assert_eq!(d, one, "runs of {cut}");
        }
    }

    #[test]
    fn factor_one_passes_through() {
        let mut d = Decimator::try_new(1).unwrap();
        assert_eq!(d.push(2.5), Some(2.5));
        assert_eq!(d.push(-1.0), Some(-1.0));
    }
}
