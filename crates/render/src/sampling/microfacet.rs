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

use super::elementary::{atan, exp, ln};
use super::erf::{erfc_from_exp, erfinv};
/// The microfacet normal distributions Mitsuba's `roughconductor` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetDistribution {
    /// Beckmann's Gaussian slope distribution.
    Beckmann,
    /// GGX (Trowbridge-Reitz).
    Ggx,
}
use glam::{DVec3, Vec2, Vec3};
use std::f32::consts::{FRAC_2_SQRT_PI, PI};

const SQRT_PI: f32 = 1.772_453_9;

/// Below this roughness f32 evaluation of D loses its peak (Mitsuba clamps at the same value).
pub const MIN_ALPHA: f32 = 1e-4;

/// A microfacet distribution with anisotropic roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// Which distribution.
    pub distribution: MicrofacetDistribution,
    /// Roughness along the first tangent.
    pub alpha_u: f32,
    /// Roughness along the second tangent.
    pub alpha_v: f32,
}

impl Microfacet {
    /// The distribution with roughnesses clamped below at `MIN_ALPHA`.
    pub fn new(distribution: MicrofacetDistribution, alpha_u: f32, alpha_v: f32) -> Self {
        Microfacet {
            distribution,
            alpha_u: alpha_u.max(MIN_ALPHA),
            alpha_v: alpha_v.max(MIN_ALPHA),
        }
    }

    /// Normal distribution D(m), zero for normals facing down.
    #[inline(always)]
    pub fn d(&self, m: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let (x, y) = (m.x / au, m.y / av);
        let z2 = m.z * m.z;
        // z^4 is 0 for |z| below ~1e-11, where Beckmann's exp is 0 as well: no 0 / 0.
        let up = m.z > 0.0 && z2 * z2 > 0.0;
        let d = match self.distribution {
            MicrofacetDistribution::Beckmann => {
                exp(-(x * x + y * y) / z2) / (PI * au * av * z2 * z2)
            }
            MicrofacetDistribution::Ggx => {
                let t = x * x + y * y + z2;
                1.0 / (PI * au * av * t * t)
            }
        };
        // A select, not an early return: `integrator::lanes` runs this in vector lanes.
        if up {
            d
        } else {
            0.0
        }
    }

    /// Smith's Lambda for direction w (independent of the microfacet normal).
    #[inline(always)]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        // alpha(w)^2 tan^2(theta_w), the squared slope scale seen from w.
        let a2t2 = ((w.x * au).powi(2) + (w.y * av).powi(2)) / (w.z * w.z);
        let l = match self.distribution {
            MicrofacetDistribution::Ggx => 0.5 * ((1.0 + a2t2).sqrt() - 1.0),
            MicrofacetDistribution::Beckmann => {
                // Evaluated for every a2t2 and then selected (see `d`).
                let a = 1.0 / a2t2.sqrt();
                let e = exp(-a * a);
                let l = 0.5 * (e / (a * SQRT_PI) - erfc_from_exp(a, e));
                if a2t2 <= 0.0 || a > 6.0 {
                    0.0
                } else {
                    l
                }
            }
        };
        if a2t2.is_finite() {
            l.max(0.0)
        } else {
            f32::INFINITY
        }
    }

    /// Masking of normal m seen from w; zero when w sees the back of m or of the surface.
    #[inline(always)]
    pub fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        self.g1_given(w, m, self.lambda(w))
    }

    /// `g1` given Lambda(w).
    #[inline(always)]
    pub fn g1_given(&self, w: Vec3, m: Vec3, lambda: f32) -> f32 {
        let g = 1.0 / (1.0 + lambda);
        if w.dot(m) * w.z <= 0.0 {
            0.0
        } else {
            g
        }
    }

    /// A normal with density D(m) cos(theta_m).
    #[inline]
    pub fn sample_all(&self, u: Vec2) -> Vec3 {
        let (u0, u1) = (u.x as f64, u.y as f64);
        let r = match self.distribution {
            MicrofacetDistribution::Beckmann => (-(1.0 - u0).ln()).sqrt(),
            MicrofacetDistribution::Ggx => (u0 / (1.0 - u0)).sqrt(),
        };
        let (s, c) = (2.0 * std::f64::consts::PI * u1).sin_cos();
        let x = r * c * self.alpha_u as f64;
        let y = r * s * self.alpha_v as f64;
        DVec3::new(-x, -y, 1.0).normalize().as_vec3()
    }

    /// Density of a normal drawn from D(m) cos(m) (all normals).
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

    /// Density of a normal visible from `wi`: G1(wi) max(0, wi.m) D(m) / cos(wi).
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
        let (s, c) = (2.0 * std::f64::consts::PI * u.y as f64).sin_cos();
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
        let mut b = self.beckmann_visible_begin(wi, u);
        b.slope.solve();
        self.beckmann_visible_end(&b)
    }

    /// `sample_visible_beckmann` up to the slope inversion's steps. Its three parts
    /// are separate functions for the lane kernel, which runs each in a loop of its own.
    #[inline(always)]
    pub(crate) fn beckmann_visible_begin(&self, wi: Vec3, u: Vec2) -> BeckmannVisible {
        let (cos_phi, sin_phi, tan_t) = self.beckmann_visible_azimuth(wi);
        BeckmannVisible {
            cos_phi,
            sin_phi,
            y: beckmann_visible_y(u.y),
            slope: SlopeInversion::new(tan_t, u.x),
        }
    }

    /// wi's azimuth (cos, sin) and tan(theta) in the stretched configuration.
    #[inline(always)]
    pub(crate) fn beckmann_visible_azimuth(&self, wi: Vec3) -> (f32, f32, f32) {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let ws = Vec3::new(au * wi.x, av * wi.y, wi.z).normalize();
        let sin_t = (ws.x * ws.x + ws.y * ws.y).sqrt();
        let tan_t = sin_t / ws.z;
        let has_azimuth = sin_t > 0.0;
        let cos_phi = if has_azimuth { ws.x / sin_t } else { 1.0 };
        let sin_phi = if has_azimuth { ws.y / sin_t } else { 0.0 };
        (cos_phi, sin_phi, tan_t)
    }

    /// `sample_visible_beckmann` after the slope inversion: rotate back and unstretch.
    #[inline(always)]
    pub(crate) fn beckmann_visible_end(&self, b: &BeckmannVisible) -> Vec3 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let (x, y) = (b.slope.x, b.y);
        let sx = (b.cos_phi * x - b.sin_phi * y) * au;
        let sy = (b.sin_phi * x + b.cos_phi * y) * av;
        Vec3::new(-sx, -sy, 1.0).normalize()
    }
}

