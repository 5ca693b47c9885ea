//! Injection–recovery self-check: simulated "real" runs with effects the nominal model
//! lacks, diagnosed blind by the same code, scored against what was injected.
//!
//! Cases: every effect alone at [`magnitudes`] (a realistic size for a low-cost MEMS
//! gyro on a torque-wrench bench, stated in the output), the physical variants of
//! [`VARIANTS`] alone (a gyro ahead of its reference), the pairs of [`PAIRS`],
//! [`NULL_CASES`] runs with nothing injected, and the clocks of [`CLOCK_VARIANTS`] alone
//! (stamped by the sensor's count, −2.5% and +2%). Each case has [`TRAIN_RUNS`] training and
//! [`HOLDOUT_RUNS`] held-out runs of [`RUN_S`] s of bench-like motion at 1 kHz with a
//! 5 °C warm-up, each run its own motion and noise seeds (derived from the case seed).
//!
//! Scoring: **top-1** is the first effect of the ranked list when it is significant
//! (strict: the injected id; by confound group: an effect the diagnosis reports as
//! confounded with it, or one of the structurally identical pairs of [`CONFOUND_GROUPS`]);
//! **pairs**: both injected ids among the significant effects; **null**: no significant
//! effect; **coverage**: each injected parameter inside the 95% interval of its fit;
//! **fraction closed**: the verdict's held-out fraction.

use super::ensemble::RealRun;
use super::{diagnose, Diagnosis, Options, Silent};
use gyro_analysis::seed::derive_seed;
use gyro_log::{regularize, GridOptions};
use gyro_sim::{simulate, BenchProfile, Effect, Motion, SimOptions, EFFECTS};
use serde::Serialize;

/// Training runs per case.
pub const TRAIN_RUNS: usize = 5;
/// Held-out runs per case.
pub const HOLDOUT_RUNS: usize = 5;
/// Run length (s).
pub const RUN_S: f64 = 60.0;
/// Cases with nothing injected.
pub const NULL_CASES: usize = 7;
/// Variants of an effect injected alone besides its self-test magnitude: a gyro ahead of
/// its reference.
pub const VARIANTS: [Effect; 1] = [Effect::Latency { delay_s: -0.005 }];
/// Sample clocks stamped by the sensor's count near the ends of a MEMS internal
/// oscillator's ±1–3% (MPU-6050, BMI160 datasheets), whose lag grows by a second and more
/// over a run; planned after the null cases, so the earlier cases keep their seeds.
pub const CLOCK_VARIANTS: [Effect; 2] = [
    Effect::ClockErrorCountStamped { ppm: -25_000.0 },
    Effect::ClockErrorCountStamped { ppm: 20_000.0 },
];
/// Effects injected together.
pub const PAIRS: [(&str, &str); 9] = [
    ("scale_factor", "latency"),
    ("scale_asymmetry", "temperature_bias"),
    ("nonlinearity", "turn_on_bias"),
    ("quantization", "latency"),
    ("temperature_scale", "bias_instability"),
    ("saturation", "dropouts"),
    ("rate_random_walk", "scale_factor"),
    ("clock_error_count_stamped", "turn_on_bias"),
    ("vibration", "nonlinearity_even"),
];
/// Effects whose simulator terms leave nearly the same signature (a two-pole sensor
/// bandwidth delays slow hand motion like a pure latency; only the second-order term
/// differs). Clock error and scale factor are told apart by the time stamps.
pub const CONFOUND_GROUPS: [(&str, &str); 1] = [("latency", "bandwidth")];

/// The magnitudes injected by the self-check.
pub fn magnitudes() -> Vec<Effect> {
    EFFECTS.iter().map(|info| info.self_test).collect()
}

fn magnitude(id: &str) -> Option<Effect> {
    magnitudes().into_iter().find(|e| e.id() == id)
}

