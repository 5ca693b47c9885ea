//! Stage 2, where: each statistic's z-scores against the runs' baseline ensembles,
//! combined over runs (Stouffer: Σz/√n), largest |z| first; and, once the effects are
//! selected, the statistics the selected model still leaves unexplained.

use super::score::RunScore;
use super::{Unexplained, Where};
use crate::Settings;
use std::collections::BTreeMap;

/// The default |z| at or above which a statistic is unexplained by the selected model
/// (`tests.z_critical` of [`Settings::DEFAULT`]), for the report's wording; the
/// diagnosis reads the settings it is given.
pub const UNEXPLAINED_Z: f64 = Settings::DEFAULT.tests.z_critical;

/// One statistic over a set of runs.
#[derive(Default)]
struct Combined {
    z_sum: f64,
    z_count: usize,
    /// Σ of each run's z against at least `locate.unexplained_tolerance` of the value.
    z_tolerant_sum: f64,
    real_sum: f64,
    real_count: usize,
    mean_sum: f64,
    mean_count: usize,
}

impl Combined {
    /// Stouffer's combination Σz/√n.
    fn z(&self) -> f64 {
        stouffer(self.z_sum, self.z_count)
    }

    /// Stouffer's combination of the tolerant z.
    fn z_tolerant(&self) -> f64 {
        stouffer(self.z_tolerant_sum, self.z_count)
    }

    fn real(&self) -> f64 {
        ratio(self.real_sum, self.real_count)
    }

    fn simulated(&self) -> f64 {
        ratio(self.mean_sum, self.mean_count)
    }
}

