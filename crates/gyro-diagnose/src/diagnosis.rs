//! The diagnosis: the JSON contract of `diagnose --format json`, plus what the report
//! and `--out` need (not serialised).

use gyro_analysis::model::ModelFile;
use gyro_sim::{Effect, SensorModel};
use serde::Serialize;
use std::collections::BTreeMap;

/// The gap figures of the JSON contract.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapSummary {
    /// G of the training runs, nominal model.
    pub train_before: f64,
    /// G of the training runs, with the selected effects.
    pub train_after: f64,
    /// G of the held-out runs, nominal model.
    pub holdout_before: f64,
    /// G of the held-out runs, with the selected effects.
    pub holdout_after: f64,
    /// G between independent simulated ensembles.
    pub floor: f64,
}

/// One "where" entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Where {
    /// Segment or stratum.
    pub segment: String,
    /// Statistic.
    pub statistic: String,
    /// Combined z over all runs (Σz/√n).
    pub z: f64,
}

/// A statistic the selected model leaves unexplained on the training runs (combined
/// |z| at least `UNEXPLAINED_Z`): what no effect of the vocabulary, as selected, brings
/// to its simulated ensemble. Means are over the runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Unexplained {
    /// Segment or stratum.
    pub segment: String,
    /// Statistic.
    pub statistic: String,
    /// The real runs' value (mean over the training runs).
    pub real: f64,
    /// The nominal model's simulated value (mean of the ensembles' means).
    pub nominal: f64,
    /// The selected model's simulated value (mean of the ensembles' means).
    pub simulated: f64,
    /// Combined z over the training runs with the selected model (Σz/√n).
    pub z_train: f64,
    /// Combined z over the training runs with the nominal model.
    pub z_train_nominal: f64,
    /// Combined z over the held-out runs with the selected model.
    pub z_holdout: f64,
}

/// One candidate effect's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectResult {
    /// Effect id.
    pub id: &'static str,
    /// Fitted parameters by name.
    pub params: BTreeMap<&'static str, f64>,
    /// BIC(nominal) − BIC(nominal + effect) on the held-out runs (positive favours it);
    /// null when the effect was not scored on the held-out runs (its parameter test does
    /// not pass on the training runs, so it can never be named; `--score-every-candidate`
    /// scores it anyway). The same for the other held-out figures.
    pub delta_bic: Option<f64>,
    /// G of the held-out runs, nominal (the candidate ensemble's seeds).
    pub holdout_gap_before: f64,
    /// G of the held-out runs with this effect added.
    pub holdout_gap_after: Option<f64>,
    /// (before − after) / (before − floor); 0 when before is within 10% of the floor
    /// (no gap to close).
    pub fraction_closed: Option<f64>,
    /// Named in the verdict.
    pub significant: bool,
    /// 95% intervals of the parameters (null: unbounded).
    pub ci95: BTreeMap<&'static str, [Option<f64>; 2]>,
    /// Parameter test z on the training runs (null where the test is exact).
    pub z: Option<f64>,
    /// The parameter test read on the held-out runs, in the direction of `z`: a
    /// regression effect's coefficient, a wander's Allan-variance excess (null for the
    /// other effects).
    pub holdout_z: Option<f64>,
    /// A bias wander's shape evidence: the log-likelihood of the residual's Allan
    /// variances at 1, 4 and 16 s over the training and the held-out runs under the
    /// wander as fitted; of two look-alike wanders that qualify, the larger is named
    /// (null for the other effects and for a wander whose test does not pass).
    pub shape_loglik: Option<f64>,
    /// The parameter test and its outcome.
    pub test: String,
    /// Bootstrap over held-out runs: P(no likelihood improvement).
    pub bootstrap_p: Option<f64>,
    /// Effects it is confounded with (indistinguishable on these runs).
    pub confounded_with: Vec<&'static str>,
    /// The posterior check on its signature statistics (see
    /// [`super::posterior`]): with the named set for a named effect, alone otherwise
    /// (null when not scored on the held-out runs). An effect that fails it is not named.
    pub posterior_check: Option<super::posterior::PosteriorCheck>,
}

