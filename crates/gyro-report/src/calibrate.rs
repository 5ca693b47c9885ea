//! The text of `calibrate`: fitted models and the per-run scores.

use gyro_analysis::calibrate::delay::DelaySource;
use gyro_analysis::calibrate::{
    Calibration, Candidate, CandidateScore, ChoiceReason, Objective, RunScore,
};
use gyro_core::{Compensation, Config};
use serde::Serialize;

/// The JSON of `calibrate`: the calibration, then each run's input-quality report.
pub fn json(
    inputs: &[crate::input::InputJson<'_>],
    calibration: &Calibration,
) -> serde_json::Result<String> {
    #[derive(Serialize)]
    struct Json<'a> {
        #[serde(flatten)]
        calibration: &'a Calibration,
        inputs: &'a [crate::input::InputJson<'a>],
    }
    serde_json::to_string_pretty(&Json {
        calibration,
        inputs,
    })
}

/// The last `n` characters of `s` (whole characters: names may be non-ASCII).
fn last_chars(s: &str, n: usize) -> &str {
    let count = s.chars().count();
    match s.char_indices().nth(count.saturating_sub(n)) {
        Some((i, _)) if count > n => &s[i..],
        _ => s,
    }
}

fn score_table(title: &str, scores: &[RunScore]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    if scores.is_empty() {
        return s;
    }
    let _ = writeln!(s, "{title}: max abs angle error per run (deg)");
    let _ = writeln!(
        s,
        "  {:<40} {:>9} {:>9} {:>9} {:>9}",
        "run", "default", "none", "paper", "kalman"
    );
    for r in scores {
        let name = last_chars(&r.name, 40);
        let _ = writeln!(
            s,
            "  {:<40} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
            name,
            r.default_max_abs_deg,
            r.none_max_abs_deg,
            r.paper_max_abs_deg,
            r.kalman_max_abs_deg
        );
    }
    let median = |f: fn(&RunScore) -> f64| {
        let mut v: Vec<f64> = scores.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let _ = writeln!(
        s,
        "  {:<40} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
        "median",
        median(|r| r.default_max_abs_deg),
        median(|r| r.none_max_abs_deg),
        median(|r| r.paper_max_abs_deg),
        median(|r| r.kalman_max_abs_deg)
    );
    s
}

fn compensation_text(compensation: Compensation) -> &'static str {
    match compensation {
        Compensation::None => "no",
        Compensation::Paper => "paper",
        Compensation::Kalman => "Kalman",
    }
}

/// What a candidate is, in words.
pub fn candidate_text(c: &Calibration, candidate: Candidate) -> String {
    match candidate {
        Candidate::Default => format!(
            "the starting configuration with {} compensation{}",
            compensation_text(c.start.compensation),
            if c.scale.written {
                ", nothing fitted but the scale"
            } else {
                ", nothing fitted"
            }
        ),
        Candidate::None => "no compensation".to_string(),
        Candidate::Paper => "the fitted paper error model".to_string(),
        Candidate::Kalman => "the Kalman form with the fitted settings".to_string(),
    }
}

/// What an objective measures, in words.
pub fn objective_text(objective: Objective) -> &'static str {
    match objective {
        Objective::MeanMaxAbs => "the mean over the runs of each run's largest |angle error|",
        Objective::MeanRms => "the mean over the runs of each run's RMS angle error",
        Objective::WorstMaxAbs => "the largest |angle error| of any run",
        Objective::MovementRms => "the RMS over every completed movement of its angle error",
    }
}

/// The left-out runs on which `score` errs less than `default`.
fn runs_better(score: &CandidateScore, default: &CandidateScore) -> usize {
    score
        .leave_one_out_runs_deg
        .iter()
        .zip(&default.leave_one_out_runs_deg)
        .filter(|(v, d)| v < d)
        .count()
}

/// The median of `scores` by `f` (NaN for none).
fn median_of(scores: &[RunScore], f: fn(&RunScore) -> f64) -> f64 {
    let v: Vec<f64> = scores.iter().map(f).collect();
    gyro_analysis::median(&v).unwrap_or(f64::NAN)
}

/// A run score's max abs angle error for `candidate` (deg).
fn score_of(r: &RunScore, candidate: Candidate) -> f64 {
    match candidate {
        Candidate::Default => r.default_max_abs_deg,
        Candidate::None => r.none_max_abs_deg,
        Candidate::Paper => r.paper_max_abs_deg,
        Candidate::Kalman => r.kalman_max_abs_deg,
    }
}

