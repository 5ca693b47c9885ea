//! The diagnosis in a bench engineer's words: one sentence per named effect in the units
//! of the trade, rounded to what the interval supports, then what the written model
//! corrects; and the words for a ΔBIC (Kass & Raftery's scale).

use gyro_diagnose::{Diagnosis, EffectResult};

/// What the held-out columns of an effect not scored on the held-out runs say: its
/// parameter test does not pass on the training runs, so it can never be named.
pub const NOT_SCORED: &str = "not scored (test fails)";

/// Kass & Raftery's words for a BIC difference in favour of a model.
pub fn evidence(delta_bic: f64) -> &'static str {
    if !delta_bic.is_finite() || delta_bic <= 0.0 {
        "none"
    } else if delta_bic < 2.0 {
        "barely worth mentioning"
    } else if delta_bic < 6.0 {
        "positive"
    } else if delta_bic < 10.0 {
        "strong"
    } else {
        "decisive"
    }
}

/// `x` with as many significant digits as a value of spread `half` supports (at least 2).
pub fn rounded(x: f64, half: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    let scale = if half.is_finite() && half > 0.0 {
        half
    } else {
        x.abs() * 1e-3
    };
    if scale == 0.0 {
        return format!("{x}");
    }
    // One significant digit of the half-width, at least two of the value.
    let digits_half = -(scale.log10().floor() as i32);
    let digits_value = 1 - (x.abs().max(f64::MIN_POSITIVE).log10().floor() as i32);
    let decimals = digits_half.max(digits_value).clamp(0, 9) as usize;
    format!("{x:.decimals$}")
}

/// Parameter `name` of `e` times `unit`, with its 95% interval as "v [lo, hi]" when
/// `interval`, else alone (rounded to what the interval supports either way).
fn value(e: &EffectResult, name: &str, unit: f64, interval: bool) -> Option<String> {
    let v = *e.params.get(name)? * unit;
    let ci = e.ci95.get(name).copied().unwrap_or([None, None]);
    Some(match ci {
        [Some(lo), Some(hi)] => {
            let (lo, hi) = ((lo * unit).min(hi * unit), (lo * unit).max(hi * unit));
            let half = 0.5 * (hi - lo).abs();
            if interval {
                format!(
                    "{} [{}, {}]",
                    rounded(v, half),
                    rounded(lo, half),
                    rounded(hi, half)
                )
            } else {
                // Alone, at most three significant digits.
                rounded(v, half.max(0.05 * v.abs()))
            }
        }
        _ if interval => rounded(v, f64::NAN),
        _ => rounded(v, 0.05 * v.abs()),
    })
}

