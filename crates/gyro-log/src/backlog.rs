//! Rows a stalled link delivers together: re-timed over the stall, not counted twice.
//!
//! A logger that stamps rows on arrival (a PC reading USB, Bluetooth or a wireless link)
//! sees the link stall now and then: the sensor keeps sampling, and the rows it buffered
//! arrive together after the stall, a few milliseconds (or microseconds) apart. Stamped on
//! arrival, the stall's samples sit after it: the grid bridges the stall as a gap (the
//! rate interpolated across it) and then places the backlog's rows too, so the stall's
//! rotation counts twice (32° of a 90° turn for a 0.2 s stall at its peak rate).
//!
//! The retimer holds the rows after a gap until the count of rows catches up with the
//! sensor's *local period*, the mean step of the rows of the [`LOCAL_PERIOD_WINDOW_S`]
//! before the gap (steps of at most the gap threshold): the first row `n` rows after the
//! gap stamped at most `n` local periods after the row before it ends a *backlog*, and the
//! gap and its `n` rows share that span evenly. When the count does not catch up within
//! [`BACKLOG_HORIZON_S`] of the first row after the gap, samples were lost: the stamps stay
//! and the gap is bridged.
//!
//! Lost samples cannot pass for a backlog unless a row's delay exceeds anything the steps
//! show: `n` rows after a gap of `m` lost samples, the count catches up only if the row
//! before the gap was delayed by `m` periods more than the row reached, and a gap is at
//! least 1.5 periods (twice the 99th-percentile step for rows in bursts).
//!
//! The retimer works on the stamps made non-decreasing (a step back counts as no time);
//! rows it does not re-time keep their stamps as logged.

use crate::Row;
use std::collections::VecDeque;

/// How long after the first row that follows a gap the arrival count has to catch up with
/// the sensor's period before the gap counts as lost samples (s): a link's buffer drains
/// in a few tenths of a second (the rasteiro stall's 24 rows in 0.11 s).
pub const BACKLOG_HORIZON_S: f64 = 0.5;
/// The sensor's local period is the mean step over this long before a gap (s): the row
/// rate of a bursty log differs between rest and motion (9 against 12 ms on the rasteiro
/// recordings), so the log's mean step is not the period at the gap.
pub const LOCAL_PERIOD_WINDOW_S: f64 = 1.0;
/// Fewer steps than this before a gap give no local period: the gap is left as it is.
pub const MIN_LOCAL_STEPS: usize = 5;

/// Rows in, rows out, with the stamps of a backlog after a gap spread evenly over the gap
/// and the backlog (see the module docs).
#[derive(Debug)]
pub(crate) struct Retimer {
    gap_step_s: f64,
    /// Steps of at most `gap_step_s` between released rows (stamps made non-decreasing)
    /// within [`LOCAL_PERIOD_WINDOW_S`] of the last: (the later row's stamp, the step).
    recent: VecDeque<(f64, f64)>,
    /// The latest stamp released (non-decreasing).
    clock_s: Option<f64>,
    /// After a gap: the stamp of the row before it, the local period, and the span from
    /// that stamp to the first row after the gap.
    anchor: Option<(f64, f64, f64)>,
    /// The rows since the gap, held until the count catches up or the horizon passes.
    held: Vec<Row>,
    /// Gaps followed by a backlog, re-timed.
    pub(crate) backlogs: u64,
    /// Rows re-timed over those gaps.
    pub(crate) retimed_rows: u64,
}

impl Retimer {
    /// A retimer for a log whose steps over `gap_step_s` are gaps.
    pub(crate) fn new(gap_step_s: f64) -> Self {
        Self {
            gap_step_s,
            recent: VecDeque::new(),
            clock_s: None,
            anchor: None,
            held: Vec::new(),
            backlogs: 0,
            retimed_rows: 0,
        }
    }

    /// Take the next row; push the rows released, in order, onto `out`.
    pub(crate) fn push(&mut self, row: Row, out: &mut Vec<Row>) {
        if let Some((anchor_s, period_s, gap_s)) = self.anchor {
            // A backlog's rows arrive in order, give or take a jitter: a row stamped a gap
            // before the one held ahead of it makes that one a stamp out of line (a
            // corrupt 1e300 s), not the end of a stall, and nothing is re-timed.
            let out_of_line = self
                .held
                .last()
                .is_some_and(|last| last.time_s - row.time_s > self.gap_step_s);
            self.held.push(row);
            let count = self.held.len();
            let span_s = row.time_s.max(anchor_s) - anchor_s;
            if out_of_line {
                // released as stamped below
            } else if span_s <= count as f64 * period_s {
                for (k, held) in self.held.iter_mut().enumerate() {
                    held.time_s = anchor_s + span_s * (k + 1) as f64 / count as f64;
                }
                self.backlogs += 1;
                self.retimed_rows += count as u64;
            } else if span_s - gap_s < BACKLOG_HORIZON_S {
                return;
            }
            self.anchor = None;
            let held = std::mem::take(&mut self.held);
            for row in &held {
                self.release(*row, out);
            }
            self.held = held;
            self.held.clear();
            return;
        }
        if let Some(clock_s) = self.clock_s {
            if row.time_s - clock_s > self.gap_step_s && self.recent.len() >= MIN_LOCAL_STEPS {
                let sum_s: f64 = self.recent.iter().map(|&(_, step_s)| step_s).sum();
                let gap_s = row.time_s - clock_s;
                self.anchor = Some((clock_s, sum_s / self.recent.len() as f64, gap_s));
                self.held.push(row);
                return;
            }
        }
        self.release(row, out);
    }

