//! Real-time budget of the full pipeline: cost per 1 kHz input sample, beside its floor.
//!
//! Target: under 50 ns per input sample on the development machine (a 1 kHz sensor leaves
//! 1 ms per sample on the MCU; the host replays hours of logs).
//!
//! The floor is the same math as the plainest loop, in the same criterion group and over
//! the same input, so that the ratio of the two is measured in one run:
//! - `plain_loop`: average-decimate 20:1 (a plain f32 sum), one biquad section in direct
//!   form (the pipeline's Butterworth design, rounded to f32), a threshold detector
//!   (|rate| above `enter_dps`), trapezoid integration while moving.
//!
//! The pipeline runs each compensation mode sample by sample (`Pipeline::push`: `none`,
//! `paper`, `kalman`) and through `Pipeline::push_block`, the whole input in one call
//! (`block_*`) and in calls of 100 samples (`block100_*`).
//!
//! `scripts/bench_ratio.py` prints each bench's ns per input sample and its ratio to
//! `plain_loop`, from criterion's `target/criterion/pipeline_90s_1khz/*/new/estimates.json`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gyro_benches::bench_signal_dps;
use gyro_core::{Compensation, Config, Pipeline};
use std::hint::black_box;

/// The floor's settings, from the default pipeline configuration.
#[derive(Clone, Copy)]
struct Plain {
    factor: usize,
    /// `[b0, b1, b2, a1, a2]` of the single section (`a0` = 1).
    biquad: [f32; 5],
    enter_dps: f32,
    half_dt_s: f32,
}

impl Plain {
    fn new(config: &Config) -> Self {
        let factor = usize::from(config.decimation_factor().expect("valid config"));
        let output_rate_hz = config.effective_output_rate_hz().expect("valid config");
        let design = config
            .filter
            .design(output_rate_hz.into())
            .expect("valid filter");
        let [b0, b1, b2, a0, a1, a2] = design.sections()[0];
        Self {
            factor,
            biquad: [b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0].map(|c| c as f32),
            enter_dps: config.motion.enter_dps,
            half_dt_s: 0.5 / output_rate_hz,
        }
    }

    /// Decimate, filter, detect, integrate: the angle turned while moving (deg).
    fn run(&self, signal: &[f32]) -> f32 {
        let [b0, b1, b2, a1, a2] = self.biquad;
        let (mut x1, mut x2, mut y1, mut y2) = (0.0_f32, 0.0_f32, 0.0_f32, 0.0_f32);
        let mut angle_deg = 0.0_f32;
        let scale = 1.0 / self.factor as f32;
        for block in signal.chunks_exact(self.factor) {
            let mut sum = 0.0_f32;
            for &x in block {
                sum += x;
            }
            let x = sum * scale;
            let y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
            if y.abs() > self.enter_dps {
                angle_deg += self.half_dt_s * (y1 + y);
            }
            (x2, x1, y2, y1) = (x1, x, y1, y);
        }
        angle_deg
    }
}

fn pipeline_per_sample(c: &mut Criterion) {
    const N: usize = 90_000; // 90 s at 1 kHz
    let signal = bench_signal_dps(N);
    let times_s: Vec<f64> = (0..N).map(|i| i as f64 * 1e-3).collect();
    let mut group = c.benchmark_group("pipeline_90s_1khz");
    group.throughput(Throughput::Elements(N as u64));
    let plain = Plain::new(&Config::default());
    group.bench_with_input("plain_loop", &signal, |b, signal| {
        b.iter(|| plain.run(black_box(signal)))
    });
    for (name, compensation) in [
        ("none", Compensation::None),
        ("paper", Compensation::Paper),
        ("kalman", Compensation::Kalman),
    ] {
        let config = Config {
            compensation,
            ..Config::default()
        };
        group.bench_with_input(BenchmarkId::from_parameter(name), &signal, |b, signal| {
            b.iter(|| {
                let mut pipeline = Pipeline::try_new(&config).expect("default config is valid");
                let mut last = 0.0_f32;
                for (i, &rate_dps) in signal.iter().enumerate() {
                    if let Some(out) = pipeline.push(i as f64 * 1e-3, black_box(rate_dps)) {
                        last = out.angle_deg;
                    }
                }
                black_box(last)
            })
        });
        // The same samples through `push_block`: the whole 90 s in one call, and in calls
        // of 100 samples (a firmware's DMA buffer of 0.1 s).
        for chunk in [N, 100] {
            let id = if chunk == N {
                format!("block_{name}")
            } else {
                format!("block{chunk}_{name}")
            };
            group.bench_with_input(id, &signal, |b, signal| {
                b.iter(|| {
                    let mut pipeline = Pipeline::try_new(&config).expect("default config is valid");
                    let mut last = 0.0_f32;
                    for (times_s, rates_dps) in times_s.chunks(chunk).zip(signal.chunks(chunk)) {
                        pipeline
                            .push_block(times_s, black_box(rates_dps), |out| last = out.angle_deg)
                            .expect("same lengths");
                    }
                    black_box(last)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, pipeline_per_sample);
criterion_main!(benches);
