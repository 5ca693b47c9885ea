//! `gyro-cli record` as a process, fed in real time through a pseudo-terminal pair: killed
//! with SIGKILL it leaves a file whose data reads back to within the last second;
//! interrupted with SIGINT it finishes the file and prints a summary. And `gyro-cli
//! emulate --create-pty` feeding `gyro-cli record`.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;

use crm100_driver::serial::serialport::{SerialPort, TTYPort};
use gyro_bridge::{self as bridge, Emulator, EmulatorConfig, Pacing, Sample};
use gyro_log::{self as log, McapOptions};
use std::ffi::OsStr;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_gyro-cli");

/// A fresh folder for one test, named after it; removed with everything in it when the
/// returned guard is dropped, so that test runs leave nothing in the temporary folder.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gyro-record-cli-{name}-"))
        .tempdir()
        .unwrap()
}

/// A real-time 1 kHz emulator on a fresh pty pair: the slave's name, the frames sent so
/// far, the stop flag and the thread (which returns both ends, kept open till joined).
struct Bridge {
    name: String,
    sent: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    thread: JoinHandle<(TTYPort, TTYPort)>,
}

fn start_bridge(seconds: usize) -> Bridge {
    let (mut master, slave) = TTYPort::pair().unwrap();
    let name = slave.name().unwrap();
    let sent = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let (sent2, stop2) = (Arc::clone(&sent), Arc::clone(&stop));
    let thread = std::thread::spawn(move || {
        let samples = (0..seconds * 1000).map(|i| Sample {
            time_s: i as f64 * 1e-3,
            rate_dps: Some((i as f64 * 1e-3).sin() * 100.0),
            temperature_c: Some(30.0),
        });
        let emulator = Emulator::new(samples, EmulatorConfig::default());
        bridge::stream(
            emulator,
            &mut master,
            Pacing::RealTime,
            Some(&stop2),
            Some(&sent2),
            None,
        )
        .unwrap();
        (master, slave)
    });
    Bridge {
        name,
        sent,
        stop,
        thread,
    }
}

fn spawn_record(port: &str, out: &Path) -> Child {
    Command::new(BIN)
        .args(["record", "--port", port, "-o"])
        .arg(out)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn wait_for_file(path: &Path) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "record never created its file"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Rows are the emulator's frames 0, 1, 2, ... in order (no faults injected here).
fn assert_prefix(rows: &[log::Row]) {
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row.time_s, i as f64 / 1000.0, "row {i}");
        let expected = (i as f64 * 1e-3).sin() * 100.0;
        assert!(
            (row.rate_dps.unwrap() - expected).abs() <= 1.0 / 24.0,
            "row {i}"
        );
    }
}

