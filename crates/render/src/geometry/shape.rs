//! World-space shapes: triangle meshes and exact spheres.

use super::SurfacePoint;
use crate::math::{max_abs, PI};
use glam::{Vec2, Vec3};

/// A triangle mesh in world space.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals, one per vertex (None: flat shading).
    pub normals: Option<Vec<Vec3>>,
    /// Triangles as three vertex indices.
    pub indices: Vec<[u32; 3]>,
    /// Per triangle: unit face normal (by winding) and, per component, the largest vertex
    /// magnitude: the error scale of points on it. Precomputed because every hit and light
    /// sample needs them.
    face: Vec<(Vec3, Vec3)>,
}

/// An exact sphere.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
    /// Whether the normals point inwards.
    pub flip_normals: bool,
}

/// A shape's geometry.
#[derive(Clone, Debug)]
pub enum ShapeKind {
    /// A triangle mesh.
    Mesh(Mesh),
    /// A sphere.
    Sphere(Sphere),
}

/// A shape of the scene: geometry, material and its emitter.
#[derive(Clone, Debug)]
pub struct Shape {
    /// The geometry.
    pub kind: ShapeKind,
    /// Index of its material in the scene.
    pub material: u32,
    /// Index of its emitter in the scene, if it emits.
    pub emitter: Option<u32>,
}

impl Shape {
    /// Surface area; a mesh's zero-area triangles add nothing.
    pub fn area(&self) -> f64 {
        match &self.kind {
            ShapeKind::Mesh(m) => (0..m.indices.len())
                .map(|t| m.triangle_area(t) as f64)
                .sum(),
            ShapeKind::Sphere(s) => s.area() as f64,
        }
    }
}

impl Mesh {
    /// A mesh with its per-triangle face normals and error scales; vertex normals that agree
    /// with every face normal are dropped (flat shading is then exact and cheaper).
    pub fn new(positions: Vec<Vec3>, normals: Option<Vec<Vec3>>, indices: Vec<[u32; 3]>) -> Self {
        let face = indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let n = (b - a).cross(c - a).normalize_or_zero();
                (n, a.abs().max(b.abs()).max(c.abs()))
            })
            .collect::<Vec<_>>();
        let normals = normals.filter(|ns| !all_flat(ns, &indices, &face));
        Mesh {
            positions,
            normals,
            indices,
            face,
        }
    }

    /// A triangle's unit face normal and error scale (see `face`).
    #[inline(always)]
    pub fn face(&self, tri: usize) -> (Vec3, Vec3) {
        self.face[tri]
    }

    /// The three vertex positions of triangle `tri`.
    #[inline]
    pub fn vertices(&self, tri: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// The area of triangle `tri`.
    pub fn triangle_area(&self, tri: usize) -> f32 {
        let [a, b, c] = self.vertices(tri);
        0.5 * (b - a).cross(c - a).length()
    }

    /// The surface point at barycentrics (b1, b2) of a triangle. The position is recomputed
    /// from the vertices, which keeps its rounding error proportional to the vertices' size
    /// rather than to the ray's length.
    #[inline(always)]
    pub fn surface_point(&self, tri: usize, b: Vec2, shape: u32) -> SurfacePoint {
        let (v, normals) = (self.vertices(tri), self.vertex_normals(tri));
        Mesh::point_from(v, self.face[tri], normals, b, shape, tri as u32)
    }

    /// `surface_point` from the triangle's data already gathered: vertices, `face(tri)` and
    /// `vertex_normals(tri)`. Degenerate (zero or opposing) vertex normals fall back to the
    /// face normal; the geometric normal is turned to the shading normal's side.
    #[inline(always)]
    pub fn point_from(
        [a, v1, v2]: [Vec3; 3],
        (ng, err_scale): (Vec3, Vec3),
        normals: Option<[Vec3; 3]>,
        b: Vec2,
        shape: u32,
        prim: u32,
    ) -> SurfacePoint {
        let b0 = 1.0 - b.x - b.y;
        let p = a * b0 + v1 * b.x + v2 * b.y;
        let ns = normals.and_then(|[n0, n1, n2]| (n0 * b0 + n1 * b.x + n2 * b.y).try_normalize());
        let (ng, ns) = match ns {
            Some(ns) if ng.dot(ns) < 0.0 => (-ng, ns),
            Some(ns) => (ng, ns),
            None => (ng, ng),
        };
        SurfacePoint {
            p,
            ng,
            ns,
            shape,
            prim,
            err_scale,
        }
    }

    /// The vertex normals of a triangle, if the mesh has them.
    #[inline(always)]
    pub fn vertex_normals(&self, tri: usize) -> Option<[Vec3; 3]> {
        let normals = self.normals.as_ref()?;
        Some(self.indices[tri].map(|i| normals[i as usize]))
    }

    /// The largest vertex coordinate magnitude: the scale of the mesh's rounding errors.
    pub fn bounds_scale(&self) -> f32 {
        self.positions
            .iter()
            .map(|p| max_abs(*p))
            .fold(0.0, f32::max)
    }
}

impl Sphere {
    /// Surface area.
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// Surface point from a point near the surface: projected back onto the sphere, which
    /// removes the error that grows with the distance the ray travelled.
    #[inline]
    pub fn surface_point(&self, near: Vec3, shape: u32) -> SurfacePoint {
        self.surface_point_along((near - self.center).normalize_or(Vec3::Z), shape)
    }

