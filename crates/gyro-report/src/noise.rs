//! Rendering a [`Characterization`]: a human-readable table, the JSON of `noise`, and the
//! PSD as CSV.

use crate::plot::sig;
use gyro_analysis::noise::{Characterization, FitTerm, NoiseLog, NoiseRun, NoiseType, Psd};
use serde::Serialize;
use std::fmt::Write as _;
use std::io::{self, Write};

fn mark(term: &FitTerm) -> &'static str {
    if term.significant {
        "*"
    } else {
        " "
    }
}

/// The answer for one data set in a few lines, in the trade's units: the bias, the white
/// noise and what it does to the angle, the bias stability, and the terms the fit finds
/// significant (and those it does not).
pub fn answer(c: &Characterization) -> Vec<String> {
    let f = &c.fit;
    let mut lines = vec![format!(
        "bias (mean rate at rest) {:.4} deg/s; white noise (angle random walk) {:.3} deg/√h: on its own it leaves an angle error of about {:.3} deg (1 σ) after 1 minute of integration",
        c.mean_rate_dps,
        f.arw_deg_per_rt_h,
        f.arw_deg_per_rt_h * (1.0f64 / 60.0).sqrt()
    )];
    lines.push(format!(
        "bias stability: the Allan deviation bottoms out at {} deg/s ({} deg/h) when averaged over {} s{}",
        sig(f.floor.adev_dps, 3),
        sig(3600.0 * f.floor.adev_dps, 3),
        sig(f.floor.tau_s, 3),
        if f.floor.at_longest_tau {
            " (at the longest averaging time: it may fall further on a longer log)"
        } else {
            ""
        }
    ));
    lines.push(fitted_terms_line(c));
    lines
}

/// The fitted terms beside the white noise in one line: those the fit finds significant,
/// in words and units, then those it does not.
fn fitted_terms_line(c: &Characterization) -> String {
    let f = &c.fit;
    let mut found = Vec::new();
    let mut not_found = Vec::new();
    let mut term = |significant: bool, found_text: String, name: &str| {
        if significant {
            found.push(found_text);
        } else {
            not_found.push(name.to_string());
        }
    };
    term(
        f.quantization_deg.significant,
        format!("quantisation {:.2e} deg", f.quantization_deg.value),
        "quantisation",
    );
    term(
        f.bias_instability_dps.significant,
        format!(
            "bias instability {} deg/s ({} deg/h)",
            sig(f.bias_instability_dps.value, 3),
            sig(3600.0 * f.bias_instability_dps.value, 3)
        ),
        "bias instability",
    );
    term(
        f.rate_random_walk_dps_per_rt_s.significant,
        format!(
            "rate random walk {:.2e} deg/s/√s{}",
            f.rate_random_walk_dps_per_rt_s.value,
            gyro_analysis::noise::rate_random_walk_look_alike(c).map_or(String::new(), |(t, _)| {
                format!(
                    " (or a Gauss-Markov bias of correlation time near or beyond {} s: this log is too short to tell them apart)",
                    sig(t, 3)
                )
            })
        ),
        "rate random walk",
    );
    let gm = &f.gauss_markov;
    term(
        gm.significant,
        format!(
            "a Gauss-Markov bias wander of σ {} deg/s{}",
            sig(gm.sigma_dps, 3),
            gm.corr_time_s
                .map_or_else(String::new, |t| format!(" over {} s", sig(t, 3)))
        ),
        "Gauss-Markov bias wander",
    );
    format!(
        "beside the white noise the fit finds {}{}",
        if found.is_empty() {
            "nothing significant".to_string()
        } else {
            found.join(", ")
        },
        if not_found.is_empty() {
            String::new()
        } else {
            format!("; not significant: {}", not_found.join(", "))
        }
    )
}

/// The Allan table, the fitted terms and the PSD summary of one data set, titled `label`:
/// the [`answer`] first.
pub fn table(label: &str, c: &Characterization) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "== {label}: {} samples at {} Hz ({:.1} s) in {} stretch{}; mean {:.5} deg/s, sd {:.5} deg/s{}",
        c.samples,
        c.sample_rate_hz,
        c.duration_s,
        c.segments,
        if c.segments == 1 { "" } else { "es" },
        c.mean_rate_dps,
        c.std_rate_dps,
        c.rate_step_dps
            .map_or(String::new(), |v| format!(", output step {v:.6} deg/s"))
    );
    for line in answer(c) {
        let _ = writeln!(s, "  {line}");
    }
    let _ = writeln!(s, "details:");
    allan_table(&mut s, c);
    fit_lines(&mut s, c);
    match &c.psd {
        Some(psd) => psd_lines(&mut s, psd),
        None => {
            let _ = writeln!(s, "PSD: no stretch long enough for a window");
        }
    }
    if !c.suggested_effects.is_empty() {
        suggested_effects_lines(&mut s, c);
    }
    s
}

