//! True motion for the simulator: bench-like hand rotations, or a recorded trajectory.
//!
//! Both give the angle and the rate at any instant, which the latency and clock-error
//! effects need (they sample the motion off the nominal grid).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One rotation with a minimum-jerk profile (smooth start and stop, as a hand turns).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Rotation {
    /// Start (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Angle turned (deg), signed.
    pub angle_deg: f64,
}

impl Rotation {
    fn fraction(&self, time_s: f64) -> f64 {
        ((time_s - self.start_s) / self.duration_s).clamp(0.0, 1.0)
    }
    fn angle_at(&self, time_s: f64) -> f64 {
        let s = self.fraction(time_s);
        self.angle_deg * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
    }
    fn rate_at(&self, time_s: f64) -> f64 {
        if time_s <= self.start_s || time_s >= self.start_s + self.duration_s {
            return 0.0;
        }
        let s = self.fraction(time_s);
        self.angle_deg / self.duration_s * 30.0 * s * s * (1.0 - s) * (1.0 - s)
    }
}

/// Settings of the bench-like profile generator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchProfile {
    /// Total duration (s); the run starts and ends at rest.
    pub duration_s: f64,
    /// Rotation angle magnitude (deg).
    pub angle_deg: f64,
    /// Shortest and longest rotation (s).
    pub rotation_s: (f64, f64),
    /// Shortest and longest rest between rotations (s).
    pub rest_s: (f64, f64),
}

impl Default for BenchProfile {
    /// 90 s of 90° rotations lasting 0.8–4 s separated by rests of 3–15 s.
    fn default() -> Self {
        Self {
            duration_s: 90.0,
            angle_deg: 90.0,
            rotation_s: (0.8, 4.0),
            rest_s: (3.0, 15.0),
        }
    }
}

/// The true motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Rotations (sorted, non-overlapping), at rest in between; angle 0 at the start.
    Rotations {
        /// The rotations.
        rotations: Vec<Rotation>,
        /// Angle before each rotation (deg).
        before_deg: Vec<f64>,
        /// Duration of the motion (s).
        duration_s: f64,
    },
    /// A sampled trajectory (e.g. a log's reference), uniformly spaced, starting at 0.
    Trajectory {
        /// Time of the first sample (s).
        start_s: f64,
        /// Sample period (s).
        period_s: f64,
        /// Angle (deg), relative to the first sample.
        angle_deg: Vec<f64>,
    },
}

impl Motion {
    /// Motion made of `rotations` over `duration_s`.
    pub fn from_rotations(mut rotations: Vec<Rotation>, duration_s: f64) -> Self {
        rotations.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        let mut before_deg = Vec::with_capacity(rotations.len());
        let mut total = 0.0;
        for r in &rotations {
            before_deg.push(total);
            total += r.angle_deg;
        }
        Motion::Rotations {
            rotations,
            before_deg,
            duration_s,
        }
    }

    /// A bench-like run: rest, rotations of random duration and direction, rests.
    pub fn bench(profile: &BenchProfile, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut rotations = Vec::new();
        let mut time_s = rng.random_range(3.0..6.0);
        loop {
            let duration_s = rng.random_range(profile.rotation_s.0..=profile.rotation_s.1);
            if time_s + duration_s + profile.rest_s.0.min(3.0) > profile.duration_s {
                break;
            }
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            rotations.push(Rotation {
                start_s: time_s,
                duration_s,
                angle_deg: sign * profile.angle_deg,
            });
            time_s += duration_s + rng.random_range(profile.rest_s.0..=profile.rest_s.1);
        }
        Self::from_rotations(rotations, profile.duration_s)
    }

