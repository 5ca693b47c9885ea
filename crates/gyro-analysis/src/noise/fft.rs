//! An in-place iterative radix-2 FFT (power-of-two lengths), enough for Welch's method.
//!
//! A small own routine rather than a dependency: Welch segments are chosen as powers of
//! two, and the test compares it with a direct DFT.

/// In-place forward DFT `X_k = Σ x_n e^{−2πi kn/N}` of `re + i·im`; `re.len()` must be a
/// power of two and equal `im.len()`.
pub fn fft_in_place(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    debug_assert!(n.is_power_of_two() && im.len() == n);
    if n < 2 {
        return;
    }
    // Bit-reversal permutation.
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    // Butterflies, with twiddles computed directly per stage (accurate to ~1e-15).
    let mut len = 2;
    while len <= n {
        let half = len / 2;
        let angle = -2.0 * std::f64::consts::PI / len as f64;
        let twiddles: Vec<(f64, f64)> = (0..half)
            .map(|k| {
                let a = angle * k as f64;
                (a.cos(), a.sin())
            })
            .collect();
        for start in (0..n).step_by(len) {
            for (k, &(wr, wi)) in twiddles.iter().enumerate() {
                let (a, b) = (start + k, start + k + half);
                let tr = re[b] * wr - im[b] * wi;
                let ti = re[b] * wi + im[b] * wr;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_direct_dft() {
        for n in [1usize, 2, 4, 8, 64, 256] {
            let x: Vec<f64> = (0..n)
                .map(|i| ((i * 7919) % 31) as f64 - 15.0 + 0.1 * i as f64)
                .collect();
            let (mut re, mut im) = (x.clone(), vec![0.0; n]);
            fft_in_place(&mut re, &mut im);
            for k in 0..n {
                let (mut dr, mut di) = (0.0, 0.0);
                for (t, v) in x.iter().enumerate() {
                    let a = -2.0 * std::f64::consts::PI * (k * t) as f64 / n as f64;
                    dr += v * a.cos();
                    di += v * a.sin();
                }
                let scale = 1.0 + dr.abs() + di.abs();
                assert!((re[k] - dr).abs() < 1e-9 * scale, "n {n} k {k}");
                assert!((im[k] - di).abs() < 1e-9 * scale, "n {n} k {k}");
            }
        }
    }
}
