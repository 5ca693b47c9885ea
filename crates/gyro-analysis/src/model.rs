//! The model file: a versioned JSON wrapper around the core's [`Config`].
//!
//! ```json
//! {"format": "gyro-model", "version": 1, "config": {"compensation": "paper", "paper": {"beta_per_s": 0.01, "b0_dps": 0.2, "o0_deg": 0.0}}}
//! ```
//! Missing settings take the core's defaults; unknown keys are errors (a typo must not be
//! silently ignored). `config.sample_rate_hz` is replaced by the log's rate when replaying.
//!
//! Fitted sensor errors (from `diagnose`) go in two places:
//! - `config.correction` ([`gyro_core::Correction`]): scale, asymmetry and temperature
//!   errors, which the core removes from every sample — on the wrench as in `run`;
//! - `reference_delay_s`: the gyro's latency behind the reference, which only scoring uses
//!   (the reference is shifted by it before comparing; see [`crate::replay::ReplayOptions`]);
//! - `count_clock_ppm`: a sensor clock off its nominal rate in a log stamped by the sensor's
//!   sample count, which only scoring uses too (the reference is read at the gyro's own
//!   time), beside the scale it gives the angle in `config.correction.scale_k`.
//!
//! ```json
//! {"format": "gyro-model", "version": 1,
//!  "config": {"correction": {"scale_k": 0.02, "bias_dps_per_c": 0.05}},
//!  "reference_delay_s": 0.01}
//! ```
//! Both are left out when written as the identity and zero, so such files stay readable by
//! builds that predate them.

use gyro_core::{Config, Pipeline};
use gyro_sim::SensorModel;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` value of every model file.
pub const FORMAT: &str = "gyro-model";
/// The model file version this build reads and writes.
pub const VERSION: u32 = 1;
/// The largest |`reference_delay_s`| accepted (s): a gyro's latency is milliseconds; a
/// second is a wrong unit or a wrong sign convention, not a latency.
pub const MAX_REFERENCE_DELAY_S: f64 = 1.0;
/// The largest |`count_clock_ppm`| accepted (ppm): 10%, beyond the ±1–3% of a MEMS gyro's
/// internal oscillator.
pub const MAX_COUNT_CLOCK_PPM: f64 = 1e5;

/// A model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// File version ([`VERSION`]).
    pub version: u32,
    /// The pipeline configuration.
    #[serde(default)]
    pub config: Config,
    /// The sensor's noise and error model (for `simulate`, from `noise`/`calibrate`).
    #[serde(default)]
    pub sensor: SensorModel,
    /// The gyro lags the reference by this much (s; negative: it leads), as fitted by
    /// `diagnose` (effect `latency`). Applied when scoring, not by the core: `run` compares
    /// the angle at `t` with the reference at `t − reference_delay_s` (linear between grid
    /// slots), so that the error measures the sensor, not the logger's timing. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub reference_delay_s: f64,
    /// The sensor's sample clock runs fast by this (ppm; negative: slow) and the log's rows
    /// are stamped by its sample count, as fitted by `diagnose` (effect
    /// `clock_error_count_stamped`): the sample of stamp `t` was taken at `t / (1 + ε)`,
    /// so its lag behind the reference grows through the run. Applied when scoring, not by
    /// the core: `run` compares the angle at `t` with the reference at `t / (1 + ε) −
    /// reference_delay_s` (`t` from the log's first slot). The angle's scale, 1 + ε, is
    /// `config.correction.scale_k`'s, written with it. Within ±[`MAX_COUNT_CLOCK_PPM`];
    /// default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub count_clock_ppm: f64,
    /// The gyro's scale uncertainty left after calibration (relative, 0.01 = 1%), as
    /// `calibrate` measured it on runs it was not fitted on. The movement's σ knows the bias
    /// and the noise, not the scale: `run`'s tightening decision adds it to each movement's
    /// σ as this share of the angle (its `--scale-sigma`, unless given). Within 0..1;
    /// default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub scale_sigma: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl ModelFile {
    /// A model file holding `config`.
    pub fn new(config: Config) -> Self {
        Self {
            format: FORMAT.into(),
            version: VERSION,
            config,
            sensor: SensorModel::default(),
            reference_delay_s: 0.0,
            count_clock_ppm: 0.0,
            scale_sigma: 0.0,
        }
    }

    /// The sensor's full-scale range (deg/s) the pipeline flags saturation at:
    /// `config.range_dps` if set, else the sensor section's `range_dps` (whose default is
    /// the CRM100's ±300 deg/s, like the rest of the section); `None` when that is at or
    /// above `config.max_abs_rate_dps`, the plausibility limit: no range is known
    /// ([`ModelFile::drop_contradicted_range`]).
    pub fn range_dps(&self) -> Option<f32> {
        match self.config.range_dps {
            Some(range_dps) => Some(range_dps),
            None => {
                let range_dps = self.sensor.range_dps as f32;
                (range_dps < self.config.max_abs_rate_dps).then_some(range_dps)
            }
        }
    }

    /// The sensor section's range is the CRM100's unless something said otherwise: when
    /// readings of the logs a model is written from reach beyond it
    /// ([`range_contradicted`]), it is not this sensor's, and it is replaced by the
    /// plausibility limit (no range known: `run` flags clip plateaus only, `simulate`
    /// clips nowhere below it). Returns the note that says so, if it was replaced. A
    /// range set in `config.range_dps` is left alone: someone stated it.
    pub fn drop_contradicted_range(&mut self, largest_abs_rate_dps: f64) -> Option<String> {
        let note = contradicted_range_note(self.sensor.range_dps, largest_abs_rate_dps)?;
        if self.config.range_dps.is_some() {
            return None;
        }
        self.sensor.range_dps = f64::from(self.config.max_abs_rate_dps);
        Some(note)
    }
}

