//! `gyro-cli calibrate`: fit the error model on bench runs and write a model file.

use anyhow::{Context, Result};
use gyro_analysis::calibrate::{
    calibrate, BenchRun, CalibrateOptions, Calibration, Objective, RunScore,
};
use gyro_analysis::model;
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
    #[arg(long)]
    tau_s: Option<f64>,
    /// Also fit the motion detector's thresholds (slower: runs are replayed per trial).
    #[arg(long)]
    fit_motion: bool,
    /// Skip the leave-one-run-out refits.
    #[arg(long)]
    no_leave_one_out: bool,
    #[command(flatten)]
    grid: log::GridOptions,
    #[command(flatten)]
    input: log::LogOptions,
    /// Output format on stdout.
    #[arg(long, value_enum, default_value_t = super::run::Format::Table)]
    format: super::run::Format,
    /// Plot each run's max abs error without compensation, with the paper model and the
    /// Kalman form (training and hold-out runs) to this file: .svg or .png.
    #[arg(long, value_parser = gyro_report::plot::parse_plot_path)]
    plot: Option<PathBuf>,
}

fn load_runs(paths: &[PathBuf], args: &Args) -> Result<Vec<BenchRun>> {
    paths
        .iter()
        .map(|path| {
            let (raw, warnings) = log::read_log_with_warnings(path, &args.input)?;
            for warning in &warnings {
                eprintln!("warning: {warning}");
            }
            let regular = log::regularize(&raw, &args.grid)?;
            Ok(BenchRun {
                name: path.display().to_string(),
                log: regular,
            })
        })
        .collect()
}

fn score_table(title: &str, scores: &[RunScore]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    if scores.is_empty() {
        return s;
    }
    let _ = writeln!(s, "{title}: max abs angle error per run (deg)");
    let _ = writeln!(
        s,
        "  {:<40} {:>9} {:>9} {:>9}",
        "run", "none", "paper", "kalman"
    );
    for r in scores {
        let name = if r.name.len() > 40 {
            &r.name[r.name.len() - 40..]
        } else {
            &r.name
        };
        let _ = writeln!(
            s,
            "  {:<40} {:>9.4} {:>9.4} {:>9.4}",
            name, r.none_max_abs_deg, r.paper_max_abs_deg, r.kalman_max_abs_deg
        );
    }
    let median = |f: fn(&RunScore) -> f64| {
        let mut v: Vec<f64> = scores.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let _ = writeln!(
        s,
        "  {:<40} {:>9.4} {:>9.4} {:>9.4}",
        "median",
        median(|r| r.none_max_abs_deg),
        median(|r| r.paper_max_abs_deg),
        median(|r| r.kalman_max_abs_deg)
    );
    s
}

fn table(c: &Calibration) -> String {
    let mut s = format!(
        "start: correlation time {:.1} s ({})\n",
        c.initial_tau.0, c.initial_tau.1
    );
    if c.config.motion != Config::default().motion {
        s += &format!(
            "motion thresholds: enter {:.3} deg/s, exit {:.3} deg/s\n",
            c.config.motion.enter_dps, c.config.motion.exit_dps
        );
    }
    s += &format!(
        "paper error model: beta {:.5} 1/s (T {:.1} s), b0 {:.5} deg/s, o0 {:.5} deg\n  objective {:?} = {:.4} deg after {} evaluations ({})\n",
        c.paper.beta_per_s,
        1.0 / c.paper.beta_per_s,
        c.paper.b0_dps,
        c.paper.o0_deg,
        c.objective,
        c.objective_deg,
        c.evaluations,
        c.termination
    );
    if let Some(sp) = &c.spread {
        s += &format!(
            "  leave-one-run-out ({} refits): mean ± sd [min, max], jackknife standard error\n",
            sp.refits
        );
        for (name, p) in [
            ("beta", &sp.beta_per_s),
            ("b0  ", &sp.b0_dps),
            ("o0  ", &sp.o0_deg),
        ] {
            s += &format!(
                "    {name} {:.5} ± {:.5} [{:.5}, {:.5}]  se {:.5}\n",
                p.mean, p.sd, p.min, p.max, p.standard_error
            );
        }
    }
    let k = &c.config.kalman;
    s += &format!(
        "kalman form: bias mean {:.4} deg/s, within-run sigma {:.4} deg/s, between-run sigma {:.4} deg/s, rate noise {:.4} deg/s\n",
        k.bias_mean_dps, k.bias_sigma_dps, k.initial_bias_sigma_dps, k.rate_noise_dps
    );
    s += &score_table("training runs", &c.train);
    s += &score_table("hold-out runs", &c.holdout);
    s += &format!(
        "model compensation: {:?} (best on the training runs)\n",
        c.config.compensation
    );
    s
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let base = match &args.model {
        Some(path) => model::load(path)?,
        None => model::ModelFile::new(Config::default()),
    };
    let train = load_runs(&args.logs, args)?;
    let holdout = load_runs(&args.holdout, args)?;
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
    let mut out = base.clone();
    out.config = result.config;
    model::save(&args.out, &out).with_context(|| "writing the model file".to_string())?;
    match args.format {
        super::run::Format::Json => println!("{}", serde_json::to_string_pretty(&result)?),
        _ => print!("{}", table(&result)),
    }
    eprintln!("wrote {}", args.out.display());
    if let Some(path) = &args.plot {
        gyro_report::plot::calibrate_plot(path, &result)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
