//! Correction of the sensor's scale and temperature errors, applied to every input sample.
//!
//! The sensor is modelled (the simulator's terms `scale_factor`, `scale_asymmetry`,
//! `temperature_scale`, `temperature_bias`, fitted by `gyro-cli diagnose`) as
//!
//! ```text
//! m = r · (1 + k + a·sign(r) + s·ΔT) + c·ΔT        (+ bias and noise, left to the pipeline)
//! ```
//!
//! with `r` the true rate, `m` the measured rate, `ΔT = T − T_ref` the temperature change
//! from a reference, and `k`, `a`, `s`, `c` the [`Correction`] settings. The correction is
//! the exact inverse:
//!
//! ```text
//! u = m − c·ΔT
//! r = u / (1 + k + a·sign(u) + s·ΔT)
//! ```
//!
//! `sign(u) = sign(r)` because the scale is positive (validation keeps it so), which is what
//! makes the inverse exact. Bias and noise are not part of the model: they pass through
//! divided by the scale, and the bias is then estimated at rest as before.
//!
//! Why in the core: a scale error of 1% is 0.9° on a 90° turn, more than the whole error
//! budget, and a temperature bias integrates over every movement; the firmware must apply
//! the same correction the host scores, so it lives in the pipeline both run.

use crate::error::{check_range, Error};

/// Largest temperature change from the reference (°C) the correction uses: ΔT is clamped to
/// ±this. Validation checks the scale against it.
pub const MAX_DELTA_C: f32 = 100.0;

/// Plausible sensor temperatures (°C). Readings outside are treated as invalid (like NaN):
/// a corrupted CRM100 frame decodes to thousands of degrees.
pub const TEMPERATURE_RANGE_C: (f32, f32) = (-100.0, 200.0);

/// Smallest scale (the denominator `1 + k + a·sign + s·ΔT`) a valid correction may reach
/// for any sign and any `|ΔT| ≤` [`MAX_DELTA_C`]: a gyro reading half its rate is broken,
/// not miscalibrated, and the bound keeps the division far from zero.
pub const MIN_SCALE: f32 = 0.5;

/// Correction settings: the inverse of the sensor's scale and temperature errors. The
/// default is the identity.
///
/// The sensor reads `m = r·(1 + k + a·sign(r) + s·ΔT) + c·ΔT` for the true rate `r` (bias
/// and noise aside; `ΔT` from `temperature_ref_c`); the correction gives back
/// `r = (m − c·ΔT) / (1 + k + a·sign(m − c·ΔT) + s·ΔT)`, exactly, since the scale is kept
/// positive. See [`Correction::measured_dps`] and [`Correction::corrected_dps`].
///
/// In a model file (`config.correction`), every key is optional:
///
/// ```json
/// {"scale_k": 0.02, "asymmetry_k": 0.0, "bias_dps_per_c": 0.05, "scale_per_c": 0.0,
///  "temperature_ref_c": 25.0}
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct Correction {
    /// Scale error `k` (1 = 100%): the sensor reads `r·(1 + k)`. Within ±0.25.
    pub scale_k: f32,
    /// Scale asymmetry `a`: the sensor reads `r·(1 + a)` for positive rates and
    /// `r·(1 − a)` for negative ones. Within ±0.25.
    pub asymmetry_k: f32,
    /// Temperature bias `c` (deg/s per °C of ΔT). Within ±10.
    pub bias_dps_per_c: f32,
    /// Temperature scale `s` (1/°C): the sensor reads `r·(1 + s·ΔT)`. Limited so that the
    /// scale stays at least [`MIN_SCALE`] for `|ΔT| ≤` [`MAX_DELTA_C`].
    pub scale_per_c: f32,
    /// Reference temperature `T_ref` (°C) of ΔT. `None`: the first valid temperature the
    /// pipeline receives (the temperature at the start of the run, as when fitting).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub temperature_ref_c: Option<f32>,
}

impl Correction {
    /// No correction: every sample passes unchanged (bit for bit).
    pub const IDENTITY: Self = Self {
        scale_k: 0.0,
        asymmetry_k: 0.0,
        bias_dps_per_c: 0.0,
        scale_per_c: 0.0,
        temperature_ref_c: None,
    };

