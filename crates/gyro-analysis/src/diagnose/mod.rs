//! Sim-to-real diagnosis (DESIGN.md, "Sim-to-real diagnosis"): where a real sensor
//! differs from its simulation, which unmodelled effect causes it, and how far adding the
//! effect closes the gap on runs not used to fit it.
//!
//! Method, fixed before looking at any data:
//! 1. **Baseline**: the nominal model ([`fit::nominal_model`]; or `--model`) re-simulates
//!    every run with its own reference motion and temperatures as an ensemble of
//!    [`Options::members`] seeds; every run, real or simulated, goes through the same
//!    statistics ([`stats`]) and features ([`features`]).
//! 2. **Where**: z-scores of each statistic against the run's ensemble, combined over runs
//!    (Stouffer: Σz/√n); the gap G and its floor ([`score`]).
//! 3. **Which**: every effect of the vocabulary is fitted on the training runs
//!    ([`fit`]); each testable one is added to the nominal model and the held-out runs are
//!    re-simulated with the same seeds ([`Options::candidate_members`] of them). An effect
//!    is significant when its parameter test passes on the training runs, its held-out
//!    ΔBIC is positive and the bootstrap over held-out runs gives P(no improvement) < 5%.
//!    Effects are ranked by held-out gap reduction. When several are significant, each is
//!    dropped in turn from the model holding all of them (leave-one-out); one whose
//!    removal costs nothing significant is redundant: it is confounded with the others
//!    (e.g. a latency next to a bandwidth) and not named. A clock error is measured from
//!    the time stamps against the nominal sample rate ([`ensemble::StampedClock`]); the
//!    regression-based effects are fitted on top of it (on the nominal grid the pipeline
//!    integrates on, a fast clock scales the rate like a scale factor).
//! 4. **How far**: the gap with the selected effects on the training and held-out runs,
//!    and the fraction of the held-out gap closed relative to the floor.

pub mod compensate;
pub mod ensemble;
pub mod features;
pub mod fit;
pub mod score;
pub mod selftest;
pub mod stats;

use ensemble::{ensembles, Member, RealRun};
use fit::{FitInput, Untestable};
use score::{bootstrap_p, gap, score, RunScore};
use serde::Serialize;
use std::collections::BTreeMap;

use crate::model::ModelFile;
use gyro_sim::{Effect, SensorModel};

/// Most effects the forward selection adds.
pub const MAX_EFFECTS: usize = 6;
/// Cosine similarity of two effects' shifts of the held-out z-scores above which one
/// that is not selected is reported as confounded with the selected one.
pub const CONFOUND_COSINE: f64 = 0.8;

/// ΔBIC difference below which two effects count as tied (Kass & Raftery: "not worth
/// more than a bare mention").
pub const TIE_BIC: f64 = 2.0;

/// Settings of a diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Members of the baseline ensemble per run.
    pub members: usize,
    /// Members of each candidate's ensemble per held-out run (the baseline's first seeds).
    pub candidate_members: usize,
    /// Seed of every ensemble.
    pub seed: u64,
    /// Bootstrap resamples over runs.
    pub bootstrap: usize,
    /// The sensor model to start from.
    pub prior: SensorModel,
    /// Use the prior model as it is (`--model`), without fitting the bias and white noise.
    pub fixed_model: bool,
    /// The model file whose pipeline configuration replays the held-out runs, and to
    /// which the corrections are added.
    pub base_model: ModelFile,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            members: 50,
            candidate_members: 20,
            seed: 1,
            bootstrap: 2000,
            prior: SensorModel::default(),
            fixed_model: false,
            base_model: ModelFile::new(gyro_core::Config::default()),
        }
    }
}

/// Why a diagnosis cannot run.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// A run cannot be used.
    #[error("{name}: {message}")]
    Run {
        /// Run name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// Not enough runs.
    #[error("{0}")]
    TooFewRuns(String),
    /// Runs at different sample rates.
    #[error("{0}")]
    MismatchedRates(String),
}

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

