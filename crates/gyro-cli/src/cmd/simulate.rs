//! `gyro-cli simulate`: the sensor simulator, writing a log (CSV or MCAP by the output's
//! extension) of bench-like motion, of the motion in a log's reference, or at rest.

use anyhow::{Context, Result};
use gyro_analysis::model;
use gyro_log as log;
use gyro_log::value;
use gyro_sim::{self as sim, BenchProfile, Effect, Motion, SensorModel, SimOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Output log: MCAP for a `.mcap` name, else CSV (`time_s, rate_dps, temperature_c,
    /// reference_deg`).
    #[arg(short, long, required_unless_present = "list_effects")]
    out: Option<PathBuf>,
    /// Model file whose `sensor` section gives the nominal model; default: a CRM100
    /// in the ±300 °/s range.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Seed of all random streams (same seed, same log).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Duration of the generated bench-like motion, or of the rest with --static (s).
    #[arg(long, default_value_t = 90.0, value_parser = value::positive::<f64>)]
    duration_s: f64,
    /// No motion: the sensor at rest for --duration-s, the reference at 0 throughout, the
    /// sensor model and any --effect applied as in motion. A static log for `noise`
    /// (e.g. `--static --duration-s 3600`).
    #[arg(long = "static", conflicts_with = "motion_from")]
    at_rest: bool,
    /// Re-simulate the motion of this log's `reference_deg` instead of generating motion
    /// (as `diagnose` re-simulates a run: smoothed over 20 ms when the reference is an
    /// encoder's, the rate through a quintic smoothing when it is printed with few decimals,
    /// one-sided beside a step of the acceleration).
    #[arg(long)]
    motion_from: Option<PathBuf>,
    /// Add an effect: `id` or `id:name=value,...` (e.g. `scale_factor:k=0.01`); repeatable.
    /// `--list-effects` shows them.
    #[arg(long = "effect")]
    effects: Vec<String>,
    /// List the effects, their parameters and signatures, and exit.
    #[arg(long)]
    list_effects: bool,
    /// Sample rate (Hz), overriding the model's.
    #[arg(long, value_parser = value::positive::<f64>)]
    sample_rate_hz: Option<f64>,
    /// Temperature rise during the run (°C, warm-up with a 120 s time constant), from
    /// -125 to 125 (a MEMS gyro's operating range, -40 to 85 °C, spans 125 °C).
    #[arg(long, default_value_t = 5.0,
          value_parser = value::within(-125.0, 125.0, "°C: a MEMS gyro's operating range, -40 to 85 °C, spans 125"))]
    temperature_rise_c: f64,
    #[command(flatten)]
    compression: super::output::Compression,
    #[command(flatten)]
    force: super::output::Force,
    /// Quantise the reference like an encoder with this many counts per revolution.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    encoder_counts: Option<u32>,
}

