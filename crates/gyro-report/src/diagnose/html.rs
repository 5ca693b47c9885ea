//! `diagnose --report DIR`: one self-contained HTML page (`index.html`: inline CSS and
//! inline SVG figures, nothing fetched from anywhere) and the [`Diagnosis`] as
//! `diagnosis.json` beside it.
//!
//! The page holds the gap figures, the verdict, the nominal model and its provenance,
//! the ranked effects, the largest "where" z-scores, the per-run gaps, and figures of real
//! data against simulated envelopes, each with a note on how to read it.
//!
//! **Envelopes.** The figures draw [`Envelopes`], which the analysis computes
//! ([`gyro_diagnose::envelopes`]): real data against the same statistics of
//! simulated runs, a band spanning the members' minimum to maximum with their median
//! dashed (the cross-correlation's: a 95% band, mean ± 1.96 sd of the members). The gap
//! map and the tables use every run. The page renders; it computes nothing.

use super::sig3;
use crate::plot::diagnose_plot::{
    AngleErrorPlot, AngleErrorRow, Band, EnvelopePlot, GapMapPlot, Measured, Panel,
};
use crate::plot::{render, sig, Figure, ImageFormat, RenderError};
use gyro_diagnose::envelopes::{
    quantile, Bins, Envelopes, Measures, Moments, SimModel, PSD_BANDS_PER_DECADE,
};
use gyro_diagnose::{Diagnosis, EffectResult, Options};
use gyro_sim::EFFECTS;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Colours of the gap map saturate at this |z|.
pub const GAP_MAP_CLIP: f64 = 10.0;
/// Most statistics (columns) in the gap map, by combined |z|.
pub const GAP_MAP_COLUMNS: usize = 120;
/// Rows of the "where" table.
pub const WHERE_ROWS: usize = 20;

/// Why the report could not be written; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The directory could not be created.
    #[error("cannot create {}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The diagnosis could not be encoded as JSON.
    #[error("cannot encode the diagnosis for {}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: serde_json::Error,
    },
    /// A figure could not be drawn.
    #[error("cannot draw the figure \"{figure}\" of {}", path.display())]
    Figure {
        /// The page.
        path: PathBuf,
        /// Which figure.
        figure: &'static str,
        /// What went wrong.
        #[source]
        source: RenderError,
    },
}

/// Fewest real samples for a bin to be shown.
pub const MIN_BIN_SAMPLES: f64 = 20.0;

/// The files [`write_report`] writes into its folder: the diagnosis as JSON, the page.
pub const REPORT_FILES: [&str; 2] = ["diagnosis.json", "index.html"];

/// Write `dir/diagnosis.json` and `dir/index.html` ([`REPORT_FILES`]), each whole, for the
/// diagnosis `d` computed with `options`, its figures drawn from `envelopes` (none: the
/// page says there is no run to draw).
pub fn write_report(
    dir: &Path,
    d: &Diagnosis,
    envelopes: Option<&Envelopes>,
    options: &Options,
) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let [json_name, html_name] = REPORT_FILES;
    let json_path = dir.join(json_name);
    let json = serde_json::to_string_pretty(d).map_err(|source| ReportError::Json {
        path: json_path.clone(),
        source,
    })?;
    let write = |w: &mut _| std::io::Write::write_all(w, json.as_bytes());
    gyro_log::whole::write(&json_path, write).map_err(|source| ReportError::Write {
        path: json_path.clone(),
        source,
    })?;
    let html_path = dir.join(html_name);
    let html = page(d, envelopes, options, &html_path)?;
    let write = |w: &mut _| std::io::Write::write_all(w, html.as_bytes());
    gyro_log::whole::write(&html_path, write).map_err(|source| ReportError::Write {
        path: html_path.clone(),
        source,
    })
}

// ---------------------------------------------------------------------------------------
// Envelopes.

/// Band over members of `values[member][point]` at `x`.
fn band_of(label: &str, x: &[f64], values: &[Vec<f64>]) -> Band {
    let mut lo = Vec::with_capacity(x.len());
    let mut mid = Vec::with_capacity(x.len());
    let mut hi = Vec::with_capacity(x.len());
    for i in 0..x.len() {
        let mut column: Vec<f64> = values
            .iter()
            .filter_map(|v| v.get(i).copied())
            .filter(|v| v.is_finite())
            .collect();
        lo.push(quantile(&mut column, 0.0).unwrap_or(f64::NAN));
        mid.push(quantile(&mut column, 0.5).unwrap_or(f64::NAN));
        hi.push(quantile(&mut column, 1.0).unwrap_or(f64::NAN));
    }
    Band {
        label: label.to_string(),
        x: x.to_vec(),
        lo,
        mid,
        hi,
    }
}

/// A 95% band over members of `values[member][point]` at `x`: mean ± 1.96 sd (normal).
fn normal_band_of(label: &str, x: &[f64], values: &[Vec<f64>]) -> Band {
    let mut lo = Vec::with_capacity(x.len());
    let mut mid = Vec::with_capacity(x.len());
    let mut hi = Vec::with_capacity(x.len());
    for i in 0..x.len() {
        let mut m = Moments::default();
        values
            .iter()
            .filter_map(|v| v.get(i).copied())
            .filter(|v| v.is_finite())
            .for_each(|v| m.add(v));
        let (mean, sd) = (m.mean(), m.std());
        lo.push(mean - 1.96 * sd);
        mid.push(mean);
        hi.push(mean + 1.96 * sd);
    }
    Band {
        label: label.to_string(),
        x: x.to_vec(),
        lo,
        mid,
        hi,
    }
}

/// Values of `curve` (x, y) at `x` (NaN where absent; x matched exactly).
fn at_x(curve: &[(f64, f64)], x: &[f64]) -> Vec<f64> {
    x.iter()
        .map(|xi| {
            curve
                .iter()
                .find(|(cx, _)| (cx - xi).abs() <= 1e-9 * xi.abs().max(1e-12))
                .map_or(f64::NAN, |p| p.1)
        })
        .collect()
}

fn band_label(model: &SimModel, members: usize) -> String {
    format!(
        "{}: range of {members} simulated sets, median dashed",
        model.label
    )
}

fn allan_plot(f: &Envelopes) -> EnvelopePlot {
    let real = f.real.allan_curve(f.setup.fs);
    let x: Vec<f64> = real.iter().map(|p| p.0).collect();
    let bands = f
        .models
        .iter()
        .zip(&f.sims)
        .map(|(m, sims)| {
            let values: Vec<Vec<f64>> = sims
                .iter()
                .map(|s| at_x(&s.allan_curve(f.setup.fs), &x))
                .collect();
            band_of(&band_label(m, f.members), &x, &values)
        })
        .collect();
    let empty = real.is_empty().then(|| {
        "no static segment (|reference rate| < 1 deg/s for at least 0.5 s) in these runs"
            .to_string()
    });
    EnvelopePlot {
        title: "Allan deviation of the static residual".into(),
        subtitle: "gyro − reference rate on still segments, pooled over the runs".into(),
        panels: vec![Panel {
            x_desc: "averaging time τ (s)".into(),
            y_desc: "Allan deviation (deg/s)".into(),
            log: true,
            measured: Some(Measured {
                label: "real runs".into(),
                x,
                y: real.iter().map(|p| p.1).collect(),
                bars: None,
                markers: false,
            }),
            bands,
            zero_lines: false,
            empty,
        }],
    }
}