/// One case's outcome.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseResult {
    /// "single", "pair" or "null".
    pub kind: &'static str,
    /// Injected effects.
    pub injected: Vec<Effect>,
    /// Significant effects named, best first.
    pub named: Vec<&'static str>,
    /// Top-1 correct, strict id.
    pub top1_strict: bool,
    /// Top-1 correct up to a confound group.
    pub top1_group: bool,
    /// Every injected effect named (strict ids; pairs and singles).
    pub all_named: bool,
    /// Every injected effect named up to confound groups.
    pub all_named_group: bool,
    /// Per injected parameter: inside its 95% interval.
    pub covered: Vec<(String, bool)>,
    /// The verdict's held-out fraction closed.
    pub fraction_closed: f64,
    /// Held-out gap before and after.
    pub holdout_gap: (f64, f64),
    /// The selected model leaves no statistic of the training runs unexplained.
    pub model_fits: bool,
    /// The statistics it leaves unexplained (`segment/statistic`), largest |z| first.
    pub unexplained: Vec<String>,
    /// The diagnosis's table of effects (why an effect was or was not named).
    pub effects: Vec<super::EffectResult>,
    /// Named effects that explain none of the injected ones (up to confound groups).
    pub extra: Vec<&'static str>,
    /// In a matrix case: the injected magnitude's index in its effect's range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub magnitude_index: Option<usize>,
}

/// The self-check's summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelfTest {
    /// Seed of the cases.
    pub seed: u64,
    /// Injected magnitudes.
    pub magnitudes: Vec<Effect>,
    /// Every case.
    pub cases: Vec<CaseResult>,
    /// Top-1 accuracy over single-effect cases (strict id).
    pub top1_strict: f64,
    /// Top-1 accuracy over single-effect cases, confound groups counted as one.
    pub top1_group: f64,
    /// Pairs with both effects named (strict ids).
    pub pairs_both_named: f64,
    /// Pairs with both named up to confound groups.
    pub pairs_both_named_group: f64,
    /// Null cases with no significant effect.
    pub null_clean: f64,
    /// Injected parameters inside their 95% interval.
    pub coverage: f64,
    /// Mean held-out fraction of the gap closed over cases with effects.
    pub mean_fraction_closed: f64,
    /// Cases whose selected model leaves nothing unexplained on the training runs.
    pub model_fits: f64,
    /// Confusion matrix: (injected id, top-1 named or "none", count), single cases.
    pub confusion: Vec<(String, String, usize)>,
    /// The matrix plan's cells, effect by effect, smallest magnitude first (empty for
    /// the standard plan).
    pub matrix: Vec<MatrixCell>,
    /// Per effect of the matrix: its detection limit on these runs.
    pub detection_limits: Vec<DetectionLimit>,
}

/// Share of a matrix cell's cases named first for its magnitude to count as detected: the
/// definition of the detection limit the self-check reports (the smallest magnitude named
/// first in at least 90% of its cases), not a setting of any diagnosis.
pub const DETECTED_SHARE: f64 = 0.9;

/// One effect at one magnitude of the matrix, over its repeats.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MatrixCell {
    /// The effect id.
    pub effect: &'static str,
    /// Index in the effect's range.
    pub index: usize,
    /// The injected effect.
    pub magnitude: Effect,
    /// Cases (repeats).
    pub cases: usize,
    /// Cases whose first named effect is it (confound groups counted as one).
    pub named_first: usize,
    /// Cases that name nothing it does not explain.
    pub nothing_extra: usize,
    /// Its parameters inside their 95% interval, of those fitted.
    pub covered: (usize, usize),
    /// Median held-out gap G before and after the selected effects (1: as close as
    /// the floor allows).
    pub holdout_gap: (f64, f64),
}

/// The smallest magnitude from which up every magnitude of an effect's range is named
/// first in at least [`DETECTED_SHARE`] of its cases.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DetectionLimit {
    /// The effect id.
    pub effect: &'static str,
    /// That magnitude (`None`: not even the top of the range is).
    pub limit: Option<Effect>,
    /// Its index in the range.
    pub index: Option<usize>,
}

