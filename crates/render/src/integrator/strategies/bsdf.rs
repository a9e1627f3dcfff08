//! BSDF sampling alone (Nori's `material`): `bsdf_samples` BSDF samples per camera sample.

use super::{Estimator, Techniques, Weight};
use crate::integrator::Strategy;
use crate::scene::desc::StrategyKind;

/// BSDF sampling alone.
pub(super) struct Bsdf;

impl Estimator for Bsdf {
    const KIND: StrategyKind = StrategyKind::Bsdf;

    #[inline(always)]
    fn li<T: Techniques>(t: &mut T, delta_bsdf: bool) {
        let (n, all) = (t.strategy().bsdf_samples, t.all());
        let nb = n as f32;
        for _ in 0..n {
            t.bsdf(all, Weight::One, nb);
        }
        // Delta lights, which no BSDF sample hits: light samples for them alone.
        if t.has_delta_lights() && !delta_bsdf {
            for _ in 0..n {
                t.light(all, Weight::OnlyOther, nb);
            }
        }
    }

    fn label(s: &Strategy, _: &str, _: &str, _: &str) -> String {
        format!("b{}", s.bsdf_samples)
    }
}
