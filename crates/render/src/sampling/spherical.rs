//! Uniform sampling of the solid angle a triangle subtends (Arvo 1995, in the form pbrt-v4
//! uses), so a light sample's density is 1 / Omega instead of d^2 / (A cos).

use glam::{DVec3, Vec2, Vec3};

/// Below this solid angle the spherical-triangle formulas lose precision, above it the
/// triangle nearly surrounds the point: pbrt-v4 samples by area in both cases.
pub const MIN_SOLID_ANGLE: f32 = 3e-4;
/// Above this solid angle (of 4 pi = 12.57 sr) the triangle nearly surrounds the point and
/// is sampled by area instead.
pub const MAX_SOLID_ANGLE: f32 = 6.22;

/// The projected triangle: unit vertex directions, arc normals and corner angles.
///
/// Computed in f64. Two defects showed the need: a triangle seen nearly edge-on (a sliver
/// along the horizon of a point 1e-3 from a light's edge) has corner angles within 1e-6 of 0
/// and pi, and in f32 about 1.5 % of its samples landed outside it (`directlab chi2
/// emitter/quad-solid-angle-close`); and an arc between two nearly opposite directions (a
/// receiver under the edge of a light 1e-6 away) has its plane normal computed from
/// cancelling products, which in f32 tilted the arc by degrees (`directlab extreme`).
/// The f32 vertices and point are exact in f64.
struct SphericalTriangle {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    alpha: f64,
    area: f64,
}

#[inline]
fn angle_between(u: DVec3, v: DVec3) -> f64 {
    // Numerically better than acos(dot) near 0 and pi.
    if u.dot(v) < 0.0 {
        std::f64::consts::PI - 2.0 * ((u + v).length() * 0.5).clamp(-1.0, 1.0).asin()
    } else {
        2.0 * ((v - u).length() * 0.5).clamp(-1.0, 1.0).asin()
    }
}

impl SphericalTriangle {
    #[inline]
    fn new(p: Vec3, v: [Vec3; 3]) -> Option<Self> {
        let p = p.as_dvec3();
        let a = (v[0].as_dvec3() - p).try_normalize()?;
        let b = (v[1].as_dvec3() - p).try_normalize()?;
        let c = (v[2].as_dvec3() - p).try_normalize()?;
        let n_ab = a.cross(b).try_normalize()?;
        let n_bc = b.cross(c).try_normalize()?;
        let n_ca = c.cross(a).try_normalize()?;
        let alpha = angle_between(n_ab, -n_ca);
        let beta = angle_between(n_bc, -n_ab);
        let gamma = angle_between(n_ca, -n_bc);
        let area = alpha + beta + gamma - std::f64::consts::PI;
        if !(area > 0.0) {
            return None;
        }
        Some(SphericalTriangle {
            a,
            b,
            c,
            alpha,
            area,
        })
    }
}

/// Solid angle of the triangle seen from `p` (spherical excess), or 0 if degenerate.
#[inline]
pub fn spherical_triangle_area(p: Vec3, v: [Vec3; 3]) -> f32 {
    SphericalTriangle::new(p, v).map_or(0.0, |t| t.area as f32)
}

/// Whether the spherical-triangle sampler is used for a triangle of this solid angle.
#[inline]
pub fn use_solid_angle(area: f32) -> bool {
    (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE).contains(&area)
}

