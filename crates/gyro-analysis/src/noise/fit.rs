//! Noise terms fitted to an Allan deviation: the numbers a simulator or a
//! Kalibr/`gyroparams`-style configuration takes.
//!
//! The Allan variance of independent noise terms adds. The model (τ in s, rate in deg/s):
//!
//! | term | parameter | σ²(τ) | slope of σ |
//! |---|---|---|---|
//! | quantisation | Q (deg) | 3 Q² / τ² | −1 |
//! | angle random walk | N (deg/s/√Hz = deg/√s; ×60 = deg/√h) | N² / τ | −½ |
//! | bias instability | B (deg/s) | (2 ln 2 / π) B² | 0 |
//! | rate random walk | K (deg/s/√s) | K² τ / 3 | +½ |
//! | Gauss-Markov bias | σ (deg/s), T (s) | σ² g(τ, T) | +½ for τ ≪ T, −½ for τ ≫ T |
//!
//! (IEEE Std 952 Annex C.) So N is the slope −½ asymptote read at τ = 1 s, K the slope +½
//! asymptote read at τ = 3 s, and a flat floor σ_min gives B = σ_min / 0.664.
//! For the first-order Gauss-Markov bias (b' = −b/T + w, stationary σ) in continuous time
//!
//! ```text
//! σ²_GM(τ) = (2 σ² T² / τ²) (τ/T − 3/2 + 2 e^{−τ/T} − ½ e^{−2τ/T})
//! ```
//!
//! → 2σ²τ/(3T) (a rate random walk with K² = 2σ²/T) for τ ≪ T and 2σ²T/τ (white, N² =
//! 2σ²T) for τ ≫ T. The fit uses the exact form for the *sampled* process (AR(1) with
//! φ = e^{−τ0/T}, averages of m = τ/τ0 point samples):
//!
//! ```text
//! σ²_GM(m) = σ²/m² · [m (1+φ)/(1−φ) − φ (3 − 4φ^m + φ^{2m}) / (1−φ)²]
//! ```
//!
//! which equals the continuous form for τ, T ≫ τ0 (both are tested, and against a
//! simulated process).
//!
//! **Method.** σ²(τ) is linear in (Q², N², B², K²), and in σ² at fixed T. The fit is a
//! weighted non-negative least squares over those coefficients (exact: the best of the
//! unconstrained solutions over all subsets of terms that are non-negative), with T scanned
//! on a log grid over the measured τ range (8 per decade) and refined by golden-section
//! search on ln T. Weights are for relative error: the variance of a measured σ̂² is
//! 2σ⁴/edf, so point i weighs edf_i / (2 r_i²) with r_i = √(σ̂²_i σ²_model(τ_i)), the
//! geometric mean of measurement and model: the misfit (σ̂² − σ²_model)²/(σ̂² σ²_model) is
//! then symmetric in their ratio, so a model far above a few sparse long-τ points costs as
//! much as one far below them. The model in the weights (and the noise type behind each
//! edf, from the model's local slope) is iterated three times, starting from the measured
//! values and white FM. The τ points are correlated (they share data), which the weights
//! ignore.
//!
//! **Significance.** Backward elimination: each term in turn is dropped and the rest refitted
//! (T rescanned); the increase of the weighted misfit Δ is compared with a threshold of
//! [`FitOptions::significance`] (default 8) × (τ points per octave) × (parameters: 2 for
//! the Gauss-Markov σ and T, 1 otherwise) — the points are correlated over about an
//! octave, so Δ of one independent degree of freedom spreads over that many points. The
//! term furthest below its threshold is dropped and the test repeats until every remaining
//! term passes. Reported values are those of the final fit (0 for a dropped term). The
//! default was set by simulation: on white noise only (60 runs of 200 s and 2000 s at
//! 100 Hz, 10 τ per decade) the largest Δ seen was 16 for Q and 26 for the Gauss-Markov
//! term against thresholds of about 23 and 45.

use super::allan::{AllanDeviation, NoiseType};
use serde::Serialize;

/// 2 ln 2 / π: σ² of a flicker (bias instability) floor per B².
pub const FLICKER_AVAR_PER_B2: f64 = 0.441_271_200_305_303_1;

/// √(2 ln 2 / π) ≈ 0.664: the Allan deviation floor per unit of bias instability.
pub const FLICKER_ADEV_PER_B: f64 = 0.664_282_477_723_881_6;