    /// A trajectory from uniformly sampled reference angles (deg). The angle is smoothed
    /// with a centred moving average of `smooth_samples` (encoders are quantised; their
    /// raw differences would be spikes), which keeps the total angle.
    pub fn from_reference(
        start_s: f64,
        period_s: f64,
        reference_deg: &[f64],
        smooth_samples: usize,
    ) -> Self {
        let origin = reference_deg.first().copied().unwrap_or(0.0);
        let half = smooth_samples / 2;
        let n = reference_deg.len();
        let mut prefix = Vec::with_capacity(n + 1);
        prefix.push(0.0);
        for r in reference_deg {
            prefix.push(prefix.last().copied().unwrap_or(0.0) + (r - origin));
        }
        let smoothed: Vec<f64> = (0..n)
            .map(|i| {
                let lo = i.saturating_sub(half);
                let hi = (i + half + 1).min(n);
                (prefix[hi] - prefix[lo]) / (hi - lo) as f64
            })
            .collect();
        let start = smoothed.first().copied().unwrap_or(0.0);
        let angle_deg = smoothed.iter().map(|a| a - start).collect();
        Motion::Trajectory {
            start_s,
            period_s,
            angle_deg,
        }
    }

    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        match self {
            Motion::Rotations { duration_s, .. } => *duration_s,
            Motion::Trajectory {
                period_s,
                angle_deg,
                ..
            } => period_s * angle_deg.len().saturating_sub(1) as f64,
        }
    }

    /// The rotations, if this is a rotation profile.
    pub fn rotations(&self) -> &[Rotation] {
        match self {
            Motion::Rotations { rotations, .. } => rotations,
            Motion::Trajectory { .. } => &[],
        }
    }

    /// Angle (deg) at `time_s` (s from the start of the motion).
    pub fn angle_deg(&self, time_s: f64) -> f64 {
        match self {
            Motion::Rotations {
                rotations,
                before_deg,
                ..
            } => {
                let i = rotations.partition_point(|r| r.start_s <= time_s);
                if i == 0 {
                    0.0
                } else {
                    before_deg[i - 1] + rotations[i - 1].angle_at(time_s)
                }
            }
            Motion::Trajectory {
                start_s,
                period_s,
                angle_deg,
            } => {
                let (i, w) = locate(time_s - start_s, *period_s, angle_deg.len());
                let a = angle_deg.get(i).copied().unwrap_or(0.0);
                let b = angle_deg.get(i + 1).copied().unwrap_or(a);
                a + w * (b - a)
            }
        }
    }

    /// Rate (deg/s) at `time_s`.
    pub fn rate_dps(&self, time_s: f64) -> f64 {
        match self {
            Motion::Rotations { rotations, .. } => {
                let i = rotations.partition_point(|r| r.start_s <= time_s);
                if i == 0 {
                    0.0
                } else {
                    rotations[i - 1].rate_at(time_s)
                }
            }
            Motion::Trajectory {
                start_s,
                period_s,
                angle_deg,
            } => {
                // Centred five-point derivatives at the samples, linearly interpolated:
                // the rate at a sample is centred on it (the slope of the segment after
                // it would lead the angle by half a sample), its sum over the samples
                // telescopes to the angle change (up to the ends), and its truncation
                // error is O(h⁴). The simulated gyro measures the motion's rate, not the
                // ±1-sample difference that `diagnose` takes of the reference: with the
                // same difference in both, a re-simulation would lack the difference's
                // own error (−h²·ω‴/6), which a real gyro against a 100 Hz reference
                // shows where turns start and end. Three points at the ends.
                let (i, w) = locate(time_s - start_s, *period_s, angle_deg.len());
                let slope_at = |k: usize| -> f64 {
                    let n = angle_deg.len();
                    if n < 2 {
                        return 0.0;
                    }
                    if k >= 2 && k + 2 < n {
                        let near = angle_deg[k + 1] - angle_deg[k - 1];
                        let far = angle_deg[k + 2] - angle_deg[k - 2];
                        return (8.0 * near - far) / (12.0 * period_s);
                    }
                    let (lo, hi) = (k.saturating_sub(1), (k + 1).min(n - 1));
                    (angle_deg[hi] - angle_deg[lo]) / (period_s * (hi - lo) as f64)
                };
                if i + 1 >= angle_deg.len() {
                    return slope_at(angle_deg.len().saturating_sub(1));
                }
                slope_at(i) + w * (slope_at(i + 1) - slope_at(i))
            }
        }
    }
}

