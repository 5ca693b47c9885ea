//! Stage 2, where: each statistic's z-scores against the runs' baseline ensembles,
//! combined over runs (Stouffer: Σz/√n), largest |z| first.

use super::score::RunScore;
use super::Where;
use std::collections::BTreeMap;

/// Stage 2: the combined z of every statistic over `scores`, by |z|, largest first.
pub(crate) fn locate<'a>(scores: impl Iterator<Item = &'a RunScore>) -> Vec<Where> {
    let mut combined: BTreeMap<(String, String), (f64, usize)> = BTreeMap::new();
    for s in scores {
        for (stat, z) in &s.z {
            if z.is_finite() {
                let e = combined
                    .entry((stat.segment.clone(), stat.statistic.clone()))
                    .or_insert((0.0, 0));
                e.0 += z;
                e.1 += 1;
            }
        }
    }
    let mut r#where: Vec<Where> = combined
        .into_iter()
        .map(|((segment, statistic), (sum, n))| Where {
            segment,
            statistic,
            z: sum / (n as f64).sqrt(),
        })
        .collect();
    r#where.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    r#where
}
