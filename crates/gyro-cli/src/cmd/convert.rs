//! `gyro-cli convert`: a log from one format to another (CSV, MCAP, ROS 2 bag in MCAP),
//! the output's format by its extension, MCAP chunks compressed as `--compression` says.

use anyhow::Result;
use gyro_log as log;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Input log: CSV, MCAP (`/gyro`, `/reference`) or a ROS 2 bag in MCAP.
    input: PathBuf,
    /// Output log, CSV or MCAP by its extension (`.csv`, `.mcap`) unless `--to` says.
    output: PathBuf,
    /// Output format, overriding the extension.
    #[arg(long, value_enum)]
    to: Option<log::LogFormat>,
    #[command(flatten)]
    compression: super::output::Compression,
    #[command(flatten)]
    force: super::output::Force,
    #[command(flatten)]
    input_options: log::LogOptions,
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    args.force
        .check([args.output.as_path()], [args.input.as_path()])?;
    // The format (and so whether --compression applies) is settled before anything is
    // read; a name that is neither .csv nor .mcap is refused by the writer, as before.
    let format = args
        .to
        .or_else(|| log::LogFormat::from_extension(&args.output));
    let compression = match format {
        Some(format) => args.compression.for_output(&args.output, format)?,
        None => log::McapCompression::default(),
    };
    let log = super::read(&args.input, &args.input_options)?;
    // Stamps from a wrapping tick counter are written unwrapped, as every command places
    // them: an MCAP file orders its messages by time, and would put the rows after a wrap
    // before the ones ahead of it.
    let (log, unwrapper) = log::wraps::unwrapped(&log);
    if let Some(what) = log::wraps::describe(&unwrapper) {
        super::warn(&format!(
            "{}: {what}: written unwrapped",
            args.input.display()
        ));
    }
    log::write_log_with(&args.output, &log, format, compression)?;
    let yes_no = |b: bool| if b { "yes" } else { "no" };
    // What was written, and for MCAP how: the compression the file has.
    let how = match format {
        Some(log::LogFormat::Mcap) => match compression {
            log::McapCompression::None => ", uncompressed chunks".to_string(),
            other => format!(", {other} chunks"),
        },
        _ => String::new(),
    };
    say!(
        "{} -> {}: {} rows, reference: {}, temperature: {}{how}",
        args.input.display(),
        args.output.display(),
        log.rows.len(),
        yes_no(log.has_reference),
        yes_no(log.has_temperature)
    );
    Ok(())
}
