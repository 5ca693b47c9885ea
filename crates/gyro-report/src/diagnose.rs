//! `diagnose --report DIR`: one self-contained HTML page (`index.html`: inline CSS and
//! inline SVG figures, nothing fetched from anywhere) and the [`Diagnosis`] as
//! `diagnosis.json` beside it.
//!
//! The page holds the gap figures, the verdict, the nominal model and its provenance,
//! the ranked effects, the largest "where" z-scores, the per-run gaps, and figures of real
//! data against simulated envelopes, each with a note on how to read it.
//!
//! **Envelopes.** The runs are re-simulated with the nominal model (and, when effects
//! were selected, with the model holding them) with the seeds of the diagnosis' baseline
//! ensemble ([`member_seed`] of run and member), [`REPORT_MEMBERS`] members each, so the
//! nominal band is drawn from the very ensemble the z-scores were computed against. Every
//! real and simulated run goes through the same residuals ([`residuals`]). A figure
//! pools its statistic over the runs (like [`gyro_analysis::noise`] pools segments) for the real
//! runs and, member by member, for the simulated ones; a band spans the members' minimum
//! to maximum with their median dashed (the cross-correlation's: a 95% band, mean ± 1.96
//! sd of the members). When the runs hold more than [`SAMPLE_BUDGET`] samples, an evenly
//! spaced subset of training and held-out runs is used for the figures (real and
//! simulated alike; the page says which). The gap map and the tables use every run.

use crate::plot::diagnose_plot::{
    AngleErrorPlot, AngleErrorRow, Band, EnvelopePlot, GapMapPlot, Measured, Panel,
};
use crate::plot::{render, sig, Figure, ImageFormat, RenderError};
use gyro_analysis::diagnose::ensemble::{member_seed, simulate_residuals, RealRun};
use gyro_analysis::diagnose::features::MIN_TEMPERATURE_RANGE_C;
use gyro_analysis::diagnose::fit::{model_with, nominal_model};
use gyro_analysis::diagnose::stats::{residuals, stretches, Residuals, MAX_LAG_S};
use gyro_analysis::diagnose::{Diagnosis, EffectResult, Options};
use gyro_analysis::noise::{welch, AllanDeviation, PsdOptions, TauGrid, ONE_SIGMA};
use gyro_sim::{Effect, SensorModel, EFFECTS};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Simulated members per run for the envelopes (at most the diagnosis' members).
pub const REPORT_MEMBERS: usize = 12;
/// Samples of real runs the figures use at most (each simulated [`REPORT_MEMBERS`]
/// times per model): 11 of 20 runs of 90 s at 1 kHz, about 7 s of CPU with one set of
/// selected effects.
pub const SAMPLE_BUDGET: usize = 1_000_000;
/// Colours of the gap map saturate at this |z|.
pub const GAP_MAP_CLIP: f64 = 10.0;
/// Most statistics (columns) in the gap map, by combined |z|.
pub const GAP_MAP_COLUMNS: usize = 120;
/// Rows of the "where" table.
pub const WHERE_ROWS: usize = 20;
/// Bins of the reference rate and of the angular acceleration.
const SIGNED_BINS: usize = 24;
/// Bins of the temperature change.
const TEMPERATURE_BINS: usize = 12;
/// Fewest real samples for a bin to be shown.
const MIN_BIN_SAMPLES: f64 = 20.0;
/// Welch segment length (s), rounded down to a power of two of samples.
const PSD_SEGMENT_S: f64 = 4.0;
/// Bands per decade of the PSD.
const PSD_BANDS_PER_DECADE: f64 = 10.0;

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

/// Write `dir/diagnosis.json` and `dir/index.html` for the diagnosis `d` of `train` and
/// `holdout` (the runs it was computed from, in the same order) with `options`.
pub fn write_report(
    dir: &Path,
    d: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let json_path = dir.join("diagnosis.json");
    let json = serde_json::to_string_pretty(d).map_err(|source| ReportError::Json {
        path: json_path.clone(),
        source,
    })?;
    std::fs::write(&json_path, json).map_err(|source| ReportError::Write {
        path: json_path.clone(),
        source,
    })?;
    let html_path = dir.join("index.html");
    let html = page(d, train, holdout, options, &html_path)?;
    std::fs::write(&html_path, html).map_err(|source| ReportError::Write {
        path: html_path.clone(),
        source,
    })
}

// ---------------------------------------------------------------------------------------
// Measures of one run, poolable over runs.

/// Count, sum and sum of squares.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Moments {
    n: f64,
    sum: f64,
    sum_sq: f64,
}

