//! Statistical tests of the renderer crate that need the harness's statistics or closed
//! forms: the renderer cannot depend on the harness, so its proofs that need them live here.
//!
//! Family-wise significance is `ALPHA` = 1e-3 per test function, as in the renderer's own
//! estimator tests (`integrator/tests.rs`): the defects these tests exist for give |t| of 10
//! and more.

use crate::render::RenderSettings;

mod emitter_choice;
mod lambert;
mod many_lights;
mod rng_streams;

/// Family-wise significance of every test in this module.
pub(crate) const ALPHA: f64 = 1e-3;

/// A render of `spp` independent samples per pixel with `seed`, on every core.
pub(crate) fn settings(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings::new(spp, seed)
}