/// The answer in a few lines, in degrees and plain words, for the top of the table: what
/// the written model holds, why, and what the hold-out runs say of it.
pub fn answer(c: &Calibration) -> Vec<String> {
    let written = c.choice.written;
    let mut holds = vec![candidate_text(c, written)];
    if let (Some(k), true) = (c.scale.k, c.scale.written) {
        holds.push(format!("a scale correction of {:+.3} %", 100.0 * k));
    }
    let d = &c.reference_delay;
    match d.source {
        DelaySource::CrossCorrelation | DelaySource::Given => holds.push(format!(
            "a reference delay of {:.1} ms (the gyro {} the reference)",
            1e3 * d.delay_s.abs(),
            if d.delay_s >= 0.0 { "lags" } else { "leads" }
        )),
        DelaySource::NotApplied => {}
    }
    let mut lines = vec![format!("the written model holds {}", holds.join(", "))];
    let default = c
        .choice
        .scores
        .iter()
        .find(|score| score.candidate == Candidate::Default);
    let chosen = c
        .choice
        .scores
        .iter()
        .find(|score| score.candidate == written);
    let objective = objective_text(c.objective);
    lines.push(match (c.choice.reason, default, chosen) {
        (ChoiceReason::LowestHeldOut, Some(d), Some(w)) => {
            let wins = runs_better(w, d);
            format!(
                "why: with each training run left out of the fit and scored, it errs {:.2} deg against {:.2} deg for the starting configuration ({objective}), better on {wins} of {} runs",
                w.leave_one_out_deg.unwrap_or(f64::NAN),
                d.leave_one_out_deg.unwrap_or(f64::NAN),
                d.leave_one_out_runs_deg.len()
            )
        }
        (ChoiceReason::DefaultNotBeaten, Some(d), _) => format!(
            "why: with each training run left out of the fit and scored, no fitted candidate beats the starting configuration's {:.2} deg ({objective}) on most runs",
            d.leave_one_out_deg.unwrap_or(f64::NAN)
        ),
        _ => format!("why: {}", choice_text(c)),
    });
    if let (true, Some((without, with))) = (
        c.scale.written,
        c.scale.holdout_deg.or(c.scale.leave_one_out_deg),
    ) {
        lines.push(format!(
            "the scale correction takes the turns' RMS error (rest to rest) from {without:.2} deg to {with:.2} deg on runs it was not fitted on"
        ));
    }
    if !c.holdout.is_empty() {
        let before = median_of(&c.holdout, |r| r.default_max_abs_deg);
        let v: Vec<f64> = c.holdout.iter().map(|r| score_of(r, written)).collect();
        let after = gyro_analysis::median(&v).unwrap_or(f64::NAN);
        let runs = format!(
            "on the {} hold-out run{}, each run's largest |angle error| (median)",
            c.holdout.len(),
            if c.holdout.len() == 1 { "" } else { "s" }
        );
        let scale = if c.scale.written {
            " (both with the scale correction)"
        } else {
            ""
        };
        lines.push(if written == Candidate::Default {
            format!("{runs}: {after:.2} deg with the written model")
        } else {
            format!(
                "{runs}: {after:.2} deg with the written model, {before:.2} deg with the starting configuration{scale}"
            )
        });
    }
    lines
}

/// The calibration as text: the [`answer`] first, then the fitted paper model with its
/// leave-one-run-out spread, the Kalman form, the max abs angle error per run by
/// candidate, and which candidate is written, chosen on the leave-one-run-out errors.
pub fn table(c: &Calibration) -> String {
    table_with_inputs(c, "")
}

