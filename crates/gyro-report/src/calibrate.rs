//! The text of `calibrate`: fitted models and the per-run scores.

use gyro_analysis::calibrate::{Calibration, RunScore};
use gyro_core::Config;

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
        "  {:<40} {:>9} {:>9} {:>9}",
        "run", "none", "paper", "kalman"
    );
    for r in scores {
        let name = last_chars(&r.name, 40);
        let _ = writeln!(
            s,
            "  {:<40} {:>9.4} {:>9.4} {:>9.4}",
            name, r.none_max_abs_deg, r.paper_max_abs_deg, r.kalman_max_abs_deg
        );
    }
    let median = |f: fn(&RunScore) -> f64| {
        let mut v: Vec<f64> = scores.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let _ = writeln!(
        s,
        "  {:<40} {:>9.4} {:>9.4} {:>9.4}",
        "median",
        median(|r| r.none_max_abs_deg),
        median(|r| r.paper_max_abs_deg),
        median(|r| r.kalman_max_abs_deg)
    );
    s
}

/// The calibration as text: the fitted paper model with its leave-one-run-out spread, the
/// Kalman form, and the max abs angle error per run by compensation mode.
pub fn table(c: &Calibration) -> String {
    let mut s = format!(
        "start: correlation time {:.1} s ({})\n",
        c.initial_tau.0, c.initial_tau.1
    );
    if c.config.motion != Config::default().motion {
        s += &format!(
            "motion thresholds: enter {:.3} deg/s, exit {:.3} deg/s\n",
            c.config.motion.enter_dps, c.config.motion.exit_dps
        );
    }
    s += &format!(
        "paper error model: beta {:.5} 1/s (T {:.1} s), b0 {:.5} deg/s, o0 {:.5} deg\n  objective {:?} = {:.4} deg after {} evaluations ({})\n",
        c.paper.beta_per_s,
        1.0 / c.paper.beta_per_s,
        c.paper.b0_dps,
        c.paper.o0_deg,
        c.objective,
        c.objective_deg,
        c.evaluations,
        c.termination
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
    let k = &c.config.kalman;
    s += &format!(
        "kalman form: bias mean {:.4} deg/s, within-run sigma {:.4} deg/s, between-run sigma {:.4} deg/s, rate noise {:.4} deg/s\n",
        k.bias_mean_dps, k.bias_sigma_dps, k.initial_bias_sigma_dps, k.rate_noise_dps
    );
    s += &score_table("training runs", &c.train);
    s += &score_table("hold-out runs", &c.holdout);
    s += &format!(
        "model compensation: {:?} (best on the training runs)\n",
        c.config.compensation
    );
    s
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
