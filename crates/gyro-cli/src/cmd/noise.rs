//! `gyro-cli noise`: Allan deviation / PSD characterisation of static logs.

use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use gyro_analysis::model;
use gyro_analysis::noise::{self, NoiseLog, NoiseOptions, PsdOptions, TauGrid};
use gyro_log as log;
use gyro_log::value;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Human-readable.
    Table,
    /// JSON.
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Grid {
    /// About `--per-decade` factors per decade (allantools "log10"-like).
    Log,
    /// 1, 2, 4, 8, ... (allantools "octave").
    Octave,
    /// 1, 2, 4, 10, 20, 40, ... (allantools "decade").
    Decade,
}

#[derive(clap::Args)]
pub struct Args {
    /// Static logs, CSV (`time_s,rate_dps,...`) or MCAP, e.g. from `simulate --static`.
    /// Several: each, then all pooled.
    #[arg(required = true)]
    logs: Vec<PathBuf>,
    /// Output format on stdout.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write a model file whose `sensor` section comes from the fit (of all logs pooled
    /// if several): ARW, Gauss-Markov σ/T, bias = mean rate, output step.
    #[arg(long)]
    model_out: Option<PathBuf>,
    /// Keep only the rest stretches found by the gyro-core motion detector (default: the
    /// logs are taken whole, as static).
    #[arg(long)]
    static_only: bool,
    /// With --static-only: margin cut on both sides of each movement (s).
    #[arg(long, default_value_t = 0.5, value_parser = value::non_negative::<f64>)]
    margin_s: f64,
    /// With --static-only: shortest rest stretch kept (s).
    #[arg(long, default_value_t = 1.0, value_parser = value::non_negative::<f64>)]
    min_rest_s: f64,
    /// Model file: its pipeline configuration drives --static-only's motion detector, and
    /// --model-out starts from it (its sensor section replaced, its range kept).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Averaging times: log-spaced, octaves or decades of the sample period, up to a
    /// quarter of the longest stretch.
    #[arg(long, value_enum, default_value_t = Grid::Log)]
    tau_grid: Grid,
    /// Averaging times per decade with `--tau-grid log`.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
    per_decade: u32,
    /// Confidence of the Allan bounds (default 1σ).
    #[arg(long, default_value_t = noise::ONE_SIGMA, value_parser = value::positive::<f64>)]
    confidence: f64,
    /// Welch segment length (a power of two); default: a quarter of the longest stretch,
    /// 16 to 16384.
    #[arg(long)]
    psd_segment: Option<usize>,
    /// Write the full PSD as CSV (`log,frequency_hz,psd_dps2_per_hz`) here.
    #[arg(long)]
    psd_out: Option<PathBuf>,
    /// Plot the Allan deviation with bounds, the fitted model and its terms, and the PSD
    /// to this file: .svg or .png (of all logs pooled, if several).
    #[arg(long, value_parser = gyro_report::plot::parse_plot_path)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    noise_yaml: super::NoiseYamlArgs,
    #[command(flatten)]
    force: super::output::Force,
    #[command(flatten)]
    grid: log::GridOptions,
    #[command(flatten)]
    input: log::LogOptions,
}

fn load(path: &Path, args: &Args, config: &gyro_core::Config) -> Result<NoiseLog> {
    let regular = super::load(path, &args.input, &args.grid)?;
    let rate: Vec<f64> = regular.slots.iter().map(|s| s.rate_dps).collect();
    let rests = |margin_s: f64, min_rest_s: f64| {
        noise::rest_segments(&regular, config, margin_s, min_rest_s).with_context(|| {
            format!(
                "{}: cannot configure the pipeline for this log",
                path.display()
            )
        })
    };
    let mut moving_share = None;
    let segments = if args.static_only {
        let segments = rests(args.margin_s, args.min_rest_s)?;
        if segments.is_empty() {
            bail!(
                "{}: no rest stretch of at least {} s found (--static-only)",
                path.display(),
                args.min_rest_s
            );
        }
        segments
    } else {
        // Taken whole: how much of it moves (movements themselves, no margin).
        let at_rest: usize = rests(0.0, 0.0)?.iter().map(ExactSizeIterator::len).sum();
        moving_share = Some(1.0 - at_rest as f64 / rate.len().max(1) as f64);
        std::iter::once(0..rate.len()).collect()
    };
    Ok(NoiseLog {
        file: path.display().to_string(),
        rate_dps: rate,
        sample_rate_hz: regular.sample_rate_hz,
        segments,
        input: regular.quality,
        moving_share,
    })
}