/// [`table`] with the input-quality report `inputs` ([`crate::input::tables`]) at the top
/// of the details, below the answer.
pub fn table_with_inputs(c: &Calibration, inputs: &str) -> String {
    let mut s = String::from("calibration:\n");
    for line in answer(c) {
        s += &format!("  {line}\n");
    }
    s += "\n---- details ----\n";
    s += inputs;
    s += &format!(
        "start: correlation time {:.1} s ({})\n",
        c.initial_tau.0, c.initial_tau.1
    );
    s += &delay_text(c);
    let f = &c.fitted;
    if f.motion != Config::default().motion {
        s += &format!(
            "motion thresholds: enter {:.3} deg/s, exit {:.3} deg/s\n",
            f.motion.enter_dps, f.motion.exit_dps
        );
    }
    s += &format!(
        "paper error model: beta {:.5} 1/s (T {:.1} s), b0 {:.5} deg/s, o0 {:.5} deg\n  objective ({}) {:.4} deg after {} evaluations ({})\n",
        f.paper.beta_per_s,
        1.0 / f.paper.beta_per_s,
        f.paper.b0_dps,
        f.paper.o0_deg,
        objective_text(c.objective),
        c.objective_deg,
        c.evaluations,
        match c.termination.as_str() {
            "Converged" => "converged",
            "MaxIterations" => "stopped at the iteration limit",
            "MaxEvaluations" => "stopped at the evaluation limit",
            other => other,
        }
    );
    if let Some(sp) = &c.spread {
        s += &format!(
            "  leave-one-run-out ({} refits): mean ± sd [min, max], jackknife standard error\n",
            sp.refits
        );
        for (name, p) in [
            ("beta", &sp.beta_per_s),
            ("b0  ", &sp.b0_dps),
            ("o0  ", &sp.o0_deg),
        ] {
            s += &format!(
                "    {name} {:.5} ± {:.5} [{:.5}, {:.5}]  se {:.5}\n",
                p.mean, p.sd, p.min, p.max, p.standard_error
            );
        }
    }
    let k = &f.kalman;
    s += &format!(
        "kalman form: bias mean {:.4} deg/s, within-run sigma {:.4} deg/s, between-run sigma {:.4} deg/s, rate noise {:.4} deg/s\n",
        k.bias_mean_dps, k.bias_sigma_dps, k.initial_bias_sigma_dps, k.rate_noise_dps
    );
    s += &score_table("training runs", &c.train);
    s += &score_table("hold-out runs", &c.holdout);
    s += &choice_table(c);
    s += &scale_text(c);
    s
}

/// The gyro's delay behind the reference the runs were scored with, and where it came from.
fn delay_text(c: &Calibration) -> String {
    let d = &c.reference_delay;
    let per_run = || {
        let lags: Vec<String> = d
            .per_run_s
            .iter()
            .map(|l| l.map_or_else(|| "-".to_string(), |l| format!("{:.1}", 1e3 * l)))
            .collect();
        lags.join(", ")
    };
    match d.source {
        DelaySource::Given => format!(
            "reference delay: {:.1} ms as given: every run is scored against the reference that far back\n",
            1e3 * d.delay_s
        ),
        DelaySource::CrossCorrelation => format!(
            "reference delay: the gyro lags the reference by {:.1} ms (cross-correlation peak, median of the training runs: {} ms): every run is scored against the reference that far back, and the model file says so\n",
            1e3 * d.delay_s,
            per_run()
        ),
        DelaySource::NotApplied => format!(
            "reference delay: none applied (cross-correlation peaks {} ms, under {} of a grid slot)\n",
            per_run(),
            gyro_analysis::calibrate::delay::MIN_SLOTS
        ),
    }
}

/// The scale factor from the movements' totals: its fit, its held-out effect and whether
/// it was written.
fn scale_text(c: &Calibration) -> String {
    let sc = &c.scale;
    let Some(k) = sc.k else {
        return format!(
            "scale: not fitted ({} completed movement(s) with a reference turn)\n",
            sc.movements
        );
    };
    let se = sc
        .standard_error
        .map_or_else(String::new, |se| format!(" ± {:.3}%", 100.0 * se));
    let mut s = format!(
        "scale: {:+.3}%{se} from the totals of {} movement(s) (the gyro reads (1 + k) times the reference turn)\n",
        100.0 * k,
        sc.movements
    );
    if let Some((without, with)) = sc.leave_one_out_deg {
        s += &format!(
            "  RMS error of the turns (rest to rest) on each run left out of the scale's fit, with the starting configuration: {without:.4} -> {with:.4} deg, better on {}/{} runs\n",
            sc.runs_better.0,
            sc.runs_better.1
        );
    }
    if let Some((without, with)) = sc.holdout_deg {
        s += &format!("  the same on the hold-out runs: {without:.4} -> {with:.4} deg\n");
    }
    if let (Some(u), Some(upper)) = (sc.residual_relative, sc.residual_relative_upper) {
        s += &format!(
            "  scale uncertainty left, held out: {:.3}% of the turn (RMS), at most {:.3}% (95% bound): the movement's σ does not hold it; the bound is written as the model's scale_sigma, which run's tightening decision adds\n",
            100.0 * u,
            100.0 * upper
        );
    }
    let significant = gyro_analysis::calibrate::scale::significant(k, sc.standard_error);
    s += if sc.written {
        "  written (config.correction.scale_k): held out it lowers the turns' error and is better on most runs; every candidate above is fitted and scored with it\n"
    } else if !significant {
        "  not written: within its noise (under 1.96 standard errors from zero)\n"
    } else if sc.leave_one_out_deg.is_none() {
        "  not written: no leave-one-run-out refits (or no turns) to judge it on\n"
    } else {
        "  not written: held out it does not lower the turns' error (overall and on most runs)\n"
    };
    s
}

