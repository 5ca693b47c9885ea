//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test file uses a different subset, some only with `std`

use crm100_driver::{
    command_frame, encode_to_array, BridgeFrame, Crm100, Range, Response, Settings, Status,
};
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::spi::{Mock, Transaction};

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

/// Expectations for one CS-framed 6-byte exchange with the default 25 µs CS lead.
pub fn frame(tx: Vec<u8>, rx: Vec<u8>) -> Vec<Transaction<u8>> {
    frame_with_lead(25_000, tx, rx)
}

/// Expectations for one exchange with the given CS lead (0: no delay operation).
pub fn frame_with_lead(lead_ns: u32, tx: Vec<u8>, rx: Vec<u8>) -> Vec<Transaction<u8>> {
    let mut t = vec![Transaction::transaction_start()];
    if lead_ns > 0 {
        t.push(Transaction::delay(lead_ns));
    }
    t.push(Transaction::transfer_in_place(tx, rx));
    t.push(Transaction::transaction_end());
    t
}

/// Concatenates expectation groups.
pub fn script(groups: Vec<Vec<Transaction<u8>>>) -> Vec<Transaction<u8>> {
    groups.into_iter().flatten().collect()
}

/// A driver over a mock expecting `expectations`.
pub fn new_driver(expectations: &[Transaction<u8>], settings: Settings) -> Crm100<Mock<u8>> {
    Crm100::new(Mock::new(expectations), settings)
}

/// Releases the mock and checks every expectation was consumed.
pub fn destroy(driver: Crm100<Mock<u8>>) {
    driver.release().done();
}

/// A stale response for the priming transfer (any bytes; the driver must not look at them).
pub fn stale() -> Vec<u8> {
    vec![0xFF; 6]
}

/// Priming-transfer expectations for a range.
pub fn priming(range: Range) -> Vec<Transaction<u8>> {
    frame(cmd(range.command()), stale())
}

/// An SPI device that fails the transactions whose 0-based index is in `fail_at` (they never
/// reach `inner`), and delegates the others.
pub struct Flaky<S> {
    pub inner: S,
    pub fail_at: Vec<usize>,
    pub count: usize,
}

impl<S> Flaky<S> {
    pub fn new(inner: S, fail_at: Vec<usize>) -> Self {
        Flaky {
            inner,
            fail_at,
            count: 0,
        }
    }
}

impl<S: ErrorType<Error = ErrorKind>> ErrorType for Flaky<S> {
    type Error = ErrorKind;
}

impl<S: SpiDevice<u8, Error = ErrorKind>> SpiDevice<u8> for Flaky<S> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        let index = self.count;
        self.count += 1;
        if self.fail_at.contains(&index) {
            return Err(ErrorKind::Other);
        }
        self.inner.transaction(operations)
    }
}

/// A bridge frame with a valid CRM100 response derived from the sequence number.
pub fn bridge_frame(sequence: u32) -> BridgeFrame {
    let counts = (sequence as i32 % 14_401 - 7_200) as i16;
    BridgeFrame {
        sequence,
        timestamp_us: 1_000 * u64::from(sequence) + 17,
        command: 0x38,
        response: Response {
            status: Status(0),
            rate_counts: counts,
            temperature_word: 600,
        }
        .to_bytes(),
    }
}

/// The 24 wire bytes of a frame.
pub fn wire(frame: &BridgeFrame) -> Vec<u8> {
    encode_to_array(frame).to_vec()
}
