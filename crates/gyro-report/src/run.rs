//! Rendering a [`RunReport`]: a human table, JSON, or CSV; and the 50 Hz series as CSV.

use gyro_analysis::findings::Finding;
use gyro_analysis::replay::{MovementResult, RunReport, SeriesPoint, Summary};
use gyro_core::{Tightening, Verdict};
use std::fmt::Write as _;
use std::io::{self, Write};

fn opt(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.decimals$}"))
}

/// A human-readable report, with the run's `findings` ([`gyro_analysis::findings::of_run`])
/// after the summary, one `warning:` line each.
pub fn table(file: &str, report: &RunReport, findings: &[Finding]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "file: {file}");
    s.push_str(&crate::input::table(&report.input));
    processing_lines(&mut s, report);
    let _ = writeln!(s, "movements: {}", report.movements.len());
    if !report.movements.is_empty() {
        movements_table(&mut s, report);
        if let Some(t) = &report.config.tightening {
            tightening_line(&mut s, t, &report.movements);
        }
    }
    summary_lines(&mut s, &report.summary);
    for f in findings {
        let _ = writeln!(s, "warning: {}", f.message);
    }
    s
}

/// How the run was processed: the pipeline, then (where they apply) the offline mode, the
/// correction, the reference's shift and the rejected samples.
fn processing_lines(s: &mut String, report: &RunReport) {
    let c = &report.config;
    let _ = writeln!(
        s,
        "pipeline: decimate x{} -> {} Hz{}, Butterworth order {} at {} Hz, compensation {}{}",
        report.decimation_factor,
        report.output_rate_hz,
        report
            .output_rate_lowered_from_hz
            .map_or(String::new(), |hz| format!(
                " (the log's rate, below the configured {hz} Hz)"
            )),
        c.filter.order,
        c.filter.cutoff_hz,
        match c.compensation {
            gyro_core::Compensation::None => "none",
            gyro_core::Compensation::Paper => "paper",
            gyro_core::Compensation::Kalman => "kalman",
        },
        c.range_dps
            .map_or(String::new(), |r| format!(", sensor range ±{r} deg/s"))
    );
    if report.mode == gyro_analysis::replay::Mode::Offline {
        let _ = writeln!(
            s,
            "mode: offline (each movement's angle and σ from the log's rests before and after it)"
        );
    }
    let k = &c.correction;
    if !k.is_identity() {
        let temperature = match report.temperature_reference_c {
            Some(t) => format!("ΔT from {t:.2} °C"),
            None => "no temperature: temperature terms not applied".into(),
        };
        let _ = writeln!(
            s,
            "correction: scale {:+.5}, asymmetry {:+.5}, {:+.5} deg/s/°C, scale {:+.3e} /°C ({temperature})",
            k.scale_k, k.asymmetry_k, k.bias_dps_per_c, k.scale_per_c
        );
    }
    if report.reference_delay_s != 0.0 {
        let _ = writeln!(
            s,
            "reference shifted by the gyro's latency, {:.4} s",
            report.reference_delay_s
        );
    }
    if report.summary.rejected_samples > 0 {
        let _ = writeln!(
            s,
            "  rejected input samples: {}",
            report.summary.rejected_samples
        );
    }
}

