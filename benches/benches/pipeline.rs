//! Real-time budget of the full pipeline: cost per 1 kHz input sample, beside its floor.
//!
//! Target: under 50 ns per input sample on the development machine (a 1 kHz sensor leaves
//! 1 ms per sample on the MCU; the host replays hours of logs).
//!
//! The floor is the same math as the plainest loop (`gyro_benches::Plain`), in the same
//! criterion group and over the same input, so that the ratio of the two is measured in
//! one run:
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
//! On a machine whose speed changes while the group runs, `--example ratio` times the
//! floor and each run back to back instead.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gyro_benches::{bench_signal_dps, Plain};
use gyro_core::{Compensation, Config, Pipeline};
use std::hint::black_box;

fn pipeline_per_sample(c: &mut Criterion) {
    const N: usize = 90_000; // 90 s at 1 kHz
    let signal = bench_signal_dps(N);
    let times_s: Vec<f64> = (0..N).map(|i| i as f64 * 1e-3).collect();
    let mut group = c.benchmark_group("pipeline_90s_1khz");
    group.throughput(Throughput::Elements(N as u64));
    let plain = Plain::try_new(&Config::default()).expect("default config is valid");
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
