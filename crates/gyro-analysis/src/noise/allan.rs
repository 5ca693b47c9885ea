//! Overlapping Allan deviation of rate samples, with chi-squared confidence bounds.
//!
//! For rate samples `y_k` (deg/s) at period τ0, averaging factor `m` and τ = m·τ0 (as
//! `allantools.oadev(y, rate=1/τ0, data_type="freq", taus=m·τ0)`):
//!
//! ```text
//! x_j = τ0 Σ_{k<j} y_k                      (angle, x_0 = 0; j = 0..N)
//! σ²(τ) = Σ_j (x_{j+2m} − 2 x_{j+m} + x_j)² / (2 τ² (N + 1 − 2m))
//! ```
//!
//! computed from one prefix sum per segment (f64, of the mean-removed rate), so each τ
//! costs O(N). Several *segments* (rest stretches, several logs) are pooled: only second
//! differences lying wholly inside one segment count, and σ² is their mean.
//!
//! **τ grid** ([`TauGrid`]): by default about 10 factors per decade, the distinct
//! `round(10^(k/10))` (like allantools' `"log10"`), or allantools' `"octave"` (1, 2, 4, …)
//! and `"decade"` (1, 2, 4, 10, 20, 40, …), up to a quarter of the longest segment
//! (Stable32's stop ratio for the overlapping deviation); explicit factors are kept while
//! at least two second differences exist (allantools drops `n ≤ 1`).
//!
//! **Confidence bounds**: σ²·edf/σ̂² is taken as chi-squared with `edf` equivalent degrees
//! of freedom, the simple approximations of NIST SP 1065 Table 5 (as `allantools.edf_simple`)
//! for the power-law noise that dominates at that τ ([`NoiseType`]), summed over
//! segments. The interval at confidence `c` (default 68.27%, 1σ) is
//! `σ̂ √(edf / χ²_{(1+c)/2}) … σ̂ √(edf / χ²_{(1−c)/2})` (SP 1065 eq. 45). The noise type
//! is white FM (angle random walk) until a fit says otherwise: [`mod@super::fit`] sets it per τ
//! from the local slope of the fitted model.

use super::chi2::chi2_quantile;
use serde::Serialize;

/// 1σ two-sided confidence, erf(1/√2).
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

/// Largest generated averaging factor: a quarter of the longest segment.
pub const STOP_RATIO: usize = 4;

/// How the averaging factors m (τ = m·τ0) are chosen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TauGrid {
    /// 1, 2, 4, 8, … (allantools `"octave"`).
    Octave,
    /// 1, 2, 4, 10, 20, 40, … (allantools/Stable32 `"decade"`).
    Decade,
    /// About `n` per decade: the distinct `round(10^(k/n))`.
    PerDecade(u32),
    /// These factors, where at least two second differences exist.
    Factors(Vec<usize>),
}

impl Default for TauGrid {
    fn default() -> Self {
        TauGrid::PerDecade(10)
    }
}

impl TauGrid {
    /// The averaging factors for segments whose longest has `longest` samples, sorted
    /// and distinct.
    pub fn factors(&self, longest: usize) -> Vec<usize> {
        let max_generated = longest / STOP_RATIO;
        let mut m: Vec<usize> = match self {
            TauGrid::Octave => std::iter::successors(Some(1usize), |m| m.checked_mul(2))
                .take_while(|m| *m <= max_generated)
                .collect(),
            TauGrid::Decade => std::iter::successors(Some(1usize), |m| m.checked_mul(10))
                .take_while(|m| *m <= max_generated)
                .flat_map(|d| [d, 2 * d, 4 * d])
                .filter(|m| *m <= max_generated)
                .collect(),
            TauGrid::PerDecade(n) => {
                let n = f64::from((*n).max(1));
                (0..)
                    .map(|k| 10f64.powf(f64::from(k) / n).round())
                    .take_while(|m| *m <= max_generated as f64)
                    .map(|m| m as usize)
                    .collect()
            }
            TauGrid::Factors(list) => list
                .iter()
                .copied()
                .filter(|m| *m >= 1 && longest > 2 * m)
                .collect(),
        };
        m.sort_unstable();
        m.dedup();
        m
    }
}