/// The largest |rate| (deg/s) among `rates_dps` that the pipeline would accept (finite,
/// within `max_abs_rate_dps`): what a log says of its sensor's range. 0 if none.
pub fn largest_plausible_abs_rate(
    rates_dps: impl IntoIterator<Item = f64>,
    max_abs_rate_dps: f32,
) -> f64 {
    rates_dps
        .into_iter()
        .map(f64::abs)
        .filter(|x| *x <= f64::from(max_abs_rate_dps))
        .fold(0.0, f64::max)
}

/// Whether readings up to `largest_abs_rate_dps` (deg/s) contradict a full-scale range of
/// `range_dps`: the pipeline's rule ([`gyro_core::beyond_range`]), a reading beyond the
/// range by more than its margin.
pub fn range_contradicted(range_dps: f64, largest_abs_rate_dps: f64) -> bool {
    gyro_core::beyond_range(range_dps as f32, largest_abs_rate_dps as f32)
}

/// What to say when readings up to `largest_abs_rate_dps` contradict the range
/// `range_dps` ([`range_contradicted`]); `None` if they do not.
pub fn contradicted_range_note(range_dps: f64, largest_abs_rate_dps: f64) -> Option<String> {
    range_contradicted(range_dps, largest_abs_rate_dps).then(|| {
        format!(
            "range: the logs read up to {largest_abs_rate_dps:.1} deg/s, beyond the sensor range of ±{range_dps} deg/s: that range is not this sensor's, and none is assumed (saturation is flagged on clip plateaus only, nothing is clipped in simulation); state the sensor's full scale as config.range_dps"
        )
    })
}

/// Why a model file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// Not readable.
    #[error("{path}: {cause}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause (in the message, not chained: it would print twice).
        cause: std::io::Error,
    },
    /// Not valid JSON for a model file.
    #[error("{path}:{line}:{column}: {message}")]
    Json {
        /// File.
        path: PathBuf,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Another format or version.
    #[error(
        "{path}: expected format `{FORMAT}` version {VERSION}, found `{format}` version {version}"
    )]
    Version {
        /// File.
        path: PathBuf,
        /// Format found (as [`gyro_log::excerpt`] shows it).
        format: String,
        /// Version found.
        version: u32,
    },
    /// The sensor model is invalid.
    #[error("{path}: {problem}")]
    Sensor {
        /// File.
        path: PathBuf,
        /// What is wrong (part of this message, not a separate cause).
        problem: gyro_sim::InvalidSensorModel,
    },
    /// `reference_delay_s` is not finite or beyond ±[`MAX_REFERENCE_DELAY_S`].
    #[error("{path}: reference_delay_s must be within ±{MAX_REFERENCE_DELAY_S} s, found {value}")]
    ReferenceDelay {
        /// File.
        path: PathBuf,
        /// The value found.
        value: f64,
    },
    /// `count_clock_ppm` is not finite or beyond ±[`MAX_COUNT_CLOCK_PPM`].
    #[error("{path}: count_clock_ppm must be within ±{MAX_COUNT_CLOCK_PPM} ppm, found {value}")]
    CountClock {
        /// File.
        path: PathBuf,
        /// The value found.
        value: f64,
    },
    /// `scale_sigma` is not within 0..1.
    #[error("{path}: scale_sigma must be within 0 and 1 (a share of the angle), found {value}")]
    ScaleSigma {
        /// File.
        path: PathBuf,
        /// The value found.
        value: f64,
    },
    /// A setting is invalid.
    #[error("{path}: {setting}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// Which setting (part of this message, not a separate cause: it would print
        /// twice).
        setting: gyro_core::Error,
    },
}

