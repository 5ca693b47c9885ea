//! Bad input, class by class (crash, hang, wrong output, silent accept): every command
//! refuses it with one line naming the file or the option and the right exit code, never
//! a panic, never a hang, never a silent wrong answer. Every file is made here.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;

use crate::common::{bench_log, gyro, ok, temp_dir, write};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A CSV log: `rows` rows `step_s` apart (a slow sine rate, reference 0), after `metadata`.
fn log_text(metadata: &str, rows: usize, step_s: f64) -> String {
    let mut text = String::from(metadata);
    text.push_str("time_s,rate_dps,reference_deg\n");
    for i in 0..rows {
        let rate = 0.01 * (i as f64 * 0.1).sin();
        text.push_str(&format!("{:.6},{rate:.5},0.0\n", i as f64 * step_s));
    }
    text
}

/// Assert a clean refusal: exit `code` (1: the input; 2: the command line), no panic, the
/// first stderr line an `error:` containing `needle`; for code 1, nothing but that line.
fn refused(out: &Output, code: i32, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(101), "panicked: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(code), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(
        errors[0].contains(needle),
        "expected `{needle}` in: {stderr}"
    );
    if code == 1 {
        let last = stderr.lines().last().unwrap_or_default();
        assert!(
            last.starts_with("error: "),
            "the error is the last line: {stderr}"
        );
    }
}

