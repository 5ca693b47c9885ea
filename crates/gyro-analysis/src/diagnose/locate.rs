//! Stage 2, where: each statistic's z-scores against the runs' baseline ensembles,
//! combined over runs (Stouffer: Σz/√n), largest |z| first; and, once the effects are
//! selected, the statistics the selected model still leaves unexplained.

use super::score::RunScore;
use super::{Unexplained, Where};
use std::collections::BTreeMap;

/// |z| (combined over the training runs) at or above which a statistic is unexplained by
/// the selected model: the bound of the parameter tests (a Bonferroni bound over the
/// vocabulary at a family-wise 0.1%; over the ~65 statistics it leaves a well-fitting
/// model's list empty with probability above 99%).
pub const UNEXPLAINED_Z: f64 = 4.0;

/// Share of the nominal model's discrepancy (|real − nominal|) that the selected model
/// must leave, beyond [`UNEXPLAINED_Z`], for a statistic to be unexplained. A strong
/// effect's statistics are measured far more precisely than its parameter is fitted (the
/// regression parameters carry a 2% systematic uncertainty), so a correct model can
/// leave a z of 10 in the last percent of a discrepancy in the hundreds of σ.
pub const UNEXPLAINED_SHARE: f64 = 0.1;

/// One statistic over a set of runs.
#[derive(Default)]
struct Combined {
    z_sum: f64,
    z_count: usize,
    real_sum: f64,
    real_count: usize,
    mean_sum: f64,
    mean_count: usize,
}

impl Combined {
    /// Stouffer's combination Σz/√n.
    fn z(&self) -> f64 {
        if self.z_count == 0 {
            f64::NAN
        } else {
            self.z_sum / (self.z_count as f64).sqrt()
        }
    }

    fn real(&self) -> f64 {
        ratio(self.real_sum, self.real_count)
    }

    fn simulated(&self) -> f64 {
        ratio(self.mean_sum, self.mean_count)
    }
}

fn ratio(sum: f64, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// Every statistic of `scores` combined over the runs: z, the real value's mean and the
/// ensembles' means' mean.
fn combine<'a>(scores: impl Iterator<Item = &'a RunScore>) -> BTreeMap<(String, String), Combined> {
    let mut combined: BTreeMap<(String, String), Combined> = BTreeMap::new();
    for s in scores {
        for (i, (stat, z)) in s.z.iter().enumerate() {
            let e = combined
                .entry((stat.segment.clone(), stat.statistic.clone()))
                .or_default();
            if z.is_finite() {
                e.z_sum += z;
                e.z_count += 1;
            }
            if stat.value.is_finite() {
                e.real_sum += stat.value;
                e.real_count += 1;
            }
            if let Some((mean, _)) = s.moments.get(i).filter(|(m, _)| m.is_finite()) {
                e.mean_sum += mean;
                e.mean_count += 1;
            }
        }
    }
    combined
}

/// Stage 2: the combined z of every statistic over `scores`, by |z|, largest first.
pub(crate) fn locate<'a>(scores: impl Iterator<Item = &'a RunScore>) -> Vec<Where> {
    let mut r#where: Vec<Where> = combine(scores)
        .into_iter()
        .filter(|(_, c)| c.z_count > 0)
        .map(|((segment, statistic), c)| Where {
            segment,
            statistic,
            z: c.z(),
        })
        .collect();
    r#where.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    r#where
}

/// The statistics the selected model leaves unexplained on the training runs: combined
/// |z| at least [`UNEXPLAINED_Z`] against the ensembles with the selected effects
/// (`train_after`) and more than [`UNEXPLAINED_SHARE`] of the nominal model's
/// discrepancy left, largest |z| first, each with its real value, the nominal and the selected
/// model's simulated values (means over the runs) and its combined z on the held-out runs
/// (`holdout_after`) and under the nominal model (`train_before`).
pub(crate) fn unexplained(
    train_before: &[RunScore],
    train_after: &[RunScore],
    holdout_after: &[RunScore],
) -> Vec<Unexplained> {
    let before = combine(train_before.iter());
    let holdout = combine(holdout_after.iter());
    let mut out: Vec<Unexplained> = combine(train_after.iter())
        .into_iter()
        .filter(|(_, c)| c.z().abs() >= UNEXPLAINED_Z)
        .map(|(key, c)| {
            let b = before.get(&key);
            let h = holdout.get(&key);
            Unexplained {
                z_train: c.z(),
                z_train_nominal: b.map_or(f64::NAN, Combined::z),
                z_holdout: h.map_or(f64::NAN, Combined::z),
                real: c.real(),
                nominal: b.map_or(f64::NAN, Combined::simulated),
                simulated: c.simulated(),
                segment: key.0,
                statistic: key.1,
            }
        })
        .filter(|u| !mostly_explained(u))
        .collect();
    out.sort_by(|a, b| b.z_train.abs().total_cmp(&a.z_train.abs()));
    out
}