/// One fitted parameter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct FitTerm {
    /// Value in the final fit (0 if the term was dropped).
    pub value: f64,
    /// True if the term stayed in the final fit.
    pub significant: bool,
    /// Increase of the weighted misfit when the term is dropped (at the step it was
    /// tested last).
    pub delta_cost: f64,
}

/// The fitted first-order Gauss-Markov bias.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GaussMarkovFit {
    /// Stationary standard deviation (deg/s), 0 if dropped.
    pub sigma_dps: f64,
    /// Correlation time (s), if the term is in the final fit.
    pub corr_time_s: Option<f64>,
    /// True if the term stayed in the final fit.
    pub significant: bool,
    /// Increase of the weighted misfit when the term is dropped.
    pub delta_cost: f64,
}

/// The lowest point of the Allan deviation: the conventional bias-instability reading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct AllanFloor {
    /// Minimum Allan deviation (deg/s).
    pub adev_dps: f64,
    /// Its τ (s).
    pub tau_s: f64,
    /// adev / 0.664 (deg/s).
    pub bias_instability_dps: f64,
    /// True if the minimum is at the longest τ: the curve is still falling, the floor is
    /// not reached and this is only an upper bound.
    pub at_longest_tau: bool,
}

/// Noise parameters fitted to an Allan deviation.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct NoiseFit {
    /// Quantisation noise Q (deg).
    pub quantization_deg: FitTerm,
    /// Angle random walk N (deg/s/√Hz, the same as deg/√s).
    pub arw_dps_per_rt_hz: FitTerm,
    /// Angle random walk N (deg/√h) = 60 N.
    pub arw_deg_per_rt_h: f64,
    /// Bias instability B from the flat term (deg/s).
    pub bias_instability_dps: FitTerm,
    /// Rate random walk K (deg/s/√s).
    pub rate_random_walk_dps_per_rt_s: FitTerm,
    /// First-order Gauss-Markov bias.
    pub gauss_markov: GaussMarkovFit,
    /// The Allan deviation's minimum.
    pub floor: AllanFloor,
    /// Weighted misfit of the final model: Σ edf/2 · (σ̂² − σ²_model)² / (σ̂² σ²_model).
    pub cost: f64,
    /// τ points fitted.
    pub points: usize,
    /// Sample period (s), for the sampled Gauss-Markov form.
    #[serde(skip)]
    pub tau0_s: f64,
}

/// Settings of the fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Threshold of Δmisfit per fitted parameter and per τ point per octave for a term
    /// to be significant (module docs).
    pub significance: f64,
    /// Reweighting iterations.
    pub iterations: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            significance: 8.0,
            iterations: 3,
        }
    }
}

/// `2x − 3 + 4e^{−x} − e^{−2x}` (≈ 2x³/3 for small x), without cancellation.
fn gm_r(x: f64) -> f64 {
    if x < 0.5 {
        // Σ_{k≥3} (−1)^k (4 − 2^k) x^k / k!
        let (mut sum, mut power, mut fact, mut two) = (0.0, x * x, 2.0, 4.0);
        for k in 3..40 {
            power *= x;
            fact *= f64::from(k);
            two *= 2.0;
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sum += sign * (4.0 - two) * power / fact;
        }
        sum
    } else {
        2.0 * x - 3.0 + 4.0 * (-x).exp() - (-2.0 * x).exp()
    }
}

/// `1 − e^{−2a} − 2a e^{−a}` (≈ a³/3 for small a), without cancellation.
fn gm_p(a: f64) -> f64 {
    if a < 0.5 {
        // Σ_{k≥3} (−1)^{k+1} (2^k − 2k) a^k / k!
        let (mut sum, mut power, mut fact, mut two) = (0.0, a * a, 2.0, 4.0);
        for k in 3..40 {
            power *= a;
            fact *= f64::from(k);
            two *= 2.0;
            let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
            sum += sign * (two - 2.0 * f64::from(k)) * power / fact;
        }
        sum
    } else {
        -(-2.0 * a).exp_m1() - 2.0 * a * (-a).exp()
    }
}

