//! The unmodelled effects: one table shared by the simulator and the diagnosis.
//!
//! Each effect is a term the simulator can add to the nominal sensor model, with named
//! parameters in stated units. Ids are the fixed vocabulary of DESIGN.md; JSON is
//! `{"id": "scale_factor", "params": {"k": 0.01}}`.

use serde::{Deserialize, Serialize};

/// An effect with its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "id",
    content = "params",
    rename_all = "snake_case",
    deny_unknown_fields
)]
pub enum Effect {
    /// Scale error: rate × (1 + k).
    ScaleFactor {
        /// Relative scale error (1 = 100%).
        k: f64,
    },
    /// Scale differs by sign: rate × (1 + k·sign(rate)).
    ScaleAsymmetry {
        /// Half the difference between the positive and negative scales.
        k: f64,
    },
    /// Cubic nonlinearity: rate + k3·rate³.
    Nonlinearity {
        /// Cubic coefficient (1/(deg/s)²).
        k3_per_dps2: f64,
    },
    /// Output clipped at ±limit.
    Saturation {
        /// Clip level (deg/s).
        limit_dps: f64,
    },
    /// Output rounded to a step.
    Quantization {
        /// Step (deg/s).
        lsb_dps: f64,
    },
    /// The gyro lags the true motion (and the reference).
    Latency {
        /// Delay (s).
        delay_s: f64,
    },
    /// The sensor's sample clock runs fast by `ppm`: sample k is taken at k/(fs(1+ε)), and
    /// the log stamps it with that time (a logger's accurate clock) while `sample_rate_hz`
    /// stays the nominal fs the firmware integrates with. The rate is right at its stamp;
    /// integrated over nominal periods, the angle gains ε × the angle turned.
    ClockError {
        /// Clock error (parts per million).
        ppm: f64,
    },
    /// Lost samples: rows missing from the log.
    Dropouts {
        /// Dropout events per second.
        rate_per_s: f64,
        /// Mean number of consecutive samples lost per event.
        mean_samples: f64,
    },
    /// Bias proportional to the temperature change from the start.
    TemperatureBias {
        /// Bias change per °C (deg/s/°C).
        dps_per_c: f64,
    },
    /// Scale proportional to the temperature change: rate × (1 + s·ΔT).
    TemperatureScale {
        /// Relative scale change per °C (1/°C).
        per_c: f64,
    },
    /// Flicker-like bias wander (sum of Gauss-Markov processes with τ from 1 to 1000 s),
    /// giving a flat Allan deviation floor at long τ.
    BiasInstability {
        /// Standard deviation of the wander (deg/s).
        sigma_dps: f64,
    },
    /// Bias random walk: Allan slope +½ at long τ.
    RateRandomWalk {
        /// Random walk coefficient (deg/s/√s).
        k_dps_per_rt_s: f64,
    },
    /// A constant bias drawn anew for every run (power cycle).
    TurnOnBias {
        /// Standard deviation across runs (deg/s).
        sigma_dps: f64,
    },
    /// The sensor's own low-pass (2nd-order, critically damped) on the true rate.
    Bandwidth {
        /// -3 dB bandwidth (Hz).
        cutoff_hz: f64,
    },
}

/// Static description of an effect kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EffectInfo {
    /// The id (JSON and CLI).
    pub id: &'static str,
    /// Parameter names with their units.
    pub params: &'static [(&'static str, &'static str)],
    /// What the effect does and the signature it leaves in data.
    pub signature: &'static str,
    /// A realistic magnitude for a low-cost MEMS gyro (used by tests and the self-check).
    pub typical: Effect,
}

