//! `gyro-cli run`: replay a log through the pipeline and score it against the reference.

use anyhow::{Context, Result};
use clap::ValueEnum;
use gyro_analysis::findings::Finding;
use gyro_analysis::replay;
use gyro_core::{Compensation, Direction};
use gyro_log as log;
use gyro_log::value;
use gyro_log::whole::Partial;
use gyro_report::run as report;
use std::fs::File;
use std::io::{self, BufWriter, Write as _};
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Human-readable.
    Table,
    /// JSON.
    Json,
    /// CSV of the movements.
    Csv,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CompensationArg {
    None,
    Paper,
    Kalman,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DirectionArg {
    Positive,
    Negative,
}

#[derive(clap::Args)]
pub struct Args {
    /// The log: CSV (`time_s,rate_dps[,temperature_c][,reference_deg]`), MCAP (`/gyro`,
    /// `/reference`) or a ROS 2 bag in MCAP (`sensor_msgs/msg/Imu`).
    log: PathBuf,
    /// Model file (JSON, from `calibrate`); default: the built-in configuration. Its
    /// `config.correction` is applied to every sample (with the log's temperatures), its
    /// `reference_delay_s` shifts the reference before scoring.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Override the model's compensation.
    #[arg(long, value_enum)]
    compensation: Option<CompensationArg>,
    /// The sensor's full-scale range (deg/s): a movement during which a reading reaches it
    /// is flagged saturated. Default: the model's (`config.range_dps`, else
    /// `sensor.range_dps`); without a model, unknown (only clip plateaus are flagged).
    #[arg(long, value_name = "DPS", value_parser = value::positive::<f32>)]
    range_dps: Option<f32>,
    /// Judge each movement against a tightening window: its target angle (deg, in the
    /// tightening direction). Default: the model's `config.tightening`, else no decision.
    #[arg(long, value_name = "DEG", requires = "tolerance_deg", value_parser = value::finite::<f32>)]
    target_deg: Option<f32>,
    /// Half-width of the tightening window (deg): accepted angles lie in target ± this.
    #[arg(long, value_name = "DEG", requires = "target_deg", value_parser = value::positive::<f32>)]
    tolerance_deg: Option<f32>,
    /// Guard band of the decision in standard deviations of the movement's angle: `ok`
    /// needs the angle inside the window by more than k·σ, `nok` outside by more than k·σ,
    /// else `recheck`.
    #[arg(long, value_name = "K", default_value_t = replay::settings::DEFAULT_K_SIGMA, value_parser = value::non_negative::<f32>)]
    k_sigma: f32,
    /// Which sign of the angle tightens; a turn the other way gets no verdict.
    #[arg(long, value_enum, default_value_t = DirectionArg::Positive)]
    tightening_direction: DirectionArg,
    /// Relative uncertainty of the gyro's scale factor (0.01 = 1%), added to each
    /// movement's σ as a share of its angle: the filter's σ does not know the scale. Use it
    /// for a gyro whose scale is not calibrated. Default: the model file's `scale_sigma`
    /// (what `calibrate` measured), else 0.
    #[arg(long, value_name = "FRACTION", value_parser = value::non_negative::<f32>)]
    scale_sigma: Option<f32>,
    /// The gyro's delay behind the reference (s; negative: it leads) to score against:
    /// the angle at t is compared with the reference at t − delay. Default: the model
    /// file's `reference_delay_s`, else 0 (the reference as logged). `run` warns when it
    /// measures a lag of 20 ms or more, and names the delay that would score it.
    #[arg(long, value_name = "S", value_parser = value::finite::<f64>, allow_negative_numbers = true)]
    reference_delay_s: Option<f64>,
    /// Analyse the log after the fact: each movement's angle and σ from the rests on both
    /// sides (the Kalman form smoothed over the rest after it), not only the rest before as
    /// the wrench must. Needs the Kalman compensation. Memory holds a movement and the rest
    /// after it.
    #[arg(long)]
    offline: bool,
    /// Output format on stdout (csv: the movements).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write the output-rate series (angle, reference, error, state) as CSV here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Plot angle vs reference, error (±1σ in Kalman mode), motion state and rate to this
    /// file: .svg or .png.
    #[arg(long, value_parser = gyro_report::plot::parse_plot_path)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    force: super::output::Force,
    #[command(flatten)]
    grid: log::GridOptions,
    #[command(flatten)]
    input: log::LogOptions,
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    args.force.check(
        args.out.iter().chain(&args.plot).map(PathBuf::as_path),
        [args.log.as_path()]
            .into_iter()
            .chain(args.model.as_deref()),
    )?;
    let replay::Resolved {
        config,
        options,
        mode,
    } = settings(args).resolve()?;
    // One pass: rows are read, placed on the grid and replayed as they come. The output
    // series is kept only for the plot, which needs it whole, or for an `--out` that is a
    // stream (`/dev/stdout`: written after the report, as the report may share it);
    // otherwise `--out` is written as the series comes and nothing grows with the log.
    let keep_series =
        args.plot.is_some() || args.out.as_deref().is_some_and(gyro_log::whole::is_stream);
    let mut series_file = match &args.out {
        Some(path) if !keep_series => Some(SeriesFile::beside(path)),
        _ => None,
    };
    let mut kept = Vec::new();
    let series: &mut dyn replay::SeriesSink = match (&mut series_file, keep_series) {
        (Some(file), _) => file,
        (None, true) => &mut kept,
        (None, false) => &mut (),
    };
    // The log reader's notices go to stderr as they come and into the run's findings.
    let mut notices = Vec::new();
    let mut result = replay::replay_file_into_mode(
        &args.log,
        &args.input,
        &args.grid,
        &config,
        &options,
        mode,
        &mut |notice: &str| {
            super::warn(notice);
            notices.push(notice.to_string());
        },
        series,
    )
    .map_err(|e| match e {
        replay::ReplayFileError::Log(e) => anyhow::Error::new(e),
        e @ replay::ReplayFileError::Config { .. } => anyhow::Error::new(e),
    })?;
    result.series = kept;
    // One list of findings for every output: the table, the JSON, the series' header
    // comments, and stderr (the log's notices went there as they came).
    let findings = gyro_analysis::findings::of_run(&result, &notices);
    let file = args.log.display().to_string();
    report_run(args, &file, &result, &findings)?;
    if let Some(out) = &args.out {
        match series_file {
            Some(file) => file
                .finish(result.output_rate_hz, &findings)
                .with_context(|| format!("cannot write {}", out.display()))?,
            None => super::output::write(out, |w| report::series_csv(w, &result, &findings))?,
        }
    }
    if let Some(path) = &args.plot {
        let name = args
            .log
            .file_name()
            .map_or(file.clone(), |n| n.to_string_lossy().into());
        gyro_report::plot::run_plot(path, &name, &result)?;
    }
    Ok(())
}

/// The replay's settings as the arguments give them (the model's fill in the rest).
fn settings(args: &Args) -> replay::RunSettings {
    replay::RunSettings {
        model: args.model.clone(),
        compensation: args.compensation.map(|c| match c {
            CompensationArg::None => Compensation::None,
            CompensationArg::Paper => Compensation::Paper,
            CompensationArg::Kalman => Compensation::Kalman,
        }),
        range_dps: args.range_dps,
        target_deg: args.target_deg,
        tolerance_deg: args.tolerance_deg,
        k_sigma: args.k_sigma,
        tightening_direction: match args.tightening_direction {
            DirectionArg::Positive => Direction::Positive,
            DirectionArg::Negative => Direction::Negative,
        },
        scale_sigma: args.scale_sigma,
        reference_delay_s: args.reference_delay_s,
        offline: args.offline,
    }
}

/// The report of the run of `file` on stdout in the chosen format; for the JSON and the
/// CSV, the findings on stderr too.
fn report_run(
    args: &Args,
    file: &str,
    result: &replay::RunReport,
    findings: &[Finding],
) -> Result<()> {
    let json = match args.format {
        Format::Json => Some(report::json(file, result, findings)?),
        _ => None,
    };
    super::to_stdout(|out| match args.format {
        Format::Table => write!(out, "{}", report::table(file, result, findings)),
        Format::Json => writeln!(out, "{}", json.unwrap_or_default()),
        Format::Csv => report::movements_csv(&mut &mut *out, &result.movements),
    })?;
    if args.format != Format::Table {
        // The table carries them on stdout; for the JSON and the CSV, stderr says them too.
        for f in findings
            .iter()
            .filter(|f| f.code != gyro_analysis::findings::LOG)
        {
            super::warn(&f.message);
        }
    }
    Ok(())
}

/// The `--out` series written as the replay makes it, whole all the same: into a partial
/// file beside the target ([`Partial`]), renamed over it by [`SeriesFile::finish`]; removed
/// if the run fails. A write error is kept and reported by `finish`, after the report, as
/// when the series was written at the end.
struct SeriesFile {
    partial: Option<Partial>,
    out: Option<BufWriter<File>>,
    started: bool,
    error: Option<io::Error>,
}

impl SeriesFile {
    fn beside(target: &Path) -> Self {
        let mut file = Self {
            partial: None,
            out: None,
            started: false,
            error: None,
        };
        match Partial::beside(target) {
            Ok(partial) => {
                match File::create(partial.path()) {
                    Ok(f) => file.out = Some(BufWriter::new(f)),
                    Err(e) => file.error = Some(e),
                }
                file.partial = Some(partial);
            }
            Err(e) => file.error = Some(e),
        }
        file
    }

    /// Write with `write` unless an earlier write failed.
    fn write(&mut self, write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) {
        if self.error.is_some() {
            return;
        }
        if let Some(out) = &mut self.out {
            if let Err(e) = write(out) {
                self.error = Some(e);
            }
        }
    }

    /// Complete the file (its header at `output_rate_hz` if no output came) and put it in
    /// place of the target, the run's `findings` as its first comment lines: they are known
    /// only at the end, so the rows written so far are copied after them, a buffer at a
    /// time.
    fn finish(mut self, output_rate_hz: f32, findings: &[Finding]) -> io::Result<()> {
        if !self.started {
            self.write(|w| report::series_csv_header(w, output_rate_hz));
        }
        self.write(|w| w.flush());
        self.out = None;
        let partial = self.partial.take();
        match (self.error.take(), partial) {
            (None, Some(partial)) if findings.is_empty() => partial.finish(),
            (None, Some(partial)) => {
                let result = Self::prepend(&partial, findings);
                match result {
                    Ok(()) => partial.discard(),
                    Err(e) => {
                        partial.discard();
                        return Err(e);
                    }
                }
                Ok(())
            }
            (error, partial) => {
                partial.into_iter().for_each(Partial::discard);
                Err(error.unwrap_or_else(|| io::Error::other("no partial file")))
            }
        }
    }

    /// Write `findings` then the rows of `rows` (a partial file) into the target, whole.
    fn prepend(rows: &Partial, findings: &[Finding]) -> io::Result<()> {
        let target = rows.target().to_path_buf();
        let with = Partial::beside(&target)?;
        let copy = || -> io::Result<()> {
            let mut out = BufWriter::new(File::create(with.path())?);
            report::series_csv_findings(&mut out, findings)?;
            io::copy(&mut File::open(rows.path())?, &mut out)?;
            out.flush()
        };
        match copy() {
            Ok(()) => with.finish(),
            Err(e) => {
                with.discard();
                Err(e)
            }
        }
    }
}

impl replay::SeriesSink for SeriesFile {
    fn start(&mut self, output_rate_hz: f32) {
        self.started = true;
        self.write(|w| report::series_csv_header(w, output_rate_hz));
    }

    fn point(&mut self, point: &replay::SeriesPoint) {
        self.write(|w| report::series_csv_row(w, point));
    }
}

impl Drop for SeriesFile {
    /// A run that failed leaves no partial file.
    fn drop(&mut self) {
        self.out = None;
        if let Some(partial) = self.partial.take() {
            partial.discard();
        }
    }
}
