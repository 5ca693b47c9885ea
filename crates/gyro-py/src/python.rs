//! The extension module `gyro._gyro`: the Rust layer on numpy arrays, the GIL released
//! while it works. The package `gyro` (python/gyro) wraps it: the JSON text becomes Python
//! objects there, the options arrive here as a dict.

use crate::{
    Arrays, CalibrateArgs, DiagnoseArgs, Error, NoiseOptions, RunOptions, RunOutput, Stream,
};
use clap::ValueEnum;
use gyro_analysis::replay::SeriesPoint;
use gyro_core::{Compensation, Direction, MotionState, Tightening, Verdict};
use gyro_log::{GridOptions, LogOptions};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

pyo3::create_exception!(
    _gyro,
    GyroError,
    PyValueError,
    "A log, a model or an option gyro refuses; the message is gyro-cli's."
);

impl From<Error> for PyErr {
    fn from(e: Error) -> Self {
        GyroError::new_err(e.0)
    }
}

/// One of an enum's names as the command line spells them.
fn choice<T: ValueEnum>(key: &str, value: &Bound<'_, PyAny>) -> PyResult<T> {
    let text: String = value.extract()?;
    T::from_str(&text, false).map_err(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        GyroError::new_err(format!(
            "invalid value '{text}' for {key}: expected one of {}",
            names.join(", ")
        ))
    })
}

/// `gyro-cli run`'s options from keyword arguments; an unknown one is a TypeError.
fn run_options(options: Option<&Bound<'_, PyDict>>, files: bool) -> PyResult<RunOptions> {
    let mut o = RunOptions::default();
    let Some(options) = options else {
        return Ok(o);
    };
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        let inputs = if files { Inputs::All } else { Inputs::Grid };
        if value.is_none() || log_option(&key, &value, &mut o.input, &mut o.grid, inputs)? {
            continue;
        }
        let f32_ = |v: &Bound<'_, PyAny>| v.extract::<f64>().map(|v| v as f32);
        match key.as_str() {
            "model" => o.run.model = Some(value.extract::<PathBuf>()?),
            "compensation" => {
                o.run.compensation = Some(match value.extract::<String>()?.as_str() {
                    "none" => Compensation::None,
                    "paper" => Compensation::Paper,
                    "kalman" => Compensation::Kalman,
                    other => {
                        return Err(GyroError::new_err(format!(
                            "invalid value '{other}' for compensation: expected one of none, paper, kalman"
                        )))
                    }
                })
            }
            "range_dps" => o.run.range_dps = Some(f32_(&value)?),
            "target_deg" => o.run.target_deg = Some(f32_(&value)?),
            "tolerance_deg" => o.run.tolerance_deg = Some(f32_(&value)?),
            "k_sigma" => o.run.k_sigma = f32_(&value)?,
            "tightening_direction" => {
                o.run.tightening_direction = match value.extract::<String>()?.as_str() {
                    "positive" => Direction::Positive,
                    "negative" => Direction::Negative,
                    other => {
                        return Err(GyroError::new_err(format!(
                            "invalid value '{other}' for tightening_direction: expected one of positive, negative"
                        )))
                    }
                }
            }
            "scale_sigma" => o.run.scale_sigma = Some(f32_(&value)?),
            "reference_delay_s" => o.run.reference_delay_s = Some(value.extract()?),
            "offline" => o.run.offline = value.extract()?,
            _ => return Err(unexpected(&key)),
        }
    }
    Ok(o)
}

