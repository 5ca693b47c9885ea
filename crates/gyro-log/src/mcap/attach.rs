//! Attaching reference samples to rate rows by log time while the file streams by (the
//! rule is in the `read` module docs). A row waits until no unread reference can change
//! its value: the units are read in order of their first log time, so once a unit is done
//! every unread message is at or after the next unit's start (the *frontier*). In a file
//! whose channels share chunks in time order (as `convert` and `record` write them) a row
//! waits for at most its own chunk.

use crate::Row;
use std::collections::VecDeque;

/// Rows with their reference attached, in the order the rows came.
#[derive(Debug)]
pub(super) struct Attacher {
    /// Reference samples read and still useful, sorted by time (equal times in the order
    /// read).
    reference: VecDeque<(u64, Option<f64>)>,
    /// Rows waiting for their reference, with their time (ns).
    pending: VecDeque<(u64, Row)>,
    /// No unread reference is before this time (ns).
    frontier: u64,
    /// Longest interpolation span (ns).
    max_span_ns: u64,
    /// Unread rows are at or after the frontier (their time is their log time).
    rows_at_log_time: bool,
    /// Time of the last row released, and how many before it had the same time.
    previous: Option<u64>,
    same_time: usize,
    /// Most rows held at once.
    most_held: usize,
    /// Where the last row's search ended in `reference` (checked before use: rows in time
    /// order find theirs there or one further).
    hint: usize,
}

/// References this far (ns) before the earliest row still to come are kept when rows are
/// not stamped with their log time (ROS 2 header stamps): a row further back than that
/// behind the rows before it finds no reference.
const KEEP_BEHIND_NS: u64 = 60_000_000_000;

impl Attacher {
    pub fn new(max_span_s: f64) -> Self {
        Self {
            reference: VecDeque::new(),
            pending: VecDeque::new(),
            frontier: 0,
            max_span_ns: (max_span_s * 1e9) as u64,
            rows_at_log_time: true,
            previous: None,
            same_time: 0,
            most_held: 0,
            hint: 0,
        }
    }

    /// Rows are stamped with something other than their log time.
    pub fn rows_not_at_log_time(&mut self) {
        self.rows_at_log_time = false;
    }

    /// A reference sample (log time ns, angle).
    pub fn reference(&mut self, time_ns: u64, angle: Option<f64>) {
        // After every sample with the same time (usually at the end).
        if self.reference.back().is_none_or(|&(t, _)| t <= time_ns) {
            self.reference.push_back((time_ns, angle));
        } else {
            let at = self.reference.partition_point(|&(t, _)| t <= time_ns);
            self.reference.insert(at, (time_ns, angle));
        }
    }

    /// A row stamped `time_ns`.
    pub fn row(&mut self, time_ns: u64, row: Row) {
        self.pending.push_back((time_ns, row));
        self.most_held = self.most_held.max(self.pending.len());
    }

    /// A unit was read: no unread message is before `next_start_ns`. Drops the
    /// references no row to come can use.
    pub fn advance(&mut self, next_start_ns: u64) {
        self.frontier = next_start_ns;
        let mut earliest = self.pending.iter().map(|&(t, _)| t).min();
        if self.rows_at_log_time {
            earliest = Some(earliest.map_or(next_start_ns, |t| t.min(next_start_ns)));
        } else {
            let behind = self.previous.map(|t| t.saturating_sub(KEEP_BEHIND_NS));
            earliest = match (earliest, behind) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
        }
        // A reference more than the span before a row cannot be interpolated from.
        if let Some(earliest) = earliest {
            let keep_from = earliest.saturating_sub(self.max_span_ns);
            while self.reference.front().is_some_and(|&(t, _)| t < keep_from) {
                self.reference.pop_front();
                self.hint = self.hint.saturating_sub(1);
            }
        }
    }

    /// Rows held now, and at most so far.
    pub fn held(&self) -> (usize, usize) {
        (self.pending.len(), self.most_held)
    }

    /// The next row whose reference is decided, with it attached, and its time (ns).
    pub fn pop(&mut self) -> Option<(u64, Row)> {
        let &(t, _) = self.pending.front()?;
        let value = self.decide(t)?;
        let (t, mut row) = self.pending.pop_front()?;
        row.reference_deg = value;
        Some((t, row))
    }

