//! The pipeline never touches the heap: building one and running 90 s of 1 kHz samples
//! through it allocates nothing, in every compensation mode.
// A counting `#[global_allocator]` needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#![allow(unsafe_code)]

// The helpers of the other tests (`all/`), shared with this binary of its own.
#[path = "all/common/mod.rs"]
mod common;

use common::{BenchSpec, Profile, Rng};
use gyro_core::{Compensation, Config, Correction, Event, Pipeline};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::hint::black_box;

thread_local! {
    /// Allocations made by this thread (tests run on threads of their own).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count_one() {
    // `try_with`: the thread's locals may already be gone while it exits.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

struct Counting;

// SAFETY: every method forwards to `System` with the caller's arguments unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: forwarded as is.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: forwarded as is.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        // SAFETY: forwarded as is.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as is.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Run `f` and count the allocations this thread makes meanwhile.
fn allocations_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let before = ALLOCATIONS.with(Cell::get);
    let result = f();
    let after = ALLOCATIONS.with(Cell::get);
    (result, after - before)
}

/// The counter sees allocations: the test below cannot pass for want of counting.
#[test]
fn the_counter_counts() {
    let (_, n) = allocations_during(|| {
        let v: Vec<u64> = Vec::with_capacity(16);
        black_box(v)
    });
    assert_eq!(n, 1);
    let (_, n) = allocations_during(|| black_box(format!("{}", black_box(42))).len());
    assert!(n >= 1);
}

#[test]
fn pipeline_allocates_nothing() {
    // The input is made (allocated) before counting starts: 90 s at 1 kHz, bench-like,
    // with bias, noise and a few invalid samples, so that every path is taken.
    let mut rng = Rng::new(90);
    let profile = Profile::bench(&mut rng, &BenchSpec::default());
    let mut samples = profile.samples(1000.0, 0.4, 0.08, &mut rng);
    for i in (1234..samples.len()).step_by(9973) {
        samples[i] = [f32::NAN, f32::INFINITY, 3e38][i % 3];
    }
    assert_eq!(samples.len(), 90_000);

    let correction = Correction {
        scale_k: 0.02,
        asymmetry_k: 0.005,
        bias_dps_per_c: 0.05,
        scale_per_c: 1e-3,
        temperature_ref_c: None,
    };
    for (compensation, correction, with_temperature) in [
        (Compensation::None, Correction::IDENTITY, false),
        (Compensation::Paper, Correction::IDENTITY, false),
        (Compensation::Kalman, Correction::IDENTITY, false),
        (Compensation::Kalman, correction, false),
        (Compensation::Kalman, correction, true),
    ] {
        let config = Config {
            compensation,
            correction,
            ..Config::default()
        };
        let ((outputs, movements, angle_deg), n) = allocations_during(|| {
            let mut pipeline = Pipeline::try_new(black_box(&config)).expect("default config");
            let mut outputs = 0_usize;
            let mut movements = 0_usize;
            let mut angle_deg = 0.0;
            for (i, &rate) in samples.iter().enumerate() {
                let time_s = i as f64 * 1e-3;
                let out = if with_temperature {
                    let temperature_c = 25.0 + 1e-4 * i as f32;
                    pipeline.push_with_temperature(time_s, black_box(rate), temperature_c)
                } else {
                    pipeline.push(time_s, black_box(rate))
                };
                if let Some(out) = out {
                    outputs += 1;
                    angle_deg = out.angle_deg;
                    if let Some(Event::MovementEnded(_)) = out.event {
                        movements += 1;
                    }
                }
            }
            black_box(&pipeline);
            (outputs, movements, angle_deg)
        });
        assert_eq!(n, 0, "{compensation:?} {correction:?}: {n} allocations");
        // The run did real work.
        assert_eq!(outputs, 4500);
        assert_eq!(movements, profile.swings.len());
        assert!(angle_deg != 0.0);
    }
}
