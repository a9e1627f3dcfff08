//! Receivers of the gallery: a Lambertian surface, and Nori's `microfacet` (a diffuse lobe
//! plus a Beckmann specular lobe with ks = 1 - kd, Fresnel left out), whose pdf is not
//! symmetric in (wi, wo) so that swapping them is a visible mistake. Local frame, z = normal;
//! `eval` includes cos(theta_o).

use super::Bug;
use crate::sampling::warps::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Receiver {
    Diffuse { albedo: f32 },
    Microfacet { alpha: f32, kd: f32 },
}

/// What `sample` returns: direction, weight = eval / pdf, and the pdf it used.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub wo: Vec3,
    pub weight: f32,
    pub pdf: f32,
}

fn beckmann_d(alpha: f32, m: Vec3) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let c2 = m.z * m.z;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    (-tan2 / (alpha * alpha)).exp() / (PI * alpha * alpha * c2 * c2)
}

/// Smith's shadowing for Beckmann, Walter et al.'s rational approximation (as Nori).
fn smith_g1(alpha: f32, v: Vec3, m: Vec3) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    let tan = (1.0 - v.z * v.z).max(0.0).sqrt() / v.z;
    if tan == 0.0 {
        return 1.0;
    }
    let b = 1.0 / (alpha * tan);
    if b >= 1.6 {
        1.0
    } else {
        (3.535 * b + 2.181 * b * b) / (1.0 + 2.276 * b + 2.577 * b * b)
    }
}

fn sample_beckmann(alpha: f32, u: Vec2) -> Vec3 {
    let tan2 = -alpha * alpha * (1.0 - u.x).ln();
    let c = 1.0 / (1.0 + tan2).sqrt();
    let s = (1.0 - c * c).max(0.0).sqrt();
    let (sp, cp) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(s * cp, s * sp, c)
}

pub struct Bsdf {
    pub receiver: Receiver,
    pub bug: Bug,
}

impl Bsdf {
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        match self.receiver {
            Receiver::Diffuse { albedo } => albedo * FRAC_1_PI * wo.z,
            Receiver::Microfacet { alpha, kd } => {
                let h = (wi + wo).normalize();
                let spec = beckmann_d(alpha, h) * smith_g1(alpha, wi, h) * smith_g1(alpha, wo, h)
                    / (4.0 * wi.z * wo.z);
                (kd * FRAC_1_PI + (1.0 - kd) * spec) * wo.z
            }
        }
    }

    /// The correct density of `sample`.
    fn true_pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        match self.receiver {
            Receiver::Diffuse { .. } => square_to_cosine_hemisphere_pdf(wo),
            Receiver::Microfacet { alpha, kd } => {
                let h = (wi + wo).normalize();
                let spec = beckmann_d(alpha, h) * h.z / (4.0 * wo.dot(h).abs());
                (1.0 - kd) * spec + kd * square_to_cosine_hemisphere_pdf(wo)
            }
        }
    }

    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        match self.bug {
            Bug::CosineWithUniformPdf if wi.z > 0.0 && wo.z > 0.0 => 0.5 * FRAC_1_PI,
            Bug::WiWoSwapped => self.true_pdf(wo, wi),
            _ => self.true_pdf(wi, wo),
        }
    }

    pub fn sample(&self, wi: Vec3, u1: f32, u2: Vec2) -> Option<Sample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wo = match self.receiver {
            Receiver::Microfacet { kd, alpha } if u1 >= kd => {
                let m = sample_beckmann(alpha, u2);
                2.0 * wi.dot(m) * m - wi
            }
            _ => square_to_cosine_hemisphere(u2),
        };
        if wo.z <= 0.0 {
            return None;
        }
        // The cosine-warp bug reports the uniform density; the wi/wo bug is in pdf() only.
        let pdf = if self.bug == Bug::CosineWithUniformPdf {
            self.pdf(wi, wo)
        } else {
            self.true_pdf(wi, wo)
        };
        (pdf > 0.0).then(|| Sample {
            wo,
            weight: self.eval(wi, wo) / pdf,
            pdf,
        })
    }
}
