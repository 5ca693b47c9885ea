//! The tightening decision: is a movement's angle inside the specified window?
//!
//! A guard-banded acceptance (ISO 14253-1, JCGM 106): with the angle's standard deviation
//! σ and a coverage factor k, a movement is
//! - `Ok` when its angle is inside the window by more than k·σ on both sides,
//! - `Nok` when it is outside by more than k·σ,
//! - `Recheck` when it is within k·σ of a limit (the measurement cannot tell),
//! - `Invalid` when the angle cannot be trusted at all (the sensor saturated, the movement
//!   was cut off, samples were rejected or missing during it).
//!
//! Only rotation in the tightening direction is judged: a turn the other way is not a
//! tightening and gets no verdict.
//!
//! ```
//! use gyro_core::{decide, Direction, Tightening, Verdict};
//! let window = Tightening { target_deg: 90.0, tolerance_deg: 5.0, ..Tightening::default() };
//! assert_eq!(decide(&window, 91.0, 0.5, false), Some(Verdict::Ok));
//! assert_eq!(decide(&window, 94.5, 0.5, false), Some(Verdict::Recheck));
//! assert_eq!(decide(&window, 97.0, 0.5, false), Some(Verdict::Nok));
//! assert_eq!(decide(&window, 91.0, 0.5, true), Some(Verdict::Invalid));
//! assert_eq!(decide(&window, -91.0, 0.5, false), None);
//! ```

use crate::error::{check_range, Error};

/// Which sign of the angle tightens.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Direction {
    /// A positive angle tightens (the default).
    #[default]
    Positive,
    /// A negative angle tightens.
    Negative,
}

/// The window a tightening's angle must fall in, and how surely.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct Tightening {
    /// Target angle (deg), in the tightening direction (> 0).
    pub target_deg: f32,
    /// Half-width of the window (deg): accepted angles lie in target ± tolerance.
    pub tolerance_deg: f32,
    /// Coverage factor k of the guard band k·σ (2 by default: about 95%).
    pub k_sigma: f32,
    /// Which sign of the angle tightens.
    pub direction: Direction,
    /// Relative standard uncertainty of the gyro's scale factor (e.g. 0.01 for 1%), added to
    /// the movement's σ in quadrature as `scale_sigma · |angle|`. The filter's σ knows the
    /// bias and the noise, not the scale: an uncalibrated MEMS gyro is off by 1–3% of the
    /// angle (the rasteiro recordings: 0–1.5%), more than the rest of the error. 0 by
    /// default (a calibrated scale, `config.correction`).
    pub scale_sigma: f32,
}

impl Default for Tightening {
    fn default() -> Self {
        Self {
            target_deg: 90.0,
            tolerance_deg: 5.0,
            k_sigma: 2.0,
            direction: Direction::Positive,
            scale_sigma: 0.0,
        }
    }
}

impl Tightening {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), Error> {
        check_range("tightening.target_deg", self.target_deg.into(), 1e-6, 1e6)?;
        check_range(
            "tightening.tolerance_deg",
            self.tolerance_deg.into(),
            0.0,
            f64::from(self.target_deg),
        )?;
        check_range("tightening.k_sigma", self.k_sigma.into(), 0.0, 100.0)?;
        check_range("tightening.scale_sigma", self.scale_sigma.into(), 0.0, 1.0)?;
        Ok(())
    }
}

/// The decision on one movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Verdict {
    /// Inside the window by more than k·σ.
    Ok,
    /// Outside the window by more than k·σ.
    Nok,
    /// Within k·σ of a limit: measure again (or by another means).
    Recheck,
    /// The angle cannot be trusted (saturated, cut off, samples rejected or missing).
    Invalid,
}