/// The movements, one row each: the σ column only when some movement has one, the
/// verdict column only for a tightening.
fn movements_table(s: &mut String, report: &RunReport) {
    let with_std = report.movements.iter().any(|m| m.angle_std_deg.is_some());
    let with_verdict = report.config.tightening.is_some();
    let _ = write!(
        s,
        "  {:>4} {:>10} {:>10} {:>8} {:>11} {:>11} {:>11} {:>10} {:>10}",
        "#", "start_s", "end_s", "dur_s", "angle_deg", "raw_deg", "ref_deg", "error_deg", "raw_err"
    );
    if with_std {
        let _ = write!(s, " {:>8}", "std_deg");
    }
    if with_verdict {
        let _ = write!(s, " {:>8}", "verdict");
    }
    let _ = writeln!(s);
    for m in &report.movements {
        let _ = write!(
            s,
            "  {:>4} {:>10.3} {:>10.3} {:>8.3} {:>11.3} {:>11.3} {:>11} {:>10} {:>10}",
            m.index,
            m.start_time_s,
            m.end_time_s,
            m.duration_s,
            m.angle_deg,
            m.raw_angle_deg,
            opt(m.reference_deg, 3),
            opt(m.error_deg, 3),
            opt(m.raw_error_deg, 3),
        );
        if with_std {
            let _ = write!(s, " {:>8}", opt(m.angle_std_deg.map(f64::from), 3));
        }
        if with_verdict {
            let _ = write!(s, " {:>8}", m.verdict.map_or("-", verdict_name));
        }
        let marks = movement_marks(m);
        if marks.is_empty() {
            let _ = writeln!(s);
        } else {
            let _ = writeln!(s, "  {}", marks.join(" "));
        }
    }
}

/// What makes a movement's figures doubtful: saturation, filled gaps, a cut-off end.
fn movement_marks(m: &MovementResult) -> Vec<String> {
    let mut marks = Vec::new();
    if m.saturated {
        marks.push("SATURATED".to_string());
    }
    if m.filled_samples > 0 {
        marks.push(format!("GAP ({} samples filled)", m.filled_samples));
    }
    if !m.complete {
        marks.push("(log ends while moving)".to_string());
    }
    marks
}

/// The tightening's settings and how many movements got each verdict.
fn tightening_line(s: &mut String, t: &Tightening, movements: &[MovementResult]) {
    let count = |v: Option<Verdict>| movements.iter().filter(|m| m.verdict == v).count();
    // A movement against the tightening's direction gets no verdict.
    let other_way = count(None);
    let _ = writeln!(
        s,
        "tightening {} ± {} deg ({} direction, guard band {} σ{}): ok {}, nok {}, recheck {}, invalid {}; {} turned the other way",
        t.target_deg,
        t.tolerance_deg,
        match t.direction {
            gyro_core::Direction::Positive => "positive",
            gyro_core::Direction::Negative => "negative",
        },
        t.k_sigma,
        if t.scale_sigma > 0.0 {
            format!(", scale uncertainty {}%", 100.0 * t.scale_sigma)
        } else {
            String::new()
        },
        count(Some(Verdict::Ok)),
        count(Some(Verdict::Nok)),
        count(Some(Verdict::Recheck)),
        count(Some(Verdict::Invalid)),
        other_way
    );
}

/// The run's duration and final angle, and its errors against the reference if any.
fn summary_lines(s: &mut String, sm: &Summary) {
    let _ = writeln!(
        s,
        "summary: {:.1} s, final angle {:.3} deg (uncompensated {:.3} deg)",
        sm.duration_s, sm.final_angle_deg, sm.final_raw_angle_deg
    );
    if sm.max_abs_error_deg.is_some() {
        let _ = writeln!(
            s,
            "  error vs reference: max abs {} deg, RMS {} deg, final {} deg",
            opt(sm.max_abs_error_deg, 4),
            opt(sm.rms_error_deg, 4),
            opt(sm.final_error_deg, 4)
        );
        let _ = writeln!(
            s,
            "  uncompensated:      max abs {} deg, RMS {} deg, final {} deg",
            opt(sm.raw_max_abs_error_deg, 4),
            opt(sm.raw_rms_error_deg, 4),
            opt(sm.raw_final_error_deg, 4)
        );
    } else {
        let _ = writeln!(s, "  no reference_deg column: no error figures");
    }
}

/// The JSON name of a verdict.
fn verdict_name(verdict: Verdict) -> &'static str {
    match verdict {
        Verdict::Ok => "ok",
        Verdict::Nok => "nok",
        Verdict::Recheck => "recheck",
        Verdict::Invalid => "invalid",
    }
}

