//! BSDF sampling alone (Nori's `material`): `bsdf_samples` BSDF samples per camera sample.

use super::{Direct, Estimator, Shading};
use crate::integrator::Strategy;
use crate::math::Rgb;
use crate::sampler::Sampler;
use crate::scene::desc::StrategyKind;

/// BSDF sampling alone.
pub(super) struct Bsdf;

impl Estimator for Bsdf {
    const KIND: StrategyKind = StrategyKind::Bsdf;

    #[inline(always)]
    fn li(d: &Direct, sh: &Shading, delta_bsdf: bool, rng: &mut impl Sampler, mut l: Rgb) -> Rgb {
        let s = &d.strategy;
        let nb = s.bsdf_samples as f32;
        for _ in 0..s.bsdf_samples {
            l += d.bsdf_sample(sh, rng, |_, _| 1.0) / nb;
        }
        // Delta lights, which no BSDF sample hits: light samples for them alone.
        if d.has_delta_lights() && !delta_bsdf {
            for _ in 0..s.bsdf_samples {
                l += d.light_sample(sh, rng, Direct::only_other) / nb;
            }
        }
        l
    }

    fn label(s: &Strategy, _: &str, _: &str, _: &str) -> String {
        format!("b{}", s.bsdf_samples)
    }
}
