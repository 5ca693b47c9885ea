//! The noise module against reference implementations: allantools' `oadev` and
//! `edf_simple`/`confidence_interval`, scipy's `welch` and `chi2.ppf`, on vectors made by
//! `fixtures/noise/make_allan_reference.py` (no Python at test time).
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::noise::{self, AllanDeviation, NoiseType, PsdOptions, ONE_SIGMA};
use gyro_log as log;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/noise")
        .join(name)
}

/// A CSV of numbers (empty cells as NaN), header skipped.
fn table(name: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            line.split(',')
                .map(|v| {
                    if v.is_empty() {
                        f64::NAN
                    } else {
                        v.parse().unwrap()
                    }
                })
                .collect()
        })
        .collect()
}

fn input_rate() -> (Vec<f64>, f64) {
    let raw = log::read_csv(&fixture("allan_input.csv"), &log::ColumnOptions::default()).unwrap();
    let regular = log::regularize(&raw, &log::GridOptions::default()).unwrap();
    assert_eq!(regular.quality.filled_slots, 0);
    let rate: Vec<f64> = regular.slots.iter().map(|s| s.rate_dps).collect();
    assert_eq!(rate.len(), 20_000);
    (rate, regular.sample_rate_hz)
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn oadev_matches_allantools_at_every_tau() {
    let (rate, fs) = input_rate();
    let reference = table("allan_reference.csv");
    let factors: Vec<usize> = reference.iter().map(|r| r[0] as usize).collect();
    let allan = AllanDeviation::compute(&[&rate], fs, &factors, ONE_SIGMA);
    assert_eq!(allan.points.len(), reference.len());
    let mut worst = 0.0_f64;
    for (p, r) in allan.points.iter().zip(&reference) {
        assert_eq!(p.m, r[0] as usize);
        assert!(rel(p.tau_s, r[1]) < 1e-12);
        assert_eq!(p.terms, r[4] as u64, "m {}", p.m);
        let d = rel(p.adev_dps, r[2]);
        worst = worst.max(d);
        assert!(d < 0.01, "m {}: {} vs allantools {}", p.m, p.adev_dps, r[2]);
    }
    // In fact equal to rounding: the same sums in f64.
    assert!(worst < 1e-9, "max relative difference {worst:e}");
    eprintln!(
        "oadev vs allantools: max relative difference {worst:e} over {} taus",
        reference.len()
    );
}

#[test]
fn edf_and_white_fm_interval_match_allantools() {
    let (rate, fs) = input_rate();
    let reference = table("allan_reference.csv");
    let n_phase = rate.len() + 1;
    for r in &reference {
        let m = r[0] as usize;
        let cases = [
            (NoiseType::WhitePm, r[5]),
            (NoiseType::WhiteFm, r[6]),
            (NoiseType::FlickerFm, r[7]),
            (NoiseType::RandomWalkFm, r[8]),
        ];
        for (kind, want) in cases {
            if want.is_nan() {
                continue; // allantools' flicker-FM m = 1 formula lacks SP 1065's square
            }
            let got = kind.edf(n_phase, m);
            assert!(rel(got, want) < 1e-9, "{kind:?} m {m}: {got} vs {want}");
        }
    }
    let factors: Vec<usize> = reference.iter().map(|r| r[0] as usize).collect();
    let mut allan = AllanDeviation::compute(&[&rate], fs, &factors, ONE_SIGMA);
    allan.set_bounds(|_| NoiseType::WhiteFm);
    for (p, r) in allan.points.iter().zip(&reference) {
        assert!(
            rel(p.lower_dps, r[9]) < 1e-6,
            "m {}: {} vs {}",
            p.m,
            p.lower_dps,
            r[9]
        );
        assert!(
            rel(p.upper_dps, r[10]) < 1e-6,
            "m {}: {} vs {}",
            p.m,
            p.upper_dps,
            r[10]
        );
    }
}

#[test]
fn flicker_fm_edf_at_m1_follows_sp1065() {
    // 2 (N−2)² / (2.3 N − 4.9): about 0.87 N.
    let got = NoiseType::FlickerFm.edf(1001, 1);
    assert!(rel(got, 2.0 * 999.0 * 999.0 / (2.3 * 1001.0 - 4.9)) < 1e-12);
}

#[test]
fn welch_matches_scipy() {
    let (rate, fs) = input_rate();
    let reference = table("welch_reference.csv");
    let psd = noise::welch(
        &[&rate],
        fs,
        &PsdOptions {
            segment_len: Some(1024),
            ..PsdOptions::default()
        },
    )
    .unwrap();
    assert_eq!(psd.frequency_hz.len(), reference.len());
    // (20000 − 1024) / 512 + 1 = 38 windows, as scipy.
    assert_eq!(psd.segments, 38);
    for ((f, p), r) in psd
        .frequency_hz
        .iter()
        .zip(&psd.psd_dps2_per_hz)
        .zip(&reference)
    {
        assert!((f - r[0]).abs() < 1e-9);
        assert!(rel(*p, r[1]) < 1e-8, "{f} Hz: {p} vs scipy {}", r[1]);
    }
}

#[test]
fn chi2_quantiles_match_scipy() {
    for r in table("chi2_reference.csv") {
        let (p, dof, want) = (r[0], r[1], r[2]);
        let got = noise::chi2_quantile(p, dof);
        assert!(rel(got, want) < 1e-8, "p {p} dof {dof}: {got} vs {want}");
    }
}
