//! Return codes, and the names of the settings a refused configuration points at.

use core::ffi::{c_char, CStr};

/// What a function did. Every function of this API returns one; none aborts or panics.
///
/// Negative values are errors: nothing was changed (a push that fails takes no sample; a
/// refused configuration is named in `*field`).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroStatus {
    /// Done. From a push: the sample was taken and no output sample is due yet.
    Ok = 0,
    /// From a push: the sample was taken and completed an output sample, written to
    /// `*output` (once per decimation block: every 20th sample at 1 kHz in, 50 Hz out).
    Output = 1,
    /// A pointer argument that must not be NULL was NULL.
    NullPointer = -1,
    /// A pointer argument was not aligned for its type (the pipeline storage: to
    /// `GYRO_PIPELINE_ALIGN` bytes).
    Misaligned = -2,
    /// `storage_size` is less than `GYRO_PIPELINE_SIZE`.
    StorageTooSmall = -3,
    /// The pipeline pointer does not point at storage set up by `gyro_pipeline_init`.
    NotInitialized = -4,
    /// A setting of the configuration is NaN or infinite; `*field` names it.
    ConfigNonFinite = -5,
    /// A setting of the configuration is outside its valid range, or a flag or code is none
    /// of its values; `*field` names it.
    ConfigOutOfRange = -6,
    /// An output pointer points into the pipeline's own storage.
    Overlap = -7,
}

/// A setting of `GyroConfig`, as named by a refused configuration
/// (`gyro_pipeline_init`'s `*field`); `gyro_field_name` gives its name as text.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroField {
    /// No setting: the configuration was accepted.
    None = 0,
    /// A setting this version of the API has no code for.
    Unknown = 1,
    /// `sample_rate_hz`.
    SampleRateHz = 2,
    /// `output_rate_hz`.
    OutputRateHz = 3,
    /// The ratio of `sample_rate_hz` to `output_rate_hz` (the decimation factor).
    DecimationFactor = 4,
    /// `max_abs_rate_dps`.
    MaxAbsRateDps = 5,
    /// `filter.order`.
    FilterOrder = 6,
    /// `filter.cutoff_hz`.
    FilterCutoffHz = 7,
    /// `motion.enter_dps`.
    MotionEnterDps = 8,
    /// `motion.exit_dps`.
    MotionExitDps = 9,
    /// `motion.min_motion_s`.
    MotionMinMotionS = 10,
    /// `motion.min_rest_s`.
    MotionMinRestS = 11,
    /// `motion.initial_bias_dps`.
    MotionInitialBiasDps = 12,
    /// `compensation`.
    Compensation = 13,
    /// `paper.beta_per_s`.
    PaperBetaPerS = 14,
    /// `paper.b0_dps`.
    PaperB0Dps = 15,
    /// `paper.o0_deg`.
    PaperO0Deg = 16,
    /// `kalman.beta_per_s`.
    KalmanBetaPerS = 17,
    /// `kalman.bias_sigma_dps`.
    KalmanBiasSigmaDps = 18,
    /// `kalman.bias_mean_dps`.
    KalmanBiasMeanDps = 19,
    /// `kalman.rate_noise_dps`.
    KalmanRateNoiseDps = 20,
    /// `kalman.initial_bias_sigma_dps`.
    KalmanInitialBiasSigmaDps = 21,
    /// `correction.scale_k`.
    CorrectionScaleK = 22,
    /// `correction.asymmetry_k`.
    CorrectionAsymmetryK = 23,
    /// `correction.bias_dps_per_c`.
    CorrectionBiasDpsPerC = 24,
    /// `correction.scale_per_c`.
    CorrectionScalePerC = 25,
    /// `correction.has_temperature_ref_c`.
    CorrectionHasTemperatureRefC = 26,
    /// `correction.temperature_ref_c`.
    CorrectionTemperatureRefC = 27,
    /// `has_range_dps`.
    HasRangeDps = 28,
    /// `range_dps`.
    RangeDps = 29,
    /// `tightening.enabled`.
    TighteningEnabled = 30,
    /// `tightening.target_deg`.
    TighteningTargetDeg = 31,
    /// `tightening.tolerance_deg`.
    TighteningToleranceDeg = 32,
    /// `tightening.k_sigma`.
    TighteningKSigma = 33,
    /// `tightening.direction`.
    TighteningDirection = 34,
    /// `tightening.scale_sigma`.
    TighteningScaleSigma = 35,
}

