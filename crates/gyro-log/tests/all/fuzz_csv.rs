//! Fuzz: CSV logs through `gyro_log::load` (the one way in for every command). Seeds are
//! the heads of the fixture logs, mutated line by line (duplicated, deleted, swapped
//! lines; fields replaced by odd values; metadata and junk lines inserted) and byte by
//! byte (flips, truncation, insertion, duplication), re-encoded (UTF-16, a BOM, Latin-1),
//! plus random bytes. None may panic; an error is one line naming the file and at most
//! [`crate::common::MAX_ERROR_CHARS`] long; a log that loads has finite slots.
#![allow(clippy::unwrap_used)] // a failed unwrap fails the test

use crate::common::{assert_error, byte_mutation, check_load, temp_dir, workspace_root};
use gyro_log::{GridOptions, LogOptions};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::path::Path;

/// Cases of the mutation property (the random-bytes one runs a quarter as many).
const CASES: u32 = 1600;

/// The first `lines` lines of a fixture.
fn fixture_head(path: &str, lines: usize) -> String {
    let text = std::fs::read_to_string(workspace_root().join(path)).unwrap();
    text.lines().take(lines).map(|l| format!("{l}\n")).collect()
}

fn seeds() -> Vec<String> {
    let bench = fixture_head("fixtures/logs/bench_run.csv", 400);
    let allan = fixture_head("fixtures/noise/allan_input.csv", 300);
    // The bench head without its metadata (the rate from the stamps) and without the
    // optional columns.
    let bare: String = bench
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            format!("{},{}\n", fields[0], fields[1])
        })
        .collect();
    vec![bench, allan, bare]
}

/// Values a field is replaced with.
const ODD_FIELDS: &[&str] = &[
    "",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e400",
    "1e-320",
    "0x10",
    "fast",
    "1,000",
    "\u{2212}1",
    "\u{feff}0",
    " 1 ",
    "\"1\"",
    "0.001.2",
    "-0",
    "+.5",
    "1e9",
    "99999999999999999999999999999999999999999999999999999999999999",
];

/// Lines inserted.
const ODD_LINES: &[&str] = &[
    "# sample_rate_hz: 1000",
    "# sample_rate_hz: -1000",
    "# sample_rate_hz: 0",
    "# sample_rate_hz: NaN",
    "# sample_rate_hz: 1e9",
    "# sample_rate_hz: fast",
    "# sample_rate_hz: 1000 Hz",
    "# sample_rate_hz: 10",
    "# comment \u{e9}",
    "time_s,rate_dps",
    "time_s,rate_dps,rate_dps",
    "rate_dps,time_s",
    "",
    ",",
    ",,,,,,,,",
    "1e300,1",
    "-1e300,1",
    "\u{0}\u{0}\u{0}",
];

#[derive(Clone, Debug)]
enum LineMutation {
    Duplicate(usize),
    Delete(usize),
    Swap(usize, usize),
    Field(usize, usize, usize),
    Insert(usize, usize),
    LongLine(usize, usize),
}

fn line_mutation() -> impl Strategy<Value = LineMutation> {
    let n_odd_fields = ODD_FIELDS.len();
    let n_odd_lines = ODD_LINES.len();
    prop_oneof![
        2 => any::<usize>().prop_map(LineMutation::Duplicate),
        2 => any::<usize>().prop_map(LineMutation::Delete),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| LineMutation::Swap(a, b)),
        4 => (any::<usize>(), 0usize..4, 0..n_odd_fields)
            .prop_map(|(l, c, v)| LineMutation::Field(l, c, v)),
        3 => (any::<usize>(), 0..n_odd_lines).prop_map(|(l, v)| LineMutation::Insert(l, v)),
        1 => (any::<usize>(), 100usize..5000).prop_map(|(l, n)| LineMutation::LongLine(l, n)),
    ]
}

fn apply_line(lines: &mut Vec<String>, mutation: &LineMutation) {
    let n = lines.len();
    if n == 0 {
        return;
    }
    match *mutation {
        LineMutation::Duplicate(i) => {
            let line = lines[i % n].clone();
            lines.insert(i % n, line);
        }
        LineMutation::Delete(i) => {
            lines.remove(i % n);
        }
        LineMutation::Swap(a, b) => lines.swap(a % n, b % n),
        LineMutation::Field(i, column, value) => {
            let line = &mut lines[i % n];
            let mut fields: Vec<String> = line.split(',').map(String::from).collect();
            let column = column % fields.len();
            fields[column] = ODD_FIELDS[value].to_string();
            *line = fields.join(",");
        }
        LineMutation::Insert(i, value) => lines.insert(i % (n + 1), ODD_LINES[value].into()),
        LineMutation::LongLine(i, len) => lines.insert(i % (n + 1), "7".repeat(len)),
    }
}

