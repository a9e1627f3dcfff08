//! directlab: Monte Carlo direct illumination and a harness that measures its convergence.

// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analytic;
pub mod bench;
pub mod bsdf;
pub mod camera;
pub mod check;
pub mod chi2cases;
pub mod cli;
pub mod emitter;
pub mod experiment;
pub mod film;
pub mod geometry;
pub mod integrands;
pub mod integrator;
pub mod math;
pub mod metrics;
pub mod noritest;
pub mod output;
pub mod plot;
pub mod render;
pub mod report;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod slurm;
pub mod stats;
