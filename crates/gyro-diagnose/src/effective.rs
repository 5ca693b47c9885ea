//! The effective noise on moving data: the noise a filter must assume for this sensor on
//! this motion, measured rather than taken from the model.
//!
//! A sensor's static noise (`gyro-cli noise`, or the rests of a bench run) is what it does
//! standing still. In motion, a filter also sees what no deterministic term explains:
//! the unmodelled part of the dynamic response, vibration, and what the reference itself
//! does not resolve. The usual advice is to inflate the static values "by a factor of 10
//! or more"; this measures the factor. It is the Allan deviation of each run's regression
//! residual (`features::real_features`: the smoothed gyro minus the reference rate,
//! minus the full-band regression on rate, acceleration, jerk, … — the deterministic
//! terms), characterised as `gyro-cli noise` characterises a static log
//! ([`gyro_analysis::noise::characterize`]), from τ = 0.1 s. On periodic motion that Allan
//! deviation is seldom a clean −½ line: the rig's lines and the motion's period leave
//! bounded errors whose Allan deviation falls as 1/τ (on the ssong medium trial the
//! residual's power is 96% at the 40 Hz stepper line). So the angle random walk N is the
//! largest white noise the curve allows at every τ from 1 s (where the convention reads
//! N) to 10 s (a long movement), the fitted rate random walk taken off
//! ([`gyro_analysis::noise::export::white_bound`]): what accumulates into angle over a movement.
//! The rate random walk K and the bias instability B are the fit's, where it resolves
//! them. The residual's own smoothing (the reference derivative's ±h samples) only
//! touches τ of a few samples; the reference's differentiation noise falls off as 1/τ and
//! is small by τ = 1 s. What remains there is what a filter sees as noise: the sensor's
//! own, the unmodelled response, and whatever the reference does not resolve.
//!
//! Measured on the training and the held-out runs separately: on motion of another
//! speed the effective noise differs, and that difference is itself a finding.

use super::ensemble::RealRun;
use super::stats::stretches;
use gyro_analysis::noise::export::{residual_random_walk, white_bound, white_level};
use gyro_analysis::noise::{characterize, Characterization, NoiseOptions, TauGrid};
use serde::Serialize;

/// The effective noise of one set of runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasuredNoise {
    /// Which runs: "training" or "held-out".
    pub runs: &'static str,
    /// Runs measured (those at the first run's sample rate).
    pub run_count: usize,
    /// Residual samples used.
    pub samples: usize,
    /// Angle random walk N (deg/√h): 60 × the largest white noise (deg/s/√Hz) the
    /// residual's Allan deviation (its upper 68% bound) allows from τ = 1 s to 10 s.
    pub arw_deg_per_rt_h: f64,
    /// The white noise the residual reads (deg/√h): 60 × the level its Allan deviation
    /// gives from τ = 1 s to 10 s, an estimate rather than a bound
    /// ([`gyro_analysis::noise::export::white_level`]); what the baseline of runs that never
    /// rest simulates.
    pub white_level_deg_per_rt_h: f64,
    /// Rate random walk K (deg/s/√s), as the filter YAML writes it: the fitted +1/2 line
    /// and a fitted Gauss-Markov bias of correlation time ≥ 3 s read at τ = 3 s, else the
    /// +1/2 line's upper bound.
    pub rate_random_walk_dps_per_rt_s: f64,
    /// K was resolved by the fit (else it is an upper bound).
    pub rate_random_walk_resolved: bool,
    /// Bias instability B (deg/s), 0 when no flat part is resolved.
    pub bias_instability_dps: f64,
    /// The angle random walk N is compared with (deg/√h): the sensor's own, from the
    /// training runs' rests when they have 2 s of them, else the prior model's (or the
    /// `--model` given).
    pub model_arw_deg_per_rt_h: f64,
    /// Where `model_arw_deg_per_rt_h` came from: `"rests"`, `"prior model"` or
    /// `"given model"`.
    pub compared_with: &'static str,
    /// `arw_deg_per_rt_h / model_arw_deg_per_rt_h`: how many times the sensor's own white
    /// noise a filter must assume in this motion.
    pub ratio_to_model: f64,
    /// The whole characterisation (Allan deviation and fit), for the filter YAML.
    #[serde(skip)]
    pub characterization: Characterization,
}

/// The effective noise of the training and held-out runs (either may be missing: runs
/// too short, or no residual).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EffectiveNoise {
    /// On the training runs.
    pub training: Option<MeasuredNoise>,
    /// On the held-out runs.
    pub holdout: Option<MeasuredNoise>,
}

