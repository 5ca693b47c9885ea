//! The sensor simulator: nominal model, the effect terms, true motion.

mod effects;
mod motion;
mod sensor;

pub use effects::{Effect, EffectInfo, EFFECTS};
pub use motion::{BenchProfile, Motion, Rotation};
pub use sensor::{simulate, simulate_series, SensorModel, SimOptions, SimSeries};