fn psd_plot(f: &Envelopes) -> EnvelopePlot {
    let real = f.real.psd_bands(&f.setup);
    let x: Vec<f64> = real.iter().map(|p| p.0).collect();
    let bands = f
        .models
        .iter()
        .zip(&f.sims)
        .map(|(m, sims)| {
            let values: Vec<Vec<f64>> = sims
                .iter()
                .map(|s| s.psd_bands(&f.setup).iter().map(|p| p.1).collect())
                .collect();
            band_of(&band_label(m, f.members), &x, &values)
        })
        .collect();
    EnvelopePlot {
        title: "Power spectral density of the residual".into(),
        subtitle: format!(
            "Welch, Hann windows of {} samples ({} s), averaged over {} bands per decade; whole runs",
            f.setup.psd_len,
            sig(f.setup.psd_len as f64 / f.setup.fs, 3),
            PSD_BANDS_PER_DECADE
        ),
        panels: vec![Panel {
            x_desc: "frequency (Hz)".into(),
            y_desc: "PSD ((deg/s)²/Hz)".into(),
            log: true,
            measured: Some(Measured {
                label: "real runs".into(),
                x,
                y: real.iter().map(|p| p.1).collect(),
                bars: None,
                markers: false,
            }),
            bands,
            zero_lines: false,
            empty: (real.is_empty()).then(|| {
                format!(
                    "no stretch of {} samples with a residual",
                    f.setup.psd_len
                )
            }),
        }],
    }
}

/// A binned-residual panel from `pick` (which bins of a `Measures`).
fn binned_panel(
    f: &Envelopes,
    bins: &Bins,
    pick: &dyn Fn(&Measures) -> &Vec<Moments>,
    x_desc: &str,
) -> Panel {
    let centres = bins.centres();
    let real = pick(&f.real);
    let keep: Vec<usize> = (0..centres.len())
        .filter(|&k| real.get(k).is_some_and(|m| m.n >= MIN_BIN_SAMPLES))
        .collect();
    let x: Vec<f64> = keep.iter().map(|&k| centres[k]).collect();
    let mean: Vec<f64> = keep.iter().map(|&k| real[k].mean()).collect();
    let sd: Vec<f64> = keep.iter().map(|&k| real[k].std()).collect();
    let bands = f
        .models
        .iter()
        .zip(&f.sims)
        .map(|(m, sims)| {
            let values: Vec<Vec<f64>> = sims
                .iter()
                .map(|s| {
                    let b = pick(s);
                    keep.iter()
                        .map(|&k| b.get(k).map_or(f64::NAN, Moments::mean))
                        .collect()
                })
                .collect();
            band_of(
                &format!(
                    "{}: range of the bin means of {} simulated sets",
                    m.label, f.members
                ),
                &x,
                &values,
            )
        })
        .collect();
    Panel {
        x_desc: x_desc.into(),
        y_desc: "residual (deg/s)".into(),
        log: false,
        measured: Some(Measured {
            label: "real runs: bin mean, bars ±1 sd of the samples".into(),
            bars: Some((
                mean.iter().zip(&sd).map(|(m, s)| m - s).collect(),
                mean.iter().zip(&sd).map(|(m, s)| m + s).collect(),
            )),
            x,
            y: mean,
            markers: true,
        }),
        bands,
        zero_lines: true,
        empty: keep
            .is_empty()
            .then(|| format!("no bin with {MIN_BIN_SAMPLES} real samples")),
    }
}

fn residual_plot(f: &Envelopes) -> EnvelopePlot {
    let rate = binned_panel(
        f,
        &f.setup.rate,
        &|m| &m.rate,
        "reference rate (deg/s), all samples",
    );
    let temperature = match &f.setup.temperature {
        Some(bins) => binned_panel(
            f,
            bins,
            &|m| &m.temperature,
            "temperature change since the run's start (°C), static samples",
        ),
        None => Panel {
            empty: Some(format!(
                "no temperature panel: the runs have no temperature, or it varies by less than {} °C on static samples",
                gyro_diagnose::Settings::DEFAULT.statistics.min_temperature_range_c
            )),
            ..Panel::default()
        },
    };
    let acceleration = binned_panel(
        f,
        &f.setup.acceleration,
        &|m| &m.acceleration,
        "reference angular acceleration (deg/s²), dynamic samples",
    );
    EnvelopePlot {
        title: "Residual (gyro − reference rate) against rate, temperature and acceleration".into(),
        subtitle: "binned over the runs; simulated sets re-simulate the same runs".into(),
        panels: vec![rate, temperature, acceleration],
    }
}

