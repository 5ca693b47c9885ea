//! Cascade of second-order sections (biquads): coefficients and state are separate types.
//!
//! One [`Sos`] (settings) can run any number of [`SosState`]s (channels); the state resets
//! without redesign.
//!
//! Each section runs as a trapezoidal state-variable filter, not in the direct form of
//! `scipy.signal.sosfilt`: see [`Biquad`] for why and how.

/// Most sections a cascade holds: enough for a Butterworth design of order 8.
pub const MAX_SECTIONS: usize = 4;

/// One second-order section.
///
/// A section has the transfer function of one row `[b0, b1, b2, a0, a1, a2]` of scipy's
/// `sos` array, but it does not run in the transposed direct form II of
/// `scipy.signal.sosfilt`. In f32 that form cannot hold low-cutoff designs: their poles
/// sit near z = 1, so `a1 ≈ −2` and `a2 ≈ 1` carry the pole positions in their last few
/// bits, and the state words (of the size of the output) cancel each other at every step.
/// Measured against `sosfilt` on a unit step, f32 direct form was off by 6e-5 for an
/// order-8 low-pass at fc = 0.01·fs and by 1.6e-4 at fc = 0.005·fs.
///
/// Each section therefore runs as a trapezoidal (topology-preserving) state-variable
/// filter (A. Simper, "Linear trapezoidal integrated SVF", 2013; V. Zavalishin, "The Art
/// of VA Filter Design"), which realises any stable biquad exactly (in exact arithmetic)
/// with coefficients that are small numbers stored at full relative precision:
///
/// ```text
/// c1 = A(−1)/4,  c3 = A(1)/4,  c2 = √(c1·c3),   A(z) = 1 + a1 z⁻¹ + a2 z⁻²
/// v3 = x − s2
/// v1 = c1·s1 + c2·v3            s1 ← 2·v1 − s1
/// v2 = s2 + c2·s1 + c3·v3       s2 ← 2·v2 − s2
/// y  = m0·x + m1·v1 + m2·v2
/// ```
///
/// and two refinements for f32:
/// - `c1` is stored as `u − e` with `u` = 1 (and `e` = 1 − c1, small, at low cutoffs) or
///   `u` = 0 (and `e` = −c1), so that the damping, which low cutoffs put in the last bits of
///   `c1 ≈ 1`, is not rounded away;
/// - `s2`, the state that sits at the output level and moves by tiny steps at low cutoffs,
///   is kept as an unevaluated sum `hi + lo` of two f32 (error-free "TwoSum" update);
///   without it the update `2·(c2·s1 + c3·v3)` falls below half an ulp of `s2` and the
///   output sticks up to `ulp / c3` away from its target (2e-5 for fc = 0.001·fs).
///
/// The DC gain of a section is `m0 + m2` exactly, whatever the rounding of `c1..c3`: a
/// constant input settles to `v3 = 0`, `v1 = 0`, `v2 = x`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Biquad {
    /// `[u, e, c2, c3]`: the loop coefficients, `c1 = u − e`.
    c: [f32; 4],
    /// `[m0, m1, m2]`: the output mix of input, band-pass and low-pass signals.
    m: [f32; 3],
}

impl Biquad {
    /// The section that passes its input unchanged.
    pub const IDENTITY: Self = Self {
        c: [0.0; 4],
        m: [1.0, 0.0, 0.0],
    };

    /// The section with the transfer function of a scipy `sos` row
    /// `[b0, b1, b2, a0, a1, a2]` (designed in f64; the coefficients are rounded to f32
    /// only after the conversion). `None` unless every value is finite, `a0 ≠ 0` and
    /// both poles lie strictly inside the unit circle.
    pub fn from_row(row: [f64; 6]) -> Option<Self> {
        let [b0, b1, b2, a0, a1, a2] = row;
        if !row.iter().all(|v| v.is_finite()) || a0 == 0.0 {
            return None;
        }
        let [b0, b1, b2, a1, a2] = [b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0];
        // A(−1), A(1) > 0 and a2 < 1: the stability triangle (Jury / Schur-Cohn).
        let den_nyquist = 1.0 - a1 + a2;
        let den_dc = 1.0 + a1 + a2;
        if !(den_nyquist > 0.0 && den_dc > 0.0 && a2 < 1.0) {
            return None;
        }
        let c1 = 0.25 * den_nyquist;
        let c3 = 0.25 * den_dc;
        let c2 = libm::sqrt(c1 * c3);
        // Numerator = m0·A(z) + m1·c2·(1 − z⁻²) + m2·c3·(1 + z⁻¹)², matched at z = −1,
        // z = 1 and in b0 − b2.
        let m0 = (b0 - b1 + b2) / den_nyquist;
        let m2 = (b0 + b1 + b2) / den_dc - m0;
        let m1 = (b0 - b2 - m0 * (1.0 - a2)) / (2.0 * c2);
        let (u, e) = if c1 >= 0.5 {
            (1.0, 1.0 - c1)
        } else {
            (0.0, -c1)
        };
        let biquad = Self {
            c: [u, e as f32, c2 as f32, c3 as f32],
            m: [m0 as f32, m1 as f32, m2 as f32],
        };
        biquad
            .c
            .iter()
            .chain(&biquad.m)
            .all(|v| v.is_finite())
            .then_some(biquad)
    }