impl Moments {
    fn add(&mut self, v: f64) {
        self.n += 1.0;
        self.sum += v;
        self.sum_sq += v * v;
    }

    fn merge(&mut self, o: &Moments) {
        self.n += o.n;
        self.sum += o.sum;
        self.sum_sq += o.sum_sq;
    }

    fn mean(&self) -> f64 {
        if self.n > 0.0 {
            self.sum / self.n
        } else {
            f64::NAN
        }
    }

    fn std(&self) -> f64 {
        if self.n > 1.0 {
            let m = self.mean();
            ((self.sum_sq - self.n * m * m) / (self.n - 1.0))
                .max(0.0)
                .sqrt()
        } else {
            f64::NAN
        }
    }
}

/// Fixed bins `[edges[i], edges[i+1])`.
#[derive(Clone, Debug, PartialEq)]
struct Bins {
    edges: Vec<f64>,
}

impl Bins {
    fn linear(lo: f64, hi: f64, n: usize) -> Self {
        Self {
            edges: (0..=n)
                .map(|i| lo + (hi - lo) * i as f64 / n as f64)
                .collect(),
        }
    }

    fn len(&self) -> usize {
        self.edges.len().saturating_sub(1)
    }

    fn index(&self, v: f64) -> Option<usize> {
        let (lo, hi) = (*self.edges.first()?, *self.edges.last()?);
        if !(v.is_finite() && v >= lo && v <= hi && hi > lo) {
            return None;
        }
        let k = ((v - lo) / (hi - lo) * self.len() as f64).floor() as usize;
        Some(k.min(self.len() - 1))
    }

    fn centres(&self) -> Vec<f64> {
        self.edges.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect()
    }
}

/// What every run is measured with (fixed from the real runs before any simulation).
#[derive(Clone, Debug)]
struct Setup {
    fs: f64,
    allan_factors: Vec<usize>,
    psd_len: usize,
    rate: Bins,
    acceleration: Bins,
    temperature: Option<Bins>,
    /// Lags of the cross-correlation (samples).
    lags: Vec<i64>,
}

/// A run's (or pooled runs') figure statistics.
#[derive(Clone, Debug, Default)]
struct Measures {
    /// Per averaging factor: Σ avar·terms and Σ terms of the static residual.
    allan: BTreeMap<usize, (f64, f64)>,
    /// Σ PSD·segments per bin, and Σ segments.
    psd: Vec<f64>,
    psd_segments: f64,
    rate: Vec<Moments>,
    acceleration: Vec<Moments>,
    temperature: Vec<Moments>,
    /// Σ g[i+lag]·r[i] per lag, Σ g², Σ r² (means removed per run).
    xcorr: Vec<f64>,
    g2: f64,
    r2: f64,
}

/// Σ a·b, in four independent sums (so the compiler can vectorise it).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for j in 0..4 {
            acc[j] += x[j] * y[j];
        }
    }
    acc.iter().sum::<f64>() + tail
}

impl Measures {
    fn new(setup: &Setup) -> Self {
        Self {
            allan: BTreeMap::new(),
            psd: vec![0.0; setup.psd_len / 2 + 1],
            psd_segments: 0.0,
            rate: vec![Moments::default(); setup.rate.len()],
            acceleration: vec![Moments::default(); setup.acceleration.len()],
            temperature: vec![Moments::default(); setup.temperature.as_ref().map_or(0, Bins::len)],
            xcorr: vec![0.0; setup.lags.len()],
            g2: 0.0,
            r2: 0.0,
        }
    }

