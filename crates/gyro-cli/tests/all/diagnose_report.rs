//! `diagnose --report DIR`: a self-contained `index.html` (inline SVG figures, no
//! external reference) with the ranked table, and `diagnosis.json` beside it.
//!
//! Set `GYRO_REPORT_DIR` to keep the report for a look.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;
use crate::common::{gyro, json_of, temp_dir};

use std::path::PathBuf;

#[test]
fn report_is_self_contained_with_every_figure_and_the_ranked_table() {
    let scratch = temp_dir("diagnose-report");
    let dir = scratch.path();
    let runs: Vec<String> = (1..=6)
        .map(|seed| {
            let path = dir.join(format!("run{seed}.csv"));
            let path = path.to_string_lossy().into_owned();
            let seed = seed.to_string();
            common::ok(&gyro(&[
                "simulate",
                "--sample-rate-hz",
                "200",
                "--duration-s",
                "30",
                "--effect",
                "scale_factor:k=0.02",
                "--seed",
                &seed,
                "-o",
                &path,
            ]));
            path
        })
        .collect();
    let report = match std::env::var_os("GYRO_REPORT_DIR") {
        Some(d) => PathBuf::from(d),
        None => dir.join("report"),
    };
    let report_arg = report.to_string_lossy().into_owned();
    let mut args = vec!["diagnose", "--train"];
    args.extend(runs[..4].iter().map(String::as_str));
    args.push("--holdout");
    args.extend(runs[4..].iter().map(String::as_str));
    args.extend([
        "--members",
        "8",
        "--candidate-members",
        "4",
        "--format",
        "json",
        "--report",
        &report_arg,
    ]);
    let stdout = json_of(&gyro(&args));

    // diagnosis.json is the result printed on stdout.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("diagnosis.json")).unwrap())
            .unwrap();
    assert_eq!(json, stdout);
    assert_eq!(json["verdict"]["unmodelled"][0], "scale_factor");

    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    // Self-contained: nothing fetched.
    for external in [
        "http://", "https://", "<script", "<link", "<img", "@import", "url(",
    ] {
        assert!(!html.contains(external), "the page holds {external}");
    }
    // Every figure, inline.
    for title in [
        "Allan deviation of the static residual",
        "Power spectral density of the residual",
        "Residual (gyro − reference rate) against rate, temperature and acceleration",
        "Cross-correlation of gyro rate and reference rate",
        "Gap map: z of each run",
    ] {
        assert!(html.contains(title), "no figure {title}");
    }
    let figures = if json["compensation"].is_null() {
        assert!(html.contains("No angle-error figure: "));
        5
    } else {
        6
    };
    assert_eq!(html.matches("<svg").count(), figures);
    assert_eq!(html.matches("</svg>").count(), figures);
    // One "how to read this" per folded figure (the angle error's says what it shows in
    // its title, beside the verdict).
    assert_eq!(html.matches("How to read this.").count(), 5);
    // The answer before every table and every folded section.
    let verdict = html.find("<div class=\"verdict\">").unwrap();
    assert!(verdict < html.find("<table").unwrap() && verdict < html.find("<details").unwrap());
    // The ranked table: scale_factor first, significant, with its interval.
    let row = html
        .split("<tr")
        .find(|r| r.contains("<code>scale_factor</code></td>"))
        .unwrap();
    assert!(row.starts_with(" class=\"sig\""), "{row}");
    assert!(row.contains("<td>yes</td>") && row.contains("k&nbsp;=&nbsp;0.0"));
    let first_effect = html.find("<code>scale_factor</code></td>").unwrap();
    for e in json["effects"].as_array().unwrap().iter().skip(1) {
        let id = e["id"].as_str().unwrap();
        let at = html.find(&format!("<tr><td><code>{id}</code></td>"));
        assert!(at.is_some_and(|at| at > first_effect), "{id} ranked");
    }
    // Gap figures and the nominal model's provenance.
    assert!(html.contains("floor") && html.contains("regression intercept"));
    assert!(html.contains("<b>In the statistics' terms:</b> unmodelled: <code>scale_factor</code>"));

    if std::env::var_os("GYRO_REPORT_DIR").is_none() {
        std::fs::remove_dir_all(dir).unwrap();
    }
}