/// The verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Significant effects, best first.
    pub unmodelled: Vec<&'static str>,
    /// Fraction of the held-out gap closed by them, relative to the floor.
    pub fraction_closed_holdout: f64,
    /// The selected model explains every statistic of the training runs (no entry in
    /// `unexplained`): only then does it fit the sensor at hand.
    pub model_fits: bool,
}

/// An untestable effect.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UntestableEntry {
    /// Effect id.
    pub id: &'static str,
    /// Why.
    pub reason: String,
}

/// The whole diagnosis (the JSON contract, with `untestable`, `model` and `runs`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Gap figures.
    pub gap: GapSummary,
    /// Statistics by |z|, largest first.
    pub r#where: Vec<Where>,
    /// Candidate effects, best first.
    pub effects: Vec<EffectResult>,
    /// Verdict.
    pub verdict: Verdict,
    /// The statistics the selected model leaves unexplained on the training runs,
    /// largest |z| first (empty when the model fits).
    pub unexplained: Vec<Unexplained>,
    /// Effects that could not be tested, and why.
    pub untestable: Vec<UntestableEntry>,
    /// The effects not named, each with the smallest size runs like the self-check's
    /// show of it ([`super::detection`]): not named means smaller than that, or absent.
    pub not_seen: Vec<super::detection::NotSeen>,
    /// The nominal model used, and where its values came from.
    pub model: ModelSummary,
    /// Per run figures.
    pub runs: Vec<RunSummary>,
    /// Angle error with the correctable effects compensated, if any were selected.
    pub compensation: Option<CompensationSummary>,
    /// What makes the whole diagnosis meaningless, one sentence each: a reference that
    /// turns against the gyro, or by more than a factor of two, on some runs
    /// ([`gyro_log::sense`]); left out when empty. The headline leads with them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reference_warnings: Vec<String>,
    /// Why a named effect may be a look-alike of another cause, one sentence each (a
    /// latency beside rests whose noise is low-passed); left out when empty. The verdict
    /// says them right after what it names.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub doubts: Vec<String>,
    /// What makes part of the diagnosis unreliable, one sentence each (e.g. a gyro–reference
    /// lag beyond the cross-correlation's search); left out when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The effective noise on moving data, measured from the regression residual of the
    /// training and of the held-out runs ([`super::effective`]).
    pub effective_noise: super::effective::EffectiveNoise,
    /// Lines in the motion itself (the reference rate), training and held-out runs.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub motion_lines: Vec<super::line::MotionLine>,
    /// What the movements show rest to rest (lag searched wide, scale of the turns,
    /// movements the reference does not follow), when the training runs have turns
    /// ([`super::turns`]); left out otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub turns: Option<super::turns::TurnEvidence>,
    /// What was read of each log and what was irregular in it (filled in by the caller,
    /// which read the logs; empty for the self-check's simulated runs).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<InputEntry>,
    /// The model file with those corrections (`--out`).
    #[serde(skip)]
    pub corrected_model: Option<ModelFile>,
    /// The sensor model simulated with the selected effects (the nominal one, with the
    /// white noise matched again under an extra output rounding); for the report.
    #[serde(skip)]
    pub selected_sensor: SensorModel,
}

