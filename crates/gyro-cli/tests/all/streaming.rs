//! `gyro-cli run` streams its log (read → grid → pipeline, row by row). These tests pin it
//! to the materialising path the other commands use (`read_log`, `regularize`, `replay`):
//! the same report, series and quality figures, or the same error, on the fixtures, the
//! real logs (when shared/ is beside the workspace), and generated irregular logs.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, ok, temp_dir, workspace_root, write};
use gyro_analysis::replay::{self, ReplayFileError, ReplayOptions, RunReport};
use gyro_core::{Compensation, Config, Correction};
use gyro_log::{self as log, GridOptions, LogOptions};
use gyro_report::run as report;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The materialising path, with the errors as `gyro-cli run` printed them.
fn materialised(
    path: &Path,
    grid: &GridOptions,
    config: &Config,
    options: &ReplayOptions,
) -> Result<RunReport, String> {
    let raw = log::read_log(path, &LogOptions::default()).map_err(|e| e.to_string())?;
    let regular = log::regularize(&raw, grid).map_err(|e| e.to_string())?;
    replay::replay_with(&regular, config, options).map_err(|cause| {
        let e = ReplayFileError::Config {
            path: path.to_path_buf(),
            cause,
            sample_rate_hz: regular.sample_rate_hz,
            output_rate_hz: config.output_rate_hz,
        };
        format!("{:#}", anyhow::Error::new(e))
    })
}

/// The streaming path.
fn streamed(
    path: &Path,
    grid: &GridOptions,
    config: &Config,
    options: &ReplayOptions,
) -> Result<RunReport, String> {
    replay::replay_file(
        path,
        &LogOptions::default(),
        grid,
        config,
        options,
        &mut |_| {},
    )
    .map_err(|e| match e {
        ReplayFileError::Log(e) => e.to_string(),
        e @ ReplayFileError::Config { .. } => format!("{:#}", anyhow::Error::new(e)),
    })
}

/// Everything a report holds (Debug prints every float exactly) and what `run` prints.
fn describe(path: &Path, result: Result<RunReport, String>) -> String {
    match result {
        Ok(report) => {
            let file = path.display().to_string();
            let findings = gyro_analysis::findings::of_run(&report, &[]);
            let mut series = Vec::new();
            report::series_csv(&mut series, &report, &findings).unwrap();
            let mut text = format!("{report:?}\n");
            text.push_str(&report::table(&file, &report, &findings));
            writeln!(text, "{}", report::json(&file, &report, &findings).unwrap()).unwrap();
            text.push_str(&String::from_utf8(series).unwrap());
            text
        }
        Err(e) => format!("error: {e}"),
    }
}

/// Compare both paths on `path` under a few grid options and configurations (`all`: six,
/// else two); returns the outcome of the default run (for the callers' own checks).
fn assert_same(path: &Path, all: bool) -> String {
    let none = Config {
        compensation: Compensation::None,
        ..Config::default()
    };
    let short_gaps = GridOptions {
        max_gap_s: 0.05,
        ..GridOptions::default()
    };
    let rate_option = GridOptions {
        sample_rate_hz: Some(100.0),
        max_gap_s: 2.0,
    };
    // A model's correction (temperature terms included) and a reference delay (which
    // takes the materialising path inside replay_file).
    let corrected = Config {
        correction: Correction {
            scale_k: 0.01,
            asymmetry_k: 0.002,
            bias_dps_per_c: 0.01,
            scale_per_c: 0.0005,
            temperature_ref_c: None,
        },
        ..Config::default()
    };
    let none_delay = ReplayOptions::default();
    let delayed = ReplayOptions {
        reference_delay_s: 0.004,
        ..ReplayOptions::default()
    };
    let mut runs = vec![
        (GridOptions::default(), Config::default(), none_delay),
        (short_gaps, none, none_delay),
    ];
    if all {
        runs.push((GridOptions::default(), none, none_delay));
        runs.push((rate_option, Config::default(), none_delay));
        runs.push((GridOptions::default(), corrected, none_delay));
        runs.push((GridOptions::default(), corrected, delayed));
    }
    let mut first = None;
    for (grid, config, options) in &runs {
        let a = describe(path, materialised(path, grid, config, options));
        let b = describe(path, streamed(path, grid, config, options));
        if a != b {
            let line = a.lines().zip(b.lines()).position(|(x, y)| x != y);
            panic!(
                "{}: {grid:?}, {:?}: streaming differs from materialising (line {line:?})\n--- materialised\n{}\n--- streamed\n{}",
                path.display(),
                config.compensation,
                a.chars().take(400).collect::<String>(),
                b.chars().take(400).collect::<String>(),
            );
        }
        first.get_or_insert(a);
    }
    first.unwrap_or_default()
}

