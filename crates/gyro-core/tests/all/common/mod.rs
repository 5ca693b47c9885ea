//! Shared helpers of the pipeline-level tests: a tiny deterministic PRNG, bench-like
//! synthetic rate profiles (rests and smooth swings), and a pipeline runner.
//!
//! Every test binary uses a different subset of these helpers.
#![allow(dead_code)]

use gyro_core::{Config, Event, Movement, Output, Pipeline};

/// SplitMix64: small, fast, and good enough for test signals.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// +1 or -1.
    pub fn sign(&mut self) -> f64 {
        if self.next_u64() & 1 == 0 {
            1.0
        } else {
            -1.0
        }
    }
}

/// Rate profile of one swing over its normalised time `s ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// `r = (θ/T)(1 − cos 2πs)`.
    RaisedCosine,
    /// Minimum jerk: `r = (θ/T) 30 s² (1 − s)²`.
    MinimumJerk,
}

impl Shape {
    /// Rate (deg/s) at normalised time `s` of a swing of `angle_deg` in `duration_s`.
    pub fn rate_dps(self, s: f64, angle_deg: f64, duration_s: f64) -> f64 {
        if !(0.0..=1.0).contains(&s) {
            return 0.0;
        }
        let scale = angle_deg / duration_s;
        match self {
            Shape::RaisedCosine => scale * (1.0 - (2.0 * std::f64::consts::PI * s).cos()),
            Shape::MinimumJerk => scale * 30.0 * s * s * (1.0 - s) * (1.0 - s),
        }
    }
}

/// One smooth rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swing {
    pub start_s: f64,
    pub duration_s: f64,
    pub angle_deg: f64,
    pub shape: Shape,
}

impl Swing {
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

/// Rests and swings over `[0, total_s)`; the swings are sorted and do not overlap.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    pub swings: Vec<Swing>,
    pub total_s: f64,
}

/// Settings of a bench-like profile.
#[derive(Clone, Copy, Debug)]
pub struct BenchSpec {
    pub total_s: f64,
    /// Rest before the first swing (s).
    pub first_rest_s: (f64, f64),
    /// Rests between swings (s).
    pub rest_s: (f64, f64),
    /// Swing durations (s).
    pub swing_s: (f64, f64),
    /// Swing magnitudes (deg); the sign is random.
    pub angle_deg: (f64, f64),
}

impl Default for BenchSpec {
    fn default() -> Self {
        Self {
            total_s: 90.0,
            first_rest_s: (2.0, 5.0),
            rest_s: (3.0, 15.0),
            swing_s: (0.8, 4.0),
            angle_deg: (90.0, 90.0),
        }
    }
}

impl Profile {
    /// A bench-like run: a first rest, then swings separated by rests, ending at rest
    /// (the last swing ends at least `rest_s.0` before `total_s`).
    pub fn bench(rng: &mut Rng, spec: &BenchSpec) -> Self {
        let mut swings = Vec::new();
        let mut t = rng.range(spec.first_rest_s.0, spec.first_rest_s.1);
        loop {
            let duration_s = rng.range(spec.swing_s.0, spec.swing_s.1);
            if t + duration_s + spec.rest_s.0 > spec.total_s {
                break;
            }
            let shape = if rng.next_u64() & 1 == 0 {
                Shape::RaisedCosine
            } else {
                Shape::MinimumJerk
            };
            swings.push(Swing {
                start_s: t,
                duration_s,
                angle_deg: rng.sign() * rng.range(spec.angle_deg.0, spec.angle_deg.1),
                shape,
            });
            t += duration_s + rng.range(spec.rest_s.0, spec.rest_s.1);
        }
        Self {
            swings,
            total_s: spec.total_s,
        }
    }

    /// True rate (deg/s) at `t_s`.
    pub fn rate_dps(&self, t_s: f64) -> f64 {
        self.swings
            .iter()
            .find(|s| t_s >= s.start_s && t_s <= s.end_s())
            .map_or(0.0, |s| {
                s.shape
                    .rate_dps((t_s - s.start_s) / s.duration_s, s.angle_deg, s.duration_s)
            })
    }

    /// Sampled at `sample_rate_hz` with a constant `bias_dps` and white noise of
    /// `noise_dps` rms per sample, rounded to f32.
    pub fn samples(
        &self,
        sample_rate_hz: f64,
        bias_dps: f64,
        noise_dps: f64,
        rng: &mut Rng,
    ) -> Vec<f32> {
        let n = (self.total_s * sample_rate_hz).round() as usize;
        let mut out = Vec::with_capacity(n);
        let mut next = 0;
        for i in 0..n {
            let t = i as f64 / sample_rate_hz;
            while next < self.swings.len() && self.swings[next].end_s() < t {
                next += 1;
            }
            let rate = match self.swings.get(next) {
                Some(s) if t >= s.start_s => {
                    s.shape
                        .rate_dps((t - s.start_s) / s.duration_s, s.angle_deg, s.duration_s)
                }
                _ => 0.0,
            };
            out.push((rate + bias_dps + noise_dps * rng.normal()) as f32);
        }
        out
    }
}

/// What a pipeline produced over a whole input.
pub struct Run {
    pub outputs: Vec<Output>,
    /// `(output index, start time)` of every `MovementStarted`.
    pub starts: Vec<(usize, f64)>,
    /// `(output index, movement)` of every `MovementEnded`.
    pub movements: Vec<(usize, Movement)>,
    pub pipeline: Pipeline,
}

/// Push `samples` taken at `sample_rate_hz` (time `i / rate`) through a new pipeline.
pub fn run(config: &Config, samples: &[f32], sample_rate_hz: f64) -> Run {
    let mut pipeline = Pipeline::try_new(config).expect("valid config");
    let mut outputs = Vec::with_capacity(samples.len() / 10 + 1);
    let mut starts = Vec::new();
    let mut movements = Vec::new();
    for (i, &rate) in samples.iter().enumerate() {
        if let Some(out) = pipeline.push(i as f64 / sample_rate_hz, rate) {
            match out.event {
                Some(Event::MovementStarted { start_time_s, .. }) => {
                    starts.push((outputs.len(), start_time_s))
                }
                Some(Event::MovementEnded(m)) => movements.push((outputs.len(), m)),
                None => {}
            }
            outputs.push(out);
        }
    }
    Run {
        outputs,
        starts,
        movements,
        pipeline,
    }
}
