//! CSV logs: `# key: value` metadata lines, a header, one row per sample.

use super::{Log, LogError, Row};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// Unit of the time column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TimeUnit {
    /// Seconds.
    #[default]
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
    /// Nanoseconds.
    Ns,
}

impl TimeUnit {
    fn to_seconds(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
            TimeUnit::Ns => 1e-9,
        }
    }
}

/// Unit of the rate column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum RateUnit {
    /// Degrees per second.
    #[default]
    Dps,
    /// Radians per second.
    Rads,
}

/// Which columns hold what, and in which units.
#[derive(Clone, Debug, PartialEq, Eq, clap::Args)]
pub struct ColumnOptions {
    /// Name of the time column.
    #[arg(long, default_value = "time_s")]
    pub time_column: String,
    /// Unit of the time column.
    #[arg(long, value_enum, default_value_t = TimeUnit::S)]
    pub time_unit: TimeUnit,
    /// Name of the rate column.
    #[arg(long, default_value = "rate_dps")]
    pub rate_column: String,
    /// Unit of the rate column.
    #[arg(long, value_enum, default_value_t = RateUnit::Dps)]
    pub rate_unit: RateUnit,
    /// Name of the reference (encoder) angle column, in degrees; optional in the log.
    #[arg(long, default_value = "reference_deg")]
    pub reference_column: String,
    /// Name of the temperature column, in °C; optional in the log.
    #[arg(long, default_value = "temperature_c")]
    pub temperature_column: String,
}

impl Default for ColumnOptions {
    fn default() -> Self {
        Self {
            time_column: "time_s".into(),
            time_unit: TimeUnit::S,
            rate_column: "rate_dps".into(),
            rate_unit: RateUnit::Dps,
            reference_column: "reference_deg".into(),
            temperature_column: "temperature_c".into(),
        }
    }
}

/// Parse a field: `Ok(None)` if empty, NaN or infinite (a missing value), an error if it
/// is not a number at all.
fn parse_field(field: &[u8]) -> Result<Option<f64>, ()> {
    if let Some(value) = parse_plain_decimal(field) {
        return Ok(Some(value));
    }
    let text = std::str::from_utf8(field).map_err(|_| ())?.trim();
    if text.is_empty() {
        return Ok(None);
    }
    let value: f64 = text.parse().map_err(|_| ())?;
    Ok(value.is_finite().then_some(value))
}

/// The fast path of [`parse_field`], for what loggers write: `[-]digits[.digits]` whose
/// digits, read as an integer `m`, are at most 2^53, with at most 22 decimals `k`. Then
/// `m` and `10^k` are exact doubles, and their quotient, correctly rounded, is the
/// decimal correctly rounded: what `str::parse` returns (its own fast path, Clinger's).
/// `None` for anything else (a `+`, an exponent, spaces, `nan`, more digits…), which the
/// general path decides.
fn parse_plain_decimal(field: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, digits) = match field.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, field),
    };
    let mut mantissa = 0_u64;
    let mut count = 0_usize;
    let mut decimals: Option<usize> = None;
    for (i, &b) in digits.iter().enumerate() {
        match b {
            b'0'..=b'9' => {
                count += 1;
                if count > 19 {
                    return None;
                }
                mantissa = mantissa * 10 + u64::from(b - b'0');
            }
            b'.' if decimals.is_none() => decimals = Some(digits.len() - i - 1),
            _ => return None,
        }
    }
    if count == 0 || mantissa > 1 << 53 {
        return None;
    }
    let value = mantissa as f64 / *POW10.get(decimals.unwrap_or(0))?;
    Some(if negative { -value } else { value })
}

/// A CSV log opened for reading row by row: metadata and header read, rows on demand.
///
/// [`read_csv`] collects every row; `gyro-cli run` streams them
/// ([`super::place`]) so that memory stays bounded however long the log.
pub struct CsvRows {
    path: PathBuf,
    metadata: BTreeMap<String, String>,
    csv: csv::Reader<BufReader<File>>,
    record: csv::ByteRecord,
    prelude_lines: u64,
    time_idx: usize,
    rate_idx: usize,
    reference_idx: Option<usize>,
    temperature_idx: Option<usize>,
    time_scale: f64,
    rate_scale: f64,
    columns: ColumnOptions,
    done: bool,
}

