//! The gap G, its floor, and the likelihood used for significance.
//!
//! **Gap G** (fixed before any fit): for each run, every "where" statistic is turned into
//! a z-score against that run's ensemble ([`z_scores`]); G over a set of runs is the root
//! mean square of all these z-scores, `G = sqrt(Σ z² / count)`. A simulation
//! indistinguishable from the real sensor gives G ≈ 1; an unmodelled effect raises the
//! z-scores of the statistics its signature touches.
//!
//! **Floor**: G of simulated runs against ensembles they are not part of: for each run,
//! `score.floor_members` members are taken out in turn and scored against the others. This is
//! the gap between two independent simulated ensembles, the least any model can reach.
//!
//! **Likelihood**: each statistic of a run is taken as Student-t with
//! `score.likelihood_dof` degrees of freedom, located at the ensemble's mean and scaled by its
//! standard deviation, `ℓ = Σ [−(ν+1)/2 · ln(1 + z²/ν) − ln σ]` ([`loglik`]), statistics
//! treated as independent (they are not; the bootstrap over runs is what guards the
//! decision). On a real sensor some statistics sit thousands of σ from any candidate's
//! ensemble; under a Gaussian their z² would decide every comparison (an effect that
//! merely widens those ensembles would win), while the t's heavy tails let a statistic an
//! effect brings to its ensemble count for more than large misfits shifted a little. The
//! ln σ term keeps an effect that only widens the ensemble from looking like an
//! improvement.

use super::ensemble::Member;
use super::stats::{z_scores, Segment, Stat, Statistic, STD_FLOOR_ABS, STD_FLOOR_REL};
use std::collections::BTreeMap;

/// One run scored against one ensemble.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunScore {
    /// Σ z² over the statistics with a finite z.
    pub sum_z2: f64,
    /// How many statistics.
    pub count: usize,
    /// Gaussian log-likelihood of the statistics.
    pub loglik: f64,
    /// The z-scores, by (segment, statistic).
    pub z: Vec<(Stat, f64)>,
    /// The ensemble's mean and standard deviation (floored as for the z-score) of each
    /// statistic of `z`, in the same order (NaN where the ensemble has no value).
    pub moments: Vec<(f64, f64)>,
}

/// Score `real` statistics against `members`.
/// `likelihood_dof`: the setting `score.likelihood_dof` ([`loglik`]).
pub fn score(real: &[Stat], members: &[Member], likelihood_dof: f64) -> RunScore {
    let ensemble: Vec<Vec<Stat>> = members.iter().map(|m| m.stats.clone()).collect();
    score_stats(real, &ensemble, likelihood_dof)
}

fn score_stats(real: &[Stat], ensemble: &[Vec<Stat>], likelihood_dof: f64) -> RunScore {
    let z = z_scores(real, ensemble);
    let mut values: BTreeMap<(Segment, Statistic), (f64, f64, usize)> = BTreeMap::new();
    for run in ensemble {
        for s in run {
            if s.value.is_finite() {
                let e = values
                    .entry((s.segment, s.statistic))
                    .or_insert((0.0, 0.0, 0));
                e.0 += s.value;
                e.1 += s.value * s.value;
                e.2 += 1;
            }
        }
    }
    let mut out = RunScore::default();
    for (stat, zv) in &z {
        let Some(&(sum, sum2, n)) = values.get(&(stat.segment, stat.statistic)) else {
            out.moments.push((f64::NAN, f64::NAN));
            continue;
        };
        let nf = n as f64;
        let mean = sum / nf;
        let var = ((sum2 - sum * mean) / (nf - 1.0)).max(0.0);
        let floor = STD_FLOOR_ABS.max(STD_FLOOR_REL * mean.abs().max(stat.value.abs()));
        let sd = var.sqrt().max(floor);
        out.moments.push((mean, sd));
        if !zv.is_finite() {
            continue;
        }
        out.sum_z2 += zv * zv;
        out.count += 1;
        out.loglik += loglik(*zv, sd, likelihood_dof);
    }
    out.z = z;
    out
}

