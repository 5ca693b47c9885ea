//! Golden vectors from scipy (`fixtures/filters/`, written by
//! `fixtures/filters/make_filter_vectors.py`; these tests never run Python).
//!
//! - Coefficients: [`Butterworth::design`] against `scipy.signal.butter(N, fc, fs=fs,
//!   output='sos')`, section by section, within `1e-6 × |c| + 1e-12` for each coefficient
//!   `c` (the absolute term only matters for coefficients that are exactly 0 in scipy,
//!   or ~1e-17 where the real pole sits at z = 0 for fc = fs/4).
//! - Filtering: the f32 runtime ([`gyro_core::Sos::process`], from zero state) against
//!   scipy's `sosfilt` (f64) on a 20000-sample random input and a unit step, both of full
//!   scale 1 (|x| ≤ 1): the tolerance [`FILTER_ABS_TOL`] = 1e-5 is absolute, i.e. 1e-5 of
//!   the input's full scale, for every sample.
//! - Coverage beyond the designs scipy filtered: an f64 transposed-direct-form-II cascade
//!   (scipy's `sosfilt` algorithm) is first shown to reproduce the scipy outputs, then
//!   serves as reference for every design of `butter_sos.csv` (orders 1–8, 22 cutoffs,
//!   1e-3 ≤ fc/fs ≤ 0.49) on the same inputs.
// Helpers outside #[test] fns unwrap too: a parse failure means a broken fixture.
#![allow(clippy::unwrap_used)]

use gyro_core::{Butterworth, SosState};
use std::path::PathBuf;

/// Relative tolerance on each design coefficient.
const COEFF_REL_TOL: f64 = 1e-6;
/// Absolute floor for coefficients that are (nearly) zero.
const COEFF_ABS_TOL: f64 = 1e-12;

fn fixture(name: &str) -> String {
    let path: PathBuf = [
        env!("CARGO_MANIFEST_DIR"),
        "..",
        "..",
        "fixtures",
        "filters",
        name,
    ]
    .iter()
    .collect();
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// One row of `butter_sos.csv`.
struct SectionRow {
    filter: Butterworth,
    sample_rate_hz: f64,
    section: usize,
    row: [f64; 6],
}

fn read_sections() -> Vec<SectionRow> {
    let text = fixture("butter_sos.csv");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("order,cutoff_hz,sample_rate_hz,section,b0,b1,b2,a0,a1,a2")
    );
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 10, "{line}");
            let mut row = [0.0; 6];
            for (dst, s) in row.iter_mut().zip(&f[4..]) {
                *dst = s.parse().unwrap();
            }
            SectionRow {
                filter: Butterworth {
                    order: f[0].parse().unwrap(),
                    cutoff_hz: f[1].parse().unwrap(),
                },
                sample_rate_hz: f[2].parse().unwrap(),
                section: f[3].parse().unwrap(),
                row,
            }
        })
        .collect()
}

#[test]
fn coefficients_match_scipy() {
    let rows = read_sections();
    let mut designs = 0;
    let mut max_rel = 0.0_f64;
    let mut max_abs_tiny = 0.0_f64;
    for r in &rows {
        let design = r.filter.design(r.sample_rate_hz).unwrap();
        let sections = design.sections();
        if r.section == 0 {
            designs += 1;
            // scipy has as many sections as we do: count them by the rows that follow.
            let n = rows
                .iter()
                .filter(|o| o.filter == r.filter && o.sample_rate_hz == r.sample_rate_hz)
                .count();
            assert_eq!(
                sections.len(),
                n,
                "{:?} at {} Hz",
                r.filter,
                r.sample_rate_hz
            );
        }
        let got = sections[r.section];
        for (i, (g, w)) in got.iter().zip(r.row).enumerate() {
            assert!(
                (g - w).abs() <= COEFF_REL_TOL * w.abs() + COEFF_ABS_TOL,
                "{:?} at {} Hz, section {}, coefficient {i}: {g:e} vs scipy {w:e}\n  \
                 got   {got:?}\n  scipy {:?}",
                r.filter,
                r.sample_rate_hz,
                r.section,
                r.row
            );
            if w.abs() > 1e-9 {
                max_rel = max_rel.max(((g - w) / w).abs());
            } else {
                max_abs_tiny = max_abs_tiny.max((g - w).abs());
            }
        }
    }
    // Every order 1..=8 for each of the 22 (cutoff, sample rate) pairs.
    assert_eq!(designs, 8 * 22);
    println!(
        "{designs} designs: max relative coefficient error {max_rel:e}, \
         max absolute error on coefficients below 1e-9 {max_abs_tiny:e}"
    );
}

/// Largest allowed |f32 runtime − scipy `sosfilt`|, absolute, for inputs of full scale 1
/// (|x| ≤ 1): i.e. 1e-5 of the input's full scale.
const FILTER_ABS_TOL: f64 = 1e-5;
/// Input samples are `k / INPUT_SCALE` (exact in f32 and f64).
const INPUT_SCALE: f32 = 32768.0;

/// A signal fixture: the input and, per design, scipy's `sosfilt` output.
struct Signals {
    x: Vec<f32>,
    outputs: Vec<(Butterworth, f64, Vec<f64>)>,
}

