//! The default pipeline held to the per-rest estimator on simulated CRM100 bench runs at
//! 1 kHz (fewer runs here; `cargo run --release -p gyro-analysis --example
//! rest_mean_bench` prints the full table).
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::rest_mean::{score, simulate_bench_run};
use gyro_core::Config;
use gyro_sim::{Effect, SensorModel};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median |error| per movement of (pipeline, per-rest estimator) over `runs` runs.
fn per_movement(effects: &[&str], runs: u64) -> (f64, f64) {
    let effects: Vec<Effect> = effects.iter().map(|s| Effect::parse(s).unwrap()).collect();
    let sensor = SensorModel::default();
    let (mut pipeline, mut oracle) = (vec![], vec![]);
    for seed in 1..=runs {
        let run = simulate_bench_run(&sensor, &effects, seed).unwrap();
        let errors = score(&run.log, &run.rotations, &Config::default()).unwrap();
        assert_eq!(errors.pipeline_deg.len(), run.rotations.len() + 1);
        for (p, o) in errors.per_movement() {
            pipeline.push(p.abs());
            oracle.push(o.abs());
        }
    }
    (median(pipeline), median(oracle))
}

#[test]
fn the_default_pipeline_is_not_worse_than_the_rest_mean_per_movement() {
    for effects in [
        &[][..],
        &["turn_on_bias:sigma_dps=0.3"][..],
        &["bias_instability:sigma_dps=0.05"][..],
        &["quantization:lsb_dps=0.2"][..],
        &["rate_random_walk:k_dps_per_rt_s=0.005"][..],
    ] {
        let (pipeline, oracle) = per_movement(effects, 5);
        assert!(
            pipeline <= oracle,
            "{effects:?}: pipeline {pipeline:.4} deg, rest mean {oracle:.4} deg"
        );
    }
}
