//! The data of the diagnose report's figures: real runs against simulated envelopes.
//!
//! The runs are re-simulated with the nominal model (and, when effects were selected,
//! with the model holding them) with the seeds of the diagnosis' baseline ensemble
//! (`member_seed` of run and member), [`REPORT_MEMBERS`] members each, so the nominal
//! band is drawn from the very ensemble the z-scores were computed against. Every real
//! and simulated run goes through the same residuals (`residuals`) and [`Measures`],
//! pooled over the runs (like [`gyro_analysis::noise`] pools segments) for the real runs and,
//! member by member, for the simulated ones. When the runs hold more than
//! [`SAMPLE_BUDGET`] samples, an evenly spaced subset of training and held-out runs is
//! used (real and simulated alike).

use super::ensemble::{member_seed, simulate_residuals, RealRun};
use super::stats::{residuals, stretches, Residuals};
use super::{Diagnosis, Options};
use gyro_analysis::noise::{welch, AllanDeviation, PsdOptions, TauGrid, ONE_SIGMA};
use gyro_sim::{Effect, SensorModel};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Simulated members per run for the envelopes (at most the diagnosis' members).
pub const REPORT_MEMBERS: usize = 12;
/// Samples of real runs the figures use at most (each simulated [`REPORT_MEMBERS`]
/// times per model): 11 of 20 runs of 90 s at 1 kHz, about 7 s of CPU with one set of
/// selected effects.
pub const SAMPLE_BUDGET: usize = 1_000_000;
/// Bins of the reference rate and of the angular acceleration.
pub const SIGNED_BINS: usize = 24;
/// Bins of the temperature change.
pub const TEMPERATURE_BINS: usize = 12;
/// Welch segment length (s), rounded down to a power of two of samples.
pub const PSD_SEGMENT_S: f64 = 4.0;
/// Bands per decade of the PSD.
pub const PSD_BANDS_PER_DECADE: f64 = 10.0;

// ---------------------------------------------------------------------------------------
// Measures of one run, poolable over runs.

/// Count, sum and sum of squares.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// Count.
    pub n: f64,
    /// Σ v.
    pub sum: f64,
    /// Σ v².
    pub sum_sq: f64,
}

impl Moments {
    /// Add one value.
    pub fn add(&mut self, v: f64) {
        self.n += 1.0;
        self.sum += v;
        self.sum_sq += v * v;
    }

    /// Add another set's moments.
    pub fn merge(&mut self, o: &Moments) {
        self.n += o.n;
        self.sum += o.sum;
        self.sum_sq += o.sum_sq;
    }

    /// Mean (NaN when empty).
    pub fn mean(&self) -> f64 {
        if self.n > 0.0 {
            self.sum / self.n
        } else {
            f64::NAN
        }
    }

