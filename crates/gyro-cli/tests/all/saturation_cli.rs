//! `gyro-cli run` says which movements reached the sensor's range: `"saturated"` on every
//! movement in JSON, a column in CSV, a mark and a warning in the table.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, json_of, map_column, ok, temp_dir, write};

/// The bench fixture as a sensor of range ±120 deg/s reads it (three of its six turns
/// peak above): beyond 119.5 deg/s a reading lands anywhere within 0.5% below the range
/// and 0.1 deg/s above it, as a noisy output at its full scale does, with no two alike
/// in a row (no clip plateau: only the range can flag them). Written into `dir`.
fn clipped_log(dir: &std::path::Path) -> String {
    let text = std::fs::read_to_string(bench_log()).unwrap();
    let at_range = |x: f64| {
        if x.abs() > 119.5 {
            x.signum() * (119.5 + (x.abs() * 7.3).fract() * 0.6)
        } else {
            x
        }
    };
    write(dir, "clipped.csv", &map_column(&text, "rate_dps", at_range))
}

/// (time_s, rate_dps) of the bench fixture.
fn fixture_rates() -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(bench_log()).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time_s"))
        .map(|l| {
            let mut fields = l.split(',');
            let t = fields.next().unwrap().parse().unwrap();
            let r = fields.next().unwrap().parse().unwrap();
            (t, r)
        })
        .collect()
}

#[test]
fn json_carries_saturated_on_every_movement() {
    let log = bench_log();
    let log = log.to_str().unwrap();
    // The fixture never reaches ±300 deg/s: no movement is saturated, range known or not.
    for extra in [&[][..], &["--range-dps", "300"][..]] {
        let mut args = vec!["run", log, "--format", "json"];
        args.extend_from_slice(extra);
        let report = json_of(&gyro(&args));
        let movements = report["movements"].as_array().unwrap();
        assert_eq!(movements.len(), 6);
        for m in movements {
            assert_eq!(m["saturated"].as_bool(), Some(false), "{m}");
        }
        assert!(
            !report.to_string().contains("beyond the sensor range"),
            "{report}"
        );
    }

    // Told the sensor's range is ±120 deg/s, the fixture reads up to 208 deg/s, which no
    // sensor of that range could: said, and no movement is flagged for reaching it.
    let report = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--range-dps",
        "120",
    ]));
    let said = report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .any(|w| w.contains("beyond the sensor range of ±120 deg/s in use"));
    assert!(said, "{}", report["warnings"]);
    assert!(report["summary"]["largest_abs_rate_dps"].as_f64().unwrap() > 200.0);
    assert_eq!(report["summary"]["range_contradicted"], true);
    let movements = report["movements"].as_array().unwrap();
    assert!(movements.iter().all(|m| m["saturated"] == false));

    // Clipped at ±120 deg/s: exactly the movements with a reading within 0.5% of it are
    // flagged (peaks 78 to 208 deg/s: three of six), and the range stands.
    let scratch = temp_dir("saturation-json");
    let dir = scratch.path();
    let clipped = clipped_log(dir);
    let report = json_of(&gyro(&[
        "run",
        &clipped,
        "--format",
        "json",
        "--range-dps",
        "120",
    ]));
    assert!(
        !report.to_string().contains("beyond the sensor range"),
        "{report}"
    );
    assert_eq!(report["config"]["range_dps"].as_f64(), Some(120.0));
    let rates = fixture_rates();
    let mut flagged = 0;
    for m in report["movements"].as_array().unwrap() {
        let (start, end) = (
            m["start_time_s"].as_f64().unwrap(),
            m["end_time_s"].as_f64().unwrap(),
        );
        let peak = rates
            .iter()
            .filter(|(t, _)| *t >= start && *t <= end)
            .fold(0.0_f64, |a, (_, r)| a.max(r.abs()));
        let reached = peak >= 120.0 * (1.0 - 0.005);
        assert_eq!(m["saturated"].as_bool(), Some(reached), "peak {peak}: {m}");
        flagged += usize::from(reached);
    }
    assert_eq!(flagged, 3);
}

