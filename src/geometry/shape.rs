//! World-space shapes: triangle meshes and exact spheres.

use super::SurfacePoint;
use crate::math::{max_abs, PI};
use glam::{Vec2, Vec3, Vec3A, Vec3Swizzles};

#[derive(Clone, Debug)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub indices: Vec<[u32; 3]>,
    /// Per triangle: unit face normal (by winding) and, per component, the largest vertex
    /// magnitude: the error scale of points on it. Precomputed because every hit and light
    /// sample needs them.
    face: Vec<(Vec3, Vec3)>,
}

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub flip_normals: bool,
}

#[derive(Clone, Debug)]
pub enum ShapeKind {
    Mesh(Mesh),
    Sphere(Sphere),
}

#[derive(Clone, Debug)]
pub struct Shape {
    pub kind: ShapeKind,
    pub material: u32,
    pub emitter: Option<u32>,
}

impl Mesh {
    pub fn new(positions: Vec<Vec3>, normals: Option<Vec<Vec3>>, indices: Vec<[u32; 3]>) -> Self {
        let face = indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let n = (b - a).cross(c - a).normalize_or_zero();
                (n, a.abs().max(b.abs()).max(c.abs()))
            })
            .collect();
        Mesh {
            positions,
            normals,
            indices,
            face,
        }
    }

    #[inline]
    pub fn vertices(&self, tri: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    pub fn triangle_area(&self, tri: usize) -> f32 {
        let [a, b, c] = self.vertices(tri);
        0.5 * (b - a).cross(c - a).length()
    }

    /// The surface point at barycentrics (b1, b2) of a triangle. The position is recomputed
    /// from the vertices, which keeps its rounding error proportional to the vertices' size
    /// rather than to the ray's length.
    #[inline]
    pub fn surface_point(&self, tri: usize, b: Vec2, shape: u32) -> SurfacePoint {
        let [a, v1, v2] = self.vertices(tri);
        let b0 = 1.0 - b.x - b.y;
        let p = a * b0 + v1 * b.x + v2 * b.y;
        let (ng, err_scale) = self.face[tri];
        let mut ns = ng;
        let mut ngo = ng;
        if let Some(normals) = &self.normals {
            let [i0, i1, i2] = self.indices[tri];
            let n =
                normals[i0 as usize] * b0 + normals[i1 as usize] * b.x + normals[i2 as usize] * b.y;
            // Degenerate (zero or opposing) vertex normals fall back to the face normal.
            if let Some(n) = n.try_normalize() {
                ns = n;
                if ng.dot(ns) < 0.0 {
                    ngo = -ng;
                }
            }
        }
        SurfacePoint {
            p,
            ng: ngo,
            ns,
            shape,
            prim: tri as u32,
            err_scale,
        }
    }

    pub fn bounds_scale(&self) -> f32 {
        self.positions
            .iter()
            .map(|p| max_abs(*p))
            .fold(0.0, f32::max)
    }
}

impl Sphere {
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// Surface point from a point near the surface: projected back onto the sphere, which
    /// removes the error that grows with the distance the ray travelled.
    #[inline]
    pub fn surface_point(&self, near: Vec3, shape: u32) -> SurfacePoint {
        let n = (near - self.center).normalize_or(Vec3::Z);
        let p = self.center + n * self.radius;
        let n = if self.flip_normals { -n } else { n };
        SurfacePoint {
            p,
            ng: n,
            ns: n,
            shape,
            prim: 0,
            err_scale: self.center.abs() + Vec3::splat(self.radius),
        }
    }
}

/// Per-ray setup of the watertight ray-triangle test (Woop, Benthin and Wald 2013): the ray
/// is mapped to +z by a permutation and shear, so neighbouring triangles evaluate their
/// shared edge with identical arithmetic and no ray slips between them. (The paper also swaps
/// x and y when d.z < 0 to keep the determinant's sign for back-face culling; without culling
/// that swap changes neither t nor the barycentrics.)
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    o: Vec3A,
    /// (-d_x / d_z, -d_y / d_z, 1 / d_z) in the permuted frame.
    shear: Vec3A,
    /// The direction, for the f64 re-evaluation of hits too close for the f32 bound.
    d: Vec3A,
    /// Dominant axis of the direction: which cyclic permutation maps it to z.
    kz: u8,
}