/// The verdict on a movement of `angle_deg` with standard deviation `angle_std_deg` (0 if
/// the compensation gives none: then only the scale term guards), `None` if it turned the
/// other way (not a tightening). `untrusted` makes it [`Verdict::Invalid`]. The guard band
/// is `k · sqrt(σ² + (scale_sigma · angle)²)`.
///
/// A σ that is not finite (or negative) cannot be guarded against: such a movement is
/// `Recheck` at best.
pub fn decide(
    window: &Tightening,
    angle_deg: f32,
    angle_std_deg: f32,
    untrusted: bool,
) -> Option<Verdict> {
    let turned = match window.direction {
        Direction::Positive => angle_deg,
        Direction::Negative => -angle_deg,
    };
    if turned.is_nan() {
        return Some(Verdict::Invalid);
    }
    if turned <= 0.0 {
        return None;
    }
    if untrusted {
        return Some(Verdict::Invalid);
    }
    let low = window.target_deg - window.tolerance_deg;
    let high = window.target_deg + window.tolerance_deg;
    let scale_deg = window.scale_sigma * turned;
    let sigma_deg = libm::sqrtf(angle_std_deg * angle_std_deg + scale_deg * scale_deg);
    let guard = if angle_std_deg >= 0.0 {
        window.k_sigma * sigma_deg
    } else {
        f32::NAN
    };
    if guard.is_nan() || guard < 0.0 || guard.is_infinite() {
        return Some(Verdict::Recheck);
    }
    Some(if turned > low + guard && turned < high - guard {
        Verdict::Ok
    } else if turned < low - guard || turned > high + guard {
        Verdict::Nok
    } else {
        Verdict::Recheck
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window() -> Tightening {
        Tightening {
            target_deg: 90.0,
            tolerance_deg: 5.0,
            k_sigma: 2.0,
            direction: Direction::Positive,
            scale_sigma: 0.0,
        }
    }

    /// A scale uncertainty widens the guard band with the angle: 1% of 90° is 0.9°.
    #[test]
    fn the_scale_uncertainty_adds_in_quadrature() {
        let w = Tightening {
            scale_sigma: 0.01,
            ..window()
        };
        // Guard 2·sqrt(0.1² + 0.935²) ≈ 1.88: 93.5 is within it of the upper limit 95.
        assert_eq!(decide(&w, 93.5, 0.1, false), Some(Verdict::Recheck));
        assert_eq!(decide(&window(), 93.5, 0.1, false), Some(Verdict::Ok));
        assert_eq!(decide(&w, 92.0, 0.1, false), Some(Verdict::Ok));
        assert!(Tightening {
            scale_sigma: -0.1,
            ..window()
        }
        .validate()
        .is_err());
    }

    #[test]
    fn the_guard_band_is_k_sigma_on_each_limit() {
        let w = window();
        // Limits 85 and 95; σ 1: guard 2.
        for (angle, verdict) in [
            (90.0, Verdict::Ok),
            (87.1, Verdict::Ok),
            (92.9, Verdict::Ok),
            (87.0, Verdict::Recheck),
            (86.0, Verdict::Recheck),
            (83.0, Verdict::Recheck),
            (82.9, Verdict::Nok),
            (93.5, Verdict::Recheck),
            (97.0, Verdict::Recheck),
            (97.1, Verdict::Nok),
            (10.0, Verdict::Nok),
        ] {
            assert_eq!(decide(&w, angle, 1.0, false), Some(verdict), "{angle}");
        }
        // A guard wider than the window: never Ok.
        assert_eq!(decide(&w, 90.0, 3.0, false), Some(Verdict::Recheck));
        // No σ: no guard band.
        assert_eq!(decide(&w, 94.9, 0.0, false), Some(Verdict::Ok));
        assert_eq!(decide(&w, 95.1, 0.0, false), Some(Verdict::Nok));
    }

    #[test]
    fn only_the_tightening_direction_is_judged() {
        let mut w = window();
        assert_eq!(decide(&w, -90.0, 0.1, false), None);
        assert_eq!(decide(&w, 0.0, 0.1, false), None);
        w.direction = Direction::Negative;
        assert_eq!(decide(&w, -90.0, 0.1, false), Some(Verdict::Ok));
        assert_eq!(decide(&w, 90.0, 0.1, false), None);
    }

    #[test]
    fn untrusted_or_unguardable_angles_are_never_ok() {
        let w = window();
        assert_eq!(decide(&w, 90.0, 0.1, true), Some(Verdict::Invalid));
        assert_eq!(decide(&w, f32::NAN, 0.1, false), Some(Verdict::Invalid));
        assert_eq!(decide(&w, 90.0, f32::NAN, false), Some(Verdict::Recheck));
        assert_eq!(
            decide(&w, 90.0, f32::INFINITY, false),
            Some(Verdict::Recheck)
        );
        assert_eq!(decide(&w, 90.0, -1.0, false), Some(Verdict::Recheck));
    }

    #[test]
    fn settings_are_checked() {
        assert!(window().validate().is_ok());
        let bad = Tightening {
            tolerance_deg: -1.0,
            ..window()
        };
        assert_eq!(
            bad.validate(),
            Err(Error::OutOfRange("tightening.tolerance_deg"))
        );
        let bad = Tightening {
            k_sigma: f32::NAN,
            ..window()
        };
        assert!(bad.validate().is_err());
    }
}
