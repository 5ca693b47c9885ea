//! Fuzz: MCAP logs through `gyro_log::load`. Seeds are the ROS 2 fixture bags and the
//! head of the bench fixture written by `write_mcap`, mutated byte by byte (flips,
//! truncation, insertion, duplication, deletion, lengths and times overwritten), plus
//! random bytes after the MCAP magic. None may panic; an error or warning is one line,
//! an error names the file; a log that loads has finite slots.
#![allow(clippy::unwrap_used)] // a failed unwrap fails the test

use crate::common::{byte_mutation, check_load, temp_dir, workspace_root};
use gyro_log::{ColumnOptions, GridOptions, LogOptions, McapOptions, TimeSource};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::path::Path;
use std::sync::OnceLock;

/// Cases of the mutation property (the random-bytes one runs a quarter as many).
const CASES: u32 = 2000;

/// The MCAP magic every file starts with.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn seeds() -> &'static [Vec<u8>] {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let root = workspace_root();
        // The first 300 rows of the bench log, written by the project's MCAP writer.
        let scratch = temp_dir("fuzz-mcap-seeds");
        let dir = scratch.path();
        let head: String = std::fs::read_to_string(root.join("fixtures/logs/bench_run.csv"))
            .unwrap()
            .lines()
            .take(304)
            .map(|l| format!("{l}\n"))
            .collect();
        let csv = dir.join("bench_head.csv");
        std::fs::write(&csv, head).unwrap();
        let log = gyro_log::read_csv(&csv, &ColumnOptions::default()).unwrap();
        let mcap = dir.join("bench_head.mcap");
        gyro_log::write_mcap(&mcap, &log).unwrap();
        vec![
            std::fs::read(mcap).unwrap(),
            std::fs::read(root.join("fixtures/mcap/ros2_imu.mcap")).unwrap(),
            std::fs::read(root.join("fixtures/mcap/ros2_two_imus.mcap")).unwrap(),
        ]
    })
}

/// Load `bytes` as an MCAP log: no panic, a one-line error naming the file, or finite slots.
fn check(path: &Path, bytes: &[u8], options: &LogOptions) -> Result<(), TestCaseError> {
    check_load(path, bytes, options, &GridOptions::default())
}

fn options() -> impl Strategy<Value = LogOptions> {
    (
        prop_oneof![
            3 => Just(None),
            1 => Just(Some("/imu/data".to_string())),
            1 => Just(Some("/gyro".to_string())),
        ],
        any::<bool>(),
    )
        .prop_map(|(topic, log_time)| LogOptions {
            mcap: McapOptions {
                topic,
                time_source: if log_time {
                    TimeSource::LogTime
                } else {
                    TimeSource::Header
                },
                ..McapOptions::default()
            },
            ..LogOptions::default()
        })
}

#[test]
fn the_unmutated_seeds_load() {
    let scratch = temp_dir("fuzz-mcap-unmutated");
    let dir = scratch.path();
    let options = LogOptions {
        mcap: McapOptions {
            topic: Some("/imu/data".into()),
            ..McapOptions::default()
        },
        ..LogOptions::default()
    };
    for (i, (seed, options)) in seeds()
        .iter()
        .zip([LogOptions::default(), LogOptions::default(), options])
        .enumerate()
    {
        let path = dir.join(format!("seed{i}.mcap"));
        std::fs::write(&path, seed).unwrap();
        let log = gyro_log::load(&path, &options, &GridOptions::default(), &mut |w| {
            panic!("{w}")
        });
        assert!(log.unwrap().slots.len() > 10, "seed {i}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x00AC_F022),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// A fixture MCAP mutated by bytes, read with some options.
    #[test]
    fn mutated_fixture_mcaps_load_or_fail_in_one_line(
        seed in 0usize..3,
        mutations in proptest::collection::vec(byte_mutation(), 1..6),
        options in options(),
    ) {
        let mut data = seeds()[seed].clone();
        mutations.iter().for_each(|m| m.apply(&mut data));
        let scratch = temp_dir("fuzz-mcap");
        let path = scratch.path().join("case.mcap");
        check(&path, &data, &options)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES / 4,
        rng_seed: RngSeed::Fixed(0x00AC_F023),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// The magic, then random bytes (with or without the closing magic).
    #[test]
    fn random_bytes_after_the_magic_fail_in_one_line(
        bytes in proptest::collection::vec(any::<u8>(), 0..600),
        closed in any::<bool>(),
    ) {
        let mut data = [MAGIC, &bytes].concat();
        if closed {
            data.extend_from_slice(MAGIC);
        }
        let scratch = temp_dir("fuzz-mcap-random");
        let path = scratch.path().join("case.mcap");
        check(&path, &data, &LogOptions::default())?;
    }
}
