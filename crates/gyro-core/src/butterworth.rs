//! Butterworth low-pass design as second-order sections.
//!
//! Designed in f64 at construction (analog prototype, bilinear transform with the cutoff
//! pre-warped), with the conventions of `scipy.signal.butter(N, Wn, fs=fs, output='sos')`:
//! for odd orders the first-order section comes first; the other sections follow in order
//! of increasing pole radius (the pair nearest the unit circle last); the overall gain sits
//! in the first section's numerator. The runtime cascade is f32 ([`Sos`]): the same
//! sections, each scaled to unit DC gain and run in the state-variable form described at
//! [`Biquad`], which keeps low cutoffs accurate in f32.

use crate::error::{check_range, Error};
use crate::sos::{Biquad, Sos, MAX_SECTIONS};
use core::f64::consts::PI;

/// Highest supported order (`2 × MAX_SECTIONS`).
pub const MAX_ORDER: u8 = 2 * MAX_SECTIONS as u8;

/// Settings of a Butterworth low-pass.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Butterworth {
    /// Filter order, 1 to [`MAX_ORDER`].
    pub order: u8,
    /// -3 dB cutoff frequency in Hz; must be below half the sample rate.
    pub cutoff_hz: f32,
}

/// An f64 design: sections `[b0, b1, b2, a0, a1, a2]` (scipy's `sos` rows, `a0 = 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SosDesign {
    sections: [[f64; 6]; MAX_SECTIONS],
    len: usize,
}

impl SosDesign {
    /// The designed sections, as rows of scipy's `sos` array.
    pub fn sections(&self) -> &[[f64; 6]] {
        &self.sections[..self.len]
    }

    /// The f32 cascade: each section realised by [`Biquad::from_row`] after scaling its
    /// numerator to unit DC gain (the product, the whole filter's gain, is 1 to f64
    /// rounding). Normalised sections keep every intermediate signal at the input's
    /// scale and make the f32 cascade's DC gain exactly 1 (each section's `m0 + m2`).
    pub fn to_sos(&self) -> Sos {
        let mut out = [Biquad::IDENTITY; MAX_SECTIONS];
        for (dst, row) in out.iter_mut().zip(self.sections()) {
            let [b0, b1, b2, a0, a1, a2] = *row;
            let scale = (a0 + a1 + a2) / (b0 + b1 + b2);
            // Valid designs have every pole strictly inside the unit circle and the
            // numerator's zeros at −1 or 0, so the conversion cannot fail.
            *dst = Biquad::from_row([b0 * scale, b1 * scale, b2 * scale, a0, a1, a2])
                .unwrap_or(Biquad::IDENTITY);
        }
        Sos::from_array(out, self.len)
    }
}

impl Butterworth {
    /// Lowest valid `cutoff_hz / sample_rate_hz`. The f32 runtime is verified against
    /// scipy's `sosfilt` (within 1e-5 of the input's full scale) from here up; lower
    /// cutoffs also work (errors stay below 1e-6 down to 1e-4) but settle over more than
    /// 10⁴ samples, far slower than any rate filter of the pipeline needs, and are not
    /// covered by the tests.
    pub const MIN_CUTOFF_RATIO: f64 = 1e-3;
    /// Highest valid `cutoff_hz / sample_rate_hz` (Nyquist is 0.5). Closer to Nyquist the
    /// poles crowd z = −1, the f32 runtime's rounding noise grows (max error against
    /// `sosfilt` 2e-6 at 0.49, 5e-6 at 0.499, 1.3e-5 at 0.4999), and the design, which
    /// passes almost the whole band, no longer filters anything worth filtering.
    pub const MAX_CUTOFF_RATIO: f64 = 0.49;

    /// Check the settings against a sample rate: order 1 to [`MAX_ORDER`], `cutoff_hz`
    /// between [`Self::MIN_CUTOFF_RATIO`] and [`Self::MAX_CUTOFF_RATIO`] times the
    /// sample rate.
    pub fn validate(&self, sample_rate_hz: f64) -> Result<(), Error> {
        if self.order == 0 || self.order > MAX_ORDER {
            return Err(Error::OutOfRange("filter.order"));
        }
        check_range(
            "sample_rate_hz",
            sample_rate_hz,
            f64::MIN_POSITIVE,
            f64::MAX,
        )?;
        let cutoff_hz = check_range(
            "filter.cutoff_hz",
            f64::from(self.cutoff_hz),
            0.0,
            0.5 * sample_rate_hz,
        )?;
        let ratio = cutoff_hz / sample_rate_hz;
        if !(Self::MIN_CUTOFF_RATIO..=Self::MAX_CUTOFF_RATIO).contains(&ratio) {
            return Err(Error::OutOfRange("filter.cutoff_hz"));
        }
        Ok(())
    }

    /// Design the low-pass for `sample_rate_hz`, in f64.
    pub fn design(&self, sample_rate_hz: f64) -> Result<SosDesign, Error> {
        self.validate(sample_rate_hz)?;
        Ok(design_lowpass(
            usize::from(self.order),
            f64::from(self.cutoff_hz),
            sample_rate_hz,
        ))
    }

    /// Design and round to the f32 runtime cascade.
    pub fn sos(&self, sample_rate_hz: f64) -> Result<Sos, Error> {
        Ok(self.design(sample_rate_hz)?.to_sos())
    }
}

