//! directlab: Monte Carlo direct illumination and a harness that measures its convergence.

// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// The renderer's modules, under the paths the harness has always used (`crate::scene`, ...).
// The compiler keeps the boundary: the renderer crate cannot name anything below.
pub use directlab_render::{
    aov, bsdf, camera, counts, emitter, film, fnv, geometry, integrator, limits, math, memory,
    named, output, render, rng, sampler, sampling, scene, RENDERER_HASH,
};

pub mod analytic;
pub mod bench;
pub mod check;
pub mod checksampler;
pub mod chi2cases;
pub mod choices;
pub mod cli;
pub mod compare;
pub mod cost;
pub mod experiment;
pub mod integrands;
pub mod labels;
pub mod metrics;
pub mod noritest;
pub mod pipeline;
pub mod plot;
pub mod progress;
pub mod render_cmd;
#[cfg(test)]
mod render_tests;
pub mod report;
pub mod slurm;
pub mod stats;