/// Refuse the input settings of columns and channels noise does not read (it takes the
/// rate alone): given, they would be ignored.
fn refuse_unused_inputs(input: &log::LogOptions) -> Result<()> {
    let reference_topic = (input.mcap.reference_topic
        != log::McapOptions::default().reference_topic)
        .then_some(&input.mcap.reference_topic);
    let unused = [
        (
            "--reference-column",
            input.columns.reference_column.as_ref(),
        ),
        (
            "--temperature-column",
            input.columns.temperature_column.as_ref(),
        ),
        ("--reference-topic", reference_topic),
    ];
    if let Some((flag, value)) = unused
        .into_iter()
        .find_map(|(flag, value)| Some((flag, value?)))
    {
        bail!(
            "{flag} {}: noise reads only the time and the rate of a log, so it would be ignored; leave it out",
            log::excerpt(value.as_bytes())
        );
    }
    Ok(())
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    check_args(args)?;
    let base = match &args.model {
        Some(path) => Some(model::load(path)?),
        None => None,
    };
    let config = base
        .as_ref()
        .map_or_else(gyro_core::Config::default, |m| m.config);
    let options = noise_options(args);

    let loaded = args
        .logs
        .iter()
        .map(|path| load(path, args, &config))
        .collect::<Result<Vec<_>>>()?;
    let run = noise::characterize_logs(&loaded, &options)?;
    if run.rates_differ {
        say!("note: the logs differ in sample rate; no pooled result");
    }

    if let Some(out) = &args.model_out {
        write_model_out(out, base, &loaded, &run)?;
    }
    if let Some(out) = &args.noise_yaml.noise_yaml {
        write_noise_yaml(out, args, &loaded, &run)?;
    }
    if let Some(out) = &args.psd_out {
        write_psd(out, &loaded, &run)?;
    }
    if let Some(path) = &args.plot {
        plot(path, &loaded, &run)?;
    }

    let text = match args.format {
        Format::Table => gyro_report::noise::tables(&loaded, &run),
        Format::Json => {
            let model_out = args.model_out.as_ref().map(|p| p.display().to_string());
            gyro_report::noise::json(&loaded, &run, args.static_only, model_out.as_deref())? + "\n"
        }
    };
    super::to_stdout(|out| out.write_all(text.as_bytes()))?;
    Ok(())
}

/// Refuse arguments that cannot work (outputs that would overwrite, unused inputs, values
/// out of range) before any log is read.
fn check_args(args: &Args) -> Result<()> {
    refuse_unused_inputs(&args.input)?;
    let outputs = [
        &args.model_out,
        &args.psd_out,
        &args.noise_yaml.noise_yaml,
        &args.plot,
    ];
    args.force.check(
        outputs.into_iter().flatten().map(PathBuf::as_path),
        args.logs
            .iter()
            .map(PathBuf::as_path)
            .chain(args.model.as_deref()),
    )?;
    super::refuse_repeated_runs(&[("static", &args.logs)])?;
    if !(args.confidence > 0.0 && args.confidence < 1.0) {
        bail!("--confidence must be in (0, 1)");
    }
    if !(args.margin_s >= 0.0 && args.min_rest_s >= 0.0) {
        bail!("--margin-s and --min-rest-s must be >= 0");
    }
    if let Some(len) = args.psd_segment {
        if len < 2 || !len.is_power_of_two() {
            bail!("--psd-segment must be a power of two >= 2");
        }
    }
    Ok(())
}

