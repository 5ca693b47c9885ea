//! No command writes over one of its inputs, however the path is spelled: the input is
//! left as it was and the command fails naming both.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, temp_dir};

#[test]
fn outputs_never_overwrite_inputs() {
    let scratch = temp_dir("overwrite");
    let dir = scratch.path();
    let log = dir.join("in.csv");
    std::fs::copy(bench_log(), &log).unwrap();
    let original = std::fs::read(&log).unwrap();
    let linked = dir.join("hard-link.csv");
    std::fs::hard_link(&log, &linked).unwrap();
    let relative = format!("{}/./in.csv", dir.display());
    let through = format!("{}/sub/../in.csv", dir.display());
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let l = log.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["run", l, "--out", &relative],
        vec!["run", l, "--out", linked.to_str().unwrap()],
        vec!["calibrate", l, "-o", &through],
        vec!["diagnose", "--train", l, "--holdout", l, "-o", &relative],
        vec!["noise", l, "--psd-out", &relative],
        vec!["noise", l, "--model-out", linked.to_str().unwrap()],
        vec!["simulate", "--motion-from", l, "-o", &relative],
        vec!["convert", l, &through],
    ];
    for args in cases {
        let out = gyro(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("refusing to overwrite"),
            "{args:?}: {stderr}"
        );
        assert_eq!(
            std::fs::read(&log).unwrap(),
            original,
            "{args:?} changed the input"
        );
    }
    // A new output is written as before.
    let series = dir.join("series.csv");
    let out = gyro(&["run", l, "--out", series.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(series.exists());
}

/// `record` keeps an earlier recording unless told `--force`; a failed `convert --force`
/// leaves the file that was there and no partial one; `simulate -o x.mcap` writes MCAP.
#[test]
fn recordings_and_outputs_are_kept_or_written_whole() {
    let scratch = temp_dir("kept");
    let dir = scratch.path();
    let earlier = dir.join("earlier.mcap");
    std::fs::write(&earlier, b"an earlier recording").unwrap();
    let out = gyro(&[
        "record",
        "--port",
        "/nonexistent/port",
        "-o",
        earlier.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(&earlier).unwrap(), b"an earlier recording");

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "time_s,rate_dps\n0.0,x\n").unwrap();
    let out = gyro(&[
        "convert",
        bad.to_str().unwrap(),
        earlier.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read(&earlier).unwrap(), b"an earlier recording");
    let mut left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["bad.csv", "earlier.mcap"], "no partial file is left");

    let simulated = dir.join("sim.mcap");
    let out = gyro(&[
        "simulate",
        "-o",
        simulated.to_str().unwrap(),
        "--duration-s",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::read(&simulated)
        .unwrap()
        .starts_with(b"\x89MCAP0\r\n"));
}
