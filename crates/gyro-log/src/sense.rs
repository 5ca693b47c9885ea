//! Whether the reference turns the way the gyro does.
//!
//! A reference that counts the other way (an encoder wired in reverse, a pose axis of the
//! opposite sense, a board mounted upside down) makes every error against it the motion
//! twice over, and every fit against it nonsense: a scale of −200%, a lag at the end of
//! the search. Nothing else in a log shows it, so it is measured on every log with a
//! reference: the gyro's turn (trapezoid of the rate) and the reference's change are
//! summed over blocks of [`BLOCK_S`] (long beside a logger's or a pose's lag of a tenth of
//! a second, so the lag does not hide the sense), and the correlation of the two over the
//! blocks is reported ([`crate::Quality::reference_correlation`]) once the gyro or the
//! reference has turned [`MIN_MOTION_DEG`] over them in all. At or below [`OPPOSED_CORRELATION`] it is warned
//! of in every output. Steps the jump detector holds as suspect are left out (a wrap is
//! not motion).
//!
//! The same sums give the reference's turn per degree of the gyro's (the least-squares
//! slope over the blocks, [`crate::Quality::reference_gain`]): a rate in rad/s read as
//! deg/s makes it 57.3, a reference in radians 0.017, a gear ratio its ratio. Beyond
//! [`GAIN_LIMIT`] either way (and with the turns correlated) it is warned of: a sensor's
//! scale error is a few percent, and the blocks' lag leaves real recordings at 0.77–1.19
//! (rasteiro) and 0.99–1.02 (ssong).

/// Length of the blocks the turns are summed over (s).
pub const BLOCK_S: f64 = 0.5;
/// The gyro or the reference must turn at least this much over the blocks, in all (deg),
/// for the sense to be measured: a still log has none.
pub const MIN_MOTION_DEG: f64 = 30.0;
/// A correlation at or below this is a reference that turns against the gyro.
pub const OPPOSED_CORRELATION: f64 = -0.5;

/// A reference turning more than this many times as far as the gyro, or less than its
/// inverse, is warned of.
pub const GAIN_LIMIT: f64 = 2.0;

/// How a reference fails to measure the gyro's motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mismatch {
    /// It turns against the gyro: correlation at or below [`OPPOSED_CORRELATION`].
    Opposed,
    /// It turns with the gyro, by more than [`GAIN_LIMIT`] times as far or less than its
    /// inverse.
    Scaled,
}

/// The mismatch that a log's `reference_correlation` and `reference_gain` show, if any
/// (the one rule [`Sense`]'s warning and every summary of many logs follow).
pub fn mismatch(correlation: f64, gain: f64) -> Option<Mismatch> {
    if correlation <= OPPOSED_CORRELATION {
        Some(Mismatch::Opposed)
    } else if correlation >= -OPPOSED_CORRELATION
        && !(1.0 / GAIN_LIMIT..=GAIN_LIMIT).contains(&gain)
    {
        Some(Mismatch::Scaled)
    } else {
        None
    }
}

/// Running sums of the blocks' turns.
#[derive(Clone, Debug, Default)]
pub(crate) struct Sense {
    block_start_s: Option<f64>,
    gyro_deg: f64,
    reference_deg: f64,
    /// Σ g·r, Σ g², Σ r², Σ |g|, Σ |r| over the finished blocks.
    sums: [f64; 5],
}

impl Sense {
    /// A step ending at `time_s` over which the gyro turned `gyro_deg` and the reference
    /// changed by `reference_deg`.
    pub(crate) fn step(&mut self, time_s: f64, gyro_deg: f64, reference_deg: f64) {
        if !(gyro_deg.is_finite() && reference_deg.is_finite()) {
            return;
        }
        let start_s = *self.block_start_s.get_or_insert(time_s);
        self.gyro_deg += gyro_deg;
        self.reference_deg += reference_deg;
        if time_s - start_s >= BLOCK_S {
            self.close(time_s);
        }
    }

    fn close(&mut self, time_s: f64) {
        let (g, r) = (self.gyro_deg, self.reference_deg);
        self.sums[0] += g * r;
        self.sums[1] += g * g;
        self.sums[2] += r * r;
        self.sums[3] += g.abs();
        self.sums[4] += r.abs();
        self.gyro_deg = 0.0;
        self.reference_deg = 0.0;
        self.block_start_s = Some(time_s);
    }

