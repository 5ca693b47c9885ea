//! The diagnosis and the self-check as text (`gyro-cli diagnose`'s table).

use gyro_diagnose::{selftest, Diagnosis};
use std::fmt::Write as _;

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.0}%", 100.0 * x)
    } else {
        "-".into()
    }
}

/// The self-check's summary as text.
pub fn self_test_table(t: &selftest::SelfTest) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "injection-recovery self-test, seed {}: {} training + {} held-out runs of {} s at 1 kHz per case",
        t.seed,
        selftest::TRAIN_RUNS,
        selftest::HOLDOUT_RUNS,
        selftest::RUN_S
    );
    matrix_table(&mut s, t);
    let _ = writeln!(s, "injected magnitudes:");
    for e in &t.magnitudes {
        let _ = writeln!(s, "  {}", serde_json::to_string(e).unwrap_or_default());
    }
    cases_table(&mut s, t);
    scores_table(&mut s, t);
    s
}

/// The self-check's cases, one line each: what was injected and named, the held-out gap
/// before and after, the coverage of the intervals.
fn cases_table(s: &mut String, t: &selftest::SelfTest) {
    let _ = writeln!(
        s,
        "
cases:"
    );
    for c in &t.cases {
        let injected: Vec<&str> = c.injected.iter().map(|e| e.id()).collect();
        let cov: Vec<String> = c
            .covered
            .iter()
            .map(|(n, ok)| format!("{n}:{}", if *ok { "in" } else { "OUT" }))
            .collect();
        let _ = writeln!(
            s,
            "  {:<6} {:<38} named {:<38} gap {:>8.2} -> {:>6.2}  closed {:>6}  {}{}",
            c.kind,
            if injected.is_empty() {
                "none".into()
            } else {
                injected.join("+")
            },
            if c.named.is_empty() {
                "nothing".into()
            } else {
                c.named.join("+")
            },
            c.holdout_gap.0,
            c.holdout_gap.1,
            pct(c.fraction_closed),
            cov.join(" "),
            if c.model_fits { "" } else { "  (does not fit)" }
        );
    }
}

/// The self-check's scores: the confusion of single effects, then each share of cases.
fn scores_table(s: &mut String, t: &selftest::SelfTest) {
    let _ = writeln!(
        s,
        "
confusion (single effects: injected -> top-1 named):"
    );
    for (truth, got, n) in &t.confusion {
        let _ = writeln!(s, "  {truth:<18} -> {got:<18} {n}");
    }
    let _ = writeln!(
        s,
        "
top-1 accuracy (single effects): {} strict, {} counting confounded pairs ({}) as one",
        pct(t.top1_strict),
        pct(t.top1_group),
        selftest::CONFOUND_GROUPS
            .iter()
            .map(|(a, b)| format!("{a}~{b}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "pairs with both effects named: {} strict, {} by confound group",
        pct(t.pairs_both_named),
        pct(t.pairs_both_named_group)
    );
    let _ = writeln!(
        s,
        "null cases with nothing significant: {}",
        pct(t.null_clean)
    );
    let _ = writeln!(
        s,
        "95% intervals covering the injected value: {}",
        pct(t.coverage)
    );
    let _ = writeln!(
        s,
        "mean fraction of the held-out gap closed (cases with effects): {}",
        pct(t.mean_fraction_closed)
    );
    let _ = writeln!(
        s,
        "cases whose selected model leaves nothing unexplained on the training runs: {}",
        pct(t.model_fits)
    );
}

/// The matrix plan's answer first: each effect's detection limit, then every cell.
fn matrix_table(s: &mut String, t: &selftest::SelfTest) {
    if t.matrix.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "detection limits (the smallest magnitude from which up every magnitude of the range is named first in {} of its cases):",
        pct(selftest::DETECTED_SHARE)
    );
    for l in &t.detection_limits {
        let _ = writeln!(
            s,
            "  {:<26} {}",
            l.effect,
            l.limit.map_or_else(
                || "not named at the top of its range".to_string(),
                |e| e.spec()
            )
        );
    }
    let _ = writeln!(
        s,
        "\nmatrix (effect alone at each magnitude; named first, nothing else named, 95% interval covers, held-out gap G before -> after):"
    );
    for c in &t.matrix {
        let _ = writeln!(
            s,
            "  {:<58} named first {}/{}  nothing extra {}/{}  covers {}/{}  G {:>7.2} -> {:>6.2}",
            c.magnitude.spec(),
            c.named_first,
            c.cases,
            c.nothing_extra,
            c.cases,
            c.covered.0,
            c.covered.1,
            c.holdout_gap.0,
            c.holdout_gap.1
        );
    }
    let _ = writeln!(s);
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "-".into()
    }
}

