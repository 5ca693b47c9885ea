//! # gyro-ffi
//!
//! The C API of [`gyro_core`]: the pipeline a C firmware links from `libgyro_ffi.a`, with
//! the header `crates/gyro-ffi/include/gyro.h` generated from this crate by cbindgen.
//! `no_std`, no allocation, no global state: the pipeline lives in storage the caller owns,
//! `GYRO_PIPELINE_SIZE` bytes aligned to `GYRO_PIPELINE_ALIGN`. Every function returns a [`GyroStatus`]; none aborts or panics on
//! any input: every pointer is checked for NULL and alignment, every flag and code of the
//! configuration for its values, and gyro-core validates the numbers. The API only
//! translates: the pipeline and the tightening decision are gyro-core's own
//! ([`gyro_core::Pipeline`], [`gyro_core::decide`]).
//!
//! In C (`examples/c-firmware/main.c` is a whole firmware):
//!
//! ```c
//! #include "gyro.h"
//!
//! static _Alignas(GYRO_PIPELINE_ALIGN) uint8_t storage[GYRO_PIPELINE_SIZE];
//!
//! GyroConfig config;
//! gyro_config_default(&config);           /* 1 kHz in, 50 Hz out, Kalman */
//! config.has_range_dps = 1;
//! config.range_dps = 300.0f;              /* the CRM100's range: flags saturation */
//! config.tightening.enabled = 1;          /* a verdict on every movement */
//! config.tightening.target_deg = 90.0f;
//! config.tightening.tolerance_deg = 5.0f;
//!
//! GyroPipeline *pipeline;
//! GyroField field;
//! if (gyro_pipeline_init(storage, sizeof storage, &config, &pipeline, &field) != GYRO_STATUS_OK) {
//!     /* gyro_field_name(field) names the setting refused */
//! }
//! GyroOutput out;   /* then at every sample (1 kHz): */
//! if (gyro_pipeline_push(pipeline, time_s, rate_dps, &out) == GYRO_STATUS_OUTPUT
//!     && out.event == GYRO_EVENT_ENDED) {
//!     /* out.movement.angle_deg, .angle_std_deg, .saturated, .verdict */
//! }
//! ```
//!
//! The same from Rust (the functions are plain `extern "C"` ones):
//!
//! ```
//! use core::ptr;
//! use gyro_ffi::*;
//!
//! #[repr(C, align(8))]
//! struct Storage([u8; GYRO_PIPELINE_SIZE]);
//! assert!(core::mem::align_of::<Storage>() >= GYRO_PIPELINE_ALIGN);
//! let mut storage = Storage([0; GYRO_PIPELINE_SIZE]);
//!
//! let mut config = core::mem::MaybeUninit::<GyroConfig>::uninit();
//! // SAFETY: a writable GyroConfig.
//! assert_eq!(unsafe { gyro_config_default(config.as_mut_ptr()) }, GyroStatus::Ok);
//! // SAFETY: gyro_config_default filled it.
//! let mut config = unsafe { config.assume_init() };
//! config.tightening.enabled = 1;
//! config.tightening.target_deg = 90.0;
//! config.tightening.tolerance_deg = 5.0;
//!
//! let (mut pipeline, mut field) = (ptr::null_mut(), GyroField::Unknown);
//! // SAFETY: storage of GYRO_PIPELINE_SIZE bytes, aligned; valid pointers to the rest.
//! let status = unsafe {
//!     gyro_pipeline_init(storage.0.as_mut_ptr().cast(), storage.0.len(), &config, &mut pipeline, &mut field)
//! };
//! assert_eq!((status, field), (GyroStatus::Ok, GyroField::None));
//!
//! // 1 s of rest, a 90° turn in 1 s (raised-cosine rate), then rest; at 1 kHz.
//! let mut ended = Vec::new();
//! for i in 0..6000 {
//!     let time_s = i as f64 * 1e-3;
//!     let rate_dps = if (1.0..2.0).contains(&time_s) {
//!         90.0 * (1.0 - (2.0 * core::f64::consts::PI * (time_s - 1.0)).cos()) as f32
//!     } else {
//!         0.0
//!     };
//!     let mut out = core::mem::MaybeUninit::<GyroOutput>::uninit();
//!     // SAFETY: the pipeline gyro_pipeline_init set up; a writable GyroOutput.
//!     match unsafe { gyro_pipeline_push(pipeline, time_s, rate_dps, out.as_mut_ptr()) } {
//!         GyroStatus::Ok => {}
//!         // SAFETY: GYRO_STATUS_OUTPUT: the output was written.
//!         GyroStatus::Output => {
//!             let out = unsafe { out.assume_init() };
//!             if out.event == GyroEvent::Ended {
//!                 ended.push(out.movement);
//!             }
//!         }
//!         error => panic!("push failed: {error:?}"),
//!     }
//! }
//! assert_eq!(ended.len(), 1);
//! assert!((ended[0].angle_deg - 90.0).abs() < 0.05);
//! assert!(ended[0].has_angle_std && ended[0].angle_std_deg > 0.0);
//! assert_eq!(ended[0].verdict, GyroVerdict::Ok);
//!
//! // Errors are codes: a NULL output pointer, a refused setting.
//! // SAFETY: NULL is checked for.
//! let status = unsafe { gyro_pipeline_push(pipeline, 6.0, 0.0, ptr::null_mut()) };
//! assert_eq!(status, GyroStatus::NullPointer);
//! config.motion.exit_dps = -1.0;
//! // SAFETY: as above.
//! let status = unsafe {
//!     gyro_pipeline_init(storage.0.as_mut_ptr().cast(), storage.0.len(), &config, &mut pipeline, &mut field)
//! };
//! assert_eq!((status, field), (GyroStatus::ConfigOutOfRange, GyroField::MotionExitDps));
//! ```
//!
//! On a bare-metal target the staticlib carries a `#[panic_handler]` (feature
//! `panic-handler`, on by default), because a staticlib must name one; it raises a HardFault.
//! Nothing in this crate can panic, and the checks of gyro-core it links (slices bounded by
//! the filter's section count) guard the pipeline's own invariants, not its input.
//!
//! The header is committed and checked: `cargo test -p gyro-ffi --test all header::` fails when
//! `include/gyro.h` differs from what cbindgen makes of this crate, and
//! `GYRO_FFI_BLESS=1 cargo test -p gyro-ffi --test all header::` rewrites it.
#![no_std]
// The API is raw pointers from C: checked, then dereferenced in `unsafe` blocks, each with
// its reason (`SAFETY:`).
#![allow(unsafe_code)]
#![deny(unsafe_op_in_unsafe_fn, clippy::undocumented_unsafe_blocks)]

