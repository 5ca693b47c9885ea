//! The diagnosis and the self-check as text (`gyro-cli diagnose`'s table).

use gyro_analysis::diagnose::{selftest, Diagnosis};
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
    let _ = writeln!(s, "injected magnitudes:");
    for e in &t.magnitudes {
        let _ = writeln!(s, "  {}", serde_json::to_string(e).unwrap_or_default());
    }
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
            "  {:<6} {:<38} named {:<38} gap {:>8.2} -> {:>6.2}  closed {:>6}  {}",
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
            cov.join(" ")
        );
    }
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
    s
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "-".into()
    }
}

/// The human-readable summary.
pub fn table(d: &Diagnosis) -> String {
    let mut s = crate::input::tables(d.inputs.iter().map(|i| (i.file.as_str(), &i.input)));
    let g = &d.gap;
    let _ = writeln!(
        s,
        "gap G (RMS z of the where-statistics; floor = two simulated ensembles)"
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
    let _ = writeln!(s, "\nwhere (largest |z| of real vs the nominal ensembles):");
    for w in d.r#where.iter().take(10) {
        let _ = writeln!(s, "  {:>8.1}  {:<28} {}", w.z, w.segment, w.statistic);
    }
    let _ = writeln!(
        s,
        "\neffects (ranked; gap on held-out runs before -> after adding the fitted effect)"
    );
    let _ = writeln!(
        s,
        "  {:<18} {:>4} {:>9} {:>9} {:>9} {:>9}  parameters [95% interval]",
        "effect", "sig", "z", "dBIC", "gap", "closed"
    );
    for e in &d.effects {
        let params: Vec<String> = e
            .params
            .iter()
            .map(|(k, v)| {
                let ci = e.ci95.get(k).map_or(String::new(), |[a, b]| {
                    let f = |x: &Option<f64>| x.map_or("inf".to_string(), |v| format!("{v:.4e}"));
                    format!(" [{}, {}]", f(a), f(b))
                });
                format!("{k}={v:.4e}{ci}")
            })
            .collect();
        let _ = writeln!(
            s,
            "  {:<18} {:>4} {:>9} {:>9.1} {:>9} {:>9}  {}{}",
            e.id,
            if e.significant { "yes" } else { "" },
            e.z.map_or("exact".to_string(), |z| format!("{z:.1}")),
            e.delta_bic,
            num(e.holdout_gap_after),
            num(e.fraction_closed),
            params.join(", "),
            if e.confounded_with.is_empty() {
                String::new()
            } else {
                format!("  (confounded with {})", e.confounded_with.join(", "))
            }
        );
    }
    for u in &d.untestable {
        let _ = writeln!(s, "  {:<18} untestable: {}", u.id, u.reason);
    }
    if let Some(c) = &d.compensation {
        let _ = writeln!(
            s,
            "\nrun --model with corrections for {}: max abs angle error per held-out run (deg)",
            c.corrected.join(", ")
        );
        for r in &c.runs {
            let _ = writeln!(
                s,
                "  {:<40} {:>9.4} -> {:>9.4}",
                r.name, r.max_abs_error_before_deg, r.max_abs_error_after_deg
            );
        }
    }
    let _ = writeln!(s, "\nnominal model:");
    for n in &d.model.notes {
        let _ = writeln!(s, "  {n}");
    }
    s
}