/// Segment index and weight of `offset_s` in a uniform series of `n` samples.
fn locate(offset_s: f64, period_s: f64, n: usize) -> (usize, f64) {
    if n < 2 || offset_s <= 0.0 {
        return (0, 0.0);
    }
    let x = offset_s / period_s;
    let i = (x.floor() as usize).min(n - 2);
    (i, (x - i as f64).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_jerk_rotation_integrates_to_its_angle() {
        let m = Motion::from_rotations(
            vec![Rotation {
                start_s: 1.0,
                duration_s: 0.8,
                angle_deg: 90.0,
            }],
            3.0,
        );
        let dt = 1e-4;
        let integral: f64 = (0..30_000).map(|k| m.rate_dps(k as f64 * dt) * dt).sum();
        assert!((integral - 90.0).abs() < 1e-3, "{integral}");
        assert_eq!(m.angle_deg(0.5), 0.0);
        assert!((m.angle_deg(1.4) - 45.0).abs() < 1e-9);
        assert_eq!(m.angle_deg(2.5), 90.0);
    }

    #[test]
    fn bench_profile_is_seeded_and_bench_like() {
        let p = BenchProfile::default();
        let a = Motion::bench(&p, 3);
        assert_eq!(a, Motion::bench(&p, 3));
        assert_ne!(a, Motion::bench(&p, 4));
        let r = a.rotations();
        assert!(r.len() >= 4, "{}", r.len());
        for w in r.windows(2) {
            let rest = w[1].start_s - (w[0].start_s + w[0].duration_s);
            assert!((3.0..=15.0).contains(&rest), "{rest}");
        }
        for x in r {
            assert!((0.8..=4.0).contains(&x.duration_s));
            assert_eq!(x.angle_deg.abs(), 90.0);
            assert!(x.start_s + x.duration_s <= p.duration_s);
        }
    }

    #[test]
    fn trajectory_rate_integrates_to_the_smoothed_angle() {
        let reference: Vec<f64> = (0..1000)
            .map(|k| (k as f64 * 0.01).sin() * 50.0 + 10.0)
            .collect();
        let m = Motion::from_reference(0.0, 0.01, &reference, 5);
        let integral: f64 = (0..999)
            .map(|k| m.rate_dps(k as f64 * 0.01 + 0.005) * 0.01)
            .sum();
        // Telescoping up to the ends, where the stencil changes.
        assert!(
            (integral - m.angle_deg(9.99)).abs() < 1e-2,
            "{integral} {}",
            m.angle_deg(9.99)
        );
        assert!((m.angle_deg(9.99) - (reference[999] - reference[0])).abs() < 0.2);
    }

    #[test]
    fn trajectory_rate_is_the_motions_rate_not_a_centred_difference() {
        // A 2 Hz swing sampled at 100 Hz: a ±1-sample difference is 2.6% short of the
        // peak rate (sin(x)/x at x = 2π·2/100); the five-point one is within 0.02%.
        let (f_hz, period_s) = (2.0, 0.01);
        let reference: Vec<f64> = (0..500)
            .map(|k| (std::f64::consts::TAU * f_hz * k as f64 * period_s).sin() * 30.0)
            .collect();
        let m = Motion::from_reference(0.0, period_s, &reference, 1);
        let worst = (5..495)
            .map(|k| {
                let t = k as f64 * period_s;
                let truth =
                    30.0 * std::f64::consts::TAU * f_hz * (std::f64::consts::TAU * f_hz * t).cos();
                (m.rate_dps(t) - truth).abs()
            })
            .fold(0.0, f64::max);
        let peak = 30.0 * std::f64::consts::TAU * f_hz;
        assert!(worst < 2e-4 * peak, "{worst} of {peak}");
    }
}
