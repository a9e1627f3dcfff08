//! The scene's acceleration structure: one 8-wide BVH (see `bvh`) whose leaves hold up to
//! four triangles as one SIMD packet (see `watertight`), plus any spheres.

use super::bvh::WideBvh;
use super::shape::{intersect_sphere, Shape, ShapeKind};
use super::sphere8::Spheres8;
use super::watertight::{Tri4, WatertightRay};
use super::{Hit, Ray, RayPacket, SurfacePoint, NO_SKIP};
use glam::{BVec4A, Vec2, Vec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::builder::build_bvh2, BvhBuildParams};
use std::time::Duration;

/// Triangles per packet, and so the most primitives a BVH leaf may hold.
const LEAF_SIZE: usize = 4;
/// Primitive count above which the BVH is built with obvhs's fuller leaves: a large mesh's
/// structure outgrows the caches, and fewer nodes and leaves then beat cheaper leaves (level
/// at 1e4 triangles in the bench's sweep, ahead above it).
const FULL_LEAVES_FROM: usize = 10_000;

/// Primitive count above which the binary BVH is built with obvhs's slow preset (wider PLOC
/// search, more reinsertion): its better tree pays for the longer build at a million
/// triangles and not yet at a hundred thousand (reports/bench/NOTES.md), so the switch sits
/// between the two.
const QUALITY_BUILD_FROM: usize = 300_000;

/// One BVH leaf: its triangles as a packet and its spheres.
#[derive(Clone, Copy, Debug)]
pub(super) struct Leaf {
    pub(super) tris: Tri4,
    /// Per lane, the triangle's index in `refs` (unused lanes repeat lane 0).
    pub(super) tri_ref: [u32; 4],
    pub(super) n_tris: u32,
    /// Range in `spheres`.
    pub(super) spheres: (u32, u32),
}

impl Leaf {
    /// The lanes holding triangle `id`.
    #[inline(always)]
    pub(super) fn skip(&self, id: u32) -> BVec4A {
        let r = &self.tri_ref;
        BVec4A::new(r[0] == id, r[1] == id, r[2] == id, r[3] == id)
    }
}

/// The surface point of a closest hit at distance `t` along `ray`: on primitive
/// `(shape, local index)` at barycentrics `b` (a triangle) or projected onto it (a sphere).
#[inline(always)]
pub(super) fn surface_point(
    shapes: &[Shape],
    (shape, local): (u32, u32),
    b: Vec2,
    ray: &Ray,
    t: f32,
) -> SurfacePoint {
    match &shapes[shape as usize].kind {
        ShapeKind::Mesh(m) => m.surface_point(local as usize, b, shape),
        ShapeKind::Sphere(s) => s.surface_point(ray.o + ray.d * t, shape),
    }
}

/// The scene's acceleration structure: an 8-wide BVH over every triangle and sphere.
pub struct Accel {
    pub(super) bvh: WideBvh,
    pub(super) leaves: Vec<Leaf>,
    /// (centre, radius, index in `refs`).
    pub(super) spheres: Vec<(Vec3, f32, u32)>,
    /// (shape index, triangle index within the shape) per primitive id.
    pub(super) refs: Vec<(u32, u32)>,
    /// Per shape, the id of its first triangle (ids of a mesh's triangles are consecutive,
    /// so a surface point names its triangle's id), or `NO_SKIP` for a sphere.
    tri_base: Vec<u32>,
    /// Primitives in the BVH (zero-area triangles have an id but are left out).
    n_prims: usize,
    /// All the primitives as lanes, for `occluded`, when they are at most eight spheres.
    spheres8: Option<Spheres8>,
}

/// A primitive before it is placed in a leaf.
enum Prim {
    Tri([Vec3; 3]),
    Sphere(Vec3, f32),
}

/// A zero-area triangle is left out of the BVH, since no ray can hit it.
fn hittable([a, b, c]: [Vec3; 3]) -> bool {
    (b - a).cross(c - a).length_squared() != 0.0
}