/// All effects, in the DESIGN.md order.
pub const EFFECTS: &[EffectInfo] = &[
    EffectInfo {
        id: "scale_factor",
        params: &[("k", "1")],
        signature: "only in motion, residual proportional to rate",
        typical: Effect::ScaleFactor { k: 0.01 },
    },
    EffectInfo {
        id: "scale_asymmetry",
        params: &[("k", "1")],
        signature: "scale error that differs by the sign of the rate",
        typical: Effect::ScaleAsymmetry { k: 0.005 },
    },
    EffectInfo {
        id: "nonlinearity",
        params: &[("k3_per_dps2", "1/(deg/s)^2")],
        signature: "residual curved (cubic) in the rate",
        typical: Effect::Nonlinearity { k3_per_dps2: 2e-7 },
    },
    EffectInfo {
        id: "saturation",
        params: &[("limit_dps", "deg/s")],
        signature: "raw values clipped at a level",
        typical: Effect::Saturation { limit_dps: 120.0 },
    },
    EffectInfo {
        id: "quantization",
        params: &[("lsb_dps", "deg/s")],
        signature: "raw values on a grid (rounding each rate sample adds white rate noise of lsb^2/12: a higher -1/2 Allan slope, not -1)",
        typical: Effect::Quantization { lsb_dps: 0.2 },
    },
    EffectInfo {
        id: "latency",
        params: &[("delay_s", "s")],
        signature: "residual proportional to angular acceleration; cross-correlation peak off zero",
        typical: Effect::Latency { delay_s: 0.005 },
    },
    EffectInfo {
        id: "clock_error",
        params: &[("ppm", "ppm")],
        signature: "time stamps drift from the nominal rate; angle error proportional to total angle; rate residual clean at the stamps",
        typical: Effect::ClockError { ppm: 5000.0 },
    },
    EffectInfo {
        id: "dropouts",
        params: &[("rate_per_s", "1/s"), ("mean_samples", "samples")],
        signature: "missing samples; angle lost during motion",
        typical: Effect::Dropouts {
            rate_per_s: 0.5,
            mean_samples: 5.0,
        },
    },
    EffectInfo {
        id: "temperature_bias",
        params: &[("dps_per_c", "deg/s/degC")],
        signature: "static bias tracks temperature",
        typical: Effect::TemperatureBias { dps_per_c: 0.05 },
    },
    EffectInfo {
        id: "temperature_scale",
        params: &[("per_c", "1/degC")],
        signature: "scale error tracks temperature",
        typical: Effect::TemperatureScale { per_c: 1e-3 },
    },
    EffectInfo {
        id: "bias_instability",
        params: &[("sigma_dps", "deg/s")],
        signature: "Allan deviation flat (slope 0) at long tau",
        typical: Effect::BiasInstability { sigma_dps: 0.05 },
    },
    EffectInfo {
        id: "rate_random_walk",
        params: &[("k_dps_per_rt_s", "deg/s/sqrt(s)")],
        signature: "Allan slope +1/2 at long tau",
        typical: Effect::RateRandomWalk {
            k_dps_per_rt_s: 0.005,
        },
    },
    EffectInfo {
        id: "turn_on_bias",
        params: &[("sigma_dps", "deg/s")],
        signature: "between-run spread of static means much larger than within-run",
        typical: Effect::TurnOnBias { sigma_dps: 0.5 },
    },
    EffectInfo {
        id: "bandwidth",
        params: &[("cutoff_hz", "Hz")],
        signature: "high-band PSD attenuated, lag",
        typical: Effect::Bandwidth { cutoff_hz: 15.0 },
    },
];

