//! Integration tests of `gyro-cli noise` on simulated static logs and on bad input.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{gyro, json_of, temp_dir, write};

use gyro_log as log;
use gyro_sim::{simulate, Motion, Rotation, SensorModel, SimOptions};
use std::path::Path;
use std::process::Output;

/// A simulated log written as CSV.
fn simulated(dir: &Path, name: &str, model: &SensorModel, motion: &Motion, seed: u64) -> String {
    let log = simulate(
        model,
        &[],
        motion,
        &SimOptions {
            seed,
            ..SimOptions::default()
        },
    );
    let path = dir.join(name);
    let mut file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    log::write_csv(&mut file, &log).unwrap();
    drop(file);
    path.to_string_lossy().into_owned()
}

/// ARW 0.3 deg/√h, Gauss-Markov σ 0.05 deg/s T 0.5 s, 100 Hz, no quantisation.
fn model() -> SensorModel {
    SensorModel {
        sample_rate_hz: 100.0,
        bias_dps: 0.3,
        arw_deg_per_rt_h: 0.3,
        gm_sigma_dps: 0.05,
        gm_tau_s: 0.5,
        lsb_dps: 0.0,
        range_dps: 300.0,
    }
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// An error: exit code 1, one line on stderr naming `what`, no panic.
fn assert_error(out: &Output, what: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // One error line, the last (notes may precede it).
    let lines: Vec<&str> = stderr.trim_end().lines().collect();
    assert_eq!(
        lines.iter().filter(|l| l.starts_with("error: ")).count(),
        1,
        "{stderr}"
    );
    assert!(lines.last().unwrap().starts_with("error: "), "{stderr}");
    for w in what {
        assert!(stderr.contains(w), "expected `{w}` in: {stderr}");
    }
}

#[test]
fn static_log_json_table_and_model_file() {
    let scratch = temp_dir("static");
    let dir = scratch.path();
    let log = simulated(
        dir,
        "static.csv",
        &model(),
        &Motion::from_rotations(vec![], 1000.0),
        11,
    );
    let model_out = dir.join("fitted.json");
    let model_out = model_out.to_str().unwrap();
    let out = gyro(&["noise", &log, "--format", "json", "--model-out", model_out]);
    let json = json_of(&out);
    let entry = &json["logs"][0];
    assert_eq!(entry["file"], log.as_str());
    // A static log is not said to move.
    assert_eq!(f(&entry["moving_share"]), 0.0);
    assert!(entry["warnings"].is_null());
    assert!(json["combined"].is_null());
    assert_eq!(entry["samples"], 100_001);
    let fit = &entry["fit"];
    let arw = f(&fit["arw_deg_per_rt_h"]);
    let gm = &fit["gauss_markov"];
    eprintln!("ARW {arw}, GM {gm}");
    assert!((arw / 0.3 - 1.0).abs() < 0.1, "{arw}");
    assert_eq!(gm["significant"], true);
    assert!((f(&gm["sigma_dps"]) / 0.05 - 1.0).abs() < 0.1);
    assert!((f(&gm["corr_time_s"]) / 0.5 - 1.0).abs() < 0.15);
    // The Allan table: increasing τ, bounds around each value, a noise type each.
    let points = entry["allan"]["points"].as_array().unwrap();
    assert!(points.len() > 30);
    let mut last_tau = 0.0;
    for p in points {
        let (tau, adev) = (f(&p["tau_s"]), f(&p["adev_dps"]));
        assert!(tau > last_tau);
        last_tau = tau;
        assert!(
            f(&p["lower_dps"]) < adev && adev < f(&p["upper_dps"]),
            "{p}"
        );
        assert!(p["noise"].is_string() && f(&p["edf"]) > 0.0);
    }
    assert!((f(&points[0]["tau_s"]) - 0.01).abs() < 1e-12);
    assert!(last_tau <= 250.0 + 1e-9, "{last_tau}"); // a quarter of the log
    let psd = &entry["psd"];
    assert!((f(&psd["white_density_dps_per_rt_hz"]) / 0.005 - 1.0).abs() < 0.05);
    assert!(!psd["bands"].as_array().unwrap().is_empty());

    // The model file: loadable, its sensor section from the fit, usable by `simulate`.
    let fitted = gyro_analysis::model::load(Path::new(model_out)).unwrap();
    assert_eq!(fitted.sensor.sample_rate_hz, 100.0);
    assert_eq!(fitted.sensor.arw_deg_per_rt_h, arw);
    assert_eq!(fitted.sensor.gm_sigma_dps, f(&gm["sigma_dps"]));
    assert_eq!(fitted.sensor.gm_tau_s, f(&gm["corr_time_s"]));
    assert!((fitted.sensor.bias_dps - f(&entry["mean_rate_dps"])).abs() < 1e-12);
    let resim = dir.join("resim.csv");
    let out = gyro(&[
        "simulate",
        "--model",
        model_out,
        "--out",
        resim.to_str().unwrap(),
        "--duration-s",
        "5",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The table.
    let out = gyro(&["noise", &log]);
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    // The answer first, in the trade's units, before the Allan table.
    let second = table.lines().nth(1).unwrap_or_default();
    assert!(
        second.contains("white noise (angle random walk)")
            && second.contains("deg/√h")
            && second.contains("deg (1 σ) after 1 minute"),
        "{table}"
    );
    assert!(table.find("bias stability").unwrap() < table.find("Allan deviation (").unwrap());
    for needle in [
        "Allan deviation",
        "angle random walk N",
        "deg/√h",
        "Gauss-Markov bias",
        "white density",
    ] {
        assert!(table.contains(needle), "no `{needle}` in:\n{table}");
    }
}

#[test]
fn several_logs_are_pooled_and_psd_written() {
    let scratch = temp_dir("pooled");
    let dir = scratch.path();
    let a = simulated(
        dir,
        "a.csv",
        &model(),
        &Motion::from_rotations(vec![], 200.0),
        1,
    );
    let b = simulated(
        dir,
        "b.csv",
        &model(),
        &Motion::from_rotations(vec![], 300.0),
        2,
    );
    let psd_out = dir.join("psd.csv");
    let out = gyro(&[
        "noise",
        &a,
        &b,
        "--format",
        "json",
        "--tau-grid",
        "octave",
        "--psd-out",
        psd_out.to_str().unwrap(),
    ]);
    let json = json_of(&out);
    assert_eq!(json["logs"].as_array().unwrap().len(), 2);
    let combined = &json["combined"];
    assert_eq!(f(&combined["samples"]), 20_001.0 + 30_001.0);
    assert_eq!(combined["segments"], 2);
    // Octave grid: τ = 2^k τ0 up to a quarter of the longest log.
    let taus: Vec<f64> = combined["allan"]["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| f(&p["tau_s"]))
        .collect();
    assert_eq!(taus.len(), 13, "{taus:?}"); // 1..4096 ≤ 30001/4
    assert!((taus[12] - 40.96).abs() < 1e-9);
    let csv = std::fs::read_to_string(&psd_out).unwrap();
    assert!(csv.starts_with("log,frequency_hz,psd_dps2_per_hz\n"));
    assert!(csv.lines().any(|l| l.starts_with("combined,")));
    assert!(csv.lines().any(|l| l.starts_with(&format!("{a},"))));
}

#[test]
fn static_only_uses_the_rest_stretches_of_a_log_with_motion() {
    let scratch = temp_dir("motion");
    let dir = scratch.path();
    let rotations: Vec<Rotation> = (0..8)
        .map(|i| Rotation {
            start_s: 15.0 + 25.0 * f64::from(i),
            duration_s: 1.5,
            angle_deg: if i % 2 == 0 { 90.0 } else { -90.0 },
        })
        .collect();
    let sensor = SensorModel {
        sample_rate_hz: 1000.0,
        gm_sigma_dps: 0.0,
        ..model()
    };
    let log = simulated(
        dir,
        "bench.csv",
        &sensor,
        &Motion::from_rotations(rotations, 210.0),
        3,
    );
    let whole = json_of(&gyro(&["noise", &log, "--format", "json"]));
    let rest = json_of(&gyro(&["noise", &log, "--format", "json", "--static-only"]));
    let entry = &rest["logs"][0];
    let stretches = entry["rest_stretches_s"].as_array().unwrap();
    assert_eq!(stretches.len(), 9, "{stretches:?}");
    let arw = f(&entry["fit"]["arw_deg_per_rt_h"]);
    assert!((arw / 0.3 - 1.0).abs() < 0.1, "{arw}");
    // Taken whole, the rotations dominate the Allan deviation at τ ≈ 1 s.
    let at_1s = |j: &serde_json::Value| {
        let points = j["logs"][0]["allan"]["points"].as_array().unwrap().clone();
        let p = points
            .iter()
            .min_by(|a, b| (f(&a["tau_s"]).ln().abs()).total_cmp(&f(&b["tau_s"]).ln().abs()))
            .unwrap();
        f(&p["adev_dps"])
    };
    assert!(
        at_1s(&whole) > 100.0 * at_1s(&rest),
        "{} vs {}",
        at_1s(&whole),
        at_1s(&rest)
    );
    // Taken whole, the log is said to move, in the JSON and the table (8 turns of 1.5 s
    // and their filter tails in 210 s: about 6%); its rests alone are not.
    let share = f(&whole["logs"][0]["moving_share"]);
    assert!((0.04..0.1).contains(&share), "{share}");
    let warnings = whole["logs"][0]["warnings"].to_string();
    assert!(
        warnings.contains("in motion by the motion detector"),
        "{warnings}"
    );
    assert!(entry["moving_share"].is_null() && entry["warnings"].is_null());
    let table = String::from_utf8_lossy(&gyro(&["noise", &log]).stdout).into_owned();
    assert!(
        table.contains("warning: ") && table.contains("--static-only"),
        "{table}"
    );
}

#[test]
fn bad_input_is_a_one_line_error_naming_the_file() {
    let scratch = temp_dir("bad");
    let dir = scratch.path();
    let empty = write(dir, "empty.csv", "time_s,rate_dps\n");
    assert_error(&gyro(&["noise", &empty]), &["empty.csv"]);

    let missing = dir.join("missing.csv").to_string_lossy().into_owned();
    assert_error(&gyro(&["noise", &missing]), &["missing.csv"]);

    let mut short = String::from("# sample_rate_hz: 100\ntime_s,rate_dps\n");
    for k in 0..10 {
        short.push_str(&format!("{:.2},0.{k}\n", f64::from(k) * 0.01));
    }
    let short = write(dir, "short.csv", &short);
    assert_error(
        &gyro(&["noise", &short]),
        &["short.csv", "too short", "10 samples"],
    );

    let garbage = write(dir, "garbage.csv", "time_s,rate_dps\n0.0,abc\n");
    assert_error(&gyro(&["noise", &garbage]), &["garbage.csv", "abc"]);

    // Always turning: no rest stretch.
    let mut turning = String::from("# sample_rate_hz: 100\ntime_s,rate_dps\n");
    for k in 0..2000 {
        turning.push_str(&format!("{:.2},50.0\n", f64::from(k) * 0.01));
    }
    let turning = write(dir, "turning.csv", &turning);
    assert_error(
        &gyro(&["noise", &turning, "--static-only"]),
        &["turning.csv", "no rest stretch"],
    );

    // A good log and a bad one: the bad one is named.
    let good = simulated(
        dir,
        "good.csv",
        &model(),
        &Motion::from_rotations(vec![], 20.0),
        1,
    );
    assert_error(&gyro(&["noise", &good, &short]), &["short.csv"]);

    // A model file needs one data set: logs of two rates cannot be pooled.
    let other = simulated(
        dir,
        "other.csv",
        &SensorModel {
            sample_rate_hz: 200.0,
            ..model()
        },
        &Motion::from_rotations(vec![], 20.0),
        1,
    );
    let m = dir.join("m.json");
    assert_error(
        &gyro(&["noise", &good, &other, "--model-out", m.to_str().unwrap()]),
        &["--model-out"],
    );
    assert_error(
        &gyro(&["noise", &good, "--psd-segment", "100"]),
        &["--psd-segment"],
    );
    // No log at all: clap's usage error.
    assert!(!gyro(&["noise"]).status.success());
}

/// The nominal sensor at rest for 600 s: its own Gauss-Markov bias (T = 100 s) reads as a
/// rate random walk over the averaging times such a log has; the table says the two are
/// look-alikes here rather than that the sensor model lacks it.
#[test]
fn a_short_static_log_says_its_random_walk_may_be_the_models_own_bias() {
    let scratch = temp_dir("noise-look-alike");
    let log = scratch.path().join("rest.csv");
    let log = log.to_str().unwrap();
    let out = gyro(&["simulate", "--static", "--duration-s", "600", "-o", log]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = gyro(&["noise", log]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        table.contains("this log is too short to tell them apart")
            && table.contains("may also be the sensor model's own Gauss-Markov bias"),
        "{table}"
    );
}