    /// Gain at DC of the f32 section, `m0 + m2`, evaluated in f64.
    pub fn dc_gain(&self) -> f64 {
        f64::from(self.m[0]) + f64::from(self.m[2])
    }

    /// Filter one sample through this section, updating its state `[s1, s2.hi, s2.lo]`.
    #[inline]
    fn process(&self, s: &mut [f32; 3], x: f32) -> f32 {
        let [u, e, c2, c3] = self.c;
        let [m0, m1, m2] = self.m;
        let [s1, hi, lo] = *s;
        let v3 = (x - hi) - lo;
        let delta = c2 * v3 - e * s1;
        let v1 = u * s1 + delta;
        let d = c2 * s1 + c3 * v3;
        let v2 = hi + (lo + d);
        // s2 ← s2 + 2·d, as hi + lo: TwoSum(hi, lo + 2·d) is exact.
        let a = lo + 2.0 * d;
        let t = hi + a;
        let t_a = t - hi;
        let err = (hi - (t - t_a)) + (a - t_a);
        // s1 ← 2·v1 − s1 = (2u − 1)·s1 + 2·delta, with 2u − 1 = ±1 exactly.
        *s = [(2.0 * u - 1.0) * s1 + 2.0 * delta, t, err];
        m0 * x + m1 * v1 + m2 * v2
    }

    /// Steady state `[s1, s2.hi, s2.lo]` and output for the constant input `x`; a fixed
    /// point of [`Self::process`] bit for bit.
    fn settled(&self, x: f32) -> ([f32; 3], f32) {
        let [m0, m1, m2] = self.m;
        ([0.0, x, 0.0], m0 * x + m1 * 0.0 + m2 * x)
    }
}

/// The coefficients of a cascade of up to [`MAX_SECTIONS`] sections.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sos {
    sections: [Biquad; MAX_SECTIONS],
    len: u8,
}

/// The state of one channel through a [`Sos`] cascade (three words per section).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SosState {
    s: [[f32; 3]; MAX_SECTIONS],
}

/// Inputs are clamped to ±`INPUT_LIMIT` (far beyond any rate a gyroscope reports), so
/// that for a Butterworth design no intermediate value can overflow f32 and the state
/// stays finite for every finite input: the largest state word seen for inputs bounded
/// by M is 36·M (order 8 at 0.49·fs, square wave near its resonance), and
/// 1e34 × 36 is 1/1000 of `f32::MAX`.
const INPUT_LIMIT: f32 = 1e34;

impl Sos {
    /// A cascade of the given sections; `None` if there are more than [`MAX_SECTIONS`].
    pub fn from_sections(sections: &[Biquad]) -> Option<Self> {
        if sections.len() > MAX_SECTIONS {
            return None;
        }
        let mut all = [Biquad::IDENTITY; MAX_SECTIONS];
        all[..sections.len()].copy_from_slice(sections);
        Some(Self {
            sections: all,
            len: sections.len() as u8,
        })
    }

    /// The first `len` (clamped to [`MAX_SECTIONS`]) of `sections`.
    pub(crate) fn from_array(sections: [Biquad; MAX_SECTIONS], len: usize) -> Self {
        Self {
            sections,
            len: len.min(MAX_SECTIONS) as u8,
        }
    }

    /// The sections in use, first applied first.
    pub fn sections(&self) -> &[Biquad] {
        &self.sections[..usize::from(self.len)]
    }

    /// Gain of the whole cascade at DC, in f64.
    pub fn dc_gain(&self) -> f64 {
        self.sections().iter().map(Biquad::dc_gain).product()
    }

    /// Filter one sample through the cascade, updating `state`. Inputs beyond ±1e34 are
    /// clamped; NaN propagates (reject it before, as the pipeline does).
    #[inline]
    pub fn process(&self, state: &mut SosState, x: f32) -> f32 {
        let mut y = x.clamp(-INPUT_LIMIT, INPUT_LIMIT);
        for (section, s) in self.sections().iter().zip(state.s.iter_mut()) {
            y = section.process(s, y);
        }
        y
    }

    /// Set `state` to the steady state for a constant input `x` (no start-up transient):
    /// feeding `x` afterwards leaves the state unchanged, bit for bit.
    pub fn settle(&self, state: &mut SosState, x: f32) {
        let mut y = x.clamp(-INPUT_LIMIT, INPUT_LIMIT);
        for (section, s) in self.sections().iter().zip(state.s.iter_mut()) {
            (*s, y) = section.settled(y);
        }
    }
}

