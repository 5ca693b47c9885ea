//! `gyro-cli diagnose`: where a real sensor differs from its simulation, which
//! unmodelled effect causes it, and how far the gap shrinks on held-out runs.

use anyhow::{bail, Result};
use clap::ValueEnum;
use gyro_analysis::model;
use gyro_diagnose::files::{self, FileOptions, FileRuns, LoadError};
use gyro_diagnose::RealRun;
use gyro_diagnose::{self as diagnose, selftest, DiagnoseError, Diagnosis, Options, Progress};
use gyro_log as log;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// Output format.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Human-readable.
    Table,
    /// The JSON contract of docs/diagnose-json.md.
    Json,
}

/// Arguments of `diagnose`.
#[derive(clap::Args)]
pub struct Args {
    /// Runs to fit the nominal model and the candidate effects on (logs with
    /// `reference_deg`; `temperature_c` where present).
    #[arg(long, num_args = 1.., required_unless_present = "self_test")]
    train: Vec<PathBuf>,
    /// Runs to score the effects on, never used in fitting.
    #[arg(long, num_args = 1.., required_unless_present = "self_test")]
    holdout: Vec<PathBuf>,
    /// Cut every log into windows of this many seconds, each a run (for long recordings).
    #[arg(long, value_parser = gyro_log::value::positive::<f64>)]
    split_s: Option<f64>,
    /// Use this model file's sensor model as the nominal model, as it is (and its
    /// pipeline configuration for the compensated replays).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Write a model file with the corrections of the selected correctable effects
    /// (scale, asymmetry, temperature, latency, turn-on bias), for `run --model`.
    #[arg(short, long, conflicts_with = "self_test")]
    out: Option<PathBuf>,
    /// Output format on stdout.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write an HTML report with plots into this directory: index.html and diagnosis.json
    /// (with --force if they exist).
    #[arg(long, value_name = "DIR", conflicts_with = "self_test")]
    report: Option<PathBuf>,
    /// Seed of the simulated ensembles.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Members of the baseline ensemble per run (at least 50 for the figures to mean
    /// what the report says).
    #[arg(long, default_value_t = 50, value_parser = at_least_two)]
    members: usize,
    /// Members per held-out run for each candidate effect.
    #[arg(long, default_value_t = 20, value_parser = at_least_two)]
    candidate_members: usize,
    /// Score on the held-out runs also the effects whose parameter test does not pass on
    /// the training runs. They can never be named; by default their held-out figures and
    /// posterior checks are left out, which saves one candidate ensemble per effect.
    #[arg(long)]
    score_every_candidate: bool,
    /// Run the injection–recovery self-check instead of diagnosing logs.
    #[arg(long)]
    self_test: bool,
    /// With --self-test: only the cases that inject this effect id (`none`: the null
    /// cases); each case is the same as in the whole run.
    #[arg(long, requires = "self_test")]
    only: Option<String>,
    /// With --self-test: every effect at each magnitude of its realistic range (see
    /// `gyro-cli simulate --list-effects`), each this many times with its own seeds, then
    /// the pairs and the null cases; prints each effect's detection limit.
    #[arg(long, requires = "self_test", value_name = "REPEATS")]
    matrix: Option<usize>,
    #[command(flatten)]
    noise_yaml: super::NoiseYamlArgs,
    #[command(flatten)]
    force: super::output::Force,
    #[command(flatten)]
    grid: log::GridOptions,
    #[command(flatten)]
    input: log::LogOptions,
}

/// A count of ensemble members: at least 2 (a spread needs two).
fn at_least_two(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if n >= 2 => Ok(n),
        _ => Err(format!(
            "expected a whole number >= 2, got `{}`",
            text.chars().take(40).collect::<String>()
        )),
    }
}

struct Bar(ProgressBar);

