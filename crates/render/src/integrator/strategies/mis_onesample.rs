//! One-sample MIS: each camera sample picks the light technique with probability
//! c = n_e / (n_e + n_b) (0 for a delta BSDF), else the BSDF technique, and weights by
//! h(c_i p_i, c_j p_j) / c_i.

use super::{Direct, Estimator, Shading};
use crate::integrator::direct::heuristic;
use crate::integrator::Strategy;
use crate::math::Rgb;
use crate::sampler::Sampler;
use crate::scene::desc::StrategyKind;

/// One-sample MIS.
pub(super) struct MisOneSample;

impl Estimator for MisOneSample {
    const KIND: StrategyKind = StrategyKind::MisOneSample;

    #[inline(always)]
    fn li(d: &Direct, sh: &Shading, delta_bsdf: bool, rng: &mut impl Sampler, mut l: Rgb) -> Rgb {
        let s = &d.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let c_light = if delta_bsdf { 0.0 } else { ne / (ne + nb) };
        let c_bsdf = 1.0 - c_light;
        if rng.technique() < c_light {
            l += d.light_sample(sh, rng, |pl, pb| {
                heuristic(s.heuristic, c_light * pl, c_bsdf * pb) / c_light
            });
        } else {
            l += d.bsdf_sample(sh, rng, |pb, pl| {
                heuristic(s.heuristic, c_bsdf * pb, c_light * pl) / c_bsdf
            });
        }
        l
    }

    fn label(_: &Strategy, h: &str, sel: &str, ls: &str) -> String {
        format!("{h}-{sel}-{ls}")
    }
}
