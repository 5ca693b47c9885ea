//! Sim-to-real diagnosis (DESIGN.md, "Sim-to-real diagnosis").

pub mod features;
pub mod stats;
