//! `gyro-cli calibrate`: fit the error model on bench runs and write a model file.

use anyhow::{Context, Result};
use gyro_analysis::calibrate::{
    calibrate, BenchRun, CalibrateOptions, Calibration, ChoiceReason, Objective,
};
use gyro_analysis::model;
use gyro_analysis::replay::{config_for_rate, lowered_rate_note};
use gyro_core::Config;
use gyro_log as log;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// Arguments of `calibrate`.
#[derive(clap::Args)]
pub struct Args {
    /// Bench runs with `reference_deg` to fit on.
    #[arg(required = true)]
    logs: Vec<PathBuf>,
    /// Model file to write.
    #[arg(short, long)]
    out: PathBuf,
    /// Runs to score the fit on, not used in fitting.
    #[arg(long, num_args = 1..)]
    holdout: Vec<PathBuf>,
    /// What to minimise.
    #[arg(long, value_enum, default_value_t = Objective::MeanMaxAbs)]
    objective: Objective,
    /// Start from this model file (pipeline and sensor settings kept, error model refitted).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Initial bias correlation time (s), e.g. from `gyro-cli noise`.
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    tau_s: Option<f64>,
    /// Also fit the motion detector's thresholds (slower: runs are replayed per trial).
    #[arg(long)]
    fit_motion: bool,
    /// The gyro's delay behind the reference (s; negative: it leads) to score every run
    /// with, written to the model file. Default: the `--model` file's `reference_delay_s`
    /// if it has one, else measured on the training runs (cross-correlation of the rates
    /// within ±0.5 s, applied from half a grid slot); 0 scores against the reference as logged.
    #[arg(long, value_parser = gyro_log::value::finite::<f64>, allow_negative_numbers = true)]
    reference_delay_s: Option<f64>,
    /// Skip the leave-one-run-out refits. The model written is chosen on their held-out
    /// errors, so without them the starting configuration is written.
    #[arg(long)]
    no_leave_one_out: bool,
    #[command(flatten)]
    grid: log::GridOptions,
    #[command(flatten)]
    input: log::LogOptions,
    /// Output format on stdout.
    #[arg(long, value_enum, default_value_t = super::run::Format::Table)]
    format: super::run::Format,
    #[command(flatten)]
    force: super::output::Force,
    /// Plot each run's max abs error without compensation, with the paper model and the
    /// Kalman form (training and hold-out runs) to this file: .svg or .png.
    #[arg(long, value_parser = gyro_report::plot::parse_plot_path)]
    plot: Option<PathBuf>,
}

fn load_runs(paths: &[PathBuf], args: &Args) -> Result<Vec<BenchRun>> {
    paths
        .iter()
        .map(|path| {
            let regular = super::load(path, &args.input, &args.grid)?;
            Ok(BenchRun {
                name: path.display().to_string(),
                log: regular,
            })
        })
        .collect()
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let inputs = args.logs.iter().chain(&args.holdout).map(PathBuf::as_path);
    args.force.check(
        [args.out.as_path()].into_iter().chain(args.plot.as_deref()),
        inputs.chain(args.model.as_deref()),
    )?;
    super::refuse_repeated_runs(&[("training", &args.logs), ("hold-out", &args.holdout)])?;
    super::check_reference_delay(args.reference_delay_s)?;
    let base = match &args.model {
        Some(path) => model::load(path)?,
        None => model::ModelFile::new(Config::default()),
    };
    let train = load_runs(&args.logs, args)?;
    let holdout = load_runs(&args.holdout, args)?;
    warn_lowered_rates(&base, train.iter().chain(&holdout));
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let options = CalibrateOptions {
        objective: args.objective,
        leave_one_out: !args.no_leave_one_out,
        initial_tau_s: args.tau_s,
        fit_motion: args.fit_motion,
        reference_delay_s: args
            .reference_delay_s
            .or((base.reference_delay_s != 0.0).then_some(base.reference_delay_s)),
    };
    let result = calibrate(
        &train,
        &holdout,
        &base.config,
        &options,
        &mut |stage, n, best| {
            if n % 10 == 0 {
                bar.set_message(format!("{stage}: {n} evaluations, best {best:.4} deg"));
                bar.tick();
            }
        },
    );
    bar.finish_and_clear();
    let result = result?;
    let (out, note) = result.model_file(&base, train.iter().chain(&holdout));
    if let Some(note) = note {
        say!("{}: {note}", args.out.display());
    }
    model::save(&args.out, &out).with_context(|| "writing the model file".to_string())?;
    report(args, &train, &holdout, &result)?;
    if let Some(path) = &args.plot {
        gyro_report::plot::calibrate_plot(path, &result)?;
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// Warn of each run whose sample rate lowers the configured filter rates (the model
/// written keeps them).
fn warn_lowered_rates<'a>(base: &model::ModelFile, runs: impl Iterator<Item = &'a BenchRun>) {
    for run in runs {
        let (placed, lowered) = config_for_rate(&base.config, run.log.sample_rate_hz);
        if let Some(configured_hz) = lowered {
            super::warn(&format!(
                "{}: {}; the written model keeps the configured rates",
                run.name,
                lowered_rate_note(
                    run.log.sample_rate_hz,
                    configured_hz,
                    placed.filter.cutoff_hz
                )
            ));
        }
    }
}

/// The calibration's report on stdout (with what was read of each run), then on stderr
/// which model was written.
fn report(
    args: &Args,
    train: &[BenchRun],
    holdout: &[BenchRun],
    result: &Calibration,
) -> Result<()> {
    let inputs: Vec<_> = train
        .iter()
        .chain(holdout)
        .map(|run| gyro_report::input::InputJson {
            file: &run.name,
            input: &run.log.quality,
        })
        .collect();
    let text = match args.format {
        super::run::Format::Json => gyro_report::calibrate::json(&inputs, result)? + "\n",
        _ => gyro_report::calibrate::table_with_inputs(
            result,
            &gyro_report::input::tables(inputs.iter().map(|i| (i.file, i.input))),
        ),
    };
    super::to_stdout(|out| out.write_all(text.as_bytes()))?;
    say!(
        "wrote {}: {}",
        args.out.display(),
        gyro_report::calibrate::choice_text(result)
    );
    if result.choice.reason == ChoiceReason::NoRefits && args.no_leave_one_out {
        say!("drop --no-leave-one-out to let calibrate write a fitted model");
    }
    Ok(())
}
