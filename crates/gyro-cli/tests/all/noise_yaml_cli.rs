//! `--noise-yaml` of `noise` and `diagnose`: the gyro noise as Kalibr / OpenVINS /
//! VINS-Fusion YAML, checked against a log of known noise, parsed, never written over an
//! input.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{gyro, json_of, ok, run_csv, temp_dir, workspace_root};

use gyro_sim::Effect;
use std::path::Path;

/// `fixtures/noise/noise_yaml_input.csv` (`make_noise_yaml_input.py`): white noise of
/// N = 0.005 deg/s/√Hz and a rate random walk of K = 0.01 deg/s/√s, 400 s at 50 Hz.
fn golden_log() -> String {
    workspace_root()
        .join("fixtures/noise/noise_yaml_input.csv")
        .to_string_lossy()
        .into_owned()
}

/// The YAML in `path` as a value; the OpenCV directive line of OpenVINS's format, which
/// is not standard YAML, dropped first.
fn parse(path: &Path) -> (String, serde_yaml::Value) {
    let text = std::fs::read_to_string(path).unwrap();
    let body = match text.strip_prefix("%YAML:1.0") {
        Some(rest) => rest.split_once('\n').unwrap().1.to_string(),
        None => text.clone(),
    };
    let value = serde_yaml::from_str(&body).unwrap_or_else(|e| panic!("{e}:\n{text}"));
    (text, value)
}

fn num(v: &serde_yaml::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number {key} in {v:?}"))
}

/// Kalibr's YAML from `noise` on the golden log is within the tolerance of the truth:
/// N within 2%, K within 15%. Over 20 independent logs of the same noise
/// (`make_noise_yaml_input.py SEED OUT`, seeds 1–20) the estimates scattered around the
/// truth with a mean of −0.1% and a standard deviation of 0.6% (N), −0.7% and 4.7% (K);
/// the tolerances are about 3 of those standard deviations.
#[test]
fn noise_writes_the_known_density_and_random_walk() {
    let scratch = temp_dir("noise_yaml_golden");
    let dir = scratch.path();
    let out = dir.join("imu.yaml");
    let run = gyro(&[
        "noise",
        &golden_log(),
        "--noise-yaml",
        out.to_str().unwrap(),
    ]);
    ok(&run);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("wrote") && stderr.contains("Kalibr"),
        "{stderr}"
    );
    let (text, yaml) = parse(&out);
    let n_true = 0.005f64.to_radians();
    let k_true = 0.01f64.to_radians();
    let n = num(&yaml, "gyroscope_noise_density");
    let k = num(&yaml, "gyroscope_random_walk");
    assert!((n / n_true - 1.0).abs() < 0.02, "N {n} vs {n_true}\n{text}");
    assert!((k / k_true - 1.0).abs() < 0.15, "K {k} vs {k_true}\n{text}");
    assert_eq!(num(&yaml, "update_rate"), 50.0);
    assert!(text.contains("# Source: static Allan deviation (gyro-cli noise) of "));
    assert!(text.contains("noise_yaml_input.csv"));
    assert!(!text.contains("UPPER BOUND"), "{text}");
    // Gyroscope keys only.
    assert!(yaml.get("accelerometer_noise_density").is_none());
    assert!(yaml.get("rostopic").is_none());
}

/// All three formats from one log: the same numbers under each tool's keys.
#[test]
fn every_format_is_written_and_parses() {
    let scratch = temp_dir("noise_yaml_formats");
    let dir = scratch.path();
    let mut values = Vec::new();
    for (format, nested, keys) in [
        (
            "kalibr",
            false,
            ["gyroscope_noise_density", "gyroscope_random_walk"],
        ),
        (
            "openvins",
            true,
            ["gyroscope_noise_density", "gyroscope_random_walk"],
        ),
        ("vins", false, ["gyr_n", "gyr_w"]),
    ] {
        let out = dir.join(format!("{format}.yaml"));
        ok(&gyro(&[
            "noise",
            &golden_log(),
            "--noise-yaml",
            out.to_str().unwrap(),
            "--noise-yaml-format",
            format,
        ]));
        let (text, yaml) = parse(&out);
        assert_eq!(format == "openvins", text.starts_with("%YAML:1.0"));
        let map = if nested { &yaml["imu0"] } else { &yaml };
        values.push((num(map, keys[0]), num(map, keys[1])));
    }
    assert!(values.windows(2).all(|w| w[0] == w[1]), "{values:?}");
    let out = gyro(&[
        "noise",
        &golden_log(),
        "--noise-yaml",
        dir.join("x.yaml").to_str().unwrap(),
        "--noise-yaml-format",
        "rpng",
    ]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "an unknown format is a usage error"
    );
}