/// At most [`UNEXPLAINED_SHARE`] of the nominal discrepancy left. A NaN (no ensemble
/// value) is not explained: nothing says it is.
fn mostly_explained(u: &Unexplained) -> bool {
    (u.real - u.simulated).abs() <= UNEXPLAINED_SHARE * (u.real - u.nominal).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::stats::Stat;

    fn run(entries: &[(&str, f64, f64, f64)]) -> RunScore {
        // (statistic, real value, ensemble mean, z)
        RunScore {
            z: entries
                .iter()
                .map(|(name, value, _, z)| {
                    (
                        Stat {
                            segment: "all".into(),
                            statistic: (*name).into(),
                            value: *value,
                        },
                        *z,
                    )
                })
                .collect(),
            moments: entries.iter().map(|(_, _, m, _)| (*m, 1.0)).collect(),
            ..RunScore::default()
        }
    }

    #[test]
    fn a_statistic_the_model_misses_on_every_run_is_unexplained_and_noise_is_not() {
        // Four runs: `wander` 3 sigma off on each (combined 6), `noise` within 1.5 sigma.
        let after: Vec<RunScore> = (0..4)
            .map(|i| {
                run(&[
                    ("wander", 5.0, 2.0, 3.0),
                    ("noise", 0.1, 0.0, if i % 2 == 0 { 1.5 } else { -1.5 }),
                ])
            })
            .collect();
        let before: Vec<RunScore> = (0..4)
            .map(|_| run(&[("wander", 5.0, 1.0, 40.0), ("noise", 0.1, 0.0, 1.0)]))
            .collect();
        let holdout: Vec<RunScore> = (0..2).map(|_| run(&[("wander", 6.0, 2.0, 5.0)])).collect();
        let u = unexplained(&before, &after, &holdout);
        assert_eq!(u.len(), 1);
        let w = &u[0];
        assert_eq!(w.statistic, "wander");
        assert!((w.z_train - 6.0).abs() < 1e-12);
        assert!((w.z_train_nominal - 80.0).abs() < 1e-12);
        assert!((w.z_holdout - 10.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!((w.real - 5.0).abs() < 1e-12);
        assert!((w.simulated - 2.0).abs() < 1e-12);
        assert!((w.nominal - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_last_percent_of_a_large_discrepancy_is_explained() {
        // Nominal 0, real 2.00, selected 1.98: z 10, but 1% of the discrepancy left.
        let before: Vec<RunScore> = (0..4).map(|_| run(&[("slope", 2.0, 0.0, 400.0)])).collect();
        let after: Vec<RunScore> = (0..4).map(|_| run(&[("slope", 2.0, 1.98, 5.0)])).collect();
        assert!(unexplained(&before, &after, &after).is_empty());
        // Selected 1.5: a quarter left.
        let after: Vec<RunScore> = (0..4).map(|_| run(&[("slope", 2.0, 1.5, 5.0)])).collect();
        assert_eq!(unexplained(&before, &after, &after).len(), 1);
    }

    #[test]
    fn a_model_that_fits_leaves_nothing_unexplained() {
        let after: Vec<RunScore> = (0..5).map(|_| run(&[("a", 1.0, 1.0, 0.5)])).collect();
        assert!(unexplained(&after, &after, &after).is_empty());
    }

    #[test]
    fn where_combines_by_stouffer_largest_first() {
        let scores = [
            run(&[("a", 0.0, 0.0, 1.0), ("b", 0.0, 0.0, -3.0)]),
            run(&[("a", 0.0, 0.0, 1.0), ("b", 0.0, 0.0, -3.0)]),
        ];
        let w = locate(scores.iter());
        assert_eq!(w[0].statistic, "b");
        assert!((w[0].z + 6.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!((w[1].z - 2.0 / 2f64.sqrt()).abs() < 1e-12);
    }
}