/// The power-law noise assumed at a τ for the degrees of freedom (α: exponent of f in
/// the rate PSD; μ: exponent of τ in the Allan variance).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseType {
    /// White phase (angle) noise, α = 2, μ = −2: quantisation noise.
    WhitePm,
    /// White frequency (rate) noise, α = 0, μ = −1: angle random walk.
    WhiteFm,
    /// Flicker frequency noise, α = −1, μ = 0: bias instability.
    FlickerFm,
    /// Random-walk frequency noise, α = −2, μ = +1: rate random walk.
    RandomWalkFm,
}

impl NoiseType {
    /// The power law nearest to a local Allan-variance slope `μ = d ln σ² / d ln τ`.
    pub fn from_avar_slope(mu: f64) -> Self {
        if mu < -1.5 {
            NoiseType::WhitePm
        } else if mu < -0.5 {
            NoiseType::WhiteFm
        } else if mu < 0.5 {
            NoiseType::FlickerFm
        } else {
            NoiseType::RandomWalkFm
        }
    }

    /// Equivalent degrees of freedom of the overlapping Allan variance at factor `m` from
    /// `n_phase` angle points (samples + 1): NIST SP 1065 Table 5.
    pub fn edf(self, n_phase: usize, m: usize) -> f64 {
        let n = n_phase as f64;
        let m = m as f64;
        let edf = match self {
            NoiseType::WhitePm => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
            NoiseType::WhiteFm => {
                (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * (4.0 * m * m)
                    / (4.0 * m * m + 5.0)
            }
            NoiseType::FlickerFm if m < 1.5 => 2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9),
            NoiseType::FlickerFm => 5.0 * n * n / (4.0 * m * (n + 3.0 * m)),
            NoiseType::RandomWalkFm => {
                (n - 2.0) / (m * (n - 3.0) * (n - 3.0))
                    * ((n - 1.0) * (n - 1.0) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
            }
        };
        if edf.is_finite() {
            edf.max(0.0)
        } else {
            0.0
        }
    }
}

/// One τ of the Allan deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AllanPoint {
    /// Averaging factor (τ = m·τ0).
    pub m: usize,
    /// Averaging time (s).
    pub tau_s: f64,
    /// Overlapping Allan deviation (deg/s).
    pub adev_dps: f64,
    /// Lower confidence bound (deg/s).
    pub lower_dps: f64,
    /// Upper confidence bound (deg/s).
    pub upper_dps: f64,
    /// Noise type assumed for the degrees of freedom.
    pub noise: NoiseType,
    /// Equivalent degrees of freedom (summed over segments).
    pub edf: f64,
    /// Second differences averaged (summed over segments).
    pub terms: u64,
}

impl AllanPoint {
    /// Allan variance ((deg/s)²).
    pub fn avar(&self) -> f64 {
        self.adev_dps * self.adev_dps
    }
}

/// An overlapping Allan deviation over one or more segments.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanDeviation {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Confidence of the bounds (e.g. 0.6827).
    pub confidence: f64,
    /// The τ points, increasing.
    pub points: Vec<AllanPoint>,
    /// Samples per segment.
    #[serde(skip)]
    pub segment_lengths: Vec<usize>,
}

impl AllanDeviation {
    /// Compute the overlapping Allan deviation of rate `segments` (deg/s) sampled at
    /// `sample_rate_hz` for averaging `factors`, with white-FM bounds at `confidence`.
    /// Factors without a second difference in any segment are left out.
    pub fn compute(
        segments: &[&[f64]],
        sample_rate_hz: f64,
        factors: &[usize],
        confidence: f64,
    ) -> Self {
        let tau0 = 1.0 / sample_rate_hz;
        // Prefix sums of the mean-removed rate, one per segment: S_0 = 0, S_j = Σ_{k<j}.
        let prefix: Vec<Vec<f64>> = segments
            .iter()
            .map(|seg| {
                let mean = seg.iter().sum::<f64>() / seg.len().max(1) as f64;
                let mut sums = Vec::with_capacity(seg.len() + 1);
                let mut acc = 0.0;
                sums.push(0.0);
                for y in seg.iter() {
                    acc += y - mean;
                    sums.push(acc);
                }
                sums
            })
            .collect();
        let mut points = Vec::with_capacity(factors.len());
        for &m in factors {
            if m == 0 {
                continue;
            }
            let (mut sum_sq, mut terms) = (0.0_f64, 0_u64);
            for s in &prefix {
                if s.len() < 2 * m + 1 {
                    continue;
                }
                let count = s.len() - 2 * m;
                let mut acc = 0.0;
                for j in 0..count {
                    let d = s[j + 2 * m] - 2.0 * s[j + m] + s[j];
                    acc += d * d;
                }
                sum_sq += acc;
                terms += count as u64;
            }
            // allantools drops n ≤ 1.
            if terms < 2 {
                continue;
            }
            let mf = m as f64;
            let avar = sum_sq / (2.0 * mf * mf * terms as f64);
            points.push(AllanPoint {
                m,
                tau_s: mf * tau0,
                adev_dps: avar.sqrt(),
                lower_dps: f64::NAN,
                upper_dps: f64::NAN,
                noise: NoiseType::WhiteFm,
                edf: f64::NAN,
                terms,
            });
        }
        let mut allan = Self {
            sample_rate_hz,
            confidence,
            points,
            segment_lengths: segments.iter().map(|s| s.len()).collect(),
        };
        allan.set_bounds(|_| NoiseType::WhiteFm);
        allan
    }