/// The series as numpy arrays, a missing value NaN; `moving`: the motion state.
fn series<'py>(py: Python<'py>, points: &[SeriesPoint]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let f64s = |f: &dyn Fn(&SeriesPoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    let nan = f64::NAN;
    d.set_item("time_s", PyArray1::from_vec(py, f64s(&|p| p.time_s)))?;
    d.set_item(
        "rate_dps",
        PyArray1::from_vec(py, f64s(&|p| f64::from(p.rate_dps))),
    )?;
    d.set_item(
        "moving",
        PyArray1::from_vec(
            py,
            points
                .iter()
                .map(|p| p.motion == MotionState::Dynamic)
                .collect::<Vec<bool>>(),
        ),
    )?;
    d.set_item(
        "angle_deg",
        PyArray1::from_vec(py, f64s(&|p| f64::from(p.angle_deg))),
    )?;
    d.set_item(
        "raw_angle_deg",
        PyArray1::from_vec(py, f64s(&|p| f64::from(p.raw_angle_deg))),
    )?;
    d.set_item(
        "angle_std_deg",
        PyArray1::from_vec(py, f64s(&|p| p.angle_std_deg.map_or(nan, f64::from))),
    )?;
    d.set_item(
        "bias_dps",
        PyArray1::from_vec(py, f64s(&|p| f64::from(p.bias_dps))),
    )?;
    d.set_item(
        "reference_deg",
        PyArray1::from_vec(py, f64s(&|p| p.reference_deg.unwrap_or(nan))),
    )?;
    d.set_item(
        "error_deg",
        PyArray1::from_vec(py, f64s(&|p| p.error_deg().unwrap_or(nan))),
    )?;
    Ok(d)
}

/// The JSON text and the series arrays.
fn result<'py>(py: Python<'py>, out: RunOutput) -> PyResult<(String, Bound<'py, PyDict>)> {
    let s = series(py, &out.series)?;
    Ok((out.json, s))
}

/// A numpy array's values, borrowed when contiguous.
fn values<'a>(a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err("expected a contiguous float64 array"))
}

/// `gyro-cli run PATH --format json`: (JSON text, series arrays).
#[pyfunction]
#[pyo3(signature = (path, file, options=None))]
fn run_file<'py>(
    py: Python<'py>,
    path: PathBuf,
    file: String,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    let options = run_options(options, true)?;
    let out = py.detach(|| crate::run_file(&path, &file, &options))?;
    result(py, out)
}

/// `gyro-cli run` on arrays: (JSON text, series arrays).
#[pyfunction]
#[pyo3(signature = (time_s, rate_dps, reference_deg, temperature_c, nominal_rate_hz, name, first_line, options=None))]
#[allow(clippy::too_many_arguments)]
fn run_arrays<'py>(
    py: Python<'py>,
    time_s: PyReadonlyArray1<'py, f64>,
    rate_dps: PyReadonlyArray1<'py, f64>,
    reference_deg: Option<PyReadonlyArray1<'py, f64>>,
    temperature_c: Option<PyReadonlyArray1<'py, f64>>,
    nominal_rate_hz: Option<f64>,
    name: String,
    first_line: u64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    let options = run_options(options, false)?;
    let arrays = Arrays {
        time_s: values(&time_s)?,
        rate_dps: values(&rate_dps)?,
        reference_deg: reference_deg.as_ref().map(values).transpose()?,
        temperature_c: temperature_c.as_ref().map(values).transpose()?,
        nominal_rate_hz,
        first_line,
    };
    let out = py.detach(|| crate::run_arrays(&arrays, &name, &options))?;
    result(py, out)
}

/// `gyro-cli noise`'s options from keyword arguments (`inputs`: which log options apply).
fn noise_options(options: Option<&Bound<'_, PyDict>>, inputs: Inputs) -> PyResult<NoiseOptions> {
    let mut o = NoiseOptions::default();
    let Some(options) = options else {
        return Ok(o);
    };
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        if value.is_none() || log_option(&key, &value, &mut o.input, &mut o.grid, inputs)? {
            continue;
        }
        match key.as_str() {
            "static_only" => o.static_only = value.extract()?,
            "margin_s" => o.margin_s = value.extract()?,
            "min_rest_s" => o.min_rest_s = value.extract()?,
            "model" => o.model = Some(value.extract()?),
            "tau_grid" => o.tau_grid = value.extract()?,
            "per_decade" => o.per_decade = value.extract()?,
            "confidence" => o.confidence = value.extract()?,
            "psd_segment" => o.psd_segment = Some(value.extract()?),
            _ => return Err(unexpected(&key)),
        }
    }
    Ok(o)
}