/// Run `gyro-cli args` in a child process, killed after `limit`: `None` if it had to be.
fn within(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while start.elapsed() < limit {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    None
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Crashes: an absurd declared rate, a run too long to simulate, a full stdout.
#[test]
fn absurd_sizes_and_a_full_stdout_are_one_line_errors() {
    let scratch = temp_dir("crash");
    let dir = scratch.path();
    // 1e9 Hz declared on rows 1 ms apart: many rows (the median says 1000 Hz) and a few.
    let many = write(
        dir,
        "many.csv",
        &log_text("# sample_rate_hz: 1e9\n", 3000, 0.001),
    );
    let few = write(
        dir,
        "few.csv",
        &log_text("# sample_rate_hz: 1e9\n", 10, 0.001),
    );
    let good = write(dir, "good.csv", &log_text("", 3000, 0.001));
    let model = dir.join("m.json");
    let sim = dir.join("sim.csv");
    for log in [&many, &few] {
        let name = Path::new(log).file_name().unwrap().to_str().unwrap();
        let needle = format!("{name}: the sample_rate_hz metadata gives 1000000000 Hz");
        refused(&gyro(&["noise", log]), 1, &needle);
        refused(&gyro(&["calibrate", log, "-o", s(&model)]), 1, &needle);
        refused(
            &gyro(&["diagnose", "--train", log, "--holdout", &good]),
            1,
            &needle,
        );
        refused(
            &gyro(&["simulate", "--motion-from", log, "-o", s(&sim)]),
            1,
            &needle,
        );
    }
    refused(
        &gyro(&["noise", &good, "--sample-rate-hz", "1e9"]),
        1,
        "the --sample-rate-hz option gives 1000000000 Hz but the time stamps say 1000",
    );
    // Bridging gaps of 1e7 s at 1 kHz: refused before a slot is made.
    refused(
        &gyro(&["noise", &good, "--max-gap-s", "1e7"]),
        1,
        "good.csv: bridging gaps of up to 10000000 s at 1000 Hz would hold 1000000000",
    );
    // Epoch-microsecond stamps read as seconds: 2 000 000 s of motion at 1 kHz.
    let mut epoch = String::from("time_s,rate_dps,reference_deg\n");
    for i in 0..2000_u64 {
        epoch.push_str(&format!("{},0.0,0.0\n", 1_700_000_000_000_000 + i * 1000));
    }
    let epoch = write(dir, "epoch_us.csv", &epoch);
    let out = gyro(&["simulate", "--motion-from", &epoch, "-o", s(&sim)]);
    refused(&out, 1, "epoch_us.csv: cannot simulate its motion");
    refused(
        &out,
        1,
        "1999000 s at 1000 Hz would be 1999000001 samples (163.8 GiB)",
    );
    let out = gyro(&[
        "simulate",
        "--sample-rate-hz",
        "1e6",
        "--duration-s",
        "86400",
        "-o",
        s(&sim),
    ]);
    refused(
        &out,
        1,
        "86400 s at 1000000 Hz would be 86400000001 samples",
    );
    assert!(!sim.exists());
    // A full disk on stdout: one line, status 1.
    #[cfg(unix)]
    if Path::new("/dev/full").exists() {
        let full = || {
            std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap()
        };
        for args in [
            vec![
                "calibrate",
                s(&bench_log()),
                "-o",
                s(&model),
                "--no-leave-one-out",
            ],
            vec!["simulate", "--list-effects"],
            vec!["run", s(&bench_log()), "--format", "csv"],
        ] {
            let out = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
                .args(&args)
                .stdout(full())
                .output()
                .unwrap();
            refused(&out, 1, "cannot write to stdout: No space left on device");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Hangs: a 1e9 Hz grid under `run`, an emulator whose port nobody reads; each must end
/// on its own well within the limit.
#[test]
fn nothing_waits_forever() {
    let scratch = temp_dir("hang");
    let dir = scratch.path();
    let limit = Duration::from_secs(60);
    for (name, rows) in [("few.csv", 10), ("many.csv", 3000)] {
        let log = write(dir, name, &log_text("", rows, 0.001));
        let out = within(&["run", &log, "--sample-rate-hz", "1e9"], limit)
            .unwrap_or_else(|| panic!("run on a 1e9 Hz grid ({name}) did not end"));
        refused(&out, 1, "--sample-rate-hz option gives 1000000000 Hz");
    }
    #[cfg(unix)]
    {
        let started = Instant::now();
        let out = within(
            &[
                "emulate",
                "--create-pty",
                "--duration-s",
                "30",
                "--write-timeout-s",
                "1",
            ],
            limit,
        )
        .expect("emulate to a port nobody reads did not end");
        refused(
            &out,
            1,
            "the port took no byte for 1 s: is anything reading it?",
        );
        assert!(started.elapsed() < Duration::from_secs(20));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Wrong output: fits that cannot be made are untestable (not NaN), rates that overflow
/// are refused, and numbers that make no sense are refused at parse time.
#[test]
fn no_nan_fits_no_inf_tables_no_empty_simulations() {
    let scratch = temp_dir("wrong");
    let dir = scratch.path();
    let runs: Vec<String> = (1..=4)
        .map(|seed| {
            let path = dir.join(format!("short{seed}.csv"));
            let seed = seed.to_string();
            ok(&gyro(&[
                "simulate",
                "-o",
                s(&path),
                "--seed",
                &seed,
                "--duration-s",
                "15",
            ]));
            s(&path).to_string()
        })
        .collect();
    let diagnose = |format: &str| {
        gyro(&[
            "diagnose",
            "--train",
            &runs[0],
            &runs[1],
            "--holdout",
            &runs[2],
            &runs[3],
            "--members",
            "6",
            "--candidate-members",
            "3",
            "--format",
            format,
        ])
    };
    let table = ok(&diagnose("table"));
    assert!(!table.contains("NaN"), "{table}");
    assert!(
        table.contains(
            "scale_factor       untestable: needs training runs whose motion determines it"
        ),
        "{table}"
    );
    let json: serde_json::Value = serde_json::from_str(&ok(&diagnose("json"))).unwrap();
    for effect in json["effects"].as_array().unwrap() {
        for (name, value) in effect["params"].as_object().unwrap() {
            assert!(value.is_number(), "{}: {name} = {value}", effect["id"]);
        }
        for (name, bounds) in effect["ci95"].as_object().unwrap() {
            let finite = bounds.as_array().unwrap().iter().all(|b| !b.is_null());
            assert!(
                finite || effect["id"] == "bandwidth",
                "{}: {name}",
                effect["id"]
            );
        }
    }
    let untestable: Vec<&str> = json["untestable"]
        .as_array()
        .unwrap()
        .iter()
        .map(|u| u["id"].as_str().unwrap())
        .collect();
    assert!(untestable.contains(&"scale_factor"), "{untestable:?}");

    let mut huge = String::from("# sample_rate_hz: 1000\ntime_s,rate_dps\n");
    for i in 0..3000 {
        let sign = if i % 2 == 0 { "-" } else { "" };
        huge.push_str(&format!("{:.3},{sign}1e300\n", i as f64 * 0.001));
    }
    let huge = write(dir, "huge.csv", &huge);
    refused(
        &gyro(&["noise", &huge]),
        1,
        "huge.csv: rates up to 1e300 deg/s: too large",
    );

    let out_csv = dir.join("out.csv");
    for (option, value) in [
        ("--temperature-rise-c", "nan"),
        ("--temperature-rise-c", "inf"),
        ("--encoder-counts", "0"),
        ("--duration-s", "-5"),
        ("--sample-rate-hz", "0"),
    ] {
        let arg = format!("{option}={value}");
        let out = gyro(&["simulate", "-o", s(&out_csv), &arg]);
        refused(&out, 2, &format!("invalid value '{value}' for '{option}"));
        assert!(!out_csv.exists(), "{arg}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Silent accepts: bad metadata, duplicate or missing named columns, a run given twice,
/// numeric options out of range are errors; calibrate, diagnose and simulate --motion-from
/// show the input report.
#[test]
fn nothing_bad_is_accepted_silently() {
    let scratch = temp_dir("silent");
    let dir = scratch.path();
    for (name, metadata, line) in [
        ("negative.csv", "# sample_rate_hz: -1000\n", 1),
        ("zero.csv", "# sample_rate_hz: 0\n", 1),
        ("nan.csv", "# sample_rate_hz: NaN\n", 1),
        ("word.csv", "# sample_rate_hz: fast\n", 1),
        ("unit.csv", "# sample_rate_hz: 1000 Hz\n", 1),
        (
            "twice.csv",
            "# sample_rate_hz: 1000\n# sample_rate_hz: 500\n",
            2,
        ),
    ] {
        let log = write(dir, name, &log_text(metadata, 100, 0.001));
        for command in ["run", "noise"] {
            refused(
                &gyro(&[command, &log]),
                1,
                &format!("{name}:{line}: `sample_rate_hz"),
            );
        }
    }
    let dup = write(
        dir,
        "dup.csv",
        "time_s,rate_dps,rate_dps\n0.000,1,2\n0.001,1,2\n0.002,1,2\n",
    );
    refused(
        &gyro(&["run", &dup]),
        1,
        "dup.csv:1: column `rate_dps` appears twice",
    );
    let good = write(dir, "good.csv", &log_text("", 3000, 0.001));
    refused(
        &gyro(&["run", &good, "--reference-column", "ref_deg"]),
        1,
        "good.csv:1: no column `ref_deg` in the header",
    );

    // The same run twice, or in training and hold-out (also through a hard link).
    let model = dir.join("m.json");
    let bench = bench_log();
    let bench = s(&bench);
    let link = dir.join("link.csv");
    std::fs::hard_link(bench, &link).unwrap();
    refused(
        &gyro(&["calibrate", bench, bench, "-o", s(&model)]),
        1,
        "is given twice among the training runs",
    );
    refused(
        &gyro(&["calibrate", bench, "--holdout", s(&link), "-o", s(&model)]),
        1,
        "is given among the training runs and again among the hold-out runs",
    );
    refused(
        &gyro(&["diagnose", "--train", bench, &good, "--holdout", s(&link)]),
        1,
        "is given among the training runs and again among the hold-out runs",
    );
    refused(&gyro(&["noise", &good, &good]), 1, "given twice");
    assert!(!model.exists());

    // Numbers out of range, refused at parse time with the option named.
    for args in [
        vec!["run", bench, "--max-gap-s=nan"],
        vec!["run", bench, "--sample-rate-hz=-1000"],
        vec!["run", bench, "--range-dps=inf"],
        vec!["run", bench, "--target-deg=90", "--tolerance-deg=-1"],
        vec!["run", bench, "--k-sigma=nan"],
        vec!["noise", bench, "--margin-s=-1"],
        vec!["noise", bench, "--per-decade=0"],
        vec!["calibrate", bench, "-o", s(&model), "--tau-s=0"],
        vec![
            "diagnose",
            "--train",
            bench,
            "--holdout",
            bench,
            "--split-s=inf",
        ],
        vec![
            "diagnose",
            "--train",
            bench,
            "--holdout",
            bench,
            "--members=1",
        ],
        vec!["record", "--port", "x", "-o", s(&model), "--duration=-1"],
        vec!["emulate", "--create-pty", "--rate-hz=nan"],
    ] {
        let option = args.last().unwrap().split('=').next().unwrap();
        refused(&gyro(&args), 2, &format!("for '{option}"));
    }

    // The input report of run, in calibrate (table and JSON), diagnose and simulate.
    let table = ok(&gyro(&[
        "calibrate",
        bench,
        "-o",
        s(&model),
        "--no-leave-one-out",
    ]));
    assert!(
        table.contains(&format!(
            "file: {bench}\ninput: 40000 rows -> 40000 samples at 1000 Hz (metadata)"
        )),
        "{table}"
    );
    let json: serde_json::Value = serde_json::from_str(&ok(&gyro(&[
        "calibrate",
        bench,
        "-o",
        s(&model),
        "--no-leave-one-out",
        "--format",
        "json",
        "--force",
    ])))
    .unwrap();
    assert_eq!(json["inputs"][0]["file"], bench);
    assert_eq!(json["inputs"][0]["input"]["slots"], 40000);
    let out = gyro(&[
        "simulate",
        "--motion-from",
        bench,
        "-o",
        s(&dir.join("again.csv")),
    ]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("input: 40000 rows -> 40000 samples"),
        "{stderr}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A setting of the other format (CSV columns on an MCAP log, MCAP channels on a CSV log)
/// would be ignored: it is refused, naming the file and the flag.
#[test]
fn options_of_the_other_format_are_refused() {
    let scratch = temp_dir("not-applicable");
    let dir = scratch.path();
    let csv = write(dir, "log.csv", &log_text("", 3000, 0.001));
    let mcap = dir.join("log.mcap");
    ok(&gyro(&["convert", &csv, mcap.to_str().unwrap()]));
    let mcap = mcap.to_str().unwrap();
    for (log, flag, value) in [
        (mcap, "--reference-column", "ref_deg"),
        (mcap, "--temperature-column", "temp"),
        (mcap, "--time-unit", "ms"),
        (csv.as_str(), "--topic", "/gyro"),
        (csv.as_str(), "--time-source", "log-time"),
    ] {
        let out = gyro(&["run", log, flag, value]);
        refused(&out, 1, flag);
        refused(&out, 1, log);
    }
    ok(&gyro(&["run", mcap]));
}

/// A stderr that cannot be written (`2>/dev/full`) ends the command with its exit code,
/// never a panic through `eprintln!`.
#[test]
fn a_full_stderr_does_not_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    let scratch = temp_dir("full-stderr");
    let dir = scratch.path();
    let empty = write(dir, "empty.csv", "");
    let out = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
        .args(["run", &empty])
        .stderr(full)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}

/// The files in `dir`, with their bytes, sorted by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|entry| {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = std::fs::read(&path).unwrap_or_default(); // a folder: no bytes
            (name, bytes)
        })
        .collect();
    files.sort();
    files
}

/// Clobber: every option that writes a file refuses one that exists, unless --force; the
/// file keeps its bytes and nothing else is written.
#[test]
fn existing_outputs_are_refused_without_force() {
    let scratch = temp_dir("existing");
    let dir = scratch.path();
    let good = write(dir, "good.csv", &log_text("", 3000, 0.001));
    let other = write(dir, "other.csv", &log_text("", 3000, 0.001));
    let bench = bench_log();
    let bench = s(&bench);
    let out = dir.join("out");
    let report = dir.join("report");
    let cases: Vec<(&str, Vec<&str>)> = vec![
        ("series.csv", vec!["run", &good, "--out"]),
        ("run.svg", vec!["run", &good, "--plot"]),
        ("model.json", vec!["calibrate", bench, "-o"]),
        (
            "calibration.png",
            vec!["calibrate", bench, "-o", "new-model.json", "--plot"],
        ),
        ("psd.csv", vec!["noise", &good, "--psd-out"]),
        ("model.json", vec!["noise", &good, "--model-out"]),
        ("imu.yaml", vec!["noise", &good, "--noise-yaml"]),
        ("allan.svg", vec!["noise", &good, "--plot"]),
        (
            "corrected.json",
            vec!["diagnose", "--train", &good, "--holdout", &other, "-o"],
        ),
        (
            "imu.yaml",
            vec![
                "diagnose",
                "--train",
                &good,
                "--holdout",
                &other,
                "--noise-yaml",
            ],
        ),
        ("sim.csv", vec!["simulate", "--duration-s", "2", "-o"]),
        ("copy.mcap", vec!["convert", &good]),
        (
            "faults.json",
            vec!["emulate", "--port", "/nonexistent/port", "--fault-log"],
        ),
        (
            "run.mcap",
            vec!["record", "--port", "/nonexistent/port", "-o"],
        ),
    ];
    for (name, args) in cases {
        std::fs::create_dir_all(&out).unwrap();
        let existing = out.join(name);
        std::fs::write(&existing, b"an earlier output\n").unwrap();
        let before = contents(&out);
        let mut args = args.clone();
        args.push(s(&existing));
        let output = Command::new(env!("CARGO_BIN_EXE_gyro-cli"))
            .args(&args)
            .current_dir(&out)
            .output()
            .unwrap();
        refused(
            &output,
            1,
            &format!(
                "{}: exists; choose another name, or --force to replace it",
                s(&existing)
            ),
        );
        assert_eq!(contents(&out), before, "{args:?}");
        std::fs::remove_dir_all(&out).unwrap();
    }
    // The report's two files: either one there refuses the report.
    for name in ["index.html", "diagnosis.json"] {
        std::fs::create_dir_all(&report).unwrap();
        std::fs::write(report.join(name), b"an earlier report\n").unwrap();
        let before = contents(&report);
        let output = gyro(&[
            "diagnose",
            "--train",
            &good,
            "--holdout",
            &other,
            "--report",
            s(&report),
        ]);
        refused(&output, 1, &format!("{name}: exists"));
        assert_eq!(contents(&report), before);
        std::fs::remove_dir_all(&report).unwrap();
    }
    // One file named for two outputs: refused before either is written.
    let twice = dir.join("twice.csv");
    let twice_too = format!("{}/./twice.csv", dir.display());
    refused(
        &gyro(&[
            "noise",
            &good,
            "--psd-out",
            s(&twice),
            "--model-out",
            &twice_too,
        ]),
        1,
        "named for two outputs",
    );
    assert!(!twice.exists());
    // An output that is an input is refused even with --force.
    let before = std::fs::read(&good).unwrap();
    refused(
        &gyro(&["run", &good, "--out", &good, "--force"]),
        1,
        "refusing to overwrite it",
    );
    assert_eq!(std::fs::read(&good).unwrap(), before);
    std::fs::remove_dir_all(dir).unwrap();
}

/// With --force, every output that exists is replaced, whole (no partial file is left).
#[test]
fn force_replaces_existing_outputs() {
    let scratch = temp_dir("force");
    let dir = scratch.path();
    let earlier = b"an earlier output\n";
    let existing = |name: &str| {
        let path = dir.join(name);
        std::fs::write(&path, earlier).unwrap();
        s(&path).to_string()
    };
    let replaced = |path: &str| {
        let bytes = std::fs::read(path).unwrap();
        assert!(
            !bytes.is_empty() && bytes != earlier,
            "{path} was not replaced"
        );
    };
    let good = write(dir, "good.csv", &log_text("", 3000, 0.001));
    let bench = bench_log();
    let bench = s(&bench);

    let (series, plot) = (existing("series.csv"), existing("run.svg"));
    ok(&gyro(&[
        "run", bench, "--out", &series, "--plot", &plot, "--force",
    ]));
    let (model, calibration) = (existing("model.json"), existing("calibration.png"));
    ok(&gyro(&[
        "calibrate",
        bench,
        "-o",
        &model,
        "--plot",
        &calibration,
        "--no-leave-one-out",
        "--force",
    ]));
    let noise_outputs = [
        existing("psd.csv"),
        existing("noise-model.json"),
        existing("imu.yaml"),
        existing("allan.svg"),
    ];
    let [psd, noise_model, yaml, allan] = &noise_outputs;
    ok(&gyro(&[
        "noise",
        &good,
        "--psd-out",
        psd,
        "--model-out",
        noise_model,
        "--noise-yaml",
        yaml,
        "--plot",
        allan,
        "--force",
    ]));
    let runs: Vec<String> = (1..=4)
        .map(|seed| {
            let run = existing(&format!("run{seed}.csv"));
            let seed = seed.to_string();
            ok(&gyro(&[
                "simulate",
                "-o",
                &run,
                "--seed",
                &seed,
                "--duration-s",
                "15",
                "--force",
            ]));
            run
        })
        .collect();
    let mcap = existing("copy.mcap");
    ok(&gyro(&["convert", &runs[0], &mcap, "--force"]));
    let (corrected, diagnosed_yaml) = (existing("corrected.json"), existing("diagnosed.yaml"));
    let report = dir.join("report");
    std::fs::create_dir_all(&report).unwrap();
    std::fs::write(report.join("index.html"), earlier).unwrap();
    ok(&gyro(&[
        "diagnose",
        "--train",
        &runs[0],
        &runs[1],
        "--holdout",
        &runs[2],
        &runs[3],
        "--members",
        "6",
        "--candidate-members",
        "3",
        "-o",
        &corrected,
        "--noise-yaml",
        &diagnosed_yaml,
        "--report",
        s(&report),
        "--force",
    ]));
    let html = s(&report.join("index.html")).to_string();
    for path in [&series, &plot, &model, &calibration, &mcap, &corrected]
        .into_iter()
        .chain(&noise_outputs)
        .chain(&runs)
        .chain([&diagnosed_yaml, &html])
    {
        replaced(path);
    }
    assert!(std::fs::read(&mcap).unwrap().starts_with(b"\x89MCAP0\r\n"));
    #[cfg(unix)]
    {
        let faults = existing("faults.json");
        let recording = existing("recording.mcap");
        let emulate_args = [
            "--seed",
            "3",
            "--duration-s",
            "2",
            "--as-fast-as-possible",
            "--fault-log",
            &faults,
            "--force",
        ];
        let emulate_args: Vec<&std::ffi::OsStr> =
            emulate_args.iter().map(std::ffi::OsStr::new).collect();
        let (emulated, recorded) =
            common::emulate_into_record_with(&emulate_args, &["--force"], Path::new(&recording));
        ok(&emulated);
        ok(&recorded);
        replaced(&faults);
        replaced(&recording);
        assert!(std::fs::read(&recording)
            .unwrap()
            .starts_with(b"\x89MCAP0\r\n"));
    }
    let left: Vec<String> = contents(dir)
        .into_iter()
        .map(|(name, _)| name)
        .filter(|name| name.contains(".partial"))
        .collect();
    assert!(left.is_empty(), "partial files left: {left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Silent accept: a column option of a column the command does not read (noise reads the
/// rate alone) or that the log lacks is refused, naming the option or the column.
#[test]
fn temperature_and_reference_columns_that_are_not_used_are_refused() {
    let scratch = temp_dir("unused-columns");
    let dir = scratch.path();
    let bench = bench_log();
    let bench = s(&bench);
    for (flag, value) in [
        ("--temperature-column", "temperature_c"),
        ("--reference-column", "reference_deg"),
        ("--reference-topic", "/encoder"),
    ] {
        refused(
            &gyro(&["noise", bench, flag, value]),
            1,
            &format!("{flag} {value}: noise reads only the time and the rate"),
        );
    }
    // A log without a temperature column: the column named is not there.
    let plain = write(dir, "plain.csv", &log_text("", 3000, 0.001));
    for command in ["run", "convert"] {
        let mut args = vec![command, &plain, "--temperature-column", "temperature_c"];
        let copy = dir.join("copy.csv");
        if command == "convert" {
            args.push(s(&copy));
        }
        refused(
            &gyro(&args),
            1,
            "plain.csv:1: no column `temperature_c` in the header",
        );
        assert!(!copy.exists());
    }
    // Where it is read, it is taken.
    ok(&gyro(&[
        "run",
        bench,
        "--temperature-column",
        "temperature_c",
    ]));
    std::fs::remove_dir_all(dir).unwrap();
}

/// Absurd stamps and fields (issue 46): refused where they enter, one line naming the file
/// (and the line) and what to do, by every command that reads the log.
#[test]
fn absurd_stamps_and_fields_are_refused_where_they_enter() {
    let scratch = temp_dir("absurd");
    let dir = scratch.path();
    let good = log_text("# sample_rate_hz: 1000\n", 3000, 0.001);
    let lines: Vec<&str> = good.lines().collect();
    // lines[0] metadata, lines[1] header, data from lines[2] (file line 3).
    let mut huge = lines[..1502].join("\n");
    huge.push_str("\n1e300,0.1,0.0\n");
    huge.push_str(&lines[1502..].join("\n"));
    let huge = write(dir, "huge.csv", &(huge + "\n"));
    let zero: String = log_text("# sample_rate_hz: 1000\n", 3000, 0.0);
    let zero = write(dir, "zero.csv", &zero);
    let mut reversed: Vec<&str> = lines[2..].to_vec();
    reversed.reverse();
    let reversed = write(
        dir,
        "reversed.csv",
        &format!("{}\n{}\n{}\n", lines[0], lines[1], reversed.join("\n")),
    );
    // Row 1000 (file line 1003) with its rate replaced.
    let with_rate = |rate: &str| {
        let mut rows: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        rows[1002] = format!("1.000000,{rate},0.0");
        rows.join("\n") + "\n"
    };
    let long = write(
        dir,
        "long.csv",
        &with_rate(&format!("1{}", "0".repeat(1_000_000))),
    );
    let overflow = write(dir, "overflow.csv", &with_rate("1e400"));
    let out = dir.join("o.mcap");
    let cases: [(&str, &str); 5] = [
        (&huge, "huge.csv:150"),
        (&zero, "zero.csv: all 3000 rows (3 to 3002, by CSV line or MCAP message) are stamped 0.000000 s"),
        (&reversed, "reversed.csv:4: time runs backwards: 2999 of 2999 steps"),
        (&long, "long.csv:1003: column `rate_dps`: `1000"),
        (&overflow, "overflow.csv:1003: column `rate_dps`: `1e400` is too large for any number"),
    ];
    for (log, needle) in cases {
        refused(&gyro(&["run", log]), 1, needle);
        refused(&gyro(&["noise", log]), 1, needle);
        refused(&gyro(&["convert", log, s(&out)]), 1, needle);
        assert!(!out.exists(), "{log}: nothing written");
    }
    // MCAP messages backwards in time, or all at one log time.
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/mcap");
    let reverse = fixtures.join("reverse_time.mcap");
    let one_time = fixtures.join("one_log_time.mcap");
    refused(
        &gyro(&["run", s(&reverse)]),
        1,
        "reverse_time.mcap:2: time runs backwards",
    );
    refused(&gyro(&["run", s(&one_time)]), 1, "are stamped 5.000000 s");
}

/// An output path that is a directory: one line naming it, for every command that writes.
#[test]
fn an_output_that_is_a_directory_is_named() {
    let scratch = temp_dir("outdir");
    let dir = scratch.path();
    let log = bench_log();
    let log: &str = s(&log);
    let folder = dir.join("folder");
    std::fs::create_dir(&folder).unwrap();
    let d = s(&folder);
    let needle = format!("{d}: is a directory; give a file name");
    for args in [
        vec!["run", log, "--out", d],
        vec!["run", log, "--out", d, "--force"],
        vec!["calibrate", log, "-o", d],
        vec!["noise", log, "--psd-out", d],
        vec!["simulate", "--duration-s", "2", "-o", d],
        vec!["convert", log, d],
        vec!["record", "--port", "/dev/null", "-o", d],
    ] {
        refused(&gyro(&args), 1, &needle);
    }
}

/// A negative number after a flag is the flag's value, judged by its parser; a
/// temperature rise out of any gyro's range is refused.
#[test]
fn negative_numbers_after_a_flag_are_values() {
    let log = bench_log();
    refused(
        &gyro(&["run", s(&log), "--sample-rate-hz", "-1000"]),
        2,
        "expected a positive finite number, got `-1000`",
    );
    refused(
        &gyro(&["simulate", "--duration-s", "-5", "-o", "x.csv"]),
        2,
        "--duration-s",
    );
    refused(
        &gyro(&["simulate", "--temperature-rise-c", "-1e308", "-o", "x.csv"]),
        2,
        "expected a number from -125 to 125",
    );
    let scratch = temp_dir("cooling");
    let out = scratch.path().join("s.csv");
    ok(&gyro(&[
        "simulate",
        "--temperature-rise-c",
        "-5",
        "--duration-s",
        "2",
        "-o",
        s(&out),
    ]));
}