    /// Check the settings: each finite and in its range, the scale at least [`MIN_SCALE`]
    /// for every sign and `|ΔT| ≤` [`MAX_DELTA_C`], the reference temperature plausible.
    pub fn validate(&self) -> Result<(), Error> {
        let k = check_range("correction.scale_k", self.scale_k.into(), -0.25, 0.25)?;
        let a = check_range(
            "correction.asymmetry_k",
            self.asymmetry_k.into(),
            -0.25,
            0.25,
        )?;
        check_range(
            "correction.bias_dps_per_c",
            self.bias_dps_per_c.into(),
            -10.0,
            10.0,
        )?;
        let s = check_range("correction.scale_per_c", self.scale_per_c.into(), -1.0, 1.0)?;
        // With |k|, |a| ≤ 0.25 the scale without temperature is at least 0.5; only the
        // temperature term can take it lower.
        let lowest = 1.0 + k - libm::fabs(a) - libm::fabs(s) * f64::from(MAX_DELTA_C);
        if lowest < f64::from(MIN_SCALE) {
            return Err(Error::OutOfRange("correction.scale_per_c"));
        }
        if let Some(t) = self.temperature_ref_c {
            let (lo, hi) = TEMPERATURE_RANGE_C;
            check_range(
                "correction.temperature_ref_c",
                t.into(),
                lo.into(),
                hi.into(),
            )?;
        }
        Ok(())
    }

    /// True if this is [`Self::IDENTITY`], reference temperature included.
    pub fn is_exactly_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// True if this is the identity (the reference temperature aside).
    pub fn is_identity(&self) -> bool {
        self.scale_k == 0.0
            && self.asymmetry_k == 0.0
            && self.bias_dps_per_c == 0.0
            && self.scale_per_c == 0.0
    }

    /// The forward model: what the sensor reads for the true rate `rate_dps` at a
    /// temperature change `delta_c` (°C) from the reference (bias and noise aside).
    pub fn measured_dps(&self, rate_dps: f32, delta_c: f32) -> f32 {
        rate_dps * self.scale(sign(rate_dps), delta_c) + self.bias_dps_per_c * delta_c
    }

    /// The inverse: the true rate for the reading `measured_dps` at a temperature change
    /// `delta_c` (°C). `delta_c` is clamped to ±[`MAX_DELTA_C`]; valid settings keep the
    /// divisor at least [`MIN_SCALE`].
    pub fn corrected_dps(&self, measured_dps: f32, delta_c: f32) -> f32 {
        let corrector = Corrector {
            scale_k: self.scale_k,
            asymmetry_k: self.asymmetry_k,
            bias_dps_per_c: self.bias_dps_per_c,
            scale_per_c: self.scale_per_c,
            reference_c: f32::NAN,
            delta_c: 0.0,
        };
        corrector.invert(measured_dps, clamp_delta(delta_c))
    }

    /// `1 + k + a·sign + s·ΔT`.
    fn scale(&self, sign: f32, delta_c: f32) -> f32 {
        1.0 + self.scale_k + self.asymmetry_k * sign + self.scale_per_c * delta_c
    }
}

/// −1, 0 or +1 (0 for ±0 and NaN).
#[inline]
fn sign(x: f32) -> f32 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// ΔT clamped to ±[`MAX_DELTA_C`] (NaN becomes 0).
#[inline]
fn clamp_delta(delta_c: f32) -> f32 {
    if delta_c.is_nan() {
        0.0
    } else {
        delta_c.clamp(-MAX_DELTA_C, MAX_DELTA_C)
    }
}