/// Read and validate a model file.
pub fn load(path: &Path) -> Result<ModelFile, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|cause| ModelError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    // A byte-order mark (as some Windows editors write) is not part of the JSON.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let model: ModelFile = serde_json::from_str(text).map_err(|e| ModelError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: json_message(&e),
    })?;
    if model.format != FORMAT || model.version != VERSION {
        return Err(ModelError::Version {
            path: path.to_path_buf(),
            format: gyro_log::excerpt(model.format.as_bytes()),
            version: model.version,
        });
    }
    Pipeline::try_new(&model.config).map_err(|setting| ModelError::Invalid {
        path: path.to_path_buf(),
        setting,
    })?;
    model
        .sensor
        .validate()
        .map_err(|problem| ModelError::Sensor {
            path: path.to_path_buf(),
            problem,
        })?;
    // (JSON has no NaN or infinity; the check keeps the bound honest for any caller.)
    let delay_ok = model.reference_delay_s.is_finite()
        && model.reference_delay_s.abs() <= MAX_REFERENCE_DELAY_S;
    if !delay_ok {
        return Err(ModelError::ReferenceDelay {
            path: path.to_path_buf(),
            value: model.reference_delay_s,
        });
    }
    if !(model.count_clock_ppm.is_finite() && model.count_clock_ppm.abs() <= MAX_COUNT_CLOCK_PPM) {
        return Err(ModelError::CountClock {
            path: path.to_path_buf(),
            value: model.count_clock_ppm,
        });
    }
    if !(0.0..=1.0).contains(&model.scale_sigma) {
        return Err(ModelError::ScaleSigma {
            path: path.to_path_buf(),
            value: model.scale_sigma,
        });
    }
    Ok(model)
}

/// serde_json's message without the position (the error gives it in front) and with every
/// quoted value longer than [`gyro_log::excerpt`] shows cut to that: a corrupt file must
/// not make a message hundreds of characters long.
fn json_message(error: &serde_json::Error) -> String {
    let full = error.to_string();
    let suffix = format!(" at line {} column {}", error.line(), error.column());
    let message = full.strip_suffix(&suffix).unwrap_or(&full);
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(open) = rest.find(['"', '`']) {
        let quote = &rest[open..=open];
        out.push_str(&rest[..=open]);
        rest = &rest[open + 1..];
        match rest.find(quote) {
            Some(close) => {
                out.push_str(&gyro_log::excerpt(&rest.as_bytes()[..close]));
                out.push_str(quote);
                rest = &rest[close + 1..];
            }
            None => break,
        }
    }
    out.push_str(rest);
    out
}

/// Write a model file (pretty JSON), whole ([`gyro_log::whole`]).
pub fn save(path: &Path, model: &ModelFile) -> Result<(), ModelError> {
    let io = |cause| ModelError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let text = serde_json::to_string_pretty(model).map_err(|e| io(std::io::Error::other(e)))?;
    gyro_log::whole::write(path, |w| {
        std::io::Write::write_all(w, (text + "\n").as_bytes())
    })
    .map_err(io)
}

#[cfg(test)]
mod tests {