impl Effect {
    /// The effect's id.
    pub fn id(&self) -> &'static str {
        self.info().id
    }

    /// The table entry of this effect's kind.
    pub fn info(&self) -> &'static EffectInfo {
        let index = match self {
            Effect::ScaleFactor { .. } => 0,
            Effect::ScaleAsymmetry { .. } => 1,
            Effect::Nonlinearity { .. } => 2,
            Effect::Saturation { .. } => 3,
            Effect::Quantization { .. } => 4,
            Effect::Latency { .. } => 5,
            Effect::ClockError { .. } => 6,
            Effect::Dropouts { .. } => 7,
            Effect::TemperatureBias { .. } => 8,
            Effect::TemperatureScale { .. } => 9,
            Effect::BiasInstability { .. } => 10,
            Effect::RateRandomWalk { .. } => 11,
            Effect::TurnOnBias { .. } => 12,
            Effect::Bandwidth { .. } => 13,
        };
        &EFFECTS[index]
    }

    /// Parameter values in the order of [`EffectInfo::params`].
    pub fn params(&self) -> Vec<f64> {
        match *self {
            Effect::ScaleFactor { k } | Effect::ScaleAsymmetry { k } => vec![k],
            Effect::Nonlinearity { k3_per_dps2 } => vec![k3_per_dps2],
            Effect::Saturation { limit_dps } => vec![limit_dps],
            Effect::Quantization { lsb_dps } => vec![lsb_dps],
            Effect::Latency { delay_s } => vec![delay_s],
            Effect::ClockError { ppm } => vec![ppm],
            Effect::Dropouts {
                rate_per_s,
                mean_samples,
            } => vec![rate_per_s, mean_samples],
            Effect::TemperatureBias { dps_per_c } => vec![dps_per_c],
            Effect::TemperatureScale { per_c } => vec![per_c],
            Effect::BiasInstability { sigma_dps } | Effect::TurnOnBias { sigma_dps } => {
                vec![sigma_dps]
            }
            Effect::RateRandomWalk { k_dps_per_rt_s } => vec![k_dps_per_rt_s],
            Effect::Bandwidth { cutoff_hz } => vec![cutoff_hz],
        }
    }

    /// The same kind of effect with other parameter values (order of [`Self::params`]);
    /// `None` if the count is wrong.
    pub fn with_params(&self, values: &[f64]) -> Option<Effect> {
        if values.len() != self.info().params.len() {
            return None;
        }
        let v = values[0];
        Some(match self {
            Effect::ScaleFactor { .. } => Effect::ScaleFactor { k: v },
            Effect::ScaleAsymmetry { .. } => Effect::ScaleAsymmetry { k: v },
            Effect::Nonlinearity { .. } => Effect::Nonlinearity { k3_per_dps2: v },
            Effect::Saturation { .. } => Effect::Saturation { limit_dps: v },
            Effect::Quantization { .. } => Effect::Quantization { lsb_dps: v },
            Effect::Latency { .. } => Effect::Latency { delay_s: v },
            Effect::ClockError { .. } => Effect::ClockError { ppm: v },
            Effect::Dropouts { .. } => Effect::Dropouts {
                rate_per_s: v,
                mean_samples: values[1],
            },
            Effect::TemperatureBias { .. } => Effect::TemperatureBias { dps_per_c: v },
            Effect::TemperatureScale { .. } => Effect::TemperatureScale { per_c: v },
            Effect::BiasInstability { .. } => Effect::BiasInstability { sigma_dps: v },
            Effect::RateRandomWalk { .. } => Effect::RateRandomWalk { k_dps_per_rt_s: v },
            Effect::TurnOnBias { .. } => Effect::TurnOnBias { sigma_dps: v },
            Effect::Bandwidth { .. } => Effect::Bandwidth { cutoff_hz: v },
        })
    }

    /// Parse `id` or `id:name=value,name=value` (missing parameters take the typical value).
    pub fn parse(spec: &str) -> Result<Effect, String> {
        let (id, rest) = spec.split_once(':').unwrap_or((spec, ""));
        let info = EFFECTS.iter().find(|e| e.id == id.trim()).ok_or_else(|| {
            let ids: Vec<&str> = EFFECTS.iter().map(|e| e.id).collect();
            format!("unknown effect `{id}` (known: {})", ids.join(", "))
        })?;
        let mut values = info.typical.params();
        for pair in rest.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (name, value) = pair
                .split_once('=')
                .ok_or_else(|| format!("effect `{id}`: expected name=value, found `{pair}`"))?;
            let index = info
                .params
                .iter()
                .position(|(n, _)| *n == name.trim())
                .ok_or_else(|| {
                    let names: Vec<&str> = info.params.iter().map(|p| p.0).collect();
                    format!(
                        "effect `{id}` has no parameter `{name}` (it has: {})",
                        names.join(", ")
                    )
                })?;
            values[index] = value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("effect `{id}`: `{value}` is not a finite number"))?;
        }
        let effect = info
            .typical
            .with_params(&values)
            .ok_or_else(|| format!("effect `{id}`: wrong number of parameters"))?;
        effect.validate()?;
        Ok(effect)
    }

    /// Check the parameters are physically meaningful.
    pub fn validate(&self) -> Result<(), String> {
        let p = self.params();
        let bad = |what: &str| Err(format!("effect `{}`: {what}", self.id()));
        match *self {
            Effect::Saturation { limit_dps } if limit_dps <= 0.0 => bad("limit_dps must be > 0"),
            Effect::Quantization { lsb_dps } if lsb_dps < 0.0 => bad("lsb_dps must be >= 0"),
            Effect::Latency { delay_s } if !(0.0..=1.0).contains(&delay_s) => {
                bad("delay_s must be in [0, 1]")
            }
            Effect::ClockError { ppm } if ppm.abs() >= 1e5 => bad("|ppm| must be < 100000"),
            Effect::Dropouts {
                rate_per_s,
                mean_samples,
            } if rate_per_s < 0.0 || mean_samples < 1.0 => {
                bad("rate_per_s >= 0 and mean_samples >= 1")
            }
            Effect::BiasInstability { sigma_dps } | Effect::TurnOnBias { sigma_dps }
                if sigma_dps < 0.0 =>
            {
                bad("sigma_dps must be >= 0")
            }
            Effect::RateRandomWalk { k_dps_per_rt_s } if k_dps_per_rt_s < 0.0 => {
                bad("k_dps_per_rt_s must be >= 0")
            }
            Effect::Bandwidth { cutoff_hz } if cutoff_hz <= 0.0 => bad("cutoff_hz must be > 0"),
            _ if p.iter().any(|v| !v.is_finite()) => bad("parameters must be finite"),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_complete_and_consistent() {
        let ids = [
            "scale_factor",
            "scale_asymmetry",
            "nonlinearity",
            "saturation",
            "quantization",
            "latency",
            "clock_error",
            "dropouts",
            "temperature_bias",
            "temperature_scale",
            "bias_instability",
            "rate_random_walk",
            "turn_on_bias",
            "bandwidth",
        ];
        assert_eq!(EFFECTS.len(), ids.len());
        for (info, id) in EFFECTS.iter().zip(ids) {
            assert_eq!(info.id, id);
            assert_eq!(info.typical.id(), id);
            assert_eq!(info.typical.params().len(), info.params.len());
            assert!(info.typical.validate().is_ok());
            // JSON uses the same id.
            let json = serde_json::to_value(info.typical).unwrap();
            assert_eq!(json["id"], id);
            let back: Effect = serde_json::from_value(json).unwrap();
            assert_eq!(back, info.typical);
        }
    }

    #[test]
    fn parse_specs() {
        assert_eq!(
            Effect::parse("scale_factor:k=0.02"),
            Ok(Effect::ScaleFactor { k: 0.02 })
        );
        assert_eq!(
            Effect::parse("latency"),
            Ok(Effect::Latency { delay_s: 0.005 })
        );
        assert_eq!(
            Effect::parse("dropouts:mean_samples=2"),
            Ok(Effect::Dropouts {
                rate_per_s: 0.5,
                mean_samples: 2.0
            })
        );
        assert!(Effect::parse("scale:k=1")
            .unwrap_err()
            .contains("unknown effect"));
        assert!(Effect::parse("latency:delay=1")
            .unwrap_err()
            .contains("no parameter `delay`"));
        assert!(Effect::parse("latency:delay_s=x")
            .unwrap_err()
            .contains("not a finite number"));
        assert!(Effect::parse("saturation:limit_dps=-1").is_err());
    }
}