    /// The surface point in unit direction `n` from the centre. For a direction drawn on the
    /// unit sphere (area sampling) this skips `surface_point`'s square root and division, and
    /// its rounding: centre + n r - centre keeps only the digits of n r that the centre's
    /// magnitude leaves, which turned the normal of a 0.01-radius light 100 units out by up
    /// to 5e-4 rad (`sphere_point_along_a_direction_keeps_it`).
    #[inline]
    pub fn surface_point_along(&self, n: Vec3, shape: u32) -> SurfacePoint {
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

/// Nearest root of |o + t d - c| = r inside (tmin, tmax). The discriminant is computed from
/// the ray's perpendicular distance to the centre (Ray Tracing Gems ch. 7), which stays
/// accurate when the sphere is small and far away.
#[inline(always)]
pub fn intersect_sphere(o: Vec3, d: Vec3, tmin: f32, tmax: f32, c: Vec3, r: f32) -> Option<f32> {
    let (disc, q, t0, t1) = sphere_roots(o, d, c, r);
    if disc < 0.0 || q == 0.0 {
        None
    } else if t0 > tmin && t0 < tmax {
        Some(t0)
    } else if t1 > tmin && t1 < tmax {
        Some(t1)
    } else {
        None
    }
}

/// `intersect_sphere`'s arithmetic: the discriminant, q and the two roots in order, which are
/// roots only where the discriminant is >= 0 and q is not 0. Without branches, so that
/// `sphere8` runs it in vector lanes with the same answers.
#[inline(always)]
pub(super) fn sphere_roots(o: Vec3, d: Vec3, c: Vec3, r: f32) -> (f32, f32, f32, f32) {
    let f = o - c;
    let a = d.dot(d);
    let b = f.dot(d);
    let cc = f.dot(f) - r * r;
    let l = f - (b / a) * d;
    let disc = a * (r * r - l.dot(l));
    let q = -(b + disc.sqrt().copysign(b));
    let (t0, t1) = (cc / q, q / a);
    let swap = t0 > t1;
    (
        disc,
        q,
        if swap { t1 } else { t0 },
        if swap { t0 } else { t1 },
    )
}

/// Whether every triangle's vertex normals are its face normal (to 1e-5 per component, f32
/// rounding of a transformed normal): flat shapes such as Mitsuba's rectangle and cube, or an
/// OBJ exported with flat normals. Such normals shade as the face normal does, so `Mesh::new`
/// drops them and every hit is spared an interpolation and a normalisation.
fn all_flat(normals: &[Vec3], indices: &[[u32; 3]], face: &[(Vec3, Vec3)]) -> bool {
    indices.iter().zip(face).all(|(t, (ng, _))| {
        t.iter().all(|&i| {
            let n = normals[i as usize].normalize_or_zero();
            (n - *ng).abs().max_element() < 1e-5
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point drawn in direction n on a small light far out keeps n as its normal exactly
    /// (reprojecting centre + n r, `surface_point`, turns it; the test prints by how much).
    #[test]
    fn sphere_point_along_a_direction_keeps_it() {
        let mut worst_reprojected = 0.0f32;
        for flip in [false, true] {
            let s = Sphere {
                center: Vec3::new(100.0, -40.0, 7.0),
                radius: 0.01,
                flip_normals: flip,
            };
            for k in 0..64 {
                let (a, z) = (k as f32 * 0.37, (k as f32 / 32.0) - 1.0);
                let r = (1.0 - z * z).sqrt();
                let n = Vec3::new(r * a.cos(), r * a.sin(), z);
                let sp = s.surface_point_along(n, 3);
                let out = if flip { -n } else { n };
                assert_eq!((sp.ng, sp.ns, sp.shape), (out, out, 3));
                assert_eq!(sp.p, s.center + n * s.radius);
                let old = s.surface_point(s.center + n * s.radius, 3);
                worst_reprojected = worst_reprojected.max(old.ng.angle_between(out));
            }
        }
        eprintln!("reprojected normals off by up to {worst_reprojected:.2e} rad");
    }

    /// Vertex normals equal to the face normals are dropped; any that bend the shading (a
    /// smooth mesh, normals flipped against the winding, one tilted vertex) are kept.
    #[test]
    fn flat_vertex_normals_are_dropped_and_others_kept() {
        let p = vec![Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 3.0];
        let with = |n: [Vec3; 3]| Mesh::new(p.clone(), Some(n.to_vec()), vec![[0, 1, 2]]);
        assert!(with([Vec3::Z * 4.0; 3]).normals.is_none());
        assert!(with([-Vec3::Z; 3]).normals.is_some());
        let tilted = Vec3::new(1e-3, 0.0, 1.0);
        assert!(with([Vec3::Z, Vec3::Z, tilted]).normals.is_some());
        // A rectangle through a rotation keeps flat normals flat.
        let r = glam::Quat::from_rotation_x(-0.9);
        let q = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let m = Mesh::new(
            q.map(|v| r * v).to_vec(),
            Some(vec![r * Vec3::Z; 3]),
            vec![[0, 1, 2]],
        );
        assert!(m.normals.is_none());
        assert!((m.surface_point(0, Vec2::new(0.2, 0.3), 0).ns - r * Vec3::Z).length() < 1e-6);
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
