//! The direct estimator for eight camera samples of a pixel at once, in vector lanes.
//!
//! Only the traversals stay one ray at a time. Everything between them (shading frames, light
//! points, densities, BSDF values, MIS weights, the shadow and BSDF rays) runs as loops over
//! the eight samples, in structure-of-arrays form, which the compiler turns into vector code.
//! Each loop body calls the same scalar functions as `Direct::li`, in the same order, so every
//! sample is bitwise what `li` gives it (`render` tests this on the bundled scenes).
//!
//! It covers the configuration of the study's figures: MIS with one light and one BSDF sample,
//! area sampling, every emitter a mesh area light without vertex normals. A camera hit whose
//! material is not one-sided diffuse goes to `li_hit`, the scalar definition.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::direct::{heuristic, Direct};
use crate::bsdf::{BsdfKind, BsdfSample, Diffuse};
use crate::emitter::{Emitter, LightSampling};
use crate::geometry::{Mesh, Ray, ShapeKind, NO_SKIP};
use crate::math::{offset_origin, Frame, Rgb};
use crate::rng::{RngLanes, LANES};
use crate::sampling::warps::{
    square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf, square_to_uniform_triangle,
};
use crate::sampling::AliasTable;
use crate::scene::desc::StrategyKind;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// Eight 3-vectors, one array per component.
#[derive(Clone, Copy, Default)]
struct V3x8 {
    x: [f32; LANES],
    y: [f32; LANES],
    z: [f32; LANES],
}

impl V3x8 {
    #[inline(always)]
    fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    #[inline(always)]
    fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
}

/// An emitter the lanes can sample: a mesh area light.
pub(super) struct LaneLight<'a> {
    mesh: &'a Mesh,
    triangles: &'a AliasTable,
    radiance: Rgb,
    area: f32,
}

/// The lane lights, one per emitter, if the scene and strategy are the configuration the
/// lanes cover; otherwise None and `Direct` shades every sample with `li`.
pub(super) fn lane_lights<'a>(direct: &Direct<'a>) -> Option<Vec<LaneLight<'a>>> {
    let (scene, s) = (direct.scene, &direct.strategy);
    let covered = s.kind == StrategyKind::Mis
        && s.emitter_samples == 1
        && s.bsdf_samples == 1
        && s.light_sampling == LightSampling::Area
        && !scene.emitters.is_empty();
    if !covered {
        return None;
    }
    scene
        .emitters
        .iter()
        .map(|e| match e {
            Emitter::Area(a) => match (&scene.shapes[a.shape as usize].kind, &a.triangles) {
                (ShapeKind::Mesh(mesh), Some(triangles)) => Some(LaneLight {
                    mesh,
                    triangles,
                    radiance: a.radiance,
                    area: a.area,
                }),
                _ => None,
            },
            Emitter::Point(_) => None,
        })
        .collect()
}

/// What the camera hits of the eight samples leave for shading.
#[derive(Default)]
struct CameraHits {
    p: V3x8,
    ng: V3x8,
    ns: V3x8,
    err: V3x8,
    /// Camera ray direction.
    d: V3x8,
    reflectance: V3x8,
    /// Accelerator skip ids of the hit triangle (all rays, emitter-only structure).
    skip: [u32; LANES],
    emitter_skip: [u32; LANES],
    /// The estimate so far (emission seen at the hit); None for lanes not shaded here.
    l: [Option<Rgb>; LANES],
}

/// The light sample of each lane, drawn with scalar table lookups.
#[derive(Default)]
struct LightDraws {
    v: [V3x8; 3],
    /// Vertex normals, where the mesh has them (`has_normals`).
    n: [V3x8; 3],
    has_normals: [bool; LANES],
    ng: V3x8,
    err: V3x8,
    radiance: V3x8,
    area: [f32; LANES],
    pmf: [f32; LANES],
}

/// The lanes' rays and candidate contributions, before visibility.
#[derive(Default)]
struct Shaded {
    shadow_o: V3x8,
    shadow_target: V3x8,
    light: V3x8,
    light_ok: [bool; LANES],
    bsdf_o: V3x8,
    bsdf_d: V3x8,
    bsdf_pdf: [f32; LANES],
    bsdf_ok: [bool; LANES],
}