    /// The correlation of the blocks' turns, when the gyro or the reference turned
    /// enough and both moved at all.
    pub(crate) fn correlation(&self) -> Option<f64> {
        let [gr, gg, rr, gyro_moved, reference_moved] = self.sums;
        let scale = (gg * rr).sqrt();
        (gyro_moved.max(reference_moved) >= MIN_MOTION_DEG && scale > 0.0).then(|| gr / scale)
    }

    /// The reference's turn per degree of the gyro's over the blocks (least squares), when
    /// the correlation is measured.
    pub(crate) fn gain(&self) -> Option<f64> {
        let [gr, gg, ..] = self.sums;
        self.correlation().map(|_| gr / gg)
    }

    /// The warning for a reference that turns against the gyro, or by a different
    /// amount, if it does.
    pub(crate) fn warning(&self) -> Option<String> {
        let (c, gain) = self.correlation().zip(self.gain())?;
        Some(match mismatch(c, gain)? {
            Mismatch::Opposed => format!(
                "the reference turns against the gyro (correlation of their turns over {BLOCK_S} s: {c:.2}): one of them counts the other way (an encoder or axis of the opposite sense, a board mounted upside down), so every error against it is the motion twice over and every fit to it is meaningless; negate one of them"
            ),
            Mismatch::Scaled => format!(
                "the reference turns {gain:.3} times as far as the gyro (least squares over {BLOCK_S} s blocks, correlation {c:.2}): their units or scales differ (a rate in rad/s read as deg/s makes 57.3: --rate-unit rads; a reference in radians 0.017; a gear ratio its ratio), so the errors against it are mostly that, not the sensor's"
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PER_RAD: f64 = 180.0 / std::f64::consts::PI;

    /// Turns of ±90° in 1 s, then 1 s of rest, in steps of 10 ms, with a small bias: the
    /// gyro's turns times `gyro_scale`, the reference's times `reference_scale`, the
    /// reference `lag_steps` behind.
    fn sense(gyro_scale: f64, reference_scale: f64, lag_steps: usize) -> Sense {
        let rate = |k: usize| {
            let t = (k % 200) as f64 * 0.01;
            let dir = if (k / 200) % 2 == 0 { 1.0 } else { -1.0 };
            if t < 1.0 {
                dir * 90.0 * (1.0 - (2.0 * std::f64::consts::PI * t).cos())
            } else {
                0.0
            }
        };
        let mut s = Sense::default();
        for k in 0..2000 {
            let reference = if k >= lag_steps {
                rate(k - lag_steps)
            } else {
                0.0
            };
            s.step(
                k as f64 * 0.01,
                gyro_scale * (rate(k) + 0.5) * 0.01,
                reference_scale * reference * 0.01,
            );
        }
        s
    }

    #[test]
    fn a_reference_of_the_opposite_sense_is_found_through_a_lag() {
        let same = sense(1.0, 1.0, 10);
        assert!(
            same.correlation().unwrap() > 0.8,
            "{:?}",
            same.correlation()
        );
        assert!(same.warning().is_none());
        let opposed = sense(1.0, -1.0, 10);
        assert!(opposed.correlation().unwrap() < -0.8);
        assert!(opposed
            .warning()
            .unwrap()
            .contains("turns against the gyro"));
    }

    #[test]
    fn a_reference_in_other_units_is_found() {
        let gain = sense(1.0, 1.0, 10).gain().unwrap();
        assert!((0.9..1.1).contains(&gain), "{gain}");
        // A rate in rad/s read as deg/s: the reference turns 57.3 times as far.
        let rad_rate = sense(1.0 / PER_RAD, 1.0, 10);
        let gain = rad_rate.gain().unwrap();
        assert!((gain / PER_RAD - 1.0).abs() < 0.1, "{gain}");
        assert!(rad_rate.warning().unwrap().contains("--rate-unit rads"));
        // A reference in radians: 0.017.
        let rad_reference = sense(1.0, 1.0 / PER_RAD, 10);
        let gain = rad_reference.gain().unwrap();
        assert!((gain * PER_RAD - 1.0).abs() < 0.1, "{gain}");
        assert!(rad_reference
            .warning()
            .unwrap()
            .contains("times as far as the gyro"));
        // A sensor's scale error, however large, within a factor of two: not warned of.
        assert!(sense(1.5, 1.0, 10).warning().is_none());
        assert!(sense(1.0, 1.5, 10).warning().is_none());
    }

    #[test]
    fn a_still_log_has_no_sense() {
        let mut s = Sense::default();
        for k in 0..2000 {
            s.step(k as f64 * 0.01, 0.005, 0.0);
        }
        assert_eq!(s.correlation(), None);
        assert_eq!(s.gain(), None);
        assert!(s.warning().is_none());
    }
}
