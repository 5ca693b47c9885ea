//! The diagnosis rendered: the HTML report of `diagnose --report DIR` ([`write_report`]) and
//! the text summary ([`table`], [`self_test_table`]).

mod headline;
mod html;
mod text;
mod words;

pub use headline::{
    clause, evidence, findings, headline, rounded, sentence, sig3, verdict, Findings, MISSED_LINES,
    NOT_SCORED,
};
pub use words::{described, missed, segment};

pub use html::{
    write_report, ReportError, GAP_MAP_CLIP, GAP_MAP_COLUMNS, MIN_BIN_SAMPLES, REPORT_FILES,
    WHERE_ROWS,
};
pub use text::{self_test_table, table};

use gyro_diagnose::Diagnosis;

/// `name` (a run's log path, as given) without the directory all of `d`'s runs share:
/// the report names runs relative to their input, and long absolute paths that differ
/// only in the file name are unreadable in a table.
pub fn run_label(d: &Diagnosis, name: &str) -> String {
    let dir = |n: &str| n.rfind(['/', '\\']).map_or(0, |i| i + 1);
    let Some(first) = d.runs.first() else {
        return name.to_string();
    };
    // The longest directory prefix (ending at a separator) common to every run.
    let mut common = &first.name[..dir(&first.name)];
    for r in &d.runs {
        while !r.name.starts_with(common) {
            common = &common[..dir(&common[..common.len().saturating_sub(1)])];
        }
    }
    name.strip_prefix(common).unwrap_or(name).to_string()
}

/// The files of `d`'s runs of `role` (`train`, `holdout`), each once, named as
/// [`run_label`] names them ("no run" for none): the windows of one file (`#1`, `#2`, …)
/// are one file.
pub fn run_files(d: &Diagnosis, role: &str) -> String {
    let mut files: Vec<&str> = d
        .runs
        .iter()
        .filter(|r| r.role == role)
        .map(|r| r.name.split('#').next().unwrap_or(&r.name))
        .collect();
    files.dedup();
    let names: Vec<String> = files.iter().map(|f| run_label(d, f)).collect();
    if names.is_empty() {
        "no run".into()
    } else {
        names.join(", ")
    }
}
