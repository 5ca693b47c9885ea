//! Host side of gyro: log reading, replay through the `gyro-core` pipeline, reports.
