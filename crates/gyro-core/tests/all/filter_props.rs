//! Properties of the decimator and of every valid Butterworth design's f32 runtime.
//!
//! "Every valid design": order 1..=8, any sample rate from 1 Hz to 100 kHz, any cutoff
//! with `Butterworth::MIN_CUTOFF_RATIO ≤ cutoff / sample rate ≤ MAX_CUTOFF_RATIO`
//! (log-uniform, ends included), i.e. whatever `Butterworth::validate` accepts.
// Helpers outside #[test] fns unwrap too: the strategies only produce valid designs.
#![allow(clippy::unwrap_used)]

use gyro_core::{Butterworth, Decimator, Sos, SosDesign, SosState, MAX_ORDER};
use proptest::prelude::*;

/// Unit roundoff of f32.
const U32: f64 = f32::EPSILON as f64 / 2.0;

// ---------------------------------------------------------------------------------------
// Strategies and helpers.

/// A design `validate` accepts, with its sample rate.
fn valid_design() -> impl Strategy<Value = (Butterworth, f64)> {
    let unit = prop_oneof![1 => Just(0.0), 1 => Just(1.0), 8 => 0.0..=1.0_f64];
    (1..=MAX_ORDER, unit, 0.0..=5.0_f64).prop_filter_map(
        "cutoff rounded to f32 left the valid range",
        |(order, r, log_fs)| {
            let (lo, hi) = (Butterworth::MIN_CUTOFF_RATIO, Butterworth::MAX_CUTOFF_RATIO);
            let ratio = lo * (hi / lo).powf(r);
            let fs = 10_f64.powf(log_fs);
            let filter = Butterworth {
                order,
                cutoff_hz: (ratio * fs) as f32,
            };
            filter.validate(fs).ok().map(|()| (filter, fs))
        },
    )
}

/// Largest pole radius of the f64 design.
fn max_pole_radius(design: &SosDesign) -> f64 {
    design
        .sections()
        .iter()
        .map(|&[_, _, _, a0, a1, a2]| {
            let (a1, a2) = (a1 / a0, a2 / a0);
            let disc = a1 * a1 - 4.0 * a2;
            if disc < 0.0 {
                a2.sqrt()
            } else {
                let r = disc.sqrt();
                ((-a1 + r) / 2.0).abs().max(((-a1 - r) / 2.0).abs())
            }
        })
        .fold(0.0, f64::max)
}

/// Samples after which every mode of the design has decayed by e⁻²⁵ (3e-11).
fn settle_len(design: &SosDesign) -> usize {
    let r = max_pole_radius(design);
    assert!(r < 1.0);
    (25.0 / -r.ln()).ceil() as usize + 10
}

/// The f64 impulse response (scipy's `sosfilt` algorithm on the f64 design), long
/// enough that the rest is below 3e-11 of its peak.
fn impulse_response(design: &SosDesign) -> Vec<f64> {
    let n = settle_len(design);
    let mut state = vec![[0.0_f64; 2]; design.sections().len()];
    (0..n)
        .map(|i| {
            let mut y = if i == 0 { 1.0 } else { 0.0 };
            for (row, s) in design.sections().iter().zip(state.iter_mut()) {
                let [b0, b1, b2, _, a1, a2] = *row;
                let input = y;
                y = b0 * input + s[0];
                s[0] = b1 * input - a1 * y + s[1];
                s[1] = b2 * input - a2 * y;
            }
            y
        })
        .collect()
}

/// An f32 of magnitude 10^[lo, hi] and either sign.
fn magnitude(lo: f64, hi: f64) -> impl Strategy<Value = f32> {
    (lo..=hi, any::<bool>()).prop_map(|(e, neg)| {
        let m = 10_f64.powf(e) as f32;
        if neg {
            -m
        } else {
            m
        }
    })
}

// ---------------------------------------------------------------------------------------
// (a) Decimation preserves the integral.

/// Inputs of every scale up to 1e4, zeros included.
fn decimator_input() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -1e4_f32..=1e4,
        2 => -1.0_f32..=1.0,
        1 => -1e-3_f32..=1e-3,
        1 => magnitude(-30.0, 4.0),
        1 => Just(0.0_f32),
    ]
}

/// Arbitrary sequences, and sequences where a large sample is followed by many small
/// ones of one sign: plain f32 summation drops the small ones (each below half an ulp of
/// the large one) and fails the tolerance; compensated summation keeps them.
fn decimator_sequence() -> impl Strategy<Value = Vec<f32>> {
    prop_oneof![
        prop::collection::vec(decimator_input(), 0..600),
        (
            magnitude(2.0, 4.0),
            magnitude(-6.0, -3.0),
            0_usize..600,
            1_usize..=60
        )
            .prop_map(|(big, small, len, period)| {
                (0..len)
                    .map(|i| if i % period == 0 { big } else { small })
                    .collect()
            }),
    ]
}

