//! Golden-section search for a minimum on an interval: the refinement after a grid scan
//! that the noise fit ([`crate::noise`]) and the bias path ([`crate::bias_path`]) share.

/// Where a golden-section search ended: the bracket and its two interior points with what
/// `f` gave there.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bracket<T> {
    /// The bracket's ends.
    pub lo: f64,
    pub hi: f64,
    /// The two interior points, (x, f(x)), left first.
    pub inner: [(f64, T); 2],
}

impl<T> Bracket<T> {
    /// The bracket's middle.
    pub fn middle(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }
}

/// `iterations` steps of golden-section search for the minimum of `cost(f(x))` on
/// `[lo, hi]`: each step keeps the left part when the left interior point costs less than
/// the right one, else the right part.
pub(crate) fn minimize<T: Copy>(
    f: impl Fn(f64) -> T,
    cost: impl Fn(&T) -> f64,
    mut lo: f64,
    mut hi: f64,
    iterations: usize,
) -> Bracket<T> {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if cost(&fc) < cost(&fd) {
            hi = d;
            d = c;
            fd = fc;
            c = hi - r * (hi - lo);
            fc = f(c);
        } else {
            lo = c;
            c = d;
            fc = fd;
            d = lo + r * (hi - lo);
            fd = f(d);
        }
    }
    Bracket {
        lo,
        hi,
        inner: [(c, fc), (d, fd)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parabola's minimum, found to the bracket's width after 40 steps.
    #[test]
    fn the_minimum_of_a_parabola_is_found() {
        let end = minimize(|x| (x - 0.3) * (x - 0.3), |y| *y, -2.0, 5.0, 40);
        assert!((end.middle() - 0.3).abs() < 1e-7, "{}", end.middle());
        assert!(end.hi - end.lo < 1e-7);
    }
}
