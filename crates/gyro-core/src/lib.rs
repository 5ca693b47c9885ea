//! # gyro-core
//!
//! One-dimensional rotation angle from a single-axis gyroscope (Silicon Sensing CRM100),
//! `#![no_std]`, allocation-free, f32 state: the pipeline an intelligent torque wrench
//! runs on its MCU, and the one the host tools replay logs through.
//!
//! Input (typically 1 kHz) → [`Correction`] of scale and temperature errors (identity by
//! default) → [`Decimator`] (boxcar average, preserves the integral of the
//! rate) → [`Butterworth`] low-pass ([`Sos`] cascade) → [`MotionDetector`] (static/dynamic,
//! hysteresis, dwell times) → [`Integrator`] (trapezoidal, only while moving) → error
//! compensation: the paper's Gauss-Markov model ([`GaussMarkov`]) or its Kalman form
//! ([`KalmanBias`]), which also reports the angle's standard deviation.
//!
//! Samples go in one at a time ([`Pipeline::push`]) or in blocks ([`Pipeline::push_block`],
//! the same outputs bit for bit, at a third of the cost per sample on long blocks).
//!
//! ```
//! use gyro_core::{Config, Event, Pipeline};
//!
//! let mut pipeline = Pipeline::try_new(&Config::default())?;
//! let mut turned_deg = 0.0;
//! for i in 0..6000 {
//!     let time_s = i as f64 * 1e-3;
//!     // 1 s of rest, a 90° turn in 1 s (raised-cosine rate profile), then rest.
//!     let rate_dps = if (1.0..2.0).contains(&time_s) {
//!         90.0 * (1.0 - (2.0 * core::f64::consts::PI * (time_s - 1.0)).cos()) as f32
//!     } else {
//!         0.0
//!     };
//!     if let Some(out) = pipeline.push(time_s, rate_dps) {
//!         if let Some(Event::MovementEnded(movement)) = out.event {
//!             turned_deg = movement.angle_deg;
//!         }
//!     }
//! }
//! assert!((turned_deg - 90.0).abs() < 0.05);
//! # Ok::<(), gyro_core::Error>(())
//! ```
#![cfg_attr(not(test), no_std)]

mod butterworth;
mod correction;
mod decimator;
mod decision;
mod error;
mod gauss_markov;
mod integrator;
mod kahan;
mod kalman;
mod motion;
mod pipeline;
mod sos;

pub use butterworth::{Butterworth, SosDesign, MAX_ORDER};
pub use correction::{Correction, Corrector, MAX_DELTA_C, MIN_SCALE, TEMPERATURE_RANGE_C};
pub use decimator::{BlockRun, Decimator};
pub use decision::{decide, Direction, Tightening, Verdict};
pub use error::Error;
pub use gauss_markov::GaussMarkov;
pub use integrator::Integrator;
pub use kahan::KahanSum;
pub use kalman::{KalmanBias, KalmanConfig};
pub use motion::{MotionConfig, MotionDetector, MotionState, Phase};
pub use pipeline::{
    beyond_range, Compensation, Config, Event, Movement, Output, Pipeline, CLIP_PLATEAU_LEAD_DPS,
    CLIP_PLATEAU_LONG_S, CLIP_PLATEAU_MIN_DPS, CLIP_PLATEAU_SAMPLES, CLIP_PLATEAU_SHORT_S,
    RANGE_MARGIN,
};
pub use sos::{Biquad, Sos, SosState, MAX_SECTIONS};