    /// Sample standard deviation (NaN below two values).
    pub fn std(&self) -> f64 {
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
pub struct Bins {
    /// Bin edges, increasing.
    pub edges: Vec<f64>,
}

impl Bins {
    /// `n` equal bins from `lo` to `hi`.
    pub fn linear(lo: f64, hi: f64, n: usize) -> Self {
        Self {
            edges: (0..=n)
                .map(|i| lo + (hi - lo) * i as f64 / n as f64)
                .collect(),
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.edges.len().saturating_sub(1)
    }

    /// True without a bin.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bin of `v` (the last bin includes its upper edge); `None` outside.
    pub fn index(&self, v: f64) -> Option<usize> {
        let (lo, hi) = (*self.edges.first()?, *self.edges.last()?);
        if !(v.is_finite() && v >= lo && v <= hi && hi > lo) {
            return None;
        }
        let k = ((v - lo) / (hi - lo) * self.len() as f64).floor() as usize;
        Some(k.min(self.len() - 1))
    }

    /// Bin centres.
    pub fn centres(&self) -> Vec<f64> {
        self.edges.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect()
    }
}

/// What every run is measured with (fixed from the real runs before any simulation).
#[derive(Clone, Debug)]
pub struct Setup {
    /// Sample rate (Hz).
    pub fs: f64,
    /// Averaging factors of the Allan deviation.
    pub allan_factors: Vec<usize>,
    /// Welch segment length (samples, a power of two).
    pub psd_len: usize,
    /// Bins of the reference rate (deg/s).
    pub rate: Bins,
    /// Bins of the angular acceleration (deg/s²).
    pub acceleration: Bins,
    /// Bins of the temperature change (°C), when it varies enough.
    pub temperature: Option<Bins>,
    /// Lags of the cross-correlation (samples).
    pub lags: Vec<i64>,
}

/// A run's (or pooled runs') figure statistics.
#[derive(Clone, Debug, Default)]
pub struct Measures {
    /// Per averaging factor: Σ avar·terms and Σ terms of the static residual.
    pub allan: BTreeMap<usize, (f64, f64)>,
    /// Σ PSD·segments per bin, and Σ segments.
    pub psd: Vec<f64>,
    /// Σ segments of the PSD.
    pub psd_segments: f64,
    /// Residual (deg/s) per reference-rate bin.
    pub rate: Vec<Moments>,
    /// Residual (deg/s) per acceleration bin, in motion.
    pub acceleration: Vec<Moments>,
    /// Residual (deg/s) per temperature-change bin, at rest.
    pub temperature: Vec<Moments>,
    /// `Σ g[i+lag]·r[i]` per lag, `Σ g²`, `Σ r²` (means removed per run).
    pub xcorr: Vec<f64>,
    /// Σ g² (gyro rate, mean removed).
    pub g2: f64,
    /// Σ r² (reference rate, mean removed).
    pub r2: f64,
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
    /// Empty measures for `setup`.
    pub(crate) fn new(setup: &Setup) -> Self {
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

    /// Pool another run's measures into these.
    pub(crate) fn merge(&mut self, o: &Measures) {
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

    /// The measures of one run's residuals.
    pub(crate) fn of(r: &Residuals, setup: &Setup) -> Self {
        let mut out = Self::new(setup);
        out.add_static_allan(r, setup);
        out.add_psd(r, setup);
        out.add_binned(r, setup);
        out.set_xcorr(r, setup);
        out
    }

    /// Adds the Allan variance sums of `r`'s static residual, each static stretch a
    /// segment.
    fn add_static_allan(&mut self, r: &Residuals, setup: &Setup) {
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
                self.allan
                    .insert(p.m, (p.avar() * p.terms as f64, p.terms as f64));
            }
        }
    }

    /// Adds the Welch PSD of `r`'s residual (weighted by its segments) over every stretch
    /// long enough for a segment.
    fn add_psd(&mut self, r: &Residuals, setup: &Setup) {
        let n = r.residual_dps.len();
        let res = &r.residual_dps;
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
            self.psd
                .iter_mut()
                .zip(&psd.psd_dps2_per_hz)
                .for_each(|(a, p)| *a += p * k);
            self.psd_segments += k;
        }
    }

    /// Adds `r`'s residuals to the bins of reference rate, of acceleration (in motion) and
    /// of temperature change (at rest).
    fn add_binned(&mut self, r: &Residuals, setup: &Setup) {
        let res = &r.residual_dps;
        // Binned residuals.
        let t0 = r.temperature_c.iter().copied().find(|t| t.is_finite());
        for (i, &v) in res.iter().enumerate() {
            if !v.is_finite() {
                continue;
            }
            if let Some(k) = setup.rate.index(r.reference_rate_dps[i]) {
                self.rate[k].add(v);
            }
            if !r.is_static[i] {
                if let Some(k) = setup.acceleration.index(r.reference_acceleration_dps2[i]) {
                    self.acceleration[k].add(v);
                }
            } else if let (Some(bins), Some(t0)) = (&setup.temperature, t0) {
                if let Some(k) = bins.index(r.temperature_c[i] - t0) {
                    self.temperature[k].add(v);
                }
            }
        }
    }

    /// Sets the cross-correlation sums of `r`'s gyro and reference rate (means removed)
    /// at the setup's lags, and their energies.
    fn set_xcorr(&mut self, r: &Residuals, setup: &Setup) {
        let n = r.residual_dps.len();
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
            self.g2 = g.iter().map(|v| v * v).sum();
            self.r2 = rr.iter().map(|v| v * v).sum();
            for (c, &lag) in self.xcorr.iter_mut().zip(&setup.lags) {
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
    }

    /// Pooled Allan deviation: (τ, σ).
    pub fn allan_curve(&self, fs: f64) -> Vec<(f64, f64)> {
        self.allan
            .iter()
            .filter(|(_, (_, t))| *t >= 2.0)
            .map(|(m, (a, t))| (*m as f64 / fs, (a / t).sqrt()))
            .collect()
    }

    /// PSD averaged over log bands: (centre frequency, PSD).
    pub fn psd_bands(&self, setup: &Setup) -> Vec<(f64, f64)> {
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
    pub fn xcorr_curve(&self) -> Vec<f64> {
        let norm = (self.g2 * self.r2).sqrt();
        self.xcorr
            .iter()
            .map(|c| if norm > 0.0 { c / norm } else { f64::NAN })
            .collect()
    }
}

/// Quantile `q` of the finite `values` (nearest rank).
pub fn quantile(values: &mut [f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    let k = ((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
    Some(*v.select_nth_unstable_by(k, f64::total_cmp).1)
}

/// The measurement set-up from the real runs' residuals.
fn setup(real: &[Residuals], fs: f64, settings: &crate::Settings) -> Setup {
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
    let quantiles = &settings.envelopes;
    let rate_max = span(&mut abs_rate, quantiles.rate_quantile);
    let acc_max = span(&mut abs_acc, quantiles.acceleration_quantile);
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
        (hi - lo >= settings.statistics.min_temperature_range_c)
            .then(|| Bins::linear(lo, hi, TEMPERATURE_BINS))
    };
    let max_lag = ((settings.statistics.max_lag_s * fs).round() as i64).max(1);
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
pub struct SimModel {
    /// What the model is, as the figures label it.
    pub label: String,
    /// The sensor model.
    pub model: SensorModel,
    /// The effects added to it.
    pub effects: Vec<Effect>,
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

/// Everything the diagnose report's figures draw: the real runs' pooled measures and
/// each simulated model's, member by member.
pub struct Envelopes {
    /// What every run is measured with.
    pub setup: Setup,
    /// The real runs, pooled.
    pub real: Measures,
    /// The simulated models: the nominal one, then the selected one if any.
    pub models: Vec<SimModel>,
    /// Pooled measures per model and member (`[model][member]`).
    pub sims: Vec<Vec<Measures>>,
    /// Members per model.
    pub members: usize,
    /// Runs the figures use.
    pub runs_used: usize,
    /// Runs of the diagnosis.
    pub runs_total: usize,
    /// Real runs whose residuals could not be computed, and why.
    pub real_errors: Vec<String>,
}

/// The envelopes of the diagnosis `d` of `train` and `holdout` (the runs it was computed
/// from, in the same order) with `options`: every figure run re-simulated with the
/// nominal model and, when effects were selected, the selected model, with the seeds of
/// the baseline ensemble. `None` without runs.
pub fn envelopes(
    d: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
) -> Option<Envelopes> {
    let runs = figure_runs(train, holdout);
    let computed: Vec<_> = runs
        .par_iter()
        .map(|f| residuals(&f.run.log, &f.run.statistics))
        .collect();
    let mut real_errors = Vec::new();
    let mut real_res: Vec<Residuals> = Vec::new();
    for (f, r) in runs.iter().zip(computed) {
        match r {
            Ok(r) => real_res.push(r),
            Err(e) => real_errors.push(format!("{}: {e}", f.run.name)),
        }
    }
    let fs = runs.first()?.run.sample_rate_hz;
    let setup = setup(&real_res, fs, &options.settings);
    let mut real = Measures::new(&setup);
    for r in &real_res {
        real.merge(&Measures::of(r, &setup));
    }
    drop(real_res);
    let mut models = vec![SimModel {
        label: "nominal model".to_string(),
        model: d.model.sensor,
        effects: Vec::new(),
    }];
    if !d.model.effects.is_empty() {
        let ids: Vec<&str> = d.model.effects.iter().map(Effect::id).collect();
        models.push(SimModel {
            label: format!("nominal + {}", ids.join(" + ")),
            model: d.selected_sensor,
            effects: d.model.effects.clone(),
        });
    }
    let members = REPORT_MEMBERS.min(options.members).max(2);
    let sims = simulate_all(&runs, &models, members, options.seed, &setup);
    Some(Envelopes {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
