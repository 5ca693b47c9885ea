//! CSV logs: `# key: value` metadata lines, a header, one row per sample.

use super::{Log, LogError, Row};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Unit of the time column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum RateUnit {
    /// Degrees per second.
    #[default]
    Dps,
    /// Radians per second.
    Rads,
}

/// Which columns hold what, and in which units.
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ColumnOptions {
    /// Name of the time column.
    #[cfg_attr(feature = "clap", arg(long, default_value = "time_s"))]
    pub time_column: String,
    /// Unit of the time column.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = TimeUnit::S))]
    pub time_unit: TimeUnit,
    /// Name of the rate column.
    #[cfg_attr(feature = "clap", arg(long, default_value = "rate_dps"))]
    pub rate_column: String,
    /// Unit of the rate column.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = RateUnit::Dps))]
    pub rate_unit: RateUnit,
    /// Name of the reference (encoder) angle column, in degrees [default: reference_deg,
    /// used if the log has it]. A name given must be in the header.
    #[cfg_attr(feature = "clap", arg(long, value_name = "NAME"))]
    pub reference_column: Option<String>,
    /// Name of the temperature column, in °C [default: temperature_c, used if the log has
    /// it]. A name given must be in the header.
    #[cfg_attr(feature = "clap", arg(long, value_name = "NAME"))]
    pub temperature_column: Option<String>,
}

/// The reference column looked for when none is named.
pub const DEFAULT_REFERENCE_COLUMN: &str = "reference_deg";
/// The temperature column looked for when none is named.
pub const DEFAULT_TEMPERATURE_COLUMN: &str = "temperature_c";

impl ColumnOptions {
    /// The reference column's name (the one given, else the default).
    pub fn reference_name(&self) -> &str {
        self.reference_column
            .as_deref()
            .unwrap_or(DEFAULT_REFERENCE_COLUMN)
    }

    /// The temperature column's name (the one given, else the default).
    pub fn temperature_name(&self) -> &str {
        self.temperature_column
            .as_deref()
            .unwrap_or(DEFAULT_TEMPERATURE_COLUMN)
    }
}

impl Default for ColumnOptions {
    fn default() -> Self {
        Self {
            time_column: "time_s".into(),
            time_unit: TimeUnit::S,
            rate_column: "rate_dps".into(),
            rate_unit: RateUnit::Dps,
            reference_column: None,
            temperature_column: None,
        }
    }
}

/// The longest field read as a number (characters): `%.17g` of any double is 24, `%f` of
/// 1e100 is 108; a longer field is a corrupt line, not a value a logger wrote.
pub const MAX_NUMBER_CHARS: usize = 128;

/// Why a field is not a value.
#[derive(Debug, PartialEq)]
enum FieldError {
    /// Not a number at all.
    NotANumber,
    /// A number written out that is too large for a double (`1e400`, a thousand digits):
    /// read as infinite it would pass for a missing value.
    Overflows,
    /// Longer than [`MAX_NUMBER_CHARS`].
    TooLong(usize),
}

/// Parse a field: `Ok(None)` if empty, `nan` or `inf` as written (a missing value), an
/// error if it is not a number at all, is a number too large for a double, or is longer
/// than [`MAX_NUMBER_CHARS`].
fn parse_field(field: &[u8]) -> Result<Option<f64>, FieldError> {
    if let Some(value) = parse_plain_decimal(field) {
        return Ok(Some(value));
    }
    let text = std::str::from_utf8(field)
        .map_err(|_| FieldError::NotANumber)?
        .trim();
    if text.is_empty() {
        return Ok(None);
    }
    if text.len() > MAX_NUMBER_CHARS {
        return Err(FieldError::TooLong(text.chars().count()));
    }
    let value: f64 = text.parse().map_err(|_| FieldError::NotANumber)?;
    if value.is_infinite() && !text.to_ascii_lowercase().contains("inf") {
        return Err(FieldError::Overflows);
    }
    Ok(value.is_finite().then_some(value))
}

/// The fast path of [`parse_field`], for what loggers write: `[-]digits[.digits]` whose
/// digits, read as an integer `m`, are at most 2^53, with at most 22 decimals `k`. Then
/// `m` and `10^k` are exact doubles, and their quotient, correctly rounded, is the
/// decimal correctly rounded: what `str::parse` returns (its own fast path, Clinger's).
/// `None` for anything else (a `+`, an exponent, spaces, `nan`, more digits…), which the
/// general path decides.
pub(crate) fn parse_plain_decimal(field: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, digits) = match field.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, field),
    };
    // At most 19 digits: the mantissa fits in a u64.
    if digits.len() > 19 {
        return None;
    }
    let mut mantissa = 0_u64;
    let mut dot: Option<usize> = None;
    for (i, &b) in digits.iter().enumerate() {
        let digit = b.wrapping_sub(b'0');
        if digit < 10 {
            mantissa = mantissa * 10 + u64::from(digit);
        } else if b == b'.' && dot.is_none() {
            dot = Some(i);
        } else {
            return None;
        }
    }
    let decimals = dot.map_or(0, |i| digits.len() - i - 1);
    if digits.len() == usize::from(dot.is_some()) || mantissa > 1 << 53 {
        return None; // no digit, or too many for an exact double
    }
    let value = mantissa as f64 / *POW10.get(decimals)?;
    Some(if negative { -value } else { value })
}

