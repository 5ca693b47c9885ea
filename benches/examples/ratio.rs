//! The pipeline's cost per input sample as a ratio to its plain-loop floor, each
//! repetition timing the floor and every bench one after the other.
//!
//! The criterion bench (`benches/pipeline.rs`, read by `scripts/bench_ratio.py`) measures
//! each function for seconds before the next; on a shared machine whose speed changes
//! by a fifth from one minute to the next, the floor and the pipeline are then measured
//! at different speeds. Here every repetition runs the floor and the criterion bench's
//! pipeline runs (`block_*`, `block100_*`, `push` per sample) back to back over the same
//! 90 s at 1 kHz, so a ratio is taken within one repetition. It prints each bench's fastest time, its
//! ratio to the floor's fastest (the machine at its quickest), and the median over
//! repetitions of the ratio within a repetition (the machine as it is).
//!
//! `cargo run --release -p gyro-benches --example ratio [REPETITIONS]` (default 200).

use gyro_benches::{bench_signal_dps, Plain};
use gyro_core::{Compensation, Config, Error, Pipeline};
use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

const MODES: [(&str, Compensation); 3] = [
    ("none", Compensation::None),
    ("paper", Compensation::Paper),
    ("kalman", Compensation::Kalman),
];

/// Seconds taken by `work`.
fn timed(work: impl FnOnce()) -> f64 {
    let start = Instant::now();
    work();
    start.elapsed().as_secs_f64()
}

/// The last output angle of a pipeline fed `signal` by `push_block` in calls of `chunk`
/// samples, or by `push` one sample at a time.
fn angle_deg(
    config: &Config,
    chunk: Option<usize>,
    times_s: &[f64],
    signal: &[f32],
) -> Result<f32, Error> {
    let mut pipeline = Pipeline::try_new(config)?;
    let mut last = 0.0_f32;
    match chunk {
        Some(chunk) => {
            for (times_s, rates_dps) in times_s.chunks(chunk).zip(signal.chunks(chunk)) {
                pipeline.push_block(times_s, black_box(rates_dps), |out| last = out.angle_deg)?;
            }
        }
        None => {
            // The time as the criterion bench makes it.
            for (i, &rate_dps) in signal.iter().enumerate() {
                if let Some(out) = pipeline.push(i as f64 * 1e-3, black_box(rate_dps)) {
                    last = out.angle_deg;
                }
            }
        }
    }
    Ok(last)
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn main() -> ExitCode {
    let repetitions = match std::env::args().nth(1).map(|arg| arg.parse::<usize>()) {
        None => 200,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("ratio: REPETITIONS must be a positive whole number");
            return ExitCode::FAILURE;
        }
    };
    match run(repetitions) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("ratio: the configuration is refused: {error}");
            ExitCode::FAILURE
        }
    }
}

/// Time every bench `repetitions` times and print the table.
fn run(repetitions: usize) -> Result<(), Error> {
    const N: usize = 90_000; // 90 s at 1 kHz, as the criterion bench
    let signal = bench_signal_dps(N);
    let times_s: Vec<f64> = (0..N).map(|i| i as f64 * 1e-3).collect();
    let plain = Plain::try_new(&Config::default())?;
    let configs = MODES.map(|(_, compensation)| Config {
        compensation,
        ..Config::default()
    });
    // Per mode: the whole input in one `push_block`, in calls of 100 samples (a 0.1 s
    // buffer), and one sample per `push`.
    let benches: Vec<(String, &Config, Option<usize>)> = MODES
        .iter()
        .zip(&configs)
        .flat_map(|((name, _), config)| {
            [
                (format!("block_{name}"), config, Some(N)),
                (format!("block100_{name}"), config, Some(100)),
                (name.to_string(), config, None),
            ]
        })
        .collect();
    let mut floor_s = Vec::with_capacity(repetitions);
    let mut bench_s = vec![Vec::with_capacity(repetitions); benches.len()];
    for _ in 0..repetitions {
        floor_s.push(timed(|| {
            black_box(plain.run(black_box(&signal)));
        }));
        for ((_, config, chunk), times) in benches.iter().zip(&mut bench_s) {
            let mut angle = Ok(0.0);
            times.push(timed(|| {
                angle = black_box(angle_deg(config, *chunk, &times_s, &signal));
            }));
            angle?;
        }
    }
    let ns = |seconds: f64| seconds * 1e9 / N as f64;
    let fastest = |times: &[f64]| times.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "{repetitions} repetitions of 90 s at 1 kHz; plain_loop fastest {:.3} ns/sample",
        ns(fastest(&floor_s))
    );
    println!(
        "{:<16} {:>18} {:>18} {:>20}",
        "bench", "fastest ns/sample", "fastest × plain", "median × plain"
    );
    for ((name, _, _), times) in benches.iter().zip(&bench_s) {
        let mut ratios: Vec<f64> = times.iter().zip(&floor_s).map(|(t, f)| t / f).collect();
        println!(
            "{name:<16} {:>18.3} {:>18.2} {:>20.2}",
            ns(fastest(times)),
            fastest(times) / fastest(&floor_s),
            median(&mut ratios)
        );
    }
    Ok(())
}
