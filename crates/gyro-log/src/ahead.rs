//! Read rows ahead on a second thread: parsing a CSV log is most of the work of `run`, and
//! the grid and the pipeline can take the rows as they come.

use super::{LogError, Row};
use std::sync::mpsc::{sync_channel, IntoIter, Receiver};
use std::sync::Mutex;

/// Rows per batch sent between the threads.
const BATCH_ROWS: usize = 4096;
/// Batches in flight (the memory held: about `BATCH_ROWS * (BATCHES + 2)` rows).
const BATCHES: usize = 8;

type Batch = Result<Vec<Row>, LogError>;

/// Call `consume` with the rows of `rows`, read on a second thread in batches, in order;
/// an error ends them. If the thread cannot be started, the rows are read on this one.
/// `consume` may stop early: the reader stops too.
pub fn read_ahead<I, R>(
    rows: I,
    consume: impl FnOnce(&mut dyn Iterator<Item = Result<Row, LogError>>) -> R,
) -> R
where
    I: Iterator<Item = Result<Row, LogError>> + Send,
{
    let source = Mutex::new(Some(rows));
    let source = &source;
    std::thread::scope(|scope| {
        let (sender, receiver) = sync_channel::<Batch>(BATCHES);
        let reader = std::thread::Builder::new()
            .name("gyro-read-ahead".into())
            .spawn_scoped(scope, move || {
                let Some(mut rows) = source.lock().ok().and_then(|mut s| s.take()) else {
                    return;
                };
                loop {
                    let mut batch = Vec::with_capacity(BATCH_ROWS);
                    let mut end = None;
                    for row in rows.by_ref() {
                        match row {
                            Ok(row) => batch.push(row),
                            Err(e) => {
                                end = Some(e);
                                break;
                            }
                        }
                        if batch.len() == BATCH_ROWS {
                            break;
                        }
                    }
                    let last = end.is_some() || batch.len() < BATCH_ROWS;
                    if !batch.is_empty() && sender.send(Ok(batch)).is_err() {
                        return; // the consumer stopped
                    }
                    if let Some(e) = end {
                        let _ = sender.send(Err(e));
                    }
                    if last {
                        return;
                    }
                }
            });
        match reader {
            Ok(_) => consume(&mut Batches::new(receiver)),
            // The closure, and the sender with it, are dropped.
            Err(_) => match source.lock().ok().and_then(|mut s| s.take()) {
                Some(mut rows) => consume(&mut rows),
                None => consume(&mut std::iter::empty()),
            },
        }
        // The receiver is dropped with the iterator: a reader still sending stops.
    })
}

/// The rows of the batches received, in order.
struct Batches {
    batches: IntoIter<Batch>,
    current: std::vec::IntoIter<Row>,
}

impl Batches {
    fn new(receiver: Receiver<Batch>) -> Self {
        Self {
            batches: receiver.into_iter(),
            current: Vec::new().into_iter(),
        }
    }
}

impl Iterator for Batches {
    type Item = Result<Row, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(row) = self.current.next() {
                return Some(Ok(row));
            }
            match self.batches.next()? {
                Ok(batch) => self.current = batch.into_iter(),
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn row(i: usize) -> Row {
        Row {
            line: i as u64,
            time_s: i as f64,
            rate_dps: Some(1.0),
            reference_deg: None,
            temperature_c: None,
        }
    }

    fn bad(line: u64) -> LogError {
        LogError::BadTime {
            path: PathBuf::from("x.csv"),
            line,
            column: "time_s".into(),
        }
    }

    #[test]
    fn rows_arrive_in_order_with_the_error_last() {
        for n in [
            0,
            1,
            BATCH_ROWS - 1,
            BATCH_ROWS,
            BATCH_ROWS + 1,
            5 * BATCH_ROWS + 7,
        ] {
            let rows = (0..n).map(|i| Ok(row(i)));
            let got: Vec<u64> = read_ahead(rows, |it| it.map(|r| r.unwrap().line).collect());
            assert_eq!(got, (0..n as u64).collect::<Vec<_>>());

            let rows = (0..n)
                .map(|i| Ok(row(i)))
                .chain(std::iter::once(Err(bad(7))))
                .chain((0..10).map(|i| Ok(row(i))));
            let got: Vec<String> = read_ahead(rows, |it| {
                it.map(|r| r.map_or_else(|e| e.to_string(), |r| r.line.to_string()))
                    .collect()
            });
            assert_eq!(got.len(), n + 1, "rows after the error are not read");
            assert!(got[n].contains("x.csv:7:"), "{:?}", got[n]);
        }
    }

    #[test]
    fn the_consumer_may_stop_early() {
        let rows = (0..100 * BATCH_ROWS).map(|i| Ok(row(i)));
        let got = read_ahead(rows, |it| it.take(3).count());
        assert_eq!(got, 3);
    }
}
