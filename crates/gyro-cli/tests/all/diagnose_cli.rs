//! Integration tests of `gyro-cli diagnose`: an injected effect named blind and
//! compensated by `run --model`, the JSON contract, and bad input.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{gyro, json_of, map_column, ok, run_csv, run_csv_from, temp_dir, write};

use gyro_sim::Effect;
use std::path::Path;

/// Runs simulated from the model a diagnosis starts from (`gyro_diagnose::default_prior`:
/// the CRM100 without a bias wander), at 250 Hz for 45 s, with `effects`.
fn runs(dir: &Path, prefix: &str, count: usize, effects: &[Effect], seed: u64) -> Vec<String> {
    let model = gyro_sim::SensorModel {
        sample_rate_hz: 250.0,
        ..gyro_diagnose::default_prior()
    };
    (0..count)
        .map(|i| {
            let name = format!("{prefix}{i}.csv");
            run_csv_from(dir, &name, &model, 45.0, effects, seed + i as u64)
        })
        .collect()
}

fn fails_with(args: &[&str], needle: &str) {
    let out = gyro(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: expected `{needle}` in: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "one-line error: {stderr}");
}

#[test]
fn names_an_injected_scale_factor_and_compensates_it() {
    let scratch = temp_dir("diagnose_scale");
    let dir = scratch.path();
    let effect = [Effect::ScaleFactor { k: 0.02 }];
    let train = runs(dir, "train", 4, &effect, 10);
    let holdout = runs(dir, "hold", 3, &effect, 50);
    let model = dir.join("model.json");
    let report = dir.join("report");
    let report_s = report.to_string_lossy().into_owned();
    let mut args = vec![
        "diagnose",
        "--members",
        "20",
        "--candidate-members",
        "8",
        "--report",
        &report_s,
        "-o",
    ];
    let model_s = model.to_string_lossy().into_owned();
    args.push(&model_s);
    args.push("--train");
    args.extend(train.iter().map(String::as_str));
    args.push("--holdout");
    args.extend(holdout.iter().map(String::as_str));
    let table = ok(&gyro(&args));
    // The answer in the first five lines, in degrees and plain words.
    let head: Vec<&str> = table.lines().take(5).collect();
    let head = head.join("\n");
    let reads = ["2.0", "1.9", "2.1"].map(|k| format!("The gyro reads {k}"));
    assert!(
        reads.iter().any(|r| head.contains(r.as_str()))
            && head.contains("more than the reference (scale factor)"),
        "{table}"
    );
    assert!(
        head.contains("the scale cuts the held-out angle error from") && head.contains("°"),
        "{table}"
    );
    // The report's page leads with the same verdict, before any table.
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    let verdict = html.find("the scale cuts").unwrap();
    assert!(verdict < html.find("<table").unwrap(), "{html}");
    // The JSON contract, from the report's diagnosis.json (the object `--format json`
    // prints).
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("diagnosis.json")).unwrap())
            .unwrap();
    // The contract's keys.
    for key in [
        "train_before",
        "train_after",
        "holdout_before",
        "holdout_after",
        "floor",
    ] {
        assert!(d["gap"][key].is_number(), "gap.{key}: {}", d["gap"]);
    }
    assert!(d["where"][0]["segment"].is_string() && d["where"][0]["z"].is_number());
    let first = &d["effects"][0];
    for key in [
        "delta_bic",
        "holdout_gap_before",
        "holdout_gap_after",
        "fraction_closed",
    ] {
        assert!(first[key].is_number(), "effects[0].{key}: {first}");
    }
    // An effect whose test does not pass is not scored on the held-out runs: its
    // held-out figures are null, said so in the table.
    for e in d["effects"].as_array().unwrap() {
        let passes = !e["test"].as_str().unwrap().ends_with("does not pass");
        assert_eq!(e["delta_bic"].is_number(), passes, "{e}");
        assert_eq!(e["holdout_gap_after"].is_number(), passes, "{e}");
        assert!(e["holdout_gap_before"].is_number(), "{e}");
    }
    assert_eq!(first["id"], "scale_factor", "{}", d["effects"]);
    assert_eq!(first["significant"], true);
    let k = first["params"]["k"].as_f64().unwrap();
    assert!((k - 0.02).abs() < 2e-3, "k = {k}");
    assert_eq!(d["verdict"]["unmodelled"][0], "scale_factor");
    // With the true effect the model fits: nothing is left unexplained.
    assert_eq!(d["verdict"]["model_fits"], true, "{}", d["unexplained"]);
    assert_eq!(d["unexplained"].as_array().map(Vec::len), Some(0));
    assert!(d["verdict"]["fraction_closed_holdout"].as_f64().unwrap() > 0.8);
    let g = &d["gap"];
    assert!(g["holdout_after"].as_f64().unwrap() < 0.2 * g["holdout_before"].as_f64().unwrap());

    // The model file carries the correction; `run --model` uses it.
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let scale = file["config"]["correction"]["scale_k"].as_f64().unwrap();
    assert!((scale - 0.02).abs() < 2e-3, "{file}");
    let comp = &d["compensation"]["runs"];
    for r in comp.as_array().unwrap() {
        let (before, after) = (
            r["max_abs_error_before_deg"].as_f64().unwrap(),
            r["max_abs_error_after_deg"].as_f64().unwrap(),
        );
        assert!(after < 0.5 * before, "{r}");
    }
    let with = json_of(&gyro(&[
        "run",
        &holdout[0],
        "--format",
        "json",
        "--model",
        &model_s,
    ]));
    let without = json_of(&gyro(&["run", &holdout[0], "--format", "json"]));
    let e = |v: &serde_json::Value| v["summary"]["max_abs_error_deg"].as_f64().unwrap();
    assert!(
        e(&with) < 0.5 * e(&without),
        "{} vs {}",
        e(&with),
        e(&without)
    );
}