/// A CSV log opened for reading row by row: metadata and header read, rows on demand.
///
/// [`read_csv`] collects every row; `gyro-cli run` streams them ([`super::place`]) so
/// that memory stays bounded however long the log.
///
/// The data lines of a regular file are split here, for speed, as long as they are
/// plain: no quote, no carriage return but one before the line feed, a line feed at the
/// end. From the first line that is not, the `csv` crate reads the rest. Either way the rows, their line numbers
/// and the errors are the `csv` crate's, quirks included: a row is numbered from where
/// the reader stood after the previous row, that is before any blank or comment lines
/// in between, and after a `\r\n` row still on that row's line.
pub struct CsvRows {
    columns: Columns,
    metadata: BTreeMap<String, String>,
    data: Data,
    done: bool,
}

/// Which fields hold what: everything needed to turn fields into a [`Row`].
struct Columns {
    path: PathBuf,
    names: ColumnOptions,
    /// Fields in the header (every row must have as many).
    len: usize,
    time: usize,
    rate: usize,
    reference: Option<usize>,
    temperature: Option<usize>,
    time_scale: f64,
    rate_scale: f64,
    /// Metadata lines before the header.
    prelude_lines: u64,
}

/// Where the data rows come from.
enum Data {
    /// Plain lines split here.
    Lines(Lines),
    /// The `csv` crate.
    Csv(CsvData),
}

/// The `csv` crate reading data rows; its line numbers are shifted by `line_offset`.
struct CsvData {
    reader: csv::Reader<Box<dyn Read + Send>>,
    record: csv::ByteRecord,
    line_offset: u64,
    /// The line of the first row, if not the reader's own (it starts mid-file).
    first_line: Option<u64>,
    /// True if this reader checks the field count (it read the header itself).
    checks_lengths: bool,
}

impl CsvRows {
    /// Open `path`, read its metadata lines and header, and find the columns.
    pub fn open(path: &Path, columns: &ColumnOptions) -> Result<Self, LogError> {
        Self::open_with(path, columns, true)
    }

    /// [`Self::open`]; `split_lines: false` leaves every row to the `csv` crate.
    fn open_with(
        path: &Path,
        columns: &ColumnOptions,
        split_lines: bool,
    ) -> Result<Self, LogError> {
        let file = File::open(path).map_err(io_error(path))?;
        // Lines are split here only in a regular file: the data is read again from the
        // header's end.
        let lines_file = if split_lines && file.metadata().is_ok_and(|m| m.is_file()) {
            file.try_clone().ok()
        } else {
            None
        };
        let mut reader = BufReader::with_capacity(1 << 20, file);
        let prelude = read_prelude(&mut reader, path)?;

        let mut csv = csv::ReaderBuilder::new()
            .has_headers(true)
            .comment(Some(b'#'))
            .from_reader(Box::new(reader) as Box<dyn Read + Send>);
        let headers = csv
            .byte_headers()
            .map_err(|e| csv_error(path, prelude.lines, e))?
            .clone();
        let columns = Columns::find(path, columns, &headers, prelude.lines)?;

        // Where the reader stands after the header: the data's first byte, and the line
        // its first row is numbered with.
        let after_header = csv.position().clone();
        let start = prelude.bytes + after_header.byte();
        let line = prelude.lines + after_header.line();
        let lines = lines_file.and_then(|mut file| {
            file.seek(SeekFrom::Start(start)).ok()?;
            Some(Lines::new(file, line))
        });
        let data = match lines {
            Some(lines) => Data::Lines(lines),
            None => Data::Csv(CsvData {
                reader: csv,
                record: csv::ByteRecord::new(),
                line_offset: prelude.lines,
                first_line: None,
                checks_lengths: true,
            }),
        };
        Ok(Self {
            columns,
            metadata: prelude.metadata,
            data,
            done: false,
        })
    }

    /// The `# key: value` metadata lines before the header.
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.metadata
    }

    /// True if the header has the reference column.
    pub fn has_reference(&self) -> bool {
        self.columns.reference.is_some()
    }

    /// True if the header has the temperature column.
    pub fn has_temperature(&self) -> bool {
        self.columns.temperature.is_some()
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
        let columns = &self.columns;
        if let Data::Lines(lines) = &mut self.data {
            match lines.next_record(columns)? {
                Record::Row(row) => return Ok(Some(row)),
                Record::End => return Ok(None),
                Record::NotPlain {
                    rest,
                    line_offset,
                    first_line,
                } => {
                    let reader = csv::ReaderBuilder::new()
                        .has_headers(false)
                        .flexible(true)
                        .comment(Some(b'#'))
                        .from_reader(rest);
                    self.data = Data::Csv(CsvData {
                        reader,
                        record: csv::ByteRecord::new(),
                        line_offset,
                        first_line: Some(first_line),
                        checks_lengths: false,
                    });
                }
            }
        }
        match &mut self.data {
            Data::Csv(data) => data.next_row(columns),
            Data::Lines(_) => Ok(None), // replaced above
        }
    }
}

