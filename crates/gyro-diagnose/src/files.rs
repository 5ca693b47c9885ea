//! The runs of a diagnosis from log files, as `gyro-cli diagnose --train … --holdout …`
//! reads them: one home for the command line and the Python package (`gyro-py`).

use crate::{InputEntry, RealRun};
use gyro_log::repeated::{refuse_repeated_runs, RepeatedRun};
use gyro_log::{GridOptions, LogError, LogOptions};
use std::path::{Path, PathBuf};

/// How the logs are read and cut.
#[derive(Clone, Copy, Debug)]
pub struct FileOptions<'a> {
    /// The CSV and MCAP input options.
    pub input: &'a LogOptions,
    /// The grid (`--sample-rate-hz`, `--max-gap-s`).
    pub grid: &'a GridOptions,
    /// `--split-s`: cut every log into windows of this many seconds, each a run.
    pub split_s: Option<f64>,
}

/// The training and held-out runs, and each log's input report (training first).
#[derive(Debug)]
pub struct FileRuns {
    /// Runs to fit on.
    pub train: Vec<RealRun>,
    /// Runs to score on.
    pub holdout: Vec<RealRun>,
    /// Each log's input report, in the order given.
    pub inputs: Vec<InputEntry>,
}

/// Why the runs could not be read; the messages are `gyro-cli diagnose`'s.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// A log given twice.
    #[error(transparent)]
    Repeated(#[from] RepeatedRun),
    /// A log that cannot be read or placed on the grid.
    #[error(transparent)]
    Log(#[from] LogError),
    /// A log without reference.
    #[error("{}: no reference_deg column; diagnose compares the gyro with an encoder reference, so every {role} run needs one", .path.display())]
    NoReference {
        /// The log.
        path: PathBuf,
        /// "training", "held-out".
        role: String,
    },
    /// A window length that is not a positive number.
    #[error("--split-s {0}: expected a positive number of seconds")]
    SplitInvalid(f64),
    /// A log too short for one window.
    #[error("{}: shorter than half a --split-s window ({split_s} s)", .path.display())]
    ShorterThanSplit {
        /// The log.
        path: PathBuf,
        /// The window (s).
        split_s: f64,
    },
    /// A run whose statistics cannot be computed.
    #[error("{name}: {message}")]
    Prepare {
        /// The run (`file` or `file#k` for the k-th window).
        name: String,
        /// What is wrong (part of this message).
        message: String,
    },
}

/// The runs of `paths` (cut by `split_s`), each log's input report added to `inputs`;
/// `role` ("training", "held-out") names them in errors, `warn` takes the logs' notices.
pub fn load_runs(
    paths: &[PathBuf],
    role: &str,
    options: &FileOptions<'_>,
    inputs: &mut Vec<InputEntry>,
    warn: &mut dyn FnMut(&str),
) -> Result<Vec<RealRun>, LoadError> {
    let mut runs = Vec::new();
    for path in paths {
        let regular = gyro_log::load(path, options.input, options.grid, warn)?;
        runs.extend(runs_of_log(
            &path.display().to_string(),
            regular,
            role,
            options.split_s,
            inputs,
        )?);
    }
    Ok(runs)
}

/// The runs of one log already on its grid, named `name` (a file's path, or a name given
/// with arrays), cut by `split_s`; its input report added to `inputs`.
pub fn runs_of_log(
    name: &str,
    regular: gyro_log::RegularLog,
    role: &str,
    split_s: Option<f64>,
    inputs: &mut Vec<InputEntry>,
) -> Result<Vec<RealRun>, LoadError> {
    let path = PathBuf::from(name);
    inputs.push(InputEntry {
        file: name.to_string(),
        input: regular.quality.clone(),
    });
    if !regular.has_reference {
        return Err(LoadError::NoReference {
            path,
            role: role.to_string(),
        });
    }
    let pieces = match split_s {
        Some(s) if !(s.is_finite() && s > 0.0) => return Err(LoadError::SplitInvalid(s)),
        Some(s) => {
            let pieces = crate::split(&regular, s);
            if pieces.is_empty() {
                return Err(LoadError::ShorterThanSplit { path, split_s: s });
            }
            pieces
        }
        None => vec![regular],
    };
    let count = pieces.len();
    let mut runs = Vec::with_capacity(count);
    for (i, piece) in pieces.into_iter().enumerate() {
        let name = run_name(&path, i, count);
        let run = RealRun::prepare(name.clone(), piece).map_err(|e| LoadError::Prepare {
            name,
            message: e.to_string(),
        })?;
        runs.push(run);
    }
    Ok(runs)
}

/// The name of window `i` of `count` of `path`: the path, with `#k` when cut.
fn run_name(path: &Path, i: usize, count: usize) -> String {
    if count > 1 {
        format!("{}#{}", path.display(), i + 1)
    } else {
        path.display().to_string()
    }
}

/// The training and held-out runs of the logs `train` and `holdout`: a log given twice
/// refused first ([`refuse_repeated_runs`]), then each read in turn.
pub fn load_files(
    train: &[PathBuf],
    holdout: &[PathBuf],
    options: &FileOptions<'_>,
    warn: &mut dyn FnMut(&str),
) -> Result<FileRuns, LoadError> {
    refuse_repeated_runs(&[("training", train), ("hold-out", holdout)])?;
    let mut inputs = Vec::new();
    let train = load_runs(train, "training", options, &mut inputs, warn)?;
    let holdout = load_runs(holdout, "held-out", options, &mut inputs, warn)?;
    Ok(FileRuns {
        train,
        holdout,
        inputs,
    })
}