impl Accel {
    /// The primitives `build_where(shapes, keep)` holds, counted without building it.
    pub fn primitive_count_where(shapes: &[Shape], keep: impl Fn(&Shape) -> bool) -> usize {
        shapes
            .iter()
            .filter(|s| keep(s))
            .map(|s| match &s.kind {
                ShapeKind::Mesh(m) => (0..m.indices.len())
                    .filter(|&t| hittable(m.vertices(t)))
                    .count(),
                ShapeKind::Sphere(_) => 1,
            })
            .sum()
    }

    /// Builds over all shapes; zero-area triangles are left out since no ray can hit them.
    pub fn build(shapes: &[Shape]) -> Accel {
        Accel::build_where(shapes, |_| true)
    }

    /// Builds over the shapes `keep` selects. Hits still name their shape by its index in
    /// `shapes`; a surface point on a left-out shape has no triangle to skip here.
    pub fn build_where(shapes: &[Shape], keep: impl Fn(&Shape) -> bool) -> Accel {
        // (primitive, its id in `refs`)
        let mut prims = Vec::new();
        let mut refs = Vec::new();
        let mut tri_base = Vec::new();
        let mut aabbs = Vec::new();
        for (si, shape) in shapes.iter().enumerate() {
            if !keep(shape) {
                tri_base.push(NO_SKIP);
                continue;
            }
            match &shape.kind {
                ShapeKind::Mesh(m) => {
                    tri_base.push(refs.len() as u32);
                    for ti in 0..m.indices.len() {
                        refs.push((si as u32, ti as u32));
                        let [a, b, c] = m.vertices(ti);
                        if !hittable([a, b, c]) {
                            continue;
                        }
                        prims.push((Prim::Tri([a, b, c]), refs.len() as u32 - 1));
                        aabbs.push(Aabb::from_points(&[a, b, c].map(Vec3A::from)));
                    }
                }
                ShapeKind::Sphere(s) => {
                    tri_base.push(NO_SKIP);
                    prims.push((Prim::Sphere(s.center, s.radius), refs.len() as u32));
                    refs.push((si as u32, 0));
                    let (c, r): (Vec3A, _) = (s.center.into(), Vec3A::splat(s.radius));
                    aabbs.push(Aabb::new(c - r, c + r));
                }
            }
        }
        let mut accel = Accel {
            bvh: WideBvh::empty(),
            leaves: Vec::new(),
            spheres: Vec::new(),
            refs,
            tri_base,
            n_prims: prims.len(),
            spheres8: None,
        };
        if prims.is_empty() {
            return accel;
        }
        let params = BvhBuildParams {
            max_prims_per_leaf: LEAF_SIZE as u32,
            // obvhs's default of 3 makes leaves of 3-4 triangles; with 8-wide nodes a node
            // visit is cheap, so a lower cost per visit is the better guess for small scenes
            // (measured on the bundled scenes' rays), but not for large ones (see
            // `FULL_LEAVES_FROM`).
            collapse_traversal_cost: if prims.len() > FULL_LEAVES_FROM {
                3.0
            } else {
                1.0
            },
            // A large tree's traversal waits on memory, where a tree with fewer and better
            // placed nodes pays for its slower build (see `QUALITY_BUILD_FROM`).
            ..if prims.len() > QUALITY_BUILD_FROM {
                BvhBuildParams::slow_build()
            } else {
                BvhBuildParams::medium_build()
            }
        };
        let bvh2 = build_bvh2(&aabbs, params, &mut Duration::default());
        accel.bvh = WideBvh::from_bvh2(&bvh2);
        for &(first, count) in accel.bvh.leaves() {
            let ids = &bvh2.primitive_indices[first as usize..(first + count) as usize];
            assert!(
                ids.len() <= LEAF_SIZE,
                "BVH leaf of {} primitives",
                ids.len()
            );
            let mut tris = Vec::new();
            let mut tri_ref = [0; 4];
            let s0 = accel.spheres.len() as u32;
            for &id in ids {
                match prims[id as usize] {
                    (Prim::Tri(v), rid) => {
                        tri_ref[tris.len()] = rid;
                        tris.push(v);
                    }
                    (Prim::Sphere(c, r), rid) => accel.spheres.push((c, r, rid)),
                }
            }
            let n_tris = tris.len() as u32;
            if tris.is_empty() {
                tris.push([Vec3::ZERO; 3]);
            }
            for lane in n_tris as usize..4 {
                tri_ref[lane] = tri_ref[0];
            }
            accel.leaves.push(Leaf {
                tris: Tri4::new(&tris),
                tri_ref,
                n_tris,
                spheres: (s0, accel.spheres.len() as u32),
            });
        }
        if accel.leaves.iter().all(|l| l.n_tris == 0) {
            accel.spheres8 = Spheres8::new(accel.spheres.iter().map(|&(c, r, _)| (c, r)));
        }
        accel
    }