/// Each candidate's held-out (leave-one-run-out) and training error, and the one written.
fn choice_table(c: &Calibration) -> String {
    use std::fmt::Write as _;
    let mut s = format!(
        "choice of the model written, on leave-one-run-out error (each training run scored with what was fitted on the other runs; {}, deg; training error not used)\n",
        objective_text(c.objective)
    );
    let _ = writeln!(
        s,
        "  {:<10} {:>13} {:>14} {:>13}",
        "candidate", "held-out deg", "runs better", "training deg"
    );
    let default = c
        .choice
        .scores
        .iter()
        .find(|score| score.candidate == Candidate::Default);
    for score in &c.choice.scores {
        let held_out = score
            .leave_one_out_deg
            .map_or_else(|| "-".to_string(), |v| format!("{v:.4}"));
        // Left-out runs on which the candidate beats the default.
        let better = match default {
            Some(d)
                if score.candidate != Candidate::Default && score.leave_one_out_deg.is_some() =>
            {
                format!(
                    "{}/{}",
                    runs_better(score, d),
                    d.leave_one_out_runs_deg.len()
                )
            }
            _ => "-".to_string(),
        };
        let _ = writeln!(
            s,
            "  {:<10} {:>13} {:>14} {:>13.4}",
            candidate_name(score.candidate),
            held_out,
            better,
            score.training_deg
        );
    }
    if c.choice.paper_at_bound {
        let _ = writeln!(
            s,
            "  paper: not eligible: its fit sits on a bound (b0 {:.3} deg/s, o0 {:.3} deg), absorbing an error the model cannot express",
            c.fitted.paper.b0_dps, c.fitted.paper.o0_deg
        );
    }
    let _ = writeln!(s, "model written: {}", choice_text(c));
    s
}

fn candidate_name(candidate: Candidate) -> &'static str {
    match candidate {
        Candidate::Default => "default",
        Candidate::None => "none",
        Candidate::Paper => "paper",
        Candidate::Kalman => "kalman",
    }
}

/// The candidate written and why, in one line.
pub fn choice_text(c: &Calibration) -> String {
    let written = c.choice.written;
    let why = match c.choice.reason {
        ChoiceReason::LowestHeldOut => {
            "held out it beats the default (lower objective, better on most runs), lowest of those that do"
        }
        ChoiceReason::DefaultNotBeaten => {
            "no fitted candidate beats it held out (lower objective and better on most runs)"
        }
        ChoiceReason::NoRefits => {
            "no leave-one-run-out refits (switched off, or one training run), so nothing fitted is written"
        }
    };
    let scale = match c.scale.k {
        Some(k) if c.scale.written => format!("; scale {:+.3}% written", 100.0 * k),
        _ => String::new(),
    };
    format!(
        "{} ({}): {why}{scale}",
        candidate_name(written),
        candidate_text(c, written)
    )
}

#[cfg(test)]
mod tests {
    use super::last_chars;

    #[test]
    fn last_chars_cuts_on_character_boundaries() {
        assert_eq!(last_chars("abc", 40), "abc");
        assert_eq!(last_chars("abcdef", 3), "def");
        let name = "Prüfstand/lauf_ö_ä_ü_ß_Prüfstand_Prüfstand_lauf_ö.csv";
        let tail = last_chars(name, 40);
        assert_eq!(tail.chars().count(), 40);
        assert!(name.ends_with(tail));
    }
}