/// Lag (s) of the largest value of `c` over `lags_s`, refined by a parabola.
fn peak_lag(c: &[f64], lags_s: &[f64]) -> Option<f64> {
    let (k, _) = c
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if k == 0 || k + 1 >= c.len() {
        return Some(lags_s[k]);
    }
    let (a, b, d) = (c[k - 1], c[k], c[k + 1]);
    let denom = a - 2.0 * b + d;
    let step = lags_s[k + 1] - lags_s[k];
    let offset = if denom < 0.0 {
        (0.5 * (a - d) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    Some(lags_s[k] + offset * step)
}

/// One curve per member.
type Curves = Vec<Vec<f64>>;

/// The cross-correlation figure, and a sentence on the peak lags.
fn xcorr_plot(f: &Envelopes) -> (EnvelopePlot, String) {
    let lags_s: Vec<f64> = f
        .setup
        .lags
        .iter()
        .map(|l| *l as f64 / f.setup.fs)
        .collect();
    let x: Vec<f64> = lags_s.iter().map(|l| l * 1e3).collect();
    let real = f.real.xcorr_curve();
    let per_model: Vec<Curves> = f
        .sims
        .iter()
        .map(|sims| sims.iter().map(Measures::xcorr_curve).collect())
        .collect();
    let nominal_mean = per_model
        .first()
        .map(|v| normal_band_of("", &x, v).mid)
        .unwrap_or_default();
    let minus =
        |v: &[f64]| -> Vec<f64> { v.iter().zip(&nominal_mean).map(|(a, b)| a - b).collect() };
    let bands = |values: &dyn Fn(&Curves) -> Curves| -> Vec<Band> {
        f.models
            .iter()
            .zip(&per_model)
            .map(|(m, v)| {
                let label = format!(
                    "{}: 95% band (mean ± 1.96 sd of {} simulated sets), mean dashed",
                    m.label, f.members
                );
                normal_band_of(&label, &x, &values(v))
            })
            .collect()
    };
    let peaks = peak_lags_text(f, &real, &per_model, &lags_s);
    let real_line = |y: Vec<f64>| Measured {
        label: "real runs".into(),
        x: x.clone(),
        y,
        bars: None,
        markers: false,
    };
    let top = Panel {
        x_desc: "lag (ms)".into(),
        y_desc: "normalised cross-correlation".into(),
        log: false,
        measured: Some(real_line(real.clone())),
        bands: bands(&|v| v.clone()),
        zero_lines: true,
        empty: None,
    };
    let bottom = Panel {
        x_desc: "lag (ms)".into(),
        y_desc: "minus the nominal mean".into(),
        log: false,
        measured: Some(real_line(minus(&real))),
        bands: bands(&|v| v.iter().map(|c| minus(c)).collect()),
        zero_lines: true,
        empty: None,
    };
    let plot = EnvelopePlot {
        title: "Cross-correlation of gyro rate and reference rate".into(),
        subtitle:
            "means removed per run, pooled over the runs; below: minus the nominal ensemble's mean"
                .into(),
        panels: vec![top, bottom],
    };
    (plot, peaks)
}

/// The peak lags in words: the real runs' (`real`), then each model's range over its
/// simulated sets (`per_model`); `lags_s` are the curves' lags.
fn peak_lags_text(f: &Envelopes, real: &[f64], per_model: &[Curves], lags_s: &[f64]) -> String {
    let ms = |v: Option<f64>| v.map_or("–".to_string(), |s| sig(s * 1e3, 3));
    let mut peaks = format!(
        "Peak lag (positive: the gyro lags the reference): real runs {} ms",
        ms(peak_lag(real, lags_s))
    );
    for (m, v) in f.models.iter().zip(per_model) {
        let lags: Vec<f64> = v.iter().filter_map(|c| peak_lag(c, lags_s)).collect();
        let lo = lags.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = lags.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() {
            let _ = write!(
                peaks,
                "; {} {} to {} ms",
                esc(&m.label),
                sig(lo * 1e3, 3),
                sig(hi * 1e3, 3)
            );
        }
    }
    peaks.push('.');
    peaks
}

fn gap_map(d: &Diagnosis) -> GapMapPlot {
    let mut columns: Vec<String> = d
        .r#where
        .iter()
        .map(|w| format!("{}/{}", w.segment, w.statistic))
        .collect();
    let mut extra: Vec<String> = d
        .runs
        .iter()
        .flat_map(|r| r.z.iter().map(|(k, _)| k.clone()))
        .filter(|k| !columns.contains(k))
        .collect();
    extra.sort();
    extra.dedup();
    columns.extend(extra);
    let dropped = columns.len().saturating_sub(GAP_MAP_COLUMNS);
    columns.truncate(GAP_MAP_COLUMNS);
    let z: Vec<Vec<f64>> = d
        .runs
        .iter()
        .map(|r| {
            let by: BTreeMap<&str, f64> = r.z.iter().map(|(k, v)| (k.as_str(), *v)).collect();
            columns
                .iter()
                .map(|c| by.get(c.as_str()).copied().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let holdout_from = d
        .runs
        .iter()
        .position(|r| r.role != "train")
        .unwrap_or(d.runs.len());
    let rows = d
        .runs
        .iter()
        .map(|r| {
            if r.role == "train" {
                super::run_label(d, &r.name)
            } else {
                format!("{} (held out)", super::run_label(d, &r.name))
            }
        })
        .collect();
    GapMapPlot {
        title: "Gap map: z of each run's statistics against its nominal ensemble".into(),
        subtitle: format!(
            "training runs above the line, held-out runs below; columns by combined |z|, largest left{}",
            if dropped > 0 {
                format!(" ({dropped} smallest left out)")
            } else {
                String::new()
            }
        ),
        rows,
        holdout_from,
        columns,
        z,
        clip: GAP_MAP_CLIP,
    }
}

/// What is corrected, and what is named but not corrected.
fn subtitle(c: &gyro_diagnose::CompensationSummary) -> String {
    let mut s = if c.corrected.is_empty() {
        "corrected: none (no correction lowered the held-out error)".to_string()
    } else {
        format!("corrected: {}", c.corrected.join(", "))
    };
    if !c.not_corrected.is_empty() {
        let ids: Vec<&str> = c.not_corrected.iter().map(|n| n.id).collect();
        s.push_str(&format!("; named, not corrected: {}", ids.join(", ")));
    }
    s
}

fn angle_error_plot(d: &Diagnosis) -> Option<AngleErrorPlot> {
    let c = d.compensation.as_ref()?;
    Some(AngleErrorPlot {
        title: "Held-out angle error: each run's largest error, nominal and with the written model"
            .into(),
        subtitle: subtitle(c),
        rows: c
            .runs
            .iter()
            .map(|r| AngleErrorRow {
                name: super::run_label(d, &r.name),
                before_deg: r.max_abs_error_before_deg,
                after_deg: r.max_abs_error_after_deg,
            })
            .collect(),
        before_label: "nominal configuration (run)".into(),
        after_label: "with the corrections (run --model)".into(),
    })
}

// ---------------------------------------------------------------------------------------
// HTML.

/// `text` with HTML's special characters escaped.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// `sig(x, digits)` without trailing zeros after the decimal point.
fn short(x: f64, digits: usize) -> String {
    let s = sig(x, digits);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn percent(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1}%", 100.0 * x)
    } else {
        "–".into()
    }
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "–".into()
    }
}

/// The signature of effect `id` from the effect table.
fn signature(id: &str) -> String {
    let text = EFFECTS
        .iter()
        .find(|e| e.id == id)
        .map_or("", |e| e.signature);
    format!("<code>{}</code> ({})", esc(id), esc(text))
}

/// The SVG of `figure`, for inline use (no XML namespace URL: HTML does not need it).
fn inline_svg(
    figure: &impl Figure,
    name: &'static str,
    page: &Path,
) -> Result<String, ReportError> {
    let bytes = render(figure, ImageFormat::Svg).map_err(|source| ReportError::Figure {
        path: page.to_path_buf(),
        figure: name,
        source,
    })?;
    let svg = String::from_utf8_lossy(&bytes).into_owned();
    let svg = svg.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1);
    Ok(format!(
        "<div class=\"figure\" role=\"img\" aria-label=\"{}\">\n{svg}</div>\n",
        esc(name)
    ))
}

const STYLE: &str = "body{font-family:'DejaVu Sans',Verdana,sans-serif;color:#1e1e1e;max-width:1180px;margin:1.5em auto;padding:0 1em;line-height:1.45}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.6em 0;font-size:.88em}th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}
th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
tr.sig td{background:#eef6ee}tr.sig td:first-child{font-weight:bold}
.gap{font-size:1.05em}.verdict{font-size:1.15em;padding:.5em .8em;background:#f4f4f8;border-left:4px solid #0072b2}
.figure svg{max-width:100%;height:auto;display:block}.read{background:#fafafa;border-left:3px solid #bbb;padding:.4em .8em;font-size:.92em}
.warn{color:#a04000}code{font-size:.95em}
.wide{overflow-x:auto}table.effects{font-size:.8em}
.sub{color:#555;margin-top:-.6em}.verdict p{margin:.3em 0}
details{margin:1em 0;border:1px solid #ddd;border-radius:4px;padding:.3em .8em}
summary{cursor:pointer;font-weight:bold;padding:.3em 0}";

fn effect_row(s: &mut String, e: &EffectResult) {
    let params: Vec<String> = e
        .params
        .iter()
        .map(|(k, v)| {
            let ci = e.ci95.get(k).map_or(String::new(), |[a, b]| {
                let f = |x: &Option<f64>| x.map_or("∞".to_string(), |v| sig(v, 3));
                format!(" [{}, {}]", f(a), f(b))
            });
            format!("{}&nbsp;=&nbsp;{}{}", esc(k), sig(*v, 4), esc(&ci))
        })
        .collect();
    let _ = writeln!(
        s,
        "<tr{}><td><code>{}</code></td><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
        if e.significant { " class=\"sig\"" } else { "" },
        esc(e.id),
        if e.significant {
            "yes"
        } else if super::text::fails_posterior(e) {
            "no: fails its posterior check"
        } else {
            "no"
        },
        params.join("<br>"),
        e.z.map_or("exact".to_string(), |z| format!("{z:.2}")),
        e.holdout_z.map_or("–".to_string(), |z| format!("{z:.2}")),
        e.delta_bic.map_or(super::NOT_SCORED.to_string(), |d| format!(
            "{} ({})",
            super::evidence(d),
            sig(d, 3)
        )),
        num(e.holdout_gap_before),
        num(e.holdout_gap_after.unwrap_or(f64::NAN)),
        num(e.fraction_closed.unwrap_or(f64::NAN)),
        num(e.bootstrap_p.unwrap_or(f64::NAN)),
        if e.confounded_with.is_empty() {
            "–".to_string()
        } else {
            e.confounded_with
                .iter()
                .map(|c| format!("<code>{}</code>", esc(c)))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
}

/// The test column: the parameter test and, for a bias wander, its shape evidence.
fn test_cell(e: &EffectResult) -> String {
    match e.shape_loglik {
        Some(l) => format!(
            "{}<br>shape: log-likelihood {l:.1} of the 1/4/16 s Allan variances, all runs \
             (of two look-alike wanders, the larger is named)",
            esc(&e.test)
        ),
        None => esc(&e.test),
    }
}

/// The answer first: the verdict sentences, the held-out angle error before and after the
/// written corrections, what is named, what the model still misses and the notes, in
/// plain words (the same lines as the text table's).
fn summary(s: &mut String, d: &Diagnosis, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(s, "<div class=\"verdict\">");
    for line in super::verdict(d) {
        let class = if line.starts_with("warning:") {
            " class=\"warn\""
        } else {
            ""
        };
        let _ = writeln!(s, "<p{class}>{}</p>", esc(&line));
    }
    let _ = writeln!(s, "</div>");
    match angle_error_plot(d) {
        Some(plot) if !plot.rows.is_empty() => {
            s.push_str(&inline_svg(&plot, "angle error before and after", page)?);
        }
        _ => {
            let _ = writeln!(
                s,
                "<p>No angle-error figure: {}.</p>",
                if d.verdict.unmodelled.is_empty() {
                    "no effect was named, so there is no correction to compare"
                } else {
                    "none of the named effects is one the model file corrects"
                }
            );
        }
    }
    let f = super::findings(d);
    for (title, lines, listed) in [
        ("Named", f.named, 0),
        ("What the model still misses", f.missed, f.missed_listed),
        ("Notes", f.notes, 0),
    ] {
        if lines.is_empty() {
            continue;
        }
        let _ = writeln!(s, "<h2>{title}</h2>");
        findings_list(s, &lines, listed);
    }
    Ok(())
}

/// A list of findings: warnings marked, the detection limits folded, and the `listed`
/// lines after the first nested under it (the statistics it introduces).
fn findings_list(s: &mut String, lines: &[String], listed: usize) {
    let _ = writeln!(s, "<ul>");
    for (i, line) in lines.iter().enumerate() {
        let class = if line.starts_with("warning:") {
            " class=\"warn\""
        } else {
            ""
        };
        // Long and rarely the answer: folded.
        let item = if line.starts_with(super::headline::NOT_NAMED) {
            format!(
                "<details><summary>Not named: absent, or smaller than these runs can show \
                 (the self-check's detection limits)</summary>{}</details>",
                esc(line)
            )
        } else {
            esc(line)
        };
        let open = i == 0 && listed > 0;
        let close = listed > 0 && i == listed;
        let _ = write!(s, "<li{class}>{item}");
        if open {
            let _ = writeln!(s, "\n<ul>");
        } else {
            let _ = writeln!(s, "</li>");
        }
        if close {
            let _ = writeln!(s, "</ul></li>");
        }
    }
    if listed > 0 && lines.len() <= listed {
        let _ = writeln!(s, "</ul></li>");
    }
    let _ = writeln!(s, "</ul>");
}

/// The gap G with its explanation, the ensembles, the turns and the nominal model.
fn header(s: &mut String, d: &Diagnosis, options: &Options) {
    gap_section(s, d);
    ensembles_line(s, options);
    turns_section(s, d);
    nominal_model_section(s, d);
}

/// The verdict in the statistics' terms, the gap G's table and what G is.
fn gap_section(s: &mut String, d: &Diagnosis) {
    let g = &d.gap;
    let verdict = if d.verdict.unmodelled.is_empty() {
        "nothing significant: no candidate effect closes the held-out gap".to_string()
    } else {
        format!(
            "unmodelled: {}; they close {} of the held-out gap G above the floor (G is not in degrees: the angle error is above)",
            d.verdict
                .unmodelled
                .iter()
                .map(|u| format!("<code>{}</code>", esc(u)))
                .collect::<Vec<_>>()
                .join(", "),
            percent(d.verdict.fraction_closed_holdout)
        )
    };
    let _ = writeln!(s, "<p><b>In the statistics' terms:</b> {verdict}.</p>");
    let _ = writeln!(
        s,
        "<table class=\"gap\"><tr><th>gap G</th><th>nominal model</th><th>with the selected effects</th></tr>\
<tr><td>training runs</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>\
<tr><td>held-out runs</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>\
<tr><td>floor</td><td class=\"n\" colspan=\"2\">{}</td></tr></table>",
        num(g.train_before),
        num(g.train_after),
        num(g.holdout_before),
        num(g.holdout_after),
        num(g.floor)
    );
    let _ = writeln!(
        s,
        "<p><b>G</b> is the RMS of the z-scores of the “where” statistics of every run against \
that run's simulated ensemble (the same motion, temperatures and processing, re-simulated \
with the model); G near the floor means the simulation explains the data as well as it \
explains itself. The <b>floor</b> is G between two independent simulated ensembles. \
Effects are fitted on the training runs only and scored on the held-out runs.</p>"
    );
}

/// The ensembles' sizes, seed and bootstrap resamples (with a warning when small).
fn ensembles_line(s: &mut String, options: &Options) {
    let _ = writeln!(
        s,
        "<p>Ensembles: {} members per run (baseline), {} per held-out run for each candidate whose test passes; seed {}; {} bootstrap resamples.{}</p>",
        options.members,
        options.candidate_members,
        options.seed,
        options.bootstrap,
        if options.members < 50 {
            " <span class=\"warn\">Fewer than 50 baseline members: the z-scores and G are rough.</span>"
        } else {
            ""
        }
    );
}

/// The nominal sensor model, where its values come from and the effects added to it.
fn nominal_model_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>Nominal model</h2>");
    let m = &d.model.sensor;
    let _ = writeln!(
        s,
        "<table><tr><th>sample rate</th><th>bias</th><th>angle random walk</th><th>Gauss-Markov σ</th><th>Gauss-Markov T</th><th>output step</th><th>range</th></tr>\
<tr><td class=\"n\">{} Hz</td><td class=\"n\">{} deg/s</td><td class=\"n\">{} deg/√h</td><td class=\"n\">{} deg/s</td><td class=\"n\">{} s</td><td class=\"n\">{} deg/s</td><td class=\"n\">±{} deg/s</td></tr></table>",
        short(m.sample_rate_hz, 4),
        short(m.bias_dps, 4),
        short(m.arw_deg_per_rt_h, 4),
        short(m.gm_sigma_dps, 3),
        short(m.gm_tau_s, 3),
        short(m.lsb_dps, 4),
        short(m.range_dps, 4)
    );
    let _ = writeln!(s, "<p>Where the values come from:</p><ul>");
    for n in &d.model.notes {
        let _ = writeln!(s, "<li>{}</li>", esc(n));
    }
    let _ = writeln!(s, "</ul>");
    model_effects_list(s, d);
}

/// The selected effects added to the model, each with its parameters and units.
fn model_effects_list(s: &mut String, d: &Diagnosis) {
    if d.model.effects.is_empty() {
        let _ = writeln!(s, "<p>No effect was added to the model.</p>");
    } else {
        let _ = writeln!(s, "<p>Selected effects added to it:</p><ul>");
        for e in &d.model.effects {
            let info = e.info();
            let params: Vec<String> = info
                .params
                .iter()
                .zip(e.params())
                .map(|(spec, v)| {
                    let unit = if spec.unit == "1" {
                        String::new()
                    } else {
                        format!(" {}", esc(spec.unit))
                    };
                    format!("{}&nbsp;=&nbsp;{}{unit}", esc(spec.name), short(v, 4))
                })
                .collect();
            let _ = writeln!(
                s,
                "<li><code>{}</code>: {}</li>",
                esc(info.id),
                params.join(", ")
            );
        }
        let _ = writeln!(s, "</ul>");
    }
}

/// The posterior checks of the named effects and of those left out for failing theirs.
fn posterior_table(s: &mut String, d: &Diagnosis) {
    let rows: Vec<_> = d
        .effects
        .iter()
        .filter_map(|e| e.posterior_check.as_ref().map(|c| (e, c)))
        .filter(|(e, c)| super::text::shows_posterior(e, c))
        .collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(s, "<h2>Posterior checks</h2>");
    let _ = writeln!(
        s,
        "<p>Before an effect is named, the held-out runs simulated with it (and the other named \
effects) must reproduce the statistics that identify it: their ensembles cover the real value \
(95% band of the pooled mean), or leave at most half of the nominal model's discrepancy. An \
effect that fails is not named and the selection is made again without it.</p>"
    );
    let _ = writeln!(
        s,
        "<table><tr><th>effect</th><th>statistic</th><th>real</th><th>nominal</th><th>with the effect</th><th>±95%</th><th>check</th></tr>"
    );
    for (e, c) in rows {
        if c.unmeasured {
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td colspan=\"5\">{}</td><td><span class=\"warn\">fails</span></td></tr>",
                esc(e.id),
                esc(&c.describe())
            );
        }
        for st in &c.statistics {
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td>{} {}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
                esc(e.id),
                esc(&st.segment.to_string()),
                esc(&st.statistic.to_string()),
                short(st.real, 4),
                short(st.nominal, 4),
                short(st.with_effect, 4),
                short(st.band, 2),
                if st.passes { "passes" } else { "<span class=\"warn\">fails</span>" }
            );
        }
    }
    let _ = writeln!(s, "</table>");
}

/// What the movements show rest to rest: the lag searched wide, the turns' scale, and
/// the movements the reference does not follow, one row per run.
fn turns_section(s: &mut String, d: &Diagnosis) {
    let Some(t) = &d.turns else {
        return;
    };
    if t.train_turns == 0 && t.untracked.is_empty() {
        return;
    }
    let _ = writeln!(s, "<h2>Turns, rest to rest</h2>");
    let _ = writeln!(
        s,
        "<p>Each movement's total, the angle and the reference read at the middle of the rests \
around it: what neither a reference reported late or coarsely nor the per-sample statistics \
change. A scale is named when it is at least 4 standard errors and 0.1% from zero and the \
held-out turns keep at most half of their own scale with it; it is written when it lowers \
the held-out turns' RMS error (paired over held-out runs, bootstrap P &lt; 5%).</p>"
    );
    let pct = |x: f64| format!("{:+.2}%", 100.0 * x);
    let _ = writeln!(
        s,
        "<table><tr><th></th><th>training</th><th>held out</th></tr>\
<tr><td>turns (reference ≥ 10°)</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
        t.train_turns, t.holdout_turns
    );
    if let Some(l) = &t.lag {
        let _ = writeln!(
            s,
            "<tr><td>gyro–reference lag, searched within ±500 ms (median; + the gyro lags)</td><td class=\"n\">{:.1} ms [{:.1}, {:.1}]</td><td class=\"n\">{}</td></tr>",
            1e3 * l.median_s,
            1e3 * l.train_range_s.0,
            1e3 * l.train_range_s.1,
            l.holdout_median_s
                .map_or("–".to_string(), |h| format!("{:.1} ms", 1e3 * h))
        );
    }
    if let Some(k) = &t.scale {
        let _ = writeln!(
            s,
            "<tr><td>scale of the turns (95% interval)</td><td class=\"n\">{} [{}, {}]</td><td class=\"n\">{} → {} with it</td></tr>\
<tr><td>turn RMS error</td><td></td><td class=\"n\">{:.2}° → {:.2}°, better on {} of {} runs</td></tr>\
<tr><td>scale verdict</td><td colspan=\"2\">{}</td></tr>",
            pct(k.k),
            pct(k.ci95.0),
            pct(k.ci95.1),
            pct(k.holdout_k.0),
            pct(k.holdout_k.1),
            k.holdout_turn_rms_deg.0,
            k.holdout_turn_rms_deg.1,
            k.holdout_runs_better.0,
            k.holdout_runs_better.1,
            if k.written {
                "named and written (<code>config.correction.scale_k</code>)"
            } else if k.named {
                "named, not corrected"
            } else {
                "not named"
            }
        );
    }
    let _ = writeln!(s, "</table>");
    if !t.untracked.is_empty() {
        let _ = writeln!(
            s,
            "<p>Movements the reference does not follow (the gyro turns, the reference less than \
half as much): a turn about another axis seen through a mount off the reference's axes, or \
motion the reference misses. No effect of the vocabulary expresses them.</p>\
<table><tr><th>run</th><th>gyro</th><th>reference</th></tr>"
        );
        for u in &t.untracked {
            let _ = writeln!(
                s,
                "<tr><td>{}</td><td class=\"n\">{:+.2}°</td><td class=\"n\">{:+.2}°</td></tr>",
                esc(&super::run_label(d, &u.run)),
                u.gyro_deg,
                u.reference_deg
            );
        }
        let _ = writeln!(s, "</table>");
    }
}

fn tables(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>Candidate effects, ranked</h2>");
    let _ = writeln!(
        s,
        "<p>Significant effects first, then by held-out gap reduction. An effect is significant \
when its parameter test passes on the training runs (|z| ≥ 4; for a regression coefficient \
also on all the runs: at least 2 on the training and the held-out runs alike, 4 pooled), its \
held-out ΔBIC is positive and the bootstrap over held-out runs gives P(no improvement) &lt; \
0.05 or, for a regression coefficient, the held-out z reaches 2 (an effect seen directly in \
the raw data — a clip plateau, an output grid, gaps — when the same direct test passes on the \
held-out runs too); one that adds nothing once the others are in the model is confounded \
with them and not named. An effect whose parameter test does not pass can never be named and \
is not scored on the held-out runs (“not scored”; <code>--score-every-candidate</code> scores \
it too). Intervals are 95%; \
z is the parameter test on the training runs (“exact” where the test is not a z-test), \
held-out z the same coefficient's test on the held-out runs, in the same direction; \
“closed” is (before − after) / (before − floor).</p>"
    );
    let _ = writeln!(
        s,
        "<div class=\"wide\"><table class=\"effects\"><tr><th>effect</th><th>significant</th><th>parameters [95% interval]</th><th>z</th><th>held-out z</th><th>held-out evidence (ΔBIC)</th><th>held-out G before</th><th>after</th><th>closed</th><th>bootstrap p</th><th>confounded with</th></tr>"
    );
    for e in &d.effects {
        effect_row(s, e);
    }
    let _ = writeln!(s, "</table></div>");
    let _ = writeln!(s, "<p>How each candidate's parameter was tested:</p><ul>");
    for e in &d.effects {
        let _ = writeln!(s, "<li><code>{}</code>: {}</li>", esc(e.id), test_cell(e));
    }
    let _ = writeln!(s, "</ul>");
    if !d.untestable.is_empty() {
        let _ = writeln!(
            s,
            "<p>Effects that could not be tested on these runs:</p><ul>"
        );
        for u in &d.untestable {
            let _ = writeln!(s, "<li><code>{}</code>: {}</li>", esc(u.id), esc(&u.reason));
        }
        let _ = writeln!(s, "</ul>");
    }

    posterior_table(s, d);

    unexplained_table(s, d);

    where_table(s, d);

    runs_table(s, d);
}

/// Where the gap lies: the statistics with the largest |z| of real against nominal.
fn where_table(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>Where the gap lies</h2>");
    let _ = writeln!(
        s,
        "<p>The {WHERE_ROWS} statistics with the largest |z| of real against the nominal ensembles, \
combined over all runs (Σz/√n). Positive: the real value is above the simulated ones.</p>"
    );
    let _ = writeln!(
        s,
        "<table><tr><th>z</th><th>what it is</th><th>segment</th><th>statistic</th></tr>"
    );
    for w in d.r#where.iter().take(WHERE_ROWS) {
        let _ = writeln!(
            s,
            "<tr><td class=\"n\">{:.1}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            w.z,
            esc(&super::described(&w.segment, &w.statistic)),
            esc(&w.segment),
            esc(&w.statistic)
        );
    }
    let _ = writeln!(s, "</table>");
}

/// The runs: each one's role, duration and gap before and after the selected effects.
fn runs_table(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>Runs</h2>");
    let _ = writeln!(
        s,
        "<table><tr><th>run</th><th>role</th><th>duration</th><th>G nominal</th><th>G with the selected effects</th></tr>"
    );
    for r in &d.runs {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td class=\"n\">{} s</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            esc(&super::run_label(d, &r.name)),
            esc(r.role),
            sig(r.duration_s, 4),
            num(r.gap_before),
            num(r.gap_after)
        );
    }
    let _ = writeln!(s, "</table>");
}

/// The statistics the selected model leaves unexplained on the training runs.
fn unexplained_table(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>What the model leaves unexplained</h2>");
    if d.unexplained.is_empty() {
        let _ = writeln!(
            s,
            "<p>Every statistic of the training runs is within |z| &lt; {} of its simulated ensemble with the selected model: it fits the sensor at hand.</p>",
            gyro_diagnose::locate::UNEXPLAINED_Z
        );
        return;
    }
    let _ = writeln!(
        s,
        "<p class=\"warn\">The model does not fit the training runs: {} statistics stay at |z| ≥ {} \
against their ensembles with the selected effects (G {} against a floor of {}). No effect of the \
vocabulary, as selected, brings them to the simulation; they are what the sensor (or the rig, or \
the reference) does that the model cannot say. Real and simulated values are means over the \
training runs; the held-out z is with the same model.</p>",
        d.unexplained.len(),
        gyro_diagnose::locate::UNEXPLAINED_Z,
        sig3(d.gap.train_after),
        sig3(d.gap.floor)
    );
    let _ = writeln!(
        s,
        "<table><tr><th>what it is</th><th>statistic</th><th>segment</th><th>real</th><th>nominal model</th><th>selected model</th><th>z nominal</th><th>z selected</th><th>z held out</th></tr>"
    );
    for u in &d.unexplained {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            esc(&super::described(&u.segment, &u.statistic)),
            esc(&u.statistic),
            esc(&u.segment),
            sig3(u.real),
            sig3(u.nominal),
            sig3(u.simulated),
            sig3(u.z_train_nominal),
            sig3(u.z_train),
            sig3(u.z_holdout)
        );
    }
    let _ = writeln!(s, "</table>");
}

/// Draw `plot` into `s`, or, when none of its panels has anything to draw, one line
/// saying why; true if drawn.
fn drawn(
    s: &mut String,
    plot: &EnvelopePlot,
    name: &'static str,
    page: &Path,
) -> Result<bool, ReportError> {
    let reasons: Vec<&str> = plot
        .panels
        .iter()
        .filter_map(|p| p.empty.as_deref())
        .collect();
    if !plot.panels.is_empty() && reasons.len() == plot.panels.len() {
        let _ = writeln!(
            s,
            "<p>{name}: nothing to draw: {}.</p>",
            esc(&reasons.join("; "))
        );
        return Ok(false);
    }
    s.push_str(&inline_svg(plot, name, page)?);
    Ok(true)
}

fn read(s: &mut String, text: &str) {
    let _ = writeln!(s, "<p class=\"read\"><b>How to read this.</b> {text}</p>");
}

/// The figures: the real data against its simulations (if any run was drawn), then
/// the gap map.
fn figures(
    s: &mut String,
    d: &Diagnosis,
    envelopes: Option<&Envelopes>,
    page: &Path,
) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h2>Figures</h2>");
    match envelopes {
        None => {
            let _ = writeln!(s, "<p>No run to draw.</p>");
        }
        Some(f) => {
            envelopes_intro(s, f);
            allan_figure(s, f, page)?;
            psd_figure(s, f, page)?;
            residual_figure(s, f, page)?;
            xcorr_figure(s, f, page)?;
        }
    }
    gap_map_figure(s, d, page)
}

/// What the envelope figures show and which runs they pool, and the runs left out.
fn envelopes_intro(s: &mut String, f: &Envelopes) {
    let _ = writeln!(
        s,
        "<p>Real data (black) against {} simulated sets of the same runs (shaded: their range, median dashed; a 95% band for the cross-correlation): blue with the nominal model{}. {}</p>",
        f.members,
        if f.models.len() > 1 {
            ", orange with the selected effects added"
        } else {
            ""
        },
        if f.runs_used < f.runs_total {
            format!(
                "To keep the report fast, the figures use {} of the {} runs (evenly spaced, training and held-out); the tables and the gap map use all.",
                f.runs_used, f.runs_total
            )
        } else {
            format!("All {} runs are pooled.", f.runs_total)
        }
    );
    for e in &f.real_errors {
        let _ = writeln!(s, "<p class=\"warn\">left out: {}</p>", esc(e));
    }
}

/// The Allan deviation, and how to read it (if drawn).
fn allan_figure(s: &mut String, f: &Envelopes, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h3>Allan deviation</h3>");
    if drawn(s, &allan_plot(f), "Allan deviation", page)? {
        read(
            s,
            &format!(
                "White rate noise falls with slope −½; the nominal Gauss-Markov bias bends the curve \
at long τ. Real above the band at short τ: more white noise or a coarser output than modelled — \
{}. Real above the band at long τ: bias wander the model lacks — {}; {}. Below the band: the \
model's noise is too large.",
                signature("quantization"),
                signature("bias_instability"),
                signature("rate_random_walk")
            ),
        );
    }
    Ok(())
}

/// The PSD of the residual, and how to read it (if drawn).
fn psd_figure(s: &mut String, f: &Envelopes, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h3>Power spectral density</h3>");
    if drawn(s, &psd_plot(f), "PSD", page)? {
        read(
            s,
            &format!(
                "The residual's spectrum over whole runs (still and moving). The flat level is the \
white noise; where the motion has power the residual picks up any rate-dependent error. \
Real below the band at high frequency: {}. Real above the band where the motion has power: \
an error that scales with the motion — {}; {}.",
                signature("bandwidth"),
                signature("latency"),
                signature("scale_factor")
            ),
        );
    }
    Ok(())
}

/// The residual against rate, temperature and acceleration, and how to read it.
fn residual_figure(s: &mut String, f: &Envelopes, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(
        s,
        "<h3>Residual against rate, temperature and acceleration</h3>"
    );
    s.push_str(&inline_svg(
        &residual_plot(f),
        "residual vs rate, temperature, acceleration",
        page,
    )?);
    read(
        s,
        &format!(
            "Top: a straight line through the bias is {}; different slopes for the two signs: {}; \
an S-shaped curve: {}; a residual that turns at the largest rates: {}. Middle (still samples): a slope \
with the temperature change is {} ({} shows instead as a rate slope that changes with temperature: \
see the “where” statistics by temperature tercile). Bottom: a slope against angular acceleration is \
{}; {}.",
            signature("scale_factor"),
            signature("scale_asymmetry"),
            signature("nonlinearity"),
            signature("saturation"),
            signature("temperature_bias"),
            signature("temperature_scale"),
            signature("latency"),
            signature("bandwidth")
        ),
    );
    Ok(())
}

/// The cross-correlation with the reference rate, its peaks, and how to read it.
fn xcorr_figure(s: &mut String, f: &Envelopes, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h3>Cross-correlation</h3>");
    let (plot, peaks) = xcorr_plot(f);
    s.push_str(&inline_svg(&plot, "cross-correlation", page)?);
    let _ = writeln!(s, "<p>{peaks}</p>");
    read(
        s,
        &format!(
            "The correlation of the gyro with the reference rate peaks where the two line up; the \
simulation has the same reference smoothing, so its peak is where a sensor without delay peaks. A \
real peak shifted from the band's (below: a real curve leaving the band, odd about lag 0) is {}, \
or {}. A real curve below the band at every lag is a scale or noise difference, not a delay.",
            signature("latency"),
            signature("bandwidth")
        ),
    );
    Ok(())
}

/// The gap map of every run's z-scores, and how to read it (if there are any).
fn gap_map_figure(s: &mut String, d: &Diagnosis, page: &Path) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h3>Gap map</h3>");
    if d.runs.iter().all(|r| r.z.is_empty()) {
        let _ = writeln!(s, "<p>No per-run z-scores to map.</p>");
    } else {
        s.push_str(&inline_svg(&gap_map(d), "gap map", page)?);
        read(
            s,
            &format!(
                "Each cell is one run's statistic against that run's own nominal ensemble: |z| ≲ 2 is \
noise (pale), red means the real value is above the simulated ones, blue below. A column coloured in \
every run is a systematic effect (the “where” table names it); a row coloured alone is one odd run — \
for a bias column, {}. Columns by time third (<code>time_1..3</code>) that drift across a row point to \
warm-up: {}.",
                signature("turn_on_bias"),
                signature("temperature_bias")
            ),
        );
    }
    Ok(())
}

/// The whole page: the answer first, the details folded below it.
fn page(
    d: &Diagnosis,
    envelopes: Option<&Envelopes>,
    options: &Options,
    path: &Path,
) -> Result<String, ReportError> {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>gyro diagnose: {}</title>\n<style>\n{STYLE}\n</style>\n</head>\n<body>",
        if d.verdict.unmodelled.is_empty() {
            "nothing significant".to_string()
        } else {
            esc(&d.verdict.unmodelled.join(", "))
        }
    );
    let _ = writeln!(
        s,
        "<h1>Sim-to-real diagnosis</h1>\n<p class=\"sub\">Trained on {}; held out: {}.</p>",
        esc(&super::run_files(d, "train")),
        esc(&super::run_files(d, "holdout"))
    );
    summary(&mut s, d, path)?;
    let _ = writeln!(
        s,
        "<details><summary>How far the simulation is from the runs: the gap G, the ensembles, the turns, the nominal model</summary>"
    );
    header(&mut s, d, options);
    let _ = writeln!(s, "</details>");
    let _ = writeln!(
        s,
        "<details><summary>Every candidate effect, the checks, what is unexplained and where the gap lies (tables)</summary>"
    );
    tables(&mut s, d);
    let _ = writeln!(s, "</details>");
    let _ = writeln!(
        s,
        "<details><summary>Figures: the real runs against simulated ones (Allan deviation, spectrum, residual, cross-correlation, gap map)</summary>"
    );
    figures(&mut s, d, envelopes, path)?;
    let _ = writeln!(s, "</details>");
    let _ = writeln!(
        s,
        "<p><small>Written by gyro-cli diagnose {}; the machine-readable result is <code>diagnosis.json</code> beside this page.</small></p>\n</body>\n</html>",
        env!("CARGO_PKG_VERSION")
    );
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    use gyro_sim::{Effect, SensorModel};

    use gyro_diagnose::{
        CompensationRun, CompensationSummary, GapSummary, ModelSummary, RunSummary, Verdict,
    };

    /// The statistics a "the largest:" line introduces are nested under it, the line after
    /// them is not, and the detection limits are folded with their text kept.
    #[test]
    fn findings_nest_the_largest_and_fold_the_limits() {
        let lines: Vec<String> = [
            "the model does not explain the training runs: ...; the largest:",
            "statistic a",
            "statistic b",
            "effective noise on moving data",
            "not named, so absent or smaller than what 5 runs show",
        ]
        .map(String::from)
        .to_vec();
        let mut s = String::new();
        findings_list(&mut s, &lines, 2);
        let nested = s.find("<ul>\n<li>statistic a").is_some()
            && s.find("statistic b</li>\n</ul></li>").is_some();
        assert!(nested, "{s}");
        assert!(s.contains("<li>effective noise on moving data</li>"), "{s}");
        assert!(
            s.contains("<details><summary>Not named")
                && s.contains("not named, so absent or smaller than what 5 runs show</details>"),
            "{s}"
        );
        assert_eq!(s.matches("<ul>").count(), s.matches("</ul>").count(), "{s}");
    }

    fn diagnosis() -> Diagnosis {
        let run = |name: &str, role: &'static str, z: f64| RunSummary {
            name: name.into(),
            role,
            duration_s: 30.0,
            gap_before: z,
            gap_after: 1.0,
            reference_grid: None,
            z: vec![
                ("static/residual_mean".into(), z),
                ("dynamic/slope_vs_rate".into(), -z),
            ],
        };
        Diagnosis {
            gap: GapSummary {
                train_before: 5.0,
                train_after: 1.2,
                holdout_before: 4.0,
                holdout_after: 1.1,
                floor: 1.0,
            },
            r#where: Vec::new(),
            effects: Vec::new(),
            verdict: Verdict {
                unmodelled: vec!["clock_error"],
                fraction_closed_holdout: 0.9,
                model_fits: false,
            },
            not_seen: gyro_diagnose::detection::not_seen(&["clock_error"]),
            unexplained: vec![gyro_diagnose::Unexplained {
                segment: "dynamic".into(),
                statistic: "residual_std".into(),
                real: 3.2,
                nominal: 0.05,
                simulated: 0.9,
                z_train: 512.0,
                z_train_nominal: 5169.0,
                z_holdout: 600.0,
            }],
            untestable: Vec::new(),
            model: ModelSummary {
                sensor: SensorModel::default(),
                notes: vec!["bias <from> the prior".into()],
                rest_noise: None,
                effects: vec![Effect::ClockError { ppm: 500.0 }],
            },
            runs: vec![run("a.csv", "train", 3.0), run("b.csv", "holdout", -12.0)],
            compensation: Some(CompensationSummary {
                corrected: vec!["clock_error"],
                not_corrected: Vec::new(),
                runs: vec![CompensationRun {
                    name: "b.csv".into(),
                    max_abs_error_before_deg: 1.5,
                    max_abs_error_after_deg: 0.2,
                }],
            }),
            reference_warnings: Vec::new(),
            doubts: Vec::new(),
            warnings: Vec::new(),
            effective_noise: Default::default(),
            motion_lines: Vec::new(),
            inputs: Vec::new(),
            turns: None,
            corrected_model: None,
            selected_sensor: SensorModel::default(),
        }
    }

    /// A report folder not yet made, inside a fresh folder that the guard removes when
    /// dropped.
    fn temp(name: &str) -> (tempfile::TempDir, PathBuf) {
        let scratch = tempfile::Builder::new()
            .prefix(&format!("gyro-report-unit-{name}-"))
            .tempdir()
            .unwrap();
        let dir = scratch.path().join("report");
        (scratch, dir)
    }

    #[test]
    fn page_without_runs_has_the_gap_map_and_the_angle_error_bars() {
        let (_scratch, dir) = temp("no-runs");
        write_report(&dir, &diagnosis(), None, &Options::default()).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert_eq!(html.matches("<svg").count(), 2, "gap map and bars");
        assert!(html.contains("No run to draw."));
        assert!(html.contains("bias &lt;from&gt; the prior"), "escaped");
        assert!(html.contains("b.csv (held out)"));
        assert!(html.contains("0.200 deg"));
        assert!(!html.contains("http://"));
        let json = std::fs::read_to_string(dir.join("diagnosis.json")).unwrap();
        assert!(json.contains("\"clock_error\""));
        assert!(
            html.contains("The model does not fit the training runs: 1 statistics"),
            "the unexplained statistics are said"
        );
        assert!(html.contains("<td>residual_std</td><td>dynamic</td><td class=\"n\">3.20</td>"));
        assert!(json.contains("\"model_fits\": false") || json.contains("\"model_fits\":false"));
        assert!(json.contains("\"unexplained\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_path() {
        let (_scratch, dir) = temp("blocked");
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("not-a-dir");
        std::fs::write(&file, "x").unwrap();
        let err = write_report(
            &file.join("report"),
            &diagnosis(),
            None,
            &Options::default(),
        )
        .unwrap_err();
        assert!(matches!(err, ReportError::CreateDir { .. }));
        assert!(err.to_string().contains("not-a-dir"), "{err}");
        let err = write_report(&file, &diagnosis(), None, &Options::default()).unwrap_err();
        assert!(err.to_string().contains("not-a-dir"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An effect whose signature no held-out run measures fails its check, and both the
    /// page and the table say why.
    #[test]
    fn an_unmeasured_signature_is_shown_failing() {
        let mut d = diagnosis();
        d.effects.push(gyro_diagnose::EffectResult {
            id: "clock_error_count_stamped",
            params: std::collections::BTreeMap::from([("ppm", 5737.0)]),
            delta_bic: Some(360.0),
            holdout_gap_before: 296.0,
            holdout_gap_after: Some(199.0),
            fraction_closed: Some(0.33),
            significant: false,
            ci95: std::collections::BTreeMap::new(),
            z: Some(4.4),
            holdout_z: None,
            shape_loglik: None,
            test: String::new(),
            bootstrap_p: Some(0.0),
            confounded_with: Vec::new(),
            posterior_check: Some(gyro_diagnose::posterior::PosteriorCheck {
                passes: false,
                statistics: Vec::new(),
                unmeasured: true,
            }),
        });
        let mut html = String::new();
        posterior_table(&mut html, &d);
        assert!(html.contains("clock_error_count_stamped"), "{html}");
        assert!(html.contains("not measured on the held-out runs"), "{html}");
        let text = super::super::text::table(&d);
        assert!(
            text.contains(
                "clock_error_count_stamped fails  its signature statistic is not measured"
            ),
            "{text}"
        );
        // A wander's shape evidence is in its test cell; another effect's is not.
        assert!(!test_cell(&d.effects[d.effects.len() - 1]).contains("shape"));
        let mut walk = d.effects[d.effects.len() - 1].clone();
        walk.id = "rate_random_walk";
        walk.test = "Allan variance <test>".into();
        walk.shape_loglik = Some(53.04);
        let cell = test_cell(&walk);
        assert!(
            cell.starts_with("Allan variance &lt;test&gt;<br>"),
            "{cell}"
        );
        assert!(
            cell.contains("log-likelihood 53.0 of the 1/4/16 s"),
            "{cell}"
        );
        assert!(cell.ends_with("the larger is named)"), "{cell}");
    }

    #[test]
    fn escapes_html() {
        assert_eq!(esc("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }

    #[test]
    fn peak_lag_refines_between_samples() {
        let lags: Vec<f64> = (-5..=5).map(|k| f64::from(k) * 1e-3).collect();
        let c: Vec<f64> = lags.iter().map(|l| -(l - 1.3e-3).powi(2)).collect();
        let p = peak_lag(&c, &lags).unwrap();
        assert!((p - 1.3e-3).abs() < 1e-6, "{p}");
    }

    #[test]
    fn band_spans_members() {
        let b = band_of(
            "x",
            &[1.0, 2.0],
            &[vec![1.0, 5.0], vec![3.0, f64::NAN], vec![2.0, 4.0]],
        );
        assert_eq!(b.lo, vec![1.0, 4.0]);
        assert_eq!(b.mid, vec![2.0, 5.0]);
        assert_eq!(b.hi, vec![3.0, 5.0]);
    }

    #[test]
    fn the_headline_says_what_the_turns_show() {
        use gyro_diagnose::turns::{TurnEvidence, TurnScale, Untracked, WideLag};
        let mut d = diagnosis();
        d.turns = Some(TurnEvidence {
            train_turns: 12,
            holdout_turns: 6,
            lag: Some(WideLag {
                median_s: 0.107,
                train_range_s: (0.094, 0.111),
                holdout_median_s: Some(0.09),
                beyond_statistic: true,
                holdout_max_abs_error_deg: Some((37.4, 11.9)),
                bootstrap_p: Some(0.0),
                written: true,
            }),
            scale: Some(TurnScale {
                k: -0.0112,
                standard_error: 0.0007,
                ci95: (-0.0127, -0.0097),
                z: -16.0,
                holdout_k: (-0.0107, 0.0005),
                holdout_turn_rms_deg: (2.11, 0.55),
                holdout_runs_better: (2, 2),
                bootstrap_p: 0.0,
                named: true,
                written: true,
            }),
            untracked: vec![Untracked {
                run: "a.csv".into(),
                gyro_deg: -9.5,
                reference_deg: 0.002,
            }],
        });
        let lines = super::super::headline(&d).join("\n");
        assert!(lines.contains("the gyro lags the reference by 107 ms (94 to 111 over the training runs; 90 ms on the held-out runs)"), "{lines}");
        assert!(lines.contains("written as the model's reference_delay_s (held-out median max |angle error| 37.40 -> 11.90 deg)"), "{lines}");
        assert!(
            lines.contains(
                "the gyro reads -1.12% [-1.27%, -0.97%] of the reference's turn (12 training turns"
            ),
            "{lines}"
        );
        assert!(lines.contains("RMS error 2.11 -> 0.55 deg with it, better on 2 of 2 runs: written (config.correction.scale_k)"), "{lines}");
        assert!(lines.contains("1 movements the reference does not follow, in 1 runs: the gyro turns 9.5 to 9.5 deg"), "{lines}");
        assert!(d
            .residual_caveat()
            .is_some_and(|c| c.starts_with("the reference is 107 ms ahead of the gyro")));
        let (_scratch, dir) = temp("turns");
        write_report(&dir, &d, None, &Options::default()).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(html.contains("<h2>Turns, rest to rest</h2>"), "{html}");
        assert!(
            html.contains("−1.12%") || html.contains("-1.12% [-1.27%, -0.97%]"),
            "{html}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The answer first: the verdict's sentences (that the model does not explain the runs
    /// before what is named), then the held-out angle error figure, both before every
    /// table and every folded section.
    #[test]
    fn the_verdict_and_the_angle_error_lead_the_page() {
        let mut d = diagnosis();
        d.effects = vec![EffectResult {
            id: "clock_error",
            params: BTreeMap::from([("ppm", 500.0)]),
            delta_bic: Some(40.0),
            holdout_gap_before: 4.0,
            holdout_gap_after: Some(1.1),
            fraction_closed: Some(0.9),
            significant: true,
            ci95: BTreeMap::from([("ppm", [Some(480.0), Some(520.0)])]),
            z: Some(9.0),
            holdout_z: None,
            shape_loglik: None,
            test: "z test".into(),
            bootstrap_p: Some(0.0),
            confounded_with: Vec::new(),
            posterior_check: None,
        }];
        d.doubts = vec!["The clock may be another cause's look-alike".into()];
        let (_scratch, dir) = temp("verdict_first");
        write_report(&dir, &d, None, &Options::default()).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        let at = |needle: &str| {
            html.find(needle)
                .unwrap_or_else(|| panic!("{needle} not in the page:\n{html}"))
        };
        let verdict = at("<div class=\"verdict\">");
        let said = at("The gyro samples 500 ppm fast against the declared sample rate");
        let doubt = at("The clock may be another cause&#39;s look-alike.");
        let error = at("Correcting the clock cuts the held-out angle error from 1.5° to 0.20°");
        let missed =
            at("The model does not explain these runs: in motion, the rate noise is 3.6 times");
        let figure = at("aria-label=\"angle error before and after\"");
        let first_table = at("<table");
        let first_fold = at("<details");
        // The model not fitting comes first: what is named is at most part of the answer.
        assert!(verdict < missed && missed < said && said < error, "{html}");
        // A doubt on what is named follows it at once.
        assert!(said < doubt && doubt < error, "{html}");
        assert!(error < figure, "the figure follows the verdict");
        assert!(figure < first_table && figure < first_fold, "{html}");
        assert!(
            !html[..first_fold].contains("G ="),
            "no G before the details"
        );
    }

    #[test]
    fn runs_are_named_relative_to_the_directory_they_share() {
        let mut d = diagnosis();
        d.runs[0].name = "/data/real/rasteiro/a_x.csv".into();
        d.runs[1].name = "/data/real/rasteiro/b_x.csv".into();
        assert_eq!(
            super::super::run_label(&d, "/data/real/rasteiro/a_x.csv"),
            "a_x.csv"
        );
        d.runs[1].name = "/data/real/ssong/é.csv".into();
        assert_eq!(
            super::super::run_label(&d, "/data/real/ssong/é.csv"),
            "ssong/é.csv"
        );
        assert_eq!(
            super::super::run_label(&d, "/data/real/rasteiro/a_x.csv#2"),
            "rasteiro/a_x.csv#2"
        );
        d.runs[1].name = "b.csv".into();
        assert_eq!(
            super::super::run_label(&d, "/data/real/rasteiro/a_x.csv"),
            "/data/real/rasteiro/a_x.csv"
        );
    }
}