// Longer than a screen: one match over every effect id, a table of clauses that reads
// best whole (split, each part would be an arbitrary slice of the table).
/// What a named effect does, as a clause whose subject is the gyro ("lags the reference
/// by 12.6 ms"), with each value's 95% interval when `interval`.
pub fn clause(e: &EffectResult, interval: bool) -> String {
    let v = |name: &str, unit: f64| value(e, name, unit, interval).unwrap_or_else(|| "-".into());
    let negative = |name: &str| e.params.get(name).is_some_and(|x| *x < 0.0);
    match e.id {
        "latency" if negative("delay_s") => format!(
            "leads the reference (the reference lags) by {} ms",
            v("delay_s", -1e3)
        ),
        "latency" => format!("lags the reference by {} ms", v("delay_s", 1e3)),
        "bandwidth" => format!(
            "responds as a two-pole low-pass at {} Hz",
            v("cutoff_hz", 1.0)
        ),
        "scale_factor" if negative("k") => format!(
            "reads {} % less than the reference (scale factor)",
            v("k", -100.0)
        ),
        "scale_factor" => format!(
            "reads {} % more than the reference (scale factor)",
            v("k", 100.0)
        ),
        "scale_asymmetry" => format!(
            "reads {} % more turning the positive way than the negative way (scale asymmetry)",
            v("k", 100.0)
        ),
        "nonlinearity" => format!(
            "reads {} % of the rate off at 100 deg/s, with the rate's sign (cubic nonlinearity {} per (deg/s)²)",
            v("k3_per_dps2", 1e6),
            v("k3_per_dps2", 1.0)
        ),
        "nonlinearity_even" => format!(
            "reads {} % of the rate off at 100 deg/s, the same sign both ways (quadratic nonlinearity {} per deg/s)",
            v("k2_per_dps", 1e4),
            v("k2_per_dps", 1.0)
        ),
        "clock_error_count_stamped" if negative("ppm") => format!(
            "samples {} ppm slow and its rows are stamped by its sample count, so it runs ahead of the reference by {} ms more each minute",
            v("ppm", -1.0),
            v("ppm", -0.06)
        ),
        "clock_error_count_stamped" => format!(
            "samples {} ppm fast and its rows are stamped by its sample count, so its lag behind the reference grows by {} ms each minute",
            v("ppm", 1.0),
            v("ppm", 0.06)
        ),
        "vibration" => format!(
            "sees a vibration the reference does not: {} deg/s at {} Hz",
            v("amplitude_dps", 1.0),
            v("frequency_hz", 1.0)
        ),
        "saturation" => format!("clips at ±{} deg/s", v("limit_dps", 1.0)),
        "quantization" => format!("moves in steps of {} deg/s", v("lsb_dps", 1.0)),
        "clock_error" if negative("ppm") => format!(
            "samples {} ppm slow against the declared sample rate (its time stamps show it)",
            v("ppm", -1.0)
        ),
        "clock_error" => format!(
            "samples {} ppm fast against the declared sample rate (its time stamps show it)",
            v("ppm", 1.0)
        ),
        "dropouts" => format!(
            "drops samples {} times per s, {} at a time",
            v("rate_per_s", 1.0),
            v("mean_samples", 1.0)
        ),
        "temperature_bias" => format!(
            "has a bias that moves by {} deg/s per degC",
            v("dps_per_c", 1.0)
        ),
        "temperature_scale" => format!(
            "has a scale that moves by {} % per degC",
            v("per_c", 100.0)
        ),
        "bias_instability" => format!(
            "has a bias that wanders by σ {} deg/s within a run",
            v("sigma_dps", 1.0)
        ),
        "rate_random_walk" => format!(
            "has a bias that random-walks by {} deg/s/√s",
            v("k_dps_per_rt_s", 1.0)
        ),
        "turn_on_bias" => format!(
            "has a bias that differs from run to run by σ {} deg/s",
            v("sigma_dps", 1.0)
        ),
        other => {
            let params: Vec<String> = e
                .params
                .keys()
                .map(|k| format!("{k} = {}", v(k, 1.0)))
                .collect();
            format!("shows {other}: {}", params.join(", "))
        }
    }
}

/// An effect's size in words and units, for a detection limit ("bias instability of
/// σ 0.0125 deg/s (45 deg/h)").
pub fn size_words(e: &gyro_sim::Effect) -> String {
    use gyro_sim::Effect as E;
    // The shortest decimal of the nearest f32: 0.2, not 0.19999999999999998.
    let g = |x: f64| format!("{}", x as f32);
    match *e {
        E::ScaleFactor { k } => format!("a scale factor of {} %", g(100.0 * k.abs())),
        E::ScaleAsymmetry { k } => format!("a scale asymmetry of {} %", g(100.0 * k.abs())),
        E::Nonlinearity { k3_per_dps2 } => format!(
            "a cubic nonlinearity of {} % at 100 deg/s",
            g(1e6 * k3_per_dps2.abs())
        ),
        E::NonlinearityEven { k2_per_dps } => format!(
            "an even nonlinearity of {} % at 100 deg/s",
            g(1e4 * k2_per_dps.abs())
        ),
        E::Saturation { limit_dps } => format!("a clip at ±{} deg/s", g(limit_dps)),
        E::Quantization { lsb_dps } => format!("an output step of {} deg/s", g(lsb_dps)),
        E::Latency { delay_s } => format!("a latency of {} ms", g(1e3 * delay_s.abs())),
        E::ClockError { ppm } => format!(
            "a clock error of {} % (stamped by the logger)",
            g(1e-4 * ppm.abs())
        ),
        E::ClockErrorCountStamped { ppm } => format!(
            "a clock error of {} % (stamped by the sample count)",
            g(1e-4 * ppm.abs())
        ),
        E::Dropouts {
            rate_per_s,
            mean_samples,
        } => format!(
            "dropouts of {} per s, {} samples each",
            g(rate_per_s),
            g(mean_samples)
        ),
        E::TemperatureBias { dps_per_c } => format!(
            "a temperature bias of {} deg/s per degC",
            g(dps_per_c.abs())
        ),
        E::TemperatureScale { per_c } => format!(
            "a temperature scale of {} % per degC",
            g(100.0 * per_c.abs())
        ),
        E::BiasInstability { sigma_dps } => format!(
            "a bias instability of σ {} deg/s ({:.0} deg/h)",
            g(sigma_dps),
            3600.0 * sigma_dps
        ),
        E::RateRandomWalk { k_dps_per_rt_s } => {
            format!("a rate random walk of {} deg/s/√s", g(k_dps_per_rt_s))
        }
        E::TurnOnBias { sigma_dps } => {
            format!("a turn-on bias of σ {} deg/s from run to run", g(sigma_dps))
        }
        E::Bandwidth { cutoff_hz } => format!("a bandwidth of {} Hz", g(cutoff_hz)),
        E::Vibration {
            amplitude_dps,
            frequency_hz,
        } => format!(
            "a vibration of {} deg/s at {} Hz",
            g(amplitude_dps),
            g(frequency_hz)
        ),
    }
}