/// A unit direction uniformly distributed in the triangle's solid angle, with its density
/// 1 / Omega; None when the triangle is outside the usable range (caller samples by area).
#[inline]
pub fn sample_spherical_triangle(p: Vec3, v: [Vec3; 3], u: Vec2) -> Option<(Vec3, f32)> {
    let t = SphericalTriangle::new(p, v)?;
    let area = t.area as f32;
    if !use_solid_angle(area) {
        return None;
    }
    let (a, b, c, alpha) = (t.a, t.b, t.c, t.alpha);
    let (ux, uy) = (u.x as f64, u.y as f64);
    // Choose the sub-triangle area, then the point c' on arc ac that produces it.
    // phi = (A' + pi) - alpha, with A' the sub-triangle's area.
    let (sin_phi, cos_phi) = (std::f64::consts::PI + ux * t.area - alpha).sin_cos();
    let (sin_alpha, cos_alpha) = alpha.sin_cos();
    let cos_c = a.dot(b);
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * cos_c;
    let denom = (k2 * sin_phi + k1 * cos_phi) * sin_alpha;
    let cos_bp = if denom != 0.0 {
        ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / denom).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let sin_bp = (1.0 - cos_bp * cos_bp).max(0.0).sqrt();
    let c_perp = (c - a * c.dot(a)).try_normalize()?;
    let cp = a * cos_bp + c_perp * sin_bp;
    // Then a point uniformly in solid angle on the arc from b to c'.
    let cos_theta = 1.0 - uy * (1.0 - cp.dot(b));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let cp_perp = (cp - b * cp.dot(b)).try_normalize().unwrap_or(DVec3::ZERO);
    let w = (b * cos_theta + cp_perp * sin_theta).try_normalize()?;
    Some((w.as_vec3(), 1.0 / area))
}

