//! Multi-sample MIS of `emitter_samples` light and `bsdf_samples` BSDF samples, each weighted
//! by h(n_i p_i, n_j p_j) (Veach's balance or power heuristic).

use super::{Estimator, Techniques, Weight};
use crate::integrator::Strategy;
use crate::scene::desc::StrategyKind;

/// Multi-sample MIS.
pub(super) struct Mis;

impl Estimator for Mis {
    const KIND: StrategyKind = StrategyKind::Mis;

    #[inline(always)]
    fn li<T: Techniques>(t: &mut T, delta_bsdf: bool) {
        let (s, all) = (*t.strategy(), t.all());
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let h = s.heuristic;
        let light_w = Weight::Mis {
            h,
            own: ne,
            other: nb,
        };
        // A delta BSDF draws no light samples (they would add zero): BSDF samples then carry
        // weight 1.
        let ne_drawn = if delta_bsdf { 0.0 } else { ne };
        let bsdf_w = Weight::Mis {
            h,
            own: nb,
            other: ne_drawn,
        };
        let n_light = if delta_bsdf { 0 } else { s.emitter_samples };
        for _ in 1..n_light {
            t.light(all, light_w, ne);
        }
        // The last light sample and the first BSDF sample are drawn before either traces its
        // ray.
        let mut n_bsdf = s.bsdf_samples;
        if n_light > 0 && n_bsdf > 0 {
            t.light_and_bsdf(light_w, ne, bsdf_w, nb);
            n_bsdf -= 1;
        } else if n_light > 0 {
            t.light(all, light_w, ne);
        }
        for _ in 0..n_bsdf {
            t.bsdf(all, bsdf_w, nb);
        }
    }

    fn label(s: &Strategy, h: &str, sel: &str, ls: &str) -> String {
        format!("{h}-e{}b{}-{sel}-{ls}", s.emitter_samples, s.bsdf_samples)
    }
}
