//! Beckmann and GGX microfacet distributions, isotropic or anisotropic (alpha_u along local x,
//! alpha_v along y), with the exact Smith masking term and two samplers:
//! - the full distribution, density D(m) cos(theta_m) (Walter et al. 2007);
//! - visible normals, density G1(wi, m) max(0, wi.m) D(m) / cos(theta_i) (Heitz 2018 for
//!   GGX; Heitz & d'Eon 2014 slope inversion for Beckmann).
//!
//! Beckmann uses the exact erf-based Lambda, not the rational fit: the visible-normal pdf is
//! only normalised with the exact term, and sample/pdf must agree.
//!
//! Both samplers work in slope space: m = normalize(-x, -y, 1) and D(m) cos(theta_m) dω equals
//! the slope density P22(x, y) dx dy; stretching slopes by (alpha_u, alpha_v) gives anisotropy.

use super::erf::{erfc_from_exp, erfinv, erfinv_approx};
pub use crate::scene::desc::MicrofacetDistribution;
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::PI;

/// Below this roughness f32 evaluation of D loses its peak (Mitsuba clamps at the same value).
pub const MIN_ALPHA: f32 = 1e-4;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub distribution: MicrofacetDistribution,
    pub alpha_u: f32,
    pub alpha_v: f32,
}

impl Microfacet {
    pub fn new(distribution: MicrofacetDistribution, alpha_u: f32, alpha_v: f32) -> Self {
        Microfacet {
            distribution,
            alpha_u: alpha_u.max(MIN_ALPHA),
            alpha_v: alpha_v.max(MIN_ALPHA),
        }
    }

    /// Normal distribution D(m), zero for normals facing down.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let m = m.as_dvec3();
        let (au, av) = (self.alpha_u as f64, self.alpha_v as f64);
        let (x, y) = (m.x / au, m.y / av);
        let z2 = m.z * m.z;
        let d = match self.distribution {
            MicrofacetDistribution::Beckmann => {
                (-(x * x + y * y) / z2).exp() / (PI * au * av * z2 * z2)
            }
            MicrofacetDistribution::Ggx => {
                let t = x * x + y * y + z2;
                1.0 / (PI * au * av * t * t)
            }
        };
        d as f32
    }

    /// Smith's Lambda for direction w (independent of the microfacet normal).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let w = w.as_dvec3();
        let (au, av) = (self.alpha_u as f64, self.alpha_v as f64);
        // alpha(w)^2 tan^2(theta_w), the squared slope scale seen from w.
        let a2t2 = ((w.x * au).powi(2) + (w.y * av).powi(2)) / (w.z * w.z);
        if !a2t2.is_finite() {
            return f32::INFINITY;
        }
        let l = match self.distribution {
            MicrofacetDistribution::Ggx => 0.5 * ((1.0 + a2t2).sqrt() - 1.0),
            MicrofacetDistribution::Beckmann => {
                if a2t2 <= 0.0 {
                    return 0.0;
                }
                let a = 1.0 / a2t2.sqrt();
                if a > 6.0 {
                    0.0
                } else {
                    let e = (-a * a).exp();
                    0.5 * (e / (a * PI.sqrt()) - erfc_from_exp(a, e))
                }
            }
        };
        l.max(0.0) as f32
    }

    /// Masking of normal m seen from w; zero when w sees the back of m or of the surface.
    #[inline]
    pub fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        if w.dot(m) * w.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(w))
    }

    /// A normal with density D(m) cos(theta_m).
    #[inline]
    pub fn sample_all(&self, u: Vec2) -> Vec3 {
        let (u0, u1) = (u.x as f64, u.y as f64);
        let r = match self.distribution {
            MicrofacetDistribution::Beckmann => (-(1.0 - u0).ln()).sqrt(),
            MicrofacetDistribution::Ggx => (u0 / (1.0 - u0)).sqrt(),
        };
        let (s, c) = (2.0 * PI * u1).sin_cos();
        let x = r * c * self.alpha_u as f64;
        let y = r * s * self.alpha_v as f64;
        DVec3::new(-x, -y, 1.0).normalize().as_vec3()
    }

    #[inline]
    pub fn pdf_all(&self, m: Vec3) -> f32 {
        self.d(m) * m.z.max(0.0)
    }

    /// A normal visible from wi (wi.z > 0), density `pdf_visible(wi, m)`.
    #[inline]
    pub fn sample_visible(&self, wi: Vec3, u: Vec2) -> Vec3 {
        match self.distribution {
            MicrofacetDistribution::Ggx => self.sample_visible_ggx(wi, u),
            MicrofacetDistribution::Beckmann => self.sample_visible_beckmann(wi, u),
        }
    }

    #[inline]
    pub fn pdf_visible(&self, wi: Vec3, m: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        self.g1(wi, m) * wi.dot(m).max(0.0) * self.d(m) / wi.z
    }

    /// Heitz 2018, "Sampling the GGX distribution of visible normals".
    fn sample_visible_ggx(&self, wi: Vec3, u: Vec2) -> Vec3 {
        let (au, av) = (self.alpha_u as f64, self.alpha_v as f64);
        let wi = wi.as_dvec3();
        let vh = DVec3::new(au * wi.x, av * wi.y, wi.z).normalize();
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 0.0 {
            DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
        } else {
            DVec3::X
        };
        let t2 = vh.cross(t1);
        let r = (u.x as f64).sqrt();
        let (s, c) = (2.0 * PI * u.y as f64).sin_cos();
        let p1 = r * c;
        let h = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - h) * (1.0 - p1 * p1).max(0.0).sqrt() + h * r * s;
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        DVec3::new(au * nh.x, av * nh.y, nh.z.max(0.0))
            .normalize()
            .as_vec3()
    }

    /// Heitz & d'Eon 2014: in the stretched configuration, sample the slope x along the
    /// projected incident direction from its visible marginal, y from a Gaussian, rotate back
    /// and unstretch.
    fn sample_visible_beckmann(&self, wi: Vec3, u: Vec2) -> Vec3 {
        let (au, av) = (self.alpha_u as f64, self.alpha_v as f64);
        let wi = wi.as_dvec3();
        let ws = DVec3::new(au * wi.x, av * wi.y, wi.z).normalize();
        let sin_t = (ws.x * ws.x + ws.y * ws.y).sqrt();
        let tan_t = sin_t / ws.z;
        let (cp, sp) = if sin_t > 0.0 {
            (ws.x / sin_t, ws.y / sin_t)
        } else {
            (1.0, 0.0)
        };
        // The y marginal is Gaussian (variance 1/2): a plain inverse erf. Computed first, its
        // dependency chain overlaps the slope inversion's instead of following it.
        let y = erfinv(2.0 * (u.y as f64).clamp(1e-12, 1.0 - 1e-12) - 1.0);
        let x = beckmann_visible_slope(tan_t, u.x as f64);
        let sx = (cp * x - sp * y) * au;
        let sy = (sp * x + cp * y) * av;
        DVec3::new(-sx, -sy, 1.0).normalize().as_vec3()
    }
}