// A hosted staticlib links std for its panic runtime (unwinding needs it); the code uses
// `core` only, which the thumbv7em-none-eabihf build proves.
#[cfg(not(target_os = "none"))]
extern crate std;

mod config;
mod output;
mod status;

use core::ffi::c_void;
use core::mem::{align_of, size_of};

use gyro_core::{decide, Event, Output, Pipeline, Tightening};

pub use config::{
    GyroCompensation, GyroConfig, GyroCorrectionConfig, GyroDirection, GyroFilterConfig,
    GyroKalmanConfig, GyroMotionConfig, GyroPaperConfig, GyroTighteningConfig,
};
pub use output::{GyroEvent, GyroMotion, GyroMovement, GyroOutput, GyroPipelineInfo, GyroVerdict};
pub use status::{gyro_field_name, gyro_status_name, GyroField, GyroStatus};

/// Bytes of storage a pipeline needs (`gyro_pipeline_init`'s `storage_size` at least).
pub const GYRO_PIPELINE_SIZE: usize = 552;

/// Alignment (bytes) the pipeline's storage needs, e.g.
/// `static _Alignas(GYRO_PIPELINE_ALIGN) uint8_t storage[GYRO_PIPELINE_SIZE];`.
pub const GYRO_PIPELINE_ALIGN: usize = 8;

const _: () = assert!(
    size_of::<GyroPipeline>() == GYRO_PIPELINE_SIZE,
    "GYRO_PIPELINE_SIZE must be size_of::<GyroPipeline>()"
);
const _: () = assert!(
    align_of::<GyroPipeline>() == GYRO_PIPELINE_ALIGN,
    "GYRO_PIPELINE_ALIGN must be align_of::<GyroPipeline>()"
);

/// Marks storage that `gyro_pipeline_init` set up ("GYRO").
const MAGIC: u32 = u32::from_be_bytes(*b"GYRO");

