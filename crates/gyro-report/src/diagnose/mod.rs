//! The diagnosis rendered: the HTML report of `diagnose --report DIR` ([`write_report`]) and
//! the text summary ([`table`], [`self_test_table`]).

mod headline;
mod html;
mod text;

pub use headline::{evidence, headline, rounded, sentence, sig3};

pub use html::{
    write_report, ReportError, GAP_MAP_CLIP, GAP_MAP_COLUMNS, MIN_BIN_SAMPLES, REPORT_FILES,
    WHERE_ROWS,
};
pub use text::{self_test_table, table};