/// Allan variance of a sampled first-order Gauss-Markov process of stationary standard
/// deviation `sigma` and correlation time `corr_time_s`, sampled every `tau0_s`, at
/// averaging time `tau_s` (exact for the AR(1) sequence; module docs). Evaluated as
/// `σ² (m p(a) + φ r(m a)) / (m² (1−φ)²)` with a = τ0/T, p(a) = 1 − e^{−2a} − 2a e^{−a}
/// and r(x) = 2x − 3 + 4e^{−x} − e^{−2x}, both by series for small arguments, so that no
/// precision is lost for T ≫ τ.
pub fn gauss_markov_avar(tau_s: f64, tau0_s: f64, sigma: f64, corr_time_s: f64) -> f64 {
    let m = tau_s / tau0_s;
    let a = tau0_s / corr_time_s;
    let eps = -(-a).exp_m1(); // 1 − φ
    let phi = (-a).exp();
    let unit = (m * gm_p(a) + phi * gm_r(m * a)) / (m * m * eps * eps);
    sigma * sigma * unit.max(0.0)
}

/// Allan variance of a continuous first-order Gauss-Markov process (continuous averages):
/// `(2σ²T²/τ²)(τ/T − 3/2 + 2e^{−τ/T} − ½e^{−2τ/T})`.
pub fn gauss_markov_avar_continuous(tau_s: f64, sigma: f64, corr_time_s: f64) -> f64 {
    let x = tau_s / corr_time_s;
    sigma * sigma * gm_r(x) / (x * x)
}

const Q: usize = 0;
const N: usize = 1;
const B: usize = 2;
const K: usize = 3;
const GM: usize = 4;
const ALL: u8 = 0b1_1111;

/// The longest Gauss-Markov correlation time fitted, as a fraction of the longest τ.
const GM_MAX_T_RATIO: f64 = 5.0;

/// Unit basis of term `j` at τ.
fn basis(j: usize, tau_s: f64, tau0_s: f64, corr_time_s: f64) -> f64 {
    match j {
        Q => 3.0 / (tau_s * tau_s),
        N => 1.0 / tau_s,
        B => FLICKER_AVAR_PER_B2,
        K => tau_s / 3.0,
        _ => gauss_markov_avar(tau_s, tau0_s, 1.0, corr_time_s),
    }
}

/// The Allan variance of coefficients `coef` (Q², N², B², K², σ²) at τ.
fn model(coef: &[f64; 5], corr_time_s: f64, tau_s: f64, tau0_s: f64) -> f64 {
    (0..5)
        .filter(|j| coef[*j] > 0.0)
        .map(|j| coef[j] * basis(j, tau_s, tau0_s, corr_time_s))
        .sum()
}

/// Weighted data: τ, measured σ², √weight.
struct Data {
    tau_s: Vec<f64>,
    avar: Vec<f64>,
    sqrt_w: Vec<f64>,
    tau0_s: f64,
}

#[derive(Clone, Copy, Debug)]
struct Solution {
    coef: [f64; 5],
    corr_time_s: f64,
    cost: f64,
}