/// The quality report in an outcome (or the error).
fn quality(outcome: &str) -> &str {
    let start = outcome.find("input: Quality").unwrap_or(0);
    let end = outcome.find(", config: Config").unwrap_or(outcome.len());
    &outcome[start..end.max(start)]
}

/// A 100 Hz log with the warts of real data: duplicate rows, gaps, jitter, missing rates,
/// references and temperatures, a repeated time stamp with new values, a step back, and
/// missing rates at both ends (trimmed). `rate_header`: `# sample_rate_hz: 100`, else
/// the rate is detected.
fn wart_log(rate_header: bool) -> String {
    let mut s = String::new();
    if rate_header {
        s.push_str("# sample_rate_hz: 100\n");
    }
    s.push_str("time_s,rate_dps,reference_deg,temperature_c\n");
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
        if [500, 700, 701, 702].contains(&k) {
            continue; // lost samples: gaps
        }
        let jitter = if k % 7 == 3 { 0.001 } else { 0.0 };
        let rate_field = match k {
            0..3 | 998.. | 200 | 201 | 650 => String::new(),
            651 => "nan".into(),
            _ => format!("{rate:.4}"),
        };
        let reference = if (400..405).contains(&k) || (800..900).contains(&k) {
            String::new()
        } else {
            format!("{angle:.4}")
        };
        let temperature = if (10..13).contains(&k) {
            String::new()
        } else {
            format!("{:.3}", 25.0 + t / 100.0)
        };
        let row = format!("{:.3},{rate_field},{reference},{temperature}\n", t + jitter);
        s.push_str(&row);
        if k == 300 || k == 301 {
            s.push_str(&row); // the logger repeated the row
        }
        if k == 310 {
            let again = format!(
                "{:.3},{:.4},{reference},{temperature}\n",
                t + jitter,
                rate + 0.1
            );
            s.push_str(&again);
        }
        if k == 320 {
            s.push_str(&format!(
                "{:.3},{rate:.4},{reference},{temperature}\n",
                t - 0.002
            ));
        }
    }
    s
}

/// A jittery 1 kHz log without a rate header, longer than the rate look-ahead window, with
/// occasional lost samples, missing rates and duplicates (deterministic).
fn long_jittery_log() -> String {
    let mut s = String::from("time_s,rate_dps,reference_deg\n");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1_u64 << 53) as f64
    };
    let (mut t, mut angle) = (0.0_f64, 0.0_f64);
    for k in 0..(log::RATE_WINDOW_STEPS + 20_000) {
        t += 0.001 + (uniform() - 0.5) * 0.0004;
        if uniform() < 0.001 {
            t += 0.003;
        }
        let rate = (k as f64 / 3000.0).sin() * 20.0;
        angle += rate * 0.001;
        let rate_field = if uniform() < 0.001 {
            String::new()
        } else {
            format!("{rate:.5}")
        };
        let row = format!("{t:.6},{rate_field},{angle:.5}\n");
        s.push_str(&row);
        if uniform() < 0.001 {
            s.push_str(&row);
        }
    }
    s
}

/// Reference only from the middle on: the origin is found while streaming.
fn late_reference_log() -> String {
    let mut s = String::from("time_s,rate_dps,reference_deg\n");
    for k in 0..3000 {
        let t = k as f64 * 0.001;
        let rate = if (1.0..2.0).contains(&t) { 45.0 } else { 0.0 };
        let reference = if k < 1500 {
            String::new()
        } else {
            format!("{}", 45.0 * (t - 1.0).min(1.0))
        };
        s.push_str(&format!("{t:.3},{rate},{reference}\n"));
    }
    s
}

