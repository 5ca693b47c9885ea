//! How far below the per-rest mean an estimate that reads the bias from the rests can go,
//! on the bench kinds of [`gyro_analysis::rest_mean::bench`]: the median over runs of the
//! max |accumulated angle error| at mid-rest, as a ratio to the per-rest mean's, for
//!
//! - "both rests": the bias read over the last `WINDOW_S` of the rest before each movement
//!   and the first `WINDOW_S` of the rest after, linear in time between them (the plain
//!   offline estimate);
//! - "bias path": the bias through the whole run from `BLOCK_S` blocks of every rest
//!   ([`gyro_analysis::bias_path`], what `run --offline` fits), on the raw samples and the
//!   true rests;
//! - "rests exact": the same interpolation from the true bias at the rests' edges (the run
//!   simulated again with the same seed and no white noise gives the bias path), the floor
//!   of any estimate that reads the bias at the rests;
//! - "bias known": the bias known exactly through the movements too
//!   ([`bias_known_max_deg`]).
//!
//! "rests exact" is not given for the output-step kinds, whose rounding is not noise.
//! `cargo run --release -p gyro-analysis --example offline_floor [RUNS [WINDOW_S]]` (default
//! 40 runs from seed 1, a window of 2 s).
use gyro_analysis::bias_path::{BiasPath, Reading};
use gyro_analysis::rest_mean::bench::{bench_kinds, bias_known_max_deg, geometric_mean};
use gyro_analysis::rest_mean::{per_rest_angles, rests_between, simulate_bench_run, Rest};
use gyro_sim::Effect;

type Error = Box<dyn std::error::Error + Send + Sync>;

/// The max |accumulated error| at mid-rest of `angles` (one per rest).
fn max_error(log: &gyro_log::RegularLog, rests: &[Rest], angles: &[f64]) -> f64 {
    let reference = |rest: &Rest| {
        log.slots[(rest.start + rest.end) / 2]
            .reference_deg
            .unwrap_or(f64::NAN)
    };
    let origin = rests.first().map_or(0.0, reference);
    rests
        .iter()
        .zip(angles)
        .map(|(rest, a)| (a - (reference(rest) - origin)).abs())
        .fold(0.0, f64::max)
}

/// The angle at each rest with the bias of each movement linear in time between
/// `bias_at(rest before, rest after)`'s two (time s, bias deg/s) points.
fn interpolated(
    rates: &[f64],
    times: &[f64],
    rests: &[Rest],
    bias_at: impl Fn(Rest, Rest) -> ((f64, f64), (f64, f64)),
) -> Vec<f64> {
    let mut angles = vec![0.0];
    let mut angle = 0.0;
    for pair in rests.windows(2) {
        let ((t0, b0), (t1, b1)) = bias_at(pair[0], pair[1]);
        for j in pair[0].end + 1..=pair[1].start {
            let dt = times[j] - times[j - 1];
            angle += (rates[j] - (b0 + (b1 - b0) * (times[j] - t0) / (t1 - t0))) * dt;
        }
        angles.push(angle);
    }
    angles
}

