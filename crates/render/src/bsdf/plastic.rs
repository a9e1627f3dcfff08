//! Mitsuba 3's `plastic`: a smooth dielectric coating (index ratio eta = int_ior / ext_ior)
//! over a Lambertian base, as its plastic.cpp defines it. Two lobes:
//! - specular (delta): the mirror direction with throughput specular_reflectance F(cos_i);
//! - diffuse: f = d / (1 - F_dr,int) (1 - F(cos_i)) (1 - F(cos_o)) / (eta^2 pi), where
//!   F_dr,int is the coating's diffuse Fresnel reflectance seen from inside (internal
//!   reflections summed as a geometric series; with `nonlinear` the series is taken per
//!   colour, d / (1 - d F_dr,int), so the colour saturates as in a real varnish).
//!
//! `sample` picks the specular lobe with probability proportional to F(cos_i) s against
//! (1 - F(cos_i)) (1 - s), with s = mean(specular) / (mean(diffuse) + mean(specular)); `eval`
//! and `pdf` describe the diffuse lobe only (the delta lobe has no density). One-sided.

use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
use super::params::{self, Params};
use super::{Bsdf, BsdfSample};
use crate::math::{Rgb, INV_PI};
use crate::sampling::warps::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};

/// Mitsuba's `plastic`: a diffuse base under a smooth dielectric coating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// int_ior / ext_ior.
    pub eta: f32,
    /// Albedo of the base, per channel.
    pub diffuse_reflectance: Rgb,
    /// Scale on the coating's reflection.
    pub specular_reflectance: Rgb,
    /// Mitsuba's `nonlinear`: account for the colour shift of light bouncing inside the coating.
    pub nonlinear: bool,
    /// d / (1 - F_dr,int) (per channel with `nonlinear`) / eta^2: the diffuse lobe's constant.
    diffuse_scale: Rgb,
    /// s above.
    specular_weight: f32,
}

impl Plastic {
    /// A coating of relative index `eta` over the `diffuse` base, with the precomputed internal
    /// reflectance the model needs.
    pub fn new(eta: f32, diffuse: Rgb, specular: Rgb, nonlinear: bool) -> Self {
        let fdr_int = fresnel_diffuse_reflectance(1.0 / eta);
        let internal = if nonlinear {
            Rgb::ONE - diffuse * fdr_int
        } else {
            Rgb::splat(1.0 - fdr_int)
        };
        let (d_mean, s_mean) = (diffuse.element_sum() / 3.0, specular.element_sum() / 3.0);
        Plastic {
            eta,
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            nonlinear,
            diffuse_scale: diffuse / internal / (eta * eta),
            specular_weight: s_mean / (d_mean + s_mean),
        }
    }

    /// The largest channel of the albedo at normal incidence, F s + (1 - F) (1 - F_dr,ext)
    /// times the diffuse constant: the coating reflects F_dr,ext of diffuse light back in.
    /// Above 1 where the diffuse Fresnel fits disagree (white plastic of index ratio 3:
    /// 1.185).
    pub fn normal_albedo(&self) -> f32 {
        let f = fresnel_dielectric(1.0, self.eta).0;
        let fdr_ext = fresnel_diffuse_reflectance(self.eta);
        let diffuse = self.diffuse_scale * ((1.0 - f) * (1.0 - fdr_ext));
        (self.specular_reflectance * f + diffuse).max_element()
    }

    /// (F(cos_i), probability of the specular lobe).
    #[inline]
    fn lobes(&self, cos_i: f32) -> (f32, f32) {
        let f_i = fresnel_dielectric(cos_i, self.eta).0;
        let spec = f_i * self.specular_weight;
        let diff = (1.0 - f_i) * (1.0 - self.specular_weight);
        (f_i, spec / (spec + diff))
    }

    /// The diffuse lobe's f |cos_o| given F(cos_i).
    #[inline]
    fn diffuse(&self, f_i: f32, wo: Vec3) -> Rgb {
        let f_o = if crate::seeded::active(crate::seeded::SeededBug::PlasticExitFresnel) {
            f_i
        } else {
            fresnel_dielectric(wo.z, self.eta).0
        };
        self.diffuse_scale * ((1.0 - f_i) * (1.0 - f_o) * INV_PI * wo.z)
    }
}

impl Bsdf for Plastic {
    const DELTA: bool = false;
    const DELTA_LOBE: bool = true;

    /// Mitsuba 3's names and defaults: int_ior "polypropylene" (1.49), ext_ior "air",
    /// diffuse_reflectance 0.5, specular_reflectance 1, nonlinear false.
    fn from_params<P: Params>(p: &mut P) -> Result<Self, P::Error> {
        let (eta, diffuse, specular, nonlinear) = params::coated(p)?;
        let m = Plastic::new(eta, diffuse, specular, nonlinear);
        let most = m.normal_albedo();
        if most > 1.01 {
            p.warn(format!(
                "this plastic reflects {most:.3} of the light arriving along the normal: \
                 Mitsuba's fit of the coating's internal reflection is off at an index ratio \
                 of {} (rendered as Mitsuba does; a lower diffuse_reflectance avoids it)",
                m.eta
            ));
        }
        Ok(m)
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
        let (f_i, p_spec) = self.lobes(wi.z);
        let pdf = (1.0 - p_spec) * square_to_cosine_hemisphere_pdf(wo);
        (self.diffuse(f_i, wo), pdf)
    }

    #[inline]
    fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let (f_i, p_spec) = self.lobes(wi.z);
        if u1 < p_spec {
            return Some(BsdfSample {
                wo: Vec3::new(-wi.x, -wi.y, wi.z),
                weight: self.specular_reflectance * (f_i / p_spec),
                pdf: p_spec,
                delta: true,
            });
        }
        let wo = square_to_cosine_hemisphere(u2);
        let p_diff = 1.0 - p_spec;
        let pdf = p_diff * square_to_cosine_hemisphere_pdf(wo);
        if !(pdf > 0.0) {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta).0;
        Some(BsdfSample {
            wo,
            weight: self.diffuse_scale * ((1.0 - f_i) * (1.0 - f_o) / p_diff),
            pdf,
            delta: false,
        })
    }
}

#[cfg(test)]
#[path = "plastic_tests.rs"]
mod tests;