impl CsvRows {
    /// Open `path`, read its metadata lines and header, and find the columns.
    pub fn open(path: &Path, columns: &ColumnOptions) -> Result<Self, LogError> {
        let io_err = |cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let file = File::open(path).map_err(io_err)?;
        let mut reader = BufReader::with_capacity(1 << 20, file);

        // Metadata: `# key: value` lines before the header.
        let mut metadata = BTreeMap::new();
        let mut prelude_lines = 0_u64;
        loop {
            let buf = reader.fill_buf().map_err(io_err)?;
            if buf.first() != Some(&b'#') {
                break;
            }
            let mut line = String::new();
            reader.read_line(&mut line).map_err(io_err)?;
            prelude_lines += 1;
            if let Some((key, value)) = line.trim_start_matches('#').split_once(':') {
                metadata.insert(key.trim().to_string(), value.trim().to_string());
            }
        }

        let mut csv = csv::ReaderBuilder::new()
            .has_headers(true)
            .comment(Some(b'#'))
            .from_reader(reader);
        let header_line = prelude_lines + 1;
        let headers = csv
            .byte_headers()
            .map_err(|e| csv_error(path, prelude_lines, e))?
            .clone();
        if headers.is_empty() || headers.iter().all(|h| h.is_empty()) {
            return Err(LogError::NoHeader {
                path: path.to_path_buf(),
            });
        }
        let names: Vec<String> = headers
            .iter()
            .map(|h| String::from_utf8_lossy(h).trim().to_string())
            .collect();
        let find = |name: &str| names.iter().position(|n| n == name);
        let required = |name: &str| {
            find(name).ok_or_else(|| LogError::MissingColumn {
                path: path.to_path_buf(),
                line: header_line,
                column: name.to_string(),
                available: names.join(", "),
            })
        };
        let time_idx = required(&columns.time_column)?;
        let rate_idx = required(&columns.rate_column)?;
        let reference_idx = find(&columns.reference_column);
        let temperature_idx = find(&columns.temperature_column);
        let time_scale = columns.time_unit.to_seconds();
        let rate_scale = match columns.rate_unit {
            RateUnit::Dps => 1.0,
            RateUnit::Rads => 180.0 / std::f64::consts::PI,
        };
        Ok(Self {
            path: path.to_path_buf(),
            metadata,
            csv,
            record: csv::ByteRecord::new(),
            prelude_lines,
            time_idx,
            rate_idx,
            reference_idx,
            temperature_idx,
            time_scale,
            rate_scale,
            columns: columns.clone(),
            done: false,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The `# key: value` metadata lines before the header.
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.metadata
    }

    /// True if the header has the reference column.
    pub fn has_reference(&self) -> bool {
        self.reference_idx.is_some()
    }

    /// True if the header has the temperature column.
    pub fn has_temperature(&self) -> bool {
        self.temperature_idx.is_some()
    }

    /// The next row; `Ok(None)` at the end of the file. After an error, the end.
    pub fn next_row(&mut self) -> Result<Option<Row>, LogError> {
        if self.done {
            return Ok(None);
        }
        let row = self.read_row();
        if !matches!(row, Ok(Some(_))) {
            self.done = true;
        }
        row
    }

    fn read_row(&mut self) -> Result<Option<Row>, LogError> {
        let path = self.path.as_path();
        match self.csv.read_byte_record(&mut self.record) {
            Ok(false) => return Ok(None),
            Ok(true) => {}
            Err(e) => return Err(csv_error(path, self.prelude_lines, e)),
        }
        let record = &self.record;
        let line = self.prelude_lines + record.position().map_or(0, |p| p.line());
        let field = |idx: usize, column: &str| -> Result<Option<f64>, LogError> {
            let raw = record.get(idx).unwrap_or_default();
            parse_field(raw).map_err(|()| LogError::NotANumber {
                path: path.to_path_buf(),
                line,
                column: column.to_string(),
                value: String::from_utf8_lossy(raw).into_owned(),
            })
        };
        let columns = &self.columns;
        let time_s = field(self.time_idx, &columns.time_column)?
            .map(|t| t * self.time_scale)
            .ok_or_else(|| LogError::BadTime {
                path: path.to_path_buf(),
                line,
                column: columns.time_column.clone(),
            })?;
        let rate_dps = field(self.rate_idx, &columns.rate_column)?.map(|r| r * self.rate_scale);
        let reference_deg = match self.reference_idx {
            Some(idx) => field(idx, &columns.reference_column)?,
            None => None,
        };
        let temperature_c = match self.temperature_idx {
            Some(idx) => field(idx, &columns.temperature_column)?,
            None => None,
        };
        Ok(Some(Row {
            line,
            time_s,
            rate_dps,
            reference_deg,
            temperature_c,
        }))
    }
}

impl Iterator for CsvRows {
    type Item = Result<Row, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_row().transpose()
    }
}

/// Read a CSV log whole.
pub fn read_csv(path: &Path, columns: &ColumnOptions) -> Result<Log, LogError> {
    let mut reader = CsvRows::open(path, columns)?;
    let mut rows = Vec::new();
    while let Some(row) = reader.next_row()? {
        rows.push(row);
    }
    Ok(Log {
        path: reader.path,
        has_reference: reader.reference_idx.is_some(),
        has_temperature: reader.temperature_idx.is_some(),
        metadata: reader.metadata,
        rows,
    })
}

fn csv_error(path: &Path, prelude_lines: u64, e: csv::Error) -> LogError {
    let line = prelude_lines + e.position().map_or(0, |p| p.line());
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("row has {len} fields, the header has {expected_len}"),
        csv::ErrorKind::Io(err) => format!("read error: {err}"),
        _ => e.to_string(),
    };
    LogError::Csv {
        path: path.to_path_buf(),
        line,
        message,
    }
}

