//! Accuracy of the f32 pipeline: against an f64 reference of the same processing, and
//! against the true angle of smooth rotations (how much the default filter bends them).

use crate::common::{run, Profile, Rng, Shape, Swing};
use gyro_core::{Butterworth, Compensation, Config, Event, MotionState};
use proptest::prelude::*;

/// Block means in f64 of `samples` (complete blocks only), as the decimator computes them.
fn block_means(samples: &[f32], factor: usize) -> Vec<f64> {
    samples
        .chunks_exact(factor)
        .map(|block| block.iter().map(|&x| f64::from(x)).sum::<f64>() / factor as f64)
        .collect()
}

/// `scipy.signal.sosfilt` in f64 (transposed direct form II), started in the steady state
/// of the first input as the pipeline starts its filter.
fn sosfilt(sections: &[[f64; 6]], input: &[f64]) -> Vec<f64> {
    let mut state: Vec<[f64; 2]> = Vec::with_capacity(sections.len());
    let mut x0 = input.first().copied().unwrap_or(0.0);
    for &[b0, b1, b2, a0, a1, a2] in sections {
        assert_eq!(a0, 1.0);
        let y0 = x0 * (b0 + b1 + b2) / (1.0 + a1 + a2);
        let s1 = b2 * x0 - a2 * y0;
        state.push([b1 * x0 - a1 * y0 + s1, s1]);
        x0 = y0;
    }
    input
        .iter()
        .map(|&x| {
            let mut y = x;
            for (&[b0, b1, b2, _, a1, a2], s) in sections.iter().zip(state.iter_mut()) {
                let input = y;
                y = b0 * input + s[0];
                s[0] = b1 * input - a1 * y + s[1];
                s[1] = b2 * input - a2 * y;
            }
            y
        })
        .collect()
}

/// Trapezoidal integral of `rate[from..=to]` (deg/s) with step `dt_s`.
fn trapezoid(rate: &[f64], from: usize, to: usize, dt_s: f64) -> f64 {
    (from + 1..=to)
        .map(|j| 0.5 * dt_s * (rate[j - 1] + rate[j]))
        .sum()
}

/// How far the f32 pipeline strays from the f64 reference over one input.
#[derive(Debug, Default)]
struct Deviation {
    /// Largest |raw angle − reference| over the compared output samples (deg).
    raw_series_deg: f64,
    /// The same for the compensated angle (`Compensation::None`) (deg).
    angle_series_deg: f64,
    /// Largest |movement angle − reference| (raw and compensated) (deg).
    movement_deg: f64,
    /// Output samples compared, and left out (tentative integration of a run that may
    /// turn out not to be a movement: the reference cannot know it).
    compared: usize,
    skipped: usize,
    movements: usize,
}

