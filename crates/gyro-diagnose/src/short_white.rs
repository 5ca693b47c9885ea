//! The white noise of runs that never rest, read where the residual holds the most
//! blocks.
//!
//! Runs without 2 s of rest take their white noise from the moving residual's Allan
//! deviation from 1 to 10 s ([`super::effective`]). A minute of data holds few blocks
//! that long: on 4 × 60 s its level has a standard error of about 4%, while the
//! per-sample residual statistics a simulation must match resolve 1%. From
//! [`SHORT_TAUS_S`] the same residual holds ten times the blocks, but there it is also
//! shaped by what is not the sensor's noise: the smoothing both signals share, the
//! reference's differentiation noise and output rounding. So the level there is matched
//! by simulation: each training run is simulated from its own reference with the
//! prior's wander and output step, once with the 1–10 s white level σ₁ and once without
//! white noise (same seeds, [`SHORT_MEMBERS`] each), its residual taken as a real run's,
//! and `σ² = σ₁² (A − A₀) / (A₁ − A₀)`, with A the residuals' white variance over the
//! band ([`robust_band_variance`]: from the median squared difference of block means,
//! so that a few spikes, a rate step where a log's windows join or a turn's end the
//! re-simulation does not follow, do not read as white noise; a mean would take them
//! for it). The short level replaces the 1–10 s one only when
//! the two agree within `tests.z_critical` of their combined standard error, the rule of
//! the rests' whiteness check: a rig's line or a response the model lacks puts more in
//! the short band than white noise, and then the 1–10 s level stays.

use super::effective::MeasuredNoise;
use super::ensemble::{simulate_residuals, RealRun};
use super::features::regression_residual;
use super::stats::stretches;
use gyro_analysis::noise::export::{band_white_variance, WHITE_TAUS_S};
use gyro_analysis::seed::derive_seed;
use gyro_sim::SensorModel;
use serde::Serialize;

/// The averaging times of the short band (s, ends included): [`SHORT_TAUS`]' first and last.
pub const SHORT_TAUS_S: (f64, f64) = (SHORT_TAUS[0], SHORT_TAUS[SHORT_TAUS.len() - 1]);
/// Simulations per training run and white level.
pub const SHORT_MEMBERS: usize = 4;

/// The short band's white level, and whether it agrees with the 1–10 s level.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShortWhite {
    /// The white level matched by simulation over [`SHORT_TAUS_S`] (deg/√h).
    pub level_deg_per_rt_h: f64,
    /// The 1–10 s level it is compared with (deg/√h).
    pub long_level_deg_per_rt_h: f64,
    /// (short − long) over the standard error of the difference.
    pub z: f64,
    /// |z| < `tests.z_critical`: the short level is the baseline's.
    pub agrees: bool,
}

/// The short band's white level of `train` (their moving residual measured as `long`),
/// simulated with `prior`'s wander and output step and seeds from `seed`; `None` when a
/// residual is too short for the band or the simulation shows no white noise there.
pub fn short_white(
    train: &[&RealRun],
    prior: &SensorModel,
    long: &MeasuredNoise,
    seed: u64,
    z_critical: f64,
) -> Option<ShortWhite> {
    let fs = train.first()?.sample_rate_hz;
    let runs: Vec<&&RealRun> = train.iter().filter(|r| r.sample_rate_hz == fs).collect();
    let sigma1 = long.white_level_deg_per_rt_h;
    if sigma1.is_nan() || sigma1 <= 0.0 {
        return None;
    }
    let real: Vec<&[f64]> = runs.iter().map(|r| r.residual_dps.as_slice()).collect();
    let (a_real, edf_real) = robust_band_variance(&real, fs)?;
    let simulated = |arw: f64| simulated_band(&runs, prior, arw, seed);
    let (a1, a0) = (simulated(sigma1)?, simulated(0.0)?);
    if a1.is_nan() || a0.is_nan() || a1 <= a0 {
        return None;
    }
    let level = sigma1 * ((a_real - a0).max(0.0) / (a1 - a0)).sqrt();
    // N to a relative standard error of about √(2/edf)/2 (N² to √(2/edf)); the short
    // level's from the real residuals and the simulated ones (as many degrees of
    // freedom per member as the real runs').
    let rel = |edf: f64| (2.0 / edf).sqrt() / 2.0;
    let (_, edf_long) = band_white_variance(&long.characterization, WHITE_TAUS_S)?;
    let short_rel = rel(edf_real).hypot(rel(edf_real * SHORT_MEMBERS as f64));
    let se = (sigma1 * rel(edf_long)).hypot(level * short_rel);
    let z = (level - sigma1) / se;
    Some(ShortWhite {
        level_deg_per_rt_h: level,
        long_level_deg_per_rt_h: sigma1,
        z,
        agrees: z.abs() < z_critical,
    })
}

