//! The bridge reader over a real pseudo-terminal pair, opened by name like a serial port.
#![allow(clippy::unwrap_used)]

use crate::common::{bridge_frame, wire};
use crm100_driver::serial::{
    self,
    serialport::{SerialPort, TTYPort},
};
use crm100_driver::ReadEvent;
use std::io::Write;
use std::time::Duration;

#[test]
fn frames_written_to_a_pty_master_are_read_from_the_slave_by_name() {
    let (mut master, slave) = TTYPort::pair().unwrap();
    let name = slave.name().unwrap();
    let mut reader = serial::open_reader(&name, 921_600, Duration::from_millis(50)).unwrap();
    let mut bytes = Vec::new();
    for seq in 0..200_u32 {
        if seq != 50 {
            bytes.extend(wire(&bridge_frame(seq)));
        }
    }
    let writer = std::thread::spawn(move || {
        master.write_all(&bytes).unwrap();
        master
    });
    let mut frames = 0;
    let mut timeouts = 0;
    while frames < 199 && timeouts < 40 {
        match reader.next_event().unwrap() {
            Some(ReadEvent::Frame(_)) => frames += 1,
            Some(ReadEvent::Timeout) => timeouts += 1,
            Some(other) => panic!("unexpected {other:?}"),
            None => break,
        }
    }
    let _master = writer.join().unwrap();
    assert_eq!(frames, 199);
    assert_eq!(reader.stats().receiver.sequence.frames_lost, 1);
    drop(slave);
}