    /// The number of primitives (triangles and spheres) it holds.
    pub fn primitive_count(&self) -> usize {
        self.n_prims
    }

    /// `Ray::skip` for a ray leaving `sp`, or ending on it: its triangle, which is flat, so no
    /// such ray meets it again; a sphere can be met again (from inside), so nothing is skipped.
    #[inline]
    pub fn skip_id(&self, sp: &SurfacePoint) -> u32 {
        Accel::skip_from(self.skip_base(sp.shape), sp.prim)
    }

    /// The part of `skip_id` that depends on the shape alone, for tables built per shape.
    pub fn skip_base(&self, shape: u32) -> u32 {
        self.tri_base[shape as usize]
    }

    /// `skip_id` from the shape's `skip_base` and the point's triangle.
    #[inline(always)]
    pub fn skip_from(base: u32, prim: u32) -> u32 {
        match base {
            NO_SKIP => NO_SKIP,
            base => base + prim,
        }
    }

    /// Closest hit within the ray's interval.
    #[inline]
    pub fn intersect(&self, ray: &Ray, shapes: &[Shape]) -> Option<Hit> {
        self.intersect_if(ray, shapes, |_| true)
    }

    /// Closest hit within the ray's interval if `keep(shape index)`; the surface point is
    /// only built for kept hits (a BSDF sample needs it only where it hits an emitter).
    #[inline(always)]
    pub fn intersect_if(
        &self,
        ray: &Ray,
        shapes: &[Shape],
        keep: impl Fn(usize) -> bool,
    ) -> Option<Hit> {
        let (o, d, tmin) = (ray.o, ray.d, ray.tmin);
        let wr = WatertightRay::new(o, d);
        // The best primitive and its barycentrics ride along.
        let mut best = (0u32, Vec2::ZERO);
        let t = self.bvh.closest(
            o,
            d,
            tmin,
            ray.tmax,
            #[inline(always)]
            |l, mut tmax| {
                let leaf = &self.leaves[l];
                if leaf.n_tris > 0 {
                    let skip = leaf.skip(ray.skip);
                    if let Some((lane, t, b1, b2)) = wr.closest(&leaf.tris, tmin, tmax, skip) {
                        tmax = t;
                        best = (leaf.tri_ref[lane], Vec2::new(b1, b2));
                    }
                }
                for &(c, r, id) in &self.spheres[leaf.spheres.0 as usize..leaf.spheres.1 as usize] {
                    if let Some(t) = intersect_sphere(o, d, tmin, tmax, c, r) {
                        tmax = t;
                        best = (id, Vec2::ZERO);
                    }
                }
                tmax
            },
        )?;
        let prim = self.refs[best.0 as usize];
        if !keep(prim.0 as usize) {
            return None;
        }
        Some(Hit {
            t,
            sp: surface_point(shapes, prim, best.1, ray, t),
        })
    }

    /// Asks for the node or leaf of child `c` (a `WideBvh` child slot) that a packet traversal
    /// has just put on its stack, where the tree is larger than the caches near the core: its
    /// loads then overlap the subtree visited first instead of stalling when it is popped.
    /// On the 1e6-triangle sweep scene, 7-9 % less time per sample (1 thread); a leaf's record
    /// (176 bytes) was the traversal's largest stall there.
    #[inline(always)]
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    pub(super) fn prefetch(&self, c: u32) {
        #[cfg(target_arch = "x86_64")]
        if self.bvh.prefetches() {
            use super::bvh::{Node, LEAF};
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (p, size) = if c & LEAF == 0 {
                let p = self.bvh.nodes.as_ptr().wrapping_add(c as usize) as *const i8;
                (p, std::mem::size_of::<Node>())
            } else {
                let p = self.leaves.as_ptr().wrapping_add((c & !LEAF) as usize) as *const i8;
                (p, std::mem::size_of::<Leaf>())
            };
            for line in 0..size.div_ceil(64) {
                // SAFETY: a prefetch never faults, whatever the address.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * line)) };
            }
        }
    }

