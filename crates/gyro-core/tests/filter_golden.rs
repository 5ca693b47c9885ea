//! Golden vectors from scipy (`fixtures/filters/`, written by
//! `fixtures/filters/make_filter_vectors.py`; these tests never run Python).
//!
//! - Coefficients: [`Butterworth::design`] against `scipy.signal.butter(N, fc, fs=fs,
//!   output='sos')`, section by section, within `1e-6 × |c| + 1e-12` for each coefficient
//!   `c` (the absolute term only matters for coefficients that are exactly 0 in scipy,
//!   or ~1e-17 where the real pole sits at z = 0 for fc = fs/4).

use gyro_core::Butterworth;
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
    // Every order 1..=8 for each of the 18 (cutoff, sample rate) pairs.
    assert_eq!(designs, 8 * 18);
    println!(
        "{designs} designs: max relative coefficient error {max_rel:e}, \
         max absolute error on coefficients below 1e-9 {max_abs_tiny:e}"
    );
}
