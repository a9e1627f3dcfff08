//! One-sample MIS: each camera sample picks the light technique with probability
//! c = n_e / (n_e + n_b) (0 for a delta BSDF), else the BSDF technique, and weights by
//! h(c_i p_i, c_j p_j) / c_i.

use super::{Estimator, Techniques, Weight};
use crate::integrator::Strategy;
use crate::scene::desc::StrategyKind;

/// One-sample MIS.
pub(super) struct MisOneSample;

impl Estimator for MisOneSample {
    const KIND: StrategyKind = StrategyKind::MisOneSample;

    #[inline(always)]
    fn li<T: Techniques>(t: &mut T, delta_bsdf: bool) {
        let s = *t.strategy();
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let c_light = if delta_bsdf { 0.0 } else { ne / (ne + nb) };
        let c_bsdf = 1.0 - c_light;
        // Each hit takes one technique; its term is added undivided (x / 1 is x exactly).
        let (light, bsdf) = t.split(c_light);
        let h = s.heuristic;
        let light_w = Weight::OneSample {
            h,
            own: c_light,
            other: c_bsdf,
        };
        let bsdf_w = Weight::OneSample {
            h,
            own: c_bsdf,
            other: c_light,
        };
        t.light(light, light_w, 1.0);
        t.bsdf(bsdf, bsdf_w, 1.0);
    }

    /// The sample counts set the technique probability c, so they are part of the label
    /// unless they are one each (c = 1/2; labels of results written before stay valid).
    fn label(s: &Strategy, h: &str, sel: &str, ls: &str) -> String {
        match (s.emitter_samples, s.bsdf_samples) {
            (1, 1) => format!("{h}-{sel}-{ls}"),
            (e, b) => format!("{h}-e{e}b{b}-{sel}-{ls}"),
        }
    }
}
