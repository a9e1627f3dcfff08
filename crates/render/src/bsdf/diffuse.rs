//! Lambertian reflection, one-sided (black from behind unless wrapped in a two-sided material).

use super::params::{checked_reflectance, Params};
use super::Bsdf;
use super::BsdfSample;
use crate::math::{Rgb, INV_PI};
use crate::sampling::warps::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};

/// A Lambertian reflector (Mitsuba's `diffuse`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Albedo, per channel.
    pub reflectance: Rgb,
}

impl Diffuse {
    /// reflectance / pi times cos(wo) for wi and wo above the surface, else 0.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.reflectance * (INV_PI * wo.z)
    }

    /// Cosine-weighted density of `wo`: cos(wo) / pi above the surface, else 0.
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        square_to_cosine_hemisphere_pdf(wo)
    }

    /// A cosine-distributed direction; its weight is the reflectance.
    #[inline]
    pub fn sample(&self, wi: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wo = square_to_cosine_hemisphere(u);
        let pdf = square_to_cosine_hemisphere_pdf(wo);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wo,
            weight: self.reflectance,
            pdf,
            delta: false,
        })
    }
}

impl Bsdf for Diffuse {
    const DELTA: bool = false;

    /// Mitsuba's `reflectance` (or Mitsuba 0.6's and Nori's `albedo`), default 0.5.
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let r = p.color("reflectance")?;
        let a = p.color("albedo")?;
        let reflectance = match (r, a) {
            (Some(_), Some(_)) => {
                return Err(p.error(
                    None,
                    "give either 'reflectance' or 'albedo', not both".into(),
                ))
            }
            (Some(v), None) => checked_reflectance(p, "reflectance", v)?,
            (None, Some(v)) => checked_reflectance(p, "albedo", v)?,
            (None, None) => Rgb::splat(0.5),
        };
        Ok(Diffuse { reflectance })
    }
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        Diffuse::eval(self, wi, wo)
    }
    #[inline]
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        Diffuse::pdf(self, wi, wo)
    }
    #[inline]
    fn sample(&self, wi: Vec3, _: f32, u2: Vec2) -> Option<BsdfSample> {
        Diffuse::sample(self, wi, u2)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::*;
    use super::super::*;

    fn diffuse(two_sided: bool) -> Material {
        Material {
            kind: BsdfKind::Diffuse(Diffuse {
                reflectance: Rgb::new(0.2, 0.5, 0.9),
            }),
            two_sided,
        }
    }

    #[test]
    fn sample_eval_pdf_agree() {
        check_sample_consistency(&diffuse(false), 20_000);
        check_sample_consistency(&diffuse(true), 20_000);
    }

    #[test]
    fn albedo_equals_reflectance() {
        let wi = Vec3::new(0.3, 0.1, 0.8).normalize();
        let (a, _) = albedo(&diffuse(false), wi, 10_000);
        assert!((a - Rgb::new(0.2, 0.5, 0.9)).abs().max_element() < 1e-5);
    }

    /// Eval alone, by quadrature (no sampler involved): the cosine-weighted integral over the
    /// hemisphere is the reflectance, at normal and grazing incidence, and eval is reciprocal.
    #[test]
    fn eval_integrates_to_the_reflectance_and_is_reciprocal() {
        let grid = crate::sampling::quadrature::LobeGrid::around_normal(1.0);
        for wi in [
            Vec3::Z,
            Vec3::new(0.3, 0.1, 0.8).normalize(),
            Vec3::new(0.0, 0.995, 0.0998),
        ] {
            let (a, mass) = quadrature(&diffuse(false), wi, &grid);
            assert!(
                (a - Rgb::new(0.2, 0.5, 0.9)).abs().max_element() < 1e-3,
                "{wi}: {a}"
            );
            assert!((mass - 1.0).abs() < 1e-3, "{wi}: pdf mass {mass}");
        }
        let (wi, wo) = (
            Vec3::new(0.3, 0.1, 0.8).normalize(),
            Vec3::new(-0.5, 0.2, 0.6).normalize(),
        );
        let m = diffuse(false);
        assert!(
            (m.eval(wi, wo) / wo.z - m.eval(wo, wi) / wi.z)
                .abs()
                .max_element()
                < 1e-6
        );
    }

    #[test]
    fn one_sided_is_black_from_behind_two_sided_is_not() {
        let wi = Vec3::new(0.0, 0.0, -1.0);
        let wo = Vec3::new(0.0, 0.6, -0.8);
        assert_eq!(diffuse(false).eval(wi, wo), Rgb::ZERO);
        assert!(diffuse(false).sample(wi, 0.5, Vec2::splat(0.5)).is_none());
        assert!(diffuse(true).eval(wi, wo).x > 0.0);
        let s = diffuse(true).sample(wi, 0.5, Vec2::splat(0.3)).unwrap();
        assert!(s.wo.z < 0.0);
    }
}
