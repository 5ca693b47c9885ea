//! Files written whole: the content goes to a partial file beside the target, which is
//! renamed over the target only once everything was written. A failure leaves no
//! half-written file that looks finished, and a file that was there is kept. A target
//! that is a device or a pipe (`/dev/stdout`, `/dev/null`) holds nothing to keep and cannot
//! be renamed over: it is written in place.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("gyro-log-whole-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let out = dir.join("out.csv");
//! gyro_log::whole::write(&out, |w| std::io::Write::write_all(w, b"time_s,rate_dps\n"))?;
//! assert_eq!(std::fs::read(&out)?, b"time_s,rate_dps\n");
//! // A failed write keeps what was there, and no partial file.
//! let failed = gyro_log::whole::write(&out, |_| Err(std::io::Error::other("no")));
//! assert!(failed.is_err());
//! assert_eq!(std::fs::read(&out)?, b"time_s,rate_dps\n");
//! assert_eq!(std::fs::read_dir(&dir)?.count(), 1);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// A partial file reserved beside its target: written by anything that takes a path, then
/// [`finish`](Self::finish)ed (renamed over the target) or [`discard`](Self::discard)ed.
#[derive(Debug)]
pub struct Partial {
    path: PathBuf,
    target: PathBuf,
    /// The target is a device or a pipe, written in place.
    in_place: bool,
}

/// True if `path` is a device, a pipe or a socket (after following links): a stream, not
/// a file whose content could be kept.
pub fn is_stream(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

impl Partial {
    /// Reserve a new, empty partial file in `target`'s folder: `NAME.partial.EXT` for
    /// `NAME.EXT` (the extension kept, so the format it names is the same), or
    /// `NAME.partial-2.EXT`, … if that exists: a file already there is never touched. A
    /// target that is a stream ([`is_stream`]) is its own partial file.
    pub fn beside(target: &Path) -> io::Result<Self> {
        if is_stream(target) {
            return Ok(Self {
                path: target.to_path_buf(),
                target: target.to_path_buf(),
                in_place: true,
            });
        }
        let stem = target
            .file_stem()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "not a file name"))?;
        let extension = target.extension();
        for attempt in 1..=100_u32 {
            let mut name = stem.to_os_string();
            name.push(".partial");
            if attempt > 1 {
                name.push(format!("-{attempt}"));
            }
            if let Some(extension) = extension {
                name.push(".");
                name.push(extension);
            }
            let path = target.with_file_name(name);
            match File::options().write(true).create_new(true).open(&path) {
                Ok(_) => {
                    return Ok(Self {
                        path,
                        target: target.to_path_buf(),
                        in_place: false,
                    })
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
        Err(io::Error::new(
            io::ErrorKind::AlreadyExists,
            "100 partial files are already beside it",
        ))
    }

    /// Where to write.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file it will replace.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flush the partial file to the disk and rename it over the target. On failure the
    /// partial file is removed.
    pub fn finish(self) -> io::Result<()> {
        if self.in_place {
            return Ok(());
        }
        let done = File::open(&self.path)
            .and_then(|file| file.sync_all())
            .and_then(|()| std::fs::rename(&self.path, &self.target));
        if done.is_err() {
            self.discard();
        }
        done
    }

    /// Remove the partial file (best effort: it is not the target).
    pub fn discard(self) {
        if !self.in_place {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Write `target` whole: `write` fills a partial file beside it ([`Partial`]), which then
/// replaces `target`. On any failure `target` is as it was and the partial file is gone.
pub fn write(
    target: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let partial = Partial::beside(target)?;
    let written = File::create(partial.path()).and_then(|file| {
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        out.flush()
    });
    match written {
        Ok(()) => partial.finish(),
        Err(e) => {
            partial.discard();
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
    use super::*;

    /// A fresh folder, removed when the guard is dropped.
    fn dir(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("gyro-log-whole-{name}-"))
            .tempdir()
            .unwrap()
    }

    #[test]
    fn partial_keeps_the_extension_and_never_takes_an_existing_name() {
        let scratch = dir("names");
        let dir = scratch.path();
        let target = dir.join("run.mcap");
        std::fs::write(dir.join("run.partial.mcap"), b"mine").unwrap();
        let partial = Partial::beside(&target).unwrap();
        assert_eq!(partial.path(), dir.join("run.partial-2.mcap"));
        assert_eq!(
            std::fs::read(dir.join("run.partial.mcap")).unwrap(),
            b"mine"
        );
        std::fs::write(partial.path(), b"new").unwrap();
        partial.finish().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let plain = Partial::beside(&dir.join("model")).unwrap();
        assert_eq!(plain.path(), dir.join("model.partial"));
        plain.discard();
        assert!(!dir.join("model.partial").exists());
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_failed_write_replaces_nothing() {
        let scratch = dir("failed");
        let dir = scratch.path();
        let target = dir.join("out.csv");
        std::fs::write(&target, b"before").unwrap();
        let e = write(&target, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(std::fs::read(&target).unwrap(), b"before");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
        write(&target, |w| w.write_all(b"after")).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"after");
        // A folder that does not exist: an error, nothing made.
        assert!(write(&dir.join("none/out.csv"), |w| w.write_all(b"x")).is_err());
        // A device is written in place, never renamed over.
        #[cfg(unix)]
        {
            let null = Path::new("/dev/null");
            assert!(is_stream(null));
            assert_eq!(Partial::beside(null).unwrap().path(), null);
            write(null, |w| w.write_all(b"x")).unwrap();
            assert!(is_stream(null));
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}