/// The characterisation's options from the arguments: averaging times, confidence, PSD
/// segment.
fn noise_options(args: &Args) -> NoiseOptions {
    NoiseOptions {
        taus: match args.tau_grid {
            Grid::Log => TauGrid::PerDecade(args.per_decade.max(1)),
            Grid::Octave => TauGrid::Octave,
            Grid::Decade => TauGrid::Decade,
        },
        confidence: args.confidence,
        psd: PsdOptions {
            segment_len: args.psd_segment,
            ..PsdOptions::default()
        },
        ..NoiseOptions::default()
    }
}

/// `--model-out`: write the model file whose sensor comes from the fit (`base`'s, if
/// given, with its sensor replaced but its range kept), and say what it holds.
fn write_model_out(
    out: &Path,
    base: Option<model::ModelFile>,
    loaded: &[NoiseLog],
    run: &noise::NoiseRun,
) -> Result<()> {
    let Some(source) = run.single() else {
        bail!("--model-out needs one log, or logs of one sample rate to pool")
    };
    let mut file = match base {
        Some(base) => model::ModelFile {
            sensor: gyro_sim::SensorModel {
                range_dps: base.sensor.range_dps,
                ..source.sensor_model()
            },
            ..base
        },
        None => source.model_file(),
    };
    let largest = model::largest_plausible_abs_rate(
        loaded.iter().flat_map(|l| l.rate_dps.iter().copied()),
        file.config.max_abs_rate_dps,
    );
    if let Some(note) = file.drop_contradicted_range(largest) {
        say!("{}: {note}", out.display());
    }
    model::save(out, &file)?;
    let s = &file.sensor;
    say!(
        "wrote {}: sensor at {} Hz, bias {:.5} deg/s, ARW {:.4} deg/√h, Gauss-Markov σ {:.4e} deg/s T {:.4} s, step {} deg/s",
        out.display(),
        s.sample_rate_hz,
        s.bias_dps,
        s.arw_deg_per_rt_h,
        s.gm_sigma_dps,
        s.gm_tau_s,
        s.lsb_dps
    );
    Ok(())
}

/// `--noise-yaml`: write the fitted noise parameters, with where they come from.
fn write_noise_yaml(
    out: &Path,
    args: &Args,
    loaded: &[NoiseLog],
    run: &noise::NoiseRun,
) -> Result<()> {
    let Some(fitted) = run.single() else {
        bail!("--noise-yaml needs one log, or logs of one sample rate to pool")
    };
    let files: Vec<&str> = loaded.iter().map(|l| l.file.as_str()).collect();
    let source = format!(
        "static Allan deviation (gyro-cli noise) of {}{}",
        match files.as_slice() {
            [one] => one.to_string(),
            all => format!("{} logs pooled: {}", all.len(), all.join(", ")),
        },
        if args.static_only {
            ", rest stretches only (--static-only)".to_string()
        } else {
            loaded
                .iter()
                .filter_map(noise::moving_warning)
                .map(|w| format!("; warning: {w}"))
                .collect()
        }
    );
    let params = noise::NoiseParams::from_allan(fitted, source)?;
    args.noise_yaml.write(out, &params)?;
    Ok(())
}

/// `--psd-out`: write every log's PSD (and the pooled one) as CSV.
fn write_psd(out: &Path, loaded: &[NoiseLog], run: &noise::NoiseRun) -> Result<()> {
    super::output::write(out, |w| {
        writeln!(w, "log,frequency_hz,psd_dps2_per_hz")?;
        for (l, r) in loaded.iter().zip(&run.results) {
            gyro_report::noise::psd_csv(w, &l.file, r)?;
        }
        if let Some(c) = &run.combined {
            gyro_report::noise::psd_csv(w, "combined", c)?;
        }
        Ok(())
    })?;
    Ok(())
}

/// `--plot`: plot the pooled result, else the first log's.
fn plot(path: &Path, loaded: &[NoiseLog], run: &noise::NoiseRun) -> Result<()> {
    let (title, result) = match (&run.combined, loaded, run.results.as_slice()) {
        (Some(c), ..) => (format!("all {} logs pooled", loaded.len()), c),
        (None, [l, ..], [r, ..]) => (l.file.clone(), r),
        _ => bail!("no result to plot"),
    };
    gyro_report::plot::noise_plot(path, &title, result)?;
    Ok(())
}
