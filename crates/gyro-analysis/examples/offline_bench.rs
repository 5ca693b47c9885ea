//! `run --offline` beside the causal `run` and the per-rest mean on simulated CRM100 bench
//! runs, one kind per line: the median over runs of the max |accumulated angle error| at the
//! middle of the rests, as a ratio to the per-rest mean's (the causal series there has had half
//! the rest after: it is nearly the offline one); the median |error| of each movement's own
//! angle (`Movement.angle_deg`: the causal one at the movement's end, the offline one after the
//! rest that follows) beside the per-rest mean's per movement; and how often the offline 95% interval (1.96 σ) covers the true angle, with
//! the quantiles of |error|/σ.
//!
//! `cargo run --release -p gyro-analysis --example offline_bench [RUNS [FIRST_SEED
//! [GM_SIGMA_DPS]]]` (default 20 runs of 90 s at 1 kHz per kind, seeds FIRST_SEED.. (1..) on;
//! GM_SIGMA_DPS replaces the sensor's Gauss-Markov bias wander, 0.05 deg/s by default: 0.005
//! or 0 is a sensor whose bias holds still between power-ups).
use gyro_analysis::replay::{replay_with_mode, Mode, ReplayOptions};
use gyro_analysis::rest_mean::{score_report, simulate_bench_run};
use gyro_core::Config;
use gyro_sim::{Effect, SensorModel};

/// The crate's one median ([`gyro_analysis::median`]), NaN for none.
fn median(v: Vec<f64>) -> f64 {
    gyro_analysis::median(&v).unwrap_or(f64::NAN)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let runs: u64 = std::env::args().nth(1).map_or(Ok(20), |a| a.parse())?;
    let first_seed: u64 = std::env::args().nth(2).map_or(Ok(1), |a| a.parse())?;
    let defaults = SensorModel::default();
    let sensor = SensorModel {
        gm_sigma_dps: std::env::args()
            .nth(3)
            .map_or(Ok(defaults.gm_sigma_dps), |a| a.parse())?,
        ..defaults
    };
    let kinds: [(&str, &[&str]); 9] = [
        ("nominal model", &[]),
        ("turn-on bias 0.05 deg/s", &["turn_on_bias:sigma_dps=0.05"]),
        ("turn-on bias 0.3 deg/s", &["turn_on_bias:sigma_dps=0.3"]),
        (
            "bias instability 10 deg/h",
            &["bias_instability:sigma_dps=0.0028"],
        ),
        (
            "bias instability 50 deg/h",
            &["bias_instability:sigma_dps=0.014"],
        ),
        ("output step 0.1 deg/s", &["quantization:lsb_dps=0.1"]),
        ("output step 0.3 deg/s", &["quantization:lsb_dps=0.3"]),
        (
            "bias instability 0.05 deg/s",
            &["bias_instability:sigma_dps=0.05"],
        ),
        (
            "rate random walk 0.005",
            &["rate_random_walk:k_dps_per_rt_s=0.005"],
        ),
    ];
    println!(
        "{:<28} {:>8} {:>8} {:>8} | {:>6} {:>6} | {:>8} {:>8} {:>8} | {:>6} {:>6} | cover95  |e|/σ p50 p90 p99",
        "kind", "causal", "offline", "restmean", "c/rm", "o/rm", "causal", "offline", "restmean", "c/rm", "o/rm"
    );
    let (mut log_causal, mut log_offline, mut count) = (0.0, 0.0, 0.0);
    let mut covered_all = (0_usize, 0_usize);
    for (name, specs) in kinds {
        let effects = specs
            .iter()
            .map(|s| Effect::parse(s))
            .collect::<Result<Vec<_>, _>>()?;
        let (mut max_c, mut max_o, mut max_r) = (vec![], vec![], vec![]);
        let (mut mv_c, mut mv_o, mut mv_r) = (vec![], vec![], vec![]);
        let mut ratios = vec![];
        let mut covered = (0_usize, 0_usize);
        for seed in first_seed..first_seed + runs {
            let run = simulate_bench_run(&sensor, &effects, seed)?;
            let options = ReplayOptions::default();
            let causal = replay_with_mode(&run.log, &Config::default(), &options, Mode::Causal)?;
            let offline = replay_with_mode(&run.log, &Config::default(), &options, Mode::Offline)?;
            let c = score_report(&run.log, &run.rotations, &causal);
            let o = score_report(&run.log, &run.rotations, &offline);
            max_c.push(c.max_abs().0);
            max_o.push(o.max_abs().0);
            max_r.push(c.max_abs().1);
            for (_, pr) in c.per_movement() {
                mv_r.push(pr.abs());
            }
            // Each movement's own angle against the truth: the causal one at its end, the
            // offline one after the rest that follows.
            for ((truth_deg, fc), (_, fo)) in run
                .movements(&causal)
                .into_iter()
                .zip(run.movements(&offline))
            {
                if let (Some(mc), Some(mo)) = (fc.filter(|m| m.complete), fo.filter(|m| m.complete))
                {
                    mv_c.push((f64::from(mc.angle_deg) - truth_deg).abs());
                    mv_o.push((f64::from(mo.angle_deg) - truth_deg).abs());
                }
            }
            for (truth_deg, found) in run.movements(&offline) {
                let Some(m) = found.filter(|m| m.complete) else {
                    continue;
                };
                if let Some(std) = m.angle_std_deg {
                    let e = (f64::from(m.angle_deg) - truth_deg).abs();
                    covered.0 += usize::from(e <= 1.96 * f64::from(std));
                    covered.1 += 1;
                    ratios.push(e / f64::from(std));
                }
            }
        }
        let (a, b, r) = (median(max_c), median(max_o), median(max_r));
        let (d, e, f) = (median(mv_c), median(mv_o), median(mv_r));
        log_causal += (a / r).ln();
        log_offline += (b / r).ln();
        count += 1.0;
        covered_all.0 += covered.0;
        covered_all.1 += covered.1;
        ratios.sort_by(f64::total_cmp);
        let q = |p: f64| {
            ratios
                .get(((ratios.len() as f64 * p) as usize).min(ratios.len().saturating_sub(1)))
                .copied()
                .unwrap_or(f64::NAN)
        };
        println!(
            "{name:<28} {a:>7.3}° {b:>7.3}° {r:>7.3}° | {:>6.2} {:>6.2} | {d:>7.4}° {e:>7.4}° {f:>7.4}° | {:>6.2} {:>6.2} | {:>5.1}%  {:.2} {:.2} {:.2}",
            a / r,
            b / r,
            d / f,
            e / f,
            100.0 * covered.0 as f64 / covered.1.max(1) as f64,
            q(0.5),
            q(0.9),
            q(0.99),
        );
    }
    println!(
        "geometric mean of the max ratios: causal {:.2}, offline {:.2}; offline 95% interval covers {:.1}% of {} movements",
        (log_causal / count).exp(),
        (log_offline / count).exp(),
        100.0 * covered_all.0 as f64 / covered_all.1.max(1) as f64,
        covered_all.1
    );
    Ok(())
}