/// A pipeline in caller-owned storage (opaque to C): set up by `gyro_pipeline_init`, then
/// fed by `gyro_pipeline_push`. It owns nothing else and needs no clean-up: the storage may
/// be reused or set up again at any time.
pub struct GyroPipeline {
    /// [`MAGIC`] once set up.
    magic: u32,
    /// Output samples produced so far: the index of the next one.
    outputs: u32,
    /// Index of the output sample whose block held the latest rejected input sample.
    last_rejected_index: Option<u32>,
    /// The tightening window the movements are judged against.
    tightening: Option<Tightening>,
    pipeline: Pipeline,
}

/// `true` if `[a, a + size_of::<A>())` and `[b, b + size_of::<B>())` share a byte.
fn overlaps<A, B>(a: *const A, b: *const B) -> bool {
    let (a, b) = (a.addr(), b.addr());
    a < b.saturating_add(size_of::<B>()) && b < a.saturating_add(size_of::<A>())
}

/// `Ok` if `ptr` is not NULL and aligned for `T`.
fn check<T>(ptr: *const T) -> Result<(), GyroStatus> {
    if ptr.is_null() {
        Err(GyroStatus::NullPointer)
    } else if !ptr.is_aligned() {
        Err(GyroStatus::Misaligned)
    } else {
        Ok(())
    }
}

/// `Ok` if `pipeline` is not NULL, aligned, and set up by `gyro_pipeline_init`.
///
/// # Safety
/// `pipeline` is NULL or points to `GYRO_PIPELINE_SIZE` readable bytes.
unsafe fn check_pipeline(pipeline: *const GyroPipeline) -> Result<(), GyroStatus> {
    check(pipeline)?;
    // SAFETY: not NULL, aligned, and (the caller's promise) GYRO_PIPELINE_SIZE =
    // size_of::<GyroPipeline>() bytes: the magic word is readable whatever they hold.
    let magic = unsafe { core::ptr::addr_of!((*pipeline).magic).read() };
    if magic == MAGIC {
        Ok(())
    } else {
        Err(GyroStatus::NotInitialized)
    }
}

/// Fill `*config` with gyro-core's default configuration: 1 kHz in, 50 Hz out,
/// 2nd-order Butterworth at 12.5 Hz, Kalman compensation, no correction, range unknown,
/// no tightening window.
///
/// Returns `GYRO_STATUS_OK`, or `GYRO_STATUS_NULL_POINTER` / `GYRO_STATUS_MISALIGNED`.
///
/// # Safety
/// `config` is NULL or points to a writable `GyroConfig`.
#[no_mangle]
pub unsafe extern "C" fn gyro_config_default(config: *mut GyroConfig) -> GyroStatus {
    if let Err(status) = check(config) {
        return status;
    }
    // SAFETY: checked above; the caller promises a writable GyroConfig.
    unsafe { config.write(GyroConfig::from_core(&gyro_core::Config::default())) };
    GyroStatus::Ok
}

/// Set up a pipeline configured by `*config` in the caller's `storage` (at least
/// `GYRO_PIPELINE_SIZE` bytes, aligned to `GYRO_PIPELINE_ALIGN`), and point `*pipeline` at
/// it. No other memory is used, and nothing needs freeing: set up the same storage again
/// to start over.
///
/// Returns `GYRO_STATUS_OK`; `GYRO_STATUS_CONFIG_NON_FINITE` or
/// `GYRO_STATUS_CONFIG_OUT_OF_RANGE` for a refused configuration, with the setting in
/// `*field`; `GYRO_STATUS_NULL_POINTER`, `GYRO_STATUS_MISALIGNED`,
/// `GYRO_STATUS_STORAGE_TOO_SMALL` or `GYRO_STATUS_OVERLAP` (`*pipeline` or `*field`
/// inside the storage) for the arguments. On any error the storage and `*pipeline` are
/// left as they were (a pipeline already there stays usable).
///
/// `field` may be NULL; otherwise `*field` is set on every return that gets that far:
/// the refused setting, or `GYRO_FIELD_NONE`.
///
/// # Safety
/// `storage` is NULL or points to `storage_size` writable bytes; `config` is NULL or points
/// to a `GyroConfig`; `pipeline` is NULL or points to a writable `GyroPipeline *`; `field`
/// is NULL or points to a writable `GyroField`.
#[no_mangle]
pub unsafe extern "C" fn gyro_pipeline_init(
    storage: *mut c_void,
    storage_size: usize,
    config: *const GyroConfig,
    pipeline: *mut *mut GyroPipeline,
    field: *mut GyroField,
) -> GyroStatus {
    let storage = storage.cast::<GyroPipeline>();
    if !field.is_null() {
        if !field.is_aligned() {
            return GyroStatus::Misaligned;
        }
        if !storage.is_null() && overlaps(field, storage) {
            return GyroStatus::Overlap;
        }
    }
    let (status, refused) = match init(storage, storage_size, config, pipeline) {
        Ok(()) => (GyroStatus::Ok, GyroField::None),
        Err((status, refused)) => (status, refused),
    };
    if !field.is_null() {
        // SAFETY: not NULL and aligned (checked above); the caller promises it writable.
        unsafe { field.write(refused) };
    }
    status
}

