//! The sensor simulator: nominal model, the effect terms, true motion.

mod effects;
mod motion;
mod sensor;

pub use effects::{
    effect_info, Bound, CoreCorrection, Effect, EffectError, EffectInfo, FitProcedure, ParamRange,
    ParamSpec, Reading, Regressor, WanderShape, EFFECTS, LOW_PASS_POLE_RATIO,
};
pub use motion::{BenchProfile, Motion, Rotation};
pub use sensor::{
    simulate, simulate_series, InvalidSensorModel, SensorModel, SimOptions, SimSeries,
};
