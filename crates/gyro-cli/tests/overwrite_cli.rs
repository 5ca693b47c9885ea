//! No command writes over one of its inputs, however the path is spelled: the input is
//! left as it was and the command fails naming both.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

mod common;
use common::{bench_log, gyro, temp_dir};

#[test]
fn outputs_never_overwrite_inputs() {
    let dir = temp_dir("overwrite");
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