/// The short band's white variance of the regression residuals of `runs` simulated with
/// `prior` at `arw_deg_per_rt_h` ([`SHORT_MEMBERS`] each, seeds from `seed`).
fn simulated_band(
    runs: &[&&RealRun],
    prior: &SensorModel,
    arw_deg_per_rt_h: f64,
    seed: u64,
) -> Option<f64> {
    let fs = runs.first()?.sample_rate_hz;
    let model = SensorModel {
        sample_rate_hz: fs,
        arw_deg_per_rt_h,
        ..*prior
    };
    let residuals: Vec<Vec<f64>> = runs
        .iter()
        .enumerate()
        .flat_map(|(i, run)| {
            (0..SHORT_MEMBERS).map(move |j| {
                let s = derive_seed(
                    derive_seed(seed, "short white", i as u64),
                    "member",
                    j as u64,
                );
                simulate_residuals(run, &model, &[], s)
                    .map(|r| regression_residual(&r))
                    .unwrap_or_default()
            })
        })
        .collect();
    let slices: Vec<&[f64]> = residuals.iter().map(Vec::as_slice).collect();
    robust_band_variance(&slices, fs).map(|(a, _)| a)
}

/// Averaging times of the short band (s).
const SHORT_TAUS: [f64; 4] = [0.1, 0.2, 0.5, 1.0];
/// Median of a χ² variable of one degree of freedom: the median squared difference of
/// two white block means over twice the Allan variance.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_7;
/// Efficiency of a variance read from a median of squares against one read from their
/// mean (Gaussian differences: the median's variance is 1/(4 n f(m)²), f the χ²₁ density
/// at its median).
const MEDIAN_EFFICIENCY: f64 = 0.368;