impl Progress for Bar {
    fn stage(&self, name: &str, total: u64) {
        self.0.set_message(name.to_string());
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn tick(&self) {
        self.0.inc(1);
    }
}

fn progress_bar() -> Bar {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{msg:<36} [{bar:30}] {pos}/{len} {elapsed_precise}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    Bar(bar)
}

/// A failure to read the runs as the command line reports it: a log's own error as it is
/// (for `main`'s flag hints), the others with their message.
fn load_error(e: LoadError) -> anyhow::Error {
    match e {
        LoadError::Log(e) => e.into(),
        e => e.into(),
    }
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    check_outputs(args)?;
    if args.self_test {
        return self_test(args);
    }
    let options = diagnose_options(args)?;
    let FileRuns {
        train,
        holdout,
        inputs,
    } = files::load_files(
        &args.train,
        &args.holdout,
        &FileOptions {
            input: &args.input,
            grid: &args.grid,
            split_s: args.split_s,
        },
        &mut super::warn,
    )
    .map_err(load_error)?;
    diagnose::check_runs(&train, &holdout).map_err(with_advice)?;
    let bar = progress_bar();
    let result = diagnose::diagnose(&train, &holdout, &options, &bar);
    bar.0.finish_and_clear();
    let mut result = result.map_err(with_advice)?;
    result.inputs = inputs;
    let text = match args.format {
        Format::Json => serde_json::to_string_pretty(&result)? + "\n",
        Format::Table => gyro_report::diagnose::table(&result),
    };
    super::to_stdout(|out| out.write_all(text.as_bytes()))?;
    if let Some(dir) = &args.report {
        write_report(dir, &result, &train, &holdout, &options)?;
    }
    if let Some(out) = &args.noise_yaml.noise_yaml {
        write_noise_yaml(out, args, &result)?;
    }
    if let Some(out) = &args.out {
        write_model(out, &result, &train, &holdout, &options)?;
    }
    Ok(())
}

/// Refuse outputs that cannot be written: `--noise-yaml` with `--self-test`, and files
/// that would overwrite without `--force` (or an input).
fn check_outputs(args: &Args) -> Result<()> {
    if args.self_test && args.noise_yaml.noise_yaml.is_some() {
        bail!("--noise-yaml writes the noise of diagnosed logs, not of --self-test");
    }
    let report_files = args.report.iter().flat_map(|dir| {
        gyro_report::diagnose::REPORT_FILES
            .iter()
            .map(|name| dir.join(name))
    });
    let outputs: Vec<PathBuf> = args
        .out
        .iter()
        .chain(&args.noise_yaml.noise_yaml)
        .cloned()
        .chain(report_files)
        .collect();
    let inputs = args.train.iter().chain(&args.holdout).map(PathBuf::as_path);
    args.force.check(
        outputs.iter().map(PathBuf::as_path),
        inputs.chain(args.model.as_deref()),
    )?;
    Ok(())
}

/// The diagnosis options from the arguments (a model file fixes the base model).
fn diagnose_options(args: &Args) -> Result<Options> {
    let mut options = Options {
        seed: args.seed,
        members: args.members,
        candidate_members: args.candidate_members,
        score_every_candidate: args.score_every_candidate,
        ..Options::default()
    };
    if args.members < 2 || args.candidate_members < 2 {
        bail!("--members and --candidate-members must be at least 2");
    }
    if let Some(path) = &args.model {
        options = options.with_fixed_model(model::load(path)?);
    }
    Ok(options)
}

/// `--out`: write the corrected model (else the base model), and say what it corrects.
fn write_model(
    out: &Path,
    result: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
) -> Result<()> {
    let mut file = result
        .corrected_model
        .clone()
        .unwrap_or_else(|| options.base_model.clone());
    let largest = model::largest_plausible_abs_rate(
        train
            .iter()
            .chain(holdout)
            .map(|r| r.features.max_abs_rate_dps),
        options.base_model.config.max_abs_rate_dps,
    );
    if let Some(note) = file.drop_contradicted_range(largest) {
        say!("{}: {note}", out.display());
    }
    model::save(out, &file)?;
    say!(
        "wrote {} ({})",
        out.display(),
        match &result.compensation {
            Some(c) if !c.corrected.is_empty() =>
                format!("corrections for {}", c.corrected.join(", ")),
            Some(_) =>
                "no correction lowered the held-out angle error: the base model unchanged".into(),
            None => "no correctable effect selected: the base model unchanged".into(),
        }
    );
    Ok(())
}

fn self_test(args: &Args) -> Result<()> {
    let options = Options {
        members: args.members,
        candidate_members: args.candidate_members,
        score_every_candidate: args.score_every_candidate,
        ..Options::default()
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("self-test {pos}/{len} {msg:<40} {elapsed_precise}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    if let Some(id) = args.only.as_deref() {
        if id != "none" && !gyro_sim::EFFECTS.iter().any(|e| e.id == id) {
            anyhow::bail!(
                "--only {id}: not an effect id (see `gyro-cli simulate --list-effects`) nor `none`"
            );
        }
    }
    let plan = match args.matrix {
        None => selftest::Plan::Standard,
        Some(0) => anyhow::bail!("--matrix 0: give the number of seeds per magnitude, 1 or more"),
        Some(repeats) => selftest::Plan::Matrix { repeats },
    };
    let result = selftest::run(
        args.seed,
        plan,
        args.only.as_deref(),
        &options,
        &|k, total, label| {
            bar.set_length(total as u64);
            bar.set_position(k as u64);
            bar.set_message(label.to_string());
        },
    );
    bar.finish_and_clear();
    let result = result.map_err(with_advice)?;
    let text = match args.format {
        Format::Json => serde_json::to_string_pretty(&result)? + "\n",
        Format::Table => gyro_report::diagnose::self_test_table(&result),
    };
    super::to_stdout(|out| out.write_all(text.as_bytes()))?;
    Ok(())
}

/// `--noise-yaml`: the effective noise measured on the training runs (else that of the
/// selected sensor model).
fn write_noise_yaml(out: &Path, args: &Args, result: &Diagnosis) -> Result<()> {
    let names = |paths: &[PathBuf]| {
        paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let runs = format!(
        "training: {}; held out: {}{}",
        names(&args.train),
        names(&args.holdout),
        args.split_s
            .map_or(String::new(), |s| format!("; in windows of {s} s"))
    );
    let params = match &result.effective_noise.training {
        Some(t) => {
            let mut notes = vec![format!(
                "{} (the diagnosis's sensor model has {:.4} deg/sqrt(h))",
                t.describe(),
                result.model.sensor.arw_deg_per_rt_h
            )];
            if let Some(h) = &result.effective_noise.holdout {
                notes.push(format!(
                    "{}: the effective noise depends on the motion",
                    h.describe()
                ));
            }
            if let Some(caveat) = result.residual_caveat() {
                notes.push(caveat);
            }
            gyro_analysis::noise::NoiseParams::from_residual(
                &t.characterization,
                format!(
                    "effective values measured on moving data by gyro-cli diagnose: the Allan deviation of what the deterministic terms leave of gyro minus reference ({runs})"
                ),
                notes,
            )?
        }
        None => gyro_analysis::noise::NoiseParams::effective(
            &result.selected_sensor,
            &result.model.effects,
            &result.model.notes,
            format!(
                "effective values of the sensor model gyro-cli diagnose selected: the runs were too short to measure them ({runs})"
            ),
        )?,
    };
    args.noise_yaml.write(out, &params)
}

/// `e` with what to pass on the command line to get past it, where there is advice.
fn with_advice(e: DiagnoseError) -> anyhow::Error {
    match e.advice() {
        Some(_) => anyhow::anyhow!("{}", e.with_advice()),
        None => e.into(),
    }
}

fn write_report(
    dir: &Path,
    result: &Diagnosis,
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
) -> Result<()> {
    let envelopes = diagnose::envelopes::envelopes(result, train, holdout, options);
    gyro_report::diagnose::write_report(dir, result, envelopes.as_ref(), options)?;
    say!("wrote {}", dir.join("index.html").display());
    Ok(())
}
