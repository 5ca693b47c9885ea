//! Plots: each figure renders as a well-formed SVG (titles, axis labels, one line per
//! series) and as a PNG of the stated size; `gyro-cli run --plot` writes one; bad paths
//! and extensions fail with a message naming the file.
//!
//! Set `GYRO_PLOT_DIR` to keep the files for a look.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro};

use gyro_analysis::calibrate::{calibrate, BenchRun, CalibrateOptions, Calibration};
use gyro_analysis::noise::{self, Characterization, NoiseOptions};
use gyro_analysis::replay::{replay, RunReport};
use gyro_core::{Compensation, Config};
use gyro_log::{self as log, GridOptions};
use gyro_report::plot::{self, CalibrationPlot, Figure, ImageFormat, NoisePlot, RunPlot};
use gyro_sim::{simulate, BenchProfile, Effect, Motion, SensorModel, SimOptions};
use std::path::{Path, PathBuf};

/// Where plots go: `GYRO_PLOT_DIR` if set (kept, to look at), else a fresh temporary
/// directory, removed when the guard returned beside it is dropped.
fn out_dir(name: &str) -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("GYRO_PLOT_DIR") {
        Some(d) => {
            let dir = PathBuf::from(d);
            std::fs::create_dir_all(&dir).unwrap();
            (None, dir)
        }
        None => {
            let scratch = tempfile::Builder::new()
                .prefix(&format!("gyro-cli-plots-{name}-"))
                .tempdir()
                .unwrap();
            let dir = scratch.path().to_path_buf();
            (Some(scratch), dir)
        }
    }
}

fn bench_report(compensation: Compensation) -> RunReport {
    let raw = log::read_csv(&bench_log(), &log::ColumnOptions::default()).unwrap();
    let regular = log::regularize(&raw, &GridOptions::default()).unwrap();
    let config = Config {
        compensation,
        ..Config::default()
    };
    replay(&regular, &config).unwrap()
}

/// A static simulated segment with white noise, a Gauss-Markov bias and quantisation.
fn static_characterization() -> Characterization {
    let model = SensorModel {
        sample_rate_hz: 100.0,
        bias_dps: 0.2,
        arw_deg_per_rt_h: 0.3,
        gm_sigma_dps: 0.01,
        gm_tau_s: 20.0,
        lsb_dps: 0.0,
        range_dps: 300.0,
    };
    let log = simulate(
        &model,
        &[],
        &Motion::from_rotations(vec![], 1200.0),
        &SimOptions::default(),
    );
    let rate: Vec<f64> = log.rows.iter().map(|r| r.rate_dps.unwrap()).collect();
    noise::characterize(&[&rate], 100.0, &NoiseOptions::default()).unwrap()
}

/// A long static segment with every power-law term: a coarse output step
/// (quantisation), white noise, bias instability and rate random walk.
fn many_terms_characterization() -> Characterization {
    let model = SensorModel {
        sample_rate_hz: 50.0,
        bias_dps: 0.1,
        arw_deg_per_rt_h: 0.2,
        gm_sigma_dps: 0.0,
        gm_tau_s: 1.0,
        lsb_dps: 0.05,
        range_dps: 300.0,
    };
    let effects = [
        Effect::BiasInstability { sigma_dps: 0.003 },
        Effect::RateRandomWalk {
            k_dps_per_rt_s: 1e-3,
        },
    ];
    let log = simulate(
        &model,
        &effects,
        &Motion::from_rotations(vec![], 4000.0),
        &SimOptions::default(),
    );
    let rate: Vec<f64> = log.rows.iter().map(|r| r.rate_dps.unwrap()).collect();
    noise::characterize(&[&rate], 50.0, &NoiseOptions::default()).unwrap()
}

fn bench_run(name: &str, seed: u64) -> BenchRun {
    let sensor = SensorModel {
        sample_rate_hz: 200.0,
        ..SensorModel::default()
    };
    let motion = Motion::bench(
        &BenchProfile {
            duration_s: 60.0,
            ..BenchProfile::default()
        },
        seed,
    );
    let log = simulate(
        &sensor,
        &[],
        &motion,
        &SimOptions {
            seed,
            ..SimOptions::default()
        },
    );
    BenchRun {
        name: format!("sim/{name}.csv"),
        log: log::regularize(&log, &GridOptions::default()).unwrap(),
    }
}

