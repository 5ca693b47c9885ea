//! Reference jumps: a reference angle that leaps by tens or hundreds of degrees within a
//! few samples while the gyro barely turns.
//!
//! Real references do this: a robot's or a motion-capture system's pose wraps at ±180°
//! (the cumulative angle then jumps by 360°), an Euler angle flips when another axis
//! passes 90°, an encoder counter overflows. Taken as motion, one such jump is a 360°
//! "error" in every score after it.
//!
//! A step whose reference change differs from the gyro's (the trapezoid of its rate over
//! the same time) by more than [`SUSPECT_DEG`], while the gyro turns by less than
//! [`GYRO_SHARE`] of that difference, is *suspect*; the slots of a stretch of suspect
//! steps are held back (a jump resampled onto a grid, or interpolated by the logger, is
//! spread over a few samples). When the stretch ends, it is a *jump* if its steps differ
//! from the gyro by more than [`REFERENCE_JUMP_DEG`] in all, the gyro again turning by
//! less than [`GYRO_SHARE`] of that: every reference value from the stretch on is
//! re-based so that over the stretch the reference follows the gyro. A jump within
//! [`WRAP_TOLERANCE_DEG`] of a whole number of turns is a wrap, and the reference after it
//! is re-based by exactly those turns: what the reference and the gyro each did over the
//! stretch (a pose that stops while a lagging gyro still turns, say) is then not traded
//! for the gyro's version. Otherwise, or when
//! the stretch outgrows [`MAX_HELD_SLOTS`], its slots go on as they were (motion the gyro
//! did not see is a finding, not a thing to hide). A gyro that clips falls that far behind
//! only under a turn many times its range; genuine motion moves both. Each jump is
//! counted ([`super::Quality::reference_jumps`]), shown with its line, and warned of.

use super::{Quality, Slot};

/// A stretch of suspect steps whose reference differs from the gyro's by more than this
/// in all (deg) is a jump.
pub const REFERENCE_JUMP_DEG: f64 = 90.0;
/// A step whose reference differs from the gyro's by more than this (deg) is suspect.
pub const SUSPECT_DEG: f64 = 10.0;
/// ... when the gyro turns by less than this share of the difference.
pub const GYRO_SHARE: f64 = 0.1;
/// A jump this close (deg) to a whole number of turns is a wrap of exactly those turns.
pub const WRAP_TOLERANCE_DEG: f64 = 10.0;
/// Longest stretch of suspect slots held back: a longer one is not a jump.
pub const MAX_HELD_SLOTS: usize = 16;

/// One held slot, with its step's reference-minus-gyro difference.
#[derive(Clone, Copy, Debug)]
struct Held {
    slot: Slot,
    mismatch_deg: f64,
}

/// The running state of the re-basing, slot by slot in grid order.
#[derive(Clone, Debug, Default)]
pub(crate) struct ReferenceJumps {
    /// Subtracted from every reference value from here on (deg).
    offset_deg: f64,
    /// The raw reference of the last slot that had one.
    last_raw_deg: Option<f64>,
    /// The gyro's turn since that slot (deg).
    gyro_since_deg: f64,
    /// Time and rate of the previous slot.
    previous: Option<(f64, f64)>,
    /// The suspect stretch held back, and the gyro's turn over it (deg).
    held: Vec<Held>,
    held_gyro_deg: f64,
    /// A suspect stretch outgrew the hold: its steps go on as motion until one is not
    /// suspect.
    drifting: bool,
    /// The largest jump (deg, by magnitude).
    largest_deg: f64,
    /// The first few jumps' notes, given to the report at the end (after the placement's
    /// own examples, in the same order however the slots were delivered).
    notes: Vec<(String, u64)>,
    /// Whether the reference turns the way the gyro does (suspect steps left out).
    sense: crate::sense::Sense,
}

impl ReferenceJumps {
    /// The next slot of the grid: `out` gets every slot whose reference is settled, in
    /// order (this one, or none while a suspect stretch is held, or the stretch and this
    /// one when it ends).
    pub(crate) fn push(
        &mut self,
        mut slot: Slot,
        quality: &mut Quality,
        out: &mut dyn FnMut(Slot),
    ) {
        if let Some((time_s, rate_dps)) = self.previous {
            self.gyro_since_deg += 0.5 * (rate_dps + slot.rate_dps) * (slot.time_s - time_s);
        }
        self.previous = Some((slot.time_s, slot.rate_dps));
        let Some(raw_deg) = slot.reference_deg else {
            if self.held.is_empty() {
                out(slot);
            } else {
                self.hold(slot, 0.0, quality, out);
            }
            return;
        };
        let gyro_deg = std::mem::take(&mut self.gyro_since_deg);
        let last_raw_deg = self.last_raw_deg.replace(raw_deg);
        let mismatch_deg = last_raw_deg.map_or(0.0, |last| (raw_deg - last) - gyro_deg);
        let suspect =
            mismatch_deg.abs() > SUSPECT_DEG && gyro_deg.abs() < GYRO_SHARE * mismatch_deg.abs();
        if !suspect {
            if let Some(last) = last_raw_deg {
                self.sense.step(slot.time_s, gyro_deg, raw_deg - last);
            }
        }
        if suspect && !self.drifting {
            self.held_gyro_deg += gyro_deg;
            self.hold(slot, mismatch_deg, quality, out);
            return;
        }
        self.drifting &= suspect;
        self.release(quality, out);
        slot.reference_deg = Some(raw_deg - self.offset_deg);
        out(slot);
    }

