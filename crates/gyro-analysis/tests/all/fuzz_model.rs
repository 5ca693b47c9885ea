//! Fuzz: model files through `gyro_analysis::model::load`. Seeds are model files written
//! by `model::save` (the default, and one with a correction, a sensor range and a
//! reference delay), mutated by token (numbers replaced by odd values, lines duplicated
//! or deleted, odd lines inserted) and by byte (flips, truncation, insertion), re-encoded
//! (BOM, UTF-16), plus random bytes. None may panic; an error is one line naming the file;
//! a model that loads makes a pipeline.
#![allow(clippy::unwrap_used)] // a failed unwrap fails the test

use gyro_analysis::model::{self, ModelFile};
use gyro_core::{Config, Pipeline};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::path::Path;
use std::sync::OnceLock;

/// Cases of the mutation property (the random-bytes one runs a quarter as many).
const CASES: u32 = 3000;

/// Longest error message accepted beyond the path (see `gyro-log`'s fuzz tests).
const MAX_ERROR_CHARS: usize = 400;

/// A fresh folder for one test, named after it; removed with everything in it when the
/// returned guard is dropped, so that test runs leave nothing in the temporary folder.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gyro-analysis-{name}-"))
        .tempdir()
        .unwrap()
}

fn seeds() -> &'static [String] {
    static SEEDS: OnceLock<Vec<String>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let scratch = temp_dir("fuzz-model-seeds");
        let dir = scratch.path();
        let mut fitted = ModelFile::new(Config::default());
        fitted.config.correction.scale_k = 0.02;
        fitted.config.correction.bias_dps_per_c = 0.05;
        fitted.sensor.range_dps = 120.0;
        fitted.reference_delay_s = 0.01;
        [ModelFile::new(Config::default()), fitted]
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let path = dir.join(format!("seed{i}.json"));
                model::save(&path, m).unwrap();
                std::fs::read_to_string(path).unwrap()
            })
            .collect()
    })
}

/// What a number, or a whole value, is replaced with.
const ODD_VALUES: &[&str] = &[
    "0",
    "-1",
    "-0",
    "1e308",
    "-1e308",
    "1e999",
    "1e-320",
    "4294967296",
    "18446744073709551616",
    "NaN",
    "Infinity",
    "null",
    "true",
    "\"x\"",
    "[]",
    "{}",
    "[1,2]",
    "\"\u{e9}\"",
    "1.5",
    "\"paper\"",
    "\"kalman\"",
    "\"none\"",
    "100000000",
    "0.5",
];

/// Lines inserted after a `{`.
const ODD_LINES: &[&str] = &[
    "\"unknown\": 1,",
    "\"format\": \"gyro-model\",",
    "\"version\": 2,",
    "\"sample_rate_hz\": 0,",
    "\"config\": {},",
    "\"reference_delay_s\": 5,",
    "\"\u{0}\": 0,",
];

#[derive(Clone, Debug)]
enum Mutation {
    /// Replace the n-th number (or value after a `:`) with an odd value.
    Value(usize, usize),
    DuplicateLine(usize),
    DeleteLine(usize),
    InsertLine(usize, usize),
    Flip(usize, u8),
    Truncate(usize),
    Insert(usize, Vec<u8>),
    LongString(usize),
    /// Replace the n-th value with a long string.
    LongValue(usize, usize),
}

/// `text` with its `i`-th value (counted modulo their number) replaced by `value`.
fn replace_value(text: &str, i: usize, value: &str) -> Vec<u8> {
    // Places where a value starts: after ": ".
    let starts: Vec<usize> = text.match_indices(": ").map(|(at, _)| at + 2).collect();
    if starts.is_empty() {
        return text.as_bytes().to_vec();
    }
    let start = starts[i % starts.len()];
    let end = text[start..]
        .find([',', '\n', '}'])
        .map_or(text.len(), |e| start + e);
    // An object is kept: the value goes in front of it.
    let end = if text[start..].starts_with('{') {
        start
    } else {
        end
    };
    [&text[..start], value, &text[end..]].concat().into_bytes()
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let (n_values, n_lines) = (ODD_VALUES.len(), ODD_LINES.len());
    prop_oneof![
        6 => (any::<usize>(), 0..n_values).prop_map(|(i, v)| Mutation::Value(i, v)),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
        2 => any::<usize>().prop_map(Mutation::DeleteLine),
        2 => (any::<usize>(), 0..n_lines).prop_map(|(i, v)| Mutation::InsertLine(i, v)),
        2 => (any::<usize>(), 0u8..8).prop_map(|(i, b)| Mutation::Flip(i, b)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
        1 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..20))
            .prop_map(|(i, b)| Mutation::Insert(i, b)),
        1 => (100usize..3000).prop_map(Mutation::LongString),
        1 => (any::<usize>(), 100usize..3000).prop_map(|(i, n)| Mutation::LongValue(i, n)),
    ]
}