/// The effects not named, with their detection limits, as one line of the findings:
/// what runs like the self-check's cannot show.
fn not_seen_line(d: &Diagnosis) -> Option<String> {
    if d.not_seen.is_empty() {
        return None;
    }
    let below: Vec<String> = d
        .not_seen
        .iter()
        .filter_map(|n| {
            n.limit
                .as_ref()
                .map(|e| format!("{} ({})", size_words(e), n.id))
        })
        .collect();
    let never: Vec<&str> = d
        .not_seen
        .iter()
        .filter(|n| n.limit.is_none())
        .map(|n| n.id)
        .collect();
    let train: Vec<f64> = d
        .runs
        .iter()
        .filter(|r| r.role == "train")
        .map(|r| r.duration_s)
        .collect();
    let mut line = format!(
        "{NOT_NAMED} or smaller than what {} training runs of {} s show (these: {} runs, {:.0} s in all); the self-check names from {}",
        gyro_diagnose::selftest::TRAIN_RUNS,
        gyro_diagnose::selftest::RUN_S,
        train.len(),
        train.iter().sum::<f64>(),
        below.join(", ")
    );
    if !never.is_empty() {
        line.push_str(&format!(
            "; not named even at the top of its realistic range: {}",
            never.join(", ")
        ));
    }
    Some(line)
}

/// The sentence for a named effect, with its 95% intervals.
pub fn sentence(e: &EffectResult) -> String {
    format!("the gyro {}", clause(e, true))
}

/// What correcting effect `id` is, in words ("the lag", "the scale").
fn correction_name(id: &str) -> String {
    match id {
        "latency" => "the lag".into(),
        "bandwidth" => "the low-pass".into(),
        "scale_factor" => "the scale".into(),
        "scale_asymmetry" => "the scale asymmetry".into(),
        "clock_error" | "clock_error_count_stamped" => "the clock".into(),
        "temperature_bias" => "the bias's temperature slope".into(),
        "temperature_scale" => "the scale's temperature slope".into(),
        gyro_diagnose::BIAS_ID => "the bias".into(),
        other => format!("the {}", other.replace('_', " ")),
    }
}

/// `items` as "a", "a and b", "a, b and c".
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The held-out runs' median max |angle error| without and with the written corrections
/// (deg), and how many runs the corrections made better.
fn held_out_error(c: &gyro_diagnose::CompensationSummary) -> (f64, f64, usize) {
    let median = |f: &dyn Fn(&gyro_diagnose::CompensationRun) -> f64| {
        let v: Vec<f64> = c.runs.iter().map(f).filter(|x| x.is_finite()).collect();
        gyro_analysis::median(&v).unwrap_or(f64::NAN)
    };
    let better = c
        .runs
        .iter()
        .filter(|r| r.max_abs_error_after_deg < r.max_abs_error_before_deg)
        .count();
    (
        median(&|r| r.max_abs_error_before_deg),
        median(&|r| r.max_abs_error_after_deg),
        better,
    )
}

/// An angle in degrees for a sentence: two significant digits, at least one decimal
/// below 10 ("7.2°", "0.45°", "38°").
fn degrees(x: f64) -> String {
    if !x.is_finite() {
        "-".into()
    } else if x.abs() >= 10.0 {
        format!("{x:.0}°")
    } else if x.abs() >= 1.0 {
        format!("{x:.1}°")
    } else {
        format!("{}°", crate::plot::sig(x, 2))
    }
}

