//! The model file: a versioned JSON wrapper around the core's [`Config`].
//!
//! ```json
//! {"format": "gyro-model", "version": 1, "config": {"compensation": "paper", "paper": {"beta_per_s": 0.01, "b0_dps": 0.2, "o0_deg": 0.0}}}
//! ```
//! Missing settings take the core's defaults; unknown keys are errors (a typo must not be
//! silently ignored). `config.sample_rate_hz` is replaced by the log's rate when replaying.

use crate::sim::SensorModel;
use gyro_core::{Config, Pipeline};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` value of every model file.
pub const FORMAT: &str = "gyro-model";
/// The model file version this build reads and writes.
pub const VERSION: u32 = 1;

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
}

impl ModelFile {
    /// A model file holding `config`.
    pub fn new(config: Config) -> Self {
        Self {
            format: FORMAT.into(),
            version: VERSION,
            config,
            sensor: SensorModel::default(),
        }
    }
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
        /// Format found.
        format: String,
        /// Version found.
        version: u32,
    },
    /// The sensor model is invalid.
    #[error("{path}: {message}")]
    Sensor {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A setting is invalid.
    #[error("{path}: {source}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// Which setting.
        source: gyro_core::Error,
    },
}

/// Read and validate a model file.
pub fn load(path: &Path) -> Result<ModelFile, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|cause| ModelError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let model: ModelFile = serde_json::from_str(&text).map_err(|e| ModelError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    if model.format != FORMAT || model.version != VERSION {
        return Err(ModelError::Version {
            path: path.to_path_buf(),
            format: model.format,
            version: model.version,
        });
    }
    Pipeline::try_new(&model.config).map_err(|source| ModelError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
    model
        .sensor
        .validate()
        .map_err(|message| ModelError::Sensor {
            path: path.to_path_buf(),
            message,
        })?;
    Ok(model)
}

/// Write a model file (pretty JSON).
pub fn save(path: &Path, model: &ModelFile) -> Result<(), ModelError> {
    let io = |cause| ModelError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let text = serde_json::to_string_pretty(model).map_err(|e| io(std::io::Error::other(e)))?;
    std::fs::write(path, text + "\n").map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyro_core::Compensation;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("gyro-model-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn round_trip() {
        let mut config = Config {
            compensation: Compensation::Kalman,
            ..Config::default()
        };
        config.paper.b0_dps = 0.25;
        let path = temp("m.json");
        save(&path, &ModelFile::new(config)).unwrap();
        assert_eq!(load(&path).unwrap().config, config);
    }

    #[test]
    fn partial_file_takes_defaults_and_typos_are_errors() {
        let path = temp("partial.json");
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
    }
}