// Newton iterations of the slope inversion, counted for the cost test.
#[cfg(test)]
thread_local!(pub static ITERS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) });

/// Inverts the marginal CDF of the visible slope x of a standard (alpha = 1) Beckmann surface
/// seen at tan(theta) = `tan_t` along +x. The density is proportional to
/// exp(-x^2) (cot(theta) - x) on x < cot(theta); its CDF, times 2 / (sqrt(pi) cot(theta)), is
///   C(x) = erfc(-x) + tan(theta) / sqrt(pi) exp(-x^2).
/// Safeguarded Newton (bisection fallback). It stops when a Newton step is below 1e-6: Newton
/// converges quadratically there, so the returned point is ~1e-12 from the root, far finer than
/// the f32 normal it feeds (stopping at steps below 1e-9 cost one more erfc and exp per sample
/// for no visible digit).
fn beckmann_visible_slope(tan_t: f64, u: f64) -> f64 {
    let k = tan_t / PI.sqrt();
    // C(x) from exp(-x^2), which erfc and the Newton step's derivative share.
    let cdf = |x: f64, e: f64| erfc_from_exp(-x, e) + k * e;
    // Beyond |x| = 9 both terms are below 1e-35 of the total: nothing left to sample.
    let (mut lo, mut hi) = (-9.0f64, if tan_t > 1.0 / 9.0 { 1.0 / tan_t } else { 9.0 });
    // hi > 0, so erfc(-hi) is exactly 2 - erfc(hi) (that is how `erfc` makes it).
    let e_hi = (-hi * hi).exp();
    let erfc_hi = erfc_from_exp(hi, e_hi);
    let target = u.clamp(1e-12, 1.0 - 1e-12) * ((2.0 - erfc_hi) + k * e_hi);
    // Mitsuba 3's starting guess, in erf space: a power of 1 - u fitted in theta.
    let c = 1.0 - erfc_hi;
    let theta = tan_t.atan();
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let guess = c - (1.0 + c) * (1.0 - u).max(0.0).powf(fit);
    let mut x = erfinv_approx(guess).clamp(lo, hi);
    for _it in 0..64 {
        #[cfg(test)]
        ITERS.with(|c| c.set(c.get() + 1));
        let e = (-x * x).exp();
        let f = cdf(x, e) - target;
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let df = 2.0 / PI.sqrt() * e * (1.0 - x * tan_t);
        let mut next = x - f / df;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let newton = next == x - f / df;
        if (newton && (next - x).abs() < 1e-6 * (1.0 + x.abs())) || hi - lo < 1e-12 {
            return next;
        }
        x = next;
    }
    x
}

#[cfg(test)]
#[path = "microfacet_tests.rs"]
mod tests;