/// What comes before the header: the metadata, and how many lines and bytes it takes.
struct Prelude {
    metadata: BTreeMap<String, String>,
    /// Metadata lines before the header.
    lines: u64,
    /// Bytes before the header (a UTF-8 byte-order mark included).
    bytes: u64,
}

/// The error of an I/O failure on `path`.
fn io_error(path: &Path) -> impl Fn(std::io::Error) -> LogError + '_ {
    move |cause| LogError::Io {
        path: path.to_path_buf(),
        cause,
    }
}

/// Read what precedes the header: refuse UTF-16, skip a UTF-8 byte-order mark, then read
/// the metadata lines.
fn read_prelude(reader: &mut BufReader<File>, path: &Path) -> Result<Prelude, LogError> {
    let io_err = io_error(path);
    // Metadata: `# key: value` lines before the header.
    let mut metadata = BTreeMap::new();
    let mut prelude_lines = 0_u64;
    let mut prelude_bytes = 0_u64;
    refuse_utf16(reader, path)?;
    // A UTF-8 byte-order mark (as some Windows tools write) is not part of the header.
    if reader
        .fill_buf()
        .map_err(&io_err)?
        .starts_with(&[0xEF, 0xBB, 0xBF])
    {
        reader.consume(3);
        prelude_bytes += 3;
    }
    loop {
        let buf = reader.fill_buf().map_err(&io_err)?;
        if buf.first() != Some(&b'#') {
            break;
        }
        // Comments may be in any encoding (a Latin-1 "é" in a note): read as bytes.
        let mut bytes = Vec::new();
        prelude_bytes += reader.read_until(b'\n', &mut bytes).map_err(&io_err)? as u64;
        prelude_lines += 1;
        add_metadata_line(&mut metadata, &bytes, path, prelude_lines)?;
    }
    Ok(Prelude {
        metadata,
        lines: prelude_lines,
        bytes: prelude_bytes,
    })
}

/// Refuse a file that starts as UTF-16 or binary: it would be read as a garbled header.
fn refuse_utf16(reader: &mut BufReader<File>, path: &Path) -> Result<(), LogError> {
    // UTF-16 (a byte-order mark, or NUL bytes between ASCII characters) is refused
    // plainly rather than read as a garbled header.
    let start = reader.fill_buf().map_err(io_error(path))?;
    let utf16 = start.starts_with(&[0xFF, 0xFE])
        || start.starts_with(&[0xFE, 0xFF])
        || start.iter().take(64).filter(|b| **b == 0).count() >= 8;
    if utf16 {
        return Err(LogError::NotUtf8 {
            path: path.to_path_buf(),
            what: "this file is UTF-16 (or binary); save it as UTF-8 CSV".into(),
        });
    }
    Ok(())
}

/// Add the metadata line `bytes` (line `line` of the file) to `metadata` if it is
/// `# key: value`, checking a sample rate against one given before.
fn add_metadata_line(
    metadata: &mut BTreeMap<String, String>,
    bytes: &[u8],
    path: &Path,
    line: u64,
) -> Result<(), LogError> {
    let text = String::from_utf8_lossy(bytes);
    if let Some((key, value)) = text.trim_start_matches('#').split_once(':') {
        let (key, value) = (key.trim(), value.trim());
        if key == crate::SAMPLE_RATE_KEY {
            crate::check_rate_metadata(value, metadata.get(key).map(String::as_str)).map_err(
                |message| LogError::Metadata {
                    path: path.to_path_buf(),
                    line: Some(line),
                    message,
                },
            )?;
        }
        metadata.insert(key.to_string(), value.to_string());
    }
    Ok(())
}

/// Refuse a header of one field holding tabs or semicolons: another separator, not a
/// missing column.
fn refuse_other_separator(path: &Path, header_line: u64, names: &[String]) -> Result<(), LogError> {
    // One field holding tabs or semicolons: another separator, not a missing column.
    if let [only] = names {
        let separator = [
            ('\t', "tabs", r"tr '\t' ','"),
            (';', "semicolons", "sed 's/,/./g; s/;/,/g'"),
        ]
        .into_iter()
        .find(|(c, _, _)| only.contains(*c));
        if let Some((_, what, fix)) = separator {
            return Err(LogError::Csv {
                path: path.to_path_buf(),
                line: header_line,
                message: format!(
                    "the header is separated by {what}, not commas (`{}`): a log must be comma-separated with `.` as the decimal point (for example `{fix}`)",
                    excerpt(only.as_bytes())
                ),
            });
        }
    }
    Ok(())
}

/// Refuse a header naming one column twice.
fn refuse_duplicate_columns(
    path: &Path,
    header_line: u64,
    names: &[String],
) -> Result<(), LogError> {
    // Two columns of one name: which one is meant cannot be known.
    for (i, name) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|n| !n.is_empty() && n == name) {
            return Err(LogError::Csv {
                path: path.to_path_buf(),
                line: header_line,
                message: format!(
                    "column `{}` appears twice in the header (fields {} and {}); rename one",
                    excerpt(name.as_bytes()),
                    j + 1,
                    i + 1
                ),
            });
        }
    }
    Ok(())
}

/// The header's columns as an error lists them: the first few, each as [`excerpt`]
/// shows it, then how many there are.
/// Which required column a hint is for.
#[derive(Clone, Copy)]
enum Role {
    Time,
    Rate,
}