/// The answer in a few sentences, in degrees and plain words, for the first lines of
/// every output: what makes the diagnosis meaningless (a reference that does not measure
/// the gyro's motion), if anything; that the model does not explain the runs, and that
/// the corrections leave most of the held-out angle error, when so (first, never below
/// what is named); what differs from the model, and by how much; and what correcting it
/// does to the held-out angle error.
pub fn verdict(d: &Diagnosis) -> Vec<String> {
    let mut out: Vec<String> = d
        .reference_warnings
        .iter()
        .map(|w| format!("warning: {w}"))
        .collect();
    // When the model does not explain the runs, that comes first: what is named below
    // is then at most part of the answer.
    if !d.verdict.model_fits {
        let first = d.unexplained.first().map(super::words::missed);
        out.push(match first {
            Some(m) => format!(
                "The model does not explain these runs: {m}{}.",
                if d.unexplained.len() > 1 {
                    format!("; {} statistics in all, listed below", d.unexplained.len())
                } else {
                    String::new()
                }
            ),
            None => "The model does not explain these runs.".into(),
        });
    }
    let named: Vec<String> = d
        .effects
        .iter()
        .filter(|e| e.significant)
        .map(|e| clause(e, false))
        .collect();
    let turns = turn_clauses(d);
    let mut differs = named.clone();
    differs.extend(turns);
    out.push(if differs.is_empty() {
        "No effect of the vocabulary is named: on these runs the gyro behaves as the model predicts, or what differs is smaller than these runs show (the limits are listed below) or not in the vocabulary.".to_string()
    } else {
        format!("The gyro {}.", and_list(&differs))
    });
    // Why a named effect may be a look-alike: right after it, before what correcting it does.
    out.extend(d.doubts.iter().map(|doubt| format!("{doubt}.")));
    if let Some(c) = &d.compensation {
        let (before, after, better) = held_out_error(c);
        let turns_wrote = turns_wrote(d);
        if c.corrected.is_empty() {
            out.push(format!(
                "The written model corrects {}: no correction of {} lowered the held-out angle error ({} as it is, each run's largest error, median over {} runs).",
                if turns_wrote { "only what the turns show" } else { "nothing" },
                if named.len() == 1 { "it" } else { "them" },
                degrees(before),
                c.runs.len()
            ));
        } else {
            let ids: Vec<String> = c.corrected.iter().map(|id| correction_name(id)).collect();
            out.push(format!(
                "Correcting {} cuts the held-out angle error from {} to {} (each run's largest error, median over {} runs; better on {better} of {}){}.",
                and_list(&ids),
                degrees(before),
                degrees(after),
                c.runs.len(),
                c.runs.len(),
                if turns_wrote { "; the turns' corrections come on top" } else { "" }
            ));
            // Most of the error left by what is named: not the whole answer, said second
            // only to the model not fitting (a bias correction alone names nothing).
            if !named.is_empty() && after > 0.5 * before {
                let at = if d.verdict.model_fits { 0 } else { 1 } + d.reference_warnings.len();
                out.insert(
                    at,
                    format!(
                        "What is named leaves most of the held-out angle error: {} of {} remains after correcting it; its cause is not found here.",
                        degrees(after),
                        degrees(before)
                    ),
                );
            }
        }
    } else if let Some(line) = turns_error_sentence(d) {
        out.push(line);
    } else if !named.is_empty() {
        out.push("None of the named effects is one the model file corrects, so the held-out angle error is not changed by it.".into());
    }
    out
}

/// What the turns show, as clauses of the verdict: a lag beyond the per-sample
/// statistics, a turn scale that is named.
fn turn_clauses(d: &Diagnosis) -> Vec<String> {
    let Some(t) = &d.turns else {
        return Vec::new();
    };
    let mut out = Vec::new();
    if let Some(lag) = t.lag.as_ref().filter(|l| l.beyond_statistic) {
        out.push(format!(
            "{} the reference by {:.0} ms",
            if lag.median_s >= 0.0 { "lags" } else { "leads" },
            1e3 * lag.median_s.abs()
        ));
    }
    if let Some(s) = t.scale.as_ref().filter(|s| s.named) {
        out.push(format!(
            "reads {:.2} % {} than the reference over whole turns",
            100.0 * s.k.abs(),
            if s.k < 0.0 { "less" } else { "more" }
        ));
    }
    out
}

/// What the turns' written corrections do to the held-out angle error, when nothing else
/// is compensated.
fn turns_error_sentence(d: &Diagnosis) -> Option<String> {
    let t = d.turns.as_ref()?;
    let lag = t
        .lag
        .as_ref()
        .filter(|l| l.written)
        .and_then(|l| l.holdout_max_abs_error_deg);
    let (b, a) = lag?;
    Some(format!(
        "Correcting the lag cuts the held-out angle error from {} to {} (each run's largest error, median).",
        degrees(b),
        degrees(a)
    ))
}

/// The sections of the diagnosis below its [`verdict`], each a list of lines in plain
/// words; every output shows all of them, in this order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Findings {
    /// One line per named effect (value, 95% interval, evidence in words), then what the
    /// turns show rest to rest, then what the written model corrects and what it does not.
    pub named: Vec<String>,
    /// What the model still misses, in words and units: the statistics it leaves
    /// unexplained, the effective noise on moving data, lines in the motion.
    pub missed: Vec<String>,
    /// How many lines after the first of [`Findings::missed`] are the statistics that first
    /// line introduces ("the largest:"); 0 when the model fits.
    pub missed_listed: usize,
    /// How the data were taken (a quantised reference) and what makes part of the
    /// diagnosis unreliable.
    pub notes: Vec<String>,
}

