//! The input-quality report every command that reads logs shows: what was read, on which
//! grid, and what was irregular ([`gyro_log::Quality`]), as text lines and as JSON.

use gyro_log::Quality;
use serde::Serialize;
use std::fmt::Write as _;

/// A rate in Hz to at most three decimals, without trailing zeros (`1000`, `108.509`).
pub(crate) fn hz(rate_hz: f64) -> String {
    let text = format!("{rate_hz:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The lines of the report (`input: …`, then arrival in bursts and the irregular lines,
/// if any), as `run`'s table prints them.
pub fn table(q: &Quality) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "input: {} rows -> {} samples at {} Hz ({}), effective {:.3} Hz",
        q.rows,
        q.slots,
        hz(q.sample_rate_hz),
        q.sample_rate_source,
        q.effective_rate_hz
    );
    if let Some(b) = &q.bursts {
        let _ = writeln!(
            s,
            "  rows arrive in bursts: {:.0}% of steps off the grid of the median step {:.1} ms \
             (mean {:.2} ms), {:.0}% of steps a repeated stamp; the integral of the rate \
             was resampled onto the grid, not placed row by row",
            100.0 * b.off_grid_share,
            1e3 * b.median_step_s,
            1e3 * b.mean_step_s,
            100.0 * b.repeated_stamp_share
        );
    }
    let issues: Vec<String> = [
        (q.duplicate_rows, "duplicate rows dropped"),
        (q.same_time_rows, "rows with a repeated time stamp"),
        (q.backward_steps, "steps back in time"),
        (q.jittered_steps, "jittered steps"),
        (q.gaps, "gaps"),
        (
            q.backlogs,
            "of them a stalled link's backlog (rows re-timed)",
        ),
        (q.retimed_rows, "rows re-timed"),
        (
            q.counter_wraps,
            "wraps of the time stamps' counter unwrapped",
        ),
        (q.missing_rate_rows, "missing rates"),
        (q.filled_slots, "samples interpolated"),
        (q.trimmed_slots, "samples trimmed at the ends"),
        (q.missing_reference_slots, "samples without reference"),
        (q.reference_jumps, "reference jumps re-based"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    if !issues.is_empty() {
        let _ = writeln!(
            s,
            "  irregular: {} (longest step {:.3} s)",
            issues.join(", "),
            q.longest_step_s
        );
        for (what, line) in q.examples.iter().take(5) {
            let _ = writeln!(s, "    line {line}: {what}");
        }
    }
    s
}

/// The reports of several logs, each under a `file:` line.
pub fn tables<'a>(inputs: impl IntoIterator<Item = (&'a str, &'a Quality)>) -> String {
    inputs
        .into_iter()
        .map(|(file, q)| format!("file: {file}\n{}", table(q)))
        .collect()
}

/// One log's report in JSON: `{"file": …, "input": {…}}` (the `input` object of `run`).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct InputJson<'a> {
    /// The log as named on the command line.
    pub file: &'a str,
    /// What was read and what was irregular.
    pub input: &'a Quality,
}