/// Long runs of missing references (left missing) and temperatures; missing references
/// and rates at the end.
fn long_runs_log() -> String {
    let mut s =
        String::from("# sample_rate_hz: 100\ntime_s,rate_dps,reference_deg,temperature_c\n");
    for k in 0..600 {
        let rate = if k > 590 {
            String::new()
        } else {
            format!("{:.4}", 0.1 * (k as f64 / 20.0).sin())
        };
        let reference = if (100..200).contains(&k) || k > 570 {
            String::new()
        } else {
            format!("{}", k as f64 * 0.001)
        };
        let temperature = if (250..=300).contains(&k) {
            String::new()
        } else {
            format!("{}", 25.0 + k as f64 * 0.001)
        };
        s.push_str(&format!(
            "{:.2},{rate},{reference},{temperature}\n",
            k as f64 * 0.01
        ));
    }
    s
}

/// A 100 Hz log with a run of 71 missing rates (too long), then optionally a gap too long
/// between rows, then optionally an unreadable value: the errors must come in the order
/// of the whole-log passes (read, gap between rows, run of missing rates).
fn long_missing_run_log(then_gap: bool, then_bad: bool) -> String {
    let mut s = String::from("# sample_rate_hz: 100\ntime_s,rate_dps\n");
    for k in 0..300 {
        let rate = if (50..=120).contains(&k) { "" } else { "1.0" };
        s.push_str(&format!("{:.2},{rate}\n", k as f64 * 0.01));
    }
    if then_gap {
        s.push_str("10.0,1.0\n");
    }
    if then_bad {
        s.push_str("10.01,abc\n");
    }
    s
}

fn generated_logs(dir: &Path) -> Vec<PathBuf> {
    let rate3: String = (0..100)
        .map(|k| format!("{:.4},0.1\n", k as f64 / 3.0))
        .collect();
    let files: Vec<(&str, String)> = vec![
        ("warts.csv", wart_log(true)),
        ("warts_detected_rate.csv", wart_log(false)),
        ("long_jittery.csv", long_jittery_log()),
        ("late_reference.csv", late_reference_log()),
        ("long_runs.csv", long_runs_log()),
        ("missing_run.csv", long_missing_run_log(false, false)),
        ("missing_run_gap.csv", long_missing_run_log(true, false)),
        ("missing_run_gap_bad.csv", long_missing_run_log(true, true)),
        (
            "gap_then_bad.csv",
            "# sample_rate_hz: 1000\ntime_s,rate_dps\n0.000,1.0\n0.001,1.0\n2.000,1.0\n2.001,zz\n"
                .into(),
        ),
        (
            "backwards.csv",
            "time_s,rate_dps\n10.000,1.0\n10.001,1.0\n3.000,1.0\n".into(),
        ),
        ("no_rate.csv", "time_s,rate_dps\n0.0,\n0.1,nan\n".into()),
        ("header_only.csv", "time_s,rate_dps\n".into()),
        ("one_row.csv", "time_s,rate_dps\n0.0,1.0\n".into()),
        ("ragged.csv", "time_s,rate_dps\n0.000,1.0\n0.001\n".into()),
        (
            "bad_rate_header.csv",
            "# sample_rate_hz: -5\ntime_s,rate_dps\n0.0,1.0\n0.01,1.0\n0.02,1.0\n".into(),
        ),
        // The pipeline cannot run at 3 Hz; with a gap too long, the gap is reported first.
        (
            "rate3.csv",
            format!("# sample_rate_hz: 3\ntime_s,rate_dps\n{rate3}"),
        ),
        (
            "rate3_gap.csv",
            format!("# sample_rate_hz: 3\ntime_s,rate_dps\n{rate3}40,0.1\n"),
        ),
    ];
    files
        .into_iter()
        .map(|(name, text)| PathBuf::from(write(dir, name, &text)))
        .collect()
}