/// How the findings line that lists what was not named, with the self-check's detection
/// limits, starts (the HTML report folds it).
pub const NOT_NAMED: &str = "not named, so absent";

/// Most unexplained statistics listed in words in [`Findings::missed`] (the rest are in
/// the details' table).
pub const MISSED_LINES: usize = 5;

/// The diagnosis's findings below the verdict ([`Findings`]).
pub fn findings(d: &Diagnosis) -> Findings {
    let (missed, missed_listed) = missed_lines(d);
    Findings {
        named: named_lines(d),
        missed,
        missed_listed,
        notes: note_lines(d),
    }
}

/// [`Findings::notes`]: how the references were quantised, then the warnings.
fn note_lines(d: &Diagnosis) -> Vec<String> {
    let mut notes = reference_grid_lines(&d.runs);
    notes.extend(d.warnings.iter().map(|w| format!("warning: {w}")));
    notes
}

/// [`Findings::named`]: the named effects (or that none is), what no run shows, the
/// turns, then what the written model corrects.
fn named_lines(d: &Diagnosis) -> Vec<String> {
    let mut named: Vec<String> = d
        .effects
        .iter()
        .filter(|e| e.significant)
        .map(|e| {
            format!(
                "{}: {} (evidence on the held-out runs: {})",
                e.id,
                sentence(e),
                e.delta_bic.map_or(NOT_SCORED, evidence)
            )
        })
        .collect();
    if named.is_empty() {
        named.push("no effect of the vocabulary is named: the nominal model holds on these runs, or what differs is not in the vocabulary (see what the model misses)".into());
    }
    named.extend(not_seen_line(d));
    named.extend(turn_lines(d));
    if let Some(c) = &d.compensation {
        named.extend(correction_lines(d, c));
    }
    named
}

/// What the written model corrects and how that changes the held-out angle error, then
/// each named effect it does not correct, and why.
fn correction_lines(d: &Diagnosis, c: &gyro_diagnose::CompensationSummary) -> Vec<String> {
    let mut lines = Vec::new();
    let (before, after, better) = held_out_error(c);
    if c.corrected.is_empty() {
        let what = if turns_wrote(d) {
            "no correction of the per-sample effects is written (the written model holds only the turns' corrections above)"
        } else {
            "no correction is written"
        };
        lines.push(format!(
            "{what}: none lowered the held-out angle error (median max |error| {before:.2} deg)"
        ));
    } else {
        let ids: Vec<String> = c
            .corrected
            .iter()
            .map(|id| {
                if *id == gyro_diagnose::BIAS_ID {
                    format!(
                        "the bias ({:.3} deg/s, fitted on the training runs)",
                        d.model.sensor.bias_dps
                    )
                } else {
                    id.to_string()
                }
            })
            .collect();
        lines.push(format!(
            "the written model corrects {}: held-out median max |angle error| {before:.2} -> {after:.2} deg, better on {better} of {} runs",
            ids.join(", "),
            c.runs.len()
        ));
    }
    for n in &c.not_corrected {
        if n.id == gyro_diagnose::BIAS_ID {
            lines.push(format!(
                "the bias ({:.3} deg/s, fitted on the training runs) is not written: it did not lower the held-out error",
                d.model.sensor.bias_dps
            ));
        } else {
            lines.push(format!(
                "{}: named, not corrected ({})",
                n.id,
                n.reason
                    .unwrap_or("its correction did not lower the held-out error")
            ));
        }
    }
    lines
}

/// [`Findings::missed`]: the unexplained statistics (if the model does not fit), the
/// effective noise on moving data and the lines in the motion; "nothing" if none. With
/// how many statistics its first line introduces ([`Findings::missed_listed`]).
fn missed_lines(d: &Diagnosis) -> (Vec<String>, usize) {
    let mut missed = Vec::new();
    let mut listed = 0;
    if !d.verdict.model_fits {
        missed.push(unexplained_line(d));
        let statistics = super::words::missed_by_statistic(&d.unexplained, MISSED_LINES);
        listed = statistics.len();
        missed.extend(statistics);
    }
    if let Some(line) = effective_noise_line(&d.effective_noise) {
        missed.push(match d.residual_caveat() {
            Some(caveat) => format!("{line}; but {caveat}"),
            None => line,
        });
    }
    missed.extend(d.motion_lines.iter().map(motion_line));
    if missed.is_empty() {
        missed.push(format!(
            "nothing: every statistic of the training runs is within |z| < {} of its simulation with the selected model",
            gyro_diagnose::locate::UNEXPLAINED_Z
        ));
    }
    (missed, listed)
}

