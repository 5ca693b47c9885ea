//! `gyro-cli emulate`: play a log (or a simulated run) as a CRM100 serial bridge on a port,
//! with seeded, counted faults.

use anyhow::{bail, Context, Result};
use crm100_driver::serial::{self, serialport};
use crm100_driver::Range;
use gyro_bridge::{self as bridge, Emulator, EmulatorConfig, FaultSpec, Pacing, Sample};
use gyro_log as log;
use gyro_sim::SensorModel;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

#[derive(clap::Args)]
pub struct Args {
    /// Port to write the bridge bytes to (one end of a pseudo-terminal pair, a serial
    /// port); see also --create-pty.
    #[arg(
        long,
        required_unless_present = "create_pty",
        conflicts_with = "create_pty"
    )]
    port: Option<String>,
    /// Create a pseudo-terminal pair, print the name to record from, and write to it.
    #[arg(long)]
    create_pty: bool,
    /// Baud rate when --port is a real serial port.
    #[arg(long, default_value_t = serial::DEFAULT_BAUD, value_parser = clap::value_parser!(u32).range(1..))]
    baud: u32,
    /// Log (CSV or MCAP) whose rate and temperature are played.
    #[arg(long, conflicts_with_all = ["seed", "duration_s"])]
    log: Option<PathBuf>,
    /// Simulate a bench run with this seed instead of playing a log.
    #[arg(long)]
    seed: Option<u64>,
    /// Duration of the simulated run (s).
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    duration_s: Option<f64>,
    /// Range (°/s) whose LSB scales the rate word: 75, 150, 300 or 900.
    #[arg(long, default_value = "300", value_parser = bridge::parse_range)]
    range: Range,
    /// Frame rate (Hz). Simulated runs: default 1000. Logs: default the log's own times.
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    rate_hz: Option<f64>,
    /// Send each frame at its time (default).
    #[arg(long, conflicts_with = "as_fast_as_possible")]
    realtime: bool,
    /// Send as fast as the reader takes the bytes.
    #[arg(long)]
    as_fast_as_possible: bool,
    /// Faults: `none`, `typical`, or `key=value,...` with keys drop, byte_loss, bit_flip,
    /// checksum, status, stall (probabilities per frame), stall_ms, seed; e.g.
    /// `typical,seed=7` or `drop=1e-3,bit_flip=5e-4`.
    #[arg(long, default_value = "none", value_parser = FaultSpec::parse)]
    faults: FaultSpec,
    /// Give up when the port takes no byte for this many seconds (nobody reading it): at
    /// 1 kHz the bridge sends 6 kB a second, so a reader away this long has lost its data.
    #[arg(long, default_value_t = 5.0, value_parser = gyro_log::value::positive::<f64>)]
    write_timeout_s: f64,
    /// Write the fault log (the report, with every lost sequence number) as JSON here.
    #[arg(long)]
    fault_log: Option<PathBuf>,
    #[command(flatten)]
    force: super::output::Force,
}

fn samples(args: &Args) -> Result<(Vec<Sample>, String)> {
    if let Some(path) = &args.log {
        let log = super::read(path, &log::LogOptions::default())?;
        let samples = log.rows.iter().map(Sample::from).collect();
        return Ok((samples, format!("log {}", path.display())));
    }
    let seed = args.seed.unwrap_or(1);
    let duration_s = args.duration_s.unwrap_or(60.0);
    if !(duration_s > 0.0 && duration_s <= 86_400.0) {
        bail!("--duration-s must be in (0, 86400]");
    }
    let range = args.range;
    let sensor = SensorModel {
        sample_rate_hz: args.rate_hz.unwrap_or(1000.0),
        lsb_dps: 1.0 / f64::from(range.lsb_per_dps()),
        range_dps: f64::from(range.full_scale_dps()),
        ..SensorModel::default()
    };
    sensor.validate()?;
    let samples = bridge::simulated_samples(&sensor, duration_s, seed)
        .context("the simulated run (--duration-s, --rate-hz)")?;
    Ok((
        samples,
        format!("simulated run, seed {seed}, {duration_s} s"),
    ))
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    args.force
        .check(args.fault_log.as_deref(), args.log.as_deref())?;
    if let Some(rate) = args.rate_hz {
        if !(rate > 0.0 && rate <= 1e6) {
            bail!("--rate-hz must be in (0, 1e6]");
        }
    }
    let (samples, what) = samples(args)?;
    let stop = super::stop_flag()?;
    // Keep the pair's other end open while writing, so the reader can come and go.
    let mut _pty_slave = None;
    let mut port: Box<dyn serialport::SerialPort> = match &args.port {
        Some(name) => serial::open(name, args.baud, Duration::from_millis(100))
            .with_context(|| format!("cannot open {name}"))?,
        None => open_pty(&mut _pty_slave)?,
    };
    let config = EmulatorConfig {
        range: args.range,
        rate_hz: args.rate_hz,
        faults: args.faults,
        ..EmulatorConfig::default()
    };
    let pacing = if args.as_fast_as_possible {
        Pacing::AsFastAsPossible
    } else {
        Pacing::RealTime
    };
    say!(
        "emulating a CRM100 bridge: {} samples from the {what}, range {}, {}; a port that takes no byte for {} s (nobody reading it) is an error (--write-timeout-s)",
        samples.len(),
        args.range,
        match pacing {
            Pacing::RealTime => "each frame at its time stamp, as a bridge sends it",
            Pacing::AsFastAsPossible => "as fast as the receiver takes the bytes",
        },
        args.write_timeout_s
    );
    let mut emulator = Emulator::new(samples.into_iter(), config);
    let write_timeout = Duration::try_from_secs_f64(args.write_timeout_s).ok();
    let port_name = args.port.as_deref().unwrap_or("the pseudo-terminal");
    let report = bridge::stream(
        &mut emulator,
        &mut *port,
        pacing,
        Some(&stop),
        None,
        write_timeout,
    )
    .with_context(|| format!("writing to {port_name} failed (--write-timeout-s)"))?;
    // Closing the port hangs the line up, and a pseudo-terminal then discards what the
    // reader has not read yet: wait until it has.
    let unread = drain(&mut *port, _pty_slave.as_ref(), &stop);
    if unread > 0 {
        say!("warning: {unread} bytes were still unread when the port was closed");
    }
    say_sent(&report, emulator.source_gaps());
    if let Some(path) = &args.fault_log {
        super::output::write(path, |out| {
            serde_json::to_writer_pretty(&mut *out, &report)?;
            writeln!(out)
        })?;
    }
    Ok(())
}

