//! Warps from the unit square to the study's domains, each with the density it produces.
//! Densities are with respect to area on the target domain (solid angle for directions).

use super::elementary::small_int_bits;
use crate::math::{INV_PI, PI};
use glam::{Vec2, Vec3};

/// A uniform point on the unit disk (concentric map).
#[inline]
pub fn square_to_uniform_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let (s, c) = sin_cos_turns(u.y);
    Vec2::new(r * c, r * s)
}

/// Density of `square_to_uniform_disk`: 1 / pi inside the disk.
#[inline]
pub fn square_to_uniform_disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        INV_PI
    } else {
        0.0
    }
}

/// Shirley-Chiu concentric map: less distortion than the polar map.
#[inline]
pub fn square_to_concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    // Both wedges need sin and cos of an angle in [-pi/4, pi/4] only: the second wedge's
    // angle pi/2 - phi swaps them. Written with selects rather than branches, so that a loop
    // over eight samples (`integrator::lanes`) runs it in vector lanes.
    let wide = o.x.abs() > o.y.abs();
    let (num, den) = if wide { (o.y, o.x) } else { (o.x, o.y) };
    let (s, c) = sin_cos_quarter(PI / 4.0 * (num / den));
    let r = if wide {
        Vec2::new(c, s)
    } else {
        Vec2::new(s, c)
    };
    if o.x == 0.0 && o.y == 0.0 {
        Vec2::ZERO
    } else {
        den * r
    }
}

/// sin and cos of 2 pi u for u in [0, 1]: the nearest quarter turn q, whose sin and cos are
/// exact, and `sin_cos_quarter` of the rest (exact in f32: u and q / 4 are within a factor
/// of two). No libm call: a sphere light's area sample runs in the lane kernel's loops, and
/// libm's sincosf was 4 % of the Veach scene's render time.
#[inline(always)]
fn sin_cos_turns(u: f32) -> (f32, f32) {
    let q = (4.0 * u).round_ties_even();
    let (s, c) = sin_cos_quarter(2.0 * PI * (u - 0.25 * q));
    let quarter = small_int_bits(q) & 3;
    let (s, c) = if quarter & 1 == 1 { (c, -s) } else { (s, c) };
    if quarter & 2 == 2 {
        (-s, -c)
    } else {
        (s, c)
    }
}

/// sin and cos of |x| <= pi/4 by Cephes' minimax polynomials (a few ulp): no range reduction
/// and no libm call, which cost 3 % of a diffuse scene's render time.
#[inline]
fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let s = x + x * z * (-1.666_665_5e-1 + z * (8.332_161e-3 + z * -1.951_529_6e-4));
    let c = 1.0 - 0.5 * z + z * z * (4.166_664_6e-2 + z * (-1.388_731_6e-3 + z * 2.443_315_7e-5));
    (s, c)
}

/// 1D tent on [-1, 1] by inverting its CDF.
#[inline]
fn tent_1d(u: f32) -> f32 {
    let x = 2.0 * u;
    if x < 1.0 {
        x.sqrt() - 1.0
    } else {
        1.0 - (2.0 - x).sqrt()
    }
}

/// Separable tent on [-1, 1]^2.
#[inline]
pub fn square_to_tent(u: Vec2) -> Vec2 {
    Vec2::new(tent_1d(u.x), tent_1d(u.y))
}

/// Density of `square_to_tent` on [-1, 1]^2.
#[inline]
pub fn square_to_tent_pdf(p: Vec2) -> f32 {
    (1.0 - p.x.abs()).max(0.0) * (1.0 - p.y.abs()).max(0.0)
}

/// Uniform barycentrics (b1, b2) on a triangle by the square-root map.
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let s = u.x.sqrt();
    Vec2::new(1.0 - s, u.y * s)
}

/// Density on the reference triangle (0,0),(1,0),(0,1), whose area is 1/2.
#[inline]
pub fn square_to_uniform_triangle_pdf(b: Vec2) -> f32 {
    if b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 {
        2.0
    } else {
        0.0
    }
}