/// The effective noise of `runs` (those at the first run's sample rate), or `None` when
/// their residual has no stretch of `turns.min_stretch_s` or cannot be characterised. Not yet
/// compared with anything ([`MeasuredNoise::compared_to`]).
pub fn measure(
    runs: &[&RealRun],
    label: &'static str,
    settings: &crate::settings::Turns,
) -> Option<MeasuredNoise> {
    let fs = runs.first()?.sample_rate_hz;
    let same_rate: Vec<&&RealRun> = runs.iter().filter(|r| r.sample_rate_hz == fs).collect();
    let residuals: Vec<&[f64]> = same_rate
        .iter()
        .map(|r| r.residual_dps.as_slice())
        .collect();
    let (c, samples) = characterize_residuals(&residuals, fs, settings)?;
    let arw = 60.0 * white_bound(&c)?;
    let level = 60.0 * white_level(&c)?;
    let (k, resolved) = residual_random_walk(&c);
    Some(MeasuredNoise {
        runs: label,
        run_count: same_rate.len(),
        samples,
        arw_deg_per_rt_h: arw,
        white_level_deg_per_rt_h: level,
        rate_random_walk_dps_per_rt_s: k,
        rate_random_walk_resolved: resolved,
        bias_instability_dps: c.fit.bias_instability_dps.value,
        model_arw_deg_per_rt_h: f64::NAN,
        compared_with: "nothing",
        ratio_to_model: f64::NAN,
        characterization: c,
    })
}

/// The Allan characterisation, from τ = `turns.min_tau_s` (below it the residual is
/// shaped by the smoothing both signals share and by the rig's lines), of the finite
/// stretches of at least `turns.min_stretch_s` of `residuals` (regression residuals at `fs` Hz), with the
/// samples used; `None` when no stretch is long enough or it cannot be characterised.
fn characterize_residuals(
    residuals: &[&[f64]],
    fs: f64,
    settings: &crate::settings::Turns,
) -> Option<(Characterization, usize)> {
    let min_len = (settings.min_stretch_s * fs).ceil() as usize;
    let segments: Vec<&[f64]> = residuals
        .iter()
        .flat_map(|residual| {
            stretches(residual.len(), |i| residual[i].is_finite())
                .into_iter()
                .filter(|s| s.len() >= min_len)
                .map(move |s| &residual[s])
        })
        .collect();
    let samples = segments.iter().map(|s| s.len()).sum();
    let longest = segments.iter().map(|s| s.len()).max()?;
    let shortest_m = (settings.min_tau_s * fs).ceil() as usize;
    let options = NoiseOptions {
        taus: TauGrid::Factors(
            TauGrid::default()
                .factors(longest)
                .into_iter()
                .filter(|&m| m >= shortest_m)
                .collect(),
        ),
        ..NoiseOptions::default()
    };
    characterize(&segments, fs, &options)
        .ok()
        .map(|c| (c, samples))
}

impl MeasuredNoise {
    /// The same measurement compared with the sensor's own angle random walk
    /// `model_arw_deg_per_rt_h` (deg/√h), which came from `compared_with`.
    pub fn compared_to(self, model_arw_deg_per_rt_h: f64, compared_with: &'static str) -> Self {
        let ratio = if model_arw_deg_per_rt_h > 0.0 {
            self.arw_deg_per_rt_h / model_arw_deg_per_rt_h
        } else {
            f64::NAN
        };
        Self {
            model_arw_deg_per_rt_h,
            compared_with,
            ratio_to_model: ratio,
            ..self
        }
    }

    /// Whose white noise N is compared with, as the text says it: "the rests'", "the prior
    /// model's", "the given model's".
    pub fn whose(&self) -> String {
        if self.compared_with.ends_with('s') {
            format!("the {}'", self.compared_with)
        } else {
            format!("the {}'s", self.compared_with)
        }
    }

    /// One line: N with its ratio to the sensor's own, K and B where resolved.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "effective angle random walk on the {} runs N = {:.3} deg/sqrt(h) ({:.0}x {} {:.3})",
            self.runs,
            self.arw_deg_per_rt_h,
            self.ratio_to_model,
            self.whose(),
            self.model_arw_deg_per_rt_h
        );
        s.push_str(&format!(
            ", K {} {:.3e} deg/s/sqrt(s)",
            if self.rate_random_walk_resolved {
                "="
            } else {
                "<="
            },
            self.rate_random_walk_dps_per_rt_s
        ));
        if self.bias_instability_dps > 0.0 {
            s.push_str(&format!(", B = {:.3e} deg/s", self.bias_instability_dps));
        }
        s
    }
}
#[cfg(test)]
pub(crate) mod tests {
    #![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
    use super::*;
    use gyro_log::{regularize, GridOptions};
    use gyro_sim::{simulate, Effect, Motion, SensorModel, SimOptions};