/// Run `samples` (1 kHz) through the pipeline in `Compensation::None` and through the f64
/// reference: block mean, f64 `SosDesign`, trapezoidal integration over the movements the
/// pipeline reports (so both share every discrete detection decision).
fn compare_with_reference(samples: &[f32]) -> Deviation {
    let config = Config {
        compensation: Compensation::None,
        ..Config::default()
    };
    let factor = usize::from(config.decimation_factor().expect("valid"));
    let output_rate_hz = f64::from(config.effective_output_rate_hz().expect("valid"));
    let dt_s = 1.0 / output_rate_hz;
    let design = config.filter.design(output_rate_hz).expect("valid filter");
    let reference = sosfilt(design.sections(), &block_means(samples, factor));

    let run = run(&config, samples, 1000.0);
    let out = &run.outputs;
    assert_eq!(out.len(), reference.len());
    let delay_s = run.pipeline.filter_delay_s();
    // Output index of a movement boundary (times are on the input time line).
    let index_of = |time_s: f64| -> usize {
        out.iter()
            .position(|o| (o.time_s - delay_s - time_s).abs() < 1e-6)
            .expect("movement boundaries fall on output samples")
    };
    // The movements, as output index spans [start, end], with the index of the output
    // that reported the end.
    struct Span {
        start: usize,
        end: Option<(usize, usize)>,
    }
    let mut spans: Vec<Span> = Vec::new();
    for (k, o) in out.iter().enumerate() {
        match o.event {
            Some(Event::MovementStarted { start_time_s, .. }) => spans.push(Span {
                start: index_of(start_time_s),
                end: None,
            }),
            Some(Event::MovementEnded(m)) => {
                let span = spans.last_mut().expect("an end follows a start");
                assert_eq!(span.start, index_of(m.start_time_s));
                span.end = Some((index_of(m.end_time_s), k));
            }
            None => {}
        }
    }
    let exit_dps = f64::from(config.motion.exit_dps);

    let mut dev = Deviation::default();
    let mut done_deg = 0.0; // reference angle of the completed movements
    let mut span_iter = spans.iter().peekable();
    let mut current: Option<&Span> = None;
    for k in 0..out.len() {
        // The movement whose integration covers k: from its start (exclusive) until it is
        // confirmed ended; the pipeline integrates its onset and its settling tentatively.
        if current.is_none() {
            if let Some(span) = span_iter.peek() {
                if k > span.start {
                    current = span_iter.next();
                }
            }
        }
        let expected_deg = match current {
            Some(span) => {
                if let Some((end, _)) = span.end.filter(|&(_, ended_at)| ended_at == k) {
                    let movement_deg = trapezoid(&reference, span.start, end, dt_s);
                    if let Some(Event::MovementEnded(m)) = out[k].event {
                        for got in [m.raw_angle_deg, m.angle_deg] {
                            dev.movement_deg =
                                dev.movement_deg.max((f64::from(got) - movement_deg).abs());
                        }
                        dev.movements += 1;
                    }
                    done_deg += movement_deg;
                    current = None;
                    done_deg
                } else {
                    done_deg + trapezoid(&reference, span.start, k, dt_s)
                }
            }
            None => done_deg,
        };
        // Outside movements, a static sample that is not quiet (by the pipeline's own rate
        // and bias reference) is integrated tentatively: a run that may become a movement
        // or be dropped. The reference only knows confirmed movements: leave it out.
        let bias_dps = match k {
            0 => config.motion.initial_bias_dps,
            _ => out[k - 1].bias_dps,
        };
        let tentative = current.is_none()
            && out[k].motion == MotionState::Static
            && (f64::from(out[k].rate_dps) - f64::from(bias_dps)).abs() > exit_dps;
        if tentative {
            dev.skipped += 1;
            continue;
        }
        dev.compared += 1;
        dev.raw_series_deg = dev
            .raw_series_deg
            .max((f64::from(out[k].raw_angle_deg) - expected_deg).abs());
        dev.angle_series_deg = dev
            .angle_series_deg
            .max((f64::from(out[k].angle_deg) - expected_deg).abs());
    }
    assert_eq!(dev.movements, run.movements.len());
    dev
}

/// A bench-like profile from proptest parameters: `(rest_s, duration_s, angle_deg,
/// minimum_jerk)` per swing, laid out from t = 2 s while they fit in 88 s.
fn profile_from(segments: &[(f64, f64, f64, bool)]) -> Profile {
    let mut swings = Vec::new();
    let mut t = 2.0;
    for &(rest_s, duration_s, angle_deg, minimum_jerk) in segments {
        if t + duration_s > 88.0 {
            break;
        }
        swings.push(Swing {
            start_s: t,
            duration_s,
            angle_deg,
            shape: if minimum_jerk {
                Shape::MinimumJerk
            } else {
                Shape::RaisedCosine
            },
        });
        t += duration_s + rest_s;
    }
    Profile {
        swings,
        total_s: 90.0,
    }
}

