//! Host bridge reader throughput: bridge frames decoded from a byte buffer through
//! `BridgeReader` (read buffer, resynchronising decoder, sequence tracking, events).
//!
//! Target: at least 100 000 frames/s, 100 × the bridge's 1 kHz real time, so `record`
//! keeps up with a backlog and replays raw captures quickly. Criterion prints the
//! throughput in elements (frames) per second. Measured on the 2-core development machine:
//! about 2.5 million frames/s clean, 2.9 million with noise (2 500 × real time).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use crm100_driver::{BridgeReader, ReadEvent};
use gyro_benches::bridge_bytes;
use std::hint::black_box;

fn reader_frames_per_second(c: &mut Criterion) {
    const N: usize = 60_000; // 60 s at 1 kHz
    let mut group = c.benchmark_group("bridge_reader_60s_1khz");
    group.throughput(Throughput::Elements(N as u64));
    for (name, noise) in [("clean", None), ("noise_every_100", Some(100))] {
        let bytes = bridge_bytes(N, noise);
        group.bench_with_input(BenchmarkId::from_parameter(name), &bytes, |b, bytes| {
            b.iter(|| {
                let mut reader = BridgeReader::new(black_box(bytes.as_slice()));
                let mut frames = 0_u64;
                let mut sum = 0_u64;
                while let Ok(Some(event)) = reader.next_event() {
                    if let ReadEvent::Frame(received) = event {
                        frames += 1;
                        sum = sum.wrapping_add(received.frame.timestamp_us);
                    }
                }
                assert_eq!(frames, N as u64);
                black_box(sum)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, reader_frames_per_second);
criterion_main!(benches);
