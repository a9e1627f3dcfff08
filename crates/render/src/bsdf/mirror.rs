//! Nori `mirror`: perfect specular reflection with reflectance 1, one-sided.

use super::params::Params;
use super::Bsdf;
use super::BsdfSample;
use crate::math::Rgb;
use glam::Vec2;
use glam::Vec3;

/// A perfect mirror (Nori's `mirror`): reflects everything, a delta BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror;

/// Mirror direction about the local normal.
#[inline]
pub fn reflect_z(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

impl Mirror {
    /// The mirror direction of `wi`, weight 1 (a delta sample); None below the surface.
    #[inline]
    pub fn sample(&self, wi: Vec3) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wo: reflect_z(wi),
            weight: Rgb::ONE,
            pdf: 1.0,
            delta: true,
        })
    }
}

impl Bsdf for Mirror {
    const DELTA: bool = true;

    /// No parameters.
    fn from_params<P: Params>(_: &mut P) -> Result<Self, P::Error> {
        Ok(Mirror)
    }
    #[inline]
    fn sample(&self, wi: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
        Mirror::sample(self, wi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::*;
    use super::super::*;

    fn mirror(two_sided: bool) -> Material {
        Material {
            kind: BsdfKind::Mirror(Mirror),
            two_sided,
        }
    }

    #[test]
    fn lossless_delta_reflection() {
        check_sample_consistency(&mirror(false), 10_000);
        for c in [1.0f32, 0.5, 0.01] {
            let wi = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            let (a, _) = albedo(&mirror(false), wi, 1000);
            assert_eq!(a, Rgb::ONE);
            let s = mirror(false).sample(wi, 0.3, Vec2::splat(0.7)).unwrap();
            assert!(s.delta && s.pdf == 1.0 && (s.wo - Vec3::new(-wi.x, 0.0, c)).length() < 1e-7);
            assert_eq!(mirror(false).eval(wi, s.wo), Rgb::ZERO);
            assert_eq!(mirror(false).pdf(wi, s.wo), 0.0);
        }
        assert!(mirror(false).is_delta());
        let below = Vec3::new(0.6, 0.0, -0.8);
        assert!(mirror(false).sample(below, 0.5, Vec2::splat(0.5)).is_none());
        let s = mirror(true).sample(below, 0.5, Vec2::splat(0.5)).unwrap();
        assert_eq!(s.wo, Vec3::new(-0.6, 0.0, -0.8));
    }
}