/// A uniform direction on the unit sphere.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u.y);
    Vec3::new(r * c, r * s, z)
}

/// Density of `square_to_uniform_sphere`: 1 / (4 pi).
#[inline]
pub fn square_to_uniform_sphere_pdf(_v: Vec3) -> f32 {
    0.25 * INV_PI
}

/// A uniform direction on the upper hemisphere.
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u.y);
    Vec3::new(r * c, r * s, z)
}

/// Positive on the horizon too, as Nori's: the sampler returns z = 0 at u.x = 0.
#[inline]
pub fn square_to_uniform_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z >= 0.0 {
        0.5 * INV_PI
    } else {
        0.0
    }
}

/// A cosine-distributed direction on the upper hemisphere.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of `square_to_cosine_hemisphere`: cos / pi above the horizon.
#[inline]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z > 0.0 {
        v.z * INV_PI
    } else {
        0.0
    }
}

/// Uniform direction in the cone around +z with the given cos of its half-angle.
#[inline]
pub fn square_to_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    square_to_uniform_cone_1m(u, 1.0 - cos_max)
}

/// [`square_to_uniform_cone`] given `1 - cos(theta_max)`, which for a narrow cone is far more
/// precise than cos(theta_max) itself: at 1e-7 sr an f32 cos has one or two distinct values
/// below 1. sin(theta) comes from w = 1 - cos(theta) as sqrt(w (2 - w)), never from 1 - z^2.
#[inline]
pub fn square_to_uniform_cone_1m(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    let w = u.x * one_minus_cos_max;
    let r = (w * (2.0 - w)).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u.y);
    Vec3::new(r * c, r * s, 1.0 - w)
}