/// `gyro-cli noise LOG... --format json`: the JSON text.
#[pyfunction]
#[pyo3(signature = (paths, options=None))]
fn noise_files(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let o = noise_options(options, Inputs::Rate)?;
    let files: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    Ok(py.detach(|| crate::noise_files(&paths, &files, &o))?)
}

/// A log as arrays from Python: (name, time_s, rate_dps, reference_deg, temperature_c,
/// nominal_rate_hz, first_line).
type ArrayLog<'py> = (
    String,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
    Option<PyReadonlyArray1<'py, f64>>,
    Option<PyReadonlyArray1<'py, f64>>,
    Option<f64>,
    u64,
);

/// The logs' names and arrays, borrowed.
fn array_logs<'a>(logs: &'a [ArrayLog<'_>]) -> PyResult<Vec<(&'a str, Arrays<'a>)>> {
    logs.iter()
        .map(
            |(
                name,
                time_s,
                rate_dps,
                reference_deg,
                temperature_c,
                nominal_rate_hz,
                first_line,
            )| {
                Ok((
                    name.as_str(),
                    Arrays {
                        time_s: values(time_s)?,
                        rate_dps: values(rate_dps)?,
                        reference_deg: reference_deg.as_ref().map(values).transpose()?,
                        temperature_c: temperature_c.as_ref().map(values).transpose()?,
                        nominal_rate_hz: *nominal_rate_hz,
                        first_line: *first_line,
                    },
                ))
            },
        )
        .collect()
}

/// `gyro-cli noise` on logs as arrays: the JSON text.
#[pyfunction]
#[pyo3(signature = (logs, options=None))]
fn noise_arrays(
    py: Python<'_>,
    logs: Vec<ArrayLog<'_>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let o = noise_options(options, Inputs::Grid)?;
    let logs = array_logs(&logs)?;
    Ok(py.detach(|| crate::noise_arrays(&logs, &o))?)
}

/// `gyro-cli calibrate`'s options from keyword arguments (`files`: the logs are files, the
/// hold-out runs and the input options given here).
fn calibrate_args(options: Option<&Bound<'_, PyDict>>, files: bool) -> PyResult<CalibrateArgs> {
    let mut a = CalibrateArgs {
        leave_one_out: true,
        ..CalibrateArgs::default()
    };
    let Some(options) = options else {
        return Ok(a);
    };
    let inputs = if files { Inputs::All } else { Inputs::Grid };
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        if value.is_none() || log_option(&key, &value, &mut a.input, &mut a.grid, inputs)? {
            continue;
        }
        match key.as_str() {
            "holdout" if files => a.holdout = value.extract()?,
            "objective" => a.objective = choice(&key, &value)?,
            "model" => a.model = Some(value.extract()?),
            "tau_s" => a.tau_s = Some(value.extract()?),
            "fit_motion" => a.fit_motion = value.extract()?,
            "reference_delay_s" => a.reference_delay_s = Some(value.extract()?),
            "leave_one_out" => a.leave_one_out = value.extract()?,
            "out" => a.out = Some(value.extract()?),
            _ => return Err(unexpected(&key)),
        }
    }
    Ok(a)
}

/// `gyro-cli calibrate LOG... --format json`: (JSON text, model file text).
#[pyfunction]
#[pyo3(signature = (logs, options=None))]
fn calibrate_files(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, String)> {
    let a = CalibrateArgs {
        logs,
        ..calibrate_args(options, true)?
    };
    Ok(py.detach(|| crate::calibrate_files(&a))?)
}

/// `gyro-cli calibrate` on runs as arrays: (JSON text, model file text).
#[pyfunction]
#[pyo3(signature = (train, holdout, options=None))]
fn calibrate_arrays(
    py: Python<'_>,
    train: Vec<ArrayLog<'_>>,
    holdout: Vec<ArrayLog<'_>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, String)> {
    let a = calibrate_args(options, false)?;
    let (train, holdout) = (array_logs(&train)?, array_logs(&holdout)?);
    Ok(py.detach(|| crate::calibrate_arrays(&train, &holdout, &a))?)
}