fn main() -> Result<(), Error> {
    let runs: u64 = std::env::args().nth(1).map_or(Ok(40), |a| a.parse())?;
    let window_s: f64 = std::env::args().nth(2).map_or(Ok(2.0), |a| a.parse())?;
    println!("seeds 1..{runs}, window {window_s} s");
    println!(
        "| kind | both rests / rest mean | bias path / rest mean | rests exact / rest mean | bias known / rest mean | walk fitted, median (deg²/s³) |"
    );
    println!("|---|---|---|---|---|---|");
    let mut both_ratios = vec![];
    let mut smooth_ratios = vec![];
    for kind in bench_kinds() {
        let effects = kind
            .effects
            .iter()
            .map(|s| Effect::parse(s))
            .collect::<Result<Vec<_>, _>>()?;
        let rounded = effects
            .iter()
            .any(|e| matches!(e, Effect::Quantization { .. }));
        let (mut plain, mut both, mut exact, mut known, mut smooth, mut walks) =
            (vec![], vec![], vec![], vec![], vec![], vec![]);
        for seed in 1..=runs {
            let run = simulate_bench_run(&kind.sensor, &effects, seed)?;
            let times: Vec<f64> = run.log.slots.iter().map(|s| s.time_s).collect();
            let rates: Vec<f64> = run.log.slots.iter().map(|s| s.rate_dps).collect();
            let rests = rests_between(&run.rotations, &times);
            let period_s = 1.0 / run.log.sample_rate_hz;
            let w = ((window_s / period_s) as usize).max(1);
            let mean = |from: usize, to: usize| {
                rates[from..=to].iter().sum::<f64>() / (to + 1 - from) as f64
            };
            plain.push(max_error(
                &run.log,
                &rests,
                &per_rest_angles(&rates, period_s, &rests),
            ));
            let read = interpolated(&rates, &times, &rests, |p, q| {
                let lo = p.end + 1 - w.min(p.end + 1 - p.start);
                let hi = (q.start + w - 1).min(q.end);
                (
                    (0.5 * (times[lo] + times[p.end]), mean(lo, p.end)),
                    (0.5 * (times[q.start] + times[hi]), mean(q.start, hi)),
                )
            });
            both.push(max_error(&run.log, &rests, &read));
            let path = smoothed_path(&rates, &times, &rests, period_s)?;
            let read = interpolated_path(&rates, &times, &rests, &path);
            smooth.push(max_error(&run.log, &rests, &read));
            walks.push(path.walk());
            if !rounded {
                let quiet_sensor = gyro_sim::SensorModel {
                    arw_deg_per_rt_h: 0.0,
                    lsb_dps: 0.0,
                    ..kind.sensor
                };
                let quiet = simulate_bench_run(&quiet_sensor, &effects, seed)?;
                let bias: Vec<f64> = quiet
                    .log
                    .slots
                    .iter()
                    .map(|s| s.rate_dps - run.motion.rate_dps(s.time_s))
                    .collect();
                let at_edges = interpolated(&rates, &times, &rests, |p, q| {
                    ((times[p.end], bias[p.end]), (times[q.start], bias[q.start]))
                });
                exact.push(max_error(&run.log, &rests, &at_edges));
            }
            known.push(bias_known_max_deg(&kind, seed)?);
        }
        let median = |v: Vec<f64>| gyro_analysis::median(&v).unwrap_or(f64::NAN);
        let base = median(plain);
        let exact = if rounded {
            "n/a".to_string()
        } else {
            format!("{:.2}", median(exact) / base)
        };
        println!(
            "| {} | {:.2} | {:.2} | {exact} | {:.2} | {:.1e} |",
            kind.name,
            median(both.clone()) / base,
            median(smooth.clone()) / base,
            median(known) / base,
            median(walks)
        );
        smooth_ratios.push(median(smooth) / base);
        both_ratios.push(median(both) / base);
    }
    println!(
        "geometric mean, both rests: {:.2}",
        geometric_mean(both_ratios)
    );
    println!(
        "geometric mean, bias path: {:.2}",
        geometric_mean(smooth_ratios)
    );
    Ok(())
}

/// Rest blocks of this length (s) read the bias for the bias path.
const BLOCK_S: f64 = 0.2;

/// The bias path through `BLOCK_S` blocks of every rest, the white noise from the
/// difference of consecutive blocks within a rest.
fn smoothed_path(
    rates: &[f64],
    times: &[f64],
    rests: &[Rest],
    period_s: f64,
) -> Result<BiasPath, Error> {
    BiasPath::fit(&path_readings(rates, times, rests, period_s))
        .ok_or_else(|| "no rest block".into())
}

/// The `BLOCK_S` readings of every rest.
fn path_readings(rates: &[f64], times: &[f64], rests: &[Rest], period_s: f64) -> Vec<Reading> {
    let n = ((BLOCK_S / period_s) as usize).max(1);
    // (time, mean, samples) of each block: a rest of `len` samples in `len / n` blocks of
    // equal length, so that its first and last samples are read.
    let mut blocks: Vec<(f64, f64, usize)> = vec![];
    let (mut pairs, mut count) = (0.0, 0.0);
    for rest in rests {
        let len = rest.end + 1 - rest.start;
        let m = (len / n).max(1);
        let mut last: Option<(f64, usize)> = None;
        for k in 0..m {
            let (i, j) = (rest.start + k * len / m, rest.start + (k + 1) * len / m);
            let mean = rates[i..j].iter().sum::<f64>() / (j - i) as f64;
            blocks.push((0.5 * (times[i] + times[j - 1]), mean, j - i));
            if let Some((l, ln)) = last {
                // Half the squared difference over the harmonic share of the two lengths:
                // the white noise's variance per sample.
                pairs += 0.5 * (mean - l) * (mean - l) / (0.5 / (j - i) as f64 + 0.5 / ln as f64);
                count += 1.0;
            }
            last = Some((mean, j - i));
        }
    }
    let per_sample = pairs / f64::max(count, 1.0);
    blocks
        .into_iter()
        .map(|(time_s, bias_dps, samples)| Reading {
            time_s,
            bias_dps,
            variance: per_sample / samples as f64,
        })
        .collect()
}

/// The angle at each rest with each movement's bias from `path`.
fn interpolated_path(rates: &[f64], times: &[f64], rests: &[Rest], path: &BiasPath) -> Vec<f64> {
    let mut angles = vec![0.0];
    let mut angle = 0.0;
    for pair in rests.windows(2) {
        for j in pair[0].end + 1..=pair[1].start {
            angle += rates[j] * (times[j] - times[j - 1]);
        }
        angle -= path.integral(times[pair[0].end], times[pair[1].start]).0;
        angles.push(angle);
    }
    angles
}
