//! Rendering a [`RunReport`]: a human table, JSON, or CSV; and the 50 Hz series as CSV.

use gyro_analysis::replay::{MovementResult, RunReport, SeriesPoint};
use gyro_core::Verdict;
use std::fmt::Write as _;
use std::io::{self, Write};

fn opt(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.decimals$}"))
}

/// A human-readable report.
pub fn table(file: &str, report: &RunReport) -> String {
    let mut s = String::new();
    let q = &report.input;
    let c = &report.config;
    let _ = writeln!(s, "file: {file}");
    s.push_str(&crate::input::table(q));
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
    let _ = writeln!(s, "movements: {}", report.movements.len());
    if !report.movements.is_empty() {
        let with_std = report.movements.iter().any(|m| m.angle_std_deg.is_some());
        let with_verdict = c.tightening.is_some();
        let _ = write!(
            s,
            "  {:>4} {:>10} {:>10} {:>8} {:>11} {:>11} {:>11} {:>10} {:>10}",
            "#",
            "start_s",
            "end_s",
            "dur_s",
            "angle_deg",
            "raw_deg",
            "ref_deg",
            "error_deg",
            "raw_err"
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
            if marks.is_empty() {
                let _ = writeln!(s);
            } else {
                let _ = writeln!(s, "  {}", marks.join(" "));
            }
        }
        for m in report.movements.iter().filter(|m| m.saturated) {
            let _ = writeln!(s, "warning: {}", saturation_warning(m.index, c.range_dps));
        }
        if let Some(warning) = range_warning(report) {
            let _ = writeln!(s, "warning: {warning}");
        }
        for m in report.movements.iter().filter(|m| m.filled_samples > 0) {
            let _ = writeln!(
                s,
                "warning: movement {} spans {} interpolated input samples (a gap or missing rates in the log): its angle across them is a guess",
                m.index, m.filled_samples
            );
        }
        if let Some(t) = &c.tightening {
            let count = |v: Verdict| {
                report
                    .movements
                    .iter()
                    .filter(|m| m.verdict == Some(v))
                    .count()
            };
            let other_way = report
                .movements
                .iter()
                .filter(|m| m.verdict.is_none())
                .count();
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
                count(Verdict::Ok),
                count(Verdict::Nok),
                count(Verdict::Recheck),
                count(Verdict::Invalid),
                other_way
            );
            for warning in unguarded_warning(report)
                .into_iter()
                .chain(scale_warning(report))
            {
                let _ = writeln!(s, "warning: {warning}");
            }
        }
    }
    let sm = &report.summary;
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
        if let Some(warning) = lag_warning(report) {
            let _ = writeln!(s, "warning: {warning}");
        }
    } else {
        let _ = writeln!(s, "  no reference_deg column: no error figures");
    }
    s
}

/// Every warning about what the figures and verdicts mean, in the order the table gives
/// them: the JSON's `warnings`, and stderr for the CSV.
pub fn warnings(report: &RunReport) -> Vec<String> {
    rate_warning(report)
        .into_iter()
        .chain(range_warning(report))
        .chain(unguarded_warning(report))
        .chain(scale_warning(report))
        .chain(lag_warning(report))
        .collect()
}

/// The warning for a log slower than the configured output rate, run at its own rate
/// ([`gyro_analysis::replay::config_for_rate`]): the low-pass is scaled with it, so the
/// rate is smoothed more than the configuration says.
pub fn rate_warning(report: &RunReport) -> Option<String> {
    let configured_hz = report.output_rate_lowered_from_hz?;
    Some(gyro_analysis::replay::lowered_rate_note(
        report.sample_rate_hz,
        configured_hz,
        report.config.filter.cutoff_hz,
    ))
}

/// The warning for readings beyond the sensor range in use: a sensor reads at most its
/// range, so that range is not this one's (a model file's sensor section holds the
/// CRM100's ±300 deg/s unless it says otherwise). From the first such reading the core
/// flags saturation on clip plateaus only; a movement that ended before it may still be
/// flagged for reaching the range.
pub fn range_warning(report: &RunReport) -> Option<String> {
    let range_dps = report.config.range_dps?;
    report.summary.range_contradicted.then(|| {
        format!(
            "readings reach {:.1} deg/s, beyond the sensor range of ±{range_dps} deg/s in use: that range is not this sensor's, so from the first such reading only clip plateaus flag a movement saturated (one that ended before it may still be flagged for reaching the range); give --range-dps with the sensor's full scale",
            report.summary.largest_abs_rate_dps
        )
    })
}

