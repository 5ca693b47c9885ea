//! Renderers of gyro's results: the text, JSON and CSV of `run` ([`run`]), the noise table
//! ([`noise`]), the calibration table ([`calibrate`]), the diagnosis report in HTML ([`diagnose`]) and every plot ([`plot`]).
//! Renderers take what the analysis computed and lay it out.

pub mod calibrate;
pub mod diagnose;
pub mod noise;
pub mod plot;
pub mod run;
