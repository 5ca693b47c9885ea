//! Silicon Sensing CRM100 single-axis gyroscope: SPI frame codec and embedded-hal 1.0 driver.
//!
//! Work in progress: the codec and driver land with the driver issue.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