    fn merge(&mut self, o: &Measures) {
        for (m, (a, t)) in &o.allan {
            let e = self.allan.entry(*m).or_insert((0.0, 0.0));
            e.0 += a;
            e.1 += t;
        }
        self.psd.iter_mut().zip(&o.psd).for_each(|(a, b)| *a += b);
        self.psd_segments += o.psd_segments;
        for (mine, theirs) in [
            (&mut self.rate, &o.rate),
            (&mut self.acceleration, &o.acceleration),
            (&mut self.temperature, &o.temperature),
        ] {
            mine.iter_mut().zip(theirs).for_each(|(a, b)| a.merge(b));
        }
        self.xcorr
            .iter_mut()
            .zip(&o.xcorr)
            .for_each(|(a, b)| *a += b);
        self.g2 += o.g2;
        self.r2 += o.r2;
    }

    fn of(r: &Residuals, setup: &Setup) -> Self {
        let mut out = Self::new(setup);
        let n = r.residual_dps.len();
        let res = &r.residual_dps;

        // Allan deviation of the static residual, each static stretch a segment.
        let statics: Vec<&[f64]> = stretches(n, |i| r.is_static[i] && res[i].is_finite())
            .into_iter()
            .map(|s| &res[s])
            .collect();
        if !statics.is_empty() {
            let allan =
                AllanDeviation::compute(&statics, setup.fs, &setup.allan_factors, ONE_SIGMA);
            for p in &allan.points {
                out.allan
                    .insert(p.m, (p.avar() * p.terms as f64, p.terms as f64));
            }
        }

        // Welch PSD of the residual over every stretch with one.
        let all: Vec<&[f64]> = stretches(n, |i| res[i].is_finite())
            .into_iter()
            .filter(|s| s.len() >= setup.psd_len)
            .map(|s| &res[s])
            .collect();
        let psd_options = PsdOptions {
            segment_len: Some(setup.psd_len),
            ..PsdOptions::default()
        };
        if let Some(psd) = welch(&all, setup.fs, &psd_options) {
            let k = psd.segments as f64;
            out.psd
                .iter_mut()
                .zip(&psd.psd_dps2_per_hz)
                .for_each(|(a, p)| *a += p * k);
            out.psd_segments += k;
        }

        // Binned residuals.
        let t0 = r.temperature_c.iter().copied().find(|t| t.is_finite());
        for (i, &v) in res.iter().enumerate() {
            if !v.is_finite() {
                continue;
            }
            if let Some(k) = setup.rate.index(r.reference_rate_dps[i]) {
                out.rate[k].add(v);
            }
            if !r.is_static[i] {
                if let Some(k) = setup.acceleration.index(r.reference_acceleration_dps2[i]) {
                    out.acceleration[k].add(v);
                }
            } else if let (Some(bins), Some(t0)) = (&setup.temperature, t0) {
                if let Some(k) = bins.index(r.temperature_c[i] - t0) {
                    out.temperature[k].add(v);
                }
            }
        }

        // Cross-correlation of gyro and reference rate, means removed.
        let both = |i: usize| r.rate_dps[i].is_finite() && r.reference_rate_dps[i].is_finite();
        let count = (0..n).filter(|&i| both(i)).count();
        if count >= 3 {
            let mean =
                |x: &[f64]| (0..n).filter(|&i| both(i)).map(|i| x[i]).sum::<f64>() / count as f64;
            let (mg, mr) = (mean(&r.rate_dps), mean(&r.reference_rate_dps));
            let g: Vec<f64> = (0..n)
                .map(|i| if both(i) { r.rate_dps[i] - mg } else { 0.0 })
                .collect();
            let rr: Vec<f64> = (0..n)
                .map(|i| {
                    if both(i) {
                        r.reference_rate_dps[i] - mr
                    } else {
                        0.0
                    }
                })
                .collect();
            out.g2 = g.iter().map(|v| v * v).sum();
            out.r2 = rr.iter().map(|v| v * v).sum();
            for (c, &lag) in out.xcorr.iter_mut().zip(&setup.lags) {
                let l = lag.unsigned_abs() as usize;
                if l >= n {
                    continue;
                }
                let (a, b) = if lag >= 0 {
                    (&g[l..], &rr[..n - l])
                } else {
                    (&g[..n - l], &rr[l..])
                };
                *c = dot(a, b);
            }
        }
        out
    }