/// Say what was sent: frames, time, bytes, and each fault counted.
fn say_sent(report: &bridge::EmulatorReport, source_gaps: u64) {
    say!(
        "sent {} frames in {:.1} s ({} bytes){}: intact {}, dropped {}, byte loss {}, bit flips {}, bad checksums {}, status faults {}, stalls {} ({} ms), clipped {}, source gaps {}",
        report.frames,
        report.elapsed_s,
        report.bytes,
        if report.stopped { " (interrupted)" } else { "" },
        report.intact,
        report.dropped,
        report.byte_loss,
        report.bit_flips,
        report.bad_checksums,
        report.status_faults,
        report.stalls,
        report.stall_ms,
        report.clipped,
        source_gaps,
    );
}

/// Waits until the bytes written are read (a pseudo-terminal's other end: its input
/// queue; a serial port: the output queue), giving up after 5 s without progress or on
/// `stop`. Returns the bytes still unread.
fn drain(
    port: &mut dyn serialport::SerialPort,
    pty_slave: Option<&PtySlave>,
    stop: &AtomicBool,
) -> u64 {
    // Bytes still on their way: in the reader's input queue and, for a pseudo-terminal,
    // still in the master's output queue (moved to the slave in chunks).
    let pending = |port: &mut dyn serialport::SerialPort| match pty_slave {
        Some(slave) => pty_unread(slave)
            .map(u64::from)
            .unwrap_or(0)
            .saturating_add(port.bytes_to_write().map_or(0, u64::from)),
        None => port.bytes_to_write().map_or(0, u64::from),
    };
    // Done when nothing has been pending for QUIET consecutive polls (a momentarily
    // empty slave queue can still be refilled from the master).
    const QUIET: u32 = 10;
    let mut last = pending(port);
    let mut since = std::time::Instant::now();
    let mut quiet = 0;
    while quiet < QUIET && !stop.load(std::sync::atomic::Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(20));
        let now = pending(port);
        if now == 0 {
            quiet += 1;
        } else {
            quiet = 0;
        }
        if now < last {
            since = std::time::Instant::now();
        } else if now > 0 && since.elapsed() > Duration::from_secs(5) {
            return now;
        }
        last = now;
    }
    last
}

#[cfg(unix)]
type PtySlave = serialport::TTYPort;
#[cfg(not(unix))]
type PtySlave = ();

#[cfg(unix)]
fn pty_unread(slave: &PtySlave) -> serialport::Result<u32> {
    use serialport::SerialPort;
    slave.bytes_to_read()
}

#[cfg(not(unix))]
fn pty_unread(_slave: &PtySlave) -> serialport::Result<u32> {
    Ok(0)
}

#[cfg(unix)]
fn open_pty(keep: &mut Option<PtySlave>) -> Result<Box<dyn serialport::SerialPort>> {
    use serialport::SerialPort;
    let (master, slave) =
        serialport::TTYPort::pair().context("cannot create a pseudo-terminal pair")?;
    let name = slave.name().context("the pseudo-terminal has no name")?;
    super::to_stdout(|out| writeln!(out, "{name}"))?;
    say!("record from {name}, e.g.: gyro-cli record --port {name} -o run.mcap");
    *keep = Some(slave);
    Ok(Box::new(master))
}

#[cfg(not(unix))]
fn open_pty(_keep: &mut Option<PtySlave>) -> Result<Box<dyn serialport::SerialPort>> {
    bail!("--create-pty needs a Unix pseudo-terminal; pass --port")
}