/// A validated [`Correction`] with the temperature state it needs at run time: the
/// reference temperature (once known) and the last valid temperature change.
///
/// Non-finite or implausible temperatures (outside [`TEMPERATURE_RANGE_C`]) are ignored:
/// the last valid temperature change stays in use, and until a valid temperature has been
/// seen ΔT is 0 (no temperature terms).
///
/// 24 bytes: the pipeline's whole state has a budget (512 bytes), so the reference is an
/// `f32` that is NaN until known rather than an `Option`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corrector {
    scale_k: f32,
    asymmetry_k: f32,
    bias_dps_per_c: f32,
    scale_per_c: f32,
    /// NaN until known.
    reference_c: f32,
    delta_c: f32,
}

impl Corrector {
    /// A corrector for validated `settings`.
    pub fn try_new(settings: &Correction) -> Result<Self, Error> {
        settings.validate()?;
        Ok(Self {
            scale_k: settings.scale_k,
            asymmetry_k: settings.asymmetry_k,
            bias_dps_per_c: settings.bias_dps_per_c,
            scale_per_c: settings.scale_per_c,
            reference_c: settings.temperature_ref_c.unwrap_or(f32::NAN),
            delta_c: 0.0,
        })
    }

    /// The settings, with the reference temperature once it is known.
    pub fn settings(&self) -> Correction {
        Correction {
            scale_k: self.scale_k,
            asymmetry_k: self.asymmetry_k,
            bias_dps_per_c: self.bias_dps_per_c,
            scale_per_c: self.scale_per_c,
            temperature_ref_c: self.reference_c(),
        }
    }

    /// The reference temperature (°C), once known.
    pub fn reference_c(&self) -> Option<f32> {
        (!self.reference_c.is_nan()).then_some(self.reference_c)
    }

    /// The temperature change in use (°C): from the last valid temperature, clamped to
    /// ±[`MAX_DELTA_C`]; 0 until a valid temperature has been seen.
    pub const fn delta_c(&self) -> f32 {
        self.delta_c
    }

    /// Take a temperature reading (°C). The first valid one becomes the reference if the
    /// settings have none. Returns false (and changes nothing) if the reading is not finite
    /// or outside [`TEMPERATURE_RANGE_C`].
    #[inline]
    pub fn observe_temperature(&mut self, temperature_c: f32) -> bool {
        let (lo, hi) = TEMPERATURE_RANGE_C;
        // `contains` is false for NaN; infinities are outside the range.
        if !(lo..=hi).contains(&temperature_c) {
            return false;
        }
        if self.reference_c.is_nan() {
            self.reference_c = temperature_c;
        }
        self.delta_c = clamp_delta(temperature_c - self.reference_c);
        true
    }

    /// Correct a reading for scale and asymmetry only (no temperature terms, ΔT = 0).
    #[inline]
    pub fn correct(&self, measured_dps: f32) -> f32 {
        self.invert(measured_dps, 0.0)
    }

    /// Correct a reading at the current temperature change ([`Self::delta_c`]).
    #[inline]
    pub fn correct_at_temperature(&self, measured_dps: f32) -> f32 {
        self.invert(measured_dps, self.delta_c)
    }