/// A posterior check worth listing: it checked something (or could not), for an effect
/// named or left out by it.
pub(super) fn shows_posterior(
    e: &gyro_diagnose::EffectResult,
    c: &gyro_diagnose::posterior::PosteriorCheck,
) -> bool {
    (!c.statistics.is_empty() || c.unmeasured) && (e.significant || !c.passes)
}

/// Not named because its simulation does not reproduce its signature statistics.
pub(super) fn fails_posterior(e: &gyro_diagnose::EffectResult) -> bool {
    e.posterior_check.as_ref().is_some_and(|c| !c.passes)
}

/// The held-out runs' angle error without and with the written model, one line per run
/// (none when nothing is compensated).
fn angle_error_lines(d: &Diagnosis) -> (String, Vec<String>) {
    let Some(c) = &d.compensation else {
        return (String::new(), Vec::new());
    };
    let title = format!(
        "held-out angle error, each run's largest |error| (deg): nominal -> with the written model ({})",
        if c.corrected.is_empty() {
            "which corrects nothing".to_string()
        } else {
            format!("corrects {}", c.corrected.join(", "))
        }
    );
    let mut lines = Vec::new();
    let width = c
        .runs
        .iter()
        .map(|r| super::run_label(d, &r.name).chars().count())
        .max()
        .unwrap_or(0);
    for r in &c.runs {
        lines.push(format!(
            "{:<width$}  {:>8.2} -> {:>8.2}",
            super::run_label(d, &r.name),
            r.max_abs_error_before_deg,
            r.max_abs_error_after_deg
        ));
    }
    (title, lines)
}

/// The human-readable summary: the verdict in its first lines, then the held-out angle
/// error per run, what is named, what the model misses and the notes; then the details
/// (what was read, the gap G, the where-statistics, the candidate table, the posterior
/// checks, the nominal model), each with its explanation.
pub fn table(d: &Diagnosis) -> String {
    let mut s = String::new();
    answer_lines(&mut s, d);
    let _ = writeln!(
        s,
        "\n---- details (the statistics behind the answer; docs/diagnose.md explains each) ----\n"
    );
    s.push_str(&crate::input::tables(
        d.inputs.iter().map(|i| (i.file.as_str(), &i.input)),
    ));
    gap_lines(&mut s, d);
    where_lines(&mut s, d);
    if !d.unexplained.is_empty() {
        unexplained_table(&mut s, d);
    }
    effects_table(&mut s, d);
    posterior_lines(&mut s, d);
    if let Some(c) = &d.compensation {
        not_corrected_lines(&mut s, c);
    }
    let _ = writeln!(s, "\nnominal model:");
    for n in &d.model.notes {
        let _ = writeln!(s, "  {n}");
    }
    s
}

/// The answer: the verdict, then the held-out angle error per run, what is named, what
/// the model misses and the notes (each section only if it has lines).
fn answer_lines(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "diagnosis (held out: {}):",
        super::run_files(d, "holdout")
    );
    for line in super::verdict(d) {
        let _ = writeln!(s, "  {line}");
    }
    let f = super::findings(d);
    let sections = [
        angle_error_lines(d),
        ("named:".to_string(), f.named),
        ("what the model still misses:".to_string(), f.missed),
        ("notes:".to_string(), f.notes),
    ];
    for (title, lines) in sections {
        if lines.is_empty() {
            continue;
        }
        let _ = writeln!(s);
        if !title.is_empty() {
            let _ = writeln!(s, "{title}");
        }
        for line in lines {
            let _ = writeln!(s, "  {line}");
        }
    }
}

/// The gap G before and after, with its floor, and the verdict in the statistics' terms.
fn gap_lines(s: &mut String, d: &Diagnosis) {
    let g = &d.gap;
    let _ = writeln!(
        s,
        "\ngap G: how far the runs' statistics lie from the model's simulations of the same runs, the RMS of their z-scores; the floor is G between two simulations of one model (what a model that explains the runs reaches)"
    );
    let _ = writeln!(
        s,
        "  train    {} -> {}\n  holdout  {} -> {}\n  floor    {}",
        num(g.train_before),
        num(g.train_after),
        num(g.holdout_before),
        num(g.holdout_after),
        num(g.floor)
    );
    let _ = writeln!(
        s,
        "verdict: {}; fraction of the held-out gap closed {}",
        if d.verdict.unmodelled.is_empty() {
            "nothing significant".to_string()
        } else {
            format!("unmodelled {}", d.verdict.unmodelled.join(", "))
        },
        num(d.verdict.fraction_closed_holdout)
    );
}