    /// Pooled Allan deviation: (τ, σ).
    fn allan_curve(&self, fs: f64) -> Vec<(f64, f64)> {
        self.allan
            .iter()
            .filter(|(_, (_, t))| *t >= 2.0)
            .map(|(m, (a, t))| (*m as f64 / fs, (a / t).sqrt()))
            .collect()
    }

    /// PSD averaged over log bands: (centre frequency, PSD).
    fn psd_bands(&self, setup: &Setup) -> Vec<(f64, f64)> {
        if self.psd_segments <= 0.0 {
            return Vec::new();
        }
        let df = setup.fs / setup.psd_len as f64;
        let mut bands: BTreeMap<i64, (f64, f64, f64)> = BTreeMap::new();
        for (k, p) in self.psd.iter().enumerate().skip(1) {
            let f = k as f64 * df;
            let band = ((f / df).log10() * PSD_BANDS_PER_DECADE).floor() as i64;
            let e = bands.entry(band).or_insert((0.0, 0.0, 0.0));
            e.0 += p / self.psd_segments;
            e.1 += 1.0;
            e.2 += f.ln();
        }
        bands
            .values()
            .map(|(sum, count, log_f)| ((log_f / count).exp(), sum / count))
            .collect()
    }

    /// Normalised cross-correlation per lag.
    fn xcorr_curve(&self) -> Vec<f64> {
        let norm = (self.g2 * self.r2).sqrt();
        self.xcorr
            .iter()
            .map(|c| if norm > 0.0 { c / norm } else { f64::NAN })
            .collect()
    }
}