/// `gyro_pipeline_init` but for `*field`.
fn init(
    storage: *mut GyroPipeline,
    storage_size: usize,
    config: *const GyroConfig,
    pipeline: *mut *mut GyroPipeline,
) -> Result<(), (GyroStatus, GyroField)> {
    let argument = |status| (status, GyroField::None);
    check(storage).map_err(argument)?;
    check(config).map_err(argument)?;
    check(pipeline).map_err(argument)?;
    if storage_size < GYRO_PIPELINE_SIZE {
        return Err(argument(GyroStatus::StorageTooSmall));
    }
    if overlaps(pipeline, storage) {
        return Err(argument(GyroStatus::Overlap));
    }
    // SAFETY: not NULL, aligned; the caller promises a GyroConfig. Copied before the storage
    // is written, which it may overlap.
    let config = unsafe { config.read() }.to_core()?;
    let core = Pipeline::try_new(&config).map_err(status::refusal)?;
    let state = GyroPipeline {
        magic: MAGIC,
        outputs: 0,
        last_rejected_index: None,
        tightening: config.tightening,
        pipeline: core,
    };
    // SAFETY: not NULL, aligned, at least GYRO_PIPELINE_SIZE = size_of::<GyroPipeline>()
    // writable bytes (the caller's promise for storage_size); `pipeline` is outside them.
    unsafe {
        storage.write(state);
        pipeline.write(storage);
    }
    Ok(())
}

/// Push one input sample: `time_s` (s) and `rate_dps` (deg/s). The configured correction's
/// scale and asymmetry apply, its temperature terms do not (see
/// `gyro_pipeline_push_with_temperature`).
///
/// Returns `GYRO_STATUS_OUTPUT` when the sample completed an output sample (written to
/// `*output`), `GYRO_STATUS_OK` when not; `GYRO_STATUS_NULL_POINTER`,
/// `GYRO_STATUS_MISALIGNED`, `GYRO_STATUS_NOT_INITIALIZED` or `GYRO_STATUS_OVERLAP` for
/// the arguments (the sample is then not taken). A rate that is not finite, or beyond
/// `max_abs_rate_dps`, is taken as the last valid rate and counted
/// (`GyroPipelineInfo.rejected_samples`); a time that is not finite as one period after
/// the last.
///
/// # Safety
/// `pipeline` is NULL or points to `GYRO_PIPELINE_SIZE` bytes (set up by
/// `gyro_pipeline_init`, or else it is refused) that nothing else uses during the call;
/// `output` is NULL or points to a writable `GyroOutput`.
#[no_mangle]
pub unsafe extern "C" fn gyro_pipeline_push(
    pipeline: *mut GyroPipeline,
    time_s: f64,
    rate_dps: f32,
    output: *mut GyroOutput,
) -> GyroStatus {
    // SAFETY: the caller's promises, passed on.
    unsafe { push(pipeline, output, |core| core.push(time_s, rate_dps)) }
}

/// Push one input sample with the sensor's temperature `temperature_c` (°C): the whole
/// correction applies, its temperature terms included. A temperature that is not finite or
/// not plausible (outside −100 to 200 °C) is ignored: the last valid one stays in use. With
/// the identity correction (the default) this gives exactly what `gyro_pipeline_push` gives.
///
/// Returns as `gyro_pipeline_push`.
///
/// # Safety
/// As `gyro_pipeline_push`.
#[no_mangle]
pub unsafe extern "C" fn gyro_pipeline_push_with_temperature(
    pipeline: *mut GyroPipeline,
    time_s: f64,
    rate_dps: f32,
    temperature_c: f32,
    output: *mut GyroOutput,
) -> GyroStatus {
    // SAFETY: the caller's promises, passed on.
    unsafe {
        push(pipeline, output, |core| {
            core.push_with_temperature(time_s, rate_dps, temperature_c)
        })
    }
}