/// The hint for a missing time or rate column: `; to read …, give …` naming the option
/// that reads the header's column that looks meant, the first whose name starts with `time`
/// (`timestamp`, `time_ms`, …) or is `t`, or starts with `rate`, `gyro` or `omega`, with the
/// unit its suffix names (`_ms`, `_us`, `_ns`; `_rads`, `_rad_s`, `_radps`); empty if none.
fn hint(names: &[String], role: Role) -> String {
    let lower: Vec<String> = names
        .iter()
        .map(|n| n.trim().to_ascii_lowercase())
        .collect();
    let found = lower.iter().position(|n| match role {
        Role::Time => n.starts_with("time") || n == "t",
        Role::Rate => ["rate", "gyro", "omega"].iter().any(|p| n.starts_with(p)),
    });
    found.map_or(String::new(), |i| {
        let name = &lower[i];
        let unit = match role {
            Role::Time => [("_ms", "ms"), ("_us", "us"), ("_ns", "ns")]
                .iter()
                .find(|(suffix, _)| name.ends_with(suffix))
                .map(|(_, unit)| format!(" --time-unit {unit}")),
            Role::Rate => ["_rads", "_rad_s", "_radps"]
                .iter()
                .any(|suffix| name.ends_with(suffix))
                .then(|| " --rate-unit rads".to_string()),
        };
        let option = match role {
            Role::Time => "--time-column",
            Role::Rate => "--rate-column",
        };
        format!(
            "; to read `{0}`, give {option} {0}{1}",
            excerpt(names[i].as_bytes()),
            unit.unwrap_or_default()
        )
    })
}

fn column_list(names: &[String]) -> String {
    const LISTED: usize = 6;
    let mut list = names
        .iter()
        .take(LISTED)
        .map(|n| excerpt(n.as_bytes()))
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > LISTED {
        list.push_str(&format!(", … ({} columns)", names.len()));
    }
    list
}

/// A field as an error shows it: at most 40 characters (a longer one cut, with its length),
/// control characters escaped, so that a corrupt line cannot flood the terminal.
///
/// ```
/// assert_eq!(gyro_log::excerpt(b"a\0b"), "a\\u{0}b");
/// assert!(gyro_log::excerpt("x".repeat(100).as_bytes()).ends_with("… (100 characters)"));
/// ```
pub fn excerpt(raw: &[u8]) -> String {
    const SHOWN: usize = 40;
    let text = String::from_utf8_lossy(raw);
    let chars = text.chars().count();
    // At most SHOWN characters as shown: an escaped control character counts as its
    // escape (`\u{0}`, five).
    let mut shown = String::new();
    let (mut width, mut taken) = (0, 0);
    for c in text.chars() {
        let piece: String = if c.is_control() {
            c.escape_default().collect()
        } else {
            c.to_string()
        };
        width += piece.chars().count();
        if width > SHOWN {
            break;
        }
        shown.push_str(&piece);
        taken += 1;
    }
    if taken < chars {
        shown.push_str(&format!("… ({chars} characters)"));
    }
    shown
}

impl Columns {
    /// The columns `options` names, found in `headers` (the header, after
    /// `prelude_lines` metadata lines); an error for a header that cannot be read right.
    fn find(
        path: &Path,
        options: &ColumnOptions,
        headers: &csv::ByteRecord,
        prelude_lines: u64,
    ) -> Result<Self, LogError> {
        let header_line = prelude_lines + 1;
        if headers.is_empty() || headers.iter().all(|h| h.is_empty()) {
            return Err(LogError::NoHeader {
                path: path.to_path_buf(),
            });
        }
        let names: Vec<String> = headers
            .iter()
            .map(|h| String::from_utf8_lossy(h).trim().to_string())
            .collect();
        refuse_other_separator(path, header_line, &names)?;
        refuse_duplicate_columns(path, header_line, &names)?;
        let find = |name: &str| names.iter().position(|n| n == name);
        // A missing time or rate column comes with the flags that read one that looks meant.
        let required = |name: &str, role: Option<Role>| {
            find(name).ok_or_else(|| LogError::MissingColumn {
                path: path.to_path_buf(),
                line: header_line,
                column: excerpt(name.as_bytes()),
                available: column_list(&names),
                hint: role.map_or(String::new(), |role| hint(&names, role)),
            })
        };
        let time = required(&options.time_column, Some(Role::Time))?;
        let rate = required(&options.rate_column, Some(Role::Rate))?;
        Ok(Columns {
            path: path.to_path_buf(),
            names: options.clone(),
            len: headers.len(),
            time,
            rate,
            reference: match &options.reference_column {
                Some(name) => Some(required(name, None)?),
                None => find(DEFAULT_REFERENCE_COLUMN),
            },
            temperature: match &options.temperature_column {
                Some(name) => Some(required(name, None)?),
                None => find(DEFAULT_TEMPERATURE_COLUMN),
            },
            time_scale: options.time_unit.to_seconds(),
            rate_scale: match options.rate_unit {
                RateUnit::Dps => 1.0,
                RateUnit::Rads => 180.0 / std::f64::consts::PI,
            },
            prelude_lines,
        })
    }
    /// The row of the fields `field(i)` (as many as the header has), at `line`.
    fn row<'a>(&self, line: u64, field: impl Fn(usize) -> &'a [u8]) -> Result<Row, LogError> {
        let value = |idx: usize, column: &str| -> Result<Option<f64>, LogError> {
            let raw = field(idx);
            parse_field(raw).map_err(|e| {
                let (path, column, value) = (self.path.clone(), column.to_string(), excerpt(raw));
                match e {
                    FieldError::NotANumber => LogError::NotANumber {
                        path,
                        line,
                        column,
                        value,
                    },
                    FieldError::Overflows => LogError::NumberOutOfRange {
                        path,
                        line,
                        column,
                        value,
                        what: "is too large for any number (it overflows a double)".into(),
                    },
                    FieldError::TooLong(chars) => LogError::NumberOutOfRange {
                        path,
                        line,
                        column,
                        value,
                        what: format!(
                            "is a field of {chars} characters, longer than any number a logger writes ({MAX_NUMBER_CHARS})"
                        ),
                    },
                }
            })
        };
        let names = &self.names;
        let time_s = value(self.time, &names.time_column)?
            .map(|t| t * self.time_scale)
            .ok_or_else(|| LogError::BadTime {
                path: self.path.clone(),
                line,
                column: names.time_column.clone(),
            })?;
        let rate_dps = value(self.rate, &names.rate_column)?.map(|r| r * self.rate_scale);
        let reference_deg = match self.reference {
            Some(idx) => value(idx, names.reference_name())?,
            None => None,
        };
        let temperature_c = match self.temperature {
            Some(idx) => value(idx, names.temperature_name())?,
            None => None,
        };
        Ok(Row {
            line,
            time_s,
            rate_dps,
            reference_deg,
            temperature_c,
        })
    }

    /// The error of a row with `len` fields, as the `csv` crate words it.
    fn length_error(&self, line: u64, len: usize) -> LogError {
        LogError::Csv {
            path: self.path.clone(),
            line,
            message: format!("row has {len} fields, the header has {}", self.len),
        }
    }
}