    /// The end of the slots: the held stretch decided and handed on, and the warning if
    /// there was any jump.
    pub(crate) fn finish(
        &mut self,
        path: &std::path::Path,
        quality: &mut Quality,
        out: &mut dyn FnMut(Slot),
    ) {
        self.release(quality, out);
        for (what, line) in self.notes.drain(..) {
            quality.note(&what, line);
        }
        quality.reference_correlation = self.sense.correlation();
        quality.reference_gain = self.sense.gain();
        quality.warnings.extend(
            self.sense
                .warning()
                .map(|w| format!("{}: {w}", path.display())),
        );
        if quality.reference_jumps > 0 {
            quality.warnings.push(format!(
                "{}: the reference jumps {} time(s) (largest {:+.1} deg) while the gyro barely turns: a pose that wraps or flips, or a counter that overflows, not motion; each later reference value is re-based by the jump, and over the jump the reference follows the gyro",
                path.display(),
                quality.reference_jumps,
                self.largest_deg
            ));
        }
    }

    fn hold(
        &mut self,
        slot: Slot,
        mismatch_deg: f64,
        quality: &mut Quality,
        out: &mut dyn FnMut(Slot),
    ) {
        self.held.push(Held { slot, mismatch_deg });
        if self.held.len() > MAX_HELD_SLOTS {
            // Too long for a jump: the stretch goes on as it was.
            self.drifting = true;
            self.release(quality, out);
        }
    }