fn list_effects(out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(out, "{:<18} {:<36} signature", "id", "parameters (typical)")?;
    for info in sim::EFFECTS {
        let params: Vec<String> = info
            .params
            .iter()
            .zip(info.typical.params())
            .map(|(spec, v)| format!("{}={v} {}", spec.name, spec.unit))
            .collect();
        writeln!(
            out,
            "{:<18} {:<36} {}",
            info.id,
            params.join(", "),
            info.signature
        )?;
        let range: Vec<String> = info
            .range
            .iter()
            .map(|e| {
                e.spec()
                    .trim_start_matches(info.id)
                    .trim_start_matches(':')
                    .to_string()
            })
            .collect();
        writeln!(
            out,
            "{:<18} realistic range (the self-check's matrix): {}; {}",
            "",
            range.join(" | "),
            info.range_source
        )?;
    }
    Ok(())
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    args.force.check(
        args.out.as_deref(),
        args.motion_from
            .as_deref()
            .into_iter()
            .chain(args.model.as_deref()),
    )?;
    if args.list_effects {
        super::to_stdout(|out| list_effects(out))?;
        return Ok(());
    }
    let Some(out) = &args.out else {
        anyhow::bail!("--out is required");
    };
    // MCAP for a `.mcap` name, else CSV (the format the command always wrote).
    let format = log::LogFormat::from_extension(out).unwrap_or(log::LogFormat::Csv);
    let compression = args.compression.for_output(out, format)?;
    let sensor = sensor_model(args)?;
    let effects = args
        .effects
        .iter()
        .map(|spec| Effect::parse(spec).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    let motion = match &args.motion_from {
        Some(path) => motion_from_log(path)?,
        None => generated_motion(args)?,
    };
    let options = SimOptions {
        seed: args.seed,
        temperature_rise_c: args.temperature_rise_c,
        encoder_counts: args.encoder_counts,
        ..SimOptions::default()
    };
    sim::check_size(&sensor, &motion).with_context(|| match &args.motion_from {
        Some(path) => format!(
            "{}: cannot simulate its motion at the sensor's rate (--sample-rate-hz)",
            path.display()
        ),
        None => "cannot simulate the run (--duration-s, --sample-rate-hz)".into(),
    })?;
    let log = sim::simulate(&sensor, &effects, &motion, &options);
    log::write_log_with(out, &log, Some(format), compression)?;
    say_written(args, out, &log, &motion, &sensor, &effects);
    Ok(())
}

/// The sensor model: the model file's (or the default), at `--sample-rate-hz` if given,
/// checked.
fn sensor_model(args: &Args) -> Result<SensorModel> {
    let mut sensor = match &args.model {
        Some(path) => model::load(path)?.sensor,
        None => SensorModel::default(),
    };
    if let Some(rate) = args.sample_rate_hz {
        sensor.sample_rate_hz = rate;
    }
    sensor.validate()?;
    Ok(sensor)
}

/// `--motion-from`: the motion of the log's reference angle, as `diagnose` takes it.
fn motion_from_log(path: &Path) -> Result<Motion> {
    let regular = super::load(
        path,
        &log::LogOptions::default(),
        &log::GridOptions::default(),
    )?;
    // What was read of it, as every command that reads a log shows it.
    say_part!(
        "{}",
        gyro_report::input::tables([(path.display().to_string().as_str(), &regular.quality)])
    );
    if !regular.has_reference {
        anyhow::bail!(
            "{}: no reference_deg column to take the motion from",
            path.display()
        );
    }
    let reference: Vec<f64> = regular
        .slots
        .iter()
        .map(|s| s.reference_deg)
        .collect::<Option<Vec<_>>>()
        .with_context(|| {
            format!(
                "{}: the reference has gaps longer than 0.5 s",
                path.display()
            )
        })?;
    // A log of a row or two gives a motion of no length: said, as `run` says it
    // of such a log (finding `short_log`), not written as if it were a run.
    let span_s = reference.len().saturating_sub(1) as f64 / regular.sample_rate_hz;
    if span_s < gyro_analysis::findings::SHORT_LOG_S {
        super::warn(&format!(
            "{}: its reference spans {span_s:.3} s ({} samples), under {} s: the simulated log is as short, too short for any figure; give a log of at least a few seconds",
            path.display(),
            reference.len(),
            gyro_analysis::findings::SHORT_LOG_S
        ));
    }
    // As `diagnose` re-simulates a run: smoothed when the reference is an
    // encoder's, one-sided beside a step of the acceleration.
    Ok(gyro_diagnose::motion_from_reference(&reference, regular.sample_rate_hz).0)
}

/// The motion made up for `--duration-s`: at rest with `--static`, else bench-like.
fn generated_motion(args: &Args) -> Result<Motion> {
    if !(args.duration_s > 0.0 && args.duration_s <= 86_400.0) {
        anyhow::bail!("--duration-s must be in (0, 86400]");
    }
    Ok(if args.at_rest {
        // No rotation at all: the angle and the rate are 0 throughout.
        Motion::from_rotations(Vec::new(), args.duration_s)
    } else {
        Motion::bench(
            &BenchProfile {
                duration_s: args.duration_s,
                ..BenchProfile::default()
            },
            args.seed,
        )
    })
}

/// Say what was written to `out`: samples, duration, rate, motion and effects.
fn say_written(
    args: &Args,
    out: &Path,
    log: &log::Log,
    motion: &Motion,
    sensor: &SensorModel,
    effects: &[Effect],
) {
    say!(
        "wrote {} samples ({:.1} s at {} Hz, {}, effects: {}) to {}",
        log.rows.len(),
        motion.duration_s(),
        sensor.sample_rate_hz,
        if args.at_rest {
            "at rest".to_string()
        } else {
            match motion.rotations().len() {
                1 => "1 rotation".to_string(),
                n => format!("{n} rotations"),
            }
        },
        if effects.is_empty() {
            "none".to_string()
        } else {
            effects
                .iter()
                .map(Effect::id)
                .collect::<Vec<_>>()
                .join(", ")
        },
        out.display()
    );
}