fn small_calibration() -> Calibration {
    let train: Vec<BenchRun> = (1..=3)
        .map(|k| bench_run(&format!("train-{k}"), k))
        .collect();
    let holdout = vec![bench_run("holdout-1", 11)];
    calibrate(
        &train,
        &holdout,
        &Config::default(),
        &CalibrateOptions {
            objective: Default::default(),
            leave_one_out: false,
            initial_tau_s: None,
            fit_motion: false,
            reference_delay_s: None,
        },
        &mut |_, _, _| {},
    )
    .unwrap()
}

/// Render `figure` both ways into `dir`; check the PNG; return the SVG text.
fn render_both(figure: &impl Figure, dir: &Path, stem: &str) -> String {
    let png = plot::render(figure, ImageFormat::Png).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&png[12..16], b"IHDR");
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert_eq!((w, h), figure.size());
    std::fs::write(dir.join(format!("{stem}.png")), &png).unwrap();

    let svg = String::from_utf8(plot::render(figure, ImageFormat::Svg).unwrap()).unwrap();
    assert!(svg.trim_start().starts_with("<svg"), "{}", &svg[..80]);
    assert!(svg.trim_end().ends_with("</svg>"));
    std::fs::write(dir.join(format!("{stem}.svg")), &svg).unwrap();
    svg
}

/// Lines drawn: `<polyline>` and `<path>` elements.
fn lines(svg: &str) -> usize {
    svg.matches("<polyline").count() + svg.matches("<path").count()
}

fn assert_has(svg: &str, texts: &[&str]) {
    for t in texts {
        let escaped = t
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;");
        assert!(svg.contains(t) || svg.contains(&escaped), "SVG lacks {t:?}");
    }
}

#[test]
fn run_plot_svg_and_png() {
    let (_scratch, dir) = out_dir("run");
    for (compensation, stem) in [
        (Compensation::Kalman, "run_kalman"),
        (Compensation::None, "run_none"),
    ] {
        let report = bench_report(compensation);
        let figure = RunPlot {
            title: "bench_run.csv",
            report: &report,
        };
        let svg = render_both(&figure, &dir, stem);
        assert_has(
            &svg,
            &[
                "run: bench_run.csv",
                "max |error|",
                "angle (deg)",
                "error (deg)",
                "rate (deg/s)",
                "time (s)",
                "motion",
                "dynamic",
                "static",
                "reference (encoder, filtered)",
                "angle − reference",
            ],
        );
        // Angle, reference, error, rate (one stretch each in this fixture), and legend
        // swatches for them.
        assert!(lines(&svg) >= 8, "{} lines", lines(&svg));
        let kalman = svg.contains("±1σ");
        assert_eq!(kalman, compensation == Compensation::Kalman);
    }
}

#[test]
fn run_plot_without_reference_drops_the_error_panel() {
    let mut report = bench_report(Compensation::Paper);
    for p in &mut report.series {
        p.reference_deg = None;
    }
    let s = &mut report.summary;
    (s.max_abs_error_deg, s.rms_error_deg, s.final_error_deg) = (None, None, None);
    let figure = RunPlot {
        title: "no_reference.csv",
        report: &report,
    };
    let (_scratch, dir) = out_dir("run-noref");
    let svg = render_both(&figure, &dir, "run_no_reference");
    assert_has(
        &svg,
        &[
            "no reference in the log",
            "angle (deg)",
            "rate (deg/s)",
            "motion",
        ],
    );
    assert!(!svg.contains("error (deg)"));
    assert!(!svg.contains("reference (encoder"));
}