    /// The box around everything in the structure.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bvh.bounds()
    }

    /// False only if the ray can hit nothing here (see `WideBvh::may_enter`). For a structure
    /// of a few spheres the answer is exact, `occluded`'s (see `may_hit_is_occluded`).
    #[inline(always)]
    pub fn may_hit(&self, ray: &Ray) -> bool {
        self.bvh.may_enter(ray.o, ray.d, ray.tmin, ray.tmax)
            && self
                .spheres8
                .as_ref()
                .is_none_or(|s| s.any(ray.o, ray.d, ray.tmin, ray.tmax))
    }

    /// `may_hit`'s box reject of each ray of a packet: bit i is lane i's answer.
    #[inline(always)]
    pub fn may_hit8(&self, rays: &RayPacket) -> u32 {
        self.bvh
            .may_enter8(&rays.o, &rays.d, &rays.tmin, &rays.tmax)
    }

    /// The rest of `may_hit` for the packet's rays set in `active`, which passed its box
    /// reject: for a structure of a few spheres, the mask of those it hits (the rays in lanes,
    /// the spheres one by one, where `occluded` takes the spheres in lanes ray by ray); else
    /// `active` whole.
    #[inline(always)]
    pub fn may_hit8_past_box(&self, rays: &RayPacket, active: u32) -> u32 {
        match &self.spheres8 {
            Some(s) if active != 0 => s.any8(rays, active),
            _ => active,
        }
    }

    /// Whether `may_hit` answers exactly what `occluded` does, so a ray it lets through needs
    /// no `occluded` query.
    #[inline(always)]
    pub fn may_hit_is_occluded(&self) -> bool {
        self.spheres8.is_some()
    }

    /// True if anything blocks the ray within its interval.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match &self.spheres8 {
            Some(s) => s.any(ray.o, ray.d, ray.tmin, ray.tmax),
            None => self.occluded_bvh(ray),
        }
    }

    /// `occluded` by a walk of the BVH: out of line, so that the few-spheres test inlines
    /// without the walk's stack frame.
    #[inline(never)]
    fn occluded_bvh(&self, ray: &Ray) -> bool {
        let (o, d, tmin, tmax) = (ray.o, ray.d, ray.tmin, ray.tmax);
        // Set up on the first leaf: many occlusion rays (and most emitter pre-tests) reach none.
        let mut wr = None;
        self.bvh.any(
            o,
            d,
            tmin,
            tmax,
            #[inline(always)]
            |l, tmax| {
                let leaf = &self.leaves[l];
                let wr = wr.get_or_insert_with(|| WatertightRay::new(o, d));
                (leaf.n_tris > 0 && wr.any(&leaf.tris, tmin, tmax, leaf.skip(ray.skip)))
                    || self.spheres[leaf.spheres.0 as usize..leaf.spheres.1 as usize]
                        .iter()
                        .any(|&(c, r, _)| intersect_sphere(o, d, tmin, tmax, c, r).is_some())
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::watertight::intersect_triangle;
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

    /// The BVH must agree with brute force over every primitive, built as for small scenes
    /// and, past `FULL_LEAVES_FROM` primitives, with fuller leaves.
    #[test]
    fn bvh_matches_brute_force() {
        for (n, rays) in [(8, 2000), (72, 300)] {
            let shapes = vec![
                quad_grid(n, 0.0),
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
            let prims = 2 * n * n + 2 * 3 * 3 + 1;
            assert_eq!(prims > FULL_LEAVES_FROM, n > 8);
            check_against_brute_force(&shapes, rays);
        }
    }

    fn check_against_brute_force(shapes: &[Shape], rays: usize) {
        let accel = Accel::build(shapes);
        let mut rng = Rng::new(1, 1);
        let mut hits = 0;
        for _ in 0..rays {
            let o = Vec3::new(rng.next_f32() * 1.4 - 0.2, rng.next_f32() * 1.4 - 0.2, 2.0);
            let d = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, -1.0).normalize();
            let ray = Ray::new(o, d);
            let inf = f32::INFINITY;
            let brute = shapes
                .iter()
                .flat_map(|s| match &s.kind {
                    ShapeKind::Mesh(m) => (0..m.indices.len())
                        .map(|t| intersect_triangle(o, d, 0.0, inf, m.vertices(t)).map(|h| h.0))
                        .collect::<Vec<_>>(),
                    ShapeKind::Sphere(s) => {
                        vec![intersect_sphere(o, d, 0.0, inf, s.center, s.radius)]
                    }
                })
                .flatten()
                .fold(inf, f32::min);
            match accel.intersect(&ray, shapes) {
                Some(h) => {
                    hits += 1;
                    assert!((h.t - brute).abs() <= 1e-5 * brute.max(1.0));
                }
                None => assert!(brute.is_infinite()),
            }
            assert_eq!(accel.occluded(&ray), brute.is_finite());
        }
        assert!(
            hits > rays / 4,
            "only {hits} hits: the test exercises too few hits"
        );
    }

    /// The count the emitter pre-test decides on before building must be the built count:
    /// zero-area triangles left out, spheres counted once, unselected shapes not at all.
    #[test]
    fn primitive_count_where_matches_the_built_structure() {
        let mut front = quad_grid(3, 0.5);
        if let ShapeKind::Mesh(m) = &mut front.kind {
            let mut indices = vec![[0, 0, 1], [2, 3, 3]];
            indices.extend_from_slice(&m.indices);
            *m = Mesh::new(m.positions.clone(), None, indices);
        }
        front.emitter = Some(0);
        let sphere = Shape {
            kind: ShapeKind::Sphere(Sphere {
                center: Vec3::ONE,
                radius: 0.5,
                flip_normals: false,
            }),
            material: 0,
            emitter: Some(1),
        };
        let shapes = vec![quad_grid(4, 0.0), front, sphere];
        let keeps: [fn(&Shape) -> bool; 3] = [|_| true, |s| s.emitter.is_some(), |_| false];
        let counts = keeps.map(|keep| {
            let n = Accel::primitive_count_where(&shapes, keep);
            assert_eq!(n, Accel::build_where(&shapes, keep).primitive_count());
            n
        });
        assert_eq!(counts, [32 + 18 + 1, 18 + 1, 0]);
    }

    /// A ray told to skip the triangle it would hit passes through to the one behind: the id
    /// a surface point gives names its own triangle, also after a zero-area triangle (which
    /// has an id but no place in the BVH).
    #[test]
    fn skipped_triangle_is_passed_through() {
        let mut front = quad_grid(4, 0.5);
        if let ShapeKind::Mesh(m) = &mut front.kind {
            let mut indices = vec![[0, 0, 1]];
            indices.extend_from_slice(&m.indices);
            *m = Mesh::new(m.positions.clone(), None, indices);
        }
        let shapes = vec![quad_grid(4, 0.0), front];
        let accel = Accel::build(&shapes);
        let mut rng = Rng::new(3, 3);
        let mut through = 0;
        for _ in 0..500 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), 2.0);
            let mut ray = Ray::new(o, -Vec3::Z);
            let front_hit = accel.intersect(&ray, &shapes).unwrap();
            assert_eq!(front_hit.sp.shape, 1);
            ray.skip = accel.skip_id(&front_hit.sp);
            let back_hit = accel.intersect(&ray, &shapes).unwrap();
            // Through an edge the ray still meets the neighbouring front triangle.
            if back_hit.sp.shape == 0 {
                assert!((back_hit.t - 2.0).abs() < 1e-5);
                through += 1;
            } else {
                assert_ne!(back_hit.sp.prim, front_hit.sp.prim);
            }
            assert!(accel.occluded(&ray));
        }
        assert!(through > 490, "{through} of 500 rays passed through");
    }

    #[test]
    fn empty_scene_misses() {
        let accel = Accel::build(&[]);
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!(accel.intersect(&ray, &[]).is_none());
        assert!(!accel.occluded(&ray));
    }
}
