//! The files a command writes: checked before any work is done (never one of the inputs,
//! never an existing file unless `--force`, never one file for two outputs), then written
//! whole ([`gyro_log::whole`]).

use anyhow::{Context, Result};
use gyro_log::repeated::same_file;
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

/// `--force`, of every command that writes files.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Force {
    /// Replace output files that exist; without it an existing output is refused and kept.
    #[arg(long)]
    pub force: bool,
}

impl Force {
    /// Check the `outputs` a command will write against its `inputs`: an output that is
    /// one of the inputs is refused even with --force ([`refuse_to_overwrite`]); an output
    /// that exists is refused unless --force; one file named for two outputs is refused.
    /// A device or a pipe (`/dev/stdout`) is never refused: it holds nothing to lose.
    pub fn check<'a>(
        self,
        outputs: impl IntoIterator<Item = &'a Path>,
        inputs: impl IntoIterator<Item = &'a Path> + Clone,
    ) -> Result<()> {
        let mut seen: Vec<(&Path, Option<PathBuf>)> = Vec::new();
        for output in outputs {
            if output.is_dir() {
                anyhow::bail!("{}: is a directory; give a file name", output.display());
            }
            refuse_to_overwrite(output, inputs.clone())?;
            // A device or a pipe (`/dev/stdout`, `/dev/null`) is written to, not replaced.
            if gyro_log::whole::is_stream(output) {
                continue;
            }
            let place = place(output);
            if let Some((first, _)) = seen
                .iter()
                .find(|(first, p)| *first == output || (p.is_some() && *p == place))
            {
                anyhow::bail!(
                    "{}: named for two outputs (also as {}); give each its own file",
                    output.display(),
                    first.display()
                );
            }
            seen.push((output, place));
            // A dangling symbolic link is there too: renaming over it replaces the link.
            if !self.force && std::fs::symlink_metadata(output).is_ok() {
                anyhow::bail!(
                    "{}: exists; choose another name, or --force to replace it",
                    output.display()
                );
            }
        }
        Ok(())
    }
}

/// `--compression`, of every command that writes MCAP (`convert`, `simulate`, `record`):
/// how the file's chunks are compressed. One flag, one meaning, one default everywhere.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Compression {
    /// Compression of an MCAP output's chunks: zstd (default, as the official `mcap` CLI
    /// writes), lz4 or none. On the bench log the file is 1.6 times the CSV with zstd
    /// (most of it the message indexes Foxglove needs), 2.0 with lz4, 4.3 with none; lz4
    /// reads about a fifth faster than zstd. Refused for a CSV output.
    #[arg(long, value_enum, value_name = "CODEC")]
    compression: Option<gyro_log::McapCompression>,
}

impl Compression {
    /// The compression to write `output` with, as `format`: the one given, else the
    /// default (zstd). Given with a CSV output it is refused: it would be ignored.
    pub fn for_output(
        self,
        output: &Path,
        format: gyro_log::LogFormat,
    ) -> Result<gyro_log::McapCompression> {
        match (format, self.compression) {
            (gyro_log::LogFormat::Csv, Some(given)) => anyhow::bail!(
                "--compression {given}: {} is written as CSV, which has none; name it .mcap \
                 for MCAP, or leave --compression out",
                output.display()
            ),
            (_, given) => Ok(given.unwrap_or_default()),
        }
    }
}

/// Where `path` is, spelled one way: its folder resolved (links, `..`) and its name; `None`
/// if the folder does not exist (writing there fails and says so).
fn place(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?;
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    Some(folder.canonicalize().ok()?.join(name))
}

/// Write `path` whole with `write` ([`gyro_log::whole::write`]): on failure the file that
/// was there is kept, and the error names `path`.
pub fn write(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<()> {
    gyro_log::whole::write(path, write).with_context(|| format!("cannot write {}", path.display()))
}

/// Refuse to write `output` if it is one of `inputs` (the same file by device and inode
/// on Unix, whatever the spelling: `./in.csv`, an absolute path, a symlink, a hard link),
/// so that nothing already recorded is lost. An output that does not exist yet is fine.
fn refuse_to_overwrite<'a>(
    output: &Path,
    inputs: impl IntoIterator<Item = &'a Path>,
) -> Result<()> {
    let Ok(written) = std::fs::metadata(output) else {
        return Ok(());
    };
    for input in inputs {
        let Ok(read) = std::fs::metadata(input) else {
            continue;
        };
        if same_file(&written, &read, output, input) {
            anyhow::bail!(
                "{}: is also an input ({}); refusing to overwrite it",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}