/// A model written from logs of a sensor that reads beyond the CRM100's ±300 deg/s
/// (the rasteiro MPU6500 at up to 450 deg/s) says no range, and `run` with it flags no
/// turn saturated; told `--range-dps 300`, `run` says the readings go beyond it and flags
/// none either.
#[test]
fn a_model_from_a_faster_sensor_claims_no_range() {
    let real = gyro_log::real_data::dir().join("rasteiro");
    let log = real.join("rasteiro_MPU6500RM3100_V1500_z.csv");
    if !log.exists() {
        gyro_log::real_data::skipped(&log.display().to_string());
        return;
    }
    let log = log.to_str().unwrap();
    let scratch = temp_dir("saturation-range-dropped");
    let dir = scratch.path();
    let model = dir.join("m.json");
    let model = model.to_str().unwrap();
    let out = gyro(&["calibrate", log, "--objective", "movement-rms", "-o", model]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("that range is not this sensor's"),
        "{stderr}"
    );
    let report = json_of(&gyro(&["run", log, "--format", "json", "--model", model]));
    assert!(
        report["config"]["range_dps"].is_null(),
        "{}",
        report["config"]
    );
    let movements = report["movements"].as_array().unwrap();
    assert!(movements.len() >= 2);
    assert!(
        movements.iter().all(|m| m["saturated"] == false),
        "{movements:?}"
    );
    let told = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--model",
        model,
        "--range-dps",
        "300",
    ]));
    assert!(told["movements"]
        .as_array()
        .unwrap()
        .iter()
        .all(|m| m["saturated"] == false));
    assert!(told["warnings"]
        .to_string()
        .contains("beyond the sensor range of ±300"));
}

#[test]
fn table_marks_and_warns_and_csv_has_a_column() {
    let scratch = temp_dir("saturation-table");
    let dir = scratch.path();
    let log = clipped_log(dir);
    let log = log.as_str();
    let table = ok(&gyro(&["run", log, "--range-dps", "120"]));
    assert!(table.contains("sensor range ±120 deg/s"), "{table}");
    let marked = table.lines().filter(|l| l.ends_with("SATURATED")).count();
    let warnings: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("warning: movement "))
        .collect();
    assert!(marked == 3 && warnings.len() == marked, "{table}");
    assert!(
        warnings[0].ends_with(
            "reached the sensor range (120 deg/s) or clipped below it: its angle is a lower bound"
        ),
        "{}",
        warnings[0]
    );
    let plain = ok(&gyro(&["run", log]));
    assert!(
        !plain.contains("SATURATED") && !plain.contains("warning"),
        "{plain}"
    );

    let csv = ok(&gyro(&[
        "run",
        log,
        "--format",
        "csv",
        "--range-dps",
        "120",
    ]));
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == "saturated").unwrap();
    let flags: Vec<&str> = lines.map(|r| r.split(',').nth(column).unwrap()).collect();
    assert_eq!(flags.len(), 6);
    assert_eq!(flags.iter().filter(|f| **f == "true").count(), marked);
    assert_eq!(flags.iter().filter(|f| **f == "false").count(), 6 - marked);
}

#[test]
fn range_comes_from_the_model_unless_given() {
    let scratch = temp_dir("saturation-model");
    let dir = scratch.path();
    let log = clipped_log(dir);
    let log = log.as_str();
    let model = write(
        dir,
        "m.json",
        r#"{"format": "gyro-model", "version": 1, "sensor": {"range_dps": 120}}"#,
    );
    let flagged = |args: &[&str]| -> (Option<f64>, usize) {
        let report = json_of(&gyro(args));
        let n = report["movements"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["saturated"].as_bool().unwrap())
            .count();
        (report["config"]["range_dps"].as_f64(), n)
    };
    let from_model = flagged(&["run", log, "--format", "json", "--model", &model]);
    let from_flag = flagged(&["run", log, "--format", "json", "--range-dps", "120"]);
    assert_eq!(from_model, from_flag);
    assert_eq!(from_model, (Some(120.0), 3));
    // The flag wins over the model.
    let overridden = flagged(&[
        "run",
        log,
        "--format",
        "json",
        "--model",
        &model,
        "--range-dps",
        "300",
    ]);
    assert_eq!(overridden, (Some(300.0), 0));
    // A model without a sensor section: the section's default range, the CRM100's ±300.
    let bare = write(
        dir,
        "bare.json",
        r#"{"format": "gyro-model", "version": 1}"#,
    );
    assert_eq!(
        flagged(&["run", log, "--format", "json", "--model", &bare]),
        (Some(300.0), 0)
    );
    // A range that is no range is refused as the command line is parsed, naming it.
    let out = gyro(&["run", log, "--range-dps", "0"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--range-dps"), "{stderr}");
}