/// Solve `G_SS x = h_S` by Cholesky; `None` if not positive definite.
#[allow(clippy::needless_range_loop)] // index notation mirrors the algorithm
fn cholesky_solve(g: &[[f64; 5]; 5], h: &[f64; 5], idx: &[usize]) -> Option<Vec<f64>> {
    let k = idx.len();
    let mut l = vec![vec![0.0; k]; k];
    for i in 0..k {
        for j in 0..=i {
            let mut s = g[idx[i]][idx[j]];
            for p in 0..j {
                s -= l[i][p] * l[j][p];
            }
            if i == j {
                if s <= 1e-12 * g[idx[i]][idx[i]].max(1e-300) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = vec![0.0; k];
    for i in 0..k {
        let mut s = h[idx[i]];
        for p in 0..i {
            s -= l[i][p] * y[p];
        }
        y[i] = s / l[i][i];
    }
    let mut x = vec![0.0; k];
    for i in (0..k).rev() {
        let mut s = y[i];
        for p in i + 1..k {
            s -= l[p][i] * x[p];
        }
        x[i] = s / l[i][i];
    }
    Some(x)
}

/// Non-negative weighted least squares over the terms in `mask` at GM time `corr_time_s`.
#[allow(clippy::needless_range_loop)] // index notation mirrors the algorithm
fn solve_fixed(data: &Data, mask: u8, corr_time_s: f64) -> Solution {
    let n = data.tau_s.len();
    // Weighted, unit-norm columns.
    let mut a = vec![[0.0_f64; 5]; n];
    let mut scale = [0.0_f64; 5];
    for j in 0..5 {
        if mask & (1 << j) == 0 {
            continue;
        }
        let mut norm2 = 0.0;
        for i in 0..n {
            let v = data.sqrt_w[i] * basis(j, data.tau_s[i], data.tau0_s, corr_time_s);
            a[i][j] = v;
            norm2 += v * v;
        }
        scale[j] = norm2.sqrt();
    }
    let b: Vec<f64> = (0..n).map(|i| data.sqrt_w[i] * data.avar[i]).collect();
    let bb: f64 = b.iter().map(|v| v * v).sum();
    let mut g = [[0.0_f64; 5]; 5];
    let mut h = [0.0_f64; 5];
    for j in 0..5 {
        if scale[j] <= 0.0 || !scale[j].is_finite() {
            continue;
        }
        for i in 0..n {
            h[j] += a[i][j] / scale[j] * b[i];
        }
        for k in 0..=j {
            if scale[k] <= 0.0 || !scale[k].is_finite() {
                continue;
            }
            let mut s = 0.0;
            for row in &a {
                s += row[j] * row[k];
            }
            g[j][k] = s / (scale[j] * scale[k]);
            g[k][j] = g[j][k];
        }
    }
    let usable: u8 = (0..5)
        .filter(|j| mask & (1 << j) != 0 && scale[*j] > 0.0 && scale[*j].is_finite())
        .fold(0, |m, j| m | (1 << j));
    let mut best = Solution {
        coef: [0.0; 5],
        corr_time_s,
        cost: bb,
    };
    for subset in 1..=usable {
        if subset & !usable != 0 {
            continue;
        }
        let idx: Vec<usize> = (0..5).filter(|j| subset & (1 << j) != 0).collect();
        if idx.len() > n {
            continue;
        }
        let Some(x) = cholesky_solve(&g, &h, &idx) else {
            continue;
        };
        if x.iter().any(|v| *v < 0.0) {
            continue;
        }
        let cost = bb - idx.iter().zip(&x).map(|(j, v)| h[*j] * v).sum::<f64>();
        if cost < best.cost {
            let mut coef = [0.0; 5];
            for (j, v) in idx.iter().zip(&x) {
                coef[*j] = v / scale[*j];
            }
            best = Solution {
                coef,
                corr_time_s,
                cost: cost.max(0.0),
            };
        }
    }
    best
}

/// As [`solve_fixed`], scanning the Gauss-Markov correlation time if `mask` has it.
fn solve(data: &Data, mask: u8) -> Solution {
    let (Some(first), Some(last)) = (data.tau_s.first(), data.tau_s.last()) else {
        return Solution {
            coef: [0.0; 5],
            corr_time_s: f64::NAN,
            cost: 0.0,
        };
    };
    if mask & (1 << GM) == 0 || *last <= first * GM_MAX_T_RATIO {
        return solve_fixed(data, mask & !(1 << GM), f64::NAN);
    }
    // T from τ_min to τ_max / 5: the Allan hump (at ≈ 1.9 T) and part of the fall after
    // it must lie in the data, else the term is a rate random walk over the range.
    let (lo, hi) = (first.ln(), (last / GM_MAX_T_RATIO).ln().max(first.ln()));
    let steps = ((hi - lo) / std::f64::consts::LN_10 * 8.0).ceil().max(2.0) as usize;
    let grid: Vec<f64> = (0..=steps)
        .map(|k| lo + (hi - lo) * k as f64 / steps as f64)
        .collect();
    let at = |ln_t: f64| solve_fixed(data, mask, ln_t.exp());
    let scanned: Vec<Solution> = grid.iter().map(|ln_t| at(*ln_t)).collect();
    let mut best_k = 0;
    for (k, s) in scanned.iter().enumerate() {
        if s.cost < scanned[best_k].cost {
            best_k = k;
        }
    }
    let mut best = scanned[best_k];
    // Golden-section refinement between the neighbours of the best grid point.
    let (a, b) = (
        grid[best_k.saturating_sub(1)],
        grid[(best_k + 1).min(steps)],
    );
    let end = crate::golden::minimize(at, |s: &Solution| s.cost, a, b, 40);
    let [(_, fc), (_, fd)] = end.inner;
    for s in [fc, fd] {
        if s.cost < best.cost {
            best = s;
        }
    }
    if best.coef[GM] <= 0.0 {
        best.corr_time_s = f64::NAN;
    }
    best
}

/// The local Allan-variance slope d ln σ²/d ln τ of a model.
fn model_slope(coef: &[f64; 5], corr_time_s: f64, tau_s: f64, tau0_s: f64) -> f64 {
    let h = 0.05;
    let up = model(coef, corr_time_s, tau_s * (1.0 + h), tau0_s);
    let down = model(coef, corr_time_s, tau_s / (1.0 + h), tau0_s);
    if up > 0.0 && down > 0.0 {
        (up / down).ln() / (2.0 * (1.0 + h).ln())
    } else {
        -1.0
    }
}

impl NoiseFit {
    fn coefficients(&self) -> ([f64; 5], f64) {
        let sq = |v: f64| v * v;
        (
            [
                sq(self.quantization_deg.value),
                sq(self.arw_dps_per_rt_hz.value),
                sq(self.bias_instability_dps.value),
                sq(self.rate_random_walk_dps_per_rt_s.value),
                sq(self.gauss_markov.sigma_dps),
            ],
            self.gauss_markov.corr_time_s.unwrap_or(f64::NAN),
        )
    }

    /// The fitted model's Allan variance at τ ((deg/s)²).
    pub fn avar(&self, tau_s: f64) -> f64 {
        let (coef, t) = self.coefficients();
        model(&coef, t, tau_s, self.tau0_s)
    }

    /// The fitted model's Allan deviation at τ (deg/s).
    pub fn adev(&self, tau_s: f64) -> f64 {
        self.avar(tau_s).sqrt()
    }

    /// The power-law noise the fitted model is closest to at τ (for confidence bounds).
    pub fn noise_type(&self, tau_s: f64) -> NoiseType {
        let (coef, t) = self.coefficients();
        NoiseType::from_avar_slope(model_slope(&coef, t, tau_s, self.tau0_s))
    }
}

/// The Allan deviation's minimum.
fn floor(allan: &AllanDeviation) -> AllanFloor {
    let mut best: Option<(usize, f64, f64)> = None;
    for (i, p) in allan.points.iter().enumerate() {
        if best.is_none_or(|(_, adev, _)| p.adev_dps < adev) {
            best = Some((i, p.adev_dps, p.tau_s));
        }
    }
    match best {
        Some((i, adev, tau)) => AllanFloor {
            adev_dps: adev,
            tau_s: tau,
            bias_instability_dps: adev / FLICKER_ADEV_PER_B,
            at_longest_tau: i + 1 == allan.points.len(),
        },
        None => AllanFloor::default(),
    }
}

/// Fit the noise terms to `allan` (see the module docs).
pub fn fit(allan: &AllanDeviation, options: &FitOptions) -> NoiseFit {
    let tau0_s = allan.tau0_s();
    let tau_s: Vec<f64> = allan.points.iter().map(|p| p.tau_s).collect();
    let avar: Vec<f64> = allan.points.iter().map(|p| p.avar()).collect();
    let max_avar = avar.iter().copied().fold(0.0, f64::max);
    let mut result = NoiseFit {
        floor: floor(allan),
        points: tau_s.len(),
        tau0_s,
        ..NoiseFit::default()
    };
    if tau_s.is_empty() || max_avar <= 0.0 {
        return result;
    }
    let data = reweighted_data(allan, &tau_s, &avar, max_avar * 1e-30, options.iterations);
    let (current, mask, delta) = backward_elimination(&data, &tau_s, options.significance);
    let term = |j: usize| FitTerm {
        value: current.coef[j].max(0.0).sqrt(),
        significant: mask & (1 << j) != 0,
        delta_cost: delta[j],
    };
    result.quantization_deg = term(Q);
    result.arw_dps_per_rt_hz = term(N);
    result.arw_deg_per_rt_h = 60.0 * result.arw_dps_per_rt_hz.value;
    result.bias_instability_dps = term(B);
    result.rate_random_walk_dps_per_rt_s = term(K);
    let gm = term(GM);
    result.gauss_markov = GaussMarkovFit {
        sigma_dps: gm.value,
        corr_time_s: (gm.significant && current.corr_time_s.is_finite())
            .then_some(current.corr_time_s),
        significant: gm.significant,
        delta_cost: gm.delta_cost,
    };
    result.cost = final_cost(allan, &current, tau0_s);
    result
}

/// The weight of each point of `allan`: √(edf/2) of its `noise` type over its
/// `reference` variance (floored at `tiny`).
fn edf_weights(
    allan: &AllanDeviation,
    reference: &[f64],
    noise: &[NoiseType],
    tiny: f64,
) -> Vec<f64> {
    allan
        .points
        .iter()
        .zip(reference)
        .zip(noise)
        .map(|((p, r), kind)| (allan.edf(*kind, p.m) / 2.0).sqrt() / r.max(tiny))
        .collect()
}

/// The fit's data: the Allan variances `avar` at `tau_s`, weighted after `iterations`
/// rounds (at least one) of fitting every term and weighting each point by the noise type
/// and level of the model there (`tiny`: the least variance a weight divides by).
fn reweighted_data(
    allan: &AllanDeviation,
    tau_s: &[f64],
    avar: &[f64],
    tiny: f64,
    iterations: usize,
) -> Data {
    let tau0_s = allan.tau0_s();
    let mut reference = avar.to_vec();
    let mut noise = vec![NoiseType::WhiteFm; tau_s.len()];
    let mut data = Data {
        tau_s: tau_s.to_vec(),
        avar: avar.to_vec(),
        sqrt_w: edf_weights(allan, &reference, &noise, tiny),
        tau0_s,
    };
    for _ in 0..iterations.max(1) {
        let full = solve(&data, ALL);
        for (i, t) in tau_s.iter().enumerate() {
            let value = model(&full.coef, full.corr_time_s, *t, tau0_s);
            // Geometric mean of measurement and model: the misfit (a − m)²/(a m) is then
            // symmetric in a/m ↔ m/a, so a model far above sparse long-τ points is not
            // cheaper than one far below them.
            reference[i] = if value > 0.0 {
                (value * avar[i].max(tiny)).sqrt()
            } else {
                avar[i]
            };
            noise[i] =
                NoiseType::from_avar_slope(model_slope(&full.coef, full.corr_time_s, *t, tau0_s));
        }
        data.sqrt_w = edf_weights(allan, &reference, &noise, tiny);
    }
    data
}

/// Backward elimination of the terms: drop the weakest term while its cost is below its
/// threshold (`significance` per octave of `tau_s`, twice for the Gauss-Markov term's
/// two parameters). The final solution, the mask of the terms kept, and each term's
/// cost when last dropped (0 if never tried).
fn backward_elimination(data: &Data, tau_s: &[f64], significance: f64) -> (Solution, u8, [f64; 5]) {
    // Backward elimination.
    let octaves = (tau_s[tau_s.len() - 1] / tau_s[0]).log2().max(1.0);
    let per_octave = (tau_s.len() as f64 / octaves).max(1.0);
    // σ and T for the Gauss-Markov term, one parameter for the others.
    let threshold = |j: usize| significance * per_octave * if j == GM { 2.0 } else { 1.0 };
    let mut mask = ALL;
    let mut current = solve(data, mask);
    let mut delta = [0.0_f64; 5];
    // Terms with a zero coefficient add nothing: drop them first.
    for j in 0..5 {
        if current.coef[j] <= 0.0 {
            mask &= !(1 << j);
        }
    }
    current = solve(data, mask);
    loop {
        let mut weakest: Option<(usize, f64, Solution)> = None;
        for j in (0..5).filter(|j| mask & (1 << j) != 0) {
            let without = solve(data, mask & !(1 << j));
            let d = (without.cost - current.cost).max(0.0);
            delta[j] = d;
            // The weakest term relative to its threshold.
            let margin = d / threshold(j);
            if weakest.as_ref().is_none_or(|(_, wm, _)| margin < *wm) {
                weakest = Some((j, margin, without));
            }
        }
        match weakest {
            Some((j, margin, without)) if margin < 1.0 => {
                mask &= !(1 << j);
                current = without;
                for k in 0..5 {
                    if current.coef[k] <= 0.0 && mask & (1 << k) != 0 {
                        mask &= !(1 << k);
                    }
                }
            }
            _ => break,
        }
    }
    (current, mask, delta)
}

/// The final misfit of the solution `current` to `allan`, with weights from the final
/// model.
fn final_cost(allan: &AllanDeviation, current: &Solution, tau0_s: f64) -> f64 {
    // The final misfit with weights from the final model.
    allan
        .points
        .iter()
        .map(|p| {
            let m = model(&current.coef, current.corr_time_s, p.tau_s, tau0_s);
            let edf = allan.edf(
                NoiseType::from_avar_slope(model_slope(
                    &current.coef,
                    current.corr_time_s,
                    p.tau_s,
                    tau0_s,
                )),
                p.m,
            );
            if m > 0.0 && p.avar() > 0.0 {
                edf / 2.0 * (p.avar() - m).powi(2) / (p.avar() * m)
            } else {
                0.0
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact Allan variance of an AR(1) sequence from its autocovariance, by brute force.
    fn ar1_avar_direct(m: usize, phi: f64, sigma: f64) -> f64 {
        let r = |k: i64| sigma * sigma * phi.powi(k.unsigned_abs() as i32);
        let mi = m as i64;
        let (mut var, mut cov) = (0.0, 0.0);
        for k in -(mi - 1)..mi {
            let w = (mi - k.abs()) as f64;
            var += w * r(k);
            cov += w * r(mi + k);
        }
        (var - cov) / (m * m) as f64
    }

    #[test]
    fn sampled_gauss_markov_formula_is_exact() {
        let tau0: f64 = 0.01;
        for corr_time in [0.02, 0.1, 1.0, 100.0, 1e5] {
            let phi = (-tau0 / corr_time).exp();
            for m in [1usize, 2, 3, 10, 57, 400] {
                let direct = ar1_avar_direct(m, phi, 0.7);
                let closed = gauss_markov_avar(m as f64 * tau0, tau0, 0.7, corr_time);
                assert!(
                    (closed - direct).abs() <= 1e-9 * direct,
                    "T {corr_time} m {m}: {closed} vs {direct}"
                );
            }
        }
    }

    #[test]
    fn continuous_form_is_the_limit_for_long_tau_and_t() {
        let tau0 = 1e-3;
        for corr_time in [1.0, 10.0] {
            for tau in [0.1, 1.0, 5.0, 30.0, 300.0] {
                let sampled = gauss_markov_avar(tau, tau0, 1.0, corr_time);
                let continuous = gauss_markov_avar_continuous(tau, 1.0, corr_time);
                assert!(
                    (sampled / continuous - 1.0).abs() < 0.01,
                    "T {corr_time} tau {tau}: {sampled} vs {continuous}"
                );
            }
            // Asymptotes: 2σ²τ/(3T) and 2σ²T/τ.
            let short = gauss_markov_avar_continuous(1e-4 * corr_time, 1.0, corr_time);
            assert!((short / (2.0 * 1e-4 / 3.0) - 1.0).abs() < 1e-3);
            let long = gauss_markov_avar_continuous(1e4 * corr_time, 1.0, corr_time);
            assert!((long / (2.0 / 1e4) - 1.0).abs() < 1e-3);
        }
    }

    #[test]
    fn nnls_recovers_exact_model_coefficients() {
        // Noise-free Allan variance of Q, N, K and a GM term: the fit must return them.
        let tau0 = 0.01;
        let (q, n, k, s, t) = (2e-4, 5e-3, 1e-3, 0.03, 2.0);
        let taus: Vec<f64> = (0..50)
            .map(|i| tau0 * 10f64.powf(i as f64 / 10.0))
            .collect();
        let avar: Vec<f64> = taus
            .iter()
            .map(|tau| {
                3.0 * q * q / (tau * tau)
                    + n * n / tau
                    + k * k * tau / 3.0
                    + gauss_markov_avar(*tau, tau0, s, t)
            })
            .collect();
        let data = Data {
            sqrt_w: avar.iter().map(|a| 1.0 / a).collect(),
            tau_s: taus,
            avar,
            tau0_s: tau0,
        };
        let sol = solve(&data, ALL);
        let got = [
            sol.coef[Q].sqrt(),
            sol.coef[N].sqrt(),
            sol.coef[K].sqrt(),
            sol.coef[GM].sqrt(),
        ];
        for (g, want) in got.iter().zip([q, n, k, s]) {
            assert!((g / want - 1.0).abs() <= 1e-4, "{got:?}");
        }
        let smallest = data.avar.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(
            sol.coef[B] * FLICKER_AVAR_PER_B2 < 1e-6 * smallest,
            "{}",
            sol.coef[B]
        );
        assert!(
            (sol.corr_time_s / t - 1.0).abs() < 1e-4,
            "{}",
            sol.corr_time_s
        );
    }
}