    /// Runs of continuous back-and-forth motion (no rest) at 100 Hz from a gyro with
    /// white noise of `arw` deg/√h and `effects`.
    pub(crate) fn moving_runs(arw: f64, effects: &[Effect]) -> Vec<RealRun> {
        let fs = 100.0;
        let model = SensorModel {
            sample_rate_hz: fs,
            arw_deg_per_rt_h: arw,
            ..SensorModel::default().noise_free()
        };
        (0..6u64)
            .map(|i| {
                let angles: Vec<f64> = (0..10_000)
                    .map(|k| {
                        let t = k as f64 / fs;
                        90.0 * (std::f64::consts::TAU * (0.2 + 0.02 * i as f64) * t).sin()
                    })
                    .collect();
                let motion = Motion::from_reference(0.0, 1.0 / fs, &angles, 1);
                let options = SimOptions {
                    seed: 40 + i,
                    ..SimOptions::default()
                };
                let log = simulate(&model, effects, &motion, &options);
                let regular = regularize(&log, &GridOptions::default()).unwrap();
                RealRun::prepare(format!("run {i}"), regular).unwrap()
            })
            .collect()
    }

    /// On moving data alone (no rest), the white noise comes back from what the
    /// deterministic terms leave: within 10% under to 20% over the simulated angle random
    /// walk (the −½ line under the Allan deviation's upper bound), also with
    /// a 15 ms latency and a 1% scale error in the gyro, which the regression takes out.
    #[test]
    fn white_noise_is_measured_on_moving_data() {
        for effects in [
            vec![],
            vec![
                Effect::Latency { delay_s: 0.015 },
                Effect::ScaleFactor { k: 0.01 },
            ],
        ] {
            let runs = moving_runs(6.0, &effects);
            let refs: Vec<&RealRun> = runs.iter().collect();
            let m = measure(&refs, "training", &crate::Settings::DEFAULT.turns)
                .unwrap()
                .compared_to(0.5, "prior model");
            // The −½ line under the upper bounds (68%) of a dozen τ up to 10 s: on 600 s it
            // is near the truth (on 300 s the scatter of the 10 s point pulls it 9% under,
            // on 1200 s it is 1% under).
            assert!(
                (0.9..1.2).contains(&(m.arw_deg_per_rt_h / 6.0)),
                "{effects:?}: {}",
                m.describe()
            );
            // The white level (what a baseline simulates) is the estimate under it.
            assert!(m.white_level_deg_per_rt_h <= m.arw_deg_per_rt_h);
            assert!(
                (0.93..1.07).contains(&(m.white_level_deg_per_rt_h / 6.0)),
                "{effects:?}: {}",
                m.white_level_deg_per_rt_h
            );
            assert!((m.ratio_to_model - m.arw_deg_per_rt_h / 0.5).abs() < 1e-12);
            // No bias wander was simulated: none is resolved.
            assert!(!m.rate_random_walk_resolved, "{}", m.describe());
            assert_eq!(m.run_count, 6);
        }
    }

    /// Runs that never rest give the nominal model the white level of their moving
    /// residual (not its bound, not the prior's), and its note says so; without the measurement it is the
    /// prior's.
    #[test]
    fn runs_without_rest_give_the_baseline_their_moving_noise() {
        let runs = moving_runs(6.0, &[]);
        let refs: Vec<&RealRun> = runs.iter().collect();
        let m = measure(&refs, "training", &crate::Settings::DEFAULT.turns).unwrap();
        let prior = SensorModel::default();
        let super::super::fit::Nominal {
            model,
            notes,
            white_target,
            whiteness,
        } = super::super::fit::nominal_model(
            &refs,
            &prior,
            Some(&m),
            None,
            &crate::Settings::DEFAULT,
        );
        assert!(white_target.is_none(), "these runs do not rest");
        assert!(whiteness.is_none(), "these runs do not rest");
        assert_eq!(model.arw_deg_per_rt_h, m.white_level_deg_per_rt_h);
        assert!((0.93..1.07).contains(&(model.arw_deg_per_rt_h / 6.0)));
        let text = notes.join("\n");
        assert!(text.contains("fitted to the moving residual"), "{text}");
        assert!(text.contains("; its wander: K "), "{text}");
        let super::super::fit::Nominal { model, notes, .. } =
            super::super::fit::nominal_model(&refs, &prior, None, None, &crate::Settings::DEFAULT);
        assert_eq!(model.arw_deg_per_rt_h, prior.arw_deg_per_rt_h);
        assert!(notes.join("\n").contains("from the prior model"));
    }

    /// No residual stretch long enough: nothing measured, rather than a number from
    /// nothing.
    #[test]
    fn no_runs_measure_nothing() {
        assert!(measure(&[], "training", &crate::Settings::DEFAULT.turns).is_none());
    }
}