/// The Allan deviation per τ with its bounds, the noise type and the fitted model.
fn allan_table(s: &mut String, c: &Characterization) {
    let _ = writeln!(
        s,
        "Allan deviation (overlapping; {:.1}% chi-squared bounds, EDF by the fitted model's noise type; noise: the type the fit takes at that τ):",
        100.0 * c.allan.confidence
    );
    let _ = writeln!(
        s,
        "  {:>10} {:>12} {:>12} {:>12} {:>14} {:>12}",
        "tau_s", "adev_dps", "lower_dps", "upper_dps", "noise", "model_dps"
    );
    for p in &c.allan.points {
        let noise = match p.noise {
            NoiseType::WhitePm => "white_pm",
            NoiseType::WhiteFm => "white_fm",
            NoiseType::FlickerFm => "flicker_fm",
            NoiseType::RandomWalkFm => "random_walk_fm",
        };
        let _ = writeln!(
            s,
            "  {:>10.4} {:>12.4e} {:>12.4e} {:>12.4e} {:>14} {:>12.4e}",
            p.tau_s,
            p.adev_dps,
            p.lower_dps,
            p.upper_dps,
            noise,
            c.fit.adev(p.tau_s)
        );
    }
}

/// The fit: each term with its significance and misfit increase, then the Allan floor
/// and the misfit.
fn fit_lines(s: &mut String, c: &Characterization) {
    let f = &c.fit;
    let _ = writeln!(
        s,
        "Fit (weighted non-negative least squares on the Allan variance; * significant, Δ = misfit increase without the term):"
    );
    let n = &f.arw_dps_per_rt_hz;
    let _ = writeln!(
        s,
        "  {} angle random walk N  {:.4e} deg/s/√Hz = {:.4} deg/√h  (Δ {:.1})",
        mark(n),
        n.value,
        f.arw_deg_per_rt_h,
        n.delta_cost
    );
    let q = &f.quantization_deg;
    let _ = writeln!(
        s,
        "  {} quantisation Q       {:.4e} deg  (Δ {:.1})",
        mark(q),
        q.value,
        q.delta_cost
    );
    let b = &f.bias_instability_dps;
    let _ = writeln!(
        s,
        "  {} bias instability B   {:.4e} deg/s  (Δ {:.1})",
        mark(b),
        b.value,
        b.delta_cost
    );
    let k = &f.rate_random_walk_dps_per_rt_s;
    let _ = writeln!(
        s,
        "  {} rate random walk K   {:.4e} deg/s/√s  (Δ {:.1})",
        mark(k),
        k.value,
        k.delta_cost
    );
    gauss_markov_lines(s, c);
    let _ = writeln!(
        s,
        "  floor: min adev {:.4e} deg/s at τ {:.4} s -> B = min/0.664 = {:.4e} deg/s{}",
        f.floor.adev_dps,
        f.floor.tau_s,
        f.floor.bias_instability_dps,
        if f.floor.at_longest_tau {
            " (at the longest τ: an upper bound)"
        } else {
            ""
        }
    );
    let _ = writeln!(s, "  misfit {:.1} over {} τ points", f.cost, f.points);
}

/// The Gauss-Markov term, and whether it is the sensor's bandwidth rather than a bias.
fn gauss_markov_lines(s: &mut String, c: &Characterization) {
    let gm = &c.fit.gauss_markov;
    let _ = writeln!(
        s,
        "  {} Gauss-Markov bias    σ {:.4e} deg/s, T {}  (Δ {:.1})",
        if gm.significant { "*" } else { " " },
        gm.sigma_dps,
        gm.corr_time_s
            .map_or_else(|| "-".to_string(), |t| format!("{t:.4} s")),
        gm.delta_cost
    );
    if let Some((_, t)) = gyro_analysis::noise::export::bandwidth_term(c) {
        let _ = writeln!(
            s,
            "    T under {} s: white noise through the sensor's own low-pass (1/(2πT) = {:.1} Hz), not a bias wander; --noise-yaml reads N from τ 1–10 s and leaves the term out of K",
            gyro_analysis::noise::export::BANDWIDTH_GM_MAX_S,
            1.0 / (std::f64::consts::TAU * t)
        );
    }
}

/// The PSD's settings, its white density and one line per half decade.
fn psd_lines(s: &mut String, psd: &Psd) {
    let _ = writeln!(
        s,
        "PSD (Welch, Hann, 50% overlap, {} samples per segment, {} averaged, {:.4} Hz resolution):",
        psd.segment_len, psd.segments, psd.resolution_hz
    );
    let _ = writeln!(
        s,
        "  white density {:.4e} deg/s/√Hz = {:.4} deg/√h (over {:.3}–{:.3} Hz)",
        psd.white_density_dps_per_rt_hz,
        psd.white_arw_deg_per_rt_h,
        psd.white_band_hz.0,
        psd.white_band_hz.1
    );
    let _ = writeln!(s, "  {:>22} {:>16}", "band_hz", "psd_dps2_per_hz");
    // One line per half decade of the ten-per-decade bands.
    for chunk in psd.bands.chunks(5) {
        let bins: usize = chunk.iter().map(|b| b.bins).sum();
        let mean = chunk
            .iter()
            .map(|b| b.psd_dps2_per_hz * b.bins as f64)
            .sum::<f64>()
            / bins.max(1) as f64;
        if let (Some(first), Some(last)) = (chunk.first(), chunk.last()) {
            let _ = writeln!(
                s,
                "  {:>10.4}–{:<11.4} {:>16.4e}",
                first.low_hz, last.high_hz, mean
            );
        }
    }
}

