//! Time stamps from a tick counter that wraps, unwrapped.
//!
//! Loggers on small controllers stamp rows with a hardware counter: Arduino's `micros()`
//! is a 32-bit count of microseconds that wraps after 71.6 min, a 16-bit millisecond
//! tick wraps every 65.5 s, a 16-bit microsecond timer every 65.5 ms. Read as they are,
//! the stamps step back by the counter's span at each wrap, and the log is refused (a
//! step back longer than `max_gap_s`) or loses that time.
//!
//! A step back is a wrap when it is one of those spans exactly: both stamps lie within the
//! counter's range (`[0, M)` unsigned or `[−M/2, M/2)` signed, M the span in seconds), and
//! the later stamp plus M is after the earlier one by at most [`WRAP_STEP_LIMIT`] times
//! the recent mean step forward (over about [`STEP_MEMORY`] steps: rows that arrive in
//! bursts step 2–20 ms at 100 Hz). The spans known are 2^16 and 2^32 counts of 1 ns, 1 µs and
//! 1 ms ([`SPANS_S`]); the first wrap fixes the span, and every later step back that is
//! that span is unwrapped too. Anything else (a step back of another size, a counter
//! of another tick) is left to the placement rules: refused or counted as a step back.

use crate::Row;

/// The counters unwrapped: (bits, tick), shortest span first.
pub const COUNTERS: [(u32, &str); 5] = [(16, "µs"), (32, "ns"), (16, "ms"), (32, "µs"), (32, "ms")];

/// Their spans (s): 2^bits ticks.
pub const SPANS_S: [f64; 5] = [
    65_536e-6,
    4_294_967_296e-9,
    65_536e-3,
    4_294_967_296e-6,
    4_294_967_296e-3,
];

/// A wrap's step (the later stamp plus the span, minus the earlier) is at most this many
/// times the recent mean step forward.
pub const WRAP_STEP_LIMIT: f64 = 4.0;
/// The recent mean step forward is an exponential mean over about this many steps.
pub const STEP_MEMORY: f64 = 16.0;

/// The span of the counter that wraps between stamps `previous_s` and `next_s`, if the
/// step back is a wrap of one of `spans_s` where the steps forward are `mean_step_s` (see
/// the module docs).
pub fn wrap_span(previous_s: f64, next_s: f64, mean_step_s: f64, spans_s: &[f64]) -> Option<f64> {
    if !(next_s < previous_s && mean_step_s > 0.0) {
        return None;
    }
    spans_s.iter().copied().find(|&span| {
        let in_range = |t: f64| (0.0..span).contains(&t) || (-span / 2.0..span / 2.0).contains(&t);
        let step = next_s + span - previous_s;
        in_range(previous_s)
            && in_range(next_s)
            && step > 0.0
            && step <= WRAP_STEP_LIMIT * mean_step_s
    })
}

/// Rows in, rows out with their stamps unwrapped (see the module docs).
#[derive(Debug, Default)]
pub struct Unwrapper {
    /// The previous row's stamp as logged.
    previous_s: Option<f64>,
    /// The recent mean step forward between stamps as logged (0: none yet).
    mean_step_s: f64,
    /// The counter's span, once a wrap has shown it.
    span_s: Option<f64>,
    /// Added to every stamp: the spans of the wraps so far.
    offset_s: f64,
    /// Wraps unwrapped.
    pub wraps: u64,
    /// The line of the first.
    pub first_line: Option<u64>,
}

impl Unwrapper {
    /// `row`'s stamp unwrapped, in place.
    #[inline]
    pub fn unwrap(&mut self, row: &mut Row) {
        let logged_s = row.time_s;
        if let Some(previous_s) = self.previous_s {
            let step_s = logged_s - previous_s;
            if step_s > 0.0 {
                self.mean_step_s = if self.mean_step_s > 0.0 {
                    self.mean_step_s + (step_s - self.mean_step_s) * (1.0 / STEP_MEMORY)
                } else {
                    step_s
                };
            } else if step_s < 0.0 {
                self.step_back(previous_s, logged_s, row.line);
            }
        }
        if logged_s.is_finite() {
            self.previous_s = Some(logged_s);
        }
        row.time_s = logged_s + self.offset_s;
    }

    /// A step back from `previous_s` to `logged_s` (at `line`): a wrap, or not.
    #[cold]
    fn step_back(&mut self, previous_s: f64, logged_s: f64, line: u64) {
        let spans: &[f64] = match &self.span_s {
            Some(span) => std::slice::from_ref(span),
            None => &SPANS_S,
        };
        if let Some(span) = wrap_span(previous_s, logged_s, self.mean_step_s, spans) {
            self.span_s = Some(span);
            self.offset_s += span;
            self.wraps += 1;
            self.first_line.get_or_insert(line);
        }
    }

    /// The counter's span (s), once a wrap has shown it.
    pub fn span_s(&self) -> Option<f64> {
        self.span_s
    }
}

/// `log` with its stamps unwrapped, and what the unwrapping did (`wraps`, the span, the
/// first line): what placement reads, for writers that must keep the rows in time order
/// (`gyro-cli convert`: MCAP orders messages by their time).
pub fn unwrapped(log: &crate::Log) -> (crate::Log, Unwrapper) {
    let mut unwrapper = Unwrapper::default();
    let rows = log
        .rows
        .iter()
        .map(|&row| {
            let mut row = row;
            unwrapper.unwrap(&mut row);
            row
        })
        .collect();
    (
        crate::Log {
            rows,
            ..log.clone()
        },
        unwrapper,
    )
}

