//! Light sampling alone (Nori's `light`): `emitter_samples` light samples per camera sample.

use super::{Estimator, Techniques, Weight};
use crate::integrator::Strategy;
use crate::scene::desc::StrategyKind;

/// Light sampling alone.
pub(super) struct Light;

impl Estimator for Light {
    const KIND: StrategyKind = StrategyKind::Light;

    #[inline(always)]
    fn li<T: Techniques>(t: &mut T, delta_bsdf: bool) {
        let (n, all) = (t.strategy().emitter_samples, t.all());
        let ne = n as f32;
        if delta_bsdf {
            // A delta BSDF gives light samples zero throughput: its light arrives by BSDF
            // samples, one in place of each light sample.
            for _ in 0..n {
                t.bsdf(all, Weight::OnlyOther, ne);
            }
            return;
        }
        // A delta lobe beside lobes with a density (plastic's coating): light samples for the
        // latter, and a BSDF sample each that counts only the delta lobe.
        let delta_lobe = t.has_delta_lobe();
        for _ in 0..n {
            t.light(all, Weight::One, ne);
            if delta_lobe {
                t.bsdf(all, Weight::OnlyOther, ne);
            }
        }
    }

    fn label(s: &Strategy, _: &str, sel: &str, ls: &str) -> String {
        format!("e{}-{sel}-{ls}", s.emitter_samples)
    }
}