/// Diagnose `train` against `holdout` (small ensembles) and return the JSON.
fn diagnose_json(train: &[String], holdout: &[String]) -> serde_json::Value {
    let mut args = vec![
        "diagnose",
        "--format",
        "json",
        "--members",
        "20",
        "--candidate-members",
        "8",
        "--train",
    ];
    args.extend(train.iter().map(String::as_str));
    args.push("--holdout");
    args.extend(holdout.iter().map(String::as_str));
    json_of(&gyro(&args))
}

#[test]
fn a_clock_error_is_named_from_the_time_stamps_not_as_a_scale_factor() {
    let scratch = temp_dir("diagnose_clock");
    let dir = scratch.path();
    let effect = [Effect::ClockError { ppm: 5000.0 }];
    let train = runs(dir, "train", 4, &effect, 20);
    let holdout = runs(dir, "hold", 3, &effect, 60);
    let d = diagnose_json(&train, &holdout);
    let first = &d["effects"][0];
    assert_eq!(first["id"], "clock_error", "{}", d["effects"]);
    assert_eq!(first["significant"], true);
    let ppm = first["params"]["ppm"].as_f64().unwrap();
    assert!((ppm - 5000.0).abs() < 1.0, "ppm = {ppm}");
    assert_eq!(
        d["verdict"]["unmodelled"],
        serde_json::json!(["clock_error"])
    );

    // Without the nominal rate in the logs, the grid takes the stamps' own rate: the
    // rate is right on that time base, so nothing is named and the clock error is
    // listed as untestable, with what it needs.
    let strip = |paths: &[String], prefix: &str| -> Vec<String> {
        paths
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let text = std::fs::read_to_string(p).unwrap();
                let kept: String = text
                    .lines()
                    .filter(|l| !l.starts_with("# sample_rate_hz"))
                    .map(|l| format!("{l}\n"))
                    .collect();
                write(dir, &format!("{prefix}{i}.csv"), &kept)
            })
            .collect()
    };
    let d = diagnose_json(&strip(&train, "bare_train"), &strip(&holdout, "bare_hold"));
    assert_eq!(
        d["verdict"]["unmodelled"],
        serde_json::json!([]),
        "{}",
        d["effects"]
    );
    let untestable = d["untestable"].as_array().unwrap();
    assert!(
        untestable.iter().any(|u| u["id"] == "clock_error"
            && u["reason"].as_str().unwrap().contains("sample_rate_hz")),
        "{untestable:?}"
    );
}

#[test]
fn nothing_significant_without_an_effect() {
    let scratch = temp_dir("diagnose_null");
    let dir = scratch.path();
    let train = runs(dir, "train", 4, &[], 200);
    let holdout = runs(dir, "hold", 3, &[], 300);
    let mut args = vec![
        "diagnose",
        "--members",
        "20",
        "--candidate-members",
        "8",
        "--train",
    ];
    args.extend(train.iter().map(String::as_str));
    args.push("--holdout");
    args.extend(holdout.iter().map(String::as_str));
    let table = ok(&gyro(&args));
    assert!(table.contains("verdict: nothing significant"), "{table}");
    assert!(
        table
            .lines()
            .nth(1)
            .is_some_and(|l| l.contains("No effect of the vocabulary is named")),
        "{table}"
    );
    assert!(
        !table.contains("does not explain") && !table.contains("Not explained"),
        "the nominal model fits runs simulated with it: {table}"
    );
    assert!(
        table.contains("temperature_bias"),
        "every effect is listed: {table}"
    );
    // The effective noise on moving data is said beside the sensor's own, from the rests.
    assert!(
        table.contains("effective noise on moving data: angle random walk at most")
            && table.contains("x the rests'"),
        "{table}"
    );
}

