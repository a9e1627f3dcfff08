//! Nori `microfacet` as its microfacet.cpp defines it: a Lambertian base kd/π plus a Beckmann
//! specular lobe weighted by ks = 1 - max(kd),
//!   f = kd/π + ks D(h) F(wi.h; extIOR, intIOR) G(wi, wo, h) / (4 cos_i cos_o cos_h)
//! where Nori's D is the Beckmann *sampling density* D_true(h) cos_h (its warp's pdf), so the
//! cos_h cancels: f = kd/π + ks D_true F G / (4 cos_i cos_o). G = G1(wi) G1(wo) uses Nori's
//! rational fit of Beckmann G1 (Walter 2007), kept on purpose to match Nori's images.
//! Sampling: specular with probability ks (u1), else cosine-weighted diffuse; the pdf is the
//! mixture ks D_true(h) cos_h / (4 |wo.h|) + (1 - ks) cos_o / π. One-sided.

use super::fresnel::fresnel_dielectric;
use super::params::{self, Params};
use super::Bsdf;
use super::BsdfSample;
use crate::math::{Rgb, INV_PI};
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use crate::sampling::warps::square_to_cosine_hemisphere;
use glam::{Vec2, Vec3};

/// Nori's `microfacet`: a Beckmann specular lobe over a diffuse base, the study's rough
/// material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoriMicrofacet {
    mf: Microfacet,
    alpha: f32,
    /// int_ior / ext_ior.
    eta: f32,
    kd: Rgb,
    ks: f32,
}

impl NoriMicrofacet {
    /// `kd` must lie in [0, 1] so that ks = 1 - max(kd) is a probability.
    pub fn new(alpha: f32, int_ior: f32, ext_ior: f32, kd: Rgb) -> Self {
        let mf = Microfacet::new(MicrofacetDistribution::Beckmann, alpha, alpha);
        NoriMicrofacet {
            mf,
            alpha: mf.alpha_u,
            eta: int_ior / ext_ior,
            kd,
            ks: 1.0 - kd.max_element(),
        }
    }

    /// Nori's G1: zero on the back of the facet, else Walter's rational fit in b = 1/(α tanθ).
    #[inline]
    fn g1(&self, w: Vec3, h: Vec3) -> f32 {
        if w.dot(h) / w.z <= 0.0 {
            return 0.0;
        }
        let tan = (1.0 - w.z * w.z).max(0.0).sqrt() / w.z;
        let b = 1.0 / (self.alpha * tan);
        if b < 1.6 {
            (3.535 * b + 2.181 * b * b) / (1.0 + 2.276 * b + 2.577 * b * b)
        } else {
            1.0
        }
    }

    /// f(wi, wo) cos(wo): the diffuse base plus the Beckmann lobe.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let h = (wi + wo).normalize();
        let d = self.mf.d(h);
        let spec = if d > 0.0 && self.ks > 0.0 {
            let f = fresnel_dielectric(wi.dot(h), self.eta).0;
            self.ks * d * f * self.g1(wi, h) * self.g1(wo, h) / (4.0 * wi.z * wo.z)
        } else {
            0.0
        };
        (self.kd * INV_PI + Rgb::splat(spec)) * wo.z
    }

    /// Density of `wo`: the lobe's and the base's, mixed by the specular sampling weight.
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        self.ks * self.mf.pdf_all(h) / (4.0 * wo.dot(h)) + (1.0 - self.ks) * wo.z * INV_PI
    }

    /// The specular lobe or the cosine-weighted base, chosen with `u1`; `u2` within it.
    #[inline]
    pub fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wo = if u1 < self.ks {
            let m = self.mf.sample_all(u2);
            (2.0 * wi.dot(m) * m - wi).normalize()
        } else {
            square_to_cosine_hemisphere(u2)
        };
        if wo.z <= 0.0 {
            return None;
        }
        // Mixture pdf: both lobes can produce any wo, so the weight needs the full mixture.
        let pdf = self.pdf(wi, wo);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wo,
            weight: self.eval(wi, wo) / pdf,
            pdf,
            delta: false,
        })
    }
}

impl Bsdf for NoriMicrofacet {
    fn glossy_lobe(&self) -> Option<(f32, f32)> {
        Some((self.alpha, self.alpha))
    }

    const DELTA: bool = false;

    /// Nori's `alpha` (default 0.1), `intIOR`, `extIOR` and `kd` (default 0.5, at most 1).
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let alpha = params::roughness(p, "alpha", 0.1)?;
        let int_ior = params::ior(p, "int_ior", params::DEFAULT_INT_IOR)?;
        let ext_ior = params::ior(p, "ext_ior", params::DEFAULT_EXT_IOR)?;
        let kd = params::reflectance(p, "kd", Rgb::splat(0.5))?;
        // ks = 1 - max(kd) is the specular lobe's selection probability.
        if kd.max_element() > 1.0 {
            return Err(p.error(
                Some("kd"),
                format!("microfacet kd must not exceed 1 (ks = 1 - max(kd)), found {kd}"),
            ));
        }
        Ok(NoriMicrofacet::new(alpha, int_ior, ext_ior, kd))
    }
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        NoriMicrofacet::eval(self, wi, wo)
    }
    #[inline]
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        NoriMicrofacet::pdf(self, wi, wo)
    }
    #[inline]
    fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        NoriMicrofacet::sample(self, wi, u1, u2)
    }
}

#[cfg(test)]
#[path = "nori_microfacet_tests.rs"]
mod tests;