fn apply(bytes: &mut Vec<u8>, mutation: &Mutation) {
    let n = bytes.len();
    if n == 0 {
        return;
    }
    let text = String::from_utf8_lossy(bytes).into_owned();
    let lines: Vec<&str> = text.lines().collect();
    match mutation {
        Mutation::Value(i, v) => *bytes = replace_value(&text, *i, ODD_VALUES[*v]),
        Mutation::LongValue(i, len) => {
            *bytes = replace_value(&text, *i, &format!("\"{}\"", "w".repeat(*len)));
        }
        Mutation::DuplicateLine(i) | Mutation::DeleteLine(i) | Mutation::InsertLine(i, _) => {
            let mut lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            if lines.is_empty() {
                return;
            }
            let at = i % lines.len();
            match mutation {
                Mutation::DuplicateLine(_) => lines.insert(at, lines[at].clone()),
                Mutation::DeleteLine(_) => drop(lines.remove(at)),
                Mutation::InsertLine(_, v) => {
                    let after = lines.iter().position(|l| l.ends_with('{')).unwrap_or(0);
                    lines.insert(after + 1, ODD_LINES[*v].to_string());
                }
                _ => unreachable!(),
            }
            *bytes = (lines.join("\n") + "\n").into_bytes();
        }
        Mutation::Flip(i, bit) => bytes[i % n] ^= 1 << bit,
        Mutation::Truncate(i) => bytes.truncate(i % n),
        Mutation::Insert(i, new) => {
            let at = i % (n + 1);
            bytes.splice(at..at, new.iter().copied());
        }
        Mutation::LongString(len) => {
            let long = format!("\"{}\"", "w".repeat(*len));
            *bytes = text.replacen("\"gyro-model\"", &long, 1).into_bytes();
        }
    }
}

/// Load `bytes` as a model file: no panic, a one-line error naming the file, or a model
/// the core accepts.
fn check(path: &Path, bytes: &[u8]) -> Result<(), TestCaseError> {
    std::fs::write(path, bytes).unwrap();
    match model::load(path) {
        Ok(model) => {
            prop_assert!(Pipeline::try_new(&model.config).is_ok());
            prop_assert!(model.reference_delay_s.is_finite());
        }
        Err(error) => {
            let message = error.to_string();
            prop_assert!(!message.contains('\n'), "more than one line: {message:?}");
            prop_assert!(message.contains(&*path.to_string_lossy()), "{message:?}");
            prop_assert!(
                message.chars().count() <= MAX_ERROR_CHARS + path.as_os_str().len(),
                "message of {} characters: {message:?}",
                message.chars().count()
            );
        }
    }
    Ok(())
}

#[test]
fn the_unmutated_seeds_load() {
    let scratch = temp_dir("fuzz-model-unmutated");
    let path = scratch.path().join("model.json");
    for seed in seeds() {
        std::fs::write(&path, seed).unwrap();
        model::load(&path).unwrap();
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x0030_DE11),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// A saved model file mutated, maybe with a BOM or as UTF-16.
    #[test]
    fn mutated_model_files_load_or_fail_in_one_line(
        seed in 0usize..2,
        mutations in proptest::collection::vec(mutation(), 1..5),
        encoding in prop_oneof![8 => Just(0u8), 1 => Just(1u8), 1 => Just(2u8)],
    ) {
        let mut data = seeds()[seed].clone().into_bytes();
        mutations.iter().for_each(|m| apply(&mut data, m));
        let data = match encoding {
            0 => data,
            1 => [&[0xEF, 0xBB, 0xBF], data.as_slice()].concat(),
            _ => [0xFF, 0xFE]
                .into_iter()
                .chain(String::from_utf8_lossy(&data).encode_utf16().flat_map(u16::to_le_bytes))
                .collect(),
        };
        check(&temp_dir("fuzz-model").path().join("model.json"), &data)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES / 4,
        rng_seed: RngSeed::Fixed(0x0030_DE12),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Random bytes, and random bytes after an opening brace.
    #[test]
    fn random_bytes_fail_in_one_line(
        brace in any::<bool>(),
        bytes in proptest::collection::vec(any::<u8>(), 0..300),
    ) {
        let data = if brace { [b"{\"format\": ".as_slice(), &bytes].concat() } else { bytes };
        check(&temp_dir("fuzz-model-random").path().join("model.json"), &data)?;
    }
}

/// Regression the fuzzing found: a long string where a number belongs, or as the format,
/// was quoted whole (and serde's position repeated).
#[test]
fn long_values_are_quoted_cut() {
    let scratch = temp_dir("fuzz-model-regressions");
    let path = scratch.path().join("model.json");
    let long = "w".repeat(500);
    for text in [
        format!("{{\"format\": \"gyro-model\", \"version\": \"{long}\"}}"),
        format!("{{\"format\": \"{long}\", \"version\": 1}}"),
    ] {
        std::fs::write(&path, text).unwrap();
        let err = model::load(&path).unwrap_err().to_string();
        assert!(err.contains("… (500 characters)"), "{err}");
        assert!(!err.contains(" at line "), "{err}");
        assert!(err.len() < 200 + path.as_os_str().len(), "{err}");
    }
}