/// Parse a column name `o{order}_fc{cutoff_hz}_fs{sample_rate_hz}`.
fn parse_design(name: &str) -> (Butterworth, f64) {
    let parts: Vec<&str> = name.split('_').collect();
    assert_eq!(parts.len(), 3, "{name}");
    let order = parts[0].strip_prefix('o').unwrap().parse().unwrap();
    let cutoff_hz = parts[1].strip_prefix("fc").unwrap().parse().unwrap();
    let fs = parts[2].strip_prefix("fs").unwrap().parse().unwrap();
    (Butterworth { order, cutoff_hz }, fs)
}

fn read_signals(name: &str) -> Signals {
    let text = fixture(name);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "k");
    let mut outputs: Vec<_> = header[1..]
        .iter()
        .map(|h| {
            let (filter, fs) = parse_design(h);
            (filter, fs, Vec::new())
        })
        .collect();
    let mut x = Vec::new();
    for line in lines {
        let mut fields = line.split(',');
        let k: i32 = fields.next().unwrap().parse().unwrap();
        x.push(k as f32 / INPUT_SCALE);
        for (out, field) in outputs.iter_mut().zip(fields) {
            out.2.push(field.parse().unwrap());
        }
    }
    for out in &outputs {
        assert_eq!(out.2.len(), x.len());
    }
    Signals { x, outputs }
}

/// The f32 runtime over `x`, from zero state.
fn run_f32(filter: &Butterworth, fs: f64, x: &[f32]) -> Vec<f32> {
    let sos = filter.sos(fs).unwrap();
    let mut state = SosState::new();
    x.iter().map(|&v| sos.process(&mut state, v)).collect()
}

fn max_abs_diff(a: &[f32], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&a, &b)| (f64::from(a) - b).abs())
        .fold(0.0, f64::max)
}

fn check_signals(name: &str) {
    let s = read_signals(name);
    let mut worst = 0.0_f64;
    for (filter, fs, want) in &s.outputs {
        let got = run_f32(filter, *fs, &s.x);
        let err = max_abs_diff(&got, want);
        println!(
            "{name}: order {} fc {} Hz fs {fs} Hz: max |f32 - sosfilt| = {err:.3e}",
            filter.order, filter.cutoff_hz
        );
        worst = worst.max(err);
    }
    assert!(worst <= FILTER_ABS_TOL, "{name}: worst error {worst:e}");
}

#[test]
fn random_input_matches_sosfilt() {
    check_signals("sosfilt_random.csv");
}

#[test]
fn step_matches_sosfilt() {
    check_signals("sosfilt_step.csv");
}

/// scipy's `sosfilt` algorithm: each section in transposed direct form II, in f64.
fn sosfilt_f64(rows: &[[f64; 6]], x: &[f32]) -> Vec<f64> {
    let mut state = vec![[0.0_f64; 2]; rows.len()];
    x.iter()
        .map(|&x| {
            let mut y = f64::from(x);
            for (row, s) in rows.iter().zip(state.iter_mut()) {
                let [b0, b1, b2, _, a1, a2] = *row;
                let input = y;
                y = b0 * input + s[0];
                s[0] = b1 * input - a1 * y + s[1];
                s[1] = b2 * input - a2 * y;
            }
            y
        })
        .collect()
}

#[test]
fn f64_reference_reproduces_sosfilt() {
    let mut worst = 0.0_f64;
    for name in ["sosfilt_random.csv", "sosfilt_step.csv"] {
        let s = read_signals(name);
        for (filter, fs, want) in &s.outputs {
            let design = filter.design(*fs).unwrap();
            let got = sosfilt_f64(design.sections(), &s.x);
            for (g, w) in got.iter().zip(want) {
                // The fixture holds 9 significant digits.
                let err = (g - w).abs();
                assert!(
                    err <= 1e-8 * w.abs() + 1e-15,
                    "{filter:?} at {fs} Hz: {g} vs {w}"
                );
                worst = worst.max(err);
            }
        }
    }
    println!("f64 reference vs sosfilt fixtures: max abs difference {worst:.3e}");
}

#[test]
fn every_design_matches_reference() {
    let rows = read_sections();
    let random = read_signals("sosfilt_random.csv").x;
    let step = read_signals("sosfilt_step.csv").x;
    let mut worst = (0.0_f64, None);
    for r in rows.iter().filter(|r| r.section == 0) {
        let design = r.filter.design(r.sample_rate_hz).unwrap();
        for x in [&random, &step] {
            let want = sosfilt_f64(design.sections(), x);
            let got = run_f32(&r.filter, r.sample_rate_hz, x);
            let err = max_abs_diff(&got, &want);
            assert!(
                err <= FILTER_ABS_TOL,
                "{:?} at {} Hz: max error {err:e}",
                r.filter,
                r.sample_rate_hz
            );
            if err > worst.0 {
                worst = (err, Some((r.filter, r.sample_rate_hz)));
            }
        }
    }
    println!(
        "every design: max |f32 - f64 sosfilt| = {:.3e} ({:?})",
        worst.0, worst.1
    );
}
