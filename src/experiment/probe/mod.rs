//! Probe mode (`[probe]` in an experiment file): for every case, strategy and seed, draw one
//! stream of a pixel's individual samples exactly as `render` draws them, and measure it
//! against the case's closed form: non-finite samples, bias (z), the error of batch means at
//! every sweep spp (one `results.csv` row each, so convergence plots and slopes are the
//! runner's), the largest sample and the share of squared error in the top 0.1 %.
//! `experiments/extreme.toml` (the stability suite of issue 6) is the probe experiment.

pub mod accumulate;
pub mod closed_form;
pub mod figure;
pub mod invalid;
mod rows;
pub mod run;
pub mod samples;
pub mod stats;

pub use run::{measure_stream, run_probe, CaseRun, ProbeOutcome};

#[cfg(test)]
#[path = "sampler_bias_tests.rs"]
mod sampler_bias_tests;