impl CsvData {
    fn next_row(&mut self, columns: &Columns) -> Result<Option<Row>, LogError> {
        let result = self.reader.read_byte_record(&mut self.record);
        let first_line = self.first_line.take();
        match result {
            Ok(false) => return Ok(None),
            Ok(true) => {}
            // An error without a position (I/O) is numbered as if from the start.
            Err(e) if e.position().is_none() => {
                return Err(csv_error(&columns.path, columns.prelude_lines, e))
            }
            Err(e) => return Err(csv_error(&columns.path, self.line_offset, e)),
        }
        let record = &self.record;
        let line = first_line
            .unwrap_or_else(|| self.line_offset + record.position().map_or(0, |p| p.line()));
        if !self.checks_lengths && record.len() != columns.len {
            return Err(columns.length_error(line, record.len()));
        }
        columns
            .row(line, |idx| record.get(idx).unwrap_or_default())
            .map(Some)
    }
}

/// What [`Lines::next_record`] found.
enum Record {
    Row(Row),
    End,
    /// A line that is not plain: the `csv` crate reads on from there (`rest`), its lines
    /// shifted by `line_offset`, its first row numbered `first_line`.
    NotPlain {
        rest: Box<dyn Read + Send>,
        line_offset: u64,
        first_line: u64,
    },
}

/// The data lines of a regular file, split on line feeds and commas.
struct Lines {
    file: Option<File>,
    buf: Vec<u8>,
    /// The unread bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    /// The line number of the next line read.
    line: u64,
    /// The line number the next row gets (see [`CsvRows`]).
    row_line: u64,
    /// Where the commas are in the current line.
    commas: Vec<usize>,
}

impl Lines {
    fn new(file: File, line: u64) -> Self {
        Self {
            file: Some(file),
            buf: vec![0; 1 << 20],
            start: 0,
            end: 0,
            line,
            row_line: line,
            commas: Vec::new(),
        }
    }