    #[test]
    fn a_range_the_logs_read_beyond_is_dropped_and_one_they_keep_within_is_not() {
        let mut model = ModelFile::new(Config::default());
        assert_eq!(model.range_dps(), Some(300.0));
        // Within the range and its margin: kept.
        assert_eq!(model.drop_contradicted_range(301.4), None);
        assert_eq!(model.range_dps(), Some(300.0));
        // Beyond: no range, and a note that says why.
        let note = model.drop_contradicted_range(450.5).expect("dropped");
        assert!(note.contains("450.5") && note.contains("±300"), "{note}");
        assert_eq!(model.range_dps(), None);
        // A range stated in the configuration is someone's word: kept, whatever the logs.
        let mut stated = ModelFile::new(Config {
            range_dps: Some(250.0),
            ..Config::default()
        });
        assert_eq!(stated.drop_contradicted_range(450.5), None);
        assert_eq!(stated.range_dps(), Some(250.0));
        // What a log says of the range: its largest reading the pipeline would accept.
        let rates = [3.0, -451.0, f64::NAN, 2e4, -f64::INFINITY];
        assert_eq!(largest_plausible_abs_rate(rates, 1e4), 451.0);
        assert_eq!(largest_plausible_abs_rate([], 1e4), 0.0);
    }

    use super::*;
    use gyro_core::Compensation;

    /// A fresh folder, removed when the guard is dropped.
    fn temp_dir() -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix("gyro-model-test-")
            .tempdir()
            .unwrap()
    }

    #[test]
    fn a_count_clock_beyond_ten_percent_is_refused_naming_the_file() {
        let scratch = temp_dir();
        let path = scratch.path().join("clock.json");
        let model = ModelFile {
            count_clock_ppm: 2e5,
            ..ModelFile::new(Config::default())
        };
        save(&path, &model).unwrap();
        let e = load(&path).expect_err("20% is no clock error");
        assert!(matches!(e, ModelError::CountClock { .. }), "{e}");
        assert!(
            e.to_string().contains("clock.json") && e.to_string().contains("count_clock_ppm"),
            "{e}"
        );
        let fine = ModelFile {
            count_clock_ppm: -24_000.0,
            ..ModelFile::new(Config::default())
        };
        save(&path, &fine).unwrap();
        assert_eq!(
            load(&path).expect("within range").count_clock_ppm,
            -24_000.0
        );
    }

    #[test]
    fn round_trip() {
        let mut config = Config {
            compensation: Compensation::Kalman,
            ..Config::default()
        };
        config.paper.b0_dps = 0.25;
        let scratch = temp_dir();
        let path = scratch.path().join("m.json");
        save(&path, &ModelFile::new(config)).unwrap();
        assert_eq!(load(&path).unwrap().config, config);
    }

    #[test]
    fn correction_and_delay_round_trip() {
        let mut config = Config::default();
        config.correction.scale_k = 0.015;
        config.correction.asymmetry_k = -0.004;
        config.correction.bias_dps_per_c = 0.05;
        config.correction.scale_per_c = 8e-4;
        config.correction.temperature_ref_c = Some(24.5);
        let model = ModelFile {
            reference_delay_s: 0.0125,
            scale_sigma: 0.0016,
            ..ModelFile::new(config)
        };
        let scratch = temp_dir();
        let path = scratch.path().join("corrected.json");
        save(&path, &model).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\"reference_delay_s\": 0.0125"), "{text}");
        assert!(text.contains("\"scale_sigma\": 0.0016"), "{text}");
        assert!(text.contains("\"temperature_ref_c\": 24.5"), "{text}");
        assert_eq!(load(&path).unwrap(), model);
    }

    #[test]
    fn partial_file_takes_defaults_and_typos_are_errors() {
        let scratch = temp_dir();
        let path = scratch.path().join("partial.json");
        std::fs::write(
            &path,
            r#"{"format":"gyro-model","version":1,"config":{"compensation":"none"}}"#,
        )
        .unwrap();
        let model = load(&path).unwrap();
        assert_eq!(model.config.compensation, Compensation::None);
        assert_eq!(model.config.filter, Config::default().filter);

        std::fs::write(
            &path,
            r#"{"format":"gyro-model","version":1,"config":{"compensaton":"none"}}"#,
        )
        .unwrap();
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("compensaton"), "{err}");

        std::fs::write(&path, r#"{"format":"gyro-model","version":2}"#).unwrap();
        assert!(matches!(
            load(&path),
            Err(ModelError::Version { version: 2, .. })
        ));

        std::fs::write(&path, r#"{"format":"gyro-model","version":1,"config":{"filter":{"order":12,"cutoff_hz":10}}}"#).unwrap();
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("filter.order"), "{err}");

        // A typo in the filter section is an error like in every other section.
        std::fs::write(&path, r#"{"format":"gyro-model","version":1,"config":{"filter":{"order":2,"cutoff_hz":12.5,"cutof_hz":10}}}"#).unwrap();
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("cutof_hz"), "{err}");
    }
}
