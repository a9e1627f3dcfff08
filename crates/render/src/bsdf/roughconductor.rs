//! Mitsuba `roughconductor`: Cook-Torrance microfacet reflection (Walter et al. 2007),
//!   f(wi, wo) |cos_o| = F(wi.h) D(h) G(wi, wo, h) / (4 cos_i),  h = normalize(wi + wo),
//! with conductor Fresnel times specular_reflectance and separable exact Smith G.
//! Sampling reflects a normal drawn from the visible normals or from D cos; the density of wo
//! is pdf_m(h) / (4 wo.h). Directions reflected below the horizon are rejected (`None`): that
//! lost mass is why pdf() integrates to < 1.
//!
//! The returned pdf and weight are evaluated at the half vector of the f32 `wo` actually
//! returned, not at the drawn m: at grazing incidence with alpha ~1e-3, rounding wo moves
//! the half vector by ~1e-7 / cos_i, enough to change D by a percent. The statistical tests
//! (chi-square, pdf mass) check that this pdf is the sampler's true density.
//! One-sided: black for wi.z <= 0.

use super::fresnel::{fresnel_conductor, fresnel_conductor_channel, is_grey};
use super::params::{self, Params};
use super::Bsdf;
use super::{BsdfSample, BsdfSamples};
use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use crate::sampling::microfacet::Microfacet;
use glam::{DVec3, Vec2, Vec3};

/// Mitsuba's `roughconductor`: a microfacet conductor (Beckmann or GGX).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    /// The microfacet distribution and its roughness.
    pub mf: Microfacet,
    /// Sample only the normals visible from `wi` (Mitsuba's `sample_visible`).
    pub sample_visible: bool,
    /// Real part of the index of refraction, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption) of the index of refraction, per channel.
    pub k: Rgb,
    /// Scale on the reflected light.
    pub specular_reflectance: Rgb,
}

impl RoughConductor {
    #[inline]
    fn fresnel(&self, cos: f32) -> Rgb {
        fresnel_conductor(cos, self.eta, self.k) * self.specular_reflectance
    }

    /// `fresnel` of a grey index (`lane_covered`), without its test for one.
    #[inline(always)]
    pub(super) fn fresnel_grey(&self, cos: f32) -> Rgb {
        Rgb::splat(fresnel_conductor_channel(cos, self.eta.x, self.k.x)) * self.specular_reflectance
    }

    /// Half vector of unit wi and wo, summed in f64: wi + wo nearly cancels at grazing
    /// angles. Each is normalised first: an f32 unit vector's length is off by up to ~1e-7,
    /// and at cos_i = 0.01 the sum of two such vectors tilts by that over |wi + wo| ~ 0.02,
    /// which moved a 1e-3-rough lobe's pdf off its samples (chi2 p ~ 1e-4 at 1e7 samples;
    /// `half_vector_ignores_input_lengths`).
    ///
    /// The lengths are 1 + e/2 - e^2/8 for e = |v|^2 - 1: off by e^3/16, below 1e-16 for the
    /// |e| < 1e-5 of unit inputs (f32 normalisation leaves |e| ~ 1e-7; not asserted: the lane
    /// kernel's uncovered lanes pass garbage, whose results it drops). The sum's length is
    /// taken in f32 and applied in f64: a common scale does not turn the vector, so only the
    /// final rounding to f32 does (f64 roots and divisions: see `fresnel_conductor_channel`
    /// for their cost).
    #[inline]
    pub(crate) fn half(wi: Vec3, wo: Vec3) -> Vec3 {
        let (wi, wo) = (wi.as_dvec3(), wo.as_dvec3());
        let length = |v: DVec3| {
            let e = v.length_squared() - 1.0;
            1.0 + e * (0.5 - 0.125 * e)
        };
        // wi / |wi| + wo / |wo|, scaled by |wi| |wo|: no divisions.
        let s = wi * length(wo) + wo * length(wi);
        (s * (s.length_squared() as f32).sqrt().recip() as f64).as_vec3()
    }

