//! One run given twice: the same file (by device and inode, whatever the spelling) twice in
//! one list of runs, or in two, would count as independent evidence twice, or score a fit
//! on the runs it was fitted to. The command line and the Python package refuse it alike.

use std::fs::Metadata;
use std::path::{Path, PathBuf};

/// A run given twice.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}: the same run as {} is given {}; give each run once", .path.display(), .first.display(), .where_)]
pub struct RepeatedRun {
    /// The path as given the second time.
    pub path: PathBuf,
    /// The path as given the first time.
    pub first: PathBuf,
    /// Where: "twice among the training runs", "among the training runs and again among
    /// the hold-out runs".
    pub where_: String,
}

/// Refuse a run given twice in `lists` (each a name, "training", "hold-out", and its
/// paths). A path that cannot be read is passed over: reading it reports the error.
pub fn refuse_repeated_runs(lists: &[(&str, &[PathBuf])]) -> Result<(), RepeatedRun> {
    let mut seen: Vec<(Metadata, &Path, &str)> = Vec::new();
    for (name, paths) in lists {
        for path in paths.iter() {
            let Ok(meta) = std::fs::metadata(path) else {
                continue;
            };
            if let Some((_, first, first_list)) =
                seen.iter().find(|(m, p, _)| same_file(m, &meta, p, path))
            {
                let where_ = if first_list == name {
                    format!("twice among the {name} runs")
                } else {
                    format!("among the {first_list} runs and again among the {name} runs")
                };
                return Err(RepeatedRun {
                    path: path.clone(),
                    first: first.to_path_buf(),
                    where_,
                });
            }
            seen.push((meta, path, name));
        }
    }
    Ok(())
}

/// True if `a` (of path `pa`) and `b` (of `pb`) are the same file.
#[cfg(unix)]
pub fn same_file(a: &Metadata, b: &Metadata, _pa: &Path, _pb: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// True if `a` (of path `pa`) and `b` (of `pb`) are the same file.
#[cfg(not(unix))]
pub fn same_file(_: &Metadata, _: &Metadata, pa: &Path, pb: &Path) -> bool {
    matches!((pa.canonicalize(), pb.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn the_same_file_by_another_spelling_is_refused() {
        let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let a = here.join("Cargo.toml");
        let b = here.join("src/../Cargo.toml");
        let c = here.join("src/lib.rs");
        let one = [a.clone(), c.clone()];
        let two = [b.clone()];
        assert!(refuse_repeated_runs(&[("training", &one)]).is_ok());
        let e = refuse_repeated_runs(&[("training", &one), ("hold-out", &two)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: the same run as {} is given among the training runs and again among the hold-out runs; give each run once",
                b.display(),
                a.display()
            )
        );
        let e = refuse_repeated_runs(&[("static", &[a.clone(), b.clone()])]).unwrap_err();
        assert!(e.to_string().contains("twice among the static runs"), "{e}");
    }
}