/// A complex number, just enough for pole placement.
#[derive(Clone, Copy)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
    fn mul(self, o: Self) -> Self {
        Self {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn abs(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
}

/// Valid inputs only (checked by [`Butterworth::validate`]).
fn design_lowpass(order: usize, cutoff_hz: f64, sample_rate_hz: f64) -> SosDesign {
    // Pre-warped analog cutoff, normalised by 2·fs: the bilinear map is z = (1+s)/(1-s).
    let warped = libm::tan(PI * cutoff_hz / sample_rate_hz);
    let one = C64 { re: 1.0, im: 0.0 };

    // Digital poles with non-negative imaginary part (one per section), and the gain
    // k = warped^N / Π(1 - s_k) over all N analog poles.
    let mut poles = [C64 { re: 0.0, im: 0.0 }; MAX_SECTIONS];
    let mut n_poles = 0;
    let mut denom = one;
    for k in 0..order {
        // Analog prototype pole: -exp(iπ(2k - N + 1) / 2N), on the left half circle.
        let theta = PI * (2.0 * k as f64 - order as f64 + 1.0) / (2.0 * order as f64);
        let s = C64 {
            re: -warped * libm::cos(theta),
            im: -warped * libm::sin(theta),
        };
        denom = denom.mul(C64 {
            re: 1.0 - s.re,
            im: -s.im,
        });
        let z = C64 {
            re: 1.0 + s.re,
            im: s.im,
        }
        .div(C64 {
            re: 1.0 - s.re,
            im: -s.im,
        });
        if z.im >= -1e-15 && n_poles < MAX_SECTIONS {
            poles[n_poles] = z;
            n_poles += 1;
        }
    }
    let gain = libm::pow(warped, order as f64) / denom.re;

    // Sections: the real pole (odd order) first, then complex pairs by increasing radius.
    let poles = &mut poles[..n_poles];
    poles.sort_unstable_by(|a, b| {
        let real_a = a.im.abs() <= 1e-15;
        let real_b = b.im.abs() <= 1e-15;
        real_b.cmp(&real_a).then(
            a.abs()
                .partial_cmp(&b.abs())
                .unwrap_or(core::cmp::Ordering::Equal),
        )
    });
    // Zeros: all at -1, plus (odd order) one at the origin, which scipy's 'nearest'
    // pairing gives to the first pole, worst (outermost) first, that lies nearer to 0
    // than to -1; if none does, the first-order section takes it.
    let mut origin_zero_left = order % 2 == 1;
    let mut sections = [[0.0; 6]; MAX_SECTIONS];
    for (row, p) in sections.iter_mut().zip(poles.iter()).rev() {
        let is_real = p.im.abs() <= 1e-15;
        let takes_origin_zero = origin_zero_left && (is_real || p.re > -0.5);
        origin_zero_left &= !takes_origin_zero;
        let b: [f64; 3] = if takes_origin_zero {
            [1.0, 1.0, 0.0]
        } else {
            [1.0, 2.0, 1.0]
        };
        let a: [f64; 2] = if is_real {
            [-p.re, 0.0]
        } else {
            [-2.0 * p.re, p.re * p.re + p.im * p.im]
        };
        *row = [b[0], b[1], b[2], 1.0, a[0], a[1]];
    }
    for b in &mut sections[0][..3] {
        *b *= gain;
    }
    SosDesign {
        sections,
        len: n_poles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bw(order: u8, cutoff_hz: f32) -> Butterworth {
        Butterworth { order, cutoff_hz }
    }

    #[test]
    fn second_order_matches_scipy() {
        // scipy.signal.butter(2, 10, fs=50, output='sos')
        let d = bw(2, 10.0).design(50.0).unwrap();
        let expected = [
            0.206_572_083_826_147_92,
            0.413_144_167_652_295_84,
            0.206_572_083_826_147_92,
            1.0,
            -0.369_527_377_351_241_4,
            0.195_815_712_655_833_06,
        ];
        for (got, want) in d.sections()[0].iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn dc_gain_is_one() {
        for order in 1..=MAX_ORDER {
            for cutoff_hz in [0.5_f32, 2.0, 10.0, 20.0, 24.0] {
                let sos = bw(order, cutoff_hz).sos(50.0).unwrap();
                assert!(
                    (sos.dc_gain() - 1.0).abs() < 1e-6,
                    "order {order} fc {cutoff_hz}"
                );
                assert_eq!(sos.sections().len(), usize::from(order).div_ceil(2));
            }
        }
    }

    #[test]
    fn invalid_settings_refused() {
        assert_eq!(
            bw(0, 10.0).design(50.0),
            Err(Error::OutOfRange("filter.order"))
        );
        assert_eq!(
            bw(9, 10.0).design(50.0),
            Err(Error::OutOfRange("filter.order"))
        );
        assert_eq!(
            bw(2, 25.0).design(50.0),
            Err(Error::OutOfRange("filter.cutoff_hz"))
        );
        // Valid range of cutoff / sample rate: [1e-3, 0.49].
        assert!(bw(2, 0.05).design(50.0).is_ok());
        assert!(bw(2, 24.5).design(50.0).is_ok());
        for cutoff_hz in [0.0, 0.04, 24.6, 24.999_998, -1.0] {
            assert_eq!(
                bw(2, cutoff_hz).design(50.0),
                Err(Error::OutOfRange("filter.cutoff_hz")),
                "{cutoff_hz}"
            );
        }
        assert_eq!(
            bw(2, f32::NAN).design(50.0),
            Err(Error::NonFinite("filter.cutoff_hz"))
        );
        assert_eq!(
            bw(2, 10.0).design(0.0),
            Err(Error::OutOfRange("sample_rate_hz"))
        );
    }
}