/// A line in the motion (the rig vibrating), and how much of it the gyro passes.
fn motion_line(m: &gyro_diagnose::line::MotionLine) -> String {
    let response = if m.gyro_gain.is_finite() && m.gyro_lag_s.is_finite() {
        format!(
            "; the gyro passes {:.2} of it, {:.1} ms behind (a pure delay passes all of it)",
            m.gyro_gain,
            1e3 * m.gyro_lag_s
        )
    } else {
        String::new()
    };
    format!(
        "seen in the data, not a sensor effect: the motion of the {} runs has a line at {:.1} Hz ({} deg/s in the motion's rate, {:.0} times its local floor): the rig vibrates and both sensors see it{response}",
        m.runs,
        m.frequency_hz,
        rounded(m.amplitude_dps, 0.05 * m.amplitude_dps),
        m.ratio
    )
}

/// Every line of the diagnosis in words: the [`verdict`], then the [`findings`].
pub fn headline(d: &Diagnosis) -> Vec<String> {
    let f = findings(d);
    let mut lines = verdict(d);
    lines.extend(f.named);
    lines.extend(f.missed);
    lines.extend(f.notes);
    lines
}

/// How the re-simulation took the quantised references of `runs`, one line per kind of
/// grid: an encoder's counts, or a print's decimals
/// ([`gyro_diagnose::ReferenceGrid`]).
pub fn reference_grid_lines(runs: &[gyro_diagnose::RunSummary]) -> Vec<String> {
    use gyro_diagnose::GridKind;
    let total = runs.len();
    [GridKind::Encoder, GridKind::Print]
        .into_iter()
        .filter_map(|kind| {
            let grids: Vec<_> = runs
                .iter()
                .filter_map(|r| r.reference_grid)
                .filter(|g| g.kind == kind)
                .collect();
            let first = grids.first()?;
            let (lo, hi) = grids.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), g| {
                (lo.min(g.step_deg), hi.max(g.step_deg))
            });
            // A print's step is a power of ten, written as such; an encoder's is fitted.
            let show = |x: f64| match kind {
                GridKind::Print => format!("{x}"),
                GridKind::Encoder => rounded(x, 1e-3 * x),
            };
            let step = if hi - lo > 1e-3 * hi {
                format!("{} to {}", show(lo), show(hi))
            } else {
                show(hi)
            };
            let half_ms = 1e3 * first.smoothing_half_width_s;
            let n = grids.len();
            Some(match kind {
                GridKind::Encoder => format!(
                    "the reference of {n} of {total} runs lies on an encoder's grid of {step} deg: the re-simulation takes the motion's rate over a ±{half_ms:.0} ms moving average and rounds its own reference to the grid"
                ),
                GridKind::Print => format!(
                    "the reference of {n} of {total} runs is printed to {step} deg: the re-simulation keeps that rounding in the reference and out of the gyro's rate (a quintic smoothing of ±{half_ms:.0} ms), as the real gyro never saw it"
                ),
            })
        })
        .collect()
}

/// True if the turns' evidence wrote a correction into the model file.
pub(super) fn turns_wrote(d: &Diagnosis) -> bool {
    d.turns.as_ref().is_some_and(|t| {
        t.lag.as_ref().is_some_and(|l| l.written) || t.scale.as_ref().is_some_and(|s| s.written)
    })
}