    /// The inverse of the model at `delta_c` (already clamped).
    #[inline]
    fn invert(&self, measured_dps: f32, delta_c: f32) -> f32 {
        let unbiased = measured_dps - self.bias_dps_per_c * delta_c;
        let scale =
            1.0 + self.scale_k + self.asymmetry_k * sign(unbiased) + self.scale_per_c * delta_c;
        unbiased / scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn finite_or_not() -> impl Strategy<Value = f32> {
        prop_oneof![
            4 => -1e4f32..1e4,
            1 => any::<f32>(),
            1 => Just(f32::NAN),
            1 => Just(f32::INFINITY),
            1 => Just(f32::NEG_INFINITY),
        ]
    }

    #[test]
    fn identity_is_exact() {
        let identity = Corrector::try_new(&Correction::IDENTITY).unwrap();
        let mut warm = identity;
        assert!(warm.observe_temperature(20.0));
        assert!(warm.observe_temperature(47.5));
        for m in [
            0.0,
            -0.0,
            1e-30,
            -3.25,
            123.456,
            1e4,
            f32::MIN_POSITIVE,
            0.1,
        ] {
            assert_eq!(identity.correct(m).to_bits(), m.to_bits());
            assert_eq!(warm.correct_at_temperature(m).to_bits(), m.to_bits());
        }
        assert!(Correction::default().is_identity());
        assert_eq!(Correction::default(), Correction::IDENTITY);
    }

    #[test]
    fn reference_is_the_first_valid_temperature() {
        let settings = Correction {
            bias_dps_per_c: 0.1,
            ..Correction::IDENTITY
        };
        let mut c = Corrector::try_new(&settings).unwrap();
        assert_eq!(c.reference_c(), None);
        assert!(!c.observe_temperature(f32::NAN));
        assert!(!c.observe_temperature(5000.0));
        assert_eq!(c.reference_c(), None);
        assert_eq!(c.delta_c(), 0.0);
        assert!(c.observe_temperature(25.0));
        assert!(c.observe_temperature(30.0));
        assert_eq!(c.reference_c(), Some(25.0));
        assert_eq!(c.delta_c(), 5.0);
        // Invalid readings keep the last valid change.
        assert!(!c.observe_temperature(f32::INFINITY));
        assert_eq!(c.delta_c(), 5.0);
        assert!((c.correct_at_temperature(1.5) - 1.0).abs() < 1e-6);
        // `correct` applies no temperature terms.
        assert_eq!(c.correct(1.5), 1.5);

        let fixed = Correction {
            temperature_ref_c: Some(20.0),
            ..settings
        };
        let mut c = Corrector::try_new(&fixed).unwrap();
        assert!(c.observe_temperature(25.0));
        assert_eq!(c.delta_c(), 5.0);
        // Far from the reference: clamped.
        assert!(c.observe_temperature(190.0));
        assert_eq!(c.delta_c(), MAX_DELTA_C);
    }

    #[test]
    fn invalid_settings_are_refused() {
        let base = Correction::IDENTITY;
        let cases = [
            (
                Correction {
                    scale_k: f32::NAN,
                    ..base
                },
                Error::NonFinite("correction.scale_k"),
            ),
            (
                Correction {
                    asymmetry_k: f32::INFINITY,
                    ..base
                },
                Error::NonFinite("correction.asymmetry_k"),
            ),
            (
                Correction {
                    bias_dps_per_c: f32::NEG_INFINITY,
                    ..base
                },
                Error::NonFinite("correction.bias_dps_per_c"),
            ),
            (
                Correction {
                    scale_per_c: f32::NAN,
                    ..base
                },
                Error::NonFinite("correction.scale_per_c"),
            ),
            (
                Correction {
                    temperature_ref_c: Some(f32::NAN),
                    ..base
                },
                Error::NonFinite("correction.temperature_ref_c"),
            ),
            (
                Correction {
                    scale_k: -0.3,
                    ..base
                },
                Error::OutOfRange("correction.scale_k"),
            ),
            (
                Correction {
                    scale_k: -0.2,
                    asymmetry_k: 0.2,
                    scale_per_c: 2e-3,
                    ..base
                },
                Error::OutOfRange("correction.scale_per_c"),
            ),
            (
                Correction {
                    temperature_ref_c: Some(-273.15),
                    ..base
                },
                Error::OutOfRange("correction.temperature_ref_c"),
            ),
        ];
        for (settings, error) in cases {
            assert_eq!(settings.validate(), Err(error), "{settings:?}");
            assert_eq!(Corrector::try_new(&settings), Err(error));
        }
        // The extremes that are allowed.
        let edge = Correction {
            scale_k: -0.25,
            asymmetry_k: 0.25,
            scale_per_c: 0.0,
            bias_dps_per_c: 10.0,
            temperature_ref_c: Some(200.0),
        };
        assert_eq!(edge.validate(), Ok(()));
        let warm = Correction {
            scale_per_c: 5e-3,
            ..base
        };
        assert_eq!(warm.validate(), Ok(()));
    }

    /// Model files: every key optional, unknown keys refused, an unknown reference left out.
    #[cfg(feature = "serde")]
    #[test]
    fn serde_defaults_and_unknown_keys() {
        let empty: Correction = serde_json::from_str("{}").unwrap();
        assert_eq!(empty, Correction::IDENTITY);
        let some: Correction =
            serde_json::from_str(r#"{"scale_k": 0.02, "temperature_ref_c": 25}"#).unwrap();
        assert_eq!(some.scale_k, 0.02);
        assert_eq!(some.temperature_ref_c, Some(25.0));
        assert!(serde_json::from_str::<Correction>(r#"{"scale": 0.02}"#).is_err());
        let text = serde_json::to_string(&Correction::IDENTITY).unwrap();
        assert!(!text.contains("temperature_ref_c"), "{text}");
        assert_eq!(
            serde_json::from_str::<Correction>(&text).unwrap(),
            Correction::IDENTITY
        );
    }

    /// Realistic corrections: a few percent of scale, asymmetry, 2e-3/°C, 0.2 deg/s/°C.
    fn realistic() -> impl Strategy<Value = Correction> {
        (-0.05f32..0.05, -0.02f32..0.02, -0.2f32..0.2, -2e-3f32..2e-3).prop_map(
            |(scale_k, asymmetry_k, bias_dps_per_c, scale_per_c)| Correction {
                scale_k,
                asymmetry_k,
                bias_dps_per_c,
                scale_per_c,
                temperature_ref_c: None,
            },
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The simulator's forward model, then the correction, gives back the rate within
        /// f32 rounding (of the model's own terms: cancellation of c·ΔT costs |c·ΔT|·ε).
        #[test]
        fn correction_inverts_the_sensor_model(
            settings in realistic(),
            rate_dps in -300f32..300.0,
            delta_c in -40f32..60.0,
        ) {
            prop_assert_eq!(settings.validate(), Ok(()));
            let measured = settings.measured_dps(rate_dps, delta_c);
            let back = settings.corrected_dps(measured, delta_c);
            let bias = settings.bias_dps_per_c * delta_c;
            let tolerance = 8.0 * f32::EPSILON * (rate_dps.abs() + bias.abs()) + 1e-30;
            prop_assert!(
                (back - rate_dps).abs() <= tolerance,
                "rate {} measured {} back {} tolerance {}", rate_dps, measured, back, tolerance
            );
            // Same through the run-time form, with a reference temperature.
            let mut corrector = Corrector::try_new(&Correction {
                temperature_ref_c: Some(20.0),
                ..settings
            }).unwrap();
            prop_assert!(corrector.observe_temperature(20.0 + delta_c));
            let delta_seen = corrector.delta_c();
            let measured = settings.measured_dps(rate_dps, delta_seen);
            let back = corrector.correct_at_temperature(measured);
            prop_assert!((back - rate_dps).abs() <= tolerance + 8.0 * f32::EPSILON * bias.abs());
        }

        /// Any input, valid settings or not: no panic; valid settings give finite output
        /// for finite input.
        #[test]
        fn no_panic_on_any_input(
            scale_k in finite_or_not(),
            asymmetry_k in finite_or_not(),
            bias_dps_per_c in finite_or_not(),
            scale_per_c in finite_or_not(),
            reference in proptest::option::of(finite_or_not()),
            temperatures in proptest::collection::vec(finite_or_not(), 1..8),
            measured in finite_or_not(),
        ) {
            let settings = Correction {
                scale_k: scale_k * 1e-4,
                asymmetry_k: asymmetry_k * 1e-4,
                bias_dps_per_c,
                scale_per_c: scale_per_c * 1e-6,
                temperature_ref_c: reference,
            };
            let Ok(mut corrector) = Corrector::try_new(&settings) else {
                return Ok(());
            };
            for t in temperatures {
                corrector.observe_temperature(t);
                prop_assert!(corrector.delta_c().abs() <= MAX_DELTA_C);
                let a = corrector.correct(measured);
                let b = corrector.correct_at_temperature(measured);
                // (Finite input to the pipeline is at most `max_abs_rate_dps` ≤ 1e30.)
                if measured.abs() <= 1e30 {
                    prop_assert!(a.is_finite() && b.is_finite(), "{} {} {:?}", a, b, corrector);
                }
            }
        }
    }
}
