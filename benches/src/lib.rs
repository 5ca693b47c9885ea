//! Benchmarks live in `benches/benches/`; this library holds shared input generators.

/// A bench-like 1 kHz gyro signal in deg/s: 90° raised-cosine rotations of 1 s every 6 s,
/// a constant bias and a small deterministic ripple standing in for noise.
pub fn bench_signal_dps(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            let time_s = i as f32 * 1.0e-3;
            let phase_s = time_s % 6.0;
            let swing_dps = if phase_s < 1.0 {
                90.0 * (1.0 - (2.0 * core::f32::consts::PI * phase_s).cos())
            } else {
                0.0
            };
            swing_dps + 0.3 + 0.05 * (i as f32 * 12.9898).sin()
        })
        .collect()
}