/// Which log-reading options a function takes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Inputs {
    /// The grid only (arrays).
    Grid,
    /// The grid, the time and rate columns and the MCAP channel (`noise`).
    Rate,
    /// All: also the reference and temperature columns and the reference topic.
    All,
}

/// Set the log-reading option `key` (`--sample-rate-hz`, `--max-gap-s`, the CSV columns,
/// the MCAP channel) if `inputs` takes it: false if it is none of them.
fn log_option(
    key: &str,
    value: &Bound<'_, PyAny>,
    input: &mut LogOptions,
    grid: &mut GridOptions,
    inputs: Inputs,
) -> PyResult<bool> {
    let columns = &mut input.columns;
    let mcap = &mut input.mcap;
    let files = inputs != Inputs::Grid;
    let all = inputs == Inputs::All;
    match key {
        "sample_rate_hz" => grid.sample_rate_hz = Some(value.extract()?),
        "max_gap_s" => grid.max_gap_s = value.extract()?,
        "time_column" if files => columns.time_column = value.extract()?,
        "time_unit" if files => columns.time_unit = choice(key, value)?,
        "rate_column" if files => columns.rate_column = value.extract()?,
        "rate_unit" if files => columns.rate_unit = choice(key, value)?,
        "reference_column" if all => columns.reference_column = Some(value.extract()?),
        "temperature_column" if all => columns.temperature_column = Some(value.extract()?),
        "topic" if files => mcap.topic = Some(value.extract()?),
        "reference_topic" if all => mcap.reference_topic = value.extract()?,
        "axis" if files => mcap.axis = choice(key, value)?,
        "flip" if files => mcap.flip = value.extract()?,
        "time_source" if files => mcap.time_source = choice(key, value)?,
        _ => return Ok(false),
    }
    Ok(true)
}

/// A keyword argument no function of the module takes.
fn unexpected(key: &str) -> PyErr {
    PyTypeError::new_err(format!("unexpected keyword argument '{key}'"))
}

/// `gyro-cli diagnose --train … --holdout … --format json`: the JSON text.
#[pyfunction]
#[pyo3(signature = (train, holdout, options=None))]
fn diagnose_files(
    py: Python<'_>,
    train: Vec<PathBuf>,
    holdout: Vec<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let a = DiagnoseArgs {
        train,
        holdout,
        ..diagnose_args(options, Inputs::All)?
    };
    Ok(py.detach(|| crate::diagnose_files(&a))?)
}

/// [`diagnose_files`] on logs given as arrays (name, columns): the JSON text.
#[pyfunction]
#[pyo3(signature = (train, holdout, options=None))]
fn diagnose_arrays(
    py: Python<'_>,
    train: Vec<ArrayLog<'_>>,
    holdout: Vec<ArrayLog<'_>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let a = diagnose_args(options, Inputs::Grid)?;
    let (train, holdout) = (array_logs(&train)?, array_logs(&holdout)?);
    Ok(py.detach(|| crate::diagnose_arrays(&train, &holdout, &a))?)
}

/// The diagnose options of `options`, the log-reading ones `inputs` takes.
fn diagnose_args(options: Option<&Bound<'_, PyDict>>, inputs: Inputs) -> PyResult<DiagnoseArgs> {
    let mut a = DiagnoseArgs::default();
    if let Some(options) = options {
        for (key, value) in options.iter() {
            let key: String = key.extract()?;
            if value.is_none() || log_option(&key, &value, &mut a.input, &mut a.grid, inputs)? {
                continue;
            }
            match key.as_str() {
                "split_s" => a.split_s = Some(value.extract()?),
                "model" => a.model = Some(value.extract()?),
                "seed" => a.seed = value.extract()?,
                "members" => a.members = value.extract()?,
                "candidate_members" => a.candidate_members = value.extract()?,
                "score_every_candidate" => a.score_every_candidate = value.extract()?,
                _ => return Err(unexpected(&key)),
            }
        }
    }
    Ok(a)
}

