//! Integration tests of `gyro-cli run` on fixture logs and on deliberately broken logs.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, json_of, map_column, temp_dir, write};

#[test]
fn bench_fixture_json_contract_and_accuracy_by_mode() {
    let log = bench_log();
    let log = log.to_str().unwrap();
    let kalman = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--compensation",
        "kalman",
    ]));
    let none = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--compensation",
        "none",
    ]));

    // The fixture has six 90° rotations (make_bench_log.py, seed 7).
    let movements = kalman["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 6);
    for m in movements {
        let reference = m["reference_deg"].as_f64().unwrap();
        assert!((reference.abs() - 90.0).abs() < 0.1, "{m}");
        assert!(m["complete"].as_bool().unwrap());
    }
    let kalman_max = kalman["summary"]["max_abs_error_deg"].as_f64().unwrap();
    let none_max = none["summary"]["max_abs_error_deg"].as_f64().unwrap();
    // A 0.3 deg/s bias over ~10 s of motion: about 2 deg uncompensated; rest updates
    // remove it (measured 0.067 deg).
    assert!(none_max > 1.0, "uncompensated {none_max}");
    assert!(kalman_max < 0.15, "kalman {kalman_max}");
    for key in ["rms_error_deg", "final_error_deg"] {
        assert!(kalman["summary"][key].is_number(), "{key}");
    }
    assert_eq!(kalman["input"]["sample_rate_hz"].as_f64(), Some(1000.0));
    assert_eq!(kalman["decimation_factor"].as_u64(), Some(20));
}

#[test]
fn table_and_csv_formats_and_series_output() {
    let scratch = temp_dir("formats");
    let dir = scratch.path();
    let series = dir.join("series.csv");
    let log = bench_log();
    let out = gyro(&[
        "run",
        log.to_str().unwrap(),
        "--out",
        series.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("movements: 6"), "{table}");
    assert!(table.contains("error vs reference: max abs"), "{table}");

    let text = std::fs::read_to_string(&series).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("# output_rate_hz: 50"));
    assert!(lines
        .next()
        .unwrap()
        .starts_with("time_s,rate_dps,motion,angle_deg"));
    // 40 s at 50 Hz.
    assert_eq!(lines.count(), 2000);

    let out = gyro(&["run", log.to_str().unwrap(), "--format", "csv"]);
    let csv = String::from_utf8_lossy(&out.stdout);
    assert!(csv.starts_with("index,start_time_s,end_time_s"), "{csv}");
    assert_eq!(csv.lines().count(), 7);
}

/// A 100 Hz log with the warts of the real data: duplicate rows, a gap, jitter, a missing
/// value. 10 s: rest, a 90° turn in 1 s, rest.
fn wart_log() -> String {
    let mut s = String::from("# sample_rate_hz: 100\ntime_s,rate_dps,reference_deg\n");
    let mut angle = 0.0_f64;
    for k in 0..1000 {
        let t = k as f64 * 0.01;
        let rate = if (3.0..4.0).contains(&t) {
            90.0 * (1.0 - (2.0 * std::f64::consts::PI * (t - 3.0)).cos())
        } else {
            0.0
        };
        if k > 0 {
            angle += rate * 0.01;
        }
        if k == 500 {
            continue; // a lost sample: gap of 20 ms
        }
        let jitter = if k % 7 == 3 { 0.001 } else { 0.0 };
        let rate_field = if k == 200 {
            String::new()
        } else {
            format!("{rate:.4}")
        };
        let row = format!("{:.3},{rate_field},{angle:.4}\n", t + jitter);
        s.push_str(&row);
        if k == 300 {
            s.push_str(&row); // logger repeated the row
        }
    }
    s
}