/// Every field with its name: the names gyro-core's errors carry (`gyro_core::Error`), and
/// the flags and codes only the C struct has. One table for both directions.
pub(crate) const FIELDS: [(GyroField, &CStr); 36] = [
    (GyroField::None, c"none"),
    (GyroField::Unknown, c"unknown"),
    (GyroField::SampleRateHz, c"sample_rate_hz"),
    (GyroField::OutputRateHz, c"output_rate_hz"),
    (GyroField::DecimationFactor, c"decimation_factor"),
    (GyroField::MaxAbsRateDps, c"max_abs_rate_dps"),
    (GyroField::FilterOrder, c"filter.order"),
    (GyroField::FilterCutoffHz, c"filter.cutoff_hz"),
    (GyroField::MotionEnterDps, c"motion.enter_dps"),
    (GyroField::MotionExitDps, c"motion.exit_dps"),
    (GyroField::MotionMinMotionS, c"motion.min_motion_s"),
    (GyroField::MotionMinRestS, c"motion.min_rest_s"),
    (GyroField::MotionInitialBiasDps, c"motion.initial_bias_dps"),
    (GyroField::Compensation, c"compensation"),
    (GyroField::PaperBetaPerS, c"paper.beta_per_s"),
    (GyroField::PaperB0Dps, c"paper.b0_dps"),
    (GyroField::PaperO0Deg, c"paper.o0_deg"),
    (GyroField::KalmanBetaPerS, c"kalman.beta_per_s"),
    (GyroField::KalmanBiasSigmaDps, c"kalman.bias_sigma_dps"),
    (GyroField::KalmanBiasMeanDps, c"kalman.bias_mean_dps"),
    (GyroField::KalmanRateNoiseDps, c"kalman.rate_noise_dps"),
    (
        GyroField::KalmanInitialBiasSigmaDps,
        c"kalman.initial_bias_sigma_dps",
    ),
    (GyroField::CorrectionScaleK, c"correction.scale_k"),
    (GyroField::CorrectionAsymmetryK, c"correction.asymmetry_k"),
    (
        GyroField::CorrectionBiasDpsPerC,
        c"correction.bias_dps_per_c",
    ),
    (GyroField::CorrectionScalePerC, c"correction.scale_per_c"),
    (
        GyroField::CorrectionHasTemperatureRefC,
        c"correction.has_temperature_ref_c",
    ),
    (
        GyroField::CorrectionTemperatureRefC,
        c"correction.temperature_ref_c",
    ),
    (GyroField::HasRangeDps, c"has_range_dps"),
    (GyroField::RangeDps, c"range_dps"),
    (GyroField::TighteningEnabled, c"tightening.enabled"),
    (GyroField::TighteningTargetDeg, c"tightening.target_deg"),
    (
        GyroField::TighteningToleranceDeg,
        c"tightening.tolerance_deg",
    ),
    (GyroField::TighteningKSigma, c"tightening.k_sigma"),
    (GyroField::TighteningDirection, c"tightening.direction"),
    (GyroField::TighteningScaleSigma, c"tightening.scale_sigma"),
];

impl GyroField {
    /// The field gyro-core names `name`, or [`GyroField::Unknown`].
    pub(crate) fn from_core_name(name: &str) -> Self {
        FIELDS
            .iter()
            .find(|(_, text)| text.to_bytes() == name.as_bytes())
            .map_or(GyroField::Unknown, |&(field, _)| field)
    }
}

/// A configuration refused: which status, which setting.
pub(crate) type Refusal = (GyroStatus, GyroField);

/// gyro-core's validation error as a status and a field.
pub(crate) fn refusal(error: gyro_core::Error) -> Refusal {
    match error {
        gyro_core::Error::NonFinite(name) => {
            (GyroStatus::ConfigNonFinite, GyroField::from_core_name(name))
        }
        gyro_core::Error::OutOfRange(name) => (
            GyroStatus::ConfigOutOfRange,
            GyroField::from_core_name(name),
        ),
        // Only from `Pipeline::push_block`, which the C API does not call.
        gyro_core::Error::LengthMismatch(_) => (GyroStatus::ConfigOutOfRange, GyroField::Unknown),
    }
}

/// The name of the `GyroField` code `field` (`"motion.exit_dps"`, ...), a static
/// NUL-terminated string; `"unknown"` for a value that is no field.
#[no_mangle]
pub extern "C" fn gyro_field_name(field: u32) -> *const c_char {
    FIELDS
        .iter()
        .find(|&&(f, _)| f as u32 == field)
        .map_or(c"unknown", |&(_, text)| text)
        .as_ptr()
}