    /// Read more bytes into the buffer (keeping the unread ones); false at the end.
    fn fill(&mut self, columns: &Columns) -> Result<bool, LogError> {
        let Some(file) = self.file.as_mut() else {
            return Ok(false);
        };
        if self.start > 0 {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        if self.end == self.buf.len() {
            self.buf.resize(self.buf.len() * 2, 0);
        }
        loop {
            match file.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.file = None;
                    return Ok(false);
                }
                Ok(n) => {
                    self.end += n;
                    return Ok(true);
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(LogError::Csv {
                        path: columns.path.clone(),
                        line: columns.prelude_lines,
                        message: format!("read error: {e}"),
                    })
                }
            }
        }
    }

    /// The next line, without its line feed, in one pass: where its commas are (in
    /// `self.commas`), whether it has quotes or carriage returns. `None` at the end.
    #[inline]
    fn scan_line(&mut self, columns: &Columns) -> Result<Option<ScannedLine>, LogError> {
        self.commas.clear();
        let (mut quotes, mut returns) = (false, 0_usize);
        let mut scanned = 0;
        let (start, end, terminated) = loop {
            let line = &self.buf[self.start..self.end];
            let mut feed = None;
            for (i, &b) in line.iter().enumerate().skip(scanned) {
                match b {
                    b',' => self.commas.push(i),
                    b'\n' => {
                        feed = Some(i);
                        break;
                    }
                    b'"' => quotes = true,
                    b'\r' => returns += 1,
                    _ => {}
                }
            }
            if let Some(i) = feed {
                break (self.start, self.start + i, true);
            }
            scanned = line.len();
            if !self.fill(columns)? {
                if self.start == self.end {
                    return Ok(None);
                }
                break (self.start, self.end, false);
            }
        };
        Ok(Some(ScannedLine {
            start,
            end,
            terminated,
            quotes,
            returns,
        }))
    }

    /// Hand the rest of the file, from the line `line` starting at `line_start`, to the
    /// `csv` crate.
    fn not_plain(&mut self, line_start: usize, line: u64) -> Record {
        // A line feed first: the `csv` crate reads on as from a line start, and
        // does not take a byte-order mark there for the file's.
        let mut rest = Vec::with_capacity(self.end - line_start + 1);
        rest.push(b'\n');
        rest.extend_from_slice(&self.buf[line_start..self.end]);
        let reader: Box<dyn Read + Send> = match self.file.take() {
            Some(file) => Box::new(std::io::Cursor::new(rest).chain(file)),
            None => Box::new(std::io::Cursor::new(rest)),
        };
        Record::NotPlain {
            rest: reader,
            line_offset: line.saturating_sub(2),
            first_line: self.row_line,
        }
    }

    /// The next row, the end, or the first line that is not plain.
    fn next_record(&mut self, columns: &Columns) -> Result<Record, LogError> {
        loop {
            // The next line, without its line feed (`terminated`: it has one), in one pass:
            // where its commas are, whether it has quotes or carriage returns.
            let Some(scanned) = self.scan_line(columns)? else {
                return Ok(Record::End);
            };
            let line = self.line;
            let mut text = &self.buf[scanned.start..scanned.end];
            let crlf = text.last() == Some(&b'\r');
            if crlf {
                text = &text[..text.len() - 1];
            }
            // The last line without a line feed also goes to the `csv` crate (which reads
            // a comment there as a row of one field).
            if !scanned.terminated || scanned.quotes || scanned.returns > usize::from(crlf) {
                return Ok(self.not_plain(scanned.start, line));
            }
            self.start = scanned.end + 1;
            self.line += 1;
            // Blank lines and comments are skipped.
            if text.is_empty() || text[0] == b'#' {
                continue;
            }
            let row_line = self.row_line;
            // The `csv` crate ends a row at `\r` and reads the `\n` with the next row.
            self.row_line = if crlf { line } else { line + 1 };
            if self.commas.len() + 1 != columns.len {
                return Err(columns.length_error(row_line, self.commas.len() + 1));
            }
            let commas = &self.commas;
            // Field `i` lies between comma `i - 1` and comma `i`.
            let field = |i: usize| {
                let from = match i.checked_sub(1) {
                    Some(before) => commas.get(before).map_or(text.len(), |c| c + 1),
                    None => 0,
                };
                let to = commas.get(i).copied().unwrap_or(text.len());
                text.get(from..to).unwrap_or_default()
            };
            return columns.row(row_line, field).map(Record::Row);
        }
    }
}

/// A line [`Lines::scan_line`] found: `buf[start..end]`, without its line feed.
struct ScannedLine {
    start: usize,
    end: usize,
    /// It ends with a line feed (not the end of the file).
    terminated: bool,
    /// It has a quote.
    quotes: bool,
    /// How many carriage returns it has.
    returns: usize,
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
        has_reference: reader.has_reference(),
        has_temperature: reader.has_temperature(),
        path: reader.columns.path,
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

    /// `text` written to `name` in a fresh folder; the guard removes the folder when dropped.
    fn write_temp(name: &str, text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
        let scratch = tempfile::Builder::new()
            .prefix("gyro-csv-test-")
            .tempdir()
            .unwrap();
        let path = scratch.path().join(name);
        std::fs::File::create(&path)
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
        (scratch, path)
    }

