//! The estimators, one file each, and their registration (`estimators!`): how the hit of a
//! camera ray is shaded under each [`StrategyKind`], and the strategy's label. A strategy's
//! name, help and label short form are its row of `StrategyKind`'s table (`scene/desc.rs`,
//! where scene files name it); its estimator is its file here and one line below. The
//! registry tests check that every named strategy has an estimator.
//!
//! Paths only one technique can produce (delta BSDFs and delta lobes: BSDF sampling only;
//! delta lights: light sampling only) are handled by that technique with weight 1 in every
//! strategy, including the pure ones, so no strategy loses them and none counts them twice.

mod bsdf;
mod light;
mod mis;
mod mis_onesample;
mod techniques;

use super::direct::{Direct, Weight};
use super::Strategy;
use crate::counts::Counts;
use crate::geometry::{Ray, SurfacePoint};
use crate::math::Rgb;
use crate::named::Named;
use crate::sampler::Sampler;
use crate::scene::desc::StrategyKind;
pub use techniques::Record;
pub(super) use techniques::{First, One, Techniques};

/// An estimator of the light a camera ray's hit receives directly, written once against
/// [`Techniques`]: `Direct` runs it for one hit, the lane kernel for the hits of eight
/// samples at once.
pub(super) trait Estimator {
    /// The strategy it estimates for.
    const KIND: StrategyKind;
    /// Adds the estimate at the hits `t` shades to what `t` holds (the emission the camera
    /// ray sees), each sample's term in turn. `delta_bsdf`: every lobe of the material is a
    /// delta (never so in lanes, which leave such hits to `Direct`).
    fn li<T: Techniques>(t: &mut T, delta_bsdf: bool);
    /// The settings the strategy uses, after the kind's short form in its label: heuristic
    /// `h`, light samples `eN`, BSDF samples `bM`, emitter choice `sel`, light sampling `ls`.
    fn label(s: &Strategy, h: &str, sel: &str, ls: &str) -> String;
}

macro_rules! estimators {
    ($($ty:path),* $(,)?) => {
        /// The estimate of `t`'s strategy at the hits it shades.
        #[inline(always)]
        pub(in crate::integrator) fn li<T: Techniques>(t: &mut T, delta_bsdf: bool) {
            let kind = t.strategy().kind;
            $(if kind == <$ty as Estimator>::KIND {
                return <$ty as Estimator>::li(t, delta_bsdf);
            })*
            unreachable!("every strategy has an estimator (registry tests)")
        }

        /// The strategy's stable label (see [`Strategy::label`]).
        pub(super) fn label(s: &Strategy) -> String {
            let (h, sel, ls) = (s.heuristic.short(), s.selection.short(), s.light_sampling.short());
            $(if s.kind == <$ty as Estimator>::KIND {
                let rest = <$ty as Estimator>::label(s, h, &sel, ls);
                return format!("{}-{rest}", s.kind.short());
            })*
            unreachable!("every strategy has an estimator (registry tests)")
        }

        /// The strategies with an estimator, in registration order.
        #[cfg(test)]
        pub(super) const REGISTERED: &[StrategyKind] = &[$(<$ty as Estimator>::KIND),*];
    };
}

estimators!(
    light::Light,
    bsdf::Bsdf,
    mis::Mis,
    mis_onesample::MisOneSample,
);

/// The entry points of the estimator: they dispatch to the strategies, so they live here,
/// above the techniques of `direct.rs`.
impl Direct<'_> {
    /// Radiance along a camera ray.
    pub fn li(&self, ray: &Ray, rng: &mut impl Sampler) -> Rgb {
        self.li_counted(ray, rng, &mut Counts::default())
    }

    /// `li`, adding what it did to `c` (the camera ray included).
    pub fn li_counted(&self, ray: &Ray, rng: &mut impl Sampler, c: &mut Counts) -> Rgb {
        self.li_recorded(ray, rng, c, &mut ())
    }

    /// `li_counted`, telling `rec` what the estimate is made of.
    pub fn li_recorded(
        &self,
        ray: &Ray,
        rng: &mut impl Sampler,
        c: &mut Counts,
        rec: &mut impl Record,
    ) -> Rgb {
        c.camera_rays += 1;
        match self.scene.intersect(ray) {
            Some(hit) => self.li_hit_recorded(ray, &hit.sp, rng, c, rec),
            None => Rgb::ZERO,
        }
    }

    /// `li` given the camera ray's hit, adding what it did past the camera ray to `c`.
    pub(super) fn li_hit(
        &self,
        ray: &Ray,
        sp: &SurfacePoint,
        rng: &mut impl Sampler,
        c: &mut Counts,
    ) -> Rgb {
        self.li_hit_recorded(ray, sp, rng, c, &mut ())
    }

    /// `li_hit`, telling `rec` what the estimate is made of.
    #[inline(always)]
    fn li_hit_recorded(
        &self,
        ray: &Ray,
        sp: &SurfacePoint,
        rng: &mut impl Sampler,
        c: &mut Counts,
        rec: &mut impl Record,
    ) -> Rgb {
        let scene = self.scene;
        let mut l = Rgb::ZERO;
        if !self.strategy.hide_emitters {
            if let Some((_, e)) = scene.emitter_at(sp) {
                let le = e.le(sp, -ray.d);
                rec.emitted(le);
                l += le;
            }
        }
        let sh = self.shading(sp, ray.d);
        // A delta BSDF gives light samples zero throughput: all its light arrives via BSDF
        // samples, which then carry weight 1.
        let delta_bsdf = sh.mat.is_delta();
        let mut one = One::new(self, &sh, rng, c, rec, l);
        li(&mut one, delta_bsdf);
        one.l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_named_strategy_has_one_estimator() {
        let mut named = StrategyKind::all();
        let mut registered = REGISTERED.to_vec();
        let key = |k: &StrategyKind| k.name();
        named.sort_by_key(key);
        registered.sort_by_key(key);
        assert_eq!(named, registered);
    }
}