/// A recording killed part-way is left under its partial name (`killed.partial.mcap` for
/// `-o killed.mcap`): readable up to the kill, and never mistaken for a finished one.
#[test]
fn sigkill_loses_under_half_a_second() {
    let scratch = temp_dir("kill");
    let dir = scratch.path();
    let finished = dir.join("killed.mcap");
    let out = dir.join("killed.partial.mcap");
    let bridge = start_bridge(60);
    let mut child = spawn_record(&bridge.name, &finished);
    wait_for_file(&out);
    std::thread::sleep(Duration::from_millis(3500));
    child.kill().unwrap(); // SIGKILL
    let sent_at_kill = bridge.sent.load(Ordering::Relaxed);
    child.wait().unwrap();
    bridge.stop.store(true, Ordering::Relaxed);
    let _ports = bridge.thread.join().unwrap();
    assert!(!finished.exists());

    let read = log::read_mcap(&out, &McapOptions::default()).unwrap();
    let rows = read.log.rows.len() as u64;
    eprintln!(
        "SIGKILL after {sent_at_kill} frames sent: {rows} rows read back ({} ms lost); warnings: {:?}",
        sent_at_kill - rows,
        read.warnings
    );
    assert!(!read.warnings.is_empty(), "an unfinished file is reported");
    assert!(rows <= sent_at_kill);
    assert!(
        rows + 500 >= sent_at_kill,
        "only {rows} of {sent_at_kill} frames survived the kill"
    );
    assert!(rows >= 2000, "{rows}");
    assert_prefix(&read.log.rows);
    assert_eq!(read.log.metadata_rate_hz(), Some(1000.0));
    assert!(
        read.warnings[0].contains("read up to byte"),
        "{:?}",
        read.warnings
    );

    // Recovery (README): `convert` writes a finished copy of everything before the damage.
    let recovered = &finished;
    let status = Command::new(BIN)
        .arg("convert")
        .args([&out, recovered])
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let bytes = std::fs::read(recovered).unwrap();
    assert!(
        mcap::Summary::read(&bytes).unwrap().is_some(),
        "indexed readers open it"
    );
    let again = log::read_mcap(recovered, &McapOptions::default()).unwrap();
    assert!(again.warnings.is_empty());
    assert_eq!(again.log.rows.len(), read.log.rows.len());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn sigint_finishes_the_file_and_prints_a_summary() {
    let scratch = temp_dir("int");
    let dir = scratch.path();
    let out = dir.join("interrupted.mcap");
    let bridge = start_bridge(60);
    let child = spawn_record(&bridge.name, &out);
    wait_for_file(&dir.join("interrupted.partial.mcap"));
    std::thread::sleep(Duration::from_millis(2500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let sent_at_signal = bridge.sent.load(Ordering::Relaxed);
    let output = child.wait_with_output().unwrap();
    bridge.stop.store(true, Ordering::Relaxed);
    let _ports = bridge.thread.join().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{stderr}");
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("stopped: interrupted"), "{stderr}");
    assert!(stderr.contains("lost 0 in 0 gaps"), "{stderr}");
    assert!(stderr.contains("CRC errors 0"), "{stderr}");
    assert!(!dir.join("interrupted.partial.mcap").exists());

    let bytes = std::fs::read(&out).unwrap();
    assert!(bytes.ends_with(log::mcap::MAGIC), "finished with a footer");
    assert!(mcap::Summary::read(&bytes).unwrap().is_some());
    let read = log::read_mcap(&out, &McapOptions::default()).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    let rows = read.log.rows.len() as u64;
    assert!(
        rows + 1000 >= sent_at_signal && rows >= 1500,
        "{rows} of {sent_at_signal}"
    );
    assert!(stderr.contains(&format!("frames {rows} ")), "{stderr}");
    assert_prefix(&read.log.rows);
    std::fs::remove_dir_all(dir).unwrap();
}

/// The two subcommands together, as a user would run them: `emulate --create-pty` prints
/// the port, `record` reads it until the line goes quiet; the counts match the fault log.
#[test]
fn emulate_and_record_commands_agree() {
    let scratch = temp_dir("cli");
    let dir = scratch.path();
    let out = dir.join("cli.mcap");
    let fault_log = dir.join("faults.json");
    let args = [
        "--seed",
        "5",
        "--duration-s",
        "10",
        "--as-fast-as-possible",
        "--faults",
        "typical,stall=0,seed=3",
        "--fault-log",
    ];
    let mut args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    args.push(fault_log.as_os_str());
    let (emulated, record) = common::emulate_into_record(&args, &out);
    let stderr = String::from_utf8_lossy(&record.stderr);
    assert!(record.status.success(), "{stderr}");
    assert!(emulated.status.success());
    let faults: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&fault_log).unwrap()).unwrap();
    let lost = faults["lost_sequences"].as_array().unwrap().len();
    let intact = faults["intact"].as_u64().unwrap();
    eprintln!("{stderr}");
    assert!(lost > 0);
    assert!(
        stderr.contains(&format!("frames {intact} ")),
        "{intact} intact: {stderr}"
    );
    assert!(
        stderr.contains(&format!("lost {lost} in")),
        "{lost} lost: {stderr}"
    );
    let read = log::read_mcap(&out, &McapOptions::default()).unwrap();
    assert_eq!(read.log.rows.len() as u64, intact);
    std::fs::remove_dir_all(dir).unwrap();
}