/// The visible slope y, whose marginal is Gaussian (variance 1/2): a plain inverse erf.
#[inline(always)]
pub(crate) fn beckmann_visible_y(u: f32) -> f32 {
    erfinv(2.0 * u - 1.0)
}

/// A Beckmann visible-normal sample between `beckmann_visible_begin` and `_end`: the
/// incident azimuth in the stretched configuration, the Gaussian slope y and the inversion
/// of the slope x.
#[derive(Clone, Copy, Default)]
pub(crate) struct BeckmannVisible {
    pub cos_phi: f32,
    pub sin_phi: f32,
    pub y: f32,
    pub slope: SlopeInversion,
}

// Steps of the slope inversion, counted for the cost test.
#[cfg(test)]
thread_local!(pub(crate) static ITERS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) });

/// Inverts the marginal CDF of the visible slope x of a standard (alpha = 1) Beckmann surface
/// seen at tan(theta) = `tan_t` along +x. The density is proportional to
/// exp(-x^2) (cot(theta) - x) on x < cot(theta); its CDF, times 2 / (sqrt(pi) cot(theta)), is
///   C(x) = erfc(-x) + tan(theta) / sqrt(pi) exp(-x^2).
/// Safeguarded Halley steps (bisection fallback) from Mitsuba 3's starting guess, in f32 as
/// Mitsuba's. Every inversion takes `FIXED_STEPS` steps, then more only until a step is below
/// 1e-5 (1 + |x|) (Halley converges cubically, so the point is then as close as f32 can
/// place it), the CDF's residual is within its f32 rounding, or the bracket is a few ulps
/// wide. The result is the exact inverse to within 4 ulps of x or 4 eps of u
/// (`beckmann_slope_inversion_matches_bisection`): as fine as the f32 uniform number that
/// drives it. The fixed steps have no branches: `integrator::lanes` runs them for eight
/// samples in vector lanes, and the scalar path runs the same steps.
#[derive(Clone, Copy, Default)]
pub(crate) struct SlopeInversion {
    /// The current point, inside the bracket (lo, hi) around the root.
    pub x: f32,
    pub lo: f32,
    pub hi: f32,
    pub target: f32,
    pub tan_t: f32,
    pub k: f32,
    /// Whether the last step converged.
    pub done: bool,
}

impl SlopeInversion {
    /// Steps every inversion takes.
    pub const FIXED_STEPS: usize = 2;

