//! `calibrate`'s table leads with its answer: what the written model holds and why, in
//! degrees and plain words, before the fits and the per-run tables; no internal names.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{gyro, ok, run_csv, temp_dir};
use gyro_sim::Effect;

#[test]
fn the_answer_comes_first_in_plain_words() {
    let scratch = temp_dir("calibrate_answer");
    let dir = scratch.path();
    let effects = [
        Effect::ScaleFactor { k: 0.02 },
        Effect::Latency { delay_s: 0.01 },
    ];
    let train: Vec<String> = (1..=3)
        .map(|i| run_csv(dir, &format!("train{i}.csv"), 1000.0, 40.0, &effects, i))
        .collect();
    let holdout = run_csv(dir, "hold.csv", 1000.0, 40.0, &effects, 9);
    let model = dir.join("model.json").to_string_lossy().into_owned();
    let mut args = vec!["calibrate"];
    args.extend(train.iter().map(String::as_str));
    args.extend(["--holdout", &holdout, "-o", &model]);
    let table = ok(&gyro(&args));
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines[0], "calibration:", "{table}");
    assert!(lines[1].contains("the written model holds"), "{table}");
    assert!(
        lines[1].contains("a scale correction of +2.0"),
        "the 2% scale is written: {table}"
    );
    assert!(
        lines[1].contains("a reference delay of ")
            && lines[1].contains("ms (the gyro lags the reference)"),
        "{table}"
    );
    assert!(
        lines[2].starts_with("  why: ") && lines[2].contains(" deg"),
        "{table}"
    );
    assert!(
        lines
            .iter()
            .take(6)
            .any(|l| l.contains("hold-out run") && l.contains(" deg")),
        "{table}"
    );
    // The details follow the answer; no internal names anywhere.
    let details = table.find("---- details").unwrap();
    assert!(table.find("file: ").unwrap() > details, "{table}");
    for internal in ["MeanMaxAbs", "Converged", "MovementRms"] {
        assert!(!table.contains(internal), "{internal} in:\n{table}");
    }
}