/// The effects outside the sensor model's form that would simulate this noise, as
/// `--effect` options, and what else the rate random walk may be.
fn suggested_effects_lines(s: &mut String, c: &Characterization) {
    let specs: Vec<String> = c
        .suggested_effects
        .iter()
        .map(|e| {
            let params: Vec<String> = e
                .info()
                .params
                .iter()
                .zip(e.params())
                .map(|(spec, v)| format!("{}={v:.4e}", spec.name))
                .collect();
            format!("--effect {}:{}", e.id(), params.join(","))
        })
        .collect();
    let _ = writeln!(
        s,
        "Not in the sensor model's form; to simulate: {}",
        specs.join(" ")
    );
    if let Some((t, sigma)) = gyro_analysis::noise::rate_random_walk_look_alike(c) {
        let _ = writeln!(
            s,
            "  it may also be the sensor model's own Gauss-Markov bias seen on too short a log: one of correlation time T near or beyond the longest averaging time here ({} s) and σ = K·√(T/2) ({} deg/s at that T) gives the same Allan deviation; a log several T long tells them apart",
            sig(t, 3),
            sig(sigma, 3)
        );
    }
}

/// The full PSD as CSV rows `label,frequency_hz,psd_dps2_per_hz` (no header).
pub fn psd_csv(out: &mut impl Write, label: &str, c: &Characterization) -> io::Result<()> {
    if let Some(psd) = &c.psd {
        for (f, p) in psd.frequency_hz.iter().zip(&psd.psd_dps2_per_hz) {
            writeln!(out, "{label},{f},{p:e}")?;
        }
    }
    Ok(())
}

/// The tables of every log (labelled with what was irregular in it) and of all pooled.
pub fn tables(logs: &[NoiseLog], run: &NoiseRun) -> String {
    let mut s = String::new();
    for (l, r) in logs.iter().zip(&run.results) {
        let irregular = l.input.filled_slots + l.input.duplicate_rows;
        let label = if irregular > 0 {
            format!(
                "{} ({} samples interpolated, {} duplicates dropped)",
                l.file, l.input.filled_slots, l.input.duplicate_rows
            )
        } else {
            l.file.clone()
        };
        if let Some(warning) = gyro_analysis::noise::moving_warning(l) {
            let _ = writeln!(s, "warning: {warning}");
        }
        let _ = writeln!(s, "{}", table(&label, r));
    }
    if let Some(c) = &run.combined {
        let label = format!("all {} logs pooled", logs.len());
        let _ = writeln!(s, "{}", table(&label, c));
    }
    s
}

#[derive(Serialize)]
struct LogJson<'a> {
    file: &'a str,
    /// Rest stretches used (s from the log's start), when only rests were used.
    #[serde(skip_serializing_if = "Option::is_none")]
    rest_stretches_s: Option<Vec<(f64, f64)>>,
    input: &'a gyro_log::Quality,
    /// Share of the log in motion, when taken whole.
    #[serde(skip_serializing_if = "Option::is_none")]
    moving_share: Option<f64>,
    /// What makes the figures mean less than they seem (a log taken whole that moves).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    warnings: Vec<String>,
    #[serde(flatten)]
    result: &'a Characterization,
}

#[derive(Serialize)]
struct RunJson<'a> {
    logs: Vec<LogJson<'a>>,
    combined: Option<&'a Characterization>,
    model_out: Option<&'a str>,
}

/// The JSON of `noise`: each log (with its rest stretches when `rests_only`), the pooled
/// result, and the model file written (if any).
pub fn json(
    logs: &[NoiseLog],
    run: &NoiseRun,
    rests_only: bool,
    model_out: Option<&str>,
) -> serde_json::Result<String> {
    serde_json::to_string_pretty(&RunJson {
        logs: logs
            .iter()
            .zip(&run.results)
            .map(|(l, r)| LogJson {
                file: &l.file,
                rest_stretches_s: rests_only.then(|| l.stretches_s()),
                input: &l.input,
                moving_share: l.moving_share,
                warnings: gyro_analysis::noise::moving_warning(l)
                    .into_iter()
                    .collect(),
                result: r,
            })
            .collect(),
        combined: run.combined.as_ref(),
        model_out,
    })
}