impl Diagnosis {
    /// Why the residual-based figures (the effective noise, the where-statistics) say
    /// little about the sensor here, when they do: a reference that lags or leads the
    /// gyro beyond the per-sample statistics' reach makes the residual during turns the
    /// rate times the lag ([`super::turns`]), and so does a lag that grows with a named
    /// count-stamped clock. `None` otherwise.
    pub fn residual_caveat(&self) -> Option<String> {
        let clock_ppm = self.model.effects.iter().find_map(|e| match e {
            gyro_sim::Effect::ClockErrorCountStamped { ppm } => Some(*ppm),
            _ => None,
        });
        if let Some(ppm) = clock_ppm {
            return Some(format!(
                "the gyro's lag grows through each run with its clock ({:.0} ms each minute): this residual holds the rate times that lag, above the sensor's own noise",
                ppm.abs() * 1e-6 * 6e4
            ));
        }
        let lag = self.turns.as_ref()?.lag.as_ref()?;
        lag.beyond_statistic.then(|| {
            format!(
                "the reference is {:.0} ms {} the gyro, beyond the per-sample statistics' reach: this residual is mostly the rate times that lag, far above the sensor's own noise",
                1e3 * lag.median_s.abs(),
                if lag.median_s >= 0.0 { "ahead of" } else { "behind" }
            )
        })
    }
}

/// One log's input-quality report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputEntry {
    /// The log as named on the command line.
    pub file: String,
    /// What was read and what was irregular ([`gyro_log::Quality`]).
    pub input: gyro_log::Quality,
}

/// The nominal model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSummary {
    /// The sensor model.
    pub sensor: SensorModel,
    /// Provenance of its values.
    pub notes: Vec<String>,
    /// Whether the training runs' rest noise is white (the first differences against
    /// the Allan variance at a short τ); absent without enough rest or with `--model`.
    pub rest_noise: Option<super::fit::RestWhiteness>,
    /// The selected effects with their parameters.
    pub effects: Vec<Effect>,
}

/// One run's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunSummary {
    /// Name.
    pub name: String,
    /// Training or held-out.
    pub role: &'static str,
    /// Duration (s).
    pub duration_s: f64,
    /// G of this run, nominal.
    pub gap_before: f64,
    /// G of this run with the selected effects.
    pub gap_after: f64,
    /// The grid its reference lies on, when quantised (an encoder's counts or a print's
    /// decimals), and the smoothing its re-simulated rate takes; left out otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_grid: Option<super::ReferenceGrid>,
    /// Its z-scores against the nominal ensemble, `(segment/statistic, z)` (for the
    /// report's gap map; not in the JSON).
    #[serde(skip)]
    pub z: Vec<(String, f64)>,
}

/// The pipeline's angle error on the held-out runs without and with the correctable
/// effects compensated (`run --model`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationSummary {
    /// The model file's corrections, as written: each lowered the held-out angle error
    /// on top of those before it (paired over the held-out runs, bootstrap P < 5%).
    pub corrected: Vec<&'static str>,
    /// Named correctable effects whose correction did not lower the held-out angle
    /// error: named, not corrected, with what the correction did.
    pub not_corrected: Vec<NotCorrected>,
    /// Per held-out run, without and with the written corrections.
    pub runs: Vec<CompensationRun>,
}

/// A named effect whose correction is not written.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotCorrected {
    /// Effect id.
    pub id: &'static str,
    /// Median over held-out runs of the max abs angle error without this correction
    /// (with those written before it) (deg).
    pub median_max_abs_error_without_deg: f64,
    /// The same with it (deg).
    pub median_max_abs_error_with_deg: f64,
    /// Held-out runs it made better.
    pub runs_better: usize,
    /// Held-out runs scored.
    pub runs: usize,
    /// Bootstrap over held-out runs: P(no lower total max abs error).
    pub bootstrap_p: f64,
    /// Why it is not written whatever the held-out runs say, if so
    /// ([`super::compensate::SCALE_FROM_TURNS`]); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<&'static str>,
}

/// One run's angle error without and with compensation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationRun {
    /// Run name.
    pub name: String,
    /// Max abs angle error of `run` with the nominal configuration (deg).
    pub max_abs_error_before_deg: f64,
    /// Max abs angle error of `run --model` with the corrections (deg).
    pub max_abs_error_after_deg: f64,
}