fn matrix_of(cases: &[CaseResult]) -> (Vec<MatrixCell>, Vec<DetectionLimit>) {
    let mut cells: Vec<MatrixCell> = Vec::new();
    for c in cases {
        let (Some(index), Some(e)) = (c.magnitude_index, c.injected.first()) else {
            continue;
        };
        let pos = match cells
            .iter()
            .position(|x| x.effect == e.id() && x.index == index)
        {
            Some(p) => p,
            None => {
                cells.push(MatrixCell {
                    effect: e.id(),
                    index,
                    magnitude: *e,
                    cases: 0,
                    named_first: 0,
                    nothing_extra: 0,
                    covered: (0, 0),
                    holdout_gap: (f64::NAN, f64::NAN),
                });
                cells.len() - 1
            }
        };
        let cell = &mut cells[pos];
        cell.cases += 1;
        cell.named_first += usize::from(c.top1_group);
        cell.nothing_extra += usize::from(c.extra.is_empty());
        cell.covered.0 += c.covered.iter().filter(|x| x.1).count();
        cell.covered.1 += c.covered.len();
    }
    for cell in &mut cells {
        let gaps = |f: fn(&CaseResult) -> f64| {
            let v: Vec<f64> = cases
                .iter()
                .filter(|c| {
                    c.magnitude_index == Some(cell.index)
                        && c.injected.first().is_some_and(|e| e.id() == cell.effect)
                })
                .map(f)
                .collect();
            gyro_analysis::median(&v).unwrap_or(f64::NAN)
        };
        cell.holdout_gap = (gaps(|c| c.holdout_gap.0), gaps(|c| c.holdout_gap.1));
    }
    let mut limits = Vec::new();
    for info in EFFECTS {
        let mine: Vec<&MatrixCell> = cells.iter().filter(|c| c.effect == info.id).collect();
        if mine.is_empty() {
            continue;
        }
        let detected = |c: &MatrixCell| c.named_first as f64 >= DETECTED_SHARE * c.cases as f64;
        // From the top of the range down, while every magnitude is detected.
        let mut index = None;
        for m in (0..info.range.len()).rev() {
            match mine.iter().find(|c| c.index == m) {
                Some(c) if detected(c) => index = Some(m),
                _ => break,
            }
        }
        limits.push(DetectionLimit {
            effect: info.id,
            limit: index.map(|m| info.range[m]),
            index,
        });
    }
    (cells, limits)
}

fn same_group(a: &str, b: &str) -> bool {
    a == b
        || CONFOUND_GROUPS
            .iter()
            .any(|&(x, y)| (a == x && b == y) || (a == y && b == x))
}

/// Simulate the runs of a case.
pub fn case_runs(effects: &[Effect], seed: u64) -> (Vec<RealRun>, Vec<RealRun>) {
    let model = crate::default_prior();
    let profile = BenchProfile {
        duration_s: RUN_S,
        ..BenchProfile::default()
    };
    let make = |i: usize| -> Option<RealRun> {
        let motion = Motion::bench(&profile, derive_seed(seed, "case run motion", i as u64));
        let options = SimOptions {
            seed: derive_seed(seed, "case run sensor", i as u64),
            ..SimOptions::default()
        };
        let log = simulate(&model, effects, &motion, &options);
        let regular = regularize(&log, &GridOptions::default()).ok()?;
        RealRun::prepare(format!("case-run-{i}"), regular).ok()
    };
    let train = (0..TRAIN_RUNS).filter_map(make).collect();
    let holdout = (TRAIN_RUNS..TRAIN_RUNS + HOLDOUT_RUNS)
        .filter_map(make)
        .collect();
    (train, holdout)
}