/// The ten statistics furthest from the nominal model.
fn where_lines(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "\nwhere the runs differ from the nominal model most (z: the real statistic's distance from its simulations, in their standard deviations; positive: real above):");
    for w in d.r#where.iter().take(10) {
        let _ = writeln!(
            s,
            "  {:>8.1}  {:<28} {:<28} {}",
            w.z,
            w.segment,
            w.statistic,
            super::described(&w.segment, &w.statistic)
        );
    }
}

/// The statistics the selected model leaves unexplained on the training runs.
fn unexplained_table(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\nunexplained by the selected model (training runs, |z| >= {}; real vs simulated, means over the runs):",
        gyro_diagnose::locate::UNEXPLAINED_Z
    );
    let _ = writeln!(
        s,
        "  {:>9} {:>9} {:>9}  {:<28} {:<28} {:>11} {:>11} {:>11}",
        "z", "nominal z", "held-out z", "segment", "statistic", "real", "nominal", "selected"
    );
    for u in &d.unexplained {
        let _ = writeln!(
            s,
            "  {:>9.1} {:>9.1} {:>9.1}  {:<28} {:<28} {:>11} {:>11} {:>11}",
            u.z_train,
            u.z_train_nominal,
            u.z_holdout,
            u.segment,
            u.statistic,
            super::sig3(u.real),
            super::sig3(u.nominal),
            super::sig3(u.simulated)
        );
    }
}

/// The candidate effects ranked, one row each, then those that could not be tested.
fn effects_table(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\neffects (ranked; gap on held-out runs before -> after adding the fitted effect)"
    );
    let _ = writeln!(
        s,
        "  {:<18} {:>4} {:>9} {:>10} {:>24} {:>9} {:>9}  parameters [95% interval]",
        "effect", "sig", "z", "held-out z", "held-out evidence", "gap", "closed"
    );
    for e in &d.effects {
        let _ = writeln!(
            s,
            "  {:<18} {:>4} {:>9} {:>10} {:>24} {:>9} {:>9}  {}{}",
            e.id,
            if e.significant { "yes" } else { "" },
            e.z.map_or("exact".to_string(), |z| format!("{z:.1}")),
            e.holdout_z.map_or("-".to_string(), |z| format!("{z:.1}")),
            e.delta_bic.map_or(super::NOT_SCORED, super::evidence),
            num(e.holdout_gap_after.unwrap_or(f64::NAN)),
            num(e.fraction_closed.unwrap_or(f64::NAN)),
            params_with_intervals(e).join(", "),
            if e.confounded_with.is_empty() {
                String::new()
            } else {
                format!("  (confounded with {})", e.confounded_with.join(", "))
            } + if fails_posterior(e) {
                "  (fails its posterior check)"
            } else {
                ""
            }
        );
    }
    for u in &d.untestable {
        let _ = writeln!(s, "  {:<18} untestable: {}", u.id, u.reason);
    }
}

/// Each fitted parameter of `e` as `name=value [lo, hi]` (the 95% interval, where known).
fn params_with_intervals(e: &gyro_diagnose::EffectResult) -> Vec<String> {
    e.params
        .iter()
        .map(|(k, v)| {
            let ci = e.ci95.get(k).map_or(String::new(), |[a, b]| {
                let f = |x: &Option<f64>| x.map_or("inf".to_string(), |v| format!("{v:.4e}"));
                format!(" [{}, {}]", f(a), f(b))
            });
            format!("{k}={v:.4e}{ci}")
        })
        .collect()
}

/// The posterior checks worth listing ([`shows_posterior`]), if any.
fn posterior_lines(s: &mut String, d: &Diagnosis) {
    let checks: Vec<_> = d
        .effects
        .iter()
        .filter_map(|e| e.posterior_check.as_ref().map(|c| (e, c)))
        .filter(|(e, c)| shows_posterior(e, c))
        .collect();
    if checks.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "\nposterior checks (held-out runs; an effect is named only if the simulation with it covers its signature statistics or leaves at most half of the nominal discrepancy)"
    );
    for (e, c) in checks {
        let _ = writeln!(
            s,
            "  {:<18} {:<6} {}",
            e.id,
            if c.passes { "passes" } else { "fails" },
            c.describe()
        );
    }
}

/// Why each named effect left out of the written model is not corrected.
fn not_corrected_lines(s: &mut String, c: &gyro_diagnose::CompensationSummary) {
    for n in &c.not_corrected {
        let _ = writeln!(
            s,
            "\n{}: named, not corrected: {}its correction gives a median held-out max abs angle error of {:.2} deg against {:.2} without, better on {} of {} runs (bootstrap P {:.2})",
            n.id,
            n.reason.map_or(String::new(), |r| format!("{r}; ")),
            n.median_max_abs_error_with_deg,
            n.median_max_abs_error_without_deg,
            n.runs_better,
            n.runs,
            n.bootstrap_p
        );
    }
}
