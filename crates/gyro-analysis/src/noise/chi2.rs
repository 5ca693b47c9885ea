//! The chi-squared quantile, for the confidence interval of a variance estimate with a
//! non-integer number of equivalent degrees of freedom.
//!
//! `ln Γ` by the Lanczos approximation (g = 7, 9 terms), the regularised lower incomplete
//! gamma function `P(a, x)` by its series (x < a + 1) or continued fraction (Numerical
//! Recipes §6.2), and the quantile by bisection on `P`. Checked against
//! `scipy.stats.chi2.ppf` (`fixtures/noise/chi2_reference.csv`).

/// ln Γ(x) for x > 0.
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// Regularised lower incomplete gamma function P(a, x), a > 0, x ≥ 0.
fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let log_prefix = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        // Series: P = e^{-x} x^a / Γ(a+1) Σ x^n / ((a+1)...(a+n)).
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum.ln() + log_prefix).exp().min(1.0)
    } else {
        // Continued fraction for Q = 1 − P (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (1.0 - (log_prefix.exp() * h)).max(0.0)
    }
}

/// The `p` quantile of the chi-squared distribution with `dof` degrees of freedom
/// (`dof` > 0, not necessarily an integer; 0 < `p` < 1).
pub fn chi2_quantile(p: f64, dof: f64) -> f64 {
    let a = 0.5 * dof;
    let cdf = |x: f64| gamma_p(a, 0.5 * x);
    let (mut lo, mut hi) = (0.0_f64, dof.max(1.0));
    while cdf(hi) < p {
        lo = hi;
        hi *= 2.0;
        if hi > 1e300 {
            return f64::INFINITY;
        }
    }
    // Bisection on a log scale near 0 (small dof puts the low quantiles at tiny x),
    // linear otherwise.
    for _ in 0..200 {
        let mid = if lo > 0.0 && hi / lo > 4.0 {
            (lo * hi).sqrt()
        } else if lo == 0.0 && hi > 1e-300 {
            hi * 1e-3
        } else {
            0.5 * (lo + hi)
        };
        if cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= hi * 1e-14 {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_known_values() {
        assert!((ln_gamma(1.0)).abs() < 1e-14);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    }

    #[test]
    fn chi2_two_dof_is_exponential() {
        // chi2(2): CDF 1 − e^{−x/2}, quantile −2 ln(1 − p).
        for p in [0.01, 0.3, 0.5, 0.9, 0.999] {
            let q = chi2_quantile(p, 2.0);
            let exact = -2.0 * (1.0 - p).ln();
            assert!((q - exact).abs() <= 1e-10 * exact, "{p}: {q} vs {exact}");
        }
    }
}