/// The white variance N² ((deg/s)²/Hz) that `residuals` (at `fs` Hz) read over
/// [`SHORT_TAUS`]: at each τ, non-overlapping block means within each finite stretch,
/// the median squared difference of neighbouring ones over 2·[`CHI2_1_MEDIAN`] (the
/// Allan variance, robust to a few spikes) times τ; averaged with the differences'
/// counts as weights. With it, the equivalent degrees of freedom of the shortest τ
/// (N² to a relative standard error of about √(2/edf)). `None` without a block pair.
pub fn robust_band_variance(residuals: &[&[f64]], fs: f64) -> Option<(f64, f64)> {
    let (mut sum, mut weights, mut best) = (0.0, 0.0, 0.0f64);
    for tau_s in SHORT_TAUS {
        let m = ((tau_s * fs).round() as usize).max(1);
        let mut squares: Vec<f64> = Vec::new();
        for residual in residuals {
            for stretch in stretches(residual.len(), |i| residual[i].is_finite()) {
                let means: Vec<f64> = residual[stretch]
                    .chunks_exact(m)
                    .map(|c| c.iter().sum::<f64>() / m as f64)
                    .collect();
                squares.extend(means.windows(2).map(|w| (w[1] - w[0]).powi(2)));
            }
        }
        if squares.is_empty() {
            continue;
        }
        let n = squares.len();
        let mid = n / 2;
        let median = *squares.select_nth_unstable_by(mid, f64::total_cmp).1;
        let avar = median / (2.0 * CHI2_1_MEDIAN);
        sum += n as f64 * avar * (m as f64 / fs);
        weights += n as f64;
        best = best.max(n as f64 * MEDIAN_EFFICIENCY);
    }
    (weights > 0.0).then(|| (sum / weights, best))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
    const Z: f64 = crate::Settings::DEFAULT.tests.z_critical;
    use super::super::effective::{measure, tests::moving_runs};
    use super::super::fit::{nominal_model, Nominal};
    use super::*;
    use gyro_sim::Effect;

    fn measured(runs: &[RealRun]) -> (Vec<&RealRun>, MeasuredNoise) {
        let refs: Vec<&RealRun> = runs.iter().collect();
        let m = measure(&refs, "training", &crate::Settings::DEFAULT.turns).unwrap();
        (refs, m)
    }

    /// White noise alone reads the same in the short band, to within 4% of the
    /// simulated level (6 runs of 100 s at 100 Hz), and the runs' baseline takes it.
    #[test]
    fn white_noise_reads_alike_in_the_short_band_and_the_baseline_takes_it() {
        let runs = moving_runs(6.0, &[]);
        let (refs, m) = measured(&runs);
        let prior = SensorModel::default();
        let w = short_white(&refs, &prior, &m, 7, Z).unwrap();
        assert!(w.agrees, "{w:?}");
        assert!(
            (0.96..1.04).contains(&(w.level_deg_per_rt_h / 6.0)),
            "{w:?}"
        );
        assert_eq!(w.long_level_deg_per_rt_h, m.white_level_deg_per_rt_h);
        let Nominal { model, notes, .. } =
            nominal_model(&refs, &prior, Some(&m), Some(&w), &crate::Settings::DEFAULT);
        assert_eq!(model.arw_deg_per_rt_h, w.level_deg_per_rt_h);
        let text = notes.join("\n");
        assert!(
            text.contains("read from 0.1 to 1 s and matched by simulating"),
            "{text}"
        );
    }

    /// A rig's line in the short band (2 deg/s at 12.8 Hz, not in the reference) reads
    /// as more than white noise there: the baseline keeps the 1–10 s level and says why.
    #[test]
    fn a_line_in_the_short_band_keeps_the_long_level() {
        let line = Effect::Vibration {
            amplitude_dps: 2.0,
            frequency_hz: 12.8,
        };
        let runs = moving_runs(6.0, &[line]);
        let (refs, m) = measured(&runs);
        let prior = SensorModel::default();
        let w = short_white(&refs, &prior, &m, 7, Z).unwrap();
        assert!(!w.agrees && w.z >= Z, "{w:?}");
        let Nominal { model, notes, .. } =
            nominal_model(&refs, &prior, Some(&m), Some(&w), &crate::Settings::DEFAULT);
        assert_eq!(model.arw_deg_per_rt_h, m.white_level_deg_per_rt_h);
        let text = notes.join("\n");
        assert!(text.contains("more there than white noise"), "{text}");
    }
    /// White noise reads its own variance in the short band; a few spikes (one sample in
    /// 2000 off by 20σ, as a rate step the re-simulation does not follow) move the
    /// robust reading by a few percent, and a mean of squares by more than 10%.
    #[test]
    fn the_short_band_reads_white_noise_through_a_few_spikes() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let fs = 100.0;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut x: Vec<f64> = (0..60_000)
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        // N² of unit white noise at fs: 1/fs.
        let (clean, edf) = robust_band_variance(&[&x], fs).unwrap();
        assert!((clean * fs - 1.0).abs() < 0.05, "{clean}");
        assert!(edf > 1000.0, "{edf}");
        for k in (100..x.len()).step_by(2000) {
            x[k] += 20.0;
        }
        let (spiked, _) = robust_band_variance(&[&x], fs).unwrap();
        assert!((spiked * fs - 1.0).abs() < 0.1, "{spiked}");
        let mean_of_squares = {
            let means: Vec<f64> = x
                .chunks_exact(10)
                .map(|c| c.iter().sum::<f64>() / 10.0)
                .collect();
            let d: Vec<f64> = means.windows(2).map(|w| (w[1] - w[0]).powi(2)).collect();
            d.iter().sum::<f64>() / d.len() as f64 / 2.0 * 0.1
        };
        assert!(mean_of_squares * fs > 1.1, "{mean_of_squares}");
    }
}
