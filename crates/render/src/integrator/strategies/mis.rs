//! Multi-sample MIS of `emitter_samples` light and `bsdf_samples` BSDF samples, each weighted
//! by h(n_i p_i, n_j p_j) (Veach's balance or power heuristic).

use super::{Direct, Estimator, Shading};
use crate::integrator::direct::heuristic;
use crate::integrator::Strategy;
use crate::math::Rgb;
use crate::sampler::Sampler;
use crate::scene::desc::StrategyKind;

/// Multi-sample MIS.
pub(super) struct Mis;

impl Estimator for Mis {
    const KIND: StrategyKind = StrategyKind::Mis;

    #[inline(always)]
    fn li(d: &Direct, sh: &Shading, delta_bsdf: bool, rng: &mut impl Sampler, mut l: Rgb) -> Rgb {
        let s = &d.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let light_w = |pl, pb| heuristic(s.heuristic, ne * pl, nb * pb);
        // A delta BSDF draws no light samples (they would add zero): BSDF samples then carry
        // weight 1.
        let ne_drawn = if delta_bsdf { 0.0 } else { ne };
        let bsdf_w = |pb, pl| heuristic(s.heuristic, nb * pb, ne_drawn * pl);
        let n_light = if delta_bsdf { 0 } else { s.emitter_samples };
        for _ in 1..n_light {
            l += d.light_sample(sh, rng, light_w) / ne;
        }
        // The last light sample and the first BSDF sample are drawn before either traces its
        // ray (random numbers still in the same order): their square roots and divisions then
        // overlap instead of waiting behind a traversal.
        let mut n_bsdf = s.bsdf_samples;
        if n_light > 0 && n_bsdf > 0 {
            let light = d.light_draw(sh, rng);
            let bsdf = d.bsdf_draw(sh, rng);
            l += d.light_finish(sh, light, light_w) / ne;
            l += d.bsdf_finish(sh, bsdf, bsdf_w) / nb;
            n_bsdf -= 1;
        } else if n_light > 0 {
            l += d.light_sample(sh, rng, light_w) / ne;
        }
        for _ in 0..n_bsdf {
            l += d.bsdf_sample(sh, rng, bsdf_w) / nb;
        }
        l
    }

    fn label(s: &Strategy, h: &str, sel: &str, ls: &str) -> String {
        format!("{h}-e{}b{}-{sel}-{ls}", s.emitter_samples, s.bsdf_samples)
    }
}