/// Quantile `q` of the finite `values` (nearest rank).
fn quantile(values: &mut [f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    let k = ((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
    Some(*v.select_nth_unstable_by(k, f64::total_cmp).1)
}

/// The measurement set-up from the real runs' residuals.
fn setup(real: &[Residuals], fs: f64) -> Setup {
    let longest_static = real
        .iter()
        .flat_map(|r| {
            stretches(r.residual_dps.len(), |i| {
                r.is_static[i] && r.residual_dps[i].is_finite()
            })
        })
        .map(|s| s.len())
        .max()
        .unwrap_or(0);
    let allan_factors = TauGrid::PerDecade(8).factors(longest_static);
    let longest = real
        .iter()
        .flat_map(|r| stretches(r.residual_dps.len(), |i| r.residual_dps[i].is_finite()))
        .map(|s| s.len())
        .max()
        .unwrap_or(0);
    let target = ((PSD_SEGMENT_S * fs) as usize).min(longest).max(16);
    let psd_len = 1usize << (usize::BITS - 1 - target.leading_zeros());

    let mut abs_rate: Vec<f64> = Vec::new();
    let mut abs_acc: Vec<f64> = Vec::new();
    let mut delta_t: Vec<f64> = Vec::new();
    for r in real {
        let t0 = r.temperature_c.iter().copied().find(|t| t.is_finite());
        for i in 0..r.residual_dps.len() {
            if !r.residual_dps[i].is_finite() {
                continue;
            }
            abs_rate.push(r.reference_rate_dps[i].abs());
            if r.is_static[i] {
                if let Some(t0) = t0 {
                    delta_t.push(r.temperature_c[i] - t0);
                }
            } else {
                abs_acc.push(r.reference_acceleration_dps2[i].abs());
            }
        }
    }
    let span = |v: &mut [f64], q: f64| quantile(v, q).filter(|x| *x > 0.0).unwrap_or(1.0);
    let rate_max = span(&mut abs_rate, 0.995);
    let acc_max = span(&mut abs_acc, 0.99);
    let temperature = {
        let lo = delta_t
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(f64::INFINITY, f64::min);
        let hi = delta_t
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        (hi - lo >= MIN_TEMPERATURE_RANGE_C).then(|| Bins::linear(lo, hi, TEMPERATURE_BINS))
    };
    let max_lag = ((MAX_LAG_S * fs).round() as i64).max(1);
    let step = ((fs / 1000.0).round() as i64).max(1);
    let lags = (-max_lag / step..=max_lag / step)
        .map(|k| k * step)
        .collect();
    Setup {
        fs,
        allan_factors,
        psd_len,
        rate: Bins::linear(-rate_max, rate_max, SIGNED_BINS),
        acceleration: Bins::linear(-acc_max, acc_max, SIGNED_BINS),
        temperature,
        lags,
    }
}

// ---------------------------------------------------------------------------------------
// Runs, simulations and envelopes.

/// A run used by the figures, with its seed index in the diagnosis.
struct FigureRun<'a> {
    id: usize,
    run: &'a RealRun,
}

/// The runs the figures use: all of them if they fit [`SAMPLE_BUDGET`], else an evenly
/// spaced subset taking held-out and training runs in turn (at least one of each).
fn figure_runs<'a>(train: &'a [RealRun], holdout: &'a [RealRun]) -> Vec<FigureRun<'a>> {
    let all: Vec<FigureRun> = train
        .iter()
        .enumerate()
        .map(|(i, run)| FigureRun { id: i, run })
        .chain(holdout.iter().enumerate().map(|(i, run)| FigureRun {
            id: train.len() + i,
            run,
        }))
        .collect();
    let total: usize = all.iter().map(|f| f.run.len()).sum();
    if total <= SAMPLE_BUDGET || all.len() <= 2 {
        return all;
    }
    let mean_len = (total / all.len()).max(1);
    let k = (SAMPLE_BUDGET / mean_len).clamp(2, all.len());
    let k_hold = (k / 2).clamp(1, holdout.len().max(1));
    let k_train = (k - k_hold).clamp(1, train.len().max(1));
    // m of n indices, evenly spaced (the middle of m equal parts).
    let spaced = |n: usize, m: usize| -> Vec<usize> {
        let m = m.min(n);
        (0..m).map(|i| ((2 * i + 1) * n) / (2 * m)).collect()
    };
    let mut chosen: Vec<usize> = spaced(train.len(), k_train);
    chosen.extend(
        spaced(holdout.len(), k_hold)
            .iter()
            .map(|i| train.len() + i),
    );
    all.into_iter().filter(|f| chosen.contains(&f.id)).collect()
}

/// One simulated model for the envelopes.
struct SimModel {
    label: String,
    model: SensorModel,
    effects: Vec<Effect>,
}

/// The pooled measures of every member of every model (`[model][member]`).
fn simulate_all(
    runs: &[FigureRun],
    models: &[SimModel],
    members: usize,
    seed: u64,
    setup: &Setup,
) -> Vec<Vec<Measures>> {
    let jobs: Vec<(usize, usize, usize)> = (0..models.len())
        .flat_map(|m| (0..members).flat_map(move |j| (0..runs.len()).map(move |r| (m, j, r))))
        .collect();
    let done: Vec<((usize, usize), Measures)> = jobs
        .par_iter()
        .filter_map(|&(m, j, r)| {
            let f = &runs[r];
            let model = &models[m];
            simulate_residuals(
                f.run,
                &model.model,
                &model.effects,
                member_seed(seed, f.id, j),
            )
            .ok()
            .map(|res| ((m, j), Measures::of(&res, setup)))
        })
        .collect();
    let mut out: Vec<Vec<Measures>> = (0..models.len())
        .map(|_| (0..members).map(|_| Measures::new(setup)).collect())
        .collect();
    for ((m, j), measures) in done {
        out[m][j].merge(&measures);
    }
    out
}

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

/// Everything the figures need.
struct FigureData {
    setup: Setup,
    real: Measures,
    models: Vec<SimModel>,
    sims: Vec<Vec<Measures>>,
    members: usize,
    runs_used: usize,
    runs_total: usize,
    real_errors: Vec<String>,
}

fn figure_data(
    d: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
) -> Option<FigureData> {
    let runs = figure_runs(train, holdout);
    let computed: Vec<_> = runs.par_iter().map(|f| residuals(&f.run.log)).collect();
    let mut real_errors = Vec::new();
    let mut real_res: Vec<Residuals> = Vec::new();
    for (f, r) in runs.iter().zip(computed) {
        match r {
            Ok(r) => real_res.push(r),
            Err(e) => real_errors.push(format!("{}: {e}", f.run.name)),
        }
    }
    let fs = runs.first()?.run.sample_rate_hz;
    let setup = setup(&real_res, fs);
    let mut real = Measures::new(&setup);
    for r in &real_res {
        real.merge(&Measures::of(r, &setup));
    }
    drop(real_res);
    // The white-noise target the diagnosis matched (it matters with quantisation only).
    let white_target = if options.fixed_model || d.model.effects.is_empty() {
        None
    } else {
        let train_refs: Vec<&RealRun> = train.iter().collect();
        nominal_model(&train_refs, &options.prior).2
    };
    let mut models = vec![SimModel {
        label: "nominal model".to_string(),
        model: d.model.sensor,
        effects: Vec::new(),
    }];
    if !d.model.effects.is_empty() {
        let ids: Vec<&str> = d.model.effects.iter().map(Effect::id).collect();
        models.push(SimModel {
            label: format!("nominal + {}", ids.join(" + ")),
            model: model_with(&d.model.sensor, &d.model.effects, white_target),
            effects: d.model.effects.clone(),
        });
    }
    let members = REPORT_MEMBERS.min(options.members).max(2);
    let sims = simulate_all(&runs, &models, members, options.seed, &setup);
    Some(FigureData {
        setup,
        real,
        models,
        sims,
        members,
        runs_used: runs.len(),
        runs_total: train.len() + holdout.len(),
        real_errors,
    })
}

fn band_label(model: &SimModel, members: usize) -> String {
    format!(
        "{}: range of {members} simulated sets, median dashed",
        model.label
    )
}

fn allan_plot(f: &FigureData) -> EnvelopePlot {
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

fn psd_plot(f: &FigureData) -> EnvelopePlot {
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
    f: &FigureData,
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

fn residual_plot(f: &FigureData) -> EnvelopePlot {
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
                "no temperature panel: the runs have no temperature, or it varies by less than {MIN_TEMPERATURE_RANGE_C} °C on static samples"
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
fn xcorr_plot(f: &FigureData) -> (EnvelopePlot, String) {
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
    let ms = |v: Option<f64>| v.map_or("–".to_string(), |s| sig(s * 1e3, 3));
    let mut peaks = format!(
        "Peak lag (positive: the gyro lags the reference): real runs {} ms",
        ms(peak_lag(&real, &lags_s))
    );
    for (m, v) in f.models.iter().zip(&per_model) {
        let lags: Vec<f64> = v.iter().filter_map(|c| peak_lag(c, &lags_s)).collect();
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
                r.name.clone()
            } else {
                format!("{} (held out)", r.name)
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

fn angle_error_plot(d: &Diagnosis) -> Option<AngleErrorPlot> {
    let c = d.compensation.as_ref()?;
    Some(AngleErrorPlot {
        title: "Angle error of the held-out runs, without and with compensation".into(),
        subtitle: format!("corrected: {}", c.corrected.join(", ")),
        rows: c
            .runs
            .iter()
            .map(|r| AngleErrorRow {
                name: r.name.clone(),
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
.warn{color:#a04000}code{font-size:.95em}";

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
        "<tr{}><td><code>{}</code></td><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td><td>{}</td></tr>",
        if e.significant { " class=\"sig\"" } else { "" },
        esc(e.id),
        if e.significant { "yes" } else { "no" },
        params.join("<br>"),
        e.z.map_or("exact".to_string(), |z| format!("{z:.2}")),
        format_args!("{:.1}", e.delta_bic),
        num(e.holdout_gap_before),
        num(e.holdout_gap_after),
        num(e.fraction_closed),
        num(e.bootstrap_p),
        if e.confounded_with.is_empty() {
            "–".to_string()
        } else {
            e.confounded_with
                .iter()
                .map(|c| format!("<code>{}</code>", esc(c)))
                .collect::<Vec<_>>()
                .join(", ")
        },
        esc(&e.test)
    );
}

fn header(s: &mut String, d: &Diagnosis, options: &Options) {
    let g = &d.gap;
    let _ = writeln!(s, "<h1>Sim-to-real diagnosis</h1>");
    let verdict = if d.verdict.unmodelled.is_empty() {
        "nothing significant: no candidate effect closes the held-out gap".to_string()
    } else {
        format!(
            "unmodelled: {}; they close {} of the held-out gap above the floor",
            d.verdict
                .unmodelled
                .iter()
                .map(|u| format!("<code>{}</code>", esc(u)))
                .collect::<Vec<_>>()
                .join(", "),
            percent(d.verdict.fraction_closed_holdout)
        )
    };
    let _ = writeln!(s, "<p class=\"verdict\"><b>Verdict:</b> {verdict}</p>");
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
    let _ = writeln!(
        s,
        "<p>Ensembles: {} members per run (baseline), {} per held-out run for each candidate; seed {}; {} bootstrap resamples.{}</p>",
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

fn tables(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "<h2>Candidate effects, ranked</h2>");
    let _ = writeln!(
        s,
        "<p>Significant effects first, then by held-out gap reduction. An effect is significant \
when its parameter test passes on the training runs, its held-out ΔBIC is positive and the \
bootstrap over held-out runs gives P(no improvement) &lt; 0.05 (an effect seen directly in \
the raw data — a clip plateau, an output grid, gaps — when the same direct test passes on the \
held-out runs too); one that adds nothing once the others are in the model is confounded \
with them and not named. Intervals are 95%; \
z is the parameter test on the training runs (“exact” where the test is not a z-test); \
“closed” is (before − after) / (before − floor).</p>"
    );
    let _ = writeln!(
        s,
        "<table><tr><th>effect</th><th>significant</th><th>parameters [95% interval]</th><th>z</th><th>ΔBIC</th><th>held-out G before</th><th>after</th><th>closed</th><th>bootstrap p</th><th>confounded with</th><th>test</th></tr>"
    );
    for e in &d.effects {
        effect_row(s, e);
    }
    let _ = writeln!(s, "</table>");
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

    let _ = writeln!(s, "<h2>Where the gap lies</h2>");
    let _ = writeln!(
        s,
        "<p>The {WHERE_ROWS} statistics with the largest |z| of real against the nominal ensembles, \
combined over all runs (Σz/√n). Positive: the real value is above the simulated ones.</p>"
    );
    let _ = writeln!(
        s,
        "<table><tr><th>z</th><th>segment</th><th>statistic</th></tr>"
    );
    for w in d.r#where.iter().take(WHERE_ROWS) {
        let _ = writeln!(
            s,
            "<tr><td class=\"n\">{:.1}</td><td>{}</td><td>{}</td></tr>",
            w.z,
            esc(&w.segment),
            esc(&w.statistic)
        );
    }
    let _ = writeln!(s, "</table>");

    let _ = writeln!(s, "<h2>Runs</h2>");
    let _ = writeln!(
        s,
        "<table><tr><th>run</th><th>role</th><th>duration</th><th>G nominal</th><th>G with the selected effects</th></tr>"
    );
    for r in &d.runs {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td class=\"n\">{} s</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            esc(&r.name),
            esc(r.role),
            sig(r.duration_s, 4),
            num(r.gap_before),
            num(r.gap_after)
        );
    }
    let _ = writeln!(s, "</table>");
}

fn read(s: &mut String, text: &str) {
    let _ = writeln!(s, "<p class=\"read\"><b>How to read this.</b> {text}</p>");
}

fn figures(
    s: &mut String,
    d: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
    page: &Path,
) -> Result<(), ReportError> {
    let _ = writeln!(s, "<h2>Figures</h2>");
    match figure_data(d, train, holdout, options) {
        None => {
            let _ = writeln!(s, "<p>No run to draw.</p>");
        }
        Some(f) => {
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
            let _ = writeln!(s, "<h3>Allan deviation</h3>");
            s.push_str(&inline_svg(&allan_plot(&f), "Allan deviation", page)?);
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
            let _ = writeln!(s, "<h3>Power spectral density</h3>");
            s.push_str(&inline_svg(&psd_plot(&f), "PSD", page)?);
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
            let _ = writeln!(
                s,
                "<h3>Residual against rate, temperature and acceleration</h3>"
            );
            s.push_str(&inline_svg(
                &residual_plot(&f),
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
            let _ = writeln!(s, "<h3>Cross-correlation</h3>");
            let (plot, peaks) = xcorr_plot(&f);
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
        }
    }

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

    let _ = writeln!(s, "<h3>Angle error of the held-out runs</h3>");
    match angle_error_plot(d) {
        Some(plot) if !plot.rows.is_empty() => {
            s.push_str(&inline_svg(&plot, "angle error before and after", page)?);
            read(
                s,
                &format!(
                    "The pipeline's max abs angle error on each held-out run with the nominal \
configuration and with the correctable selected effects compensated (<code>run --model</code>). \
Errors that grow with the total angle turned point to {}; angle lost in motion to {}.",
                    signature("clock_error"),
                    signature("dropouts")
                ),
            );
        }
        _ => {
            let which = if d.verdict.unmodelled.is_empty() {
                "no effect was selected".to_string()
            } else {
                format!(
                    "the selected effects ({}) include none that <code>run --model</code> corrects",
                    d.verdict
                        .unmodelled
                        .iter()
                        .map(|u| format!("<code>{}</code>", esc(u)))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            let _ = writeln!(
                s,
                "<p>No correctable effect was selected, so there is no angle error to compare: {which}.</p>"
            );
        }
    }
    Ok(())
}

/// The whole page.
fn page(
    d: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
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
    header(&mut s, d, options);
    tables(&mut s, d);
    figures(&mut s, d, train, holdout, options, path)?;
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

    use gyro_analysis::diagnose::{
        CompensationRun, CompensationSummary, GapSummary, ModelSummary, RunSummary, Verdict,
    };

    fn diagnosis() -> Diagnosis {
        let run = |name: &str, role: &'static str, z: f64| RunSummary {
            name: name.into(),
            role,
            duration_s: 30.0,
            gap_before: z,
            gap_after: 1.0,
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
            },
            untestable: Vec::new(),
            model: ModelSummary {
                sensor: SensorModel::default(),
                notes: vec!["bias <from> the prior".into()],
                effects: vec![Effect::ClockError { ppm: 500.0 }],
            },
            runs: vec![run("a.csv", "train", 3.0), run("b.csv", "holdout", -12.0)],
            compensation: Some(CompensationSummary {
                corrected: vec!["clock_error"],
                runs: vec![CompensationRun {
                    name: "b.csv".into(),
                    max_abs_error_before_deg: 1.5,
                    max_abs_error_after_deg: 0.2,
                }],
            }),
            corrected_model: None,
        }
    }

    fn temp(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("gyro-report-unit-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn page_without_runs_has_the_gap_map_and_the_angle_error_bars() {
        let dir = temp("no-runs");
        write_report(&dir, &diagnosis(), &[], &[], &Options::default()).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert_eq!(html.matches("<svg").count(), 2, "gap map and bars");
        assert!(html.contains("No run to draw."));
        assert!(html.contains("bias &lt;from&gt; the prior"), "escaped");
        assert!(html.contains("b.csv (held out)"));
        assert!(html.contains("0.200 deg"));
        assert!(!html.contains("http://"));
        let json = std::fs::read_to_string(dir.join("diagnosis.json")).unwrap();
        assert!(json.contains("\"clock_error\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_path() {
        let dir = temp("blocked");
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("not-a-dir");
        std::fs::write(&file, "x").unwrap();
        let err = write_report(
            &file.join("report"),
            &diagnosis(),
            &[],
            &[],
            &Options::default(),
        )
        .unwrap_err();
        assert!(matches!(err, ReportError::CreateDir { .. }));
        assert!(err.to_string().contains("not-a-dir"), "{err}");
        let err = write_report(&file, &diagnosis(), &[], &[], &Options::default()).unwrap_err();
        assert!(err.to_string().contains("not-a-dir"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn escapes_html() {
        assert_eq!(esc("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }

    #[test]
    fn bins_and_moments() {
        let b = Bins::linear(-1.0, 1.0, 4);
        assert_eq!(b.index(-1.0), Some(0));
        assert_eq!(b.index(1.0), Some(3));
        assert_eq!(b.index(0.1), Some(2));
        assert_eq!(b.index(1.5), None);
        assert_eq!(b.index(f64::NAN), None);
        assert_eq!(b.centres(), vec![-0.75, -0.25, 0.25, 0.75]);
        let mut m = Moments::default();
        [1.0, 2.0, 3.0].iter().for_each(|v| m.add(*v));
        assert_eq!(m.mean(), 2.0);
        assert!((m.std() - 1.0).abs() < 1e-12);
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
}
