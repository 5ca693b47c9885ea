//! The bench the pipeline is held to: simulated CRM100 runs of each kind of bias error,
//! scored causal (`run`) and offline (`run --offline`) against the per-rest mean.
//!
//! For each kind, over runs of seeds `seeds`: the median over runs of the max |accumulated
//! angle error| read at the middle of the rests ([`super::score_report`]), for the causal
//! run, the offline run and the per-rest mean; and how often each movement's 95% interval
//! (1.96 σ, `Movement.angle_std_deg`) covers its true angle, offline and causal.
//! `cargo run --release -p gyro-analysis --example bench_kinds` prints the table.

use super::{score_report, simulate_bench_run};
use crate::replay::{replay_with_mode, Mode, ReplayOptions};
use gyro_core::Config;
use gyro_sim::{Effect, SensorModel};

/// One kind of bench run: a sensor and the effects on it.
#[derive(Clone, Debug)]
pub struct BenchKind {
    /// What it is, for a table.
    pub name: &'static str,
    /// The sensor.
    pub sensor: SensorModel,
    /// Effect specs (`Effect::parse`).
    pub effects: &'static [&'static str],
    /// Whether the bias drifts within a run (where the filter should beat the rest mean by
    /// following it).
    pub drifting: bool,
}

/// A CRM100 whose bias holds still between power-ups: the simulator's nominal sensor with
/// a Gauss-Markov wander of σ 0.005 °/s (τ 100 s) instead of 0.05 °/s.
pub fn still_crm100() -> SensorModel {
    SensorModel {
        gm_sigma_dps: 0.005,
        ..SensorModel::default()
    }
}

/// The bench kinds: the nominal (still-bias) CRM100, a turn-on bias that differs per run
/// (σ 0.05 and 0.3 °/s), 1/f bias instability (10 and 50 °/h), a coarse output step (0.1
/// and 0.3 °/s), and three where the bias drifts within a run: the simulator's default
/// Gauss-Markov wander (σ 0.05 °/s, τ 100 s), a strong bias instability (0.05 °/s) and a
/// rate random walk (0.005 °/s/√s).
pub fn bench_kinds() -> Vec<BenchKind> {
    let still = still_crm100();
    let kind = |name, sensor, effects, drifting| BenchKind {
        name,
        sensor,
        effects,
        drifting,
    };
    vec![
        kind("nominal CRM100", still, &[], false),
        kind(
            "turn-on bias σ 0.05 °/s",
            still,
            &["turn_on_bias:sigma_dps=0.05"],
            false,
        ),
        kind(
            "turn-on bias σ 0.3 °/s",
            still,
            &["turn_on_bias:sigma_dps=0.3"],
            false,
        ),
        kind(
            "bias instability 10 °/h",
            still,
            &["bias_instability:sigma_dps=0.0028"],
            false,
        ),
        kind(
            "bias instability 50 °/h",
            still,
            &["bias_instability:sigma_dps=0.014"],
            false,
        ),
        kind(
            "output step 0.1 °/s",
            still,
            &["quantization:lsb_dps=0.1"],
            false,
        ),
        kind(
            "output step 0.3 °/s",
            still,
            &["quantization:lsb_dps=0.3"],
            false,
        ),
        kind(
            "drift: GM wander 0.05 °/s",
            SensorModel::default(),
            &[],
            true,
        ),
        kind(
            "drift: bias instability 0.05 °/s",
            still,
            &["bias_instability:sigma_dps=0.05"],
            true,
        ),
        kind(
            "drift: rate random walk 0.005",
            still,
            &["rate_random_walk:k_dps_per_rt_s=0.005"],
            true,
        ),
    ]
}

/// One kind scored over some runs.
#[derive(Clone, Debug, PartialEq)]
pub struct KindScore {
    /// Median over runs of the max |accumulated error| at mid-rest (deg): causal run.
    pub causal_deg: f64,
    /// The same, offline run.
    pub offline_deg: f64,
    /// The same, per-rest mean.
    pub rest_mean_deg: f64,
    /// Median |error| of each movement's own angle (deg): causal (at its end), offline
    /// (after the rest that follows), and the per-rest mean's per movement.
    pub movement_deg: [f64; 3],
    /// Movements whose offline 95% interval covers the truth, of how many.
    pub offline_covered: (usize, usize),
    /// Movements whose causal 95% interval covers the truth, of how many.
    pub causal_covered: (usize, usize),
    /// Median over runs of the max |accumulated error| at mid-rest (deg) of an estimate
    /// that knows the bias exactly and that the rests are still: the same runs' white
    /// noise (and the kind's output step) integrated over the movements alone, what no
    /// estimate of the bias removes ([`bias_known_max_deg`]).
    pub bias_known_deg: f64,
}

impl KindScore {
    /// Causal over per-rest mean.
    pub fn causal_ratio(&self) -> f64 {
        self.causal_deg / self.rest_mean_deg
    }

