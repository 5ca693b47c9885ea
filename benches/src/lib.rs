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

/// `n` consecutive CRM100 bridge frames (1 kHz timestamps, a sweeping rate word) as the
/// bytes a bridge sends, optionally with a run of line noise every `noise_every` frames.
pub fn bridge_bytes(n: usize, noise_every: Option<usize>) -> Vec<u8> {
    use crm100_driver::{encode_to_array, BridgeFrame, Response, Status};
    let mut bytes = Vec::with_capacity(n * crm100_driver::BRIDGE_FRAME_LEN);
    for i in 0..n {
        let response = Response {
            status: Status(0),
            rate_counts: ((i % 14_401) as i32 - 7_200) as i16,
            temperature_word: 600,
        };
        let frame = BridgeFrame {
            sequence: i as u32,
            timestamp_us: 1_000 * i as u64,
            command: 0x28,
            response: response.to_bytes(),
        };
        bytes.extend_from_slice(&encode_to_array(&frame));
        if noise_every.is_some_and(|k| k > 0 && i % k == k - 1) {
            bytes.extend_from_slice(&[0xA5, 0x00, 0x5A, 0x13]);
        }
    }
    bytes
}
