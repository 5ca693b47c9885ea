//! The gyro's lag behind the reference that `run` measures on real recordings
//! (../shared/data/real beside the workspace, when present): the MPU6050's lag behind the
//! ssong encoder (the 11-13 ms `diagnose` names as latency) and the rasteiro rows stamped
//! on arrival at a PC, 80-120 ms behind the robot's pose.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::real_log;
use gyro_analysis::replay::replay;
use gyro_core::Config;
use gyro_log::GridOptions;

fn lag_s(relative: &str) -> Option<Option<f64>> {
    let log = real_log(relative, &GridOptions::default())?;
    Some(
        replay(&log, &Config::default())
            .unwrap()
            .summary
            .reference_lag_s,
    )
}

#[test]
fn the_encoder_lag_and_the_logger_lag() {
    if let Some(lag) = lag_s("ssong_z_slow.csv") {
        let lag = lag.unwrap();
        assert!((0.010..0.015).contains(&lag), "ssong z slow: {lag}");
    }
    for file in [
        "rasteiro/rasteiro_MPU6050RM3100_V_300_x.csv",
        "rasteiro/rasteiro_MPU6500RM3100_V1500_y.csv",
    ] {
        if let Some(lag) = lag_s(file) {
            let lag = lag.unwrap();
            assert!((0.08..0.125).contains(&lag), "{file}: {lag}");
        }
    }
}