/// The name of the `GyroStatus` code `status` (`"GYRO_STATUS_NULL_POINTER"`, ...), a static
/// NUL-terminated string; `"GYRO_STATUS_UNKNOWN"` for a value that is no status.
#[no_mangle]
pub extern "C" fn gyro_status_name(status: i32) -> *const c_char {
    let name = match status {
        0 => c"GYRO_STATUS_OK",
        1 => c"GYRO_STATUS_OUTPUT",
        -1 => c"GYRO_STATUS_NULL_POINTER",
        -2 => c"GYRO_STATUS_MISALIGNED",
        -3 => c"GYRO_STATUS_STORAGE_TOO_SMALL",
        -4 => c"GYRO_STATUS_NOT_INITIALIZED",
        -5 => c"GYRO_STATUS_CONFIG_NON_FINITE",
        -6 => c"GYRO_STATUS_CONFIG_OUT_OF_RANGE",
        -7 => c"GYRO_STATUS_OVERLAP",
        _ => c"GYRO_STATUS_UNKNOWN",
    };
    name.as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_has_one_code_and_one_name() {
        for (i, (field, name)) in FIELDS.iter().enumerate() {
            assert_eq!(*field as u32, i as u32, "{name:?}: codes follow the table");
            // SAFETY: gyro_field_name returns a static NUL-terminated string.
            let named = unsafe { CStr::from_ptr(gyro_field_name(*field as u32)) };
            assert_eq!(named, *name);
            let Ok(text) = name.to_str() else {
                panic!("{name:?} is not UTF-8")
            };
            if *field != GyroField::Unknown {
                assert_eq!(GyroField::from_core_name(text), *field);
            }
        }
        assert_eq!(GyroField::from_core_name("no.such"), GyroField::Unknown);
        // SAFETY: as above.
        let named = unsafe { CStr::from_ptr(gyro_field_name(1000)) };
        assert_eq!(named, c"unknown");
    }

    #[test]
    fn core_errors_keep_their_kind_and_field() {
        assert_eq!(
            refusal(gyro_core::Error::NonFinite("motion.exit_dps")),
            (GyroStatus::ConfigNonFinite, GyroField::MotionExitDps)
        );
        assert_eq!(
            refusal(gyro_core::Error::OutOfRange("tightening.k_sigma")),
            (GyroStatus::ConfigOutOfRange, GyroField::TighteningKSigma)
        );
    }

    /// Every setting name gyro-core's sources put into an error has a code of its own: a
    /// new name in the core fails here instead of reaching C as `GYRO_FIELD_UNKNOWN`.
    #[test]
    fn every_name_gyro_core_reports_has_a_field() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../gyro-core/src");
        let mut names = std::vec::Vec::new();
        for entry in std::fs::read_dir(dir).expect("gyro-core's sources") {
            let path = entry.expect("a directory entry").path();
            let source = std::fs::read_to_string(&path).expect("a source file");
            for marker in ["check_range(", "NonFinite(", "OutOfRange("] {
                for (at, _) in source.match_indices(marker) {
                    let rest = source[at + marker.len()..].trim_start();
                    if let Some(quoted) = rest.strip_prefix('"') {
                        if let Some(end) = quoted.find('"') {
                            names.push(std::string::String::from(&quoted[..end]));
                        }
                    }
                }
            }
        }
        assert!(names.len() > 30, "found only {names:?}");
        for name in &names {
            assert_ne!(
                GyroField::from_core_name(name),
                GyroField::Unknown,
                "gyro-core reports `{name}`, which has no GyroField"
            );
        }
    }

    #[test]
    fn status_names_match_the_codes() {
        // SAFETY: gyro_status_name returns a static NUL-terminated string.
        let name = |status: GyroStatus| unsafe { CStr::from_ptr(gyro_status_name(status as i32)) };
        assert_eq!(name(GyroStatus::Ok), c"GYRO_STATUS_OK");
        assert_eq!(name(GyroStatus::Overlap), c"GYRO_STATUS_OVERLAP");
        assert_eq!(
            name(GyroStatus::ConfigOutOfRange),
            c"GYRO_STATUS_CONFIG_OUT_OF_RANGE"
        );
        // SAFETY: as above.
        let unknown = unsafe { CStr::from_ptr(gyro_status_name(42)) };
        assert_eq!(unknown, c"GYRO_STATUS_UNKNOWN");
    }
}
