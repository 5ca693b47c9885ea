//! Helpers shared by the integration tests: the workspace, the binary, temporary files.
#![allow(dead_code, clippy::unwrap_used)] // each test file uses some; a failed unwrap fails the test

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The workspace root (fixtures live there).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The bundled bench log.
pub fn bench_log() -> PathBuf {
    workspace_root().join("fixtures/logs/bench_run.csv")
}

/// Run `gyro-cli` with `args`.
pub fn gyro(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
        .args(args)
        .output()
        .expect("gyro-cli runs")
}

/// A fresh folder for one test, named after it; removed with everything in it when the
/// returned guard is dropped, so that test runs leave nothing in the temporary folder.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gyro-test-{name}-"))
        .tempdir()
        .unwrap()
}

/// Write `text` to `dir/name`; returns the path as a string for the command line.
pub fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

/// `gyro-cli emulate --create-pty ARGS` feeding `gyro-cli record --idle-stop 1 -o out`, as
/// a user runs them: the emulator prints the port, the recorder reads it until it goes
/// quiet. Returns (emulate, record) as they ended.
#[cfg(unix)]
pub fn emulate_into_record(emulate_args: &[&std::ffi::OsStr], out: &Path) -> (Output, Output) {
    emulate_into_record_with(emulate_args, &[], out)
}

/// [`emulate_into_record`] with `record_args` added to `record`'s command line.
#[cfg(unix)]
pub fn emulate_into_record_with(
    emulate_args: &[&std::ffi::OsStr],
    record_args: &[&str],
    out: &Path,
) -> (Output, Output) {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let mut emulate = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
        .args(["emulate", "--create-pty"])
        .args(emulate_args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut port = String::new();
    BufReader::new(emulate.stdout.take().unwrap())
        .read_line(&mut port)
        .unwrap();
    let record = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
        .args(["record", "--port", port.trim(), "--idle-stop", "1"])
        .args(record_args)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    (emulate.wait_with_output().unwrap(), record)
}

/// Assert success; stdout as text.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// Assert success; stdout as JSON.
pub fn json_of(out: &Output) -> serde_json::Value {
    serde_json::from_str(&ok(out)).expect("valid JSON on stdout")
}

/// The CSV `text` with the values of `column` mapped by `f` (metadata, header and other
/// fields as they are; a field that is not a number is kept).
pub fn map_column(text: &str, column: &str, f: impl Fn(f64) -> f64) -> String {
    let mut out = String::new();
    let mut index = None;
    for line in text.lines() {
        if line.starts_with('#') {
            out.push_str(line);
        } else if index.is_none() {
            index = line.split(',').position(|c| c == column);
            out.push_str(line);
        } else {
            let k = index.unwrap();
            let fields: Vec<String> = line
                .split(',')
                .enumerate()
                .map(|(i, v)| match (i == k, v.parse::<f64>()) {
                    (true, Ok(x)) => f(x).to_string(),
                    _ => v.to_string(),
                })
                .collect();
            out.push_str(&fields.join(","));
        }
        out.push('\n');
    }
    out
}

/// A simulated bench run of `duration_s` at `fs`, written as CSV.
pub fn run_csv(
    dir: &Path,
    name: &str,
    fs: f64,
    duration_s: f64,
    effects: &[gyro_sim::Effect],
    seed: u64,
) -> String {
    let model = gyro_sim::SensorModel {
        sample_rate_hz: fs,
        ..gyro_sim::SensorModel::default()
    };
    run_csv_from(dir, name, &model, duration_s, effects, seed)
}

/// [`run_csv`] from `model` instead of the simulator's default sensor.
pub fn run_csv_from(
    dir: &Path,
    name: &str,
    model: &gyro_sim::SensorModel,
    duration_s: f64,
    effects: &[gyro_sim::Effect],
    seed: u64,
) -> String {
    let profile = gyro_sim::BenchProfile {
        duration_s,
        ..gyro_sim::BenchProfile::default()
    };
    let log = gyro_sim::simulate(
        model,
        effects,
        &gyro_sim::Motion::bench(&profile, seed),
        &gyro_sim::SimOptions {
            seed: seed + 100,
            ..gyro_sim::SimOptions::default()
        },
    );
    let path = dir.join(name);
    let mut file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    gyro_log::write_csv(&mut file, &log).unwrap();
    drop(file);
    path.to_string_lossy().into_owned()
}