    #[test]
    fn reads_metadata_header_and_rows() {
        let (_scratch, path) = write_temp(
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

    /// Every row, then the error if any, as text.
    fn read_all(path: &Path, split_lines: bool) -> String {
        let mut out = String::new();
        match CsvRows::open_with(path, &ColumnOptions::default(), split_lines) {
            Err(e) => out.push_str(&format!("open error: {e}")),
            Ok(mut rows) => loop {
                match rows.next_row() {
                    Ok(Some(row)) => out.push_str(&format!("{row:?}\n")),
                    Ok(None) => break,
                    Err(e) => {
                        out.push_str(&format!("error: {e}"));
                        break;
                    }
                }
            },
        }
        out
    }

    /// One generated data line (without its terminator).
    fn data_line() -> impl proptest::strategy::Strategy<Value = String> {
        use proptest::prelude::*;
        let number = prop_oneof![
            8 => (-1000.0..1000.0_f64).prop_map(|v| format!("{v}")),
            4 => (-100_000_i64..100_000).prop_map(|v| format!("{:.3}", v as f64 / 1000.0)),
            1 => Just(String::new()),
            1 => Just("nan".to_string()),
            1 => Just(" 1.5 ".to_string()),
            1 => Just("1e-3".to_string()),
            1 => Just("x1".to_string()),
            1 => Just("\"2.5\"".to_string()),
        ];
        prop_oneof![
            20 => proptest::collection::vec(number, 3).prop_map(|f| f.join(",")),
            2 => proptest::collection::vec(-5.0..5.0_f64, 2..5).prop_map(|f| {
                f.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>().join(",")
            }),
            2 => Just(String::new()),
            2 => Just("# a comment, with a comma".to_string()),
            1 => Just("#\"quoted\" comment".to_string()),
            1 => Just("0.5,1.0\r,2.0".to_string()),
            1 => Just("\"0.25\",\"1,0\",3".to_string()),
            1 => Just("\"0.25\n0.5\",1,2".to_string()),
            1 => Just("\u{feff}0.1,2,3".to_string()),
            1 => Just(" ".to_string()),
        ]
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]
        /// Lines split here give what the `csv` crate gives: rows, line numbers, errors.
        #[test]
        fn split_lines_read_like_the_csv_crate(
            prelude in proptest::collection::vec(proptest::bool::ANY, 0..3),
            bom: bool,
            header_crlf: bool,
            lines in proptest::collection::vec((data_line(), 0_u8..10), 0..40),
            final_newline: bool,
        ) {
            let mut text = String::new();
            if bom {
                text.push('\u{feff}');
            }
            for with_rate in prelude {
                text.push_str(if with_rate { "# sample_rate_hz: 100\n" } else { "# sensor: x\n" });
            }
            text.push_str("time_s,rate_dps,reference_deg");
            text.push_str(if header_crlf { "\r\n" } else { "\n" });
            let count = lines.len();
            for (i, (line, terminator)) in lines.into_iter().enumerate() {
                text.push_str(&line);
                if i + 1 < count || final_newline {
                    text.push_str(match terminator {
                        0..=5 => "\n",
                        6..=8 => "\r\n",
                        _ => "\r",
                    });
                }
            }
            let (_scratch, path) = write_temp("split.csv", &text);
            let fast = read_all(&path, true);
            let slow = read_all(&path, false);
            proptest::prop_assert_eq!(fast, slow, "{:?}", text);
        }
    }

    /// Line numbers and errors as the `csv` crate gives them, quirks included (what
    /// `gyro-cli run` always printed).
    #[test]
    fn csv_crate_quirks_are_kept() {
        let cases = [
            // Numbered from the line after the previous row, before blank and comment lines.
            (
                "blank.csv",
                "time_s,rate_dps\n0.0,1\n\n# c\n0.01,x\n",
                "blank.csv:3: column",
            ),
            // After a `\r\n` row, still on that row's line.
            (
                "crlf.csv",
                "time_s,rate_dps\r\n0.0,1\r\n0.01,1\r\n0.02,x\r\n",
                "crlf.csv:3: column",
            ),
            (
                "crlf2.csv",
                "time_s,rate_dps\r\n0.0,1\r\n0.01,1\r\n0.02,1,3\r\n",
                "crlf2.csv:3: row has 3 fields, the header has 2",
            ),
            // A comment on the last line without a line feed is a row of one field.
            (
                "eof_comment.csv",
                "time_s,rate_dps\n0.0,1\n0.01,1\n# trailing comment",
                "eof_comment.csv:4: row has 1 fields, the header has 2",
            ),
        ];
        for (name, text, expected) in cases {
            let (_scratch, path) = write_temp(name, text);
            for split_lines in [true, false] {
                let all = read_all(&path, split_lines);
                assert!(all.contains(expected), "{name} {split_lines}: {all}");
            }
        }
    }

    /// Lines across buffer refills, a line longer than the buffer, and a switch to the
    /// `csv` crate with most of the file still unread.
    #[test]
    fn split_lines_across_buffers_read_like_the_csv_crate() {
        let mut text = String::from("# sample_rate_hz: 1000\ntime_s,rate_dps,reference_deg\n");
        for k in 0..60_000 {
            let pad = " ".repeat(k % 13);
            text.push_str(&format!("{}{pad},{},{}\n", k as f64 * 0.001, k % 7, k % 3));
            if k == 20_000 {
                text.push_str(&format!("20.0005,{}1.0,0\n", " ".repeat(3 << 20)));
            }
            if k == 40_000 {
                text.push_str("40.0005,\"1.0\",0\r\n");
            }
        }
        let (_scratch, path) = write_temp("big.csv", &text);
        let fast = read_all(&path, true);
        assert!(
            !fast.contains("error"),
            "{}",
            &fast[fast.len().saturating_sub(300)..]
        );
        assert_eq!(fast.lines().count(), 60_002);
        assert_eq!(fast, read_all(&path, false));
    }

    #[test]
    fn units_are_converted() {
        let (_scratch, path) = write_temp("units.csv", "t_ms,w\n1000,3.141592653589793\n");
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
        let (_scratch, path) =
            write_temp("bad.csv", "# a: b\ntime_s,rate_dps\n0.0,1.0\n0.001,abc\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("bad.csv:4: column `rate_dps`: `abc` is not a number"),
            "{err}"
        );

        let (_scratch, path) = write_temp("nocol.csv", "time_s,gyro\n0.0,1.0\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("nocol.csv:1: no column `rate_dps`"), "{err}");
        assert!(err.contains("time_s, gyro"), "{err}");
        assert!(
            err.ends_with("; to read `gyro`, give --rate-column gyro"),
            "{err}"
        );

        // A time or rate column under another name: the option that reads it, with the
        // unit its name gives; none when nothing looks meant.
        for (header, hint) in [
            (
                "time_ms,rate_dps",
                "; to read `time_ms`, give --time-column time_ms --time-unit ms",
            ),
            (
                "Timestamp,rate_dps",
                "; to read `Timestamp`, give --time-column Timestamp",
            ),
            ("t,rate_dps", "; to read `t`, give --time-column t"),
            (
                "time_s,gyro_z_rads",
                "; to read `gyro_z_rads`, give --rate-column gyro_z_rads --rate-unit rads",
            ),
            (
                "time_s,omega",
                "; to read `omega`, give --rate-column omega",
            ),
            ("stamp,rate_dps", ")"),
        ] {
            let (_scratch, path) = write_temp("other_names.csv", &format!("{header}\n0,1\n"));
            let err = read_csv(&path, &ColumnOptions::default())
                .unwrap_err()
                .to_string();
            assert!(err.ends_with(hint), "{header}: {err}");
        }

        // Other separators are named, with a way to convert.
        let (_scratch, path) = write_temp("tabs.tsv", "# a: b\ntime_s\trate_dps\n0.0\t1.0\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("tabs.tsv:2: the header is separated by tabs, not commas"),
            "{err}"
        );
        let (_scratch, path) = write_temp("semicolons.csv", "time_s;rate_dps\n0,0;1,5\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("semicolons.csv:1: the header is separated by semicolons")
                && err.contains("s/;/,/g"),
            "{err}"
        );

        let (_scratch, path) = write_temp("ragged.csv", "time_s,rate_dps\n0.0,1.0\n0.001,1.0,7\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("ragged.csv:3: row has 3 fields, the header has 2"),
            "{err}"
        );

        let (_scratch, path) = write_temp("notime.csv", "time_s,rate_dps\n,1.0\n");
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
        let (_scratch, path) = write_temp("rt.csv", "# sample_rate_hz: 100\ntime_s,rate_dps,temperature_c,reference_deg\n0.000000,0.12500,25.100,1.00000\n0.010000,,25.200,\n");
        let log = read_csv(&path, &ColumnOptions::default()).unwrap();
        let mut out = Vec::new();
        write_csv(&mut out, &log).unwrap();
        let (_scratch_again, again) = write_temp("rt2.csv", std::str::from_utf8(&out).unwrap());
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

    /// The `sample_rate_hz` metadata is a positive number of Hz, given once: anything else
    /// is an error naming the file and the line.
    #[test]
    fn invalid_rate_metadata_is_an_error_naming_its_line() {
        for (name, lines) in [
            ("negative", "# sample_rate_hz: -1000\n"),
            ("zero", "# sample_rate_hz: 0\n"),
            ("nan", "# sample_rate_hz: NaN\n"),
            ("word", "# sample_rate_hz: fast\n"),
            ("unit", "# sample_rate_hz: 1000 Hz\n"),
            ("twice", "# sample_rate_hz: 1000\n# sample_rate_hz: 500\n"),
        ] {
            let text = format!("# sensor: x\n{lines}time_s,rate_dps\n0,1\n0.001,1\n");
            let (_scratch, path) = write_temp(&format!("meta-{name}.csv"), &text);
            let err = read_csv(&path, &ColumnOptions::default())
                .unwrap_err()
                .to_string();
            let line = 1 + lines.lines().count();
            assert!(
                err.contains(&format!("meta-{name}.csv:{line}: `sample_rate_hz")),
                "{name}: {err}"
            );
        }
        // The same value twice, and a valid one, are read.
        let (_scratch, path) = write_temp(
            "meta-same.csv",
            "# sample_rate_hz: 1000\n# sample_rate_hz: 1e3\ntime_s,rate_dps\n0,1\n",
        );
        let log = read_csv(&path, &ColumnOptions::default()).unwrap();
        assert_eq!(log.metadata_rate_hz(), Some(1000.0));
    }

    /// Two columns of one name, and a named column the header lacks, are errors naming the
    /// header line.
    #[test]
    fn duplicate_and_missing_named_columns_are_errors() {
        let (_scratch, path) = write_temp("dup.csv", "time_s,rate_dps,rate_dps\n0,1,2\n");
        let err = read_csv(&path, &ColumnOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(
                "dup.csv:1: column `rate_dps` appears twice in the header (fields 2 and 3)"
            ),
            "{err}"
        );
        let (_scratch, path) = write_temp("named.csv", "time_s,rate_dps,reference_deg\n0,1,2\n");
        let columns = ColumnOptions {
            reference_column: Some("ref_deg".into()),
            ..ColumnOptions::default()
        };
        let err = read_csv(&path, &columns).unwrap_err().to_string();
        assert!(
            err.contains("named.csv:1: no column `ref_deg` in the header"),
            "{err}"
        );
        // Not named: used if present, else none.
        let log = read_csv(&path, &ColumnOptions::default()).unwrap();
        assert!(log.has_reference && !log.has_temperature);
    }
}
