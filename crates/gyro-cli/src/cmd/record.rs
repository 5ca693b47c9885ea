//! `gyro-cli record`: read the CRM100 serial bridge into an MCAP (or CSV) log as it comes,
//! with a live status line, every loss counted, and a clean finish on Ctrl-C.

use anyhow::{Context, Result};
use crm100_driver::{serial, Range};
use gyro_bridge::{self as bridge, CsvSink, LiveStatus, McapSink, RecordOptions, RecordSink};
use gyro_log::whole;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;
use std::time::Duration;

#[derive(clap::Args)]
pub struct Args {
    /// Serial port of the bridge (e.g. /dev/ttyACM0, COM3, a pseudo-terminal).
    #[arg(long)]
    port: String,
    /// Baud rate (24-byte frames at 1 kHz need at least 460800).
    #[arg(long, default_value_t = serial::DEFAULT_BAUD, value_parser = clap::value_parser!(u32).range(1..))]
    baud: u32,
    /// Output log: CSV for a `.csv` name (or with --csv), else MCAP. An existing file is
    /// kept unless --force: a recording is not replaced by accident. It is written as
    /// OUT's name with `.partial` before the extension and renamed to OUT when the
    /// recording ends.
    #[arg(short, long)]
    out: PathBuf,
    #[command(flatten)]
    compression: super::output::Compression,
    #[command(flatten)]
    force: super::output::Force,
    /// Stop after this many seconds (default: until Ctrl-C or the port closes).
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    duration: Option<f64>,
    /// Stop when no byte arrived for this many seconds.
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    idle_stop: Option<f64>,
    /// Range the sensor runs in (°/s): 75, 150, 300 or 900; scales the rate word.
    #[arg(long, default_value = "300", value_parser = bridge::parse_range)]
    range: Range,
    /// Nominal frame rate of the bridge (Hz), for the metadata.
    #[arg(long, default_value_t = 1000.0, value_parser = gyro_log::value::positive::<f64>)]
    sample_rate_hz: f64,
    /// Write CSV (time_s, rate_dps, temperature_c, status, sequence, raw) instead of MCAP,
    /// whatever OUT's name (a `.csv` name does without it).
    #[arg(long)]
    csv: bool,
    /// Do not verify the CRM100 response checksum (the rule is assumed, not documented).
    #[arg(long)]
    no_checksum: bool,
    /// Read timeout of the port (ms): how often the status line, flushes and Ctrl-C are
    /// looked at when the line is quiet.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    timeout_ms: u64,
}

fn seconds(value: Option<f64>, name: &str) -> Result<Option<Duration>> {
    value
        .map(|s| {
            Duration::try_from_secs_f64(s)
                .ok()
                .filter(|d| !d.is_zero())
                .with_context(|| format!("--{name} must be a positive number of seconds"))
        })
        .transpose()
}

fn status_line(s: &LiveStatus) -> String {
    let value = |v: Option<f64>, width: usize, unit: &str| {
        v.map_or_else(
            || format!("{:>width$} {unit}", "-"),
            |v| format!("{v:>+width$.2} {unit}"),
        )
    };
    let st = &s.stats;
    format!(
        "{:>7.1} s  rate {}  temp {}  {:>6.0} frames/s  frames {}  lost {}  crc {}  skipped {} B  chk {}  status {}",
        s.elapsed_s,
        value(s.rate_dps, 8, "°/s"),
        value(s.temperature_c, 6, "°C"),
        s.frames_per_s,
        st.frames,
        st.frames_lost,
        st.crc_errors,
        st.bytes_skipped,
        st.checksum_errors,
        st.status_faults,
    )
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    args.force.check([args.out.as_path()], [])?;
    // CSV with --csv or for a `.csv` name (as every command writes by the extension),
    // else MCAP; --csv with a `.mcap` name is a contradiction, refused.
    let by_name = gyro_log::LogFormat::from_extension(&args.out);
    let format = match (args.csv, by_name) {
        (true, Some(gyro_log::LogFormat::Mcap)) => anyhow::bail!(
            "--csv: {} is named .mcap; name it .csv, or leave --csv out for MCAP",
            args.out.display()
        ),
        (true, _) | (false, Some(gyro_log::LogFormat::Csv)) => gyro_log::LogFormat::Csv,
        (false, _) => gyro_log::LogFormat::Mcap,
    };
    let compression = args.compression.for_output(&args.out, format)?;
    let stop = super::stop_flag()?;
    let options = RecordOptions {
        range: args.range,
        verify_checksum: !args.no_checksum,
        sample_rate_hz: args.sample_rate_hz,
        duration: seconds(args.duration, "duration")?,
        idle_stop: seconds(args.idle_stop, "idle-stop")?,
        source: format!("{} at {} Bd", args.port, args.baud),
        compression,
        ..RecordOptions::default()
    };
    let mut reader = serial::open_reader(
        &args.port,
        args.baud,
        Duration::from_millis(args.timeout_ms.max(1)),
    )
    .with_context(|| format!("cannot open {}", args.port))?;
    // Recorded beside OUT, which an earlier recording (--force) keeps until the end.
    let partial = whole::Partial::beside(&args.out)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    let sink: Result<Box<dyn RecordSink>, _> = if format == gyro_log::LogFormat::Csv {
        CsvSink::create(partial.path(), &options).map(|s| Box::new(s) as _)
    } else {
        McapSink::create(partial.path(), &options).map(|s| Box::new(s) as _)
    };
    let sink = match sink {
        Ok(sink) => sink,
        Err(e) => {
            partial.discard();
            return Err(e.into());
        }
    };
    say!(
        "recording {} ({} Bd, range {}) to {}; Ctrl-C to stop",
        args.port,
        args.baud,
        args.range,
        args.out.display()
    );
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr_with_hz(4));
    bar.set_style(
        ProgressStyle::with_template("{msg}").unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let mut show = |s: &LiveStatus| bar.set_message(status_line(s));
    let summary = bridge::record(&mut reader, sink, &options, &stop, &mut show);
    bar.finish_and_clear();
    // A recording that failed part-way (a full disk) keeps what it holds, under its
    // partial name: it is readable, and it replaces nothing.
    let summary = summary
        .with_context(|| format!("the recording so far is in {}", partial.path().display()))?;
    partial
        .finish()
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    say!("{summary}");
    say!("wrote {}", args.out.display());
    Ok(())
}