proptest! {
    /// Each output × factor equals the sum of its block's inputs, and so does the sum of
    /// all outputs × factor with the sum of the inputs of the completed blocks. The
    /// tolerance is the error bound of the f32 arithmetic, per block: the plain sum of n
    /// samples in order ((n − 1)·u·Σ|x|, to first order) and dividing by the factor
    /// (u·|Σx|), so at most (n + 1)·u·Σ|x| with u = 2⁻²⁴ and n the factor; plus 1e-44 per
    /// block for subnormal sums.
    #[test]
    fn decimation_preserves_integral(
        factor in 1_u16..=50,
        x in decimator_sequence(),
    ) {
        let mut d = Decimator::try_new(factor).unwrap();
        let f = usize::from(factor);
        let mut outputs = Vec::new();
        for (i, &v) in x.iter().enumerate() {
            let out = d.push(v);
            prop_assert_eq!(out.is_some(), (i + 1) % f == 0);
            outputs.extend(out);
        }
        prop_assert_eq!(outputs.len(), x.len() / f);
        prop_assert_eq!(usize::from(d.pending()), x.len() % f);

        let (mut total_out, mut total_in, mut total_tol) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (block, &mean) in x.chunks_exact(f).zip(&outputs) {
            let exact: f64 = block.iter().map(|&v| f64::from(v)).sum();
            let abs_sum: f64 = block.iter().map(|&v| f64::from(v).abs()).sum();
            let got = f64::from(mean) * f64::from(factor);
            let tol = (f64::from(factor) + 1.0) * U32 * abs_sum + 1e-44;
            prop_assert!(
                (got - exact).abs() <= tol,
                "block {:?}: mean × factor {} vs sum {}", block, got, exact
            );
            total_out += got;
            total_in += exact;
            total_tol += tol;
        }
        prop_assert!(
            (total_out - total_in).abs() <= total_tol + 1e-12 * total_in.abs(),
            "Σ outputs × factor {} vs Σ inputs of completed blocks {}", total_out, total_in
        );
    }

    /// The decimator adds its samples in pairs: each output is, bit for bit, the block's
    /// f32 sum taken one sample at a time over the factor, for odd and even factors;
    /// `last` is the latest sample pushed.
    #[test]
    fn pairs_give_the_one_at_a_time_sum(
        factor in 1_u16..=25,
        x in decimator_sequence(),
    ) {
        let mut d = Decimator::try_new(factor).unwrap();
        let mut blocks = x.chunks_exact(usize::from(factor));
        for &v in &x {
            if let Some(mean) = d.push(v) {
                let mut sum = 0.0_f32;
                for &b in blocks.next().unwrap() {
                    sum += b;
                }
                let expected = sum / f32::from(factor);
                prop_assert_eq!(mean.to_bits(), expected.to_bits(), "{} vs {}", mean, expected);
            }
            prop_assert_eq!(d.last().to_bits(), v.to_bits());
        }
    }
}

// ---------------------------------------------------------------------------------------
// (b) DC gain 1.

/// Largest allowed |DC gain − 1|, both analytic and measured on the f32 cascade.
const DC_TOL: f64 = 1e-5;

/// Runs `c` through the f32 cascade from zero state until every mode has decayed, and
/// returns the largest |y/c − 1| over 20 further samples.
fn settled_dc_error(sos: &Sos, design: &SosDesign, c: f32) -> f64 {
    let mut state = SosState::new();
    for _ in 0..settle_len(design) {
        sos.process(&mut state, c);
    }
    (0..20)
        .map(|_| (f64::from(sos.process(&mut state, c)) / f64::from(c) - 1.0).abs())
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// `Sos::dc_gain` (from the f32 coefficients) and the settled output of a constant
    /// through the f32 cascade both give 1 within 1e-5; `settle` gives a state that the
    /// same constant leaves unchanged.
    #[test]
    fn dc_gain_is_one((filter, fs) in valid_design(), c in magnitude(-6.0, 6.0)) {
        let design = filter.design(fs).unwrap();
        let sos = design.to_sos();
        prop_assert!((sos.dc_gain() - 1.0).abs() <= DC_TOL, "dc_gain {}", sos.dc_gain());
        let err = settled_dc_error(&sos, &design, c);
        prop_assert!(err <= DC_TOL, "{:?} at {} Hz, input {}: |y/c - 1| = {:e}", filter, fs, c, err);

        let mut state = SosState::new();
        sos.settle(&mut state, c);
        let settled = state;
        let y = sos.process(&mut state, c);
        prop_assert_eq!(state, settled);
        prop_assert!((f64::from(y) / f64::from(c) - 1.0).abs() <= DC_TOL);
    }
}