/// Σz/√n (NaN with no z).
fn stouffer(sum: f64, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        sum / (n as f64).sqrt()
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
fn combine<'a>(
    scores: impl Iterator<Item = &'a RunScore>,
    locate: &crate::settings::Locate,
) -> BTreeMap<(String, String), Combined> {
    let mut combined: BTreeMap<(String, String), Combined> = BTreeMap::new();
    for s in scores {
        for (i, (stat, z)) in s.z.iter().enumerate() {
            let e = combined
                .entry((stat.segment.to_string(), stat.statistic.to_string()))
                .or_default();
            if z.is_finite() {
                e.z_sum += z;
                e.z_count += 1;
                e.z_tolerant_sum += match s.moments.get(i) {
                    Some(&(mean, sd)) if mean.is_finite() && sd.is_finite() => {
                        let size = mean.abs().max(stat.value.abs()).max(scale_of(s, stat));
                        (stat.value - mean) / sd.max(locate.unexplained_tolerance * size)
                    }
                    _ => *z,
                };
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

/// The size beyond its own value a statistic's tolerance is taken against: for a
/// segment's mean residual, the residual's spread there. The mean is what is left of the
/// residual's swings, and a parameter known to 2% moves it by up to 2% of them: a lag
/// growing to 0.9 s swings the residual at 30–100 °/s by ±40 °/s, and a 0.05 °/s miss of
/// its 0.78 °/s mean is 0.1% of that. Nothing for any other statistic.
fn scale_of(score: &RunScore, stat: &crate::stats::Stat) -> f64 {
    use crate::stats::Statistic;
    if stat.statistic != Statistic::ResidualMean {
        return 0.0;
    }
    (score.z.iter())
        .find(|(other, _)| {
            other.segment == stat.segment && other.statistic == Statistic::ResidualStd
        })
        .map_or(0.0, |(other, _)| other.value.abs())
        .max(0.0)
}

/// Stage 2: the combined z of every statistic over `scores`, by |z|, largest first.
pub(crate) fn locate<'a>(
    scores: impl Iterator<Item = &'a RunScore>,
    settings: &Settings,
) -> Vec<Where> {
    let mut r#where: Vec<Where> = combine(scores, &settings.locate)
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
/// |z| at least `tests.z_critical` against the ensembles with the selected effects
/// (`train_after`), each run's z taken against at least `locate.unexplained_tolerance` of the
/// statistic's size, largest |z| first, each with its real value, the nominal and the selected
/// model's simulated values (means over the runs) and its combined z on the held-out runs
/// (`holdout_after`) and under the nominal model (`train_before`).
pub(crate) fn unexplained(
    train_before: &[RunScore],
    train_after: &[RunScore],
    holdout_after: &[RunScore],
    settings: &Settings,
) -> Vec<Unexplained> {
    let before = combine(train_before.iter(), &settings.locate);
    let holdout = combine(holdout_after.iter(), &settings.locate);
    let mut out: Vec<Unexplained> = combine(train_after.iter(), &settings.locate)
        .into_iter()
        .filter(|(_, c)| c.z_tolerant().abs() >= settings.tests.z_critical)
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
        .collect();
    out.sort_by(|a, b| b.z_train.abs().total_cmp(&a.z_train.abs()));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::{Segment, Stat, Statistic};

    const WANDER: Statistic = Statistic::WanderLog10Avar(0);
    const NOISE: Statistic = Statistic::ResidualStd;
    const SLOPE: Statistic = Statistic::SlopeVsRate;
    const A: Statistic = Statistic::ResidualMean;
    const B: Statistic = Statistic::ResidualStd;

    fn run(entries: &[(Statistic, f64, f64, f64)]) -> RunScore {
        // (statistic, real value, ensemble mean, z)
        RunScore {
            z: entries
                .iter()
                .map(|(name, value, _, z)| {
                    (
                        Stat {
                            segment: Segment::All,
                            statistic: *name,
                            value: *value,
                        },
                        *z,
                    )
                })
                .collect(),
            // The spread that gives each entry its z.
            moments: entries
                .iter()
                .map(|(_, v, m, z)| (*m, if *z == 0.0 { 1.0 } else { ((v - m) / z).abs() }))
                .collect(),
            ..RunScore::default()
        }
    }

    #[test]
    fn a_statistic_the_model_misses_on_every_run_is_unexplained_and_noise_is_not() {
        // Four runs: `wander` 3 sigma off on each (combined 6), `noise` within 1.5 sigma.
        let after: Vec<RunScore> = (0..4)
            .map(|i| {
                run(&[
                    (WANDER, 5.0, 2.0, 3.0),
                    (NOISE, 0.1, 0.0, if i % 2 == 0 { 1.5 } else { -1.5 }),
                ])
            })
            .collect();
        let before: Vec<RunScore> = (0..4)
            .map(|_| run(&[(WANDER, 5.0, 1.0, 40.0), (NOISE, 0.1, 0.0, 1.0)]))
            .collect();
        let holdout: Vec<RunScore> = (0..2).map(|_| run(&[(WANDER, 6.0, 2.0, 5.0)])).collect();
        let u = unexplained(&before, &after, &holdout, &Settings::DEFAULT);
        assert_eq!(u.len(), 1);
        let w = &u[0];
        assert_eq!(w.statistic, "wander_log10_avar_1s");
        assert!((w.z_train - 6.0).abs() < 1e-12);
        assert!((w.z_train_nominal - 80.0).abs() < 1e-12);
        assert!((w.z_holdout - 10.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!((w.real - 5.0).abs() < 1e-12);
        assert!((w.simulated - 2.0).abs() < 1e-12);
        assert!((w.nominal - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_last_percent_of_a_statistic_is_within_tolerance() {
        // Real 2.00, selected 1.98 with a spread of 0.002: z 10 per run, but 1% of the
        // value, within the 2% tolerance (tolerant z 0.5 per run, 1 over four).
        let before: Vec<RunScore> = (0..4).map(|_| run(&[(SLOPE, 2.0, 0.0, 1000.0)])).collect();
        let after: Vec<RunScore> = (0..4).map(|_| run(&[(SLOPE, 2.0, 1.98, 10.0)])).collect();
        assert!(unexplained(&before, &after, &after, &Settings::DEFAULT).is_empty());
        // Selected 1.5: a quarter off (tolerant z 12.5 per run).
        let after: Vec<RunScore> = (0..4).map(|_| run(&[(SLOPE, 2.0, 1.5, 250.0)])).collect();
        assert_eq!(
            unexplained(&before, &after, &after, &Settings::DEFAULT).len(),
            1
        );
    }

    #[test]
    fn a_model_that_fits_leaves_nothing_unexplained() {
        let after: Vec<RunScore> = (0..5).map(|_| run(&[(A, 1.0, 1.0, 0.5)])).collect();
        assert!(unexplained(&after, &after, &after, &Settings::DEFAULT).is_empty());
    }

    #[test]
    fn where_combines_by_stouffer_largest_first() {
        let scores = [
            run(&[(A, 0.0, 0.0, 1.0), (B, 0.0, 0.0, -3.0)]),
            run(&[(A, 0.0, 0.0, 1.0), (B, 0.0, 0.0, -3.0)]),
        ];
        let w = locate(scores.iter(), &Settings::DEFAULT);
        assert_eq!(w[0].statistic, "residual_std");
        assert!((w[0].z + 6.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!((w[1].z - 2.0 / 2f64.sqrt()).abs() < 1e-12);
    }
}
