//! The command line as a Unix tool: every command takes and writes paths with non-ASCII
//! characters (a German line's `Prüfstand/lauf_ö.csv`), and a reader that stops reading
//! (`| head`) ends the command quietly with status 0.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;

use crate::common::{gyro, ok, temp_dir};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_gyro-cli");

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A folder and runs named like a test bench's: non-ASCII, and longer than the 40
/// characters the calibration table shows (40 bytes from the end falls inside an `ö`).
fn run_name(i: usize) -> String {
    format!("Drehwinkel_{}{i}.csv", "ö".repeat(20))
}

/// Four simulated runs with non-ASCII names in a non-ASCII folder inside a fresh scratch
/// folder (the guard, which removes it when dropped), the folder and the runs.
fn bench(name: &str) -> (tempfile::TempDir, PathBuf, Vec<PathBuf>) {
    let scratch = temp_dir(name);
    let dir = scratch.path().join("Prüfstand_Linie_3");
    std::fs::create_dir_all(&dir).unwrap();
    let runs: Vec<PathBuf> = (1..=4).map(|i| dir.join(run_name(i))).collect();
    for (i, run) in runs.iter().enumerate() {
        let seed = (11 + i).to_string();
        ok(&gyro(&[
            "simulate",
            "-o",
            s(run),
            "--seed",
            &seed,
            "--duration-s",
            "40",
        ]));
    }
    (scratch, dir, runs)
}

#[test]
fn run_noise_convert_take_non_ascii_paths() {
    let (_scratch, dir, runs) = bench("unicode-run");
    let log = s(&runs[0]);
    let series = dir.join("Reihe_ä.csv");
    let plot = dir.join("Bild_ü.svg");
    let table = ok(&gyro(&[
        "run",
        log,
        "--out",
        s(&series),
        "--plot",
        s(&plot),
    ]));
    assert!(table.contains(&run_name(1)), "{table}");
    assert!(std::fs::metadata(&series).unwrap().len() > 0);
    assert!(std::fs::metadata(&plot).unwrap().len() > 0);
    let json: serde_json::Value =
        serde_json::from_str(&ok(&gyro(&["run", log, "--format", "json"]))).unwrap();
    assert!(json["file"].as_str().unwrap().ends_with(&run_name(1)));

    let noise = ok(&gyro(&["noise", "--static-only", log]));
    assert!(noise.contains(&run_name(1)), "{noise}");

    let mcap = dir.join("Aufnahme_ß.mcap");
    ok(&gyro(&["convert", log, s(&mcap)]));
    let from_mcap = ok(&gyro(&["run", s(&mcap), "--format", "json"]));
    assert!(from_mcap.contains("Aufnahme_ß.mcap"));
    std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
}

#[test]
fn calibrate_and_diagnose_take_non_ascii_paths() {
    let (_scratch, dir, runs) = bench("unicode-calibrate");
    let model = dir.join("Modell_ö.json");
    let split = [
        s(&runs[0]),
        s(&runs[1]),
        "--holdout",
        s(&runs[2]),
        s(&runs[3]),
    ];
    let out = gyro(&[&["calibrate"], &split[..], &["-o", s(&model)]].concat());
    let table = ok(&out);
    // The table shows the last 40 characters of each run's name.
    let tail: String = s(&runs[0])
        .chars()
        .rev()
        .take(40)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    assert!(table.contains(&format!("  {tail} ")), "{table}");
    assert!(model.exists());
    ok(&gyro(&["run", s(&runs[3]), "--model", s(&model)]));

    let diagnosed = dir.join("Diagnose_ä.json");
    let report = dir.join("Bericht_ü");
    let diagnose = [
        "diagnose",
        "--members",
        "8",
        "--candidate-members",
        "4",
        "--train",
    ];
    let outputs = ["-o", s(&diagnosed), "--report", s(&report)];
    let out = gyro(&[&diagnose[..], &split[..], &outputs[..]].concat());
    ok(&out);
    assert!(report.join("index.html").exists());
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(html.contains(&run_name(3)));
    std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
}

#[test]
fn emulate_and_record_take_non_ascii_paths() {
    let (_scratch, dir, runs) = bench("unicode-bridge");
    let recording = dir.join("Mitschnitt_ö.mcap");
    let fault_log = dir.join("Fehler_ä.json");
    let args: Vec<&OsStr> = vec![
        "--as-fast-as-possible".as_ref(),
        "--log".as_ref(),
        runs[0].as_os_str(),
        "--fault-log".as_ref(),
        fault_log.as_os_str(),
    ];
    let (emulated, record) = common::emulate_into_record(&args, &recording);
    assert!(
        record.status.success(),
        "{}",
        String::from_utf8_lossy(&record.stderr)
    );
    assert!(emulated.status.success());
    assert!(fault_log.exists());
    let json: serde_json::Value =
        serde_json::from_str(&ok(&gyro(&["run", s(&recording), "--format", "json"]))).unwrap();
    assert!(json["file"]
        .as_str()
        .unwrap()
        .ends_with("Mitschnitt_ö.mcap"));
    std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
}

/// The reader closes the pipe before the command writes: status 0, nothing on stderr.
fn quiet_on_closed_pipe(args: &[&str]) {
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {:?} {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.stderr.is_empty(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_closed_output_pipe_ends_quietly() {
    let log = common::bench_log();
    let log = s(&log);
    quiet_on_closed_pipe(&["run", log, "--format", "csv"]);
    quiet_on_closed_pipe(&["run", log, "--format", "json"]);
    quiet_on_closed_pipe(&["run", log, "--out", "/dev/stdout"]);
    quiet_on_closed_pipe(&["simulate", "--list-effects"]);
}
