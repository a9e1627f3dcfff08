//! The scene's acceleration structure: one 4-wide BVH (see `bvh4`) over every triangle and
//! sphere, with primitive data stored in leaf order.

use super::bvh4::{Bvh4, MAX_LEAF};
use super::shape::{intersect_sphere, Shape, ShapeKind, WatertightRay};
use super::{Hit, Ray};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::builder::build_bvh2, BvhBuildParams};
use std::time::Duration;

/// Primitive data stored in BVH leaf order, so the traversal callback indexes it directly.
#[derive(Clone, Copy, Debug)]
enum Prim {
    Tri { v: [Vec3A; 3] },
    Sphere { c: Vec3, r: f32 },
}

pub struct Accel {
    bvh: Bvh4,
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
                        if (b - a).cross(c - a).length_squared() == 0.0 {
                            continue;
                        }
                        let v = [a, b, c].map(Vec3A::from);
                        prims.push(Prim::Tri { v });
                        refs.push((si as u32, ti as u32));
                        aabbs.push(Aabb::from_points(&v));
                    }
                }
                ShapeKind::Sphere(s) => {
                    let (c, r) = (s.center, s.radius);
                    prims.push(Prim::Sphere { c, r });
                    refs.push((si as u32, 0));
                    let r = Vec3A::splat(r);
                    let c: Vec3A = c.into();
                    aabbs.push(Aabb::new(c - r, c + r));
                }
            }
        }
        if prims.is_empty() {
            return Accel {
                bvh: Bvh4::empty(),
                prims,
                refs,
            };
        }
        let params = BvhBuildParams {
            max_prims_per_leaf: 4.min(MAX_LEAF),
            ..BvhBuildParams::medium_build()
        };
        let bvh2 = build_bvh2(&aabbs, params, &mut Duration::default());
        let order = &bvh2.primitive_indices;
        Accel {
            bvh: Bvh4::from_bvh2(&bvh2),
            prims: order.iter().map(|&i| prims[i as usize]).collect(),
            refs: order.iter().map(|&i| refs[i as usize]).collect(),
        }
    }

    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// Distance to primitive `i` (infinite on a miss) and, for triangles, barycentrics.
    #[inline(always)]
    fn prim_hit(
        &self,
        i: usize,
        wr: &WatertightRay,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> (f32, Vec2) {
        match self.prims[i] {
            Prim::Tri { v: [a, b, c] } => wr
                .intersect(a, b, c, tmin, tmax)
                .map_or((f32::INFINITY, Vec2::ZERO), |h| (h.0, Vec2::new(h.1, h.2))),
            Prim::Sphere { c, r } => (
                intersect_sphere(o, d, tmin, tmax, c, r).unwrap_or(f32::INFINITY),
                Vec2::ZERO,
            ),
        }
    }

    #[inline(always)]
    fn prim_t(&self, i: usize, wr: &WatertightRay, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
        self.prim_hit(i, wr, o, d, tmin, tmax).0
    }

    /// Closest hit within the ray's interval.
    pub fn intersect(&self, ray: &Ray, shapes: &[Shape]) -> Option<Hit> {
        let (o, d, tmin) = (ray.o, ray.d, ray.tmin);
        let wr = WatertightRay::new(o, d);
        // The barycentrics of the current best ride along.
        let mut best_bary = Vec2::ZERO;
        let (i, t) = self.bvh.closest(
            o,
            d,
            tmin,
            ray.tmax,
            #[inline(always)]
            |i, tmax| {
                let (t, bary) = self.prim_hit(i, &wr, o, d, tmin, tmax);
                if t < tmax {
                    best_bary = bary;
                }
                t
            },
        )?;
        let (shape, local) = self.refs[i];
        let sp = match &shapes[shape as usize].kind {
            ShapeKind::Mesh(m) => m.surface_point(local as usize, best_bary, shape),
            ShapeKind::Sphere(s) => s.surface_point(ray.o + ray.d * t, shape),
        };
        Some(Hit { t, sp })
    }

    /// True if anything blocks the ray within its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let (o, d, tmin, tmax) = (ray.o, ray.d, ray.tmin, ray.tmax);
        let wr = WatertightRay::new(o, d);
        self.bvh.any(
            o,
            d,
            tmin,
            tmax,
            #[inline(always)]
            |i, tmax| self.prim_t(i, &wr, o, d, tmin, tmax),
        )
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
            kind: ShapeKind::Mesh(Mesh::new(positions, None, indices)),
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
            let wr = WatertightRay::new(o, d);
            let brute = (0..accel.prims.len())
                .map(|i| accel.prim_t(i, &wr, o, d, 0.0, f32::INFINITY))
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