/// The simulator's default sensor wanders (a Gauss–Markov bias of σ 0.05 °/s over 100 s);
/// a diagnosis starts from a model that does not, so it names that wander, and only
/// what a bias wander is: on 45 s runs mostly a bias that differs from run to run.
#[test]
fn the_simulators_own_bias_wander_is_named_and_nothing_else() {
    let scratch = temp_dir("diagnose_wander");
    let dir = scratch.path();
    let run = |name: String, seed: u64| run_csv(dir, &name, 250.0, 45.0, &[], seed);
    let train: Vec<String> = (0..4).map(|i| run(format!("t{i}.csv"), 200 + i)).collect();
    let holdout: Vec<String> = (0..3).map(|i| run(format!("h{i}.csv"), 300 + i)).collect();
    let d = diagnose_json(&train, &holdout);
    let named: Vec<&str> = d["verdict"]["unmodelled"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let wanders = ["turn_on_bias", "rate_random_walk", "bias_instability"];
    assert!(!named.is_empty(), "{}", d["effects"]);
    assert!(named.iter().all(|n| wanders.contains(n)), "{named:?}");
    if let Some(e) = (d["effects"].as_array().unwrap().iter())
        .find(|e| e["id"] == "turn_on_bias" && e["significant"] == true)
    {
        let [lo, hi] = [0, 1].map(|i| e["ci95"]["sigma_dps"][i].as_f64().unwrap());
        assert!(lo <= 0.05 && 0.05 <= hi, "{e}");
    }
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let scratch = temp_dir("diagnose_bad");
    let dir = scratch.path();
    let a = run_csv(dir, "a.csv", 250.0, 20.0, &[], 1);
    let b = run_csv(dir, "b.csv", 250.0, 20.0, &[], 2);
    let c = run_csv(dir, "c.csv", 250.0, 20.0, &[], 3);
    let fast = run_csv(dir, "fast.csv", 500.0, 20.0, &[], 4);
    let no_reference = write(
        dir,
        "noref.csv",
        "time_s,rate_dps\n0.0,0.1\n0.004,0.1\n0.008,0.2\n0.012,0.1\n",
    );
    fails_with(
        &[
            "diagnose",
            "--train",
            &a,
            &no_reference,
            "--holdout",
            &b,
            &c,
        ],
        "no reference_deg column",
    );
    fails_with(
        &["diagnose", "--train", &a, &b, "--holdout", &c],
        "held-out run(s): at least 2 are needed",
    );
    fails_with(
        &["diagnose", "--train", &a, "--holdout", &b, &c],
        "training run(s): at least 2 are needed",
    );
    fails_with(
        &["diagnose", "--train", &a, &b, "--holdout", &c, &fast],
        "sample rates differ",
    );
    // Refused as the command line is parsed (status 2), the option named.
    let out = gyro(&[
        "diagnose",
        "--train",
        &a,
        &b,
        "--holdout",
        &c,
        &fast,
        "--split-s",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("invalid value '0' for '--split-s"),
        "{stderr}"
    );
    fails_with(
        &["diagnose", "--train", &a, &b, "--holdout", &c, &c],
        "the same run as",
    );
    fails_with(
        &[
            "diagnose",
            "--train",
            &a,
            "missing.csv",
            "--holdout",
            &b,
            &c,
        ],
        "missing.csv",
    );
}

/// Runs whose reference counts the other way (an encoder wired in reverse): the diagnosis
/// leads with it, in the table's headline and the JSON's `reference_warnings`, since every
/// effect it fits against such a reference measures the mismatch.
#[test]
fn a_reference_of_the_opposite_sense_leads_the_diagnosis() {
    let scratch = temp_dir("diagnose_opposite");
    let dir = scratch.path();
    let negate = |paths: Vec<String>, prefix: &str| -> Vec<String> {
        paths
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let text = std::fs::read_to_string(p).unwrap();
                let negated = map_column(&text, "reference_deg", |x| -x);
                write(dir, &format!("{prefix}{i}.csv"), &negated)
            })
            .collect()
    };
    let train = negate(runs(dir, "train", 3, &[], 400), "negated_train");
    let holdout = negate(runs(dir, "hold", 2, &[], 500), "negated_hold");
    let mut args = vec![
        "diagnose",
        "--members",
        "8",
        "--candidate-members",
        "4",
        "--train",
    ];
    args.extend(train.iter().map(String::as_str));
    args.push("--holdout");
    args.extend(holdout.iter().map(String::as_str));
    let table = ok(&gyro(&args));
    let headline: Vec<&str> = table
        .lines()
        .skip_while(|l| !l.starts_with("diagnosis"))
        .collect();
    assert!(
        headline.get(1).is_some_and(
            |l| l.contains("warning: on 5 of 5 runs the reference turns against the gyro")
        ),
        "{table}"
    );
    args.extend(["--format", "json"]);
    let d = json_of(&gyro(&args));
    let first = d["reference_warnings"][0].as_str().unwrap();
    assert!(first.contains("turns against the gyro"), "{first}");
}
