//! The causal `run` and `run --offline` beside the per-rest mean on the bench kinds of
//! [`gyro_analysis::rest_mean::bench`], one kind per line: the median over runs of the max
//! |accumulated angle error| at mid-rest as a ratio to the per-rest mean's (and that of an
//! estimate that knows the bias exactly, the floor of any); the median |error|
//! of each movement's own angle (causal, offline, per-rest mean); how often the 95% interval
//! (1.96 σ) covers the true angle, offline and causal.
//!
//! `cargo run --release -p gyro-analysis --example bench_kinds [RUNS [FIRST_SEED]]` (default
//! 20 runs of 90 s at 1 kHz per kind from seed 1: the development seeds; 1000 on are the
//! judging seeds).
use gyro_analysis::rest_mean::bench::{bench_kinds, geometric_mean, score_kind};
use gyro_core::Config;

fn main() -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let runs: u64 = std::env::args().nth(1).map_or(Ok(20), |a| a.parse())?;
    let first_seed: u64 = std::env::args().nth(2).map_or(Ok(1), |a| a.parse())?;
    let config = Config::default();
    println!("seeds {first_seed}..{}", first_seed + runs - 1);
    println!("| kind | causal / rest mean | offline / rest mean | bias known / rest mean | movement: causal | offline | rest mean | 95% covers: offline | causal |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut causal, mut offline, mut known) = (vec![], vec![], vec![]);
    let (mut cover_o, mut cover_c) = ((0, 0), (0, 0));
    for kind in bench_kinds() {
        let s = score_kind(&kind, &config, first_seed..first_seed + runs)?;
        let pct = |c: (usize, usize)| 100.0 * c.0 as f64 / c.1.max(1) as f64;
        println!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.4}° | {:.4}° | {:.4}° | {:.1}% | {:.1}% |",
            kind.name,
            s.causal_ratio(),
            s.offline_ratio(),
            s.bias_known_ratio(),
            s.movement_deg[0],
            s.movement_deg[1],
            s.movement_deg[2],
            pct(s.offline_covered),
            pct(s.causal_covered),
        );
        causal.push(s.causal_ratio());
        offline.push(s.offline_ratio());
        known.push(s.bias_known_ratio());
        cover_o = (
            cover_o.0 + s.offline_covered.0,
            cover_o.1 + s.offline_covered.1,
        );
        cover_c = (
            cover_c.0 + s.causal_covered.0,
            cover_c.1 + s.causal_covered.1,
        );
    }
    println!(
        "geometric mean: causal {:.2} (worst {:.2}), offline {:.2}, bias known {:.2}; 95% covers offline {:.1}%, causal {:.1}% of {} movements",
        geometric_mean(causal.iter().copied()),
        causal.iter().copied().fold(0.0, f64::max),
        geometric_mean(offline.iter().copied()),
        geometric_mean(known.iter().copied()),
        100.0 * cover_o.0 as f64 / cover_o.1.max(1) as f64,
        100.0 * cover_c.0 as f64 / cover_c.1.max(1) as f64,
        cover_o.1,
    );
    Ok(())
}