    /// The end of the rows: release those held (a gap the count did not catch up with).
    pub(crate) fn finish(&mut self, out: &mut Vec<Row>) {
        self.anchor = None;
        let held = std::mem::take(&mut self.held);
        for row in held {
            self.release(row, out);
        }
    }

    fn release(&mut self, row: Row, out: &mut Vec<Row>) {
        let time_s = self.clock_s.map_or(row.time_s, |c| row.time_s.max(c));
        if let Some(clock_s) = self.clock_s {
            let step_s = time_s - clock_s;
            if step_s <= self.gap_step_s {
                self.recent.push_back((time_s, step_s));
            }
        }
        while self
            .recent
            .front()
            .is_some_and(|&(t, _)| t < time_s - LOCAL_PERIOD_WINDOW_S)
        {
            self.recent.pop_front();
        }
        self.clock_s = Some(time_s);
        out.push(row);
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
mod tests {
    use super::*;

    use crate::test_row as row;

    fn retimed(stamps: &[f64], gap_step_s: f64) -> (Vec<f64>, Retimer) {
        let mut r = Retimer::new(gap_step_s);
        let mut out = Vec::new();
        for (k, &t) in stamps.iter().enumerate() {
            r.push(row(k as u64 + 2, t), &mut out);
        }
        r.finish(&mut out);
        assert_eq!(out.len(), stamps.len(), "every row comes out once");
        assert!(out.windows(2).all(|w| w[0].line < w[1].line), "in order");
        (out.iter().map(|r| r.time_s).collect(), r)
    }

    #[test]
    fn a_backlog_shares_the_stall_evenly() {
        // Samples every 10 ms; the link stalls after the one of 0.19 s, and the five taken
        // during the stall (0.20-0.24 s) arrive 1 ms apart from 0.245 s; the next live one
        // arrives on time (0.25 s), and the count has caught up.
        let mut stamps: Vec<f64> = (0..20).map(|k| f64::from(k) * 0.01).collect();
        stamps.extend((0..5).map(|k| 0.245 + f64::from(k) * 0.001));
        stamps.extend((0..10).map(|k| 0.25 + f64::from(k) * 0.01));
        let (out, r) = retimed(&stamps, 0.015);
        assert_eq!((r.backlogs, r.retimed_rows), (1, 6));
        // The gap and its backlog share 0.19 s .. 0.25 s: the samples' own times.
        for k in 0..6_u32 {
            let expected = 0.19 + 0.01 * f64::from(k + 1);
            assert!((out[20 + k as usize] - expected).abs() < 1e-12, "{out:?}");
        }
        // The rows before and after keep their stamps.
        assert_eq!(&out[..20], &stamps[..20]);
        assert_eq!(&out[26..], &stamps[26..]);
    }

    #[test]
    fn a_long_stall_s_backlog_is_re_timed_too() {
        // A 0.7 s stall: its 70 samples and the 17 taken while they drain 2 ms apart
        // arrive after it; the count catches up 0.17 s after the first row, 0.87 s after
        // the row before the gap; then the rows arrive every 10 ms again.
        let mut stamps: Vec<f64> = (0..20).map(|k| f64::from(k) * 0.01).collect();
        let first_s = 0.19 + 0.7;
        stamps.extend((0..88).map(|k| first_s + f64::from(k) * 0.002));
        stamps.extend((1..20).map(|k| first_s + 0.174 + f64::from(k) * 0.01));
        let (out, r) = retimed(&stamps, 0.015);
        assert_eq!((r.backlogs, r.retimed_rows), (1, 88), "{out:?}");
        assert!(
            out.windows(2).all(|w| (w[1] - w[0] - 0.01).abs() < 2e-4),
            "{out:?}"
        );
    }

    #[test]
    fn lost_samples_keep_their_stamps() {
        // A 50 ms gap (4 samples lost), then the rows go on every 10 ms: no catching up.
        let mut stamps: Vec<f64> = (0..20).map(|k| f64::from(k) * 0.01).collect();
        stamps.extend((0..80).map(|k| 0.24 + f64::from(k) * 0.01));
        let (out, r) = retimed(&stamps, 0.015);
        assert_eq!(r.backlogs, 0);
        assert_eq!(out, stamps);
        // A gap at the end of the rows, or before enough steps: left as it is.
        let (out, r) = retimed(&[0.0, 0.01, 0.2, 0.201, 0.202], 0.015);
        assert_eq!((r.backlogs, out[2]), (0, 0.2));
    }

    #[test]
    fn a_stamp_out_of_line_is_not_a_backlog() {
        // One row stamped 1e300 s, the next back on time: no stall, nothing re-timed (the
        // grid then refuses the gap, naming the line).
        let mut stamps: Vec<f64> = (0..10).map(|k| f64::from(k) * 0.01).collect();
        stamps.extend([1e300, 0.10, 0.11]);
        let (out, r) = retimed(&stamps, 0.015);
        assert_eq!(r.backlogs, 0);
        assert_eq!(out, stamps);
    }

    #[test]
    fn steps_back_count_as_no_time() {
        // A step back inside the backlog: re-timed with the rest.
        let mut stamps: Vec<f64> = (0..10).map(|k| f64::from(k) * 0.01).collect();
        stamps.extend([0.13, 0.1305, 0.1302, 0.131, 0.132, 0.142, 0.152]);
        let (out, r) = retimed(&stamps, 0.015);
        assert_eq!(r.backlogs, 1, "{out:?}");
        assert!(out.windows(2).all(|w| w[1] >= w[0]), "{out:?}");
    }
}