/// Barycentrics (b1, b2) where the ray p + t w meets the triangle's plane, clamped into the
/// triangle (a direction from the sampler lies inside up to rounding).
#[inline]
pub fn ray_plane_barycentrics(p: Vec3, w: Vec3, v: [Vec3; 3]) -> Option<Vec2> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let n = e1.cross(e2);
    let denom = n.dot(w);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(v[0] - p) / denom;
    if !(t > 0.0) {
        return None;
    }
    let x = p + w * t - v[0];
    let inv = 1.0 / n.length_squared();
    let b1 = x.cross(e2).dot(n) * inv;
    let b2 = e1.cross(x).dot(n) * inv;
    let b1 = b1.clamp(0.0, 1.0);
    let b2 = b2.clamp(0.0, 1.0 - b1);
    Some(Vec2::new(b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Van Oosterom-Strackee, an independent formula for the same solid angle.
    fn solid_angle_vos(p: Vec3, v: [Vec3; 3]) -> f64 {
        let [a, b, c] = v.map(|x| (x - p).as_dvec3().normalize());
        let num = a.dot(b.cross(c)).abs();
        let den = 1.0 + a.dot(b) + a.dot(c) + b.dot(c);
        2.0 * num.atan2(den)
    }

    fn triangles() -> Vec<(Vec3, [Vec3; 3])> {
        vec![
            (
                Vec3::ZERO,
                [
                    Vec3::new(-1.0, -1.0, 2.0),
                    Vec3::new(1.0, -1.0, 2.0),
                    Vec3::new(0.0, 1.0, 2.0),
                ],
            ),
            (
                Vec3::new(0.3, 0.2, 0.0),
                [
                    Vec3::new(0.0, 0.0, 0.5),
                    Vec3::new(3.0, 0.0, 0.4),
                    Vec3::new(0.0, 2.0, 0.1),
                ],
            ),
            // Under the diagonal of a square light 1e-6 above: the arc between two nearly
            // opposite directions (f32 tilted it by degrees).
            (
                Vec3::ZERO,
                [
                    Vec3::new(-0.5, -0.5, 1e-6),
                    Vec3::new(-0.5, 0.5, 1e-6),
                    Vec3::new(0.5, 0.5, 1e-6),
                ],
            ),
            (
                Vec3::new(5.0, 1.0, -2.0),
                [
                    Vec3::new(0.0, 0.0, 0.0),
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(0.0, 1.0, 0.3),
                ],
            ),
        ]
    }

    #[test]
    fn area_matches_van_oosterom_strackee() {
        for (p, v) in triangles() {
            let a = spherical_triangle_area(p, v) as f64;
            let b = solid_angle_vos(p, v);
            assert!((a - b).abs() < 1e-4 * b.max(1e-3), "{a} vs {b}");
        }
    }

    /// pbrt-v4's check: the mean of 1/pdf over samples is the solid angle, and every sample
    /// direction actually hits the triangle. 100k samples per triangle; 1/pdf is constant, so
    /// the tolerance only covers rounding.
    #[test]
    fn samples_hit_the_triangle_and_invert_to_its_solid_angle() {
        let mut rng = Rng::new(2, 9);
        for (p, v) in triangles() {
            let omega = solid_angle_vos(p, v);
            let mut s = 0.0f64;
            let n = 100_000;
            for _ in 0..n {
                let (w, pdf) = sample_spherical_triangle(p, v, rng.next_2d()).unwrap();
                s += 1.0 / pdf as f64;
                let hit =
                    crate::geometry::watertight::intersect_triangle(p, w, 0.0, f32::INFINITY, v);
                let b = ray_plane_barycentrics(p, w, v).unwrap();
                assert!(
                    hit.is_some() || b.x.min(b.y).min(1.0 - b.x - b.y) < 1e-4,
                    "sample missed the triangle"
                );
            }
            assert!((s / n as f64 - omega).abs() < 1e-3 * omega);
        }
    }

    /// Corner angles near 0 and pi: each branch of `angle_between` is the well-conditioned
    /// one on its side (acos-like forms lose half the digits there).
    #[test]
    fn angle_between_is_accurate_near_zero_and_pi() {
        for eps in [1e-3f64, 1e-6, 1e-9] {
            let u = DVec3::X;
            let near = DVec3::new(eps.cos(), eps.sin(), 0.0);
            let opposite = DVec3::new(-eps.cos(), eps.sin(), 0.0);
            let a = angle_between(u, near);
            let b = angle_between(u, opposite);
            assert!((a - eps).abs() < 1e-15, "{a} vs {eps}");
            let want = std::f64::consts::PI - eps;
            assert!((b - want).abs() < 1e-15, "{b} vs {want}");
        }
    }

    /// The barycentrics of a point q of the triangle are found again from the ray towards it,
    /// for triangles and points in general position; a ray parallel to the plane, one going
    /// away from it, and one from a point in the plane have none.
    #[test]
    fn ray_plane_barycentrics_recover_the_point() {
        let mut rng = Rng::new(8, 3);
        let mut r3 = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
        for _ in 0..1000 {
            let v = [r3(), r3(), r3()];
            let p = r3();
            let (b1, b2) = (0.7 * r3().x.abs() / 2.0, 0.3 * r3().y.abs() / 2.0);
            let q = v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2;
            let cross = (v[1] - v[0]).cross(v[2] - v[0]);
            let (n, w) = (cross.normalize(), (q - p).normalize());
            if n.dot(w).abs() < 0.05 || cross.length() < 0.5 {
                continue;
            }
            let b = ray_plane_barycentrics(p, w, v).unwrap();
            assert!(
                (b - Vec2::new(b1, b2)).abs().max_element() < 2e-4,
                "{b} vs {b1} {b2}"
            );
            assert!(
                ray_plane_barycentrics(p, -w, v).is_none(),
                "behind the point"
            );
        }
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(ray_plane_barycentrics(Vec3::new(0.2, 0.2, 1.0), Vec3::X, v).is_none());
        let in_plane = Vec3::new(0.2, 0.2, 0.0);
        assert!(ray_plane_barycentrics(in_plane, Vec3::new(0.0, 0.6, 0.8), v).is_none());
        // Points just outside are clamped onto the triangle.
        let b = ray_plane_barycentrics(Vec3::new(1.0, 1.0, 1.0), -Vec3::Z, v).unwrap();
        assert_eq!(b.x + b.y, 1.0);
    }

    #[test]
    fn tiny_and_huge_triangles_fall_back() {
        let v = [
            Vec3::new(0.0, 0.0, 1e3),
            Vec3::new(1e-2, 0.0, 1e3),
            Vec3::new(0.0, 1e-2, 1e3),
        ];
        assert!(sample_spherical_triangle(Vec3::ZERO, v, Vec2::splat(0.5)).is_none());
        assert!(!use_solid_angle(spherical_triangle_area(Vec3::ZERO, v)));
        let big = [
            Vec3::new(-1e3, -1e3, 1e-3),
            Vec3::new(1e3, -1e3, 1e-3),
            Vec3::new(0.0, 1e3, 1e-3),
        ];
        assert!(spherical_triangle_area(Vec3::ZERO, big) > 6.22);
        assert!(sample_spherical_triangle(Vec3::ZERO, big, Vec2::splat(0.5)).is_none());
    }
}