/// JSON: `{"file", "input", "config", "summary", "movements", "warnings", "findings"}`:
/// `warnings` the findings' sentences, `findings` the findings with their codes and where
/// they lie; both always present (`[]` when there is none).
pub fn json(file: &str, report: &RunReport, findings: &[Finding]) -> serde_json::Result<String> {
    #[derive(serde::Serialize)]
    struct WithFile<'a> {
        file: &'a str,
        #[serde(flatten)]
        report: &'a RunReport,
        /// What makes the figures and verdicts mean less than they seem, one sentence each.
        warnings: Vec<&'a str>,
        /// The same, with codes and places.
        findings: &'a [Finding],
    }
    serde_json::to_string_pretty(&WithFile {
        file,
        report,
        warnings: findings.iter().map(|f| f.message.as_str()).collect(),
        findings,
    })
}

/// CSV of the movements.
pub fn movements_csv(out: &mut impl Write, movements: &[MovementResult]) -> io::Result<()> {
    writeln!(
        out,
        "index,start_time_s,end_time_s,duration_s,complete,angle_deg,raw_angle_deg,reference_deg,error_deg,raw_error_deg,saturated,filled_samples,angle_std_deg,verdict"
    )?;
    for m in movements {
        writeln!(
            out,
            "{},{:.6},{:.6},{:.6},{},{:.6},{:.6},{},{},{},{},{},{},{}",
            m.index,
            m.start_time_s,
            m.end_time_s,
            m.duration_s,
            m.complete,
            m.angle_deg,
            m.raw_angle_deg,
            m.reference_deg.map_or(String::new(), |v| format!("{v:.6}")),
            m.error_deg.map_or(String::new(), |v| format!("{v:.6}")),
            m.raw_error_deg.map_or(String::new(), |v| format!("{v:.6}")),
            m.saturated,
            m.filled_samples,
            m.angle_std_deg.map_or(String::new(), |v| format!("{v:.6}")),
            m.verdict.map_or("", verdict_name),
        )?;
    }
    Ok(())
}

/// CSV of the output series (the `--out` file): the run's findings as comments
/// ([`series_csv_findings`]), [`series_csv_header`], then [`series_csv_row`] for each point.
pub fn series_csv(
    out: &mut impl Write,
    report: &RunReport,
    findings: &[Finding],
) -> io::Result<()> {
    series_csv_findings(out, findings)?;
    series_csv_header(out, report.output_rate_hz)?;
    for p in &report.series {
        series_csv_row(out, p)?;
    }
    Ok(())
}

/// The run's findings as the series CSV's first comment lines, `# warning (code): …`.
pub fn series_csv_findings(out: &mut impl Write, findings: &[Finding]) -> io::Result<()> {
    for f in findings {
        writeln!(out, "# warning ({}): {}", f.code, f.message)?;
    }
    Ok(())
}

/// The lines of the series CSV before its rows: the output rate and the column names.
pub fn series_csv_header(out: &mut impl Write, output_rate_hz: f32) -> io::Result<()> {
    writeln!(out, "# output_rate_hz: {output_rate_hz}")?;
    writeln!(
        out,
        "time_s,rate_dps,motion,angle_deg,raw_angle_deg,angle_std_deg,bias_dps,reference_deg,error_deg"
    )
}

/// One row of the series CSV.
pub fn series_csv_row(out: &mut impl Write, p: &SeriesPoint) -> io::Result<()> {
    writeln!(
        out,
        "{:.6},{:.5},{},{:.6},{:.6},{},{:.6},{},{}",
        p.time_s,
        p.rate_dps,
        match p.motion {
            gyro_core::MotionState::Static => "static",
            gyro_core::MotionState::Dynamic => "dynamic",
        },
        p.angle_deg,
        p.raw_angle_deg,
        p.angle_std_deg.map_or(String::new(), |v| format!("{v:.6}")),
        p.bias_dps,
        p.reference_deg.map_or(String::new(), |v| format!("{v:.6}")),
        p.error_deg().map_or(String::new(), |v| format!("{v:.6}")),
    )
}