#[test]
fn irregular_100hz_log_is_handled_and_reported() {
    let scratch = temp_dir("warts");
    let dir = scratch.path();
    let path = write(dir, "warts.csv", &wart_log());
    let report = json_of(&gyro(&["run", &path, "--format", "json"]));
    let input = &report["input"];
    assert_eq!(input["duplicate_rows"].as_u64(), Some(1));
    assert_eq!(input["gaps"].as_u64(), Some(1));
    assert_eq!(input["missing_rate_rows"].as_u64(), Some(1));
    assert_eq!(input["filled_slots"].as_u64(), Some(2));
    assert!(input["jittered_steps"].as_u64().unwrap() > 100);
    assert_eq!(report["decimation_factor"].as_u64(), Some(2));
    let movements = report["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 1);
    let angle = movements[0]["angle_deg"].as_f64().unwrap();
    assert!((angle - 90.0).abs() < 0.5, "{angle}");
}

#[test]
fn bad_input_is_a_clear_error_naming_file_and_line() {
    let scratch = temp_dir("bad");
    let dir = scratch.path();
    let cases = [
        (
            "value.csv",
            "time_s,rate_dps\n0.000,1.0\n0.001,1.5x\n",
            "value.csv:3: column `rate_dps`: `1.5x` is not a number",
        ),
        (
            "column.csv",
            "time,rate\n0.0,1.0\n",
            "column.csv:1: no column `time_s`",
        ),
        ("empty.csv", "", "no header line"),
        ("header_only.csv", "time_s,rate_dps\n", "no data rows"),
        (
            "ragged.csv",
            "time_s,rate_dps\n0.000,1.0\n0.001\n",
            "ragged.csv:3: row has 1 fields",
        ),
        (
            "gap.csv",
            "# sample_rate_hz: 1000\ntime_s,rate_dps\n0.000,1.0\n0.001,1.0\n2.000,1.0\n",
            "gap.csv:5: gap of 1.999 s",
        ),
        (
            "gap_hint.csv",
            "# sample_rate_hz: 1000\ntime_s,rate_dps\n0.000,1.0\n0.001,1.0\n2.000,1.0\n",
            "the longest gap bridged, 0.5 s; the rotation during it cannot be recovered (--max-gap-s)",
        ),
        (
            "one_stamp.csv",
            "time_s,rate_dps\n0.000,1.0\n0.000,1.0\n",
            "are stamped 0.000000 s: the stamps give no time order; fix the time stamps",
        ),
        (
            "backwards.csv",
            "time_s,rate_dps\n10.000,1.0\n10.001,1.0\n3.000,1.0\n",
            "backwards.csv:4: time goes back by 7.001000 s",
        ),
        (
            "norate.csv",
            "time_s,rate_dps\n0.0,\n0.1,nan\n",
            "no row has a rate value",
        ),
    ];
    for (name, text, expected) in cases {
        let path = write(dir, name, text);
        let out = gyro(&["run", &path]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name} should fail");
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        assert!(stderr.contains(expected), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
    let out = gyro(&["run", "/nonexistent/log.csv"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/log.csv"));
}

#[test]
fn model_file_is_used_and_bad_models_are_refused() {
    let scratch = temp_dir("model");
    let dir = scratch.path();
    let log = bench_log();
    let log = log.to_str().unwrap();
    let good = write(
        dir,
        "kalman.json",
        r#"{"format": "gyro-model", "version": 1, "config": {"compensation": "kalman"}}"#,
    );
    let report = json_of(&gyro(&["run", log, "--format", "json", "--model", &good]));
    assert_eq!(report["summary"]["compensation"], "kalman");
    assert!(report["movements"][0]["angle_deg"].is_number());

    let bad = write(
        dir,
        "bad.json",
        r#"{"format": "gyro-model", "version": 1, "config": {"filter": {"order": 2, "cutoff_hz": 40}}}"#,
    );
    let out = gyro(&["run", log, "--model", &bad]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("bad.json") && stderr.contains("filter.cutoff_hz"),
        "{stderr}"
    );

    let broken = write(dir, "broken.json", "{\"format\": ");
    let out = gyro(&["run", log, "--model", &broken]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken.json:1:"));
}

#[test]
fn calibrate_and_noise_take_mcap_and_refuse_logs_without_reference() {
    let scratch = temp_dir("mcap-commands");
    let dir = scratch.path();
    let log = bench_log();
    let mcap = dir.join("bench.mcap");
    let out = gyro(&["convert", log.to_str().unwrap(), mcap.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let model = dir.join("model.json");
    let out = gyro(&[
        "calibrate",
        mcap.to_str().unwrap(),
        "-o",
        model.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let report = json_of(&out);
    assert_eq!(report["train"].as_array().unwrap().len(), 1);
    assert!(report["train"][0]["kalman_max_abs_deg"].as_f64().unwrap() < 0.15);
    assert!(model.exists());

    let out = gyro(&[
        "noise",
        mcap.to_str().unwrap(),
        "--static-only",
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let no_reference = write(
        dir,
        "noref.csv",
        "time_s,rate_dps\n0.000,0.1\n0.001,0.1\n0.002,0.1\n",
    );
    let not_made = dir.join("noref-model.json");
    let out = gyro(&["calibrate", &no_reference, "-o", not_made.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("noref.csv: no reference_deg column"),
        "{stderr}"
    );
    assert!(!not_made.exists());
}

/// A declared rate the stamps contradict is refused, not turned into angles off by the
/// ratio (100 Hz declared on the 1 kHz bench log: a 90° turn would read 900°).
#[test]
fn a_declared_rate_the_stamps_contradict_is_refused() {
    let log = bench_log();
    let log = log.to_str().unwrap();
    for rate in ["100", "499", "2001", "1e9"] {
        let out = gyro(&["run", log, "--sample-rate-hz", rate]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{rate}: {stderr}");
        assert!(stderr.contains("time stamps say 1000"), "{rate}: {stderr}");
        assert!(stderr.contains("--sample-rate-hz"), "{rate}: {stderr}");
    }
    // Within a factor of 2 of the stamps: accepted, with a warning beyond 1%.
    let out = gyro(&["run", log, "--sample-rate-hz", "990"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: ") && stderr.contains("time stamps say 1000.000 Hz"),
        "{stderr}"
    );
    let out = gyro(&["run", log, "--sample-rate-hz", "999"]);
    assert!(out.status.success() && out.stderr.is_empty());
}

/// Input that is valid but unusual is read: a Latin-1 byte in a comment line, a UTF-8
/// byte-order mark before the header or the model file; an invalid `--max-gap-s` is refused.
#[test]
fn unusual_encodings_are_read_and_bad_gap_limits_refused() {
    let scratch = temp_dir("encodings");
    let dir = scratch.path();
    let latin = dir.join("latin.csv");
    std::fs::write(
        &latin,
        b"# sample_rate_hz: 100\n# note: caf\xe9\ntime_s,rate_dps\n0.00,1\n0.01,1\n0.02,1\n",
    )
    .unwrap();
    let out = gyro(&["run", latin.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bom = dir.join("bom.csv");
    std::fs::write(
        &bom,
        b"\xef\xbb\xbftime_s,rate_dps\n0.00,1\n0.01,1\n0.02,1\n",
    )
    .unwrap();
    let out = gyro(&["run", bom.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model = dir.join("model.json");
    std::fs::write(
        &model,
        b"\xef\xbb\xbf{\"format\":\"gyro-model\",\"version\":1}",
    )
    .unwrap();
    let log = bench_log();
    let out = gyro(&[
        "run",
        log.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // UTF-16 is refused plainly; a huge bad field is not echoed whole.
    let utf16 = dir.join("utf16.csv");
    let mut bytes = vec![0xFF, 0xFE];
    for unit in "time_s,rate_dps\n0.0,1\n".encode_utf16() {
        bytes.extend_from_slice(&unit.to_le_bytes());
    }
    std::fs::write(&utf16, bytes).unwrap();
    let out = gyro(&["run", utf16.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("this file is UTF-16"), "{stderr}");
    let long = dir.join("long.csv");
    std::fs::write(
        &long,
        format!("time_s,rate_dps\n0.0,1\n0.01,{}\n", "x".repeat(100_000)),
    )
    .unwrap();
    let out = gyro(&["run", long.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.len() < 300, "{}", stderr.len());
    assert!(stderr.contains("(100000 characters)"), "{stderr}");
    // A bad setting in a model file is said once.
    let bad_model = dir.join("bad-model.json");
    std::fs::write(
        &bad_model,
        r#"{"format":"gyro-model","version":1,"config":{"output_rate_hz":-5}}"#,
    )
    .unwrap();
    let out = gyro(&[
        "run",
        log.to_str().unwrap(),
        "--model",
        bad_model.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        stderr.matches("out of its valid range").count(),
        1,
        "{stderr}"
    );
    for bad in ["nan", "inf", "-1"] {
        // Refused as the command line is parsed (status 2), the option named.
        let out = gyro(&["run", log.to_str().unwrap(), &format!("--max-gap-s={bad}")]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(stderr.contains("--max-gap-s"), "{bad}: {stderr}");
    }
}

/// `calibrate` fits a scale from the turns and a gyro latency as the reference delay, writes
/// both into the model file, and `run --model` uses them; a delay of a second or more is
/// refused.
#[test]
fn calibrate_writes_the_scale_and_the_reference_delay() {
    let scratch = temp_dir("calibrate-scale");
    let dir = scratch.path();
    let mut runs = Vec::new();
    for seed in 41..=44 {
        let path = dir.join(format!("run{seed}.csv"));
        let out = gyro(&[
            "simulate",
            "--force",
            "-o",
            path.to_str().unwrap(),
            "--seed",
            &seed.to_string(),
            "--duration-s",
            "60",
            "--effect",
            "scale_factor:k=-0.02",
            "--effect",
            "latency:delay_s=0.015",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        runs.push(path.to_str().unwrap().to_string());
    }
    let model = dir.join("model.json");
    let mut args = vec![
        "calibrate",
        "--format",
        "json",
        "-o",
        model.to_str().unwrap(),
    ];
    args.extend(runs[..3].iter().map(String::as_str));
    args.extend(["--holdout", runs[3].as_str()]);
    let report = json_of(&gyro(&args));
    let scale = &report["scale"];
    assert_eq!(scale["written"], true, "{scale}");
    assert!(
        (scale["k"].as_f64().unwrap() + 0.02).abs() < 0.001,
        "{scale}"
    );
    let delay = &report["reference_delay"];
    assert_eq!(delay["source"], "cross_correlation", "{delay}");
    assert!(
        (delay["delay_s"].as_f64().unwrap() - 0.015).abs() < 0.002,
        "{delay}"
    );
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let k = file["config"]["correction"]["scale_k"].as_f64().unwrap();
    assert!((k + 0.02).abs() < 0.001, "{file}");
    assert_eq!(file["reference_delay_s"], delay["delay_s"]);
    // The scale uncertainty left held out, for the tightening decision.
    let u = file["scale_sigma"].as_f64().unwrap();
    assert!(u > 0.0 && u < 0.001, "{file}");
    assert_eq!(file["scale_sigma"], scale["residual_relative_upper"]);
    assert!(u > scale["residual_relative"].as_f64().unwrap());
    let decided = json_of(&gyro(&[
        "run",
        runs[3].as_str(),
        "--format",
        "json",
        "--model",
        model.to_str().unwrap(),
        "--target-deg",
        "90",
        "--tolerance-deg",
        "2",
    ]));
    let used = decided["config"]["tightening"]["scale_sigma"]
        .as_f64()
        .unwrap();
    assert!((used - u).abs() < 1e-6 * u.max(1e-3), "{used} vs {u}");

    // The held-out run: every turn's error, with the model and without.
    let turns = |extra: &[&str]| {
        let mut args = vec!["run", runs[3].as_str(), "--format", "json"];
        args.extend(extra);
        let run = json_of(&gyro(&args));
        run["movements"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["reference_deg"].as_f64().unwrap().abs() > 10.0)
            .map(|m| m["error_deg"].as_f64().unwrap().abs())
            .fold(0.0_f64, f64::max)
    };
    let (without, with) = (turns(&[]), turns(&["--model", model.to_str().unwrap()]));
    assert!(
        with < 0.25 * without,
        "worst turn error {without} -> {with} deg"
    );

    let refused = dir.join("refused.json");
    let out = gyro(&[
        "calibrate",
        &runs[0],
        "--reference-delay-s",
        "1.5",
        "-o",
        refused.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--reference-delay-s 1.5"), "{stderr}");
    assert!(!refused.exists());
}

/// A gyro 60 ms behind its reference: `run` measures the lag and warns in every output;
/// scored with that delay, or on the bench fixture, it does not.
#[test]
fn a_lagging_reference_is_measured_and_said() {
    let scratch = temp_dir("reference-lag");
    let dir = scratch.path();
    let log = dir.join("late.csv");
    let out = gyro(&[
        "simulate",
        "--force",
        "-o",
        log.to_str().unwrap(),
        "--seed",
        "7",
        "--duration-s",
        "40",
        "--effect",
        "latency:delay_s=0.06",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log = log.to_str().unwrap();
    let report = json_of(&gyro(&["run", log, "--format", "json"]));
    let lag = report["summary"]["reference_lag_s"].as_f64().unwrap();
    assert!((lag - 0.06).abs() < 0.004, "{lag}");
    let warning = report["warnings"][0].as_str().unwrap();
    assert!(
        warning.contains("the gyro lags the reference as logged by 60 ms"),
        "{warning}"
    );
    let table = gyro(&["run", log]);
    assert!(String::from_utf8_lossy(&table.stdout).contains("warning: the gyro lags"));
    let csv = gyro(&["run", log, "--format", "csv"]);
    assert!(String::from_utf8_lossy(&csv.stderr).contains("warning: the gyro lags"));

    let model = write(
        dir,
        "delay.json",
        r#"{"format": "gyro-model", "version": 1, "reference_delay_s": 0.06}"#,
    );
    let scored = json_of(&gyro(&["run", log, "--format", "json", "--model", &model]));
    assert!(scored["summary"]["reference_lag_s"].as_f64().unwrap().abs() < 0.004);
    assert_eq!(
        scored["warnings"],
        serde_json::json!([]),
        "{}",
        scored["warnings"]
    );
    assert_eq!(scored["findings"], serde_json::json!([]));
    // The warning names the flag that scores it; the flag does, over the model's delay.
    assert!(warning.contains("--reference-delay-s 0.06"), "{warning}");
    let flagged = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--reference-delay-s",
        "0.06",
    ]));
    assert!(
        flagged["summary"]["reference_lag_s"]
            .as_f64()
            .unwrap()
            .abs()
            < 0.004
    );
    assert_eq!(
        flagged["warnings"],
        serde_json::json!([]),
        "{}",
        flagged["warnings"]
    );
    assert_eq!(flagged["summary"], scored["summary"]);
    let over = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--model",
        &model,
        "--reference-delay-s",
        "0",
    ]));
    assert!((over["summary"]["reference_lag_s"].as_f64().unwrap() - 0.06).abs() < 0.004);
    let refused = gyro(&["run", log, "--reference-delay-s", "-1.5"]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--reference-delay-s -1.5"), "{stderr}");

    let bench = bench_log();
    let fixture = json_of(&gyro(&["run", bench.to_str().unwrap(), "--format", "json"]));
    assert!(
        fixture["summary"]["reference_lag_s"]
            .as_f64()
            .unwrap()
            .abs()
            < 0.002
    );
    assert_eq!(fixture["warnings"], serde_json::json!([]));
}

/// Verdicts without a σ (any compensation but the Kalman form) are said to be unguarded
/// in every output; with the Kalman form they are not, and without a scale uncertainty
/// every output says the guard band leaves the scale error out.
#[test]
fn verdicts_without_a_sigma_are_said_to_be_unguarded() {
    let bench = bench_log();
    let log = bench.to_str().unwrap();
    let window = ["--target-deg", "90", "--tolerance-deg", "0.5"];
    let mut args = vec!["run", log, "--format", "json", "--compensation", "none"];
    args.extend(window);
    let report = json_of(&gyro(&args));
    let warning = report["warnings"][0].as_str().unwrap();
    assert!(
        warning.contains("the verdicts have no σ") && warning.contains("guard band is zero"),
        "{warning}"
    );
    let mut args = vec![
        "run",
        log,
        "--compensation",
        "paper",
        "--scale-sigma",
        "0.01",
    ];
    args.extend(window);
    let table = String::from_utf8_lossy(&gyro(&args).stdout).to_string();
    assert!(
        table.contains("guard band is only the scale term (1% of the angle)"),
        "{table}"
    );
    // The Kalman form with a scale uncertainty: guarded, nothing to say.
    let mut args = vec!["run", log, "--format", "json", "--scale-sigma", "0.001"];
    args.extend(window);
    assert_eq!(json_of(&gyro(&args))["warnings"], serde_json::json!([]));
    // Without one, the guard band does not hold the scale error, and every output says so.
    let mut args = vec!["run", log, "--format", "json"];
    args.extend(window);
    let report = json_of(&gyro(&args));
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .as_str()
            .unwrap()
            .contains("not the gyro's scale error"),
        "{warnings:?}"
    );
    let mut args = vec!["run", log];
    args.extend(window);
    let table = String::from_utf8_lossy(&gyro(&args).stdout).to_string();
    assert!(
        table.contains("warning: the guard band holds the bias"),
        "{table}"
    );
}

/// A 100 Hz log whose PC stalls for 0.2 s at the peak of a 90° turn and then reads the
/// buffered rows 0.2 ms apart: the stall's rows are re-timed over it (a backlog), not
/// bridged as a gap and placed again after it (which read the turn as 122°).
#[test]
fn a_stalled_link_s_backlog_is_not_counted_twice() {
    let mut text = String::from("time_s,rate_dps,reference_deg\n");
    let (mut reference_deg, mut previous_rate, mut previous_stamp) = (0.0, 0.0, f64::MIN);
    for k in 0..600_u32 {
        let t = f64::from(k) * 0.01;
        let rate = if (2.0..3.0).contains(&t) {
            90.0 * (1.0 - (2.0 * std::f64::consts::PI * (t - 2.0)).cos())
        } else {
            0.0
        };
        if k > 0 {
            reference_deg += 0.5 * (rate + previous_rate) * 0.01;
        }
        previous_rate = rate;
        // Rows on time; those sampled from 2.4 s to 2.6 s wait for 2.6 s.
        let mut stamp = t;
        if (2.4..2.6).contains(&t) {
            stamp = 2.6;
        }
        stamp = stamp.max(previous_stamp + 0.0002);
        previous_stamp = stamp;
        text.push_str(&format!("{stamp:.6},{rate:.4},{reference_deg:.4}\n"));
    }
    let scratch = temp_dir("stall");
    let dir = scratch.path();
    let log = write(dir, "stall.csv", &text);
    let out = json_of(&gyro(&[
        "run",
        &log,
        "--format",
        "json",
        "--target-deg",
        "90",
        "--tolerance-deg",
        "3",
    ]));
    let input = &out["input"];
    assert_eq!(input["backlogs"].as_u64(), Some(1), "{input}");
    assert_eq!(input["gaps"].as_u64(), Some(0), "{input}");
    assert_eq!(input["filled_slots"].as_u64(), Some(0), "{input}");
    let movements = out["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 1, "{movements:?}");
    let m = &movements[0];
    assert!((m["angle_deg"].as_f64().unwrap() - 90.0).abs() < 0.5, "{m}");
    assert_eq!(m["verdict"].as_str(), Some("ok"), "{m}");
}

/// The bench fixture with `column`'s values mapped by `f`.
fn bench_with(column: &str, f: impl Fn(f64) -> f64) -> String {
    map_column(&std::fs::read_to_string(bench_log()).unwrap(), column, f)
}

/// Everything `gyro-cli ARGS` printed, stdout then stderr.
fn printed(args: &[&str]) -> String {
    let out = gyro(args);
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// An encoder wired the other way: the reference turns against the gyro. `run` (table and
/// JSON) and `calibrate` say so, with the correlation of their turns; the log as made
/// follows the gyro and says nothing of it. A rate in rad/s read as deg/s: the reference
/// turns 57 times as far, and the warning names `--rate-unit rads`, which removes it.
#[test]
fn a_reference_of_the_opposite_sense_is_said() {
    let scratch = temp_dir("opposite-sense");
    let dir = scratch.path();
    let log = write(dir, "negated.csv", &bench_with("reference_deg", |v| -v));

    let bench = bench_log();
    let as_made = json_of(&gyro(&["run", bench.to_str().unwrap(), "--format", "json"]));
    let c = as_made["input"]["reference_correlation"].as_f64().unwrap();
    assert!(c > 0.9, "{c}");
    let gain = as_made["input"]["reference_gain"].as_f64().unwrap();
    assert!((gain - 1.0).abs() < 0.1, "{gain}");
    let text = as_made.to_string();
    assert!(!text.contains("turns against") && !text.contains("times as far"));

    let report = json_of(&gyro(&["run", &log, "--format", "json"]));
    let c = report["input"]["reference_correlation"].as_f64().unwrap();
    assert!(c < -0.9, "{c}");
    let warned = report["input"]["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| {
            w.as_str()
                .unwrap()
                .contains("the reference turns against the gyro")
        });
    assert!(warned, "{}", report["input"]);
    let all = printed(&["run", &log]);
    assert!(
        all.contains("negated.csv: the reference turns against the gyro"),
        "{all}"
    );
    let model = dir.join("model.json");
    let all = printed(&["calibrate", &log, "-o", model.to_str().unwrap(), "--force"]);
    assert!(
        all.contains("negated.csv: the reference turns against the gyro"),
        "{all}"
    );

    let radians = write(dir, "radians.csv", &bench_with("rate_dps", f64::to_radians));
    let all = printed(&["run", &radians]);
    assert!(
        all.contains("radians.csv: the reference turns 57.") && all.contains("--rate-unit rads"),
        "{all}"
    );
    let read_right = json_of(&gyro(&[
        "run",
        &radians,
        "--rate-unit",
        "rads",
        "--format",
        "json",
    ]));
    let gain = read_right["input"]["reference_gain"].as_f64().unwrap();
    assert!((gain - 1.0).abs() < 0.1, "{gain}");
    assert!(!read_right.to_string().contains("times as far"));
}

/// The 1 kHz bench fixture stamped by a 64 Hz PC timer (15.625 ms ticks: 15 or 16 rows
/// share each stamp). Placed a row per slot it would take 16 times its time; resampled as
/// rows in bursts, every movement keeps its angle, and the report says what was done.
#[test]
fn rows_stamped_by_a_coarse_timer_keep_their_angles() {
    let scratch = temp_dir("coarse-timer");
    let dir = scratch.path();
    let log = write(
        dir,
        "timer.csv",
        &bench_with("time_s", |t| (t / 0.015625).floor() * 0.015625),
    );
    let table = printed(&["run", &log]);
    assert!(table.contains("% of steps a repeated stamp"), "{table}");
    let report = json_of(&gyro(&["run", &log, "--format", "json"]));
    let share = report["input"]["bursts"]["repeated_stamp_share"]
        .as_f64()
        .unwrap();
    assert!(share > 0.9, "{share}");
    let movements = report["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 6, "{}", report["movements"]);
    for m in movements {
        let error = m["error_deg"].as_f64().unwrap();
        assert!(error.abs() < 0.1, "{m}");
    }
}

/// Stamps from Arduino's `micros()` (a 32-bit count of µs) that wraps 25 s into the bench
/// log: read with `--time-unit us`, the wrap is unwrapped and said (`counter_wraps`, the
/// line), and every movement is the one of the same log without the wrap.
#[test]
fn a_micros_counter_that_wraps_is_unwrapped_and_said() {
    let scratch = temp_dir("micros");
    let dir = scratch.path();
    let span_us = 4_294_967_296.0;
    let count = |t: f64| (t * 1e6).round() + span_us - 25e6;
    let unwrapped = write(dir, "unwrapped.csv", &bench_with("time_s", count));
    let wrapped = write(
        dir,
        "micros.csv",
        &bench_with("time_s", |t| count(t).rem_euclid(span_us)),
    );
    let run = |log: &str| {
        json_of(&gyro(&[
            "run",
            log,
            "--format",
            "json",
            "--time-unit",
            "us",
        ]))
    };
    let (expected, got) = (run(&unwrapped), run(&wrapped));
    let input = &got["input"];
    assert_eq!(input["counter_wraps"].as_u64(), Some(1), "{input}");
    assert_eq!(
        input["counter_span_s"].as_f64(),
        Some(4294.967296),
        "{input}"
    );
    assert_eq!(input["backward_steps"].as_u64(), Some(0), "{input}");
    assert_eq!(expected["input"]["counter_wraps"].as_u64(), Some(0));
    let first = &input["examples"][0];
    assert_eq!(
        first[0],
        "time stamps wrap: a 32-bit count of µs (4294.967296 s), unwrapped"
    );
    assert_eq!(first[1].as_u64(), Some(25_005), "{first}"); // 4 header lines, 25 000 rows
    let movements = |out: &serde_json::Value| -> Vec<f64> {
        out["movements"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["angle_deg"].as_f64().unwrap())
            .collect()
    };
    assert!(movements(&got).len() >= 2);
    assert_eq!(movements(&got), movements(&expected));
    let table = printed(&["run", &wrapped, "--time-unit", "us"]);
    assert!(
        table.contains("1 wraps of the time stamps' counter unwrapped"),
        "{table}"
    );
    // Converted to MCAP, which orders messages by time, the stamps are written unwrapped
    // (and said): the MCAP log gives the same movements.
    let mcap = dir.join("micros.mcap");
    let mcap = mcap.to_str().unwrap();
    let out = gyro(&["convert", &wrapped, mcap, "--time-unit", "us"]);
    let note = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{note}");
    assert!(
        note.contains(
            "time stamps wrap: a 32-bit count of µs (4294.967296 s), 1 time(s), the first at line 25005: written unwrapped"
        ),
        "{note}"
    );
    let from_mcap = json_of(&gyro(&["run", mcap, "--format", "json"]));
    assert_eq!(from_mcap["input"]["counter_wraps"].as_u64(), Some(0));
    assert_eq!(from_mcap["input"]["backward_steps"].as_u64(), Some(0));
    assert_eq!(movements(&from_mcap), movements(&expected));
}

/// A log slower than the 50 Hz output rate (a 25 Hz IMU) runs at its own rate, its
/// low-pass scaled alike (12.5 of 50 Hz → 6.25 of 25 Hz), and every output says so; one
/// at 8 Hz, as a 1 kHz log with ms stamps read as seconds would look, is still refused.
#[test]
fn a_log_slower_than_the_output_rate_runs_at_its_own_rate_and_says_so() {
    let scratch = temp_dir("slow-log");
    let dir = scratch.path();
    let slow = dir.join("slow.csv");
    let slow = slow.to_str().unwrap();
    let sim = gyro(&[
        "simulate",
        "--sample-rate-hz",
        "25",
        "--duration-s",
        "30",
        "--seed",
        "3",
        "-o",
        slow,
    ]);
    assert!(sim.status.success(), "{sim:?}");
    let out = gyro(&["run", slow, "--format", "json"]);
    let report = json_of(&out);
    assert_eq!(report["output_rate_hz"].as_f64(), Some(25.0), "{report}");
    assert_eq!(report["output_rate_lowered_from_hz"].as_f64(), Some(50.0));
    assert_eq!(report["decimation_factor"].as_u64(), Some(1));
    assert_eq!(report["config"]["filter"]["cutoff_hz"].as_f64(), Some(6.25));
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains("below the configured output rate of 50 Hz"),
        "{warnings}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("below the configured output rate"));
    // The simulation's three 90° turns, each within 0.2° of the truth.
    let movements = report["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 3, "{report}");
    for m in movements {
        assert!(m["error_deg"].as_f64().unwrap().abs() < 0.2, "{m}");
    }
    let table = String::from_utf8_lossy(&gyro(&["run", slow]).stdout).into_owned();
    assert!(
        table.contains("decimate x1 -> 25 Hz (the log's rate, below the configured 50 Hz), Butterworth order 2 at 6.25 Hz"),
        "{table}"
    );

    // `calibrate` replays it the same way and says so.
    let model = dir.join("model.json");
    let out = gyro(&["calibrate", slow, "-o", model.to_str().unwrap()]);
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("slow.csv: the log's 25 Hz is below the configured output rate of 50 Hz"),
        "{err}"
    );

    let slower = dir.join("slower.csv");
    let slower = slower.to_str().unwrap();
    let sim = gyro(&[
        "simulate",
        "--sample-rate-hz",
        "8",
        "--duration-s",
        "30",
        "--seed",
        "3",
        "-o",
        slower,
    ]);
    assert!(sim.status.success(), "{sim:?}");
    let out = gyro(&["run", slower]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("time stamps in ms read as seconds?"), "{err}");
}