/// How the text becomes bytes.
#[derive(Clone, Copy, Debug)]
enum Encoding {
    Utf8,
    Utf8Bom,
    Utf16Le,
    Latin1Comment,
}

fn encode(text: &str, encoding: Encoding) -> Vec<u8> {
    match encoding {
        Encoding::Utf8 => text.as_bytes().to_vec(),
        Encoding::Utf8Bom => [&[0xEF, 0xBB, 0xBF], text.as_bytes()].concat(),
        Encoding::Utf16Le => [0xFF, 0xFE]
            .into_iter()
            .chain(text.encode_utf16().flat_map(u16::to_le_bytes))
            .collect(),
        Encoding::Latin1Comment => [b"# operator: Jos\xe9\n", text.as_bytes()].concat(),
    }
}

fn encoding() -> impl Strategy<Value = Encoding> {
    prop_oneof![
        12 => Just(Encoding::Utf8),
        1 => Just(Encoding::Utf8Bom),
        1 => Just(Encoding::Utf16Le),
        1 => Just(Encoding::Latin1Comment),
    ]
}

/// Load `bytes` as a CSV log: no panic, a one-line error naming the file, or finite slots.
fn check(path: &Path, bytes: &[u8], grid: &GridOptions) -> Result<(), TestCaseError> {
    check_load(path, bytes, &LogOptions::default(), grid)
}

#[test]
fn the_unmutated_seeds_load() {
    let scratch = temp_dir("fuzz-csv-seeds");
    let dir = scratch.path();
    for (i, seed) in seeds().iter().enumerate() {
        let path = dir.join(format!("seed{i}.csv"));
        std::fs::write(&path, seed).unwrap();
        let log = gyro_log::load(
            &path,
            &LogOptions::default(),
            &GridOptions::default(),
            &mut |w| panic!("{w}"),
        )
        .unwrap();
        assert!(log.slots.len() >= 290, "{i}: {} slots", log.slots.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x00C5_F022),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// A fixture head mutated by lines, then by bytes, in some encoding.
    #[test]
    fn mutated_fixture_logs_load_or_fail_in_one_line(
        seed in 0usize..3,
        lines in proptest::collection::vec(line_mutation(), 0..6),
        bytes in proptest::collection::vec(byte_mutation(), 0..4),
        encoding in encoding(),
        max_gap_s in prop_oneof![3 => Just(0.5), 1 => Just(0.0), 1 => Just(1e6)],
    ) {
        let seed = &seeds()[seed];
        let mut text: Vec<String> = seed.lines().map(String::from).collect();
        lines.iter().for_each(|m| apply_line(&mut text, m));
        let mut data = encode(&(text.join("\n") + "\n"), encoding);
        bytes.iter().for_each(|m| m.apply(&mut data));
        let scratch = temp_dir("fuzz-csv");
        let path = scratch.path().join("case.csv");
        check(&path, &data, &GridOptions { sample_rate_hz: None, max_gap_s })?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES / 4,
        rng_seed: RngSeed::Fixed(0x00C5_F023),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Random bytes, and random bytes after a valid header.
    #[test]
    fn random_bytes_load_or_fail_in_one_line(
        header in any::<bool>(),
        bytes in proptest::collection::vec(any::<u8>(), 0..600),
    ) {
        let data = if header { [b"time_s,rate_dps\n".as_slice(), &bytes].concat() } else { bytes };
        let scratch = temp_dir("fuzz-csv-random");
        let path = scratch.path().join("case.csv");
        check(&path, &data, &GridOptions::default())?;
    }
}

/// Regressions the fuzzing found: a time of -1e300 was printed with all 301 digits, and a
/// header of junk listed every column whole, control characters included.
#[test]
fn corrupt_numbers_and_headers_make_short_messages() {
    let scratch = temp_dir("fuzz-csv-regressions");
    let dir = scratch.path();
    let path = dir.join("back.csv");
    std::fs::write(&path, "time_s,rate_dps\n0,1\n0.001,1\n-1e300,1\n").unwrap();
    let err = gyro_log::load(
        &path,
        &LogOptions::default(),
        &GridOptions::default(),
        &mut |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("time goes back by 1.000000e300 s"), "{err}");
    assert_error(&err, Some(&path));

    let path = dir.join("junk.csv");
    let header: Vec<String> = (0..50)
        .map(|i| format!("\u{1}{}", "x".repeat(i * 10)))
        .collect();
    std::fs::write(&path, header.join(",") + "\n1,2\n").unwrap();
    let err = gyro_log::load(
        &path,
        &LogOptions::default(),
        &GridOptions::default(),
        &mut |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("… (50 columns)") && err.contains("\\u{1}"),
        "{err}"
    );
    assert_error(&err, Some(&path));
}
