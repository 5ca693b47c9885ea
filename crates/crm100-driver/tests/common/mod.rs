//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use crm100_driver::{command_frame, Response, Status};

/// The master frame for a command byte, as a Vec for the mock.
pub fn cmd(command: u8) -> Vec<u8> {
    command_frame(command).to_vec()
}

/// A valid response frame.
pub fn response(status: u8, rate_counts: i16, temperature_word: u16) -> Vec<u8> {
    Response {
        status: Status(status),
        rate_counts,
        temperature_word,
    }
    .to_bytes()
    .to_vec()
}