fn score_case(kind: &'static str, injected: Vec<Effect>, d: &Diagnosis) -> CaseResult {
    let named: Vec<&'static str> = d.verdict.unmodelled.clone();
    let top = d.effects.first().filter(|e| e.significant);
    let confounded_ok = |truth: &str, got: &str| {
        same_group(truth, got)
            || d.effects
                .iter()
                .find(|e| e.id == got)
                .is_some_and(|e| e.confounded_with.contains(&truth))
    };
    let (top1_strict, top1_group) = match (injected.first(), top) {
        (Some(t), Some(e)) => (
            t.id() == e.id,
            injected.iter().any(|t| confounded_ok(t.id(), e.id)),
        ),
        (None, None) => (true, true),
        _ => (false, false),
    };
    let all_named = injected.iter().all(|t| named.contains(&t.id()));
    let all_named_group = injected
        .iter()
        .all(|t| named.iter().any(|n| confounded_ok(t.id(), n)));
    let mut covered = Vec::new();
    for t in &injected {
        if let Some(e) = d.effects.iter().find(|e| e.id == t.id()) {
            for (spec, value) in t.info().params.iter().zip(t.params()) {
                let name = spec.name;
                if let Some([lo, hi]) = e.ci95.get(name) {
                    let inside = lo.is_none_or(|l| value >= l) && hi.is_none_or(|h| value <= h);
                    covered.push((format!("{}.{name}", t.id()), inside));
                }
            }
        }
    }
    let extra = named
        .iter()
        .copied()
        .filter(|n| !injected.iter().any(|t| confounded_ok(t.id(), n)))
        .collect();
    CaseResult {
        kind,
        injected,
        named,
        top1_strict,
        top1_group,
        all_named,
        all_named_group,
        covered,
        fraction_closed: d.verdict.fraction_closed_holdout,
        holdout_gap: (d.gap.holdout_before, d.gap.holdout_after),
        model_fits: d.verdict.model_fits,
        unexplained: d
            .unexplained
            .iter()
            .map(|u| format!("{}/{}", u.segment, u.statistic))
            .collect(),
        effects: d.effects.clone(),
        extra,
        magnitude_index: None,
    }
}

/// Which cases the self-check runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plan {
    /// Every effect alone at its self-test magnitude, [`VARIANTS`], [`PAIRS`],
    /// [`NULL_CASES`] and [`CLOCK_VARIANTS`].
    Standard,
    /// Every effect alone at each magnitude of its realistic range (`EffectInfo::range`),
    /// each `repeats` times with its own seeds, then [`PAIRS`] and [`NULL_CASES`].
    Matrix {
        /// Seeds per effect and magnitude.
        repeats: usize,
    },
}