impl SosState {
    /// All-zero state.
    pub const fn new() -> Self {
        Self {
            s: [[0.0; 3]; MAX_SECTIONS],
        }
    }

    /// True if every state word is finite.
    pub fn is_finite(&self) -> bool {
        self.s.iter().flatten().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// scipy.signal.butter(2, 10, fs=50, output='sos')[0]
    const ROW: [f64; 6] = [
        0.206_572_083_826_147_92,
        0.413_144_167_652_295_84,
        0.206_572_083_826_147_92,
        1.0,
        -0.369_527_377_351_241_4,
        0.195_815_712_655_833_06,
    ];

    /// The same row in transposed direct form II, in f64 (what `sosfilt` does).
    fn df2t(row: [f64; 6], x: &[f64]) -> Vec<f64> {
        let [b0, b1, b2, _, a1, a2] = row;
        let mut s = [0.0; 2];
        x.iter()
            .map(|&x| {
                let y = b0 * x + s[0];
                s[0] = b1 * x - a1 * y + s[1];
                s[1] = b2 * x - a2 * y;
                y
            })
            .collect()
    }

    #[test]
    fn identity_passes_through() {
        let sos = Sos::from_sections(&[Biquad::IDENTITY]).unwrap();
        let mut st = SosState::new();
        assert_eq!(sos.process(&mut st, 3.5), 3.5);
        assert_eq!(sos.process(&mut st, -1.0), -1.0);
        let row = Biquad::from_row([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]).unwrap();
        let sos = Sos::from_sections(&[row]).unwrap();
        assert_eq!(sos.process(&mut st, 3.5), 3.5);
    }

    #[test]
    fn too_many_sections_refused() {
        assert!(Sos::from_sections(&[Biquad::IDENTITY; MAX_SECTIONS + 1]).is_none());
    }

    #[test]
    fn unstable_or_invalid_rows_refused() {
        // Poles at z = 1, z = −1, on the unit circle (a2 = 1) and outside it.
        for a in [
            [-2.0, 1.0],
            [2.0, 1.0],
            [0.0, 1.0],
            [-2.5, 1.5],
            [0.0, -1.2],
        ] {
            assert_eq!(Biquad::from_row([1.0, 0.0, 0.0, 1.0, a[0], a[1]]), None);
        }
        assert_eq!(Biquad::from_row([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]), None);
        assert_eq!(Biquad::from_row([f64::NAN, 0.0, 0.0, 1.0, 0.0, 0.0]), None);
    }

    #[test]
    fn realises_general_rows() {
        // A low-pass row, a first-order row (pole and zero at 0), a high-pass-like
        // row with real poles of both signs, a resonator near z = −1, and a row with a0 ≠ 1.
        let rows = [
            ROW,
            [0.3, 0.3, 0.0, 1.0, -0.4, 0.0],
            [0.5, -1.0, 0.5, 1.0, 0.1, -0.56],
            [0.1, 0.0, -0.1, 1.0, 1.6, 0.9],
            [2.0, 1.0, 0.5, 2.0, -0.6, 0.3],
        ];
        let x: Vec<f64> = (0..200)
            .map(|i| if i % 37 < 20 { 1.0 } else { -0.5 })
            .collect();
        for row in rows {
            let sos = Sos::from_sections(&[Biquad::from_row(row).unwrap()]).unwrap();
            let mut st = SosState::new();
            let want = df2t(row.map(|v| v / row[3]), &x);
            for (&xi, w) in x.iter().zip(want) {
                let y = sos.process(&mut st, xi as f32);
                assert!((f64::from(y) - w).abs() < 1e-6, "{row:?}: {y} vs {w}");
            }
            let dc = (row[0] + row[1] + row[2]) / (row[3] + row[4] + row[5]);
            assert!((sos.dc_gain() - dc).abs() < 1e-6 * dc.abs().max(1.0));
        }
    }

    #[test]
    fn settle_gives_steady_output() {
        let sos = Sos::from_sections(&[Biquad::from_row(ROW).unwrap()]).unwrap();
        let mut st = SosState::new();
        sos.settle(&mut st, 2.0);
        let settled = st;
        let gain = sos.dc_gain() as f32;
        for _ in 0..5 {
            assert!((sos.process(&mut st, 2.0) - 2.0 * gain).abs() < 1e-6);
        }
        assert_eq!(st, settled);
    }

    #[test]
    fn huge_inputs_are_clamped() {
        let sos = Sos::from_sections(&[Biquad::from_row(ROW).unwrap()]).unwrap();
        let mut st = SosState::new();
        for i in 0..100 {
            let x = if i % 2 == 0 { f32::MAX } else { f32::MIN };
            assert!(sos.process(&mut st, x).is_finite());
        }
        assert!(st.is_finite());
    }
}