    /// f(wi, wo) cos(wo): D G F / (4 cos(wi)).
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        self.eval_pdf(wi, wo).0
    }

    /// Density of `wo`: the sampled normal's density times the reflection's Jacobian.
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.eval_pdf(wi, wo).1
    }

    /// `eval` and `pdf` together: both need the half vector, D and G1(wi), and a light
    /// sample under MIS or a BSDF sample's weight needs both (one exp, one f64 normalise).
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        self.eval_pdf_with(wi, wo, self.mf.lambda(wi), |c| self.fresnel(c))
    }

    /// `eval_pdf` given Smith's Lambda(wi), which a shading point computes once for all its
    /// samples, and the Fresnel term times specular_reflectance. Selects rather than early
    /// returns, so that `integrator::lanes` runs it in vector lanes.
    #[inline(always)]
    pub(crate) fn eval_pdf_with(
        &self,
        wi: Vec3,
        wo: Vec3,
        lambda_i: f32,
        fresnel: impl Fn(f32) -> Rgb,
    ) -> (Rgb, f32) {
        let h = Self::half(wi, wo);
        let d = self.mf.d(h);
        let g1_i = self.mf.g1_given(wi, h, lambda_i);
        let pdf = if self.sample_visible {
            // G1 (wi.h) D / cos_i over the reflection Jacobian 4 (wo.h): the dot products are
            // equal in exact arithmetic, but f32 unit vectors are not exactly unit, and at
            // grazing angles their ratio drifts from 1 by ~1e-4. Cancel them symbolically.
            g1_i * d / (4.0 * wi.z)
        } else {
            self.mf.pdf_all(h) / (4.0 * wo.dot(h))
        };
        // Separable Smith shadowing-masking, as Mitsuba's microfacet plugins.
        let g = g1_i * self.mf.g1(wo, h);
        let f = fresnel(wi.dot(h)) * (d * g / (4.0 * wi.z));
        if wi.z <= 0.0 || wo.z <= 0.0 {
            (Rgb::ZERO, 0.0)
        } else if d == 0.0 {
            (Rgb::ZERO, pdf)
        } else {
            (f, pdf)
        }
    }

    /// A microfacet normal (visible or from D cos), reflected; None when the reflection falls
    /// below the surface.
    #[inline]
    pub fn sample(&self, wi: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let m = if self.sample_visible {
            self.mf.sample_visible(wi, u)
        } else {
            self.mf.sample_all(u)
        };
        self.reflect(wi, m, self.mf.lambda(wi), |c| self.fresnel(c))
    }

    /// The sample that reflects wi (wi.z > 0) about the microfacet normal m, given Lambda(wi)
    /// and the Fresnel term (as `eval_pdf_with`); None below the horizon.
    #[inline(always)]
    pub(crate) fn reflect(
        &self,
        wi: Vec3,
        m: Vec3,
        lambda_i: f32,
        fresnel: impl Fn(f32) -> Rgb,
    ) -> Option<BsdfSample> {
        let wi_m = wi.dot(m);
        let wo = (2.0 * wi_m * m - wi).normalize();
        let (f, pdf) = self.eval_pdf_with(wi, wo, lambda_i, fresnel);
        let ok = wi_m > 0.0 && wo.z > 0.0 && pdf > 0.0;
        ok.then(|| BsdfSample {
            wo,
            weight: f / pdf,
            pdf,
            delta: false,
        })
    }
}

impl Bsdf for RoughConductor {
    fn glossy_lobe(&self) -> Option<(f32, f32)> {
        Some((self.mf.alpha_u, self.mf.alpha_v))
    }

    const DELTA: bool = false;

    /// Mitsuba's `distribution` (beckmann, ggx), `alpha` or `alpha_u` and `alpha_v` (default
    /// 0.1), `sample_visible` (default true), and the conductor's `eta`, `k` or `material`
    /// and `specular_reflectance`.
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let (eta, k, specular_reflectance) = params::conductor(p)?;
        let (mf, sample_visible) = params::microfacet(p)?;
        Ok(RoughConductor {
            mf,
            sample_visible,
            eta,
            k,
            specular_reflectance,
        })
    }
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        RoughConductor::eval(self, wi, wo)
    }
    #[inline]
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        RoughConductor::pdf(self, wi, wo)
    }
    #[inline]
    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        RoughConductor::eval_pdf(self, wi, wo)
    }
    #[inline]
    fn sample(&self, wi: Vec3, _: f32, u2: Vec2) -> Option<BsdfSample> {
        RoughConductor::sample(self, wi, u2)
    }
    /// Grey indices only (Mitsuba's default among them): their Fresnel term is one channel,
    /// which the lanes' loops inline (`fresnel_grey`); the three-channel form is a call per
    /// lane, which kept the loops from running in vector lanes.
    fn lane_covered(&self) -> bool {
        is_grey(self.eta, self.k)
    }
    /// Smith's Lambda(wi), once for both samples of a hit.
    #[inline(always)]
    fn lane_shared(&self, wi: Vec3) -> f32 {
        self.mf.lambda(wi)
    }
    /// `eval_pdf` without its early return, which `eval_pdf_with` ends in as a select.
    #[inline(always)]
    fn eval_pdf_shared(&self, wi: Vec3, wo: Vec3, lambda_i: f32) -> (Rgb, f32) {
        self.eval_pdf_with(wi, wo, lambda_i, |c| self.fresnel_grey(c))
    }
    #[inline(always)]
    fn sample_lanes<'b>(
        b: impl Fn(usize) -> &'b Self + Copy,
        wi: &V3x8,
        lambda_i: &[f32; LANES],
        u: &[[f32; LANES]; 3],
        live: u32,
    ) -> BsdfSamples
    where
        Self: 'b,
    {
        super::roughconductor_lanes::sample_lanes(b, wi, lambda_i, u, live)
    }
}

#[cfg(test)]
#[path = "roughconductor_tests.rs"]
pub(super) mod tests;
