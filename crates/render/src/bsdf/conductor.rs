//! Mitsuba `conductor`: smooth metal, a single delta reflection lobe with throughput
//! F_conductor(cos_i; eta + i k) * specular_reflectance. One-sided.

use super::fresnel::fresnel_conductor;
use super::mirror::reflect_z;
use super::params::{self, Params};
use super::Bsdf;
use super::BsdfSample;
use crate::math::Rgb;
use glam::Vec2;
use glam::Vec3;

/// A smooth conductor (Mitsuba's `conductor`): mirror reflection weighted by the Fresnel
/// reflectance of a complex index of refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the index of refraction, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption) of the index of refraction, per channel.
    pub k: Rgb,
    /// Scale on the reflected light (Mitsuba's `specular_reflectance`).
    pub specular_reflectance: Rgb,
}

impl Conductor {
    /// The mirror direction of `wi` with the Fresnel reflectance as its weight (a delta
    /// sample); None below the surface.
    #[inline]
    pub fn sample(&self, wi: Vec3) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wo: reflect_z(wi),
            weight: fresnel_conductor(wi.z, self.eta, self.k) * self.specular_reflectance,
            pdf: 1.0,
            delta: true,
        })
    }
}

impl Bsdf for Conductor {
    const DELTA: bool = true;

    /// `eta` and `k`, or a `material` name; `specular_reflectance` (default 1).
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let (eta, k, specular_reflectance) = params::conductor(p)?;
        Ok(Conductor {
            eta,
            k,
            specular_reflectance,
        })
    }
    #[inline]
    fn sample(&self, wi: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
        Conductor::sample(self, wi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::fresnel::*;
    use super::super::testing::*;
    use super::super::*;

    fn conductor(eta: Rgb, k: Rgb, spec: Rgb) -> Material {
        Material {
            kind: BsdfKind::Conductor(Conductor {
                eta,
                k,
                specular_reflectance: spec,
            }),
            two_sided: false,
        }
    }

    #[test]
    fn albedo_is_fresnel_times_specular_reflectance() {
        let gold = (
            Rgb::new(0.143119, 0.374957, 1.44248),
            Rgb::new(3.98316, 2.38572, 1.60322),
        );
        let spec = Rgb::new(0.9, 0.7, 1.0);
        let m = conductor(gold.0, gold.1, spec);
        check_sample_consistency(&m, 10_000);
        assert!(m.is_delta());
        for c in [1.0f32, 0.5, 0.01] {
            let wi = Vec3::new(0.0, (1.0 - c * c).sqrt(), c);
            let (a, _) = albedo(&m, wi, 1000);
            assert_eq!(a, fresnel_conductor(c, gold.0, gold.1) * spec);
            assert!(a.max_element() <= 1.0);
            // Mitsuba's 'none' (eta 0, k 1) is lossless: the albedo is the tint exactly.
            let (a, _) = albedo(&conductor(Rgb::ZERO, Rgb::ONE, spec), wi, 1000);
            assert!((a - spec).abs().max_element() < 1e-6, "{a}");
        }
        let below = Vec3::new(0.0, 0.6, -0.8);
        assert!(m.sample(below, 0.5, Vec2::splat(0.5)).is_none());
    }
}
