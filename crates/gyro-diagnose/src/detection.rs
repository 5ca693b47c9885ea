//! Detection limits: the smallest size of each effect the diagnosis names on runs like
//! the self-check's, so that an effect it does not name is reported as "below about N",
//! not as absent.
//!
//! Measured by the self-check's matrix (`gyro-cli diagnose --self-test --matrix 1 --seed
//! S`, [`crate::selftest::Plan::Matrix`]): every effect alone at each magnitude of its
//! realistic range (`gyro_sim::EffectInfo::range`), on [`crate::selftest::TRAIN_RUNS`]
//! training and as many held-out runs of [`crate::selftest::RUN_S`] s of bench motion. An
//! effect's limit is the smallest magnitude of its range from which up every magnitude is
//! named first ([`crate::selftest::DetectionLimit`]); the table holds its index in the
//! range, so the numbers themselves have one home, the effect table. The seeds and the
//! figures are in docs/diagnose.md (self-check).

use gyro_sim::{effect_info, Effect};
use serde::Serialize;

/// Per effect id: the index in its range of the smallest magnitude named in the matrix
/// (`None`: not named even at the top of its range). Measured on development seed
/// 20261401, one case per magnitude (`gyro-cli diagnose --self-test --matrix 1 --seed
/// 20261401`); docs/diagnose.md gives the judging seed's figures beside it.
pub const LIMITS: &[(&str, Option<usize>)] = &[
    ("scale_factor", Some(0)),
    ("scale_asymmetry", Some(0)),
    ("nonlinearity", Some(1)),
    ("nonlinearity_even", Some(1)),
    ("saturation", Some(0)),
    ("quantization", Some(0)),
    ("latency", Some(0)),
    ("clock_error", Some(0)),
    ("clock_error_count_stamped", Some(0)),
    ("dropouts", Some(0)),
    ("temperature_bias", Some(1)),
    ("temperature_scale", Some(0)),
    ("bias_instability", Some(2)),
    ("rate_random_walk", Some(1)),
    ("turn_on_bias", Some(1)),
    ("bandwidth", Some(0)),
    ("vibration", Some(0)),
];

/// An effect the diagnosis did not name, with the smallest size runs like the
/// self-check's show of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotSeen {
    /// The effect id.
    pub id: &'static str,
    /// The detection limit (`None`: not named at the top of its realistic range either).
    pub limit: Option<Effect>,
}

/// The detection limit of `id`: `Some(None)` when even the top of its range is not
/// named, `None` when the matrix has no figure for it.
pub fn limit(id: &str) -> Option<Option<Effect>> {
    let (_, index) = LIMITS.iter().find(|(e, _)| *e == id)?;
    let info = effect_info(id)?;
    Some(index.and_then(|i| info.range.get(i).copied()))
}

/// The effects of the vocabulary not in `named`, each with its detection limit, in the
/// order of the vocabulary.
pub fn not_seen(named: &[&str]) -> Vec<NotSeen> {
    gyro_sim::EFFECTS
        .iter()
        .filter(|info| !named.contains(&info.id))
        .filter_map(|info| limit(info.id).map(|limit| NotSeen { id: info.id, limit }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_effect_has_a_limit_inside_its_range() {
        for info in gyro_sim::EFFECTS {
            let entry = LIMITS.iter().find(|(id, _)| *id == info.id);
            let Some((_, index)) = entry else {
                panic!("{}: no detection limit", info.id);
            };
            if let Some(i) = index {
                assert!(*i < info.range.len(), "{}", info.id);
            }
        }
        assert_eq!(LIMITS.len(), gyro_sim::EFFECTS.len());
    }

    #[test]
    fn what_is_named_is_not_listed() {
        let all = not_seen(&[]);
        assert_eq!(all.len(), gyro_sim::EFFECTS.len());
        let rest = not_seen(&["latency"]);
        assert!(rest.iter().all(|n| n.id != "latency"));
        assert_eq!(rest.len(), all.len() - 1);
    }
}