/// What the movements show rest to rest ([`gyro_diagnose::turns`]), one line
/// each: a lag too long for the per-sample statistics, the turns' scale, and the
/// movements the reference does not follow.
pub fn turn_lines(d: &Diagnosis) -> Vec<String> {
    let Some(t) = &d.turns else {
        return Vec::new();
    };
    let mut lines = Vec::new();
    if let Some(lag) = t.lag.as_ref().filter(|l| l.beyond_statistic) {
        let (lo, hi) = lag.train_range_s;
        let held = lag.holdout_median_s.map_or(String::new(), |h| {
            format!("; {:.0} ms on the held-out runs", 1e3 * h)
        });
        let what = if lag.median_s >= 0.0 { "lags" } else { "leads" };
        let written = match (lag.written, lag.holdout_max_abs_error_deg) {
            (true, Some((b, a))) => format!(
                "written as the model's reference_delay_s (held-out median max |angle error| {b:.2} -> {a:.2} deg)"
            ),
            (false, Some((b, a))) => format!(
                "not written: as the model's reference_delay_s it did not lower the held-out angle error ({b:.2} -> {a:.2} deg)"
            ),
            _ => "not written: the starting model has a reference delay".into(),
        };
        lines.push(format!(
            "the gyro {what} the reference by {:.0} ms ({:.0} to {:.0} over the training runs{held}), beyond the per-sample statistics' ±{:.0} ms, so latency and bandwidth cannot be fitted there; the turns are judged rest to rest, where it does not matter; {written}",
            1e3 * lag.median_s.abs(),
            1e3 * lo,
            1e3 * hi,
            1e3 * gyro_diagnose::Settings::DEFAULT.statistics.max_lag_s
        ));
    }
    if let Some(s) = &t.scale {
        let pct = |x: f64| format!("{:+.2}%", 100.0 * x);
        let (kb, ka) = s.holdout_k;
        let (rb, ra) = s.holdout_turn_rms_deg;
        let (better, runs) = s.holdout_runs_better;
        let held = format!(
            "held out, the {} turns' own scale {} -> {} and their RMS error {rb:.2} -> {ra:.2} deg with it, better on {better} of {runs} runs",
            t.holdout_turns,
            pct(kb),
            pct(ka)
        );
        let verdict = if s.written {
            "written (config.correction.scale_k)".to_string()
        } else if s.named {
            format!("named, not corrected: it did not lower the held-out turns' error significantly (bootstrap P {:.2})", s.bootstrap_p)
        } else {
            "not named: within its noise, or the held-out turns do not show it".to_string()
        };
        lines.push(format!(
            "the turns, rest to rest: the gyro reads {} [{}, {}] of the reference's turn ({} training turns, z {:.1}); {held}: {verdict}",
            pct(s.k),
            pct(s.ci95.0),
            pct(s.ci95.1),
            t.train_turns,
            s.z
        ));
    }
    if !t.untracked.is_empty() {
        let gyro: Vec<f64> = t.untracked.iter().map(|u| u.gyro_deg.abs()).collect();
        let lo = gyro.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = gyro.iter().copied().fold(0.0, f64::max);
        let reference = t
            .untracked
            .iter()
            .map(|u| u.reference_deg.abs())
            .fold(0.0, f64::max);
        let mut runs: Vec<&str> = t.untracked.iter().map(|u| u.run.as_str()).collect();
        runs.dedup();
        lines.push(format!(
            "seen in the data, not in the vocabulary: {} movements the reference does not follow, in {} runs: the gyro turns {lo:.1} to {hi:.1} deg while the reference turns at most {reference:.2} deg: a turn about another axis seen through a mount off the reference's axes (cross-axis sensitivity), or motion the reference misses",
            t.untracked.len(),
            runs.len()
        ));
    }
    lines
}

/// The effective noise on moving data, training runs beside held-out ones.
fn effective_noise_line(e: &gyro_diagnose::effective::EffectiveNoise) -> Option<String> {
    let t = e.training.as_ref()?;
    let held_out = e.holdout.as_ref().map_or(String::new(), |h| {
        format!(
            "; on the held-out runs {} deg/sqrt(h) ({:.0}x)",
            sig3(h.arw_deg_per_rt_h),
            h.ratio_to_model
        )
    });
    Some(format!(
        "effective noise on moving data: angle random walk at most {} deg/sqrt(h) on the training runs ({:.0}x {} {}; read from 1 to 10 s in what the deterministic terms leave of gyro minus reference){held_out}: what a filter must assume on this motion (--noise-yaml writes it)",
        sig3(t.arw_deg_per_rt_h),
        t.ratio_to_model,
        t.whose(),
        sig3(t.model_arw_deg_per_rt_h)
    ))
}

/// `x` to three significant digits.
pub fn sig3(x: f64) -> String {
    rounded(x, 0.005 * x.abs())
}