/// Density of `square_to_uniform_cone`: 1 / (2 pi (1 - cos_max)) inside the cone.
#[inline]
pub fn square_to_uniform_cone_pdf(v: Vec3, cos_max: f32) -> f32 {
    if v.z >= cos_max {
        1.0 / (2.0 * PI * (1.0 - cos_max))
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sin and cos of 2 pi u over the whole turn, against f64's, and exact at the quarters.
    #[test]
    fn turn_sin_cos_within_a_few_ulp() {
        let n = 100_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let u = (i as f64 / n as f64) as f32;
            let (s, c) = sin_cos_turns(u);
            let x = std::f64::consts::TAU * u as f64;
            worst = worst
                .max((s as f64 - x.sin()).abs())
                .max((c as f64 - x.cos()).abs());
        }
        assert!(worst < 4e-7, "worst error {worst:e}");
        for (u, want) in [(0.0, (0.0, 1.0)), (0.25, (1.0, 0.0)), (0.5, (0.0, -1.0))] {
            let (s, c) = sin_cos_turns(u);
            assert_eq!((s.abs(), c), (want.0, want.1), "u={u}");
        }
        assert_eq!(sin_cos_turns(0.75), (-1.0, 0.0));
    }

    /// The concentric map on the square's axes (where one of the wedge ratio's terms is 0)
    /// and at its centre, by hand: the axes map onto the disk's axes, the centre to 0.
    #[test]
    fn concentric_disk_on_the_axes() {
        let d = |x: f32, y: f32| square_to_concentric_disk(Vec2::new(x, y));
        assert_eq!(d(0.5, 0.5), Vec2::ZERO);
        for (t, r) in [(0.9f32, 0.8f32), (0.1, -0.8), (1.0, 1.0)] {
            let on_x = d(t, 0.5);
            let on_y = d(0.5, t);
            assert!((on_x - Vec2::new(r, 0.0)).length() < 1e-6, "{on_x}");
            assert!((on_y - Vec2::new(0.0, r)).length() < 1e-6, "{on_y}");
        }
    }

    /// The hemisphere samplers' edge u.x = 0: the uniform one returns the horizon, z = 0, a
    /// direction its pdf must not call impossible.
    #[test]
    fn uniform_hemisphere_pdf_covers_the_horizon_it_samples() {
        for uy in [0.0f32, 0.3, 0.9] {
            let v = square_to_uniform_hemisphere(Vec2::new(0.0, uy));
            assert_eq!(v.z, 0.0);
            assert_eq!(square_to_uniform_hemisphere_pdf(v), 0.5 * INV_PI);
        }
        assert_eq!(
            square_to_uniform_hemisphere_pdf(Vec3::new(1.0, 0.0, -1e-7)),
            0.0
        );
    }

    #[test]
    fn quarter_sin_cos_within_a_few_ulp() {
        let n = 100_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = (i as f64 / n as f64 * 2.0 - 1.0) * std::f64::consts::FRAC_PI_4;
            let (s, c) = sin_cos_quarter(x as f32);
            let xs = x as f32 as f64;
            worst = worst
                .max((s as f64 - xs.sin()).abs())
                .max((c as f64 - xs.cos()).abs());
        }
        // f32's ulp at 0.7-1.0 is 6e-8.
        assert!(worst < 2.5e-7, "worst error {worst:e}");
        assert_eq!(sin_cos_quarter(0.0), (0.0, 1.0));
    }
    use crate::rng::Rng;

    /// Monte Carlo estimate of the integral of pdf over [-1,1]^2 (or the sphere), a check that
    /// the density is normalised. 400k samples: standard error well below the 1% tolerance.
    fn integral_2d(pdf: impl Fn(Vec2) -> f32) -> f64 {
        let mut rng = Rng::new(3, 0);
        let n = 400_000;
        let mut s = 0.0f64;
        for _ in 0..n {
            let p = rng.next_2d() * 2.0 - Vec2::ONE;
            s += pdf(p) as f64 * 4.0;
        }
        s / n as f64
    }

    #[test]
    fn planar_pdfs_integrate_to_one() {
        assert!((integral_2d(square_to_uniform_disk_pdf) - 1.0).abs() < 0.01);
        assert!((integral_2d(square_to_tent_pdf) - 1.0).abs() < 0.01);
        assert!((integral_2d(square_to_uniform_triangle_pdf) - 1.0).abs() < 0.01);
    }

    #[test]
    fn samples_land_in_support() {
        let mut rng = Rng::new(5, 1);
        for _ in 0..10_000 {
            let u = rng.next_2d();
            assert!(square_to_uniform_disk(u).length() <= 1.0 + 1e-6);
            assert!(square_to_concentric_disk(u).length() <= 1.0 + 1e-6);
            let b = square_to_uniform_triangle(u);
            assert!(square_to_uniform_triangle_pdf(b) > 0.0 || b.x + b.y <= 1.0 + 1e-6);
            assert!((square_to_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            assert!(square_to_uniform_hemisphere(u).z >= 0.0);
            let c = square_to_cosine_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
            assert!(square_to_uniform_cone(u, 0.9).z >= 0.9 - 1e-6);
            let t = square_to_tent(u);
            assert!(t.x.abs() <= 1.0 && t.y.abs() <= 1.0);
        }
    }

    #[test]
    fn spherical_pdfs_integrate_to_one() {
        let mut rng = Rng::new(9, 2);
        let n = 400_000;
        let (mut h, mut c, mut k) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            let v = square_to_uniform_sphere(rng.next_2d());
            let inv = 4.0 * std::f64::consts::PI;
            h += square_to_uniform_hemisphere_pdf(v) as f64 * inv;
            c += square_to_cosine_hemisphere_pdf(v) as f64 * inv;
            k += square_to_uniform_cone_pdf(v, 0.5) as f64 * inv;
        }
        for s in [h, c, k] {
            assert!((s / n as f64 - 1.0).abs() < 0.02, "{}", s / n as f64);
        }
    }
}