/// Write `log` as CSV in the shared format (metadata lines, header, rows). Columns:
/// `time_s,rate_dps`, plus `temperature_c` and `reference_deg` if the log has them.
pub fn write_csv(out: &mut impl std::io::Write, log: &Log) -> std::io::Result<()> {
    for (key, value) in &log.metadata {
        writeln!(out, "# {key}: {value}")?;
    }
    let mut header = String::from("time_s,rate_dps");
    if log.has_temperature {
        header.push_str(",temperature_c");
    }
    if log.has_reference {
        header.push_str(",reference_deg");
    }
    writeln!(out, "{header}")?;
    // Shortest round-trip formatting: every f64 reads back exactly (CSV → MCAP → CSV is
    // lossless), and values written with few digits keep them.
    let field = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v}"));
    for row in &log.rows {
        write!(out, "{},{}", row.time_s, field(row.rate_dps))?;
        if log.has_temperature {
            write!(out, ",{}", field(row.temperature_c))?;
        }
        if log.has_reference {
            write!(out, ",{}", field(row.reference_deg))?;
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn write_temp(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("gyro-csv-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::File::create(&path)
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
        path
    }

    #[test]
    fn reads_metadata_header_and_rows() {
        let path = write_temp(
            "ok.csv",
            "# sensor: CRM100\n# sample_rate_hz: 1000\ntime_s,rate_dps,temperature_c,reference_deg,extra\n0.000,0.125,25.1,0.00,x\n0.001,,25.1,0.01,y\n0.002,nan,25.1,,z\n",
        );
        let log = read_csv(&path, &ColumnOptions::default()).unwrap();
        assert_eq!(log.metadata["sensor"], "CRM100");
        assert_eq!(log.metadata_rate_hz(), Some(1000.0));
        assert!(log.has_reference && log.has_temperature);
        assert_eq!(log.rows.len(), 3);
        assert_eq!(log.rows[0].line, 4);
        assert_eq!(log.rows[0].rate_dps, Some(0.125));
        assert_eq!(log.rows[1].rate_dps, None);
        assert_eq!(log.rows[2].rate_dps, None);
        assert_eq!(log.rows[2].reference_deg, None);
        assert_eq!(log.rows[2].line, 6);
    }

    #[test]
    fn plain_decimal_fast_path_equals_str_parse() {
        let cases = [
            "0",
            "-0",
            "0.000",
            "-0.000",
            "1.",
            ".5",
            "-.5",
            "123.456",
            "0.001",
            "-0.125",
            "9007199254740992",
            "9007199254740993",
            "0.1234567890123456789",
            "1234567890123456789",
            "12345678901234567890",
            "0.0000000000000000000001",
            "1.00000000000000000000001",
            "3600.000000",
            "-299.99999",
        ];
        for text in cases {
            let fast = parse_plain_decimal(text.as_bytes());
            let std: f64 = text.parse().unwrap();
            if let Some(fast) = fast {
                assert_eq!(fast.to_bits(), std.to_bits(), "{text}");
            }
        }
        for text in [
            "", "-", ".", "1.2.3", "+1", "1e3", " 1", "1 ", "nan", "inf", "1-", "--1",
        ] {
            assert_eq!(parse_plain_decimal(text.as_bytes()), None, "{text}");
        }
        assert_eq!(parse_plain_decimal(b"0.001"), Some(0.001));
        assert_eq!(
            parse_plain_decimal(b"-0").map(f64::is_sign_negative),
            Some(true)
        );
    }

    proptest::proptest! {
        #[test]
        fn plain_decimals_parse_like_str_parse(
            negative: bool,
            int in 0_u64..100_000_000,
            frac in proptest::collection::vec(0_u8..10, 0..14),
            dot: bool,
        ) {
            let mut text = String::new();
            if negative {
                text.push('-');
            }
            text.push_str(&int.to_string());
            if dot || !frac.is_empty() {
                text.push('.');
            }
            for d in &frac {
                text.push(char::from(b'0' + d));
            }
            let std: f64 = text.parse().unwrap();
            let fast = parse_plain_decimal(text.as_bytes());
            // Up to 15 digits always take the fast path; more may not (then `None`).
            let digits = text.bytes().filter(u8::is_ascii_digit).count();
            proptest::prop_assert!(fast.is_some() || digits > 15, "{}", text);
            if let Some(fast) = fast {
                proptest::prop_assert_eq!(fast.to_bits(), std.to_bits(), "{}", text);
            }
        }
    }

    #[test]
    fn units_are_converted() {
        let path = write_temp("units.csv", "t_ms,w\n1000,3.141592653589793\n");
        let columns = ColumnOptions {
            time_column: "t_ms".into(),
            time_unit: TimeUnit::Ms,
            rate_column: "w".into(),
            rate_unit: RateUnit::Rads,
            ..ColumnOptions::default()
        };
        let log = read_csv(&path, &columns).unwrap();
        assert_eq!(log.rows[0].time_s, 1.0);
        assert!((log.rows[0].rate_dps.unwrap() - 180.0).abs() < 1e-9);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let path = write_temp("bad.csv", "# a: b\ntime_s,rate_dps\n0.0,1.0\n0.001,abc\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("bad.csv:4: column `rate_dps`: `abc` is not a number"),
            "{err}"
        );

        let path = write_temp("nocol.csv", "time_s,gyro\n0.0,1.0\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("nocol.csv:1: no column `rate_dps`"), "{err}");
        assert!(err.contains("time_s, gyro"), "{err}");

        let path = write_temp("ragged.csv", "time_s,rate_dps\n0.0,1.0\n0.001,1.0,7\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("ragged.csv:3: row has 3 fields, the header has 2"),
            "{err}"
        );

        let path = write_temp("notime.csv", "time_s,rate_dps\n,1.0\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("notime.csv:2: missing or non-finite time"),
            "{err}"
        );

        let err = read_csv(Path::new("/nonexistent/x.csv"), &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/x.csv"), "{err}");
    }

    #[test]
    fn write_then_read_round_trips() {
        let path = write_temp("rt.csv", "# sample_rate_hz: 100\ntime_s,rate_dps,temperature_c,reference_deg\n0.000000,0.12500,25.100,1.00000\n0.010000,,25.200,\n");
        let log = read_csv(&path, &ColumnOptions::default()).unwrap();
        let mut out = Vec::new();
        write_csv(&mut out, &log).unwrap();
        let again = write_temp("rt2.csv", std::str::from_utf8(&out).unwrap());
        let back = read_csv(&again, &ColumnOptions::default()).unwrap();
        assert_eq!(back.rows.len(), 2);
        for (a, b) in log.rows.iter().zip(&back.rows) {
            assert_eq!(
                (a.time_s, a.rate_dps, a.reference_deg, a.temperature_c),
                (b.time_s, b.rate_dps, b.reference_deg, b.temperature_c)
            );
        }
        assert_eq!(back.metadata, log.metadata);
    }
}
