//! Benchmarks live in `benches/benches/`; this library holds shared input generators and
//! the pipeline's plain-loop floor.

use gyro_core::{Config, Error};

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

/// The pipeline's floor: the same math as the plainest loop (average-decimate, one
/// biquad section in direct form, a threshold detector, trapezoid integration while
/// moving), with the settings of a pipeline configuration.
#[derive(Clone, Copy)]
pub struct Plain {
    factor: usize,
    /// `[b0, b1, b2, a1, a2]` of the single section (`a0` = 1).
    biquad: [f32; 5],
    enter_dps: f32,
    half_dt_s: f32,
}

impl Plain {
    /// The floor of `config`'s pipeline, or the error that makes `config` invalid.
    pub fn try_new(config: &Config) -> Result<Self, Error> {
        let factor = usize::from(config.decimation_factor()?);
        let output_rate_hz = config.effective_output_rate_hz()?;
        let design = config.filter.design(output_rate_hz.into())?;
        let [b0, b1, b2, a0, a1, a2] = design.sections()[0];
        Ok(Self {
            factor,
            biquad: [b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0].map(|c| c as f32),
            enter_dps: config.motion.enter_dps,
            half_dt_s: 0.5 / output_rate_hz,
        })
    }

    /// Decimate, filter, detect, integrate: the angle turned while moving (deg).
    pub fn run(&self, signal: &[f32]) -> f32 {
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
