//! Mitsuba 3's `roughplastic`: a rough dielectric coating (Beckmann or GGX, isotropic) over a
//! Lambertian base, as its roughplastic.cpp defines it:
//!   f = s F(wi.h) D G / (4 cos_i cos_o)
//!     + d / (1 - R_int) t(cos_i) t(cos_o) / (eta^2 pi)
//! where t(cos) is the coating's transmittance from outside, E over visible normals m of
//! (1 - F(wi.m)) G1(wt, m) for the refracted wt, tabulated at 64 cosines (Gauss-Legendre,
//! 32^2 nodes) and interpolated linearly, and R_int is the coating's diffuse reflectance from
//! inside, 2 mean(R(mu) mu) over the same 64 cosines of the rough reflectance at 1 / eta
//! (128^2 nodes). With `nonlinear` the internal reflections are summed per colour,
//! d / (1 - d R_int).
//!
//! `sample` picks the coating with probability (1 - t_i) s' against t_i (1 - s'), with
//! s' = mean(s) / (mean(d) + mean(s)), then draws a microfacet normal (visible normals by
//! default) or a cosine-weighted direction; `pdf` is the mixture. One-sided.

use super::fresnel::fresnel_dielectric;
use super::params::{self, Params};
use super::roughconductor::RoughConductor;
use super::{Bsdf, BsdfSample};
use crate::math::{Rgb, INV_PI};
use crate::sampling::gauss_legendre::gauss_legendre;
use crate::sampling::microfacet::Microfacet;
use crate::sampling::warps::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};

/// Cosines of the transmittance table (Mitsuba's MI_ROUGH_TRANSMITTANCE_RES).
const RES: usize = 64;

/// Mitsuba's `roughplastic`: a diffuse base under a rough dielectric coating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// The coating's lobe: its microfacets and sampler (its conductor indices are unused;
    /// the dielectric Fresnel term is handed in).
    coat: RoughConductor,
    /// int_ior / ext_ior.
    pub eta: f32,
    /// Albedo of the base, per channel.
    pub diffuse_reflectance: Rgb,
    /// Mitsuba's `nonlinear`: account for the colour shift of light bouncing inside the coating.
    pub nonlinear: bool,
    /// t(cos) at cos = i / 63.
    transmittance: [f32; RES],
    /// d / (1 - R_int) / eta^2 / pi.
    diffuse_scale: Rgb,
    specular_weight: f32,
}

/// The 64 cosines, as Mitsuba places them (the first raised to 1e-6) and their directions.
fn table_directions() -> impl Iterator<Item = (f32, Vec3)> {
    (0..RES).map(|i| {
        let mu = (i as f32 / (RES - 1) as f32).max(1e-6);
        (mu, Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu))
    })
}

/// The Gauss-Legendre rule Mitsuba integrates these tables with at index ratio `eta`:
/// 32 x 32 nodes above 1, 128 x 128 below.
fn rule(eta: f32) -> Vec<(f64, f64)> {
    gauss_legendre(if eta > 1.0 { 32 } else { 128 })
}

