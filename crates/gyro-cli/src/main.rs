//! `gyro-cli`: rotation angle from a single-axis gyro; replay, simulate, calibrate, diagnose.

/// `eprintln!` that ignores a stderr that cannot be written (`2>/dev/full`, a closed
/// descriptor): a message that cannot be shown must not turn into a panic (exit 101).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

/// `eprint!` that ignores a stderr that cannot be written, as `say!`.
macro_rules! say_part {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stderr().lock(), $($arg)*);
    }};
}

mod cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "gyro-cli",
    version,
    about = "Rotation angle from a single-axis gyro: replay, simulate, calibrate, diagnose"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Replay a log through the pipeline: angles, movements, errors against the reference.
    Run(cmd::run::Args),
    /// Fit the error model on bench runs with an encoder reference; write a model file.
    Calibrate(cmd::calibrate::Args),
    /// Simulate a sensor log (CSV, or MCAP for a `.mcap` name): the nominal model plus
    /// effects, on bench-like motion, a log's recorded motion, or at rest (--static).
    Simulate(cmd::simulate::Args),
    /// Noise characterisation of static logs: Allan deviation with bounds, fitted noise
    /// terms (ARW, bias instability, rate random walk, Gauss-Markov), Welch PSD.
    Noise(cmd::noise::Args),
    /// Sim-to-real diagnosis: where real runs differ from their simulation, which
    /// unmodelled effect causes it, how far adding it closes the gap on held-out runs.
    Diagnose(cmd::diagnose::Args),
    /// Convert a log between CSV and MCAP (also from a ROS 2 bag in MCAP): the output's
    /// format by its extension, MCAP chunks compressed with zstd unless --compression.
    Convert(cmd::convert::Args),
    /// Record the CRM100 serial bridge to MCAP (or CSV, for a `.csv` name) as it comes:
    /// every loss counted, a live status line, a clean finish on Ctrl-C.
    Record(cmd::record::Args),
    /// Play a log or a simulated run as a CRM100 serial bridge on a port, with seeded
    /// faults (byte loss, bit flips, bad checksums, status faults, dropped frames, stalls).
    Emulate(cmd::emulate::Args),
}

fn main() -> ExitCode {
    let cli = parse();
    let result = match &cli.command {
        Command::Run(args) => cmd::run::run(args),
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Calibrate(args) => cmd::calibrate::run(args),
        Command::Noise(args) => cmd::noise::run(args),
        Command::Diagnose(args) => cmd::diagnose::run(args),
        Command::Convert(args) => cmd::convert::run(args),
        Command::Record(args) => cmd::record::run(args),
        Command::Emulate(args) => cmd::emulate::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped reading (`| head`) is not an error: end quietly.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let hint = flag_hint(&e).unwrap_or_default();
            say!("error: {}{hint}", one_line(&format!("{e:#}")));
            ExitCode::FAILURE
        }
    }
}

/// The command line, parsed. Every subcommand takes a negative number after a flag as its
/// value (`--sample-rate-hz -1000`), for the option's value parser to judge ("expected a
/// positive finite number, got `-1000`"), not as an unknown argument `-1`.
fn parse() -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    let mut command = Cli::command();
    let names: Vec<String> = command
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        command = command.mut_subcommand(name, |s| s.allow_negative_numbers(true));
    }
    let matches = command.get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

/// True if the error comes from writing to a pipe whose reader has gone.
fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// The option that settles a library error, named as this command line spells it (the
/// libraries name no flags), to append to its message.
fn flag_hint(error: &anyhow::Error) -> Option<String> {
    use gyro_log::LogError;
    let error = error
        .chain()
        .find_map(|cause| cause.downcast_ref::<LogError>())?;
    if let LogError::NotApplicable { setting, .. } = error {
        // The settings are the options' field names: `reference_column` is given as
        // --reference-column.
        return Some(format!(" (--{})", setting.replace('_', "-")));
    }
    match error {
        LogError::SampleRateInvalid { .. } => Some(" (--sample-rate-hz)"),
        LogError::SampleRateUnknown { .. } => Some(" with --sample-rate-hz"),
        LogError::SampleRateDisagrees { .. } => {
            Some(" (fix --sample-rate-hz or the metadata, or leave it out)")
        }
        LogError::Gap { .. } | LogError::MaxGapInvalid { .. } => Some(" (--max-gap-s)"),
        LogError::McapSecondRate { .. } => Some(" with --topic"),
        LogError::McapZeroStamp { .. } => Some(": --time-source log-time"),
        _ => None,
    }
    .map(str::to_string)
}

/// An error message on one line (a cause that spans lines is joined with "; ").
fn one_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}
