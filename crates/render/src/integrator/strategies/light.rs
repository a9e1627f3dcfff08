//! Light sampling alone (Nori's `light`): `emitter_samples` light samples per camera sample.

use super::{Direct, Estimator, Shading};
use crate::integrator::Strategy;
use crate::math::Rgb;
use crate::sampler::Sampler;
use crate::scene::desc::StrategyKind;

/// Light sampling alone.
pub(super) struct Light;

impl Estimator for Light {
    const KIND: StrategyKind = StrategyKind::Light;

    #[inline(always)]
    fn li(d: &Direct, sh: &Shading, delta_bsdf: bool, rng: &mut impl Sampler, mut l: Rgb) -> Rgb {
        let s = &d.strategy;
        let ne = s.emitter_samples as f32;
        if delta_bsdf {
            // A delta BSDF gives light samples zero throughput: its light arrives by BSDF
            // samples, one in place of each light sample.
            for _ in 0..s.emitter_samples {
                l += d.bsdf_sample(sh, rng, Direct::only_other) / ne;
            }
            return l;
        }
        // A delta lobe beside lobes with a density (plastic's coating): light samples for the
        // latter, and a BSDF sample each that counts only the delta lobe.
        let delta_lobe = sh.mat.has_delta_lobe();
        for _ in 0..s.emitter_samples {
            l += d.light_sample(sh, rng, |_, _| 1.0) / ne;
            if delta_lobe {
                l += d.bsdf_sample(sh, rng, Direct::only_other) / ne;
            }
        }
        l
    }

    fn label(s: &Strategy, _: &str, sel: &str, ls: &str) -> String {
        format!("e{}-{sel}-{ls}", s.emitter_samples)
    }
}
