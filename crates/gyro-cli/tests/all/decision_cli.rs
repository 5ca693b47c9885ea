//! `gyro-cli run --target-deg T --tolerance-deg D`: each movement's guard-banded verdict and
//! its angle's standard deviation, in every output.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, json_of, ok, temp_dir, write};

#[test]
fn movements_get_a_verdict_in_the_tightening_direction() {
    let log = bench_log();
    let log = log.to_str().unwrap();
    // The fixture: six 90° turns, two positive, four negative; errors of 0.02° at most.
    let report = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--target-deg",
        "90",
        "--tolerance-deg",
        "1",
    ]));
    let movements = report["movements"].as_array().unwrap();
    assert_eq!(movements.len(), 6);
    for m in movements {
        let std = m["angle_std_deg"].as_f64().unwrap();
        assert!(std > 0.0 && std < 0.5, "{m}");
        let angle = m["angle_deg"].as_f64().unwrap();
        if angle > 0.0 {
            assert_eq!(m["verdict"], "ok", "{m}");
        } else {
            assert!(m.get("verdict").is_none(), "a turn the other way: {m}");
        }
    }
    // The other direction judges the negative turns; a window 2° off makes them nok.
    let report = json_of(&gyro(&[
        "run",
        log,
        "--format",
        "json",
        "--target-deg",
        "92",
        "--tolerance-deg",
        "0.5",
        "--tightening-direction",
        "negative",
    ]));
    let verdicts: Vec<&str> = report["movements"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m["verdict"].as_str())
        .collect();
    assert_eq!(verdicts, ["nok"; 4]);
    // Within k·σ of a limit: recheck (target 90.3 ± 0.3: the angle sits on the lower limit).
    let out = ok(&gyro(&[
        "run",
        log,
        "--target-deg",
        "90.3",
        "--tolerance-deg",
        "0.3",
    ]));
    assert!(out.contains("verdict"), "{out}");
    assert!(out.contains("recheck"), "{out}");
    assert!(out.contains("tightening 90.3 ± 0.3 deg"), "{out}");
    // Without a window: no verdict anywhere.
    let report = json_of(&gyro(&["run", log, "--format", "json"]));
    assert!(report["movements"][0].get("verdict").is_none());
}

/// A movement across a gap in the log, or cut off by its end, is `invalid` and warned about.
#[test]
fn a_movement_across_a_gap_is_invalid() {
    let text = std::fs::read_to_string(bench_log()).unwrap();
    // Drop 0.2 s of rows in the middle of the first turn (2.995-5.175 s).
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.split(',')
                .next()
                .and_then(|t| t.parse::<f64>().ok())
                .is_none_or(|t| !(4.0..4.2).contains(&t))
        })
        .collect();
    let scratch = temp_dir("decision-gap");
    let dir = scratch.path();
    let path = write(dir, "gap.csv", &(kept.join("\n") + "\n"));
    let args = [
        "run",
        path.as_str(),
        "--target-deg",
        "90",
        "--tolerance-deg",
        "5",
    ];
    let table = ok(&gyro(&args));
    assert!(table.contains("GAP ("), "{table}");
    assert!(table.contains("warning: movement 1 spans"), "{table}");
    let mut json_args = args.to_vec();
    json_args.extend(["--format", "json"]);
    let report = json_of(&gyro(&json_args));
    let first = &report["movements"][0];
    assert!(first["filled_samples"].as_u64().unwrap() >= 190, "{first}");
    assert_eq!(first["verdict"], "invalid", "{first}");
    assert_eq!(report["movements"][2]["verdict"], "ok");
}

/// The window can come from the model file (`config.tightening`); a bad one is refused.
#[test]
fn the_window_comes_from_the_model_file() {
    let scratch = temp_dir("decision-model");
    let dir = scratch.path();
    let model = write(
        dir,
        "model.json",
        r#"{"format":"gyro-model","version":1,"config":{"tightening":{"target_deg":90,"tolerance_deg":1}}}"#,
    );
    let log = bench_log();
    let out = ok(&gyro(&["run", log.to_str().unwrap(), "--model", &model]));
    assert!(out.contains("tightening 90 ± 1 deg"), "{out}");
    assert!(out.contains("ok 2, nok 0"), "{out}");
    let bad = write(
        dir,
        "bad.json",
        r#"{"format":"gyro-model","version":1,"config":{"tightening":{"target_deg":90,"tolerance_deg":-1}}}"#,
    );
    let out = gyro(&["run", log.to_str().unwrap(), "--model", &bad]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("tightening.tolerance_deg"));
}
