//! directlab: Monte Carlo direct illumination and a harness that measures its convergence.

pub mod analytic;
pub mod rng;
pub mod scene;
pub mod stats;
