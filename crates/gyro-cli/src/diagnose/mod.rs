//! Sim-to-real diagnosis (DESIGN.md, "Sim-to-real diagnosis").
//!
//! So far only point 1, "where": per-segment statistics of the residual rate and their
//! z-scores against an ensemble of simulated runs ([`stats`]).

pub mod stats;