impl WatertightRay {
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let a = d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let dp = permute(d.into(), kz);
        WatertightRay {
            o: o.into(),
            shear: Vec3A::new(-dp.x / dp.z, -dp.y / dp.z, 1.0 / dp.z),
            d: d.into(),
            kz,
        }
    }

    /// (t, b1, b2) for a hit strictly inside (tmin, tmax).
    #[inline(always)]
    pub fn intersect(
        &self,
        v0: Vec3A,
        v1: Vec3A,
        v2: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32, f32)> {
        let a = permute(v0 - self.o, self.kz);
        let b = permute(v1 - self.o, self.kz);
        let c = permute(v2 - self.o, self.kz);
        let (sx, sy) = (self.shear.x, self.shear.y);
        let (ax, ay) = (a.x + sx * a.z, a.y + sy * a.z);
        let (bx, by) = (b.x + sx * b.z, b.y + sy * b.z);
        let (cx, cy) = (c.x + sx * c.z, c.y + sy * c.z);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Exactly on an edge in f32: decide in f64 so both neighbours agree.
            let f =
                |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            u = f(cx, by, cy, bx);
            v = f(ax, cy, ay, cx);
            w = f(bx, ay, by, ax);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let sz = self.shear.z;
        let (az, bz, cz) = (sz * a.z, sz * b.z, sz * c.z);
        let t_scaled = u * az + v * bz + w * cz;
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        // pbrt-v4's conservative bound on the rounding error of t.
        let gamma = |n: f32| n * f32::EPSILON * 0.5 / (1.0 - n * f32::EPSILON * 0.5);
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = gamma(3.0) * max_z;
        let delta_x = gamma(5.0) * (max_x + max_z);
        let delta_y = gamma(5.0) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t =
            3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv.abs();
        // Within delta_t of 0 the hit may be the ray's own surface (this is what makes small
        // spawn offsets safe); within delta_t of tmin or tmax f32 cannot tell on which side
        // of the interval it lies (a shadow ray ending 1e-7 short of a light whose vertices
        // are 1e5 away "hit" that light at t = 0.99). The bound grows with the vertices'
        // distance from the origin, not with the distance being decided, so both happen at
        // geometry 1e-6 of the scene apart. f64 shrinks the bound 5e8-fold and decides; the
        // inside test stays f32's, so shared edges remain watertight.
        if t <= delta_t || (t - tmin).abs() <= delta_t || (t - tmax).abs() <= delta_t {
            let t = super::refine::distance_f64(self.o, self.d, self.kz, [v0, v1, v2])?;
            return (t > tmin as f64 && t < tmax as f64).then_some((t as f32, v * inv, w * inv));
        }
        if !(t > tmin && t < tmax) {
            return None;
        }
        Some((t, v * inv, w * inv))
    }
}

/// The cyclic permutation that moves axis `kz` to z.
#[inline(always)]
fn permute(v: Vec3A, kz: u8) -> Vec3A {
    match kz {
        0 => v.yzx(),
        1 => v.zxy(),
        _ => v,
    }
}

/// Convenience form of the watertight test for a single triangle.
#[inline]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    tmin: f32,
    tmax: f32,
    v: [Vec3; 3],
) -> Option<(f32, f32, f32)> {
    WatertightRay::new(o, d).intersect(v[0].into(), v[1].into(), v[2].into(), tmin, tmax)
}

