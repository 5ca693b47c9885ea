//! Cascade of second-order sections (biquads): coefficients and state are separate types.
//!
//! One [`Sos`] (settings) can run any number of [`SosState`]s (channels); the state resets
//! without redesign. Each section runs in transposed direct form II, as `scipy.signal.sosfilt`.

/// Most sections a cascade holds: enough for a Butterworth design of order 8.
pub const MAX_SECTIONS: usize = 4;

/// One second-order section: `[b0, b1, b2, a1, a2]` with `a0 = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Biquad {
    /// Numerator `b0, b1, b2`, then denominator `a1, a2` (`a0` is 1).
    pub ba: [f32; 5],
}

impl Biquad {
    /// The section that passes its input unchanged.
    pub const IDENTITY: Self = Self {
        ba: [1.0, 0.0, 0.0, 0.0, 0.0],
    };

    /// Gain at DC, `(b0 + b1 + b2) / (1 + a1 + a2)`, evaluated in f64.
    pub fn dc_gain(&self) -> f64 {
        let [b0, b1, b2, a1, a2] = self.ba.map(f64::from);
        (b0 + b1 + b2) / (1.0 + a1 + a2)
    }
}

/// The coefficients of a cascade of up to [`MAX_SECTIONS`] sections.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sos {
    sections: [Biquad; MAX_SECTIONS],
    len: u8,
}

/// The state of one channel through a [`Sos`] cascade (two words per section).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SosState {
    s: [[f32; 2]; MAX_SECTIONS],
}

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

    /// Filter one sample through the cascade, updating `state`.
    #[inline]
    pub fn process(&self, state: &mut SosState, x: f32) -> f32 {
        let mut y = x;
        for (section, s) in self.sections().iter().zip(state.s.iter_mut()) {
            let [b0, b1, b2, a1, a2] = section.ba;
            let input = y;
            y = b0 * input + s[0];
            s[0] = b1 * input - a1 * y + s[1];
            s[1] = b2 * input - a2 * y;
        }
        y
    }

    /// Set `state` to the steady state for a constant input `x` (no start-up transient).
    pub fn settle(&self, state: &mut SosState, x: f32) {
        let mut input = x;
        for (section, s) in self.sections().iter().zip(state.s.iter_mut()) {
            let [_, b1, b2, a1, a2] = section.ba;
            let y = input * section.dc_gain() as f32;
            s[1] = b2 * input - a2 * y;
            s[0] = b1 * input - a1 * y + s[1];
            input = y;
        }
    }
}

impl SosState {
    /// All-zero state.
    pub const fn new() -> Self {
        Self {
            s: [[0.0; 2]; MAX_SECTIONS],
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

    #[test]
    fn identity_passes_through() {
        let sos = Sos::from_sections(&[Biquad::IDENTITY]).unwrap();
        let mut st = SosState::new();
        assert_eq!(sos.process(&mut st, 3.5), 3.5);
        assert_eq!(sos.process(&mut st, -1.0), -1.0);
    }

    #[test]
    fn too_many_sections_refused() {
        assert!(Sos::from_sections(&[Biquad::IDENTITY; MAX_SECTIONS + 1]).is_none());
    }

    #[test]
    fn settle_gives_steady_output() {
        let sos = Sos::from_sections(&[Biquad {
            ba: [0.2, 0.4, 0.2, -0.5, 0.3],
        }])
        .unwrap();
        let mut st = SosState::new();
        sos.settle(&mut st, 2.0);
        let gain = sos.dc_gain() as f32;
        for _ in 0..5 {
            assert!((sos.process(&mut st, 2.0) - 2.0 * gain).abs() < 1e-6);
        }
    }
}