/// One planned case: kind, injected effects, and for a matrix case its effect's
/// magnitude index in `EffectInfo::range`.
type Planned = (&'static str, Vec<Effect>, Option<usize>);

fn plan_of(plan: Plan) -> (Vec<Planned>, &'static str) {
    let mut cases: Vec<Planned> = Vec::new();
    match plan {
        Plan::Standard => {
            for e in magnitudes().into_iter().chain(VARIANTS) {
                cases.push(("single", vec![e], None));
            }
        }
        Plan::Matrix { repeats } => {
            for info in EFFECTS {
                for (m, e) in info.range.iter().enumerate() {
                    for _ in 0..repeats {
                        cases.push(("single", vec![*e], Some(m)));
                    }
                }
            }
        }
    }
    for (a, b) in PAIRS {
        if let (Some(a), Some(b)) = (magnitude(a), magnitude(b)) {
            cases.push(("pair", vec![a, b], None));
        }
    }
    for _ in 0..NULL_CASES {
        cases.push(("null", Vec::new(), None));
    }
    match plan {
        Plan::Standard => {
            for e in CLOCK_VARIANTS {
                cases.push(("single", vec![e], None));
            }
            (cases, "self-test case")
        }
        // The matrix's cases draw from seeds of their own: none is a standard case again.
        Plan::Matrix { .. } => (cases, "self-test matrix case"),
    }
}

/// Diagnose each case of `plan` (only those injecting `only`, or the null cases for
/// `none`, when given) on runs simulated from its own seed, and score the diagnosis;
/// `progress` is told each case as it starts.
fn run_cases(
    seed: u64,
    plan: Plan,
    only: Option<&str>,
    options: &Options,
    progress: &dyn Fn(usize, usize, &str),
) -> Result<Vec<CaseResult>, super::DiagnoseError> {
    let (planned, seed_label) = plan_of(plan);
    // Case seeds follow the position in the whole plan, so a case run alone is the same.
    let planned: Vec<(usize, Planned)> = planned
        .into_iter()
        .enumerate()
        .filter(|(_, (_, effects, _))| match only {
            None => true,
            Some("none") => effects.is_empty(),
            Some(id) => effects.iter().any(|e| e.id() == id),
        })
        .collect();
    let total = planned.len();
    let mut cases = Vec::new();
    for (n, (k, (kind, effects, magnitude_index))) in planned.into_iter().enumerate() {
        let label = if effects.is_empty() {
            "none".to_string()
        } else {
            effects
                .iter()
                .map(Effect::spec)
                .collect::<Vec<_>>()
                .join(" + ")
        };
        progress(n, total, &label);
        let case_seed = derive_seed(seed, seed_label, k as u64);
        let (train, holdout) = case_runs(&effects, case_seed);
        let options = Options {
            seed: derive_seed(case_seed, "diagnosis", 0),
            ..options.clone()
        };
        let d = diagnose(&train, &holdout, &options, &Silent)?;
        let mut case = score_case(kind, effects, &d);
        case.magnitude_index = magnitude_index;
        cases.push(case);
    }
    Ok(cases)
}

/// The confusion of the single-effect cases: (injected, named first, how many cases), in
/// the order the pairs first occur ("none" where nothing was named).
fn confusion_of(cases: &[CaseResult]) -> Vec<(String, String, usize)> {
    let mut confusion: Vec<(String, String, usize)> = Vec::new();
    for c in cases.iter().filter(|c| c.kind == "single") {
        let truth = c.injected.first().map_or("none", |e| e.id()).to_string();
        let got = c.named.first().copied().unwrap_or("none").to_string();
        match confusion.iter_mut().find(|x| x.0 == truth && x.1 == got) {
            Some(x) => x.2 += 1,
            None => confusion.push((truth, got, 1)),
        }
    }
    confusion
}

/// Run the self-check (only the cases injecting `only`, or the null cases for `none`,
/// when given); `progress` is told each case as it starts.
pub fn run(
    seed: u64,
    plan: Plan,
    only: Option<&str>,
    options: &Options,
    progress: &dyn Fn(usize, usize, &str),
) -> Result<SelfTest, super::DiagnoseError> {
    let cases = run_cases(seed, plan, only, options, progress)?;
    let frac = |f: &dyn Fn(&CaseResult) -> Option<bool>| -> f64 {
        let v: Vec<bool> = cases.iter().filter_map(f).collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().filter(|b| **b).count() as f64 / v.len() as f64
        }
    };
    let top1_strict = frac(&|c| (c.kind == "single").then_some(c.top1_strict));
    let top1_group = frac(&|c| (c.kind == "single").then_some(c.top1_group));
    let pairs_both_named = frac(&|c| (c.kind == "pair").then_some(c.all_named));
    let pairs_both_named_group = frac(&|c| (c.kind == "pair").then_some(c.all_named_group));
    let null_clean = frac(&|c| (c.kind == "null").then_some(c.named.is_empty()));
    let model_fits = frac(&|c| Some(c.model_fits));
    let all_cov: Vec<bool> = cases
        .iter()
        .flat_map(|c| c.covered.iter().map(|x| x.1))
        .collect();
    let coverage = if all_cov.is_empty() {
        f64::NAN
    } else {
        all_cov.iter().filter(|b| **b).count() as f64 / all_cov.len() as f64
    };
    let closed: Vec<f64> = cases
        .iter()
        .filter(|c| c.kind != "null")
        .map(|c| c.fraction_closed)
        .collect();
    let mean_fraction_closed = closed.iter().sum::<f64>() / closed.len().max(1) as f64;
    let confusion = confusion_of(&cases);
    let (matrix, detection_limits) = matrix_of(&cases);
    Ok(SelfTest {
        seed,
        magnitudes: match plan {
            Plan::Standard => magnitudes(),
            Plan::Matrix { .. } => EFFECTS
                .iter()
                .flat_map(|i| i.range.iter().copied())
                .collect(),
        },
        cases,
        top1_strict,
        top1_group,
        pairs_both_named,
        pairs_both_named_group,
        null_clean,
        coverage,
        mean_fraction_closed,
        model_fits,
        confusion,
        matrix,
        detection_limits,
    })
}