#[test]
fn streaming_equals_materialising_on_fixtures_and_generated_logs() {
    let scratch = temp_dir("streaming");
    let dir = scratch.path();
    let root = workspace_root();
    let mut logs = vec![
        bench_log(),
        root.join("fixtures/mcap/ros2_imu.mcap"),
        root.join("fixtures/noise/allan_input.csv"),
    ];
    logs.extend(generated_logs(dir));
    let mut outcomes = Vec::new();
    for path in &logs {
        let all = !path.ends_with("long_jittery.csv");
        outcomes.push((path.clone(), assert_same(path, all)));
    }
    // The generated logs exercise what they are meant to.
    let outcome = |name: &str| &outcomes.iter().find(|(p, _)| p.ends_with(name)).unwrap().1;
    for (name, expected) in [
        ("warts.csv", "duplicate_rows: 2"),
        ("warts.csv", "sample_rate_source: \"metadata\""),
        (
            "warts_detected_rate.csv",
            "sample_rate_source: \"single_steps\"",
        ),
        ("long_jittery.csv", "sample_rate_source: \"single_steps\""),
        ("long_runs.csv", "trimmed_slots: 9"),
        ("missing_run.csv", "missing_run.csv:124: gap of 0.720 s"),
        (
            "missing_run_gap.csv",
            "missing_run_gap.csv:303: gap of 7.010 s",
        ),
        (
            "missing_run_gap_bad.csv",
            "missing_run_gap_bad.csv:304: column `rate_dps`",
        ),
        (
            "gap_then_bad.csv",
            "gap_then_bad.csv:6: column `rate_dps`: `zz`",
        ),
        ("backwards.csv", "backwards.csv:4: time goes back"),
        ("no_rate.csv", "no row has a rate value"),
        ("header_only.csv", "no data rows after the header"),
        ("one_row.csv", "cannot estimate the sample rate"),
        ("ragged.csv", "ragged.csv:3: row has 1 fields"),
        (
            "rate3.csv",
            "rate3.csv: cannot configure the pipeline for this log (its stamps give 3 Hz, below the output rate of 50 Hz and the 10 Hz a log runs at its own rate from: time stamps in ms read as seconds? --time-unit ms",
        ),
        ("rate3_gap.csv", "rate3_gap.csv:103: gap of 7.000 s"),
    ] {
        assert!(
            outcome(name).contains(expected),
            "{name}: {}",
            quality(outcome(name))
        );
    }
    let warts = outcome("warts.csv");
    for field in [
        "gaps: 2",
        "same_time_rows: 1",
        "backward_steps: 1",
        "missing_rate_rows: 9",
    ] {
        assert!(warts.contains(field), "{field}: {}", quality(warts));
    }
}

/// The real logs (shared/data/real beside the workspace), when present.
#[test]
fn streaming_equals_materialising_on_real_logs() {
    let real = gyro_log::real_data::dir();
    let logs: Vec<PathBuf> = ["x", "y", "z"]
        .iter()
        .map(|axis| real.join(format!("ssong_{axis}_slow.csv")))
        .filter(|p| p.exists())
        .collect();
    if logs.is_empty() {
        gyro_log::real_data::skipped(&format!("ssong_*_slow.csv in {}", real.display()));
        return;
    }
    for path in &logs {
        let outcome = assert_same(path, false);
        assert!(
            outcome.contains("sample_rate_source"),
            "{}",
            quality(&outcome)
        );
    }
}

/// `gyro-cli run` (streaming) prints what the materialising path reports, byte for byte,
/// with the series of `--out`.
#[test]
fn cli_output_equals_the_materialising_report() {
    let scratch = temp_dir("streaming-cli");
    let dir = scratch.path();
    let path = PathBuf::from(write(dir, "warts.csv", &wart_log(false)));
    let series = dir.join("series.csv");
    let file = path.to_str().unwrap();
    let out = gyro(&[
        "run",
        file,
        "--format",
        "json",
        "--out",
        series.to_str().unwrap(),
    ]);
    let report = materialised(
        &path,
        &GridOptions::default(),
        &Config::default(),
        &ReplayOptions::default(),
    )
    .unwrap();
    // The log reader's notices, as `run` hears them, make the head of its findings.
    let mut notices = Vec::new();
    replay::replay_file(
        &path,
        &LogOptions::default(),
        &GridOptions::default(),
        &Config::default(),
        &ReplayOptions::default(),
        &mut |n| notices.push(n.to_string()),
    )
    .unwrap();
    let findings = gyro_analysis::findings::of_run(&report, &notices);
    assert_eq!(
        ok(&out),
        format!("{}\n", report::json(file, &report, &findings).unwrap())
    );
    let mut expected = Vec::new();
    report::series_csv(&mut expected, &report, &findings).unwrap();
    assert_eq!(std::fs::read(&series).unwrap(), expected);

    let out = gyro(&["run", file]);
    assert_eq!(ok(&out), report::table(file, &report, &findings));
}