/// Log-likelihood of a statistic at `z` standard deviations `sd` from its ensemble's
/// mean: Student-t with `score.likelihood_dof` degrees of freedom, up to a constant. Close to
/// Gaussian within a few σ; its heavy tails keep statistics that no candidate model
/// reproduces (z in the thousands on a real sensor) from outweighing the statistics an
/// effect does explain.
pub fn loglik(z: f64, sd: f64, nu: f64) -> f64 {
    -0.5 * (nu + 1.0) * (z * z / nu).ln_1p() - sd.ln()
}

/// G of a set of run scores.
pub fn gap(scores: &[RunScore]) -> f64 {
    let (s, c) = scores
        .iter()
        .fold((0.0, 0usize), |(s, c), r| (s + r.sum_z2, c + r.count));
    if c == 0 {
        f64::NAN
    } else {
        (s / c as f64).sqrt()
    }
}

/// The floor: members scored against the rest of their ensemble (see the module docs).
pub fn floor(ensembles: &[Vec<Member>], settings: &crate::settings::Score) -> f64 {
    let mut scores = Vec::new();
    for members in ensembles {
        let k = settings.floor_members.min(members.len() / 2);
        for i in 0..k {
            let rest: Vec<Vec<Stat>> = members
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, m)| m.stats.clone())
                .collect();
            scores.push(score_stats(
                &members[i].stats,
                &rest,
                settings.likelihood_dof,
            ));
        }
    }
    gap(&scores)
}

/// Bootstrap over runs of a sum of per-run differences: the fraction of `resamples`
/// resamples (runs drawn with replacement, a fixed-seed generator) whose sum is ≤ 0.
pub fn bootstrap_p(differences: &[f64], resamples: usize, seed: u64) -> f64 {
    let n = differences.len();
    if n == 0 {
        return 1.0;
    }
    let mut state = seed ^ 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        // xorshift64*
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    };
    let mut not_positive = 0usize;
    for _ in 0..resamples {
        let sum: f64 = (0..n)
            .map(|_| differences[(next() % n as u64) as usize])
            .sum();
        if sum <= 0.0 {
            not_positive += 1;
        }
    }
    not_positive as f64 / resamples as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    const NU: f64 = crate::Settings::DEFAULT.score.likelihood_dof;

    #[test]
    fn bootstrap_of_clear_and_null_differences() {
        assert_eq!(bootstrap_p(&[1.0, 2.0, 0.5, 3.0], 1000, 1), 0.0);
        assert_eq!(bootstrap_p(&[-1.0, -2.0], 1000, 1), 1.0);
        let p = bootstrap_p(&[1.0, -1.0, 1.0, -1.0, 0.5, -0.5], 4000, 2);
        assert!(p > 0.3 && p < 0.8, "{p}");
    }

    #[test]
    fn likelihood_is_near_gaussian_close_in_and_heavy_tailed_far_out() {
        let gauss = |z: f64| -0.5 * z * z;
        // Close in: the t's shape differs from a Gaussian's by a factor of (ν+1)/ν.
        let r = (loglik(0.5, 1.0, NU) - loglik(0.0, 1.0, NU)) / gauss(0.5);
        assert!((r - 1.25).abs() < 0.1, "{r}");
        // Far out: bringing one statistic from 5000σ to 1σ outweighs moving ten others
        // from 3000σ to 3500σ.
        let fixed = loglik(1.0, 1.0, NU) - loglik(5000.0, 1.0, NU);
        let moved = 10.0 * (loglik(3500.0, 1.0, NU) - loglik(3000.0, 1.0, NU));
        assert!(fixed + moved > 0.0, "{fixed} {moved}");
        // Widening an ensemble tenfold costs ln 10.
        assert!((loglik(0.0, 10.0, NU) - loglik(0.0, 1.0, NU) + 10f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn gap_is_rms_z() {
        let s = |c: usize, z2: f64| RunScore {
            sum_z2: z2,
            count: c,
            ..RunScore::default()
        };
        assert!((gap(&[s(2, 8.0), s(2, 0.0)]) - 2.0f64.sqrt()).abs() < 1e-12);
        assert!(gap(&[]).is_nan());
    }
}