fn swing_params() -> impl Strategy<Value = (f64, f64, f64, bool)> {
    (
        1.0..12.0_f64,
        0.5..4.0_f64,
        prop_oneof![-180.0..-20.0_f64, 20.0..180.0_f64],
        any::<bool>(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// The f32 pipeline stays within 1e-3° of the f64 reference over 90 s at 1 kHz.
    #[test]
    fn f32_pipeline_tracks_the_f64_reference(
        segments in prop::collection::vec(swing_params(), 1..14),
        bias_dps in -1.0..1.0_f64,
        noise_dps in 0.0..0.1_f64,
        seed in any::<u64>(),
    ) {
        let profile = profile_from(&segments);
        let samples = profile.samples(1000.0, bias_dps, noise_dps, &mut Rng::new(seed));
        let dev = compare_with_reference(&samples);
        eprintln!(
            "f32 vs f64: raw series {:.2e}°, angle series {:.2e}°, movements {:.2e}° \
             ({} movements, {} samples compared, {} left out)",
            dev.raw_series_deg, dev.angle_series_deg, dev.movement_deg,
            dev.movements, dev.compared, dev.skipped,
        );
        prop_assert_eq!(dev.movements, profile.swings.len());
        prop_assert!(dev.skipped * 100 <= dev.compared, "{dev:?}");
        prop_assert!(dev.raw_series_deg < 1e-3, "{dev:?}");
        prop_assert!(dev.angle_series_deg < 1e-3, "{dev:?}");
        prop_assert!(dev.movement_deg < 1e-3, "{dev:?}");
    }
}

/// The reference itself is right: its filter matches scipy on a step, and a change of
/// filter order is seen (the comparison above would not pass with the wrong design).
#[test]
fn reference_filter_is_sosfilt() {
    // scipy.signal.butter(2, 10, fs=50, output='sos'); sosfilt(sos, step) after a zero start.
    let design = Butterworth {
        order: 2,
        cutoff_hz: 10.0,
    }
    .design(50.0)
    .expect("valid");
    let mut input = vec![0.0; 4];
    input.extend([1.0; 4]);
    let y = sosfilt(design.sections(), &input);
    let b0 = 0.206_572_083_826_147_92;
    let a1 = -0.369_527_377_351_241_4;
    assert_eq!(&y[..4], &[0.0; 4]);
    assert!((y[4] - b0).abs() < 1e-12);
    // y[5] = b0 + b1 − a1 y[4] = 3 b0 − a1 b0.
    assert!((y[5] - (3.0 * b0 - a1 * b0)).abs() < 1e-12);
    let first_order = Butterworth {
        order: 1,
        cutoff_hz: 10.0,
    }
    .design(50.0)
    .expect("valid");
    assert!((sosfilt(first_order.sections(), &input)[4] - y[4]).abs() > 1e-3);
}

/// Final movement angle of one noise-free, bias-free 90° rotation through the default
/// pipeline, for several phases of the rotation against the 20 ms decimation blocks.
fn worst_bend_deg(duration_s: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for shape in [Shape::RaisedCosine, Shape::MinimumJerk] {
        for phase in 0..10 {
            let profile = Profile {
                swings: vec![Swing {
                    start_s: 2.0 + 0.0023 * f64::from(phase),
                    duration_s,
                    angle_deg: 90.0,
                    shape,
                }],
                total_s: 3.0 + duration_s + 2.0,
            };
            let samples = profile.samples(1000.0, 0.0, 0.0, &mut Rng::new(0));
            let run = run(&Config::default(), &samples, 1000.0);
            assert_eq!(run.movements.len(), 1, "{shape:?} phase {phase}");
            let movement = run.movements[0].1;
            let bend = (f64::from(movement.angle_deg) - 90.0).abs();
            // The angle is held at rest: the output agrees at the end of the run.
            let last = run.outputs.last().expect("outputs");
            assert!((f64::from(last.angle_deg) - f64::from(movement.angle_deg)).abs() < 1e-4);
            worst = worst.max(bend);
        }
    }
    worst
}

/// The default filter does not bend a 90° hand rotation in 0.8 s by more than 0.05°.
#[test]
fn default_filter_keeps_a_fast_rotation() {
    let bend = worst_bend_deg(0.8);
    eprintln!("90° in 0.8 s: worst |angle − 90°| = {bend:.4}°");
    assert!(bend < 0.05, "{bend}");
}

/// Nor a slow one, 90° in 4 s (whose ends are the hardest to find).
#[test]
fn default_filter_keeps_a_slow_rotation() {
    let bend = worst_bend_deg(4.0);
    eprintln!("90° in 4 s: worst |angle − 90°| = {bend:.4}°");
    assert!(bend < 0.05, "{bend}");
}