/// Check the arguments, push with `push`, judge an ended movement, write the output.
///
/// # Safety
/// As `gyro_pipeline_push`.
unsafe fn push(
    pipeline: *mut GyroPipeline,
    output: *mut GyroOutput,
    push: impl FnOnce(&mut Pipeline) -> Option<Output>,
) -> GyroStatus {
    if let Err(status) = check(output) {
        return status;
    }
    if !pipeline.is_null() && overlaps(output, pipeline) {
        return GyroStatus::Overlap;
    }
    // SAFETY: the caller's promise for `pipeline`.
    if let Err(status) = unsafe { check_pipeline(pipeline) } {
        return status;
    }
    // SAFETY: gyro_pipeline_init wrote a GyroPipeline there (the magic word says so), and
    // nothing else uses it during the call.
    let state = unsafe { &mut *pipeline };
    let rejected_before = state.pipeline.rejected_samples();
    let result = push(&mut state.pipeline);
    if state.pipeline.rejected_samples() != rejected_before {
        // The sample belongs to the block of the next output.
        state.last_rejected_index = Some(state.outputs);
    }
    let Some(out) = result else {
        return GyroStatus::Ok;
    };
    let index = state.outputs;
    state.outputs = state.outputs.saturating_add(1);
    let ended = match &out.event {
        Some(Event::MovementEnded(movement)) => {
            let rejected = state
                .last_rejected_index
                .is_some_and(|i| i >= movement.start_index);
            let verdict = state.tightening.as_ref().and_then(|window| {
                decide(
                    window,
                    movement.angle_deg,
                    movement.angle_std_deg.unwrap_or(0.0),
                    movement.saturated || rejected,
                )
            });
            Some(GyroMovement::ended(movement, rejected, verdict))
        }
        _ => None,
    };
    // SAFETY: not NULL, aligned (checked above), outside the pipeline's storage; the
    // caller promises a writable GyroOutput.
    unsafe { output.write(GyroOutput::new(&out, index, ended)) };
    GyroStatus::Output
}

/// Write the pipeline's counters and state to `*info`.
///
/// Returns `GYRO_STATUS_OK`; `GYRO_STATUS_NULL_POINTER`, `GYRO_STATUS_MISALIGNED`,
/// `GYRO_STATUS_NOT_INITIALIZED` or `GYRO_STATUS_OVERLAP` for the arguments.
///
/// # Safety
/// `pipeline` as for `gyro_pipeline_push`; `info` is NULL or points to a writable
/// `GyroPipelineInfo`.
#[no_mangle]
pub unsafe extern "C" fn gyro_pipeline_info(
    pipeline: *const GyroPipeline,
    info: *mut GyroPipelineInfo,
) -> GyroStatus {
    if let Err(status) = check(info) {
        return status;
    }
    if !pipeline.is_null() && overlaps(info, pipeline) {
        return GyroStatus::Overlap;
    }
    // SAFETY: the caller's promise for `pipeline`.
    if let Err(status) = unsafe { check_pipeline(pipeline) } {
        return status;
    }
    // SAFETY: gyro_pipeline_init wrote a GyroPipeline there (the magic word says so).
    let state = unsafe { &*pipeline };
    let core = &state.pipeline;
    let summary = GyroPipelineInfo {
        filter_delay_s: core.filter_delay_s(),
        output_period_s: core.output_period_s(),
        rejected_samples: core.rejected_samples(),
        outputs: state.outputs,
        finite: core.is_finite(),
        movement_saturated: core.movement_saturated(),
        range_contradicted: core.range_contradicted(),
    };
    // SAFETY: not NULL, aligned (checked above), outside the pipeline; the caller promises
    // a writable GyroPipelineInfo.
    unsafe { info.write(summary) };
    GyroStatus::Ok
}

/// A staticlib for a bare-metal target must name a panic handler, although nothing here
/// panics: this one raises a HardFault (`udf`), which the firmware's fault handler sees.
#[cfg(all(target_os = "none", feature = "panic-handler", not(test)))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        #[cfg(target_arch = "arm")]
        // SAFETY: `udf` only raises the undefined-instruction fault.
        unsafe {
            core::arch::asm!("udf #0");
        }
        core::hint::spin_loop();
    }
}