    /// Offline over per-rest mean.
    pub fn offline_ratio(&self) -> f64 {
        self.offline_deg / self.rest_mean_deg
    }

    /// The bias known exactly, over the per-rest mean: the floor of any estimate's ratio.
    pub fn bias_known_ratio(&self) -> f64 {
        self.bias_known_deg / self.rest_mean_deg
    }
}

/// The max |accumulated angle error| at mid-rest (deg) of run `seed` of `kind` for an
/// estimate that knows the bias exactly: the run simulated again with no bias, no wander
/// and no bias effect (the same seed draws the same white noise and the same motion; the
/// kind's output step is kept), its movements integrated with a bias of zero.
pub fn bias_known_max_deg(
    kind: &BenchKind,
    seed: u64,
) -> Result<f64, Box<dyn std::error::Error + Send + Sync>> {
    let sensor = SensorModel {
        bias_dps: 0.0,
        gm_sigma_dps: 0.0,
        ..kind.sensor
    };
    let steps = kind
        .effects
        .iter()
        .map(|s| Effect::parse(s))
        .filter(|e| matches!(e, Ok(Effect::Quantization { .. })))
        .collect::<Result<Vec<_>, _>>()?;
    let run = simulate_bench_run(&sensor, &steps, seed)?;
    let times_s: Vec<f64> = run.log.slots.iter().map(|s| s.time_s).collect();
    let rates_dps: Vec<f64> = run.log.slots.iter().map(|s| s.rate_dps).collect();
    let rests = super::rests_between(&run.rotations, &times_s);
    let angles = super::rest_angles(&rates_dps, 1.0 / run.log.sample_rate_hz, &rests, |_| 0.0);
    let reference = |rest: &super::Rest| {
        run.log.slots[(rest.start + rest.end) / 2]
            .reference_deg
            .unwrap_or(f64::NAN)
    };
    let origin = rests.first().map_or(0.0, reference);
    Ok(rests
        .iter()
        .zip(angles)
        .map(|(rest, angle)| (angle - (reference(rest) - origin)).abs())
        .fold(0.0, f64::max))
}

/// The crate's one median ([`crate::median`]), NaN for none.
fn median(v: Vec<f64>) -> f64 {
    crate::median(&v).unwrap_or(f64::NAN)
}

/// Score `kind` with `config` on the runs of `seeds`.
pub fn score_kind(
    kind: &BenchKind,
    config: &Config,
    seeds: std::ops::Range<u64>,
) -> Result<KindScore, Box<dyn std::error::Error + Send + Sync>> {
    let effects = kind
        .effects
        .iter()
        .map(|s| Effect::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let options = ReplayOptions::default();
    let (mut max_c, mut max_o, mut max_r) = (vec![], vec![], vec![]);
    let (mut mv_c, mut mv_o, mut mv_r) = (vec![], vec![], vec![]);
    let (mut cover_o, mut cover_c) = ((0, 0), (0, 0));
    let mut known = vec![];
    for seed in seeds {
        known.push(bias_known_max_deg(kind, seed)?);
        let run = simulate_bench_run(&kind.sensor, &effects, seed)?;
        let causal = replay_with_mode(&run.log, config, &options, Mode::Causal)?;
        let offline = replay_with_mode(&run.log, config, &options, Mode::Offline)?;
        let c = score_report(&run.log, &run.rotations, &causal);
        let o = score_report(&run.log, &run.rotations, &offline);
        max_c.push(c.max_abs().0);
        max_o.push(o.max_abs().0);
        max_r.push(c.max_abs().1);
        mv_r.extend(c.per_movement().into_iter().map(|(_, r)| r.abs()));
        for ((truth_deg, fc), (_, fo)) in run
            .movements(&causal)
            .into_iter()
            .zip(run.movements(&offline))
        {
            let (Some(mc), Some(mo)) = (fc.filter(|m| m.complete), fo.filter(|m| m.complete))
            else {
                continue;
            };
            for (m, errors, cover) in [(mc, &mut mv_c, &mut cover_c), (mo, &mut mv_o, &mut cover_o)]
            {
                let e = (f64::from(m.angle_deg) - truth_deg).abs();
                errors.push(e);
                if let Some(std) = m.angle_std_deg {
                    cover.0 += usize::from(e <= 1.96 * f64::from(std));
                    cover.1 += 1;
                }
            }
        }
    }
    Ok(KindScore {
        causal_deg: median(max_c),
        offline_deg: median(max_o),
        rest_mean_deg: median(max_r),
        movement_deg: [median(mv_c), median(mv_o), median(mv_r)],
        offline_covered: cover_o,
        causal_covered: cover_c,
        bias_known_deg: median(known),
    })
}

/// Geometric mean of `values`.
pub fn geometric_mean(values: impl IntoIterator<Item = f64>) -> f64 {
    let (sum, n) = values
        .into_iter()
        .fold((0.0, 0.0), |(s, n), v: f64| (s + v.ln(), n + 1.0));
    (sum / n).exp()
}
