//! The paper's error model: a first-order Gauss-Markov bias and its integral.
//!
//! Bias `b` with correlation time `T = 1/β`: `b' = −β b`, started from `b0`; misalignment
//! (angle error) `o' = b`, started from `o0`. Hence
//! `o(t) = o0 + (b0/β)(1 − e^{−βt})`, which tends to `o0 + b0 t` as `β → 0`.
//! Paper mode subtracts `o(t_m)` from the angle integrated over a movement of duration `t_m`
//! (Haid et al., "One-dimensional Orientation Using a Low-cost Inertial Sensor").

use crate::error::{check_range, Error};

/// Parameters of the paper's error model (fitted by `gyro-cli calibrate`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct GaussMarkov {
    /// Inverse correlation time β = 1/T (1/s), ≥ 0.
    pub beta_per_s: f32,
    /// Bias at the start of a movement, b0 (deg/s).
    pub b0_dps: f32,
    /// Misalignment at the start of a movement, o0 (deg).
    pub o0_deg: f32,
}

impl GaussMarkov {
    /// Check the parameters.
    pub fn validate(&self) -> Result<(), Error> {
        check_range("paper.beta_per_s", self.beta_per_s.into(), 0.0, 1e6)?;
        check_range("paper.b0_dps", self.b0_dps.into(), -1e4, 1e4)?;
        check_range("paper.o0_deg", self.o0_deg.into(), -1e6, 1e6)?;
        Ok(())
    }

    /// Modelled misalignment o(t) in degrees after `t_s` seconds of movement.
    pub fn misalignment_deg(&self, t_s: f32) -> f32 {
        // (1 − e^{−βt})/β = −expm1(−βt)/β, accurate for small βt; exactly t at β = 0.
        let integral_s = if self.beta_per_s > 0.0 {
            -libm::expm1f(-self.beta_per_s * t_s) / self.beta_per_s
        } else {
            t_s
        };
        self.o0_deg + self.b0_dps * integral_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_and_limits() {
        let gm = GaussMarkov {
            beta_per_s: 0.5,
            b0_dps: 0.2,
            o0_deg: 0.1,
        };
        let t = 3.0_f32;
        let expected = 0.1 + (0.2 / 0.5) * (1.0 - (-0.5_f32 * t).exp());
        assert!((gm.misalignment_deg(t) - expected).abs() < 1e-6);
        assert_eq!(gm.misalignment_deg(0.0), 0.1);

        let zero_beta = GaussMarkov {
            beta_per_s: 0.0,
            ..gm
        };
        assert!((zero_beta.misalignment_deg(t) - (0.1 + 0.2 * t)).abs() < 1e-6);
        let tiny_beta = GaussMarkov {
            beta_per_s: 1e-12,
            ..gm
        };
        assert!((tiny_beta.misalignment_deg(t) - (0.1 + 0.2 * t)).abs() < 1e-6);
    }

    #[test]
    fn negative_beta_refused() {
        let gm = GaussMarkov {
            beta_per_s: -1.0,
            ..Default::default()
        };
        assert_eq!(gm.validate(), Err(Error::OutOfRange("paper.beta_per_s")));
    }
}
