//! One module per `gyro-cli` subcommand: its arguments (`Args`) and `run`.

pub mod calibrate;
pub mod convert;
pub mod emulate;
pub mod noise;
pub mod record;
pub mod run;
pub mod simulate;
