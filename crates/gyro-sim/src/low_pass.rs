//! The sensor's own low-pass (`bandwidth`): two equal first-order stages, −3 dB at the
//! cutoff overall, on the rate and on the white noise.

/// Two equal first-order stages (a critically damped second order), each with its pole at
/// `cutoff_hz ·` [`crate::LOW_PASS_POLE_RATIO`] (−3 dB at `cutoff_hz` overall), sampled at
/// a fixed rate.
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
    alpha: f64,
    stages: [f64; 2],
}

impl TwoPoleLowPass {
    /// The filter at `sample_rate_hz`, its stages at rest at `initial`.
    pub fn new(cutoff_hz: f64, sample_rate_hz: f64, initial: f64) -> Self {
        let pole_hz = cutoff_hz * crate::LOW_PASS_POLE_RATIO;
        Self {
            alpha: 1.0 - (-2.0 * std::f64::consts::PI * pole_hz / sample_rate_hz).exp(),
            stages: [initial; 2],
        }
    }

    /// Filter one sample.
    pub fn step(&mut self, x: f64) -> f64 {
        self.stages[0] += self.alpha * (x - self.stages[0]);
        self.stages[1] += self.alpha * (self.stages[0] - self.stages[1]);
        self.stages[1]
    }
}