    /// Decide the held stretch and hand its slots on (never a jump once it has outgrown
    /// the hold).
    fn release(&mut self, quality: &mut Quality, out: &mut dyn FnMut(Slot)) {
        if self.held.is_empty() {
            return;
        }
        let total: f64 = self.held.iter().map(|h| h.mismatch_deg).sum();
        let gyro = std::mem::take(&mut self.held_gyro_deg);
        let jump = !self.drifting
            && total.abs() > REFERENCE_JUMP_DEG
            && gyro.abs() < GYRO_SHARE * total.abs();
        if jump {
            quality.reference_jumps += 1;
            if total.abs() > self.largest_deg.abs() {
                self.largest_deg = total;
            }
            if self.notes.len() < super::regular::MAX_EXAMPLES {
                self.notes.push((
                    format!(
                        "reference jumps by {total:+.1} deg while the gyro turns {gyro:+.1} deg: later reference re-based"
                    ),
                    self.held[0].slot.line,
                ));
            }
        }
        // A wrap re-bases by whole turns: the held slots are spread over them in
        // proportion to their steps, so that the stretch ends on exactly that offset.
        let turns = (total / 360.0).round();
        let rebase = if jump && turns != 0.0 && (total - 360.0 * turns).abs() <= WRAP_TOLERANCE_DEG
        {
            360.0 * turns / total
        } else {
            1.0
        };
        for mut h in self.held.drain(..) {
            if jump {
                self.offset_deg += h.mismatch_deg * rebase;
            }
            if let Some(raw) = h.slot.reference_deg {
                h.slot.reference_deg = Some(raw - self.offset_deg);
            }
            out(h.slot);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slot(k: usize, rate_dps: f64, reference_deg: Option<f64>) -> Slot {
        Slot {
            time_s: k as f64 * 0.01,
            rate_dps,
            reference_deg,
            temperature_c: None,
            line: k as u64 + 2,
            filled: false,
        }
    }

    fn rebased(slots: &[(f64, Option<f64>)]) -> (Vec<Option<f64>>, Quality) {
        let mut q = Quality::default();
        let mut j = ReferenceJumps::default();
        let mut out = Vec::new();
        for (k, &(rate, reference)) in slots.iter().enumerate() {
            j.push(slot(k, rate, reference), &mut q, &mut |s| out.push(s));
        }
        j.finish(std::path::Path::new("jumps.csv"), &mut q, &mut |s| {
            out.push(s)
        });
        assert_eq!(out.len(), slots.len(), "every slot once");
        assert!(
            out.iter().enumerate().all(|(k, s)| s.line == k as u64 + 2),
            "in order"
        );
        (out.iter().map(|s| s.reference_deg).collect(), q)
    }

    /// A wrap of −360° interpolated over two samples at rest (the rasteiro pose) is one
    /// jump: the reference after it is back on its level, and the report says so.
    #[test]
    fn a_wrap_at_rest_is_one_jump_and_is_re_based() {
        let (out, q) = rebased(&[
            (0.0, Some(-0.01)),
            (0.0, Some(-0.01)),
            (0.0, Some(-180.0)),
            (0.0, Some(-360.01)),
            (0.0, Some(-360.01)),
        ]);
        for r in &out {
            assert!((r.unwrap_or(f64::NAN) + 0.01).abs() < 1e-9, "{out:?}");
        }
        assert_eq!(q.reference_jumps, 1);
        assert_eq!(q.examples.len(), 1);
        assert!(q.examples[0].0.contains("-360.0 deg"), "{:?}", q.examples);
        assert_eq!(q.examples[0].1, 4, "the line of the first jump step");
        assert!(
            q.warnings[0].contains("jumps 1 time(s)"),
            "{:?}",
            q.warnings
        );
    }

    /// Fast motion the gyro follows, a clipping gyro at a low rate, and missing
    /// reference values are not jumps; two separate wraps count twice.
    #[test]
    fn motion_clipping_and_gaps_are_not_jumps() {
        // 20 000 deg/s for a sample at 100 Hz: 200 deg per step, seen by both.
        let fast: Vec<(f64, Option<f64>)> =
            (0..5).map(|k| (20_000.0, Some(200.0 * k as f64))).collect();
        let (out, q) = rebased(&fast);
        assert_eq!(q.reference_jumps, 0);
        assert_eq!(out[4], Some(800.0));
        // A gyro clipped at 3 000 deg/s under a 15 000 deg/s turn: 30 of 150 deg per step.
        let clipped: Vec<(f64, Option<f64>)> =
            (0..5).map(|k| (3_000.0, Some(150.0 * k as f64))).collect();
        assert_eq!(rebased(&clipped).1.reference_jumps, 0);
        // No reference over a stretch: the gyro's turn is carried across it.
        let (out, q) = rebased(&[
            (100.0, Some(0.0)),
            (100.0, None),
            (100.0, None),
            (100.0, Some(3.0)),
        ]);
        assert_eq!(q.reference_jumps, 0);
        assert_eq!(out[3], Some(3.0));
        // Two wraps, one each way.
        let (out, q) = rebased(&[
            (0.0, Some(179.0)),
            (0.0, Some(-181.0)),
            (0.0, Some(-181.0)),
            (0.0, Some(179.0)),
        ]);
        assert_eq!(q.reference_jumps, 2);
        assert!(out.iter().all(|r| *r == Some(179.0)), "{out:?}");
    }

    /// A pose that wraps as it stops while a gyro that lags it still turns: the reference
    /// after the wrap keeps the pose's own value less 360°, not the gyro's.
    #[test]
    fn a_wrap_is_whole_turns_whatever_the_gyro_does_over_it() {
        let (out, q) = rebased(&[
            (0.0, Some(178.0)),
            (300.0, Some(180.0)),
            (200.0, Some(-180.0)),
            (100.0, Some(-180.0)),
            (0.0, Some(-180.0)),
        ]);
        assert_eq!(q.reference_jumps, 1);
        assert_eq!(out[1], Some(180.0));
        // The gyro turned 2.5 deg over the jump step; the pose none.
        assert!((out[4].unwrap() - 180.0).abs() < 1e-9, "{out:?}");
        // Not a whole turn: re-based by what the gyro did not see.
        let (out, q) = rebased(&[(0.0, Some(0.0)), (0.0, Some(250.0)), (0.0, Some(250.0))]);
        assert_eq!(q.reference_jumps, 1);
        assert_eq!(out[2], Some(0.0));
    }

    /// A wrap resampled onto a grid is spread over a few samples, one of them below the
    /// jump threshold: the whole stretch is one jump, and nothing of it is left as motion.
    /// A reference that drifts away from a still gyro for longer than a jump can take is
    /// left as it is (it is a finding, not a wrap).
    #[test]
    fn a_spread_wrap_is_whole_and_a_long_drift_is_not_a_wrap() {
        let (out, q) = rebased(&[
            (0.0, Some(-180.0)),
            (0.0, Some(-124.0)),
            (0.0, Some(56.0)),
            (0.0, Some(180.0)),
            (0.0, Some(180.0)),
        ]);
        assert_eq!(q.reference_jumps, 1);
        assert!(out.iter().all(|r| *r == Some(-180.0)), "{out:?}");
        let drift: Vec<(f64, Option<f64>)> =
            (0..40).map(|k| (0.0, Some(20.0 * k as f64))).collect();
        let (out, q) = rebased(&drift);
        assert_eq!(q.reference_jumps, 0);
        assert_eq!(out[39], Some(780.0));
    }
}
