//! One module per `gyro-cli` subcommand: its arguments (`Args`) and `run`.

pub mod calibrate;
pub mod convert;
pub mod diagnose;
pub mod emulate;
pub mod noise;
pub mod output;
pub mod record;
pub mod run;
pub mod simulate;

use anyhow::{Context, Result};
use gyro_analysis::noise::{NoiseParams, YamlFormat};
use gyro_log::{GridOptions, Log, LogOptions, RegularLog};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Refuse a run given twice: the same file (by device and inode, whatever the spelling)
/// twice in one list, or in two lists (`names` say which: "training", "hold-out")
/// ([`gyro_log::repeated::refuse_repeated_runs`]).
pub fn refuse_repeated_runs(lists: &[(&str, &[PathBuf])]) -> Result<()> {
    Ok(gyro_log::repeated::refuse_repeated_runs(lists)?)
}

/// Write a command's output to stdout with `write`, then flush: any failure is one error
/// naming stdout (a full disk: "No space left on device"). A reader that has gone (`| head`)
/// stays a broken pipe underneath, which `main` ends quietly.
pub fn to_stdout(write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let mut out = std::io::stdout().lock();
    write(&mut out)
        .and_then(|()| out.flush())
        .context("cannot write to stdout")
}

/// `--noise-yaml FILE [--noise-yaml-format F]` of `noise` and `diagnose`: the gyro noise
/// as the YAML a visual-inertial filter takes.
#[derive(clap::Args)]
pub struct NoiseYamlArgs {
    /// Write the gyro noise as filter YAML to this file: continuous-time
    /// gyroscope_noise_density (rad/s/√Hz), gyroscope_random_walk (rad/s²/√Hz) and
    /// update_rate (Hz), with units and provenance in comments; gyroscope keys only.
    #[arg(long, value_name = "FILE")]
    pub noise_yaml: Option<PathBuf>,
    /// Whose YAML --noise-yaml writes.
    #[arg(long, value_enum, value_name = "FORMAT", default_value_t = YamlFormat::Kalibr, requires = "noise_yaml")]
    pub noise_yaml_format: YamlFormat,
}

impl NoiseYamlArgs {
    /// Write `params` to `--noise-yaml` in the chosen format, saying so on stderr.
    pub fn write(&self, out: &Path, params: &NoiseParams) -> Result<()> {
        let yaml = params.to_yaml(self.noise_yaml_format);
        output::write(out, |w| w.write_all(yaml.as_bytes()))?;
        say!(
            "wrote {} ({}): gyroscope_noise_density {} rad/s/√Hz ({:.4} deg/√h), gyroscope_random_walk {} rad/s²/√Hz, update_rate {} Hz",
            out.display(),
            match self.noise_yaml_format {
                YamlFormat::Kalibr => "Kalibr imu.yaml",
                YamlFormat::OpenVins => "OpenVINS kalibr_imu_chain.yaml",
                YamlFormat::Vins => "VINS-Fusion gyr_n, gyr_w",
            },
            gyro_analysis::noise::export::sci(params.noise_density_rad_s_rt_hz),
            params.noise_density_rad_s_rt_hz.to_degrees() * 60.0,
            gyro_analysis::noise::export::sci(params.random_walk_rad_s2_rt_hz),
            params.update_rate_hz
        );
        Ok(())
    }
}

/// Refuse a `--reference-delay-s` beyond what a model file may hold
/// ([`gyro_analysis::replay::settings::check_reference_delay`]).
pub fn check_reference_delay(delay_s: Option<f64>) -> Result<()> {
    Ok(gyro_analysis::replay::settings::check_reference_delay(
        delay_s,
    )?)
}

/// Print a warning about the input on stderr.
pub fn warn(warning: &str) {
    say!("warning: {warning}");
}

/// Read a log, warnings printed ([`gyro_log::read_log_with_warnings`]).
pub fn read(path: &Path, options: &LogOptions) -> Result<Log> {
    let (log, warnings) = gyro_log::read_log_with_warnings(path, options)?;
    warnings.iter().for_each(|w| warn(w));
    Ok(log)
}

/// Read a log and place it on the grid, warnings printed ([`gyro_log::load`]).
pub fn load(path: &Path, options: &LogOptions, grid: &GridOptions) -> Result<RegularLog> {
    Ok(gyro_log::load(path, options, grid, &mut warn)?)
}

/// A flag set by SIGINT or SIGTERM, for loops that must finish their output cleanly
/// (signal-hook: an atomic store in the handler, no extra thread); a second signal while
/// the first is being handled exits at once with status 1.
pub fn stop_flag() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 1, Arc::clone(&stop))
            .context("cannot install the signal handler")?;
        signal_hook::flag::register(signal, Arc::clone(&stop))
            .context("cannot install the signal handler")?;
    }
    Ok(stop)
}