/// The warning for tightening verdicts without a σ: only the Kalman form gives a movement
/// one, so in the other compensations the guard band holds only the scale term and an
/// `ok` may sit on a bias error of any size.
pub fn unguarded_warning(report: &RunReport) -> Option<String> {
    let t = report.config.tightening.as_ref()?;
    if report.config.compensation == gyro_core::Compensation::Kalman {
        return None;
    }
    let mode = match report.config.compensation {
        gyro_core::Compensation::None => "none",
        _ => "paper",
    };
    Some(format!(
        "the verdicts have no σ: only the Kalman form gives a movement one, and with compensation {mode} the guard band is {}, so an `ok` does not allow for the bias; run with --compensation kalman for a guarded decision",
        if t.scale_sigma > 0.0 {
            format!("only the scale term ({}% of the angle)", 100.0 * t.scale_sigma)
        } else {
            "zero".to_string()
        }
    ))
}

/// The warning for tightening verdicts without a scale uncertainty: σ holds the bias and
/// the noise, not the scale factor, which on an uncalibrated MEMS gyro is off by 0.5–2%
/// (1–3° on a 150° turn, the rasteiro recordings), far beyond σ (0.03–0.25° there).
pub fn scale_warning(report: &RunReport) -> Option<String> {
    let t = report.config.tightening.as_ref()?;
    (t.scale_sigma == 0.0).then(|| {
        "the guard band holds the bias and the noise (σ), not the gyro's scale error: uncalibrated, a MEMS gyro's scale is off by 0.5-2% (1-3 deg on a 150 deg turn), far beyond σ; give --scale-sigma (a datasheet's tolerance, e.g. 0.02) or a model from `calibrate` (its scale_sigma)".to_string()
    })
}

/// The warning for a gyro that lags (or leads) the reference it is scored against by at
/// least [`gyro_analysis::lag::NOTABLE_S`]: the errors during turns are then mostly the
/// lag's, not the sensor's.
pub fn lag_warning(report: &RunReport) -> Option<String> {
    let lag_s = report.summary.reference_lag_s?;
    if lag_s.abs() < gyro_analysis::lag::NOTABLE_S {
        return None;
    }
    let how = if lag_s > 0.0 { "lags" } else { "leads" };
    let scored = if report.reference_delay_s == 0.0 {
        "the reference as logged".to_string()
    } else {
        format!(
            "the reference (shifted by {:.1} ms)",
            1e3 * report.reference_delay_s
        )
    };
    Some(format!(
        "the gyro {how} {scored} by {:.0} ms (cross-correlation of the rates): the errors against it during turns are the rate times that, not the sensor's; score with --reference-delay-s {:.3} (or a model file's reference_delay_s: `calibrate` measures and writes it)",
        1e3 * lag_s.abs(),
        report.reference_delay_s + lag_s,
    ))
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

/// Why movement `index` is flagged saturated, and what that means for its angle.
fn saturation_warning(index: usize, range_dps: Option<f32>) -> String {
    let what = match range_dps {
        Some(r) => format!("reached the sensor range ({r} deg/s) or clipped below it"),
        None => format!(
            "clipped ({} or more identical readings, and {} ms or more of them, at >= {} \
             deg/s, {} deg/s ahead of the filtered rate or lasting {} ms; sensor range \
             unknown)",
            gyro_core::CLIP_PLATEAU_SAMPLES,
            gyro_core::CLIP_PLATEAU_SHORT_S * 1000.0,
            gyro_core::CLIP_PLATEAU_MIN_DPS,
            gyro_core::CLIP_PLATEAU_LEAD_DPS,
            gyro_core::CLIP_PLATEAU_LONG_S * 1000.0
        ),
    };
    format!("movement {index} {what}: its angle is a lower bound")
}

/// JSON: `{"file", "input", "config", "summary", "movements", ...}`.
pub fn json(file: &str, report: &RunReport) -> serde_json::Result<String> {
    #[derive(serde::Serialize)]
    struct WithFile<'a> {
        file: &'a str,
        #[serde(flatten)]
        report: &'a RunReport,
        /// What makes the figures and verdicts mean less than they seem ([`warnings`]).
        #[serde(skip_serializing_if = "Vec::is_empty")]
        warnings: Vec<String>,
    }
    serde_json::to_string_pretty(&WithFile {
        file,
        report,
        warnings: warnings(report),
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

/// CSV of the output series (the `--out` file): [`series_csv_header`], then
/// [`series_csv_row`] for each point.
pub fn series_csv(out: &mut impl Write, report: &RunReport) -> io::Result<()> {
    series_csv_header(out, report.output_rate_hz)?;
    for p in &report.series {
        series_csv_row(out, p)?;
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
