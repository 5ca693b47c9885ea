//! `gyro-cli`: replay gyro logs through the core pipeline.
fn main() {}