impl Direct<'_> {
    /// `li` of the first `n` rays, each with its lane of `rng` (which must stand where `li`
    /// would receive it).
    pub fn li_lanes(&self, rays: &[Ray; LANES], n: usize, rng: &mut RngLanes) -> [Rgb; LANES] {
        let lights = self
            .lane_lights
            .as_deref()
            .expect("li_lanes needs the covered configuration (Direct::has_lanes)");
        let mut out = [Rgb::ZERO; LANES];
        let hits = self.camera_hits(rays, n, rng, &mut out);
        // The seven numbers `li` draws after the camera's: light (emitter, triangle, point),
        // then BSDF (lobe, direction).
        let u: [[f32; LANES]; 7] = std::array::from_fn(|_| rng.next_f32());
        let draws = self.light_draws(lights, &u[0], &u[1]);
        let shaded = self.shade(&hits, &draws, &u);
        self.trace_and_sum(&hits, &shaded, &mut out);
        out
    }

    /// Whether `li_lanes` covers this scene and strategy.
    pub fn has_lanes(&self) -> bool {
        self.lane_lights.is_some()
    }

    /// Camera hits; lanes the kernel does not cover are finished here by `li_hit`.
    #[inline(always)]
    fn camera_hits(
        &self,
        rays: &[Ray; LANES],
        n: usize,
        rng: &RngLanes,
        out: &mut [Rgb; LANES],
    ) -> CameraHits {
        let scene = self.scene;
        let mut h = CameraHits::default();
        for i in 0..n {
            let Some(hit) = scene.intersect(&rays[i]) else {
                continue;
            };
            let sp = hit.sp;
            let mat = scene.material(&sp);
            let BsdfKind::Diffuse(diffuse) = &mat.kind else {
                out[i] = self.li_hit(&rays[i], &sp, &mut rng.lane(i));
                continue;
            };
            if mat.two_sided {
                out[i] = self.li_hit(&rays[i], &sp, &mut rng.lane(i));
                continue;
            }
            let mut l = Rgb::ZERO;
            if !self.strategy.hide_emitters {
                if let Some((_, e)) = scene.emitter_at(&sp) {
                    l += e.le(&sp, -rays[i].d);
                }
            }
            h.l[i] = Some(l);
            h.p.set(i, sp.p);
            h.ng.set(i, sp.ng);
            h.ns.set(i, sp.ns);
            h.err.set(i, sp.err_scale);
            h.d.set(i, rays[i].d);
            h.reflectance.set(i, diffuse.reflectance);
            h.skip[i] = scene.accel.skip_id(&sp);
            h.emitter_skip[i] = scene
                .emitter_accel
                .as_ref()
                .map_or(NO_SKIP, |e| e.skip_id(&sp));
        }
        h
    }

    /// Emitter and triangle choice and the triangle's data: the table lookups of `light_draw`.
    #[inline(always)]
    fn light_draws(
        &self,
        lights: &[LaneLight],
        u_emitter: &[f32; LANES],
        u_tri: &[f32; LANES],
    ) -> LightDraws {
        let mut d = LightDraws::default();
        for i in 0..LANES {
            let Some((e, pmf)) = self.selector.sample(u_emitter[i]) else {
                continue;
            };
            let light = &lights[e];
            let tri = light.triangles.sample(u_tri[i]);
            let v = light.mesh.vertices(tri);
            let (ng, err) = light.mesh.face(tri);
            for (k, v) in v.into_iter().enumerate() {
                d.v[k].set(i, v);
            }
            if let Some(n) = light.mesh.vertex_normals(tri) {
                for (k, n) in n.into_iter().enumerate() {
                    d.n[k].set(i, n);
                }
                d.has_normals[i] = true;
            }
            d.ng.set(i, ng);
            d.err.set(i, err);
            d.radiance.set(i, light.radiance);
            d.area[i] = light.area;
            d.pmf[i] = pmf;
        }
        d
    }

    /// The arithmetic of `light_draw`, `light_finish` and `bsdf_draw` and the rays of the two
    /// samples, for all lanes at once (lanes without a covered hit compute garbage, dropped).
    #[inline(always)]
    fn shade(&self, h: &CameraHits, ld: &LightDraws, u: &[[f32; LANES]; 7]) -> Shaded {
        let s = &self.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let mut o = Shaded::default();
        for i in 0..LANES {
            let (p, ng, err) = (h.p.get(i), h.ng.get(i), h.err.get(i));
            let frame = Frame::from_normal(h.ns.get(i));
            let wi = frame.to_local(-h.d.get(i));
            let diffuse = Diffuse {
                reflectance: h.reflectance.get(i),
            };
            // Light sample: `AreaLight::sample` on a mesh, `Mesh::surface_point`.
            let b = square_to_uniform_triangle(Vec2::new(u[2][i], u[3][i]));
            let lp = Mesh::interpolate([ld.v[0].get(i), ld.v[1].get(i), ld.v[2].get(i)], b);
            let (face_ng, lerr) = (ld.ng.get(i), ld.err.get(i));
            let vertex_normals = [ld.n[0].get(i), ld.n[1].get(i), ld.n[2].get(i)];
            let (lng, lns) = match ld.has_normals[i] {
                true => Mesh::shading_normals(face_ng, vertex_normals, b),
                false => (face_ng, face_ng),
            };
            let to_light = lp - p;
            let dist = to_light.length();
            let wl = Vec3::new(to_light.x / dist, to_light.y / dist, to_light.z / dist);
            let faces = dist > 0.0 && lns.dot(-wl) > 0.0;
            let cos_l = lng.dot(wl).abs();
            let pdf_area = if cos_l > 0.0 {
                dist * dist / (ld.area[i] * cos_l)
            } else {
                0.0
            };
            let drawn = faces && pdf_area > 0.0 && pdf_area.is_finite();
            // `light_finish` before its visibility test.
            let wo = frame.to_local(wl);
            let (f, pdf_bsdf) = (diffuse.eval(wi, wo), diffuse.pdf(wi, wo));
            let radiance = ld.radiance.get(i);
            let p_light = ld.pmf[i] * pdf_area;
            let w = heuristic(s.heuristic, ne * p_light, nb * pdf_bsdf);
            o.light.set(i, f * radiance * (w / p_light));
            o.light_ok[i] = drawn && f != Rgb::ZERO && radiance != Rgb::ZERO;
            let so = offset_origin(p, ng, err, lp - p);
            o.shadow_o.set(i, so);
            o.shadow_target
                .set(i, offset_origin(lp, lng, lerr, so - lp));
            // BSDF sample: `Diffuse::sample` and `Scene::bsdf_ray`.
            let wo = square_to_cosine_hemisphere(Vec2::new(u[5][i], u[6][i]));
            let pdf = square_to_cosine_hemisphere_pdf(wo);
            o.bsdf_ok[i] = !(wi.z <= 0.0) && !(pdf <= 0.0);
            o.bsdf_pdf[i] = pdf;
            let d = frame.to_world(wo);
            o.bsdf_d.set(i, d);
            o.bsdf_o.set(i, offset_origin(p, ng, err, d));
        }
        o
    }

    /// The traversals, one ray at a time, and the estimate of each covered lane, summed in
    /// `li`'s order.
    #[inline(always)]
    fn trace_and_sum(&self, h: &CameraHits, sh: &Shaded, out: &mut [Rgb; LANES]) {
        let scene = self.scene;
        let s = &self.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let bsdf_w = |pb, pl| heuristic(s.heuristic, nb * pb, ne * pl);
        for i in 0..LANES {
            let Some(mut l) = h.l[i] else {
                continue;
            };
            let mut light = Rgb::ZERO;
            if sh.light_ok[i] {
                let ray =
                    Scene::shadow_ray_to(sh.shadow_o.get(i), sh.shadow_target.get(i), h.skip[i]);
                if !scene.accel.occluded(&ray) {
                    light = sh.light.get(i);
                }
            }
            l += light / ne;
            let mut bsdf = Rgb::ZERO;
            if sh.bsdf_ok[i] {
                let d = sh.bsdf_d.get(i);
                let ray = Ray {
                    skip: h.skip[i],
                    ..Ray::new(sh.bsdf_o.get(i), d)
                };
                let bs = BsdfSample {
                    wo: Vec3::ZERO,
                    weight: h.reflectance.get(i),
                    pdf: sh.bsdf_pdf[i],
                    delta: false,
                };
                bsdf = self.bsdf_arrive(h.p.get(i), &ray, h.emitter_skip[i], &bs, bsdf_w);
            }
            l += bsdf / nb;
            out[i] = l;
        }
    }
}