/// One candidate effect's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectResult {
    /// Effect id.
    pub id: &'static str,
    /// Fitted parameters by name.
    pub params: BTreeMap<&'static str, f64>,
    /// BIC(nominal) − BIC(nominal + effect) on the held-out runs (positive favours it).
    pub delta_bic: f64,
    /// G of the held-out runs, nominal (the candidate ensemble's seeds).
    pub holdout_gap_before: f64,
    /// G of the held-out runs with this effect added.
    pub holdout_gap_after: f64,
    /// (before − after) / (before − floor); 0 when before is within 10% of the floor
    /// (no gap to close).
    pub fraction_closed: f64,
    /// Named in the verdict.
    pub significant: bool,
    /// 95% intervals of the parameters (null: unbounded).
    pub ci95: BTreeMap<&'static str, [Option<f64>; 2]>,
    /// Parameter test z on the training runs (null where the test is exact).
    pub z: Option<f64>,
    /// The parameter test and its outcome.
    pub test: String,
    /// Bootstrap over held-out runs: P(no likelihood improvement).
    pub bootstrap_p: f64,
    /// Effects it is confounded with (indistinguishable on these runs).
    pub confounded_with: Vec<&'static str>,
}

/// The verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Significant effects, best first.
    pub unmodelled: Vec<&'static str>,
    /// Fraction of the held-out gap closed by them, relative to the floor.
    pub fraction_closed_holdout: f64,
}

/// An untestable effect.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UntestableEntry {
    /// Effect id.
    pub id: &'static str,
    /// Why.
    pub reason: String,
}

/// The whole diagnosis (the JSON contract of DESIGN.md, plus `untestable`, `model` and
/// `runs`).
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
    /// Effects that could not be tested, and why.
    pub untestable: Vec<UntestableEntry>,
    /// The nominal model used, and where its values came from.
    pub model: ModelSummary,
    /// Per run figures.
    pub runs: Vec<RunSummary>,
    /// Angle error with the correctable effects compensated, if any were selected.
    pub compensation: Option<CompensationSummary>,
    /// The model file with those corrections (`--out`).
    #[serde(skip)]
    pub corrected_model: Option<ModelFile>,
}

/// The nominal model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSummary {
    /// The sensor model.
    pub sensor: SensorModel,
    /// Provenance of its values.
    pub notes: Vec<String>,
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
    /// Its z-scores against the nominal ensemble, `(segment/statistic, z)` (for the
    /// report's gap map; not in the JSON).
    #[serde(skip)]
    pub z: Vec<(String, f64)>,
}

/// The pipeline's angle error on the held-out runs without and with the correctable
/// effects compensated (`run --model`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationSummary {
    /// The model file's corrections, as written.
    pub corrected: Vec<&'static str>,
    /// Per held-out run.
    pub runs: Vec<CompensationRun>,
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

/// Progress reports.
pub trait Progress: Sync {
    /// A new stage with `total` steps.
    fn stage(&self, name: &str, total: u64);
    /// One step done.
    fn tick(&self);
}

/// No progress reporting.
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _: &str, _: u64) {}
    fn tick(&self) {}
}

/// Check the runs can be diagnosed together.
pub fn check_runs(train: &[RealRun], holdout: &[RealRun]) -> Result<(), DiagnoseError> {
    if train.len() < 2 {
        return Err(DiagnoseError::TooFewRuns(format!(
            "{} training run(s): at least 2 are needed (3 to test turn-on bias), each a log with reference_deg",
            train.len()
        )));
    }
    if holdout.len() < 2 {
        return Err(DiagnoseError::TooFewRuns(format!(
            "{} held-out run(s): at least 2 are needed to score effects on runs not used to fit them (pass --holdout, or --split-s to cut logs into windows)",
            holdout.len()
        )));
    }
    let first = &train[0];
    for run in train.iter().chain(holdout) {
        let ratio = run.sample_rate_hz / first.sample_rate_hz;
        if (ratio - 1.0).abs() > 1e-3 {
            return Err(DiagnoseError::MismatchedRates(format!(
                "sample rates differ: {} is at {} Hz, {} at {} Hz; diagnose compares runs of one sensor setup (resample, or pass --sample-rate-hz to place all on one grid)",
                first.name, first.sample_rate_hz, run.name, run.sample_rate_hz
            )));
        }
    }
    Ok(())
}

struct Evaluation {
    scores: Vec<RunScore>,
    members: Vec<Vec<Member>>,
}

fn evaluate(
    runs: &[&RealRun],
    ids: &[usize],
    model: &SensorModel,
    effects: &[Effect],
    options: &Options,
    members: usize,
    progress: &dyn Progress,
) -> Evaluation {
    let tick = || progress.tick();
    let ens = ensembles(runs, ids, model, effects, options.seed, members, &tick);
    let scores = runs
        .iter()
        .zip(&ens)
        .map(|(r, m)| score(&r.stats, m))
        .collect();
    Evaluation {
        scores,
        members: ens,
    }
}