#[test]
fn noise_plot_svg_and_png() {
    let (_scratch, dir) = out_dir("noise");
    let result = static_characterization();
    assert!(result.fit.arw_dps_per_rt_hz.significant);
    assert!(result.psd.is_some());
    let figure = NoisePlot {
        title: "simulated static",
        result: &result,
    };
    let svg = render_both(&figure, &dir, "noise");
    assert_has(
        &svg,
        &[
            "noise: simulated static",
            "averaging time τ (s)",
            "Allan deviation σ(τ) (deg/s)",
            "fitted model",
            "angle random walk N",
            "68% bounds",
            "frequency (Hz)",
            "PSD ((deg/s)²/Hz)",
            "white density",
        ],
    );
    if result.fit.gauss_markov.significant {
        assert_has(&svg, &["Gauss-Markov σ"]);
    }

    // Without a PSD: the Allan panel alone, on a shorter figure.
    let mut no_psd = result.clone();
    no_psd.psd = None;
    let figure = NoisePlot {
        title: "no PSD",
        result: &no_psd,
    };
    let svg = render_both(&figure, &dir, "noise_no_psd");
    assert!(
        figure.size().1
            < NoisePlot {
                title: "",
                result: &result
            }
            .size()
            .1
    );
    assert_has(&svg, &["averaging time τ (s)"]);
    assert!(!svg.contains("frequency (Hz)"));

    // Every significant term gets a labelled curve.
    let result = many_terms_characterization();
    let figure = NoisePlot {
        title: "simulated static, all terms",
        result: &result,
    };
    let svg = render_both(&figure, &dir, "noise_terms");
    let fit = &result.fit;
    for (significant, label) in [
        (fit.quantization_deg.significant, "quantisation Q"),
        (fit.arw_dps_per_rt_hz.significant, "angle random walk N"),
        (fit.bias_instability_dps.significant, "bias instability B"),
        (
            fit.rate_random_walk_dps_per_rt_s.significant,
            "rate random walk K",
        ),
        (fit.gauss_markov.significant, "Gauss-Markov σ"),
    ] {
        assert_eq!(svg.contains(label), significant, "{label}");
    }
}

#[test]
fn calibrate_plot_svg_and_png() {
    let (_scratch, dir) = out_dir("calibrate");
    let calibration = small_calibration();
    let figure = CalibrationPlot {
        calibration: &calibration,
    };
    let svg = render_both(&figure, &dir, "calibrate");
    assert_has(
        &svg,
        &[
            "calibration: max abs angle error per run",
            "max abs angle error over the run (deg, log scale)",
            "no compensation",
            "paper error model",
            "Kalman form",
            "training (3)",
            "hold-out (1, not fitted)",
            "train-1.csv",
            "holdout-1.csv",
        ],
    );
    // One connecting line per run.
    assert!(lines(&svg) >= 4, "{} lines", lines(&svg));
}

#[test]
fn cli_run_plot_writes_svg_and_png() {
    let (_scratch, dir) = out_dir("cli");
    let log = bench_log();
    let log = log.to_str().unwrap();
    let svg_path = dir.join("cli_run.svg");
    let png_path = dir.join("cli_run.png");
    for path in [&svg_path, &png_path] {
        let _ = std::fs::remove_file(path);
        let out = gyro(&["run", log, "--plot", path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "stderr: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // The table still goes to stdout.
        assert!(!out.stdout.is_empty());
    }
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg"));
    assert_has(&svg, &["run: bench_run.csv", "angle (deg)", "time (s)"]);
    let png = std::fs::read(&png_path).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn cli_plot_errors_name_the_file_and_do_not_panic() {
    let (_scratch, dir) = out_dir("cli-errors");
    let log = bench_log();
    let log = log.to_str().unwrap();

    // Unknown extension: refused by the argument parser, before any work.
    let bad = dir.join("plot.jpg");
    let out = gyro(&["run", log, "--plot", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("plot.jpg"), "{stderr}");
    assert!(stderr.contains(".svg or .png"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!bad.exists());

    // Unwritable: a directory that does not exist.
    let missing = dir.join("no-such-dir").join("plot.svg");
    let out = gyro(&["run", log, "--plot", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("error: cannot write"), "{stderr}");
    assert!(stderr.contains("no-such-dir"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn library_errors_name_the_file() {
    let report = bench_report(Compensation::Kalman);
    let e = plot::run_plot(Path::new("x/plot.gif"), "t", &report).unwrap_err();
    assert!(e.to_string().contains("plot.gif"), "{e}");

    let mut empty = report.clone();
    empty.series.clear();
    let (_scratch, dir) = out_dir("lib-errors");
    let path = dir.join("empty.svg");
    let e = plot::run_plot(&path, "t", &empty).unwrap_err();
    let chain = format!("{e}: {}", std::error::Error::source(&e).unwrap());
    assert!(
        chain.contains("empty.svg") && chain.contains("nothing to plot"),
        "{chain}"
    );
    assert!(!path.exists(), "nothing written for a failed plot");
}
