//! One module per `gyro-cli` subcommand: its arguments (`Args`) and `run`.

pub mod convert;
pub mod run;
pub mod simulate;
