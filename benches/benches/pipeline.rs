//! Real-time budget of the full pipeline: cost per 1 kHz input sample.
//!
//! Target: under 50 ns per input sample on the development machine (a 1 kHz sensor leaves
//! 1 ms per sample on the MCU; the host replays hours of logs).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gyro_benches::bench_signal_dps;
use gyro_core::{Compensation, Config, Pipeline};
use std::hint::black_box;

fn pipeline_per_sample(c: &mut Criterion) {
    const N: usize = 90_000; // 90 s at 1 kHz
    let signal = bench_signal_dps(N);
    let mut group = c.benchmark_group("pipeline_90s_1khz");
    group.throughput(Throughput::Elements(N as u64));
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
    }
    group.finish();
}

criterion_group!(benches, pipeline_per_sample);
criterion_main!(benches);
