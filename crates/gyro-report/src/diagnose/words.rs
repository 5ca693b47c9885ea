//! The diagnosis's statistics in a bench engineer's words: what a "where" statistic
//! measures, on which part of the runs, and how far the real runs are from the model, in
//! the statistic's own unit (deg/s, %, ms, deg) or as a ratio where the statistic is a
//! spread. The one home for these words: the verdict, the text table and the HTML page
//! all call [`missed`].

use crate::plot::sig;
use gyro_diagnose::Unexplained;

/// How a statistic's real and simulated values are compared in words.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Compare {
    /// A spread (positive) in `unit`: "N times what the model predicts".
    Ratio { unit: &'static str },
    /// The log10 of a spread: the ratio of the powers of ten.
    Log10Ratio,
    /// A signed value: both values, in `unit` after scaling by `scale`.
    Values { scale: f64, unit: &'static str },
}

/// The plain name of statistic `statistic` and how its values compare.
fn statistic(statistic: &str) -> (String, Compare) {
    let values = |scale, unit| Compare::Values { scale, unit };
    let (name, how) = match statistic {
        "residual_mean" => (
            "the mean rate error (gyro minus reference)".into(),
            values(1.0, " deg/s"),
        ),
        "residual_std" => ("the rate noise".into(), Compare::Ratio { unit: " deg/s" }),
        "slope_vs_rate" => ("the scale".into(), values(100.0, "%")),
        "low_band_slope_vs_rate" => ("the scale in slow motion".into(), values(100.0, "%")),
        "slope_vs_acceleration" => (
            "the delay read from the rate error against angular acceleration".into(),
            values(1e3, " ms"),
        ),
        "quadratic_vs_rate" => (
            "the quadratic bend of the rate error with the rate".into(),
            values(1.0, ""),
        ),
        "cubic_vs_rate" => (
            "the cubic bend of the rate error with the rate".into(),
            values(1.0, ""),
        ),
        "lag1_autocorrelation" => (
            "the correlation of the noise from one sample to the next".into(),
            values(1.0, ""),
        ),
        "xcorr_peak_lag_s" => (
            "the gyro's lag behind the reference".into(),
            values(1e3, " ms"),
        ),
        "xcorr_lag_trend" => (
            "the growth of the gyro's lag through a run".into(),
            values(6e4, " ms per minute"),
        ),
        other => {
            if let Some(band) = other
                .strip_prefix("allan_log10_adev_")
                .and_then(|b| b.strip_suffix('s'))
            {
                let band = band.replace('_', " to ");
                (
                    format!("the noise averaged over {band} s (Allan deviation)"),
                    Compare::Log10Ratio,
                )
            } else if let Some(tau) = other
                .strip_prefix("wander_log10_avar_")
                .and_then(|b| b.strip_suffix('s'))
            {
                (
                    format!("the bias wander over {tau} s (Allan variance)"),
                    Compare::Log10Ratio,
                )
            } else if let Some(h) = other
                .strip_prefix("angle_error_rms_")
                .and_then(|b| b.strip_suffix('s'))
            {
                (
                    format!("the angle error gathered over {h} s"),
                    Compare::Ratio { unit: " deg" },
                )
            } else if let Some(term) = other.strip_prefix("regression_") {
                (
                    format!("the rate error's {} term", term.replace('_', " ")),
                    values(1.0, ""),
                )
            } else {
                (other.replace('_', " "), values(1.0, ""))
            }
        }
    };
    (name, how)
}

/// Which third, in words.
fn third(k: &str, words: [&'static str; 3]) -> Option<&'static str> {
    match k {
        "1" => Some(words[0]),
        "2" => Some(words[1]),
        "3" => Some(words[2]),
        _ => None,
    }
}

/// The part of the runs segment `segment` covers, in words ("" for the whole runs).
pub fn segment(segment: &str) -> String {
    let mut parts = segment.split('/');
    let base = match parts.next().unwrap_or("") {
        "static" => "at rest",
        "dynamic" => "in motion",
        _ => "",
    };
    let Some(sub) = parts.next() else {
        return base.to_string();
    };
    let detail = if let Some(range) = sub.strip_prefix("rate_") {
        match range.split_once('_') {
            Some((lo, "inf")) => return format!("{base} above {lo} deg/s"),
            Some((lo, hi)) => return format!("{base} at {lo} to {hi} deg/s"),
            None => sub.replace('_', " "),
        }
    } else if sub == "positive" {
        return "turning the positive way".into();
    } else if sub == "negative" {
        return "turning the negative way".into();
    } else if let Some(k) = sub.strip_prefix("time_") {
        third(k, ["first", "middle", "last"]).map_or_else(
            || sub.replace('_', " "),
            |w| format!("in the {w} third of each run"),
        )
    } else if let Some(k) = sub.strip_prefix("temperature_") {
        third(k, ["coolest", "middle", "warmest"]).map_or_else(
            || sub.replace('_', " "),
            |w| format!("in the {w} third of the temperatures"),
        )
    } else {
        sub.replace('_', " ")
    };
    if base.is_empty() {
        detail
    } else {
        format!("{base}, {detail}")
    }
}

/// What statistic `statistic` of segment `segment` is, in words ("in motion at 30 to 100
/// deg/s, the rate noise").
pub fn described(segment_name: &str, statistic_name: &str) -> String {
    let (name, _) = statistic(statistic_name);
    let place = segment(segment_name);
    if place.is_empty() {
        name
    } else {
        format!("{place}, {name}")
    }
}

/// What the selected model misses in `u`, in words and units: "in motion at 30 to 100
/// deg/s, the rate noise is 1.4 times what the model predicts (0.52 against 0.37)".
pub fn missed(u: &Unexplained) -> String {
    let (_, how) = statistic(&u.statistic);
    let lead = described(&u.segment, &u.statistic);
    let ratio_text = |ratio: f64, real: f64, sim: f64, unit: &str| {
        let (real, sim) = (sig(real, 3), sig(sim, 3));
        if ratio.is_finite() && ratio > 0.0 {
            format!(
                "{lead} is {} {} what the model predicts ({real} against {sim}{unit})",
                sig_short(ratio),
                if ratio >= 1.0 { "times" } else { "of" }
            )
        } else {
            format!("{lead} is {real}{unit}; the model predicts {sim}{unit}")
        }
    };
    match how {
        Compare::Ratio { unit } => ratio_text(u.real / u.simulated, u.real, u.simulated, unit),
        Compare::Log10Ratio => ratio_text(
            10f64.powf(u.real - u.simulated),
            10f64.powf(u.real),
            10f64.powf(u.simulated),
            "",
        ),
        Compare::Values { scale, unit } => format!(
            "{lead} is {}{unit}; the model predicts {}{unit}",
            sig(scale * u.real, 3),
            sig(scale * u.simulated, 3)
        ),
    }
}

/// What the model misses, one line per statistic (the largest |z| of each, in the order
/// of `unexplained`, which is largest first), at most `most` lines; a statistic missed in
/// several parts of the runs says in how many.
pub fn missed_by_statistic(unexplained: &[Unexplained], most: usize) -> Vec<String> {
    let mut order: Vec<(&str, &Unexplained, usize)> = Vec::new();
    for u in unexplained {
        match order.iter_mut().find(|(s, _, _)| *s == u.statistic) {
            Some((_, _, n)) => *n += 1,
            None => order.push((&u.statistic, u, 1)),
        }
    }
    order
        .into_iter()
        .take(most)
        .map(|(_, u, n)| {
            let line = missed(u);
            if n > 1 {
                format!("{line}; and in {} other parts of the runs", n - 1)
            } else {
                line
            }
        })
        .collect()
}

/// A ratio to two significant digits ("1.4", "12", "0.51").
fn sig_short(x: f64) -> String {
    sig(x, 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unexplained(segment: &str, statistic: &str, real: f64, simulated: f64) -> Unexplained {
        Unexplained {
            segment: segment.into(),
            statistic: statistic.into(),
            real,
            nominal: simulated,
            simulated,
            z_train: 10.0,
            z_train_nominal: 10.0,
            z_holdout: 10.0,
        }
    }

    #[test]
    fn segments_read_as_parts_of_the_runs() {
        assert_eq!(segment("static"), "at rest");
        assert_eq!(
            segment("dynamic/rate_30_100"),
            "in motion at 30 to 100 deg/s"
        );
        assert_eq!(segment("dynamic/rate_100_inf"), "in motion above 100 deg/s");
        assert_eq!(segment("dynamic/negative"), "turning the negative way");
        assert_eq!(
            segment("static/time_3"),
            "at rest, in the last third of each run"
        );
        assert_eq!(
            segment("dynamic/temperature_1"),
            "in motion, in the coolest third of the temperatures"
        );
        assert_eq!(segment("all"), "");
    }

    #[test]
    fn a_spread_reads_as_a_ratio_and_a_mean_in_its_unit() {
        assert_eq!(
            missed(&unexplained("dynamic", "residual_std", 0.52, 0.37)),
            "in motion, the rate noise is 1.4 times what the model predicts (0.520 against 0.370 deg/s)"
        );
        assert_eq!(
            missed(&unexplained("static", "residual_mean", 0.12, 0.01)),
            "at rest, the mean rate error (gyro minus reference) is 0.120 deg/s; the model predicts 0.0100 deg/s"
        );
        assert_eq!(
            missed(&unexplained("all", "xcorr_peak_lag_s", 0.0113, 0.0)),
            "the gyro's lag behind the reference is 11.3 ms; the model predicts 0 ms"
        );
    }

    #[test]
    fn one_line_per_statistic_says_how_many_parts_more() {
        let lines = missed_by_statistic(
            &[
                unexplained("dynamic/rate_0_30", "residual_std", 2.0, 1.0),
                unexplained("dynamic", "slope_vs_rate", 0.01, 0.0),
                unexplained("dynamic", "residual_std", 1.5, 1.0),
            ],
            5,
        );
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[0].starts_with("in motion at 0 to 30 deg/s, the rate noise is 2.0 times"));
        assert!(
            lines[0].ends_with("; and in 1 other parts of the runs"),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "in motion, the scale is 1.00%; the model predicts 0%"
        );
        assert_eq!(missed_by_statistic(&[], 5), Vec::<String>::new());
    }

    #[test]
    fn a_log_allan_deviation_reads_as_the_ratio_of_the_deviations() {
        let s = missed(&unexplained(
            "static",
            "allan_log10_adev_1_10s",
            (0.02f64).log10(),
            (0.01f64).log10(),
        ));
        assert!(
            s.starts_with(
                "at rest, the noise averaged over 1 to 10 s (Allan deviation) is 2.0 times"
            ),
            "{s}"
        );
    }
}