/// E over visible normals m of `f(m)`, by the rule `q` on the unit square of the sampler's
/// numbers.
fn visible_mean(mf: &Microfacet, wi: Vec3, q: &[(f64, f64)], f: impl Fn(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for &(x, wx) in q {
        for &(y, wy) in q {
            let u = Vec2::new((x * 0.5 + 0.5) as f32, (y * 0.5 + 0.5) as f32);
            sum += f(mf.sample_visible(wi, u)) * wx * wy * 0.25;
        }
    }
    sum
}

impl RoughPlastic {
    /// The coating's microfacet distribution over a base, with the tables of the coating's
    /// albedo the model needs (computed here).
    pub fn new(
        mf: Microfacet,
        sample_visible: bool,
        eta: f32,
        diffuse: Rgb,
        specular: Rgb,
        nonlinear: bool,
    ) -> Self {
        let mut transmittance = [0.0f32; RES];
        let mut internal = 0.0f64;
        let (outside, inside) = (rule(eta), rule(1.0 / eta));
        for (i, (mu, wi)) in table_directions().enumerate() {
            transmittance[i] = visible_mean(&mf, wi, &outside, |m| {
                let (f, cos_t, eta_ti) = fresnel_dielectric(wi.dot(m), eta);
                let wt = m * (wi.dot(m) * eta_ti + cos_t) - wi * eta_ti;
                if wt.z * wi.z >= 0.0 {
                    return 0.0;
                }
                (mf.g1(wt, m) * (1.0 - f)) as f64
            }) as f32;
            let r = visible_mean(&mf, wi, &inside, |m| {
                let wo = 2.0 * wi.dot(m) * m - wi;
                if wo.z <= 0.0 {
                    return 0.0;
                }
                (mf.g1(wo, m) * fresnel_dielectric(wi.dot(m), 1.0 / eta).0) as f64
            });
            internal += r * mu as f64;
        }
        let internal_reflectance = (2.0 * internal / RES as f64) as f32;
        let divisor = if nonlinear {
            Rgb::ONE - diffuse * internal_reflectance
        } else {
            Rgb::splat(1.0 - internal_reflectance)
        };
        let (d_mean, s_mean) = (diffuse.element_sum() / 3.0, specular.element_sum() / 3.0);
        RoughPlastic {
            coat: RoughConductor {
                mf,
                sample_visible,
                eta: Rgb::ZERO,
                k: Rgb::ONE,
                specular_reflectance: specular,
            },
            eta,
            diffuse_reflectance: diffuse,
            nonlinear,
            transmittance,
            diffuse_scale: diffuse / divisor / (eta * eta) * INV_PI,
            specular_weight: s_mean / (d_mean + s_mean),
        }
    }

    /// t(cos) interpolated in the table, as Mitsuba's lerp_gather.
    #[inline]
    pub fn transmittance(&self, cos: f32) -> f32 {
        let x = cos * (RES - 1) as f32;
        let i = (x as usize).min(RES - 2);
        let w = x - i as f32;
        self.transmittance[i] * (1.0 - w) + self.transmittance[i + 1] * w
    }

    /// (t(cos_i), probability of the coating's lobe).
    #[inline]
    fn lobes(&self, cos_i: f32) -> (f32, f32) {
        let t_i = self.transmittance(cos_i);
        let spec = (1.0 - t_i) * self.specular_weight;
        let diff = t_i * (1.0 - self.specular_weight);
        (t_i, spec / (spec + diff))
    }
}

impl Bsdf for RoughPlastic {
    fn glossy_lobe(&self) -> Option<(f32, f32)> {
        self.coat.glossy_lobe()
    }

    const DELTA: bool = false;

    /// Mitsuba 3's names and defaults: those of `plastic` and the microfacet lobe's
    /// `distribution` (beckmann), `alpha` (0.1) and `sample_visible` (true); isotropic only.
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let (eta, diffuse, specular, nonlinear) = params::coated(p)?;
        if eta == 1.0 {
            return Err(p.error(None, "int_ior and ext_ior must differ".into()));
        }
        let (mf, sample_visible) = params::microfacet(p)?;
        if mf.alpha_u != mf.alpha_v {
            return Err(p.error(
                None,
                "roughplastic takes an isotropic roughness only (as Mitsuba 3): give 'alpha'"
                    .into(),
            ));
        }
        Ok(RoughPlastic::new(
            mf,
            sample_visible,
            eta,
            diffuse,
            specular,
            nonlinear,
        ))
    }

    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        self.eval_pdf(wi, wo).0
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.eval_pdf(wi, wo).1
    }

    #[inline]
    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (Rgb, f32) {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let (t_i, p_spec) = self.lobes(wi.z);
        let spec = self.coat.specular_reflectance;
        let (f_spec, pdf_spec) = self
            .coat
            .eval_pdf_with(wi, wo, self.coat.mf.lambda(wi), |c| {
                spec * fresnel_dielectric(c, self.eta).0
            });
        let t_o = self.transmittance(wo.z);
        let f = f_spec + self.diffuse_scale * (wo.z * t_i * t_o);
        let pdf = p_spec * pdf_spec + (1.0 - p_spec) * square_to_cosine_hemisphere_pdf(wo);
        (f, pdf)
    }

    #[inline]
    fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let (_, p_spec) = self.lobes(wi.z);
        let wo = if u1 < p_spec {
            let mf = &self.coat.mf;
            let m = if self.coat.sample_visible {
                mf.sample_visible(wi, u2)
            } else {
                mf.sample_all(u2)
            };
            2.0 * wi.dot(m) * m - wi
        } else {
            square_to_cosine_hemisphere(u2)
        };
        let (f, pdf) = self.eval_pdf(wi, wo);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wo,
            weight: f / pdf,
            pdf,
            delta: false,
        })
    }
}

#[cfg(test)]
#[path = "roughplastic_tests.rs"]
mod tests;
