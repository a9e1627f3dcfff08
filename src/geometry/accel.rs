//! One compressed wide BVH (obvhs CwBvh) over every triangle and sphere of the scene.

use super::shape::{intersect_sphere, intersect_triangle, Shape, ShapeKind};
use super::{Hit, Ray};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::{aabb::Aabb, cwbvh::CwBvh, ray::RayHit, BvhBuildParams};
use std::time::Duration;

/// Primitive data stored in BVH leaf order, so the traversal callback indexes it directly.
#[derive(Clone, Copy, Debug)]
enum Prim {
    Tri { v0: Vec3, e1: Vec3, e2: Vec3 },
    Sphere { c: Vec3, r: f32 },
}

pub struct Accel {
    bvh: Option<CwBvh>,
    prims: Vec<Prim>,
    /// (shape index, triangle index within the shape) per primitive, in leaf order.
    refs: Vec<(u32, u32)>,
}

impl Accel {
    /// Builds over all shapes; zero-area triangles are left out since no ray can hit them.
    pub fn build(shapes: &[Shape]) -> Accel {
        let mut prims = Vec::new();
        let mut refs = Vec::new();
        let mut aabbs = Vec::new();
        for (si, shape) in shapes.iter().enumerate() {
            match &shape.kind {
                ShapeKind::Mesh(m) => {
                    for ti in 0..m.indices.len() {
                        let [a, b, c] = m.vertices(ti);
                        let (e1, e2) = (b - a, c - a);
                        if e1.cross(e2).length_squared() == 0.0 {
                            continue;
                        }
                        prims.push(Prim::Tri { v0: a, e1, e2 });
                        refs.push((si as u32, ti as u32));
                        aabbs.push(Aabb::from_points(&[a.into(), b.into(), c.into()]));
                    }
                }
                ShapeKind::Sphere(s) => {
                    prims.push(Prim::Sphere {
                        c: s.center,
                        r: s.radius,
                    });
                    refs.push((si as u32, 0));
                    let r = Vec3A::splat(s.radius);
                    let c: Vec3A = s.center.into();
                    aabbs.push(Aabb::new(c - r, c + r));
                }
            }
        }
        if prims.is_empty() {
            return Accel {
                bvh: None,
                prims,
                refs,
            };
        }
        let mut t = Duration::ZERO;
        let bvh =
            obvhs::cwbvh::builder::build_cwbvh(&aabbs, BvhBuildParams::medium_build(), &mut t);
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        let refs = bvh
            .primitive_indices
            .iter()
            .map(|&i| refs[i as usize])
            .collect();
        Accel {
            bvh: Some(bvh),
            prims,
            refs,
        }
    }

    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    #[inline(always)]
    fn prim_t(&self, i: usize, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
        match self.prims[i] {
            Prim::Tri { v0, e1, e2 } => {
                intersect_triangle(o, d, tmin, tmax, v0, e1, e2).map_or(f32::INFINITY, |h| h.0)
            }
            Prim::Sphere { c, r } => {
                intersect_sphere(o, d, tmin, tmax, c, r).unwrap_or(f32::INFINITY)
            }
        }
    }

    /// Closest hit within the ray's interval.
    pub fn intersect(&self, ray: &Ray, shapes: &[Shape]) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let r = obvhs::ray::Ray::new(ray.o.into(), ray.d.into(), ray.tmin, ray.tmax);
        let mut hit = RayHit::none();
        let (o, d, tmin) = (ray.o, ray.d, ray.tmin);
        let found = bvh.ray_traverse(r, &mut hit, |r, i| self.prim_t(i, o, d, tmin, r.tmax));
        if !found {
            return None;
        }
        let i = hit.primitive_id as usize;
        let (shape, local) = self.refs[i];
        let sp = match (self.prims[i], &shapes[shape as usize].kind) {
            (Prim::Tri { v0, e1, e2 }, ShapeKind::Mesh(m)) => {
                // Recompute barycentrics for the winner only, not inside the traversal.
                let (_, u, v) =
                    intersect_triangle(o, d, f32::NEG_INFINITY, f32::INFINITY, v0, e1, e2)
                        .unwrap_or((hit.t, 1.0 / 3.0, 1.0 / 3.0));
                m.surface_point(local as usize, Vec2::new(u, v), shape)
            }
            (Prim::Sphere { .. }, ShapeKind::Sphere(s)) => s.surface_point(o + d * hit.t, shape),
            _ => unreachable!("primitive and shape kinds always agree"),
        };
        Some(Hit { t: hit.t, sp })
    }

    /// True if anything blocks the ray within its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let r = obvhs::ray::Ray::new(ray.o.into(), ray.d.into(), ray.tmin, ray.tmax);
        let (o, d, tmin, tmax) = (ray.o, ray.d, ray.tmin, ray.tmax);
        !bvh.ray_traverse_miss(r, |_, i| self.prim_t(i, o, d, tmin, tmax))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Mesh, Sphere};
    use crate::rng::Rng;

    fn quad_grid(n: usize, z: f32) -> Shape {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(Vec3::new(i as f32 / n as f32, j as f32 / n as f32, z));
            }
        }
        let w = (n + 1) as u32;
        for j in 0..n as u32 {
            for i in 0..n as u32 {
                let a = j * w + i;
                indices.push([a, a + 1, a + w + 1]);
                indices.push([a, a + w + 1, a + w]);
            }
        }
        Shape {
            kind: ShapeKind::Mesh(Mesh {
                positions,
                normals: None,
                indices,
            }),
            material: 0,
            emitter: None,
        }
    }

    /// The BVH must agree with brute force over every primitive.
    #[test]
    fn bvh_matches_brute_force() {
        let shapes = vec![
            quad_grid(8, 0.0),
            quad_grid(3, 0.5),
            Shape {
                kind: ShapeKind::Sphere(Sphere {
                    center: Vec3::new(0.5, 0.5, 1.0),
                    radius: 0.2,
                    flip_normals: false,
                }),
                material: 0,
                emitter: None,
            },
        ];
        let accel = Accel::build(&shapes);
        let mut rng = Rng::new(1, 1);
        let mut hits = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rng.next_f32() * 1.4 - 0.2, rng.next_f32() * 1.4 - 0.2, 2.0);
            let d = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, -1.0).normalize();
            let ray = Ray::new(o, d);
            let brute = (0..accel.prims.len())
                .map(|i| accel.prim_t(i, o, d, 0.0, f32::INFINITY))
                .fold(f32::INFINITY, f32::min);
            match accel.intersect(&ray, &shapes) {
                Some(h) => {
                    hits += 1;
                    assert!((h.t - brute).abs() <= 1e-5 * brute.max(1.0));
                }
                None => assert!(brute.is_infinite()),
            }
            assert_eq!(accel.occluded(&ray), brute.is_finite());
        }
        assert!(
            hits > 500,
            "only {hits} hits: the test exercises too few hits"
        );
    }

    #[test]
    fn empty_scene_misses() {
        let accel = Accel::build(&[]);
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!(accel.intersect(&ray, &[]).is_none());
        assert!(!accel.occluded(&ray));
    }
}