    /// The index of the first reference at or after `t`: the hint, or the one after it, if
    /// it is that index; else a binary search.
    fn first_at_or_after(&self, t: u64) -> usize {
        let reference = &self.reference;
        let n = reference.len();
        let is_it = |i: usize| {
            (i == 0 || reference.get(i - 1).is_some_and(|&(r, _)| r < t))
                && (i == n || reference.get(i).is_some_and(|&(r, _)| r >= t))
        };
        let hint = self.hint.min(n);
        if is_it(hint) {
            hint
        } else if hint < n && is_it(hint + 1) {
            hint + 1
        } else {
            reference.partition_point(|&(r, _)| r < t)
        }
    }

    /// The reference of a row at `t`, or `None` if an unread reference could change it.
    fn decide(&mut self, t: u64) -> Option<Option<f64>> {
        if self.frontier <= t {
            return None; // a reference at exactly t may still come
        }
        let lo = self.first_at_or_after(t);
        self.hint = lo;
        let reference = &self.reference;
        let hi = lo + reference.range(lo..).take_while(|&&(r, _)| r == t).count();
        let same_time = if self.previous == Some(t) {
            self.same_time + 1
        } else {
            0
        };
        let value = if hi > lo {
            reference[lo + same_time.min(hi - lo - 1)].1
        } else {
            match lo.checked_sub(1).map(|i| reference[i]) {
                Some((t0, Some(v0))) => match reference.get(lo) {
                    // The nearest later reference is known.
                    Some(&(t1, v1)) if t1 < self.frontier => match v1 {
                        Some(v1) if t1 - t0 <= self.max_span_ns => {
                            let w = (t - t0) as f64 / (t1 - t0) as f64;
                            Some(v0 + w * (v1 - v0))
                        }
                        _ => None,
                    },
                    // Any later one is unread: decided only if it would be too far.
                    _ if self.frontier > t0.saturating_add(self.max_span_ns) => None,
                    _ => return None,
                },
                _ => None, // no earlier reference, or a null one: nothing to interpolate
            }
        };
        self.previous = Some(t);
        self.same_time = same_time;
        Some(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(line: u64) -> Row {
        Row {
            line,
            time_s: 0.0,
            rate_dps: Some(0.0),
            reference_deg: Some(-99.0),
            temperature_c: None,
        }
    }

    /// The rule of the whole-file reader, unit by unit: exact, k-th of equal times,
    /// interpolated within the span, else none; rows wait while a reference could come.
    #[test]
    fn reference_exact_interpolated_or_none_as_units_arrive() {
        let ms = 1_000_000;
        let mut a = Attacher::new(0.5);
        // Unit 1 (starts at 0): rows and references out of order inside it.
        for (i, t) in [0, 5 * ms, 10 * ms, 10 * ms, 15 * ms]
            .into_iter()
            .enumerate()
        {
            a.row(t, row(i as u64 + 1));
        }
        a.reference(10 * ms, Some(1.0));
        a.reference(10 * ms, Some(2.0));
        a.reference(0, Some(0.0));
        assert_eq!(a.pop(), None, "the frontier is still 0");
        // The next unit starts at 12 ms: rows up to 10 ms are decided.
        a.advance(12 * ms);
        let got: Vec<Option<f64>> = std::iter::from_fn(|| a.pop())
            .map(|(_, r)| r.reference_deg)
            .collect();
        assert_eq!(got, [Some(0.0), Some(0.5), Some(1.0), Some(2.0)]);
        // 15 ms waits: a reference may come between 12 and 15 ms.
        a.reference(20 * ms, None);
        a.advance(30 * ms);
        assert_eq!(a.pop().map(|(_, r)| r.reference_deg), Some(None)); // before a null
        a.row(900 * ms, row(6));
        a.reference(1000 * ms, Some(10.0));
        a.advance(1200 * ms);
        assert_eq!(a.pop().map(|(_, r)| r.reference_deg), Some(None)); // after a null
        a.reference(1400 * ms, Some(14.0));
        a.row(1500 * ms, row(7));
        a.advance(1800 * ms);
        assert_eq!(a.pop(), None, "a reference up to 1.9 s may still come");
        a.advance(1901 * ms);
        assert_eq!(a.pop().map(|(_, r)| r.reference_deg), Some(None)); // nothing within 0.5 s
        a.row(2000 * ms, row(8));
        a.reference(2050 * ms, Some(21.0));
        a.reference(1950 * ms, Some(19.0));
        a.advance(u64::MAX);
        assert_eq!(a.pop().map(|(_, r)| r.reference_deg), Some(Some(20.0)));
        assert_eq!(a.held(), (0, 5));
    }
}