/// How many statistics the selected model leaves unexplained on the training runs, in
/// words; [`super::words::missed`] says the largest ones.
fn unexplained_line(d: &Diagnosis) -> String {
    format!(
        "the model does not explain the training runs: {} of the statistics compared stay outside its simulation (gap G {} where a model that explains the runs reaches about {}); no effect of the vocabulary, as selected, brings them in; the largest:",
        d.unexplained.len(),
        sig3(d.gap.train_after),
        sig3(d.gap.floor),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn latency(v: f64, lo: f64, hi: f64) -> EffectResult {
        EffectResult {
            id: "latency",
            params: BTreeMap::from([("delay_s", v)]),
            delta_bic: Some(34_905_881.7),
            holdout_gap_before: 1.0,
            holdout_gap_after: Some(1.0),
            fraction_closed: Some(0.0),
            significant: true,
            ci95: BTreeMap::from([("delay_s", [Some(lo), Some(hi)])]),
            z: Some(10.0),
            holdout_z: None,
            shape_loglik: None,
            test: String::new(),
            bootstrap_p: Some(0.0),
            confounded_with: Vec::new(),
            posterior_check: None,
        }
    }

    #[test]
    fn a_latency_reads_in_milliseconds_rounded_to_its_interval() {
        let s = sentence(&latency(0.012_618, 0.012_31, 0.012_93));
        assert_eq!(s, "the gyro lags the reference by 12.6 [12.3, 12.9] ms");
    }

    #[test]
    fn a_scale_says_which_way_the_gyro_reads() {
        let scale = |k: f64| EffectResult {
            id: "scale_factor",
            params: BTreeMap::from([("k", k)]),
            ci95: BTreeMap::from([("k", [Some(k - 0.0003), Some(k + 0.0003)])]),
            ..latency(0.0, 0.0, 0.0)
        };
        assert_eq!(
            sentence(&scale(-0.015)),
            "the gyro reads 1.50 [1.47, 1.53] % less than the reference (scale factor)"
        );
        assert_eq!(
            sentence(&scale(0.0059)),
            "the gyro reads 0.59 [0.56, 0.62] % more than the reference (scale factor)"
        );
    }

    #[test]
    fn a_clause_alone_keeps_at_most_three_digits() {
        let e = latency(0.012_618, 0.012_31, 0.012_93);
        assert_eq!(clause(&e, false), "lags the reference by 12.6 ms");
        let clock = EffectResult {
            id: "clock_error",
            params: BTreeMap::from([("ppm", -1091.4)]),
            ci95: BTreeMap::from([("ppm", [Some(-1093.0), Some(-1090.0)])]),
            ..latency(0.0, 0.0, 0.0)
        };
        assert_eq!(
            clause(&clock, false),
            "samples 1091 ppm slow against the declared sample rate (its time stamps show it)"
        );
    }

    #[test]
    fn degrees_read_as_a_person_writes_them() {
        assert_eq!(degrees(7.204), "7.2°");
        assert_eq!(degrees(38.4), "38°");
        assert_eq!(degrees(0.4512), "0.45°");
        assert_eq!(degrees(f64::NAN), "-");
        assert_eq!(
            and_list(&["a".to_string(), "b".to_string(), "c".to_string()]),
            "a, b and c"
        );
    }

    #[test]
    fn evidence_words_follow_kass_and_raftery() {
        assert_eq!(evidence(34_905_881.7), "decisive");
        assert_eq!(evidence(7.0), "strong");
        assert_eq!(evidence(3.0), "positive");
        assert_eq!(evidence(1.0), "barely worth mentioning");
        assert_eq!(evidence(-4.0), "none");
    }

    #[test]
    fn a_quantised_reference_is_said_once_per_kind_of_grid() {
        use gyro_diagnose::{GridKind, ReferenceGrid, RunSummary};
        let run = |grid: Option<(f64, GridKind, f64)>| RunSummary {
            name: "r".into(),
            role: "train",
            duration_s: 60.0,
            gap_before: 1.0,
            gap_after: 1.0,
            reference_grid: grid.map(|(step_deg, kind, smoothing_half_width_s)| ReferenceGrid {
                step_deg,
                kind,
                smoothing_half_width_s,
            }),
            z: Vec::new(),
        };
        assert!(reference_grid_lines(&[run(None), run(None)]).is_empty());
        let lines = reference_grid_lines(&[
            run(Some((0.001, GridKind::Print, 0.04))),
            run(Some((0.001, GridKind::Print, 0.04))),
            run(None),
            run(Some((0.08775, GridKind::Encoder, 0.01))),
        ]);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(
            lines[0].starts_with(
                "the reference of 1 of 4 runs lies on an encoder's grid of 0.08775 deg"
            ),
            "{}",
            lines[0]
        );
        assert!(
            lines[1].starts_with("the reference of 2 of 4 runs is printed to 0.001 deg"),
            "{}",
            lines[1]
        );
        assert!(lines[1].contains("±40 ms"), "{}", lines[1]);
    }

    #[test]
    fn rounding_keeps_one_digit_of_the_interval() {
        assert_eq!(rounded(0.6123, 0.05), "0.61");
        assert_eq!(rounded(4.5681, 0.09), "4.57");
        assert_eq!(rounded(626.72, 171.0), "627");
        assert_eq!(rounded(f64::NAN, 1.0), "-");
    }
}
