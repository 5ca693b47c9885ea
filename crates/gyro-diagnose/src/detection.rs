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
    ("nonlinearity", Some(0)),
    ("nonlinearity_even", Some(0)),
    ("saturation", Some(0)),
    ("quantization", Some(0)),
    ("latency", Some(0)),
    ("clock_error", Some(0)),
    ("clock_error_count_stamped", Some(0)),
    ("dropouts", Some(0)),
    ("temperature_bias", Some(0)),
    ("temperature_scale", Some(0)),
    ("bias_instability", Some(1)),
    ("rate_random_walk", Some(0)),
    ("turn_on_bias", Some(0)),
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

/// Effects whose first parameter is a size, zero when absent (a scale, a delay, a σ, an
/// amplitude), so that a fit can be set against the smallest size of its range. Not the
/// clip level, the output step, the cutoff or the dropouts, whose parameters are not.
const SIZED: &[&str] = &[
    "scale_factor",
    "scale_asymmetry",
    "nonlinearity",
    "nonlinearity_even",
    "latency",
    "clock_error",
    "clock_error_count_stamped",
    "temperature_bias",
    "temperature_scale",
    "bias_instability",
    "rate_random_walk",
    "turn_on_bias",
    "vibration",
];

/// True when the whole 95% interval `ci95` of `effect`'s first parameter (both ends
/// bounded) lies under `share` of the smallest size of its realistic range (the first
/// magnitude of `gyro_sim::EffectInfo::range`, from the datasheets), either sign: what it
/// could be is smaller than the parts the range was drawn from show
/// (`fit.negligible_range_share`). The range, not the measured [`LIMITS`], so that a new
/// measurement of the limits changes no decision that the measurement itself depends on.
/// False for an effect without a sized parameter.
pub fn below_range(effect: &Effect, ci95: &[(Option<f64>, Option<f64>)], share: f64) -> bool {
    if !SIZED.contains(&effect.id()) {
        return false;
    }
    let (Some(info), Some((Some(lo), Some(hi)))) = (effect_info(effect.id()), ci95.first()) else {
        return false;
    };
    let Some(size) = info
        .range
        .first()
        .and_then(|smallest| smallest.params().first().map(|p| p.abs()))
    else {
        return false;
    };
    let bound = share * size;
    bound > 0.0 && lo.abs() < bound && hi.abs() < bound
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A turn-on bias of σ 0.0023 [0.0011, 0.0089] °/s beside a bias instability is
    /// under a tenth of the bottom of its range (σ 0.1 °/s); one whose interval reaches
    /// 0.05 is not; an output step is never sized.
    #[test]
    fn an_interval_under_the_range_is_negligible() {
        let turn_on = Effect::TurnOnBias { sigma_dps: 0.0023 };
        assert!(below_range(&turn_on, &[(Some(0.0011), Some(0.0089))], 0.1));
        assert!(!below_range(&turn_on, &[(Some(0.0011), Some(0.05))], 0.1));
        assert!(!below_range(&turn_on, &[(Some(0.0011), None)], 0.1));
        assert!(below_range(&turn_on, &[(Some(-0.02), Some(0.05))], 1.0));
        let step = Effect::Quantization { lsb_dps: 0.001 };
        assert!(!below_range(&step, &[(Some(0.001), Some(0.001))], 0.1));
    }

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