    /// Equivalent degrees of freedom at factor `m` for `noise`, summed over segments.
    pub fn edf(&self, noise: NoiseType, m: usize) -> f64 {
        let edf: f64 = self
            .segment_lengths
            .iter()
            .filter(|n| **n > 2 * m)
            .map(|n| noise.edf(n + 1, m))
            .sum();
        edf.max(1e-3)
    }

    /// Recompute every point's degrees of freedom and bounds, assuming `noise(tau_s)`.
    pub fn set_bounds(&mut self, noise: impl Fn(f64) -> NoiseType) {
        let lower_p = 0.5 * (1.0 + self.confidence);
        let upper_p = 0.5 * (1.0 - self.confidence);
        for i in 0..self.points.len() {
            let p = self.points[i];
            let kind = noise(p.tau_s);
            let edf = self.edf(kind, p.m);
            let point = &mut self.points[i];
            point.noise = kind;
            point.edf = edf;
            point.lower_dps = p.adev_dps * (edf / chi2_quantile(lower_p, edf)).sqrt();
            point.upper_dps = p.adev_dps * (edf / chi2_quantile(upper_p, edf)).sqrt();
        }
    }

    /// The sample period (s).
    pub fn tau0_s(&self) -> f64 {
        1.0 / self.sample_rate_hz
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids() {
        assert_eq!(TauGrid::Octave.factors(40), vec![1, 2, 4, 8]);
        assert_eq!(TauGrid::Decade.factors(400), vec![1, 2, 4, 10, 20, 40, 100]);
        assert_eq!(
            TauGrid::PerDecade(10).factors(100),
            vec![1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25]
        );
        assert_eq!(
            TauGrid::Factors(vec![0, 3, 1, 5, 3]).factors(10),
            vec![1, 3]
        );
    }

    #[test]
    fn white_noise_of_known_variance() {
        // Alternating ±1: at m = 1 the second differences of the angle are
        // τ0 (y_{j+1} − y_j) = ∓2, so σ² = 4 / 2 = 2.
        let y: Vec<f64> = (0..101)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let allan = AllanDeviation::compute(&[&y], 1.0, &[1, 2], ONE_SIGMA);
        assert!((allan.points[0].avar() - 2.0).abs() < 1e-12);
        // m = 2: every block mean is 0, so σ² = 0.
        assert!(allan.points[1].avar() < 1e-24);
    }

    #[test]
    fn segments_pool_only_inner_differences() {
        let a: Vec<f64> = (0..50).map(|k| (k as f64 * 0.7).sin()).collect();
        let b: Vec<f64> = (0..80).map(|k| (k as f64 * 1.3).cos() + 5.0).collect();
        let pooled = AllanDeviation::compute(&[&a, &b], 10.0, &[1, 3], ONE_SIGMA);
        let only_a = AllanDeviation::compute(&[&a], 10.0, &[1, 3], ONE_SIGMA);
        let only_b = AllanDeviation::compute(&[&b], 10.0, &[1, 3], ONE_SIGMA);
        for i in 0..2 {
            let (pa, pb) = (only_a.points[i], only_b.points[i]);
            let expected = (pa.avar() * pa.terms as f64 + pb.avar() * pb.terms as f64)
                / (pa.terms + pb.terms) as f64;
            assert!((pooled.points[i].avar() - expected).abs() < 1e-12 * expected);
            assert_eq!(pooled.points[i].terms, pa.terms + pb.terms);
        }
    }
}