/// Baseline scores using only the first `k` members.
fn rescore(runs: &[&RealRun], members: &[Vec<Member>], k: usize) -> Vec<RunScore> {
    runs.iter()
        .zip(members)
        .map(|(r, m)| score(&r.stats, &m[..k.min(m.len())]))
        .collect()
}

fn loglik_diffs(after: &[RunScore], before: &[RunScore]) -> Vec<f64> {
    after
        .iter()
        .zip(before)
        .map(|(a, b)| a.loglik - b.loglik)
        .collect()
}

fn delta_bic(diffs: &[f64], params: usize, observations: usize) -> f64 {
    2.0 * diffs.iter().sum::<f64>() - params as f64 * (observations.max(1) as f64).ln()
}

/// Diagnose `train` against `holdout`.
pub fn diagnose(
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    check_runs(train, holdout)?;
    let train_refs: Vec<&RealRun> = train.iter().collect();
    let hold_refs: Vec<&RealRun> = holdout.iter().collect();
    let train_ids: Vec<usize> = (0..train.len()).collect();
    let hold_ids: Vec<usize> = (train.len()..train.len() + holdout.len()).collect();

    // 1. Baseline.
    let (nominal, notes, white_target) = if options.fixed_model {
        let mut m = options.prior;
        m.sample_rate_hz = train[0].sample_rate_hz;
        (
            m,
            vec!["the --model sensor model as given".to_string()],
            None,
        )
    } else {
        fit::nominal_model(&train_refs, &options.prior)
    };
    let m = options.members.max(4);
    let mc = options.candidate_members.clamp(2, m);
    progress.stage(
        "baseline ensembles",
        (m * (train.len() + holdout.len())) as u64,
    );
    let base_train = evaluate(&train_refs, &train_ids, &nominal, &[], options, m, progress);
    let base_hold = evaluate(&hold_refs, &hold_ids, &nominal, &[], options, m, progress);
    let floor = {
        let all: Vec<Vec<Member>> = base_train
            .members
            .iter()
            .chain(&base_hold.members)
            .cloned()
            .collect();
        score::floor(&all)
    };
    let g_train_before = gap(&base_train.scores);
    let g_hold_before = gap(&base_hold.scores);

    // 2. Where.
    let mut combined: BTreeMap<(String, String), (f64, usize)> = BTreeMap::new();
    for s in base_train.scores.iter().chain(&base_hold.scores) {
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

    // 3. Which: fit on training runs, score on held-out runs.
    let temperature_ok = train.iter().all(|r| r.features.temperature_varies);
    let input = FitInput {
        train: &train_refs,
        null: &base_train.members,
        model: &nominal,
        temperature_ok,
        seed: options.seed,
    };
    let (fits, untestable, joint) = fit::fit_all(&input);
    let before_c = rescore(&hold_refs, &base_hold.members, mc);
    let g_before_c = gap(&before_c);
    let observations: usize = before_c.iter().map(|s| s.count).sum();
    progress.stage(
        "candidate effects on held-out runs",
        (fits.len() * mc * holdout.len()) as u64,
    );
    struct Step {
        gap_before: f64,
        gap_after: f64,
        delta_bic: f64,
        p: f64,
    }
    struct Candidate {
        fit: fit::Fit,
        /// Added alone to the nominal model.
        alone: Step,
        alone_scores: Vec<RunScore>,
        /// Qualified when added alone.
        alone_ok: bool,
        /// Added on top of the effects selected before it (selected effects only).
        added: Option<Step>,
    }
    let step_of = |after: &[RunScore], before: &[RunScore], params: usize, salt: u64| -> Step {
        let diffs = loglik_diffs(after, before);
        Step {
            gap_before: gap(before),
            gap_after: gap(after),
            delta_bic: delta_bic(&diffs, params, observations),
            p: bootstrap_p(&diffs, options.bootstrap, options.seed ^ salt),
        }
    };
    let qualifies = |f: &fit::Fit, st: &Step| -> bool {
        if f.direct {
            f.passes && fit::direct_evidence(&f.effect, &hold_refs, &base_hold.members, &nominal)
        } else {
            f.passes && st.delta_bic > 0.0 && st.p < 0.05
        }
    };
    let eval_set = |set: &[Effect]| -> Vec<RunScore> {
        let set = &joint.effects(set);
        let model = fit::model_with(&nominal, set, white_target);
        if set.iter().all(|e| e.is_neutral(&nominal)) && model == nominal {
            (0..mc * holdout.len()).for_each(|_| progress.tick());
            return before_c.clone();
        }
        evaluate(&hold_refs, &hold_ids, &model, set, options, mc, progress).scores
    };
    let mut candidates: Vec<Candidate> = Vec::new();
    for (i, f) in fits.into_iter().enumerate() {
        let scores = eval_set(&[f.effect]);
        let alone = step_of(&scores, &before_c, f.effect.params().len(), i as u64);
        let alone_ok = qualifies(&f, &alone);
        candidates.push(Candidate {
            fit: f,
            alone,
            alone_scores: scores,
            alone_ok,
            added: None,
        });
    }

    // Forward selection: add the best qualifying effect on top of those already chosen,
    // until none qualifies.
    let mut selected: Vec<usize> = Vec::new();
    let mut current = before_c.clone();
    for step in 0..MAX_EFFECTS {
        let pool: Vec<usize> = (0..candidates.len())
            .filter(|i| !selected.contains(i) && candidates[*i].fit.passes)
            .collect();
        if pool.is_empty() {
            break;
        }
        let mut tried: Vec<(usize, Step, Vec<RunScore>)> = Vec::new();
        if step == 0 {
            for &i in &pool {
                let c = &candidates[i];
                let st = step_of(
                    &c.alone_scores,
                    &current,
                    c.fit.effect.params().len(),
                    i as u64,
                );
                tried.push((i, st, c.alone_scores.clone()));
            }
        } else {
            progress.stage(
                &format!("effects on top of {} selected", selected.len()),
                (pool.len() * mc * holdout.len()) as u64,
            );
            for &i in &pool {
                let mut set: Vec<Effect> =
                    selected.iter().map(|&j| candidates[j].fit.effect).collect();
                set.push(candidates[i].fit.effect);
                let scores = eval_set(&set);
                let st = step_of(
                    &scores,
                    &current,
                    candidates[i].fit.effect.params().len(),
                    (1000 * step + i) as u64,
                );
                tried.push((i, st, scores));
            }
        }
        let mut ok: Vec<(usize, Step, Vec<RunScore>)> = tried
            .into_iter()
            .filter(|(i, st, _)| qualifies(&candidates[*i].fit, st))
            .collect();
        // Best ΔBIC; an earlier effect of the vocabulary (the simpler, more common
        // explanation of a shared signature) is preferred unless the best one is
        // significantly better on the held-out runs (bootstrap of the per-run difference).
        ok.sort_by(|a, b| b.1.delta_bic.total_cmp(&a.1.delta_bic));
        if ok.is_empty() {
            break;
        }
        let lead = ok[0].0;
        let lead_ll = loglik_diffs(&ok[0].2, &current);
        let best = ok
            .iter()
            .filter(|t| {
                let ll = loglik_diffs(&t.2, &current);
                let d: Vec<f64> = lead_ll.iter().zip(&ll).map(|(a, b)| a - b).collect();
                t.0 == lead
                    || ok[0].1.delta_bic - t.1.delta_bic < TIE_BIC
                    || bootstrap_p(&d, options.bootstrap, options.seed ^ 77) > 0.05
            })
            .map(|t| t.0)
            .min()
            .unwrap_or(lead);
        let Some(pos) = ok.iter().position(|t| t.0 == best) else {
            break;
        };
        let (i, st, scores) = ok.swap_remove(pos);
        candidates[i].added = Some(st);
        selected.push(i);
        current = scores;
    }

    // Swaps: a selected effect replaced by another that passed its parameter test, kept
    // when the held-out likelihood improves significantly (greedy selection can take a
    // look-alike first, e.g. a bandwidth for a latency while a scale error is unmodelled).
    if !selected.is_empty() {
        let alternatives: Vec<usize> = (0..candidates.len())
            .filter(|i| {
                !selected.contains(i) && candidates[*i].fit.passes && !candidates[*i].fit.direct
            })
            .collect();
        progress.stage(
            "swaps",
            (selected.len() * alternatives.len() * mc * holdout.len()) as u64,
        );
        for slot in 0..selected.len() {
            for &a in &alternatives {
                if selected.contains(&a) || candidates[selected[slot]].fit.direct {
                    continue;
                }
                let set: Vec<Effect> = selected
                    .iter()
                    .enumerate()
                    .map(|(k, &j)| {
                        if k == slot {
                            candidates[a].fit.effect
                        } else {
                            candidates[j].fit.effect
                        }
                    })
                    .collect();
                let scores = eval_set(&set);
                let diffs = loglik_diffs(&scores, &current);
                let better = diffs.iter().sum::<f64>() > 0.0
                    && bootstrap_p(
                        &diffs,
                        options.bootstrap,
                        options.seed ^ (200_000 + a) as u64,
                    ) < 0.05;
                if better {
                    let out = selected[slot];
                    let st = step_of(
                        &scores,
                        &current,
                        candidates[a].fit.effect.params().len(),
                        (300_000 + a) as u64,
                    );
                    candidates[a].added = Some(st);
                    candidates[out].added = None;
                    selected[slot] = a;
                    current = scores;
                }
            }
        }
    }

    // Leave-one-out: an effect whose removal from the selected set costs nothing
    // significant is redundant given the others.
    let mut dropped: Vec<usize> = Vec::new();
    if selected.len() >= 2 {
        progress.stage(
            "leave-one-out ablations",
            (selected.len() * mc * holdout.len()) as u64,
        );
        for &i in selected.clone().iter().rev() {
            if selected.len() < 2 || candidates[i].fit.direct {
                continue;
            }
            let rest: Vec<Effect> = selected
                .iter()
                .filter(|&&j| j != i)
                .map(|&j| candidates[j].fit.effect)
                .collect();
            let without = eval_set(&rest);
            let st = step_of(
                &current,
                &without,
                candidates[i].fit.effect.params().len(),
                (100_000 + i) as u64,
            );
            if !(st.delta_bic > 0.0 && st.p < 0.05) {
                selected.retain(|&j| j != i);
                candidates[i].added = None;
                dropped.push(i);
                current = without;
            }
        }
    }

    // Confounds: an effect that qualified alone but is not selected, and the selected
    // effect whose signature (the shift it gives the held-out z-scores) is most alike.
    let shift = |scores: &[RunScore]| -> Vec<f64> {
        scores
            .iter()
            .zip(&before_c)
            .flat_map(|(a, b)| {
                a.z.iter().zip(&b.z).map(|((_, za), (_, zb))| {
                    if za.is_finite() && zb.is_finite() {
                        za - zb
                    } else {
                        0.0
                    }
                })
            })
            .collect()
    };
    let cosine = |a: &[f64], b: &[f64]| -> f64 {
        let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
        for (x, y) in a.iter().zip(b) {
            ab += x * y;
            aa += x * x;
            bb += y * y;
        }
        if aa > 0.0 && bb > 0.0 {
            ab / (aa * bb).sqrt()
        } else {
            0.0
        }
    };
    let mut partners: BTreeMap<usize, Vec<&'static str>> = BTreeMap::new();
    for i in 0..candidates.len() {
        if selected.contains(&i) || !candidates[i].alone_ok {
            continue;
        }
        let si = shift(&candidates[i].alone_scores);
        let best = selected
            .iter()
            .map(|&j| (j, cosine(&si, &shift(&candidates[j].alone_scores))))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((j, c)) = best {
            if c > CONFOUND_COSINE || dropped.contains(&i) {
                partners
                    .entry(i)
                    .or_default()
                    .push(candidates[j].fit.effect.id());
                partners
                    .entry(j)
                    .or_default()
                    .push(candidates[i].fit.effect.id());
            }
        }
    }
    let final_scores = current;

    // 4. How far, with the joint fits of the selected effects (as they were scored).
    let alone: Vec<Effect> = selected.iter().map(|&i| candidates[i].fit.effect).collect();
    for (&i, refit) in selected.iter().zip(joint.fits(&alone)) {
        if let Some(f) = refit {
            candidates[i].fit.effect = f.effect;
            candidates[i].fit.ci95 = f.ci95;
        }
    }
    let selected_effects: Vec<Effect> =
        selected.iter().map(|&i| candidates[i].fit.effect).collect();
    let final_model = fit::model_with(&nominal, &selected_effects, white_target);
    let g_hold_after = gap(&final_scores);
    let hold_after_scores = final_scores;
    let (train_after_scores, g_train_after) = if selected.is_empty() {
        (base_train.scores.clone(), g_train_before)
    } else {
        progress.stage("selected model on training runs", (mc * train.len()) as u64);
        let e = evaluate(
            &train_refs,
            &train_ids,
            &final_model,
            &selected_effects,
            options,
            mc,
            progress,
        );
        let g = gap(&e.scores);
        (e.scores, g)
    };
    // No gap above the floor (within 10% of it): nothing to close.
    let closed = |before: f64, after: f64| -> f64 {
        let span = before - floor;
        if span <= 0.1 * floor {
            0.0
        } else {
            (before - after) / span
        }
    };

    let mut effects: Vec<(Option<usize>, EffectResult)> = candidates
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let info = c.fit.effect.info();
            let values = c.fit.effect.params();
            let params = info.params.iter().map(|p| p.name).zip(values).collect();
            let ci95 = info
                .params
                .iter()
                .map(|p| p.name)
                .zip(c.fit.ci95.iter().map(|(a, b)| [*a, *b]))
                .collect();
            let mut with = partners.get(&i).cloned().unwrap_or_default();
            with.sort_unstable();
            with.dedup();
            let st = c.added.as_ref().unwrap_or(&c.alone);
            let order = selected.iter().position(|&j| j == i);
            (
                order,
                EffectResult {
                    id: info.id,
                    params,
                    delta_bic: st.delta_bic,
                    holdout_gap_before: st.gap_before,
                    holdout_gap_after: st.gap_after,
                    fraction_closed: closed(st.gap_before, st.gap_after),
                    significant: order.is_some(),
                    ci95,
                    z: c.fit.z.is_finite().then_some(c.fit.z),
                    test: format!(
                        "{}: {}",
                        c.fit.test,
                        if c.fit.passes {
                            "passes"
                        } else {
                            "does not pass"
                        }
                    ),
                    bootstrap_p: st.p,
                    confounded_with: with,
                },
            )
        })
        .collect();
    // Selected effects in the order they were added, then the rest by held-out gap
    // reduction when added alone.
    effects.sort_by(|(oa, a), (ob, b)| match (oa, ob) {
        (Some(x), Some(y)) => x.cmp(y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => (a.holdout_gap_after - a.holdout_gap_before)
            .total_cmp(&(b.holdout_gap_after - b.holdout_gap_before)),
    });
    let effects: Vec<EffectResult> = effects.into_iter().map(|(_, e)| e).collect();
    let unmodelled: Vec<&'static str> = effects
        .iter()
        .filter(|e| e.significant)
        .map(|e| e.id)
        .collect();

    let runs = train_refs
        .iter()
        .zip(base_train.scores.iter().zip(&train_after_scores))
        .map(|(r, (b, a))| (r, "train", b, a))
        .chain(
            hold_refs
                .iter()
                .zip(before_c.iter().zip(&hold_after_scores))
                .map(|(r, (b, a))| (r, "holdout", b, a)),
        )
        .map(|(r, role, b, a)| RunSummary {
            name: r.name.clone(),
            role,
            duration_s: r.duration_s,
            gap_before: gap(std::slice::from_ref(b)),
            gap_after: gap(std::slice::from_ref(a)),
            z: b.z
                .iter()
                .map(|(s, z)| (format!("{}/{}", s.segment, s.statistic), *z))
                .collect(),
        })
        .collect();

    let (corrected, ids) = compensate::corrected_model(&options.base_model, &selected_effects);
    let (compensation, corrected_model) = if ids.is_empty() {
        (None, None)
    } else {
        progress.stage("compensated replays of held-out runs", 0);
        let summary = compensate::score(holdout, &options.base_model, &corrected, ids);
        (Some(summary), Some(corrected))
    };

    Ok(Diagnosis {
        gap: GapSummary {
            train_before: g_train_before,
            train_after: g_train_after,
            holdout_before: g_hold_before,
            holdout_after: g_hold_after,
            floor,
        },
        r#where,
        effects,
        verdict: Verdict {
            unmodelled,
            fraction_closed_holdout: closed(g_before_c, g_hold_after),
        },
        untestable: untestable
            .into_iter()
            .map(|Untestable { id, reason }| UntestableEntry { id, reason })
            .collect(),
        model: ModelSummary {
            sensor: nominal,
            notes,
            effects: selected_effects,
        },
        runs,
        compensation,
        corrected_model,
    })
}