/// The tightening decision on one angle: "ok", "nok", "recheck", "invalid", or None.
#[pyfunction]
#[pyo3(signature = (angle_deg, angle_std_deg, target_deg, tolerance_deg, k_sigma=2.0, tightening_direction="positive", scale_sigma=0.0, untrusted=false))]
#[allow(clippy::too_many_arguments)]
fn decide(
    angle_deg: f64,
    angle_std_deg: f64,
    target_deg: f64,
    tolerance_deg: f64,
    k_sigma: f64,
    tightening_direction: &str,
    scale_sigma: f64,
    untrusted: bool,
) -> PyResult<Option<&'static str>> {
    let direction = match tightening_direction {
        "positive" => Direction::Positive,
        "negative" => Direction::Negative,
        other => {
            return Err(GyroError::new_err(format!(
            "invalid value '{other}' for tightening_direction: expected one of positive, negative"
        )))
        }
    };
    let window = Tightening {
        target_deg: target_deg as f32,
        tolerance_deg: tolerance_deg as f32,
        k_sigma: k_sigma as f32,
        direction,
        scale_sigma: scale_sigma as f32,
    };
    let verdict = crate::decide(&window, angle_deg as f32, angle_std_deg as f32, untrusted)?;
    Ok(verdict.map(|v| match v {
        Verdict::Ok => "ok",
        Verdict::Nok => "nok",
        Verdict::Recheck => "recheck",
        Verdict::Invalid => "invalid",
    }))
}

/// The streaming pipeline (the Rust [`Stream`]); `gyro.Pipeline` wraps it.
#[pyclass(name = "_Stream", module = "gyro._gyro")]
struct PyStream {
    stream: Option<Stream>,
}

impl PyStream {
    fn stream(&mut self) -> PyResult<&mut Stream> {
        self.stream
            .as_mut()
            .ok_or_else(|| GyroError::new_err("the pipeline has finished: make a new one"))
    }
}

#[pymethods]
impl PyStream {
    #[new]
    #[pyo3(signature = (sample_rate_hz, options=None))]
    fn new(sample_rate_hz: f64, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let options = run_options(options, false)?;
        Ok(Self {
            stream: Some(Stream::new(sample_rate_hz, &options)?),
        })
    }

    /// Push a block: (series arrays, movement start times, JSON of the ended movements).
    #[pyo3(signature = (time_s, rate_dps, reference_deg=None, temperature_c=None))]
    #[allow(clippy::type_complexity)]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        rate_dps: PyReadonlyArray1<'py, f64>,
        reference_deg: Option<PyReadonlyArray1<'py, f64>>,
        temperature_c: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<(Bound<'py, PyDict>, Vec<f64>, String)> {
        let arrays = Arrays {
            time_s: values(&time_s)?,
            rate_dps: values(&rate_dps)?,
            reference_deg: reference_deg.as_ref().map(values).transpose()?,
            temperature_c: temperature_c.as_ref().map(values).transpose()?,
            nominal_rate_hz: None,
            first_line: 1,
        };
        let stream = self.stream()?;
        let pushed = py.detach(|| stream.push(&arrays))?;
        let ended =
            serde_json::to_string(&pushed.ended).map_err(|e| GyroError::new_err(e.to_string()))?;
        Ok((series(py, &pushed.series)?, pushed.started_s, ended))
    }

    /// The report of everything pushed (JSON text); the pipeline is then spent.
    fn finish(&mut self, py: Python<'_>, name: String) -> PyResult<String> {
        let stream = self
            .stream
            .take()
            .ok_or_else(|| GyroError::new_err("the pipeline has finished: make a new one"))?;
        let out = py.detach(|| stream.finish(&name))?;
        Ok(out.json)
    }
}

/// The native part of the `gyro` package.
#[pymodule]
fn _gyro(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("GyroError", m.py().get_type::<GyroError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(run_file, m)?)?;
    m.add_function(wrap_pyfunction!(run_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(noise_files, m)?)?;
    m.add_function(wrap_pyfunction!(decide, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_files, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_files, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(noise_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_arrays, m)?)?;
    m.add_class::<PyStream>()?;
    Ok(())
}