/// `--noise-yaml` naming an input is refused; the input is left as it was.
#[test]
fn never_overwrites_an_input() {
    let scratch = temp_dir("noise_yaml_overwrite");
    let dir = scratch.path();
    let log = dir.join("in.csv");
    std::fs::copy(golden_log(), &log).unwrap();
    let original = std::fs::read(&log).unwrap();
    let through = format!("{}/./in.csv", dir.display());
    let l = log.to_str().unwrap();
    for args in [
        vec!["noise", l, "--noise-yaml", &through],
        vec![
            "diagnose",
            "--train",
            l,
            "--holdout",
            l,
            "--noise-yaml",
            &through,
        ],
    ] {
        let out = gyro(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("refusing to overwrite"), "{stderr}");
        assert_eq!(std::fs::read(&log).unwrap(), original, "{args:?}");
    }
}

/// A simulated bench run (CRM100 at 250 Hz, 45 s) with `effects`.
fn bench_csv(dir: &Path, name: &str, effects: &[Effect], seed: u64) -> String {
    run_csv(dir, name, 250.0, 45.0, effects, seed)
}

/// `diagnose --noise-yaml` writes the effective noise measured on the training runs, as
/// the JSON reports it (`effective_noise.training`): N from the Allan deviation from 1 s to 10 s of
/// what the deterministic terms leave, K from its fit. With a rate random walk of
/// 0.02 deg/s/√s injected, the measured K is near it.
#[test]
fn diagnose_writes_the_measured_effective_noise() {
    let scratch = temp_dir("noise_yaml_diagnose");
    let dir = scratch.path();
    let effect = [Effect::RateRandomWalk {
        k_dps_per_rt_s: 0.02,
    }];
    let train: Vec<String> = (0..4)
        .map(|i| bench_csv(dir, &format!("t{i}.csv"), &effect, 10 + i))
        .collect();
    let holdout: Vec<String> = (0..3)
        .map(|i| bench_csv(dir, &format!("h{i}.csv"), &effect, 50 + i))
        .collect();
    let out = dir.join("vins.yaml");
    let out_s = out.to_string_lossy().into_owned();
    let mut args = vec![
        "diagnose",
        "--format",
        "json",
        "--members",
        "20",
        "--candidate-members",
        "8",
        "--noise-yaml",
        &out_s,
        "--noise-yaml-format",
        "vins",
        "--train",
    ];
    args.extend(train.iter().map(String::as_str));
    args.push("--holdout");
    args.extend(holdout.iter().map(String::as_str));
    let d = json_of(&gyro(&args));
    let (text, yaml) = parse(&out);
    assert!(
        text.contains("# Source: effective values measured on moving data"),
        "{text}"
    );
    let t = &d["effective_noise"]["training"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let n_dps = f(&t["arw_deg_per_rt_h"]) / 60.0;
    let k_dps = f(&t["rate_random_walk_dps_per_rt_s"]);
    let gyr_n = num(&yaml, "gyr_n");
    let gyr_w = num(&yaml, "gyr_w");
    assert!(
        (gyr_n / n_dps.to_radians() - 1.0).abs() < 1e-5,
        "{gyr_n} vs {n_dps}\n{text}"
    );
    assert!(
        (gyr_w / k_dps.to_radians() - 1.0).abs() < 1e-5,
        "{gyr_w} vs {k_dps}\n{text}"
    );
    // Resolved as a +1/2 line or bounded by one, K is near the injected walk.
    assert!((0.01..0.04).contains(&k_dps), "K {k_dps}\n{text}");
    // The model's own white noise is static; in motion the residual holds more.
    assert!(f(&t["ratio_to_model"]) >= 1.0, "{t}");
}