    #[inline(always)]
    pub fn new(tan_t: f32, u: f32) -> Self {
        let k = tan_t / SQRT_PI;
        // Beyond |x| = 9 both terms are below 1e-35 of the total: nothing left to sample.
        let cot_t = 1.0 / tan_t;
        let hi = if tan_t > 1.0 / 9.0 { cot_t } else { 9.0 };
        let lo = -9.0;
        // hi > 0, so erfc(-hi) is exactly 2 - erfc(hi) (that is how `erfc` makes it).
        let e_hi = exp(-hi * hi);
        let erfc_hi = erfc_from_exp(hi, e_hi);
        let target = u * ((2.0 - erfc_hi) + k * e_hi);
        // Mitsuba 3's starting guess, in erf space: a power of 1 - u fitted in theta.
        let c = 1.0 - erfc_hi;
        let theta = atan(tan_t);
        let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
        let guess = c - (1.0 + c) * exp(fit * ln((1.0 - u).max(0.0)));
        // `clamp` by hand: `f32::clamp` asserts lo <= hi, a panic path that kept this loop
        // out of vector lanes in the lane kernel.
        let g = erfinv(guess);
        let x = if g < lo {
            lo
        } else if g > hi {
            hi
        } else {
            g
        };
        SlopeInversion {
            x,
            lo,
            hi,
            target,
            tan_t,
            k,
            done: false,
        }
    }

    /// One safeguarded Halley step on C(x) - target.
    #[inline(always)]
    pub fn step(&mut self) {
        #[cfg(test)]
        ITERS.with(|c| c.set(c.get() + 1));
        let (x, lo, hi, done) =
            slope_step(self.x, self.lo, self.hi, self.target, self.tan_t, self.k);
        (self.x, self.lo, self.hi, self.done) = (x, lo, hi, done);
    }

    /// The fixed steps, then `finish`: the scalar path's whole inversion.
    #[inline]
    pub fn solve(&mut self) {
        for _ in 0..Self::FIXED_STEPS {
            self.step();
        }
        self.finish(Self::FIXED_STEPS);
    }

    /// Steps after the `taken` ones, while the last did not converge (at most 64 in all).
    #[inline]
    pub fn finish(&mut self, taken: usize) {
        for _ in taken..64 {
            if self.done {
                return;
            }
            self.step();
        }
    }
}

/// `SlopeInversion::step` on its fields, for the lane kernel's structure-of-arrays copy of
/// eight inversions: returns the new point, bracket and whether the step converged.
#[inline(always)]
pub(crate) fn slope_step(
    x: f32,
    lo: f32,
    hi: f32,
    target: f32,
    tan_t: f32,
    k: f32,
) -> (f32, f32, f32, bool) {
    let e = exp(-x * x);
    let f = erfc_from_exp(-x, e) + k * e - target;
    // f = 0 leaves the bracket as it is: x is then a root, and the step to x itself
    // must stay inside.
    let hi = if f > 0.0 { x } else { hi };
    let lo = if f < 0.0 { x } else { lo };
    // Halley's step, from C' and C'' (both cheap given e): converging cubically, it leaves
    // far fewer inversions short of the fixed steps than Newton's did at grazing angles.
    let d1 = FRAC_2_SQRT_PI * e * (1.0 - x * tan_t);
    let d2 = -2.0 * x * d1 - FRAC_2_SQRT_PI * e * tan_t;
    let halley = x - 2.0 * f * d1 / (2.0 * d1 * d1 - f * d2);
    // Inclusive: at the root, a step below an ulp of x lands on x, which the bracket's
    // update may just have made an end.
    let inside = halley >= lo && halley <= hi;
    let next = if inside { halley } else { 0.5 * (lo + hi) };
    // Near the top of the CDF (C ~ 2) f carries an absolute rounding error of ~1e-7, so a
    // tail root's steps never get below the first bound: the second and third stop them.
    let done = (inside && (next - x).abs() < 1e-5 * (1.0 + x.abs()))
        || f.abs() <= 4.0 * f32::EPSILON * target
        || hi - lo < 4e-6 * (1.0 + x.abs());
    (next, lo, hi, done)
}

/// `SlopeInversion` from start to root.
#[cfg(test)]
fn beckmann_visible_slope(tan_t: f32, u: f32) -> f32 {
    let mut s = SlopeInversion::new(tan_t, u);
    s.solve();
    s.x
}

#[cfg(test)]
#[path = "microfacet_tests.rs"]
mod tests;