/// Nearest root of |o + t d - c| = r inside (tmin, tmax). The discriminant is computed from
/// the ray's perpendicular distance to the centre (Ray Tracing Gems ch. 7), which stays
/// accurate when the sphere is small and far away.
#[inline(always)]
pub fn intersect_sphere(o: Vec3, d: Vec3, tmin: f32, tmax: f32, c: Vec3, r: f32) -> Option<f32> {
    let f = o - c;
    let a = d.dot(d);
    let b = f.dot(d);
    let cc = f.dot(f) - r * r;
    let l = f - (b / a) * d;
    let disc = a * (r * r - l.dot(l));
    if disc < 0.0 {
        return None;
    }
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return None;
    }
    let (mut t0, mut t1) = (cc / q, q / a);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > tmin && t0 < tmax {
        Some(t0)
    } else if t1 > tmin && t1 < tmax {
        Some(t1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_hit_and_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let o = Vec3::new(0.25, 0.5, 1.0);
        let (t, u, v) = intersect_triangle(o, -Vec3::Z, 0.0, 10.0, tri).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6);
        assert!(intersect_triangle(o, Vec3::Z, 0.0, 10.0, tri).is_none());
        assert!(intersect_triangle(o, -Vec3::Z, 0.0, 0.5, tri).is_none());
        let outside = Vec3::new(0.8, 0.8, 1.0);
        assert!(intersect_triangle(outside, -Vec3::Z, 0.0, 10.0, tri).is_none());
        // Seen from below, with a reversed winding, and along other axes: still hit.
        let (t, ..) =
            intersect_triangle(Vec3::new(0.25, 0.5, -2.0), Vec3::Z, 0.0, 10.0, tri).unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        assert!(intersect_triangle(o, -Vec3::Z, 0.0, 10.0, [tri[0], tri[2], tri[1]]).is_some());
        let side = Vec3::new(-1.0, 0.2, 0.0);
        assert!(intersect_triangle(
            Vec3::new(3.0, 0.05, 0.3),
            side.normalize(),
            0.0,
            10.0,
            [Vec3::ZERO, Vec3::Y, Vec3::Z]
        )
        .is_some());
    }

    /// The defect that motivated the watertight test: rays aimed at the shared diagonal of
    /// two huge coplanar triangles must hit one of them, every time.
    #[test]
    fn no_ray_slips_through_a_shared_edge() {
        let s = 1e3;
        let p = [
            Vec3::new(-s, -s, 0.0),
            Vec3::new(s, -s, 0.0),
            Vec3::new(s, s, 0.0),
            Vec3::new(-s, s, 0.0),
        ];
        let tris = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
        let eye = Vec3::new(3.0, 0.0, 1.0);
        let mut rng = crate::rng::Rng::new(4, 4);
        for _ in 0..100_000 {
            let x = (rng.next_f32() - 0.5) * 1e-3;
            let target = Vec3::new(x, x + (rng.next_f32() - 0.5) * 1e-6, 0.0);
            let d = (target - eye).normalize();
            let hits = tris
                .iter()
                .filter(|t| intersect_triangle(eye, d, 0.0, f32::INFINITY, **t).is_some())
                .count();
            assert!(
                hits >= 1,
                "ray towards {target} slipped through the shared edge"
            );
        }
    }

    #[test]
    fn sphere_hits_front_then_back() {
        let c = Vec3::new(0.0, 0.0, 5.0);
        let t = intersect_sphere(Vec3::ZERO, Vec3::Z, 0.0, 100.0, c, 1.0).unwrap();
        assert!((t - 4.0).abs() < 1e-5);
        let t = intersect_sphere(c, Vec3::Z, 0.0, 100.0, c, 1.0).unwrap();
        assert!((t - 1.0).abs() < 1e-5);
        assert!(intersect_sphere(Vec3::ZERO, Vec3::X, 0.0, 100.0, c, 1.0).is_none());
        // Tiny sphere far away: the robust discriminant still finds it.
        let far = Vec3::new(0.0, 0.0, 1e4);
        let t = intersect_sphere(Vec3::ZERO, Vec3::Z, 0.0, 1e6, far, 1e-2).unwrap();
        assert!((t - (1e4 - 1e-2)).abs() < 1e-2);
    }

    #[test]
    fn interpolated_normal_uses_all_three_vertices() {
        let m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            Some(vec![Vec3::Z, Vec3::new(1.0, 0.0, 1.0).normalize(), Vec3::Z]),
            vec![[0, 1, 2]],
        );
        let a = m.surface_point(0, Vec2::new(0.0, 0.0), 0).ns;
        let b = m.surface_point(0, Vec2::new(0.5, 0.0), 0).ns;
        assert!((a - Vec3::Z).length() < 1e-6);
        assert!(b.x > 0.1, "vertex 1's normal must contribute: {b}");
    }
}