/// A fixed grid over orders and cutoff ratios, reporting the worst DC gain errors seen.
#[test]
fn dc_gain_grid() {
    let (lo, hi) = (Butterworth::MIN_CUTOFF_RATIO, Butterworth::MAX_CUTOFF_RATIO);
    let mut worst_analytic = 0.0_f64;
    let mut worst_settled = 0.0_f64;
    for order in 1..=MAX_ORDER {
        for i in 0..=12 {
            let ratio = lo * (hi / lo).powf(f64::from(i) / 12.0);
            let fs = 1000.0;
            let filter = Butterworth {
                order,
                cutoff_hz: (ratio * fs) as f32,
            };
            let Ok(design) = filter.design(fs) else {
                continue;
            };
            let sos = design.to_sos();
            worst_analytic = worst_analytic.max((sos.dc_gain() - 1.0).abs());
            for c in [1.0_f32, -3.7, 900.0] {
                worst_settled = worst_settled.max(settled_dc_error(&sos, &design, c));
            }
        }
    }
    println!(
        "DC gain: |dc_gain() - 1| <= {worst_analytic:e}, settled |y/c - 1| <= {worst_settled:e}"
    );
    assert!(worst_analytic <= DC_TOL && worst_settled <= DC_TOL);
}

// ---------------------------------------------------------------------------------------
// (c) Bounded output.

/// How the bounded-output input is built.
#[derive(Clone, Debug)]
enum BoundedInput {
    /// Samples `M · u` with `u` in [−1, 1].
    Random(Vec<f32>),
    /// `M · sign(h[K − 1 − n])`: the input that drives the output at `n = K − 1` to
    /// `M · Σ|h|`, the bound itself.
    Worst,
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// For inputs bounded by M, |y| ≤ (Σ|h| + 1e-5) · M at every sample, where h is the
    /// f64 impulse response of the design (the exact bound for the exact filter; 1e-5
    /// covers the f32 runtime's deviation, ≤ 2.5e-6 of the input's full scale in
    /// filter_golden.rs), and every output is finite. With the worst-case input the
    /// output reaches the bound.
    #[test]
    fn output_is_bounded(
        (filter, fs) in valid_design(),
        m in 1e-3_f64..=1e30,
        input in prop_oneof![
            3 => prop::collection::vec(-1.0_f32..=1.0, 1..3000).prop_map(BoundedInput::Random),
            1 => Just(BoundedInput::Worst),
        ],
    ) {
        let design = filter.design(fs).unwrap();
        let sos = design.to_sos();
        let h = impulse_response(&design);
        let l1: f64 = h.iter().map(|v| v.abs()).sum();
        let x: Vec<f32> = match &input {
            BoundedInput::Random(u) => u.iter().map(|&u| (f64::from(u) * m) as f32).collect(),
            BoundedInput::Worst => h
                .iter()
                .rev()
                .map(|&v| if v < 0.0 { -m as f32 } else { m as f32 })
                .collect(),
        };
        let m_eff = x.iter().map(|&v| f64::from(v).abs()).fold(0.0, f64::max);
        let bound = (l1 + 1e-5) * m_eff;
        let mut state = SosState::new();
        let mut y = 0.0_f32;
        for &v in &x {
            y = sos.process(&mut state, v);
            prop_assert!(y.is_finite());
            prop_assert!(f64::from(y).abs() <= bound, "|y| = {} > {} (Σ|h| = {})", y, bound, l1);
        }
        if let BoundedInput::Worst = input {
            prop_assert!(f64::from(y) >= (l1 - 1e-5) * m_eff, "{} < Σ|h|·M = {}", y, l1 * m_eff);
        }
    }
}

// ---------------------------------------------------------------------------------------
// (d) Finite state for any finite input.

/// Any finite f32: every exponent, subnormals, zeros and the extremes.
fn finite_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => prop::num::f32::NORMAL | prop::num::f32::SUBNORMAL | prop::num::f32::ZERO,
        1 => prop_oneof![Just(f32::MAX), Just(f32::MIN), Just(f32::MIN_POSITIVE)],
    ]
}

/// Finite inputs: arbitrary samples, or a square wave of ±`f32::MAX` with any period
/// (the input that resonates the state most, near the cutoff).
fn finite_input() -> impl Strategy<Value = Vec<f32>> {
    prop_oneof![
        prop::collection::vec(finite_f32(), 1..2000),
        (1_usize..=60, 1_usize..4000).prop_map(|(half_period, len)| {
            (0..len)
                .map(|i| {
                    if (i / half_period) % 2 == 0 {
                        f32::MAX
                    } else {
                        f32::MIN
                    }
                })
                .collect()
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Any finite input keeps the state and the output finite (inputs beyond ±1e34 are
    /// clamped); so does `settle` with any finite value.
    #[test]
    fn state_stays_finite(
        (filter, fs) in valid_design(),
        x in finite_input(),
        start in finite_f32(),
    ) {
        let sos = filter.sos(fs).unwrap();
        let mut state = SosState::new();
        sos.settle(&mut state, start);
        prop_assert!(state.is_finite());
        for &v in &x {
            let y = sos.process(&mut state, v);
            prop_assert!(y.is_finite() && state.is_finite(), "input {} gave {}", v, y);
        }
    }
}