/// What `unwrapper` did, in words, or `None` if it unwrapped nothing: "time stamps wrap: a
/// 16-bit count of ms (65.536 s), 3 times, the first at line 905".
pub fn describe(unwrapper: &Unwrapper) -> Option<String> {
    let (span_s, line) = (unwrapper.span_s()?, unwrapper.first_line?);
    Some(format!(
        "time stamps wrap: {}, {} time(s), the first at line {line}",
        describe_span(span_s),
        unwrapper.wraps
    ))
}

/// What a counter's span is, in words: `a 32-bit count of µs (4294.967296 s)`.
pub fn describe_span(span_s: f64) -> String {
    match SPANS_S.iter().position(|&s| s == span_s) {
        Some(i) => {
            let (bits, tick) = COUNTERS[i];
            format!("a {bits}-bit count of {tick} ({span_s} s)")
        }
        None => format!("a counter of {span_s} s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_row as row;

    /// Stamps of a counter of `span_s` that starts at `start_s`, every `step_s`.
    fn counter(start_s: f64, step_s: f64, n: usize, span_s: f64) -> Vec<f64> {
        (0..n)
            .map(|i| (start_s + i as f64 * step_s).rem_euclid(span_s))
            .collect()
    }

    fn unwrap_all(stamps: &[f64]) -> (Vec<f64>, Unwrapper) {
        let mut u = Unwrapper::default();
        let out = stamps
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                let mut r = row(i as u64 + 1, t);
                u.unwrap(&mut r);
                r.time_s
            })
            .collect();
        (out, u)
    }

    #[test]
    fn every_known_counter_is_unwrapped_to_the_time_it_counts() {
        // (span, step, start): a 16-bit µs timer at 1 kHz wraps every 66 rows; Arduino's
        // micros() after 71.6 min; a 16-bit ms tick; a 32-bit ms count.
        for (span, step, start) in [
            (SPANS_S[0], 1e-3, 0.0),
            (SPANS_S[1], 1e-3, 4.0),
            (SPANS_S[2], 0.01, 60.0),
            (SPANS_S[3], 0.01, 4290.0),
            (SPANS_S[4], 1.0, 4_294_900.0),
        ] {
            let n = 2000;
            let (out, u) = unwrap_all(&counter(start, step, n, span));
            for (i, t) in out.iter().enumerate() {
                let truth = start + i as f64 * step;
                assert!(
                    (t - truth).abs() < 1e-6 * truth.max(1.0),
                    "{span} {i}: {t} {truth}"
                );
            }
            assert!(u.wraps >= 1, "{span}");
            assert_eq!(u.span_s(), Some(span));
        }
    }

    #[test]
    fn a_signed_counter_is_unwrapped_too() {
        // A signed 32-bit µs count: from +2147.48 s to −2147.48 s.
        let half = SPANS_S[3] / 2.0;
        let stamps = [half - 0.02, half - 0.01, -half + 0.0, -half + 0.01];
        let (out, u) = unwrap_all(&stamps);
        assert_eq!(u.wraps, 1);
        assert!((out[2] - (half - 0.0 + 0.0)).abs() < 1e-6, "{out:?}");
        assert!((out[3] - out[2] - 0.01).abs() < 1e-6, "{out:?}");
    }

    #[test]
    fn other_steps_back_are_left_as_they_are() {
        // A PC log stepping back 64 ms at 100 s: beyond a 16-bit µs timer's range.
        let (out, u) = unwrap_all(&[99.998, 99.999, 100.0, 99.936, 99.937]);
        assert_eq!((u.wraps, out[3]), (0, 99.936));
        // Within a counter's range, but a step back that is not its span.
        let (_, u) = unwrap_all(&[10.0, 10.01, 10.02, 3.0, 3.01]);
        assert_eq!(u.wraps, 0);
        // A wrap whose step is more than 4 steps forward: lost samples, not unwrapped.
        let (_, u) = unwrap_all(&[65.50, 65.51, 65.52, 0.04]);
        assert_eq!(u.wraps, 0);
        // A step back right after the first row: no step forward to judge it by.
        let (_, u) = unwrap_all(&[65.53, 0.001]);
        assert_eq!(u.wraps, 0);
        // Once the span is known, only it is unwrapped.
        let mut stamps = counter(60.0, 0.01, 1000, SPANS_S[2]);
        stamps.extend([30.0, 30.01]);
        let (_, u) = unwrap_all(&stamps);
        assert_eq!(u.wraps, 1);
    }

    #[test]
    fn the_spans_are_the_counters_ticks() {
        for ((bits, tick), span) in COUNTERS.iter().zip(SPANS_S) {
            let tick_s = match *tick {
                "ns" => 1e-9,
                "µs" => 1e-6,
                _ => 1e-3,
            };
            assert!((span - 2f64.powi(*bits as i32) * tick_s).abs() < 1e-12 * span);
        }
    }

    #[test]
    fn spans_are_described() {
        assert_eq!(
            describe_span(SPANS_S[3]),
            "a 32-bit count of µs (4294.967296 s)"
        );
        assert_eq!(
            describe_span(SPANS_S[0]),
            "a 16-bit count of µs (0.065536 s)"
        );
    }
}
