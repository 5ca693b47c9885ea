//! The sensor's own low-pass (`bandwidth`): a continuous critically damped second order
//! (two equal first-order stages), −3 dB at the cutoff overall, on the rate and on the
//! white noise.

/// The continuous two-pole low-pass `p² / (s + p)²`, its pole at `cutoff_hz ·`
/// [`crate::LOW_PASS_POLE_RATIO`] (−3 dB at `cutoff_hz` overall), applied to the input
/// taken as a straight line from one sample to the next (a first-order hold) and read at
/// each sample: exact for that input, so slow motion is delayed by the continuous
/// filter's `2 / p` at any sample rate. (Stepping each stage as `y += α (x − y)` takes
/// about half a sample per stage off that delay: at 100 Hz, 7 ms of an 18 Hz cutoff's
/// 11 ms.) `fixtures/filters/two_pole_low_pass.py` checks it against scipy's
/// `cont2discrete(method='foh')`.
///
/// ```
/// use gyro_sim::TwoPoleLowPass;
/// let mut filter = TwoPoleLowPass::new(15.0, 1000.0, 0.0);
/// // A step settles to its level.
/// let last = (0..1000).map(|_| filter.step(1.0)).last().unwrap();
/// assert!((last - 1.0).abs() < 1e-9);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoPoleLowPass {
    /// `e^{−pT}`: each stage's decay over one sample.
    decay: f64,
    /// `pT·e^{−pT}`: the first stage's state carried into the second over one sample.
    carry: f64,
    /// Each stage's response at the sample to a unit input held since the last one.
    held: [f64; 2],
    /// Each stage's response at the sample to the input's rise by one since the last one.
    ramp: [f64; 2],
    /// The stages' outputs.
    stages: [f64; 2],
    /// The last input.
    previous: f64,
}

impl TwoPoleLowPass {
    /// The filter at `sample_rate_hz`, its stages and input at rest at `initial`.
    pub fn new(cutoff_hz: f64, sample_rate_hz: f64, initial: f64) -> Self {
        let pole_hz = cutoff_hz * crate::LOW_PASS_POLE_RATIO;
        let u = 2.0 * std::f64::consts::PI * pole_hz / sample_rate_hz;
        let a = (-u).exp();
        let one_less_a = -(-u).exp_m1();
        // `1 − (1 − a)/u` and `1 − 2/u + a(2 + u)/u` lose every digit to cancellation
        // when u is small; their series serve there.
        let (ramp_first, ramp_second) = if u < 1e-3 {
            (u / 2.0 - u * u / 6.0, u * u / 6.0 - u * u * u / 12.0)
        } else {
            (1.0 - one_less_a / u, 1.0 - (2.0 - a * (2.0 + u)) / u)
        };
        Self {
            decay: a,
            carry: u * a,
            held: [one_less_a, one_less_a - u * a],
            ramp: [ramp_first, ramp_second],
            stages: [initial; 2],
            previous: initial,
        }
    }

    /// Filter one sample.
    pub fn step(&mut self, x: f64) -> f64 {
        let (x0, rise) = (self.previous, x - self.previous);
        let [s1, s2] = self.stages;
        self.stages = [
            self.decay * s1 + self.held[0] * x0 + self.ramp[0] * rise,
            self.decay * s2 + self.carry * s1 + self.held[1] * x0 + self.ramp[1] * rise,
        ];
        self.previous = x;
        self.stages[1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// scipy's first-order-hold discretisation of the same continuous filter
    /// (`fixtures/filters/two_pole_low_pass.py`), filtering from rest.
    #[test]
    fn matches_scipy_first_order_hold() {
        let text = include_str!("../../../fixtures/filters/two_pole_low_pass.csv");
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(header[0], "x");
        assert!(rows.len() >= 400);
        for (column, name) in header.iter().enumerate().skip(1) {
            let (cutoff, rate) = name
                .strip_prefix("fc")
                .and_then(|s| s.split_once("_fs"))
                .unwrap();
            let mut filter =
                TwoPoleLowPass::new(cutoff.parse().unwrap(), rate.parse().unwrap(), 0.0);
            for (k, row) in rows.iter().enumerate() {
                let y = filter.step(row[0]);
                assert!(
                    (y - row[column]).abs() < 1e-12,
                    "{name} sample {k}: {y} against scipy's {}",
                    row[column]
                );
            }
        }
    }

    /// Slow motion is delayed by the continuous filter's 2/p, at 100 Hz as at 1 kHz.
    #[test]
    fn a_ramp_lags_by_the_continuous_delay() {
        for (cutoff_hz, rate_hz) in [(18.0, 100.0), (15.0, 1000.0), (40.0, 100.0)] {
            let mut filter = TwoPoleLowPass::new(cutoff_hz, rate_hz, 0.0);
            let slope = 1.0;
            let n = (rate_hz * 2.0) as usize;
            let mut last = 0.0;
            for k in 0..n {
                last = filter.step(slope * k as f64 / rate_hz);
            }
            let lag_s = (n - 1) as f64 / rate_hz - last / slope;
            let expected_s =
                2.0 / (2.0 * std::f64::consts::PI * cutoff_hz * crate::LOW_PASS_POLE_RATIO);
            assert!(
                (lag_s - expected_s).abs() < 1e-6 * expected_s + 1e-9,
                "{cutoff_hz} Hz at {rate_hz} Hz: lag {lag_s} s, continuous {expected_s} s"
            );
        }
    }

    /// A pole far below the sample rate (the series branch) still settles and lags right.
    #[test]
    fn a_slow_pole_keeps_its_precision() {
        let mut filter = TwoPoleLowPass::new(0.01, 1000.0, 2.0);
        assert!((filter.step(2.0) - 2.0).abs() < 1e-12);
        let mut coarse = TwoPoleLowPass::new(0.2, 1000.0, 0.0);
        let last = (0..100_000).map(|_| coarse.step(1.0)).last().unwrap();
        assert!((last - 1.0).abs() < 1e-9, "{last}");
    }
}
