//! The direct estimator for eight camera samples of a pixel at once, in vector lanes.
//!
//! The camera rays and the shadow rays of the eight samples are made and traced as packets,
//! one array per component (`RayPacket`, see `geometry::packet`), the BSDF rays one at a
//! time. Everything between them (shading frames, light points, densities, BSDF values, MIS
//! weights, the shadow and BSDF rays) runs as loops over the eight samples, in
//! structure-of-arrays form, which the compiler turns into vector code.
//! Each loop body calls the same scalar functions as `Direct::li`, in the same order, so every
//! sample is bitwise what `li` gives it (`render` tests this on the bundled scenes).
//!
//! It covers the configuration of the study's figures: MIS with one light and one BSDF sample,
//! area sampling, every emitter an area light on a mesh or a sphere. Camera hits on one-sided
//! diffuse surfaces shade here; batches of one-sided Beckmann rough conductors shade in
//! `lanes_rough`. Other hits go to `li_hit`, the scalar definition; other configurations go
//! to `li`. The tables its lookups read are built once per render in `lane_tables`.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::direct::{heuristic, Direct};
use super::lane_tables::{
    LaneLight, LaneLightKind, LaneMaterial, LaneShape, LightTriangle, SmallLights, SmallMesh,
};
use crate::bsdf::{BsdfSample, Diffuse};
use crate::emitter::{area_pdf_along, sample_at, sphere_area_point};
use crate::geometry::packet::bits;
use crate::geometry::{lookup8, Accel, Mesh, PacketHits, RayPacket, Sphere, SurfacePoint};
use crate::math::{offset_origin, Frame, Rgb};
use crate::rng::{RngLanes, LANES};
use crate::sampling::warps::square_to_uniform_triangle;
use crate::sampling::AliasTable;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

// A pixel's eight samples trace their camera and shadow rays as one packet.
const _: () = assert!(LANES == crate::geometry::packet::PACKET);

/// Eight 3-vectors, one array per component.
#[derive(Clone, Copy, Default)]
pub(super) struct V3x8 {
    x: [f32; LANES],
    y: [f32; LANES],
    z: [f32; LANES],
}

impl V3x8 {
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        V3x8 {
            x: [v.x; LANES],
            y: [v.y; LANES],
            z: [v.z; LANES],
        }
    }

    #[inline(always)]
    pub(super) fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }

    /// The components as a ray packet holds them.
    #[inline(always)]
    pub(super) fn axes(&self) -> [[f32; LANES]; 3] {
        [self.x, self.y, self.z]
    }

    #[inline(always)]
    fn from_axes([x, y, z]: [[f32; LANES]; 3]) -> Self {
        V3x8 { x, y, z }
    }
}

/// What the camera hits of the eight samples leave for shading.
#[derive(Default)]
pub(super) struct CameraHits {
    pub(super) p: V3x8,
    pub(super) ng: V3x8,
    pub(super) ns: V3x8,
    pub(super) err: V3x8,
    /// Camera ray direction.
    pub(super) d: V3x8,
    /// Diffuse reflectance, or a rough conductor's specular reflectance.
    pub(super) reflectance: V3x8,
    /// Whether this batch's lanes are rough conductors (`lanes_rough`), else diffuse.
    pub(super) rough: bool,
    /// A rough conductor's roughness and its grey complex index of refraction.
    pub(super) alpha_u: [f32; LANES],
    pub(super) alpha_v: [f32; LANES],
    pub(super) eta: [f32; LANES],
    pub(super) k: [f32; LANES],
    /// Accelerator skip ids of the hit triangle (all rays, emitter-only structure).
    skip: [u32; LANES],
    emitter_skip: [u32; LANES],
    /// The lanes shaded here, and their estimate so far (the emission seen at the hit).
    pub(super) covered: u32,
    le: V3x8,
}

/// The sphere of each lane whose light is a sphere. Kept out of `LightDraws`: with these
/// fields it grew past what LLVM zeroes inline and became a memset call per batch.
#[derive(Default)]
pub(super) struct SphereDraws {
    any: bool,
    sphere: [Option<Sphere>; LANES],
}

/// The light triangle of each lane and its data, gathered with scalar table lookups (for a
/// sphere light, only `shape`, `radiance`, `area` and `pmf`).
#[derive(Default)]
pub(super) struct LightDraws {
    v: [V3x8; 3],
    ng: V3x8,
    err: V3x8,
    /// Vertex normals, where the mesh has them (`has_normals`).
    n: [V3x8; 3],
    has_normals: [bool; LANES],
    shape: [u32; LANES],
    tri: [u32; LANES],
    radiance: V3x8,
    area: [f32; LANES],
    pub(super) pmf: [f32; LANES],
}

impl LightDraws {
    /// Lane i's triangle of a mesh light, drawn with `u`, and its record.
    #[inline(always)]
    fn triangle(
        &mut self,
        i: usize,
        triangles: &AliasTable,
        records: &[LightTriangle],
        smooth: Option<&Mesh>,
        u: f32,
    ) {
        let tri = triangles.sample(u);
        let r = &records[tri];
        for (k, v) in r.v.into_iter().enumerate() {
            self.v[k].set(i, v);
        }
        self.vertex_normals(i, smooth, tri);
        self.ng.set(i, r.ng);
        self.err.set(i, r.err);
        self.tri[i] = tri as u32;
    }

    /// `light_draws`'s emitter choice and copies for two to eight emitters, for all lanes at
    /// once from register-held tables (`SmallLights`); lanes whose light is a mesh then draw
    /// their triangles one by one.
    #[inline(always)]
    fn small_lights(
        &mut self,
        t: &SmallLights,
        lights: &[LaneLight],
        u_emitter: &[f32; LANES],
        u_tri: &[f32; LANES],
        spheres: &mut SphereDraws,
    ) {
        let e = t.choice.draw(u_emitter);
        self.pmf = lookup8(&t.pmf, &e);
        self.shape = lookup8(&t.shape, &e).map(f32::to_bits);
        self.radiance = V3x8 {
            x: lookup8(&t.radiance[0], &e),
            y: lookup8(&t.radiance[1], &e),
            z: lookup8(&t.radiance[2], &e),
        };
        self.area = lookup8(&t.area, &e);
        let mut meshes = 0;
        for i in 0..LANES {
            spheres.sphere[i] = t.sphere[e[i] as usize];
            meshes |= (t.meshes >> e[i] & 1) << i;
        }
        spheres.any = meshes != (1 << LANES) - 1;
        for i in bits(meshes) {
            if let LaneLightKind::Mesh {
                triangles,
                records,
                smooth,
                ..
            } = &lights[e[i] as usize].kind
            {
                self.triangle(i, triangles, records, *smooth, u_tri[i]);
            }
        }
    }

    /// `triangle` of every lane from a mesh of at most eight triangles: the alias draw
    /// (`AliasTable::sample`, the same operations) and the records' reads for all lanes at
    /// once, each a `lookup8` of a register-held table; the vertex normals of a smooth mesh
    /// lane by lane.
    #[inline(always)]
    fn small_mesh_triangles(&mut self, m: &SmallMesh, smooth: Option<&Mesh>, u: &[f32; LANES]) {
        let tri = m.triangles.draw(u);
        let f = |j: usize| lookup8(&m.fields[j], &tri);
        let v3 = |j: usize| V3x8 {
            x: f(j),
            y: f(j + 1),
            z: f(j + 2),
        };
        self.v = [v3(0), v3(3), v3(6)];
        (self.ng, self.err) = (v3(9), v3(12));
        self.tri = tri;
        if smooth.is_some() {
            (0..LANES).for_each(|i| self.vertex_normals(i, smooth, tri[i] as usize));
        }
    }

    /// Lane i's vertex normals of triangle `tri`, where the mesh has them.
    #[inline(always)]
    fn vertex_normals(&mut self, i: usize, smooth: Option<&Mesh>, tri: usize) {
        if let Some(n) = smooth.and_then(|m| m.vertex_normals(tri)) {
            for (k, n) in n.into_iter().enumerate() {
                self.n[k].set(i, n);
            }
            self.has_normals[i] = true;
        }
    }
}

/// The lanes' rays and candidate contributions, before visibility. Every shading pass writes
/// every field of every lane.
#[derive(Default)]
pub(super) struct Shaded {
    pub(super) shadow_o: V3x8,
    pub(super) shadow_target: V3x8,
    pub(super) light: V3x8,
    pub(super) light_ok: [bool; LANES],
    pub(super) bsdf_o: V3x8,
    pub(super) bsdf_d: V3x8,
    pub(super) bsdf_pdf: [f32; LANES],
    pub(super) bsdf_weight: V3x8,
    pub(super) bsdf_ok: [bool; LANES],
}

/// The working arrays of `li_lanes`, made once by the caller and reused by every batch: made
/// per batch, they were copied out of the calls that fill them (a 872-byte memcpy) or zeroed
/// (three memset calls per eight samples, 2.6 % of Cornell render time). Each batch writes
/// what it reads; the fields some batches write only in part are cleared per batch.
#[derive(Default)]
pub struct LaneScratch {
    /// The camera packet's hits, filled in place (`Accel::intersect8_into`).
    packet: PacketHits,
    hits: CameraHits,
    draws: LightDraws,
    shaded: Shaded,
}

impl Direct<'_> {
    /// `li` of the first `n` rays, each with its lane of `rng` (which must stand where `li`
    /// would receive it): in lanes where they cover the scene and strategy, else one by one.
    pub fn li_lanes(
        &self,
        rays: &RayPacket,
        n: usize,
        rng: &mut RngLanes,
        scratch: &mut LaneScratch,
    ) -> [Rgb; LANES] {
        let Some(lanes) = &self.lanes else {
            return std::array::from_fn(|i| match i < n {
                true => self.li(&rays.ray(i), &mut rng.lane(i)),
                false => Rgb::ZERO,
            });
        };
        let LaneScratch {
            packet,
            hits,
            draws,
            shaded,
        } = scratch;
        let mut out = [Rgb::ZERO; LANES];
        // The seven numbers `li` draws after the camera's: light (emitter, triangle, point),
        // then BSDF (lobe, direction). Drawn before the camera rays are traced, from a copy
        // that lanes left to `li_hit` do not see: placed after, their chain of dependent
        // 64-bit multiplications (about 15 cycles each) started only once traversal ended.
        let at_hit = rng.clone();
        let u: [[f32; LANES]; 7] = std::array::from_fn(|_| rng.next_f32());
        self.scene.intersect8_into(rays, (1 << n) - 1, packet);
        self.camera_hits(&lanes.shapes, rays, packet, &at_hit, &mut out, hits);
        let mut spheres = SphereDraws::default();
        let small = lanes.small_lights.as_deref();
        self.light_draws(&lanes.lights, small, &u[0], &u[1], draws, &mut spheres);
        // Sphere lights take a branch per lane, which the mesh-only loop is spared.
        match (hits.rough, spheres.any) {
            (true, _) => self.shade_and_trace_rough(hits, draws, &spheres, &u, shaded, &mut out),
            (false, false) => {
                self.shade_and_trace::<false>(hits, draws, &spheres, &u, shaded, &mut out)
            }
            (false, true) => {
                self.shade_and_trace_spheres(hits, draws, &spheres, &u, shaded, &mut out)
            }
        }
        out
    }

    /// Whether `li_lanes` shades in lanes for this scene and strategy.
    pub fn has_lanes(&self) -> bool {
        self.lanes.is_some()
    }

    /// The camera rays' hits into lanes; lanes the kernel does not cover are finished here
    /// by `li_hit`.
    #[inline(always)]
    fn camera_hits(
        &self,
        shapes: &[LaneShape],
        rays: &RayPacket,
        camera: &PacketHits,
        rng: &RngLanes,
        out: &mut [Rgb; LANES],
        h: &mut CameraHits,
    ) {
        let scene = self.scene;
        // What the paths below write for some lanes only, or not at all.
        (h.le, h.covered) = (V3x8::default(), 0);
        // Taken whole; lanes the loop below does not cover are dropped later.
        h.p = V3x8::from_axes(camera.p);
        h.ng = V3x8::from_axes(camera.ng);
        h.ns = V3x8::from_axes(camera.ns);
        h.err = V3x8::from_axes(camera.err);
        h.d = V3x8::from_axes(rays.d);
        if let Some(shape) = one_shape(shapes, camera) {
            if self.fill_one_shape(shape, camera, rays, h) {
                return;
            }
        }
        let mut batch = None;
        for i in bits(camera.mask) {
            let (shape_id, prim) = (camera.shape[i], camera.prim[i]);
            let shape = &shapes[shape_id as usize];
            // The batch takes the kind of its first covered hit; hits of the other kind (at a
            // pixel straddling two materials) and uncovered materials take the scalar path.
            let rough = match shape.material {
                LaneMaterial::Diffuse(reflectance) => {
                    h.reflectance.set(i, reflectance);
                    Some(false)
                }
                LaneMaterial::Rough {
                    reflectance,
                    alpha,
                    eta_k,
                } => {
                    h.reflectance.set(i, reflectance);
                    (h.alpha_u[i], h.alpha_v[i]) = alpha;
                    (h.eta[i], h.k[i]) = eta_k;
                    Some(true)
                }
                LaneMaterial::Other => None,
            };
            if rough.is_none_or(|r| r != *batch.get_or_insert(r)) {
                out[i] = self.li_hit(&rays.ray(i), &camera.point(i), &mut rng.lane(i));
                continue;
            }
            let mut l = Rgb::ZERO;
            if !self.strategy.hide_emitters {
                if let Some(e) = shape.emitter {
                    l += scene.emitters[e as usize].le(&camera.point(i), -rays.d(i));
                }
            }
            h.le.set(i, l);
            h.covered |= 1 << i;
            h.skip[i] = Accel::skip_from(shape.skip_base, prim);
            h.emitter_skip[i] = Accel::skip_from(shape.emitter_skip_base, prim);
        }
        h.rough = batch == Some(true);
    }

    /// `camera_hits`'s loop for hits that all lie on one shape (most pixels' eight samples):
    /// its row read once for all lanes. False, with `h` untouched, for a material the lanes
    /// do not cover. It spells out the loop's material match and cover steps for all lanes
    /// at once: helpers shared with the loop, per lane or per lane mask, cost the Cornell box
    /// 0.8-2.1 % more instructions (callgrind).
    #[inline(always)]
    fn fill_one_shape(
        &self,
        shape: &LaneShape,
        camera: &PacketHits,
        rays: &RayPacket,
        h: &mut CameraHits,
    ) -> bool {
        // Lanes without a hit take the row too: their samples are computed and dropped.
        h.rough = match shape.material {
            LaneMaterial::Diffuse(reflectance) => {
                h.reflectance = V3x8::splat(reflectance);
                false
            }
            LaneMaterial::Rough {
                reflectance,
                alpha,
                eta_k,
            } => {
                h.reflectance = V3x8::splat(reflectance);
                (h.alpha_u, h.alpha_v) = ([alpha.0; LANES], [alpha.1; LANES]);
                (h.eta, h.k) = ([eta_k.0; LANES], [eta_k.1; LANES]);
                true
            }
            LaneMaterial::Other => return false,
        };
        if !self.strategy.hide_emitters {
            if let Some(e) = shape.emitter {
                let emitter = &self.scene.emitters[e as usize];
                for i in bits(camera.mask) {
                    let mut l = Rgb::ZERO;
                    l += emitter.le(&camera.point(i), -rays.d(i));
                    h.le.set(i, l);
                }
            }
        }
        h.covered = camera.mask;
        for i in 0..LANES {
            h.skip[i] = Accel::skip_from(shape.skip_base, camera.prim[i]);
            h.emitter_skip[i] = Accel::skip_from(shape.emitter_skip_base, camera.prim[i]);
        }
        true
    }

    /// Emitter and triangle choice and the triangle's data: the table lookups of `light_draw`.
    #[inline(always)]
    fn light_draws(
        &self,
        lights: &[LaneLight],
        small: Option<&SmallLights>,
        u_emitter: &[f32; LANES],
        u_tri: &[f32; LANES],
        d: &mut LightDraws,
        spheres: &mut SphereDraws,
    ) {
        // The one field a lane's triangle leaves unwritten (a mesh without vertex normals).
        d.has_normals = [false; LANES];
        if let Some(pmf) = self.selector.single() {
            // Every lane draws the one emitter: its data is copied once.
            let light = &lights[0];
            d.shape = [light.shape; LANES];
            d.radiance = V3x8::splat(light.radiance);
            d.area = [light.area; LANES];
            d.pmf = [pmf; LANES];
            match &light.kind {
                LaneLightKind::Mesh {
                    small: Some(small),
                    smooth,
                    ..
                } => d.small_mesh_triangles(small, *smooth, u_tri),
                LaneLightKind::Mesh {
                    triangles,
                    records,
                    smooth,
                    ..
                } => (0..LANES).for_each(|i| d.triangle(i, triangles, records, *smooth, u_tri[i])),
                LaneLightKind::Sphere(sphere) => {
                    (spheres.sphere, spheres.any) = ([Some(**sphere); LANES], true)
                }
            }
            return;
        }
        if let Some(t) = small {
            return d.small_lights(t, lights, u_emitter, u_tri, spheres);
        }
        for i in 0..LANES {
            let Some((e, pmf)) = self.selector.sample(u_emitter[i]) else {
                continue;
            };
            let light = &lights[e];
            d.shape[i] = light.shape;
            d.radiance.set(i, light.radiance);
            d.area[i] = light.area;
            d.pmf[i] = pmf;
            match &light.kind {
                LaneLightKind::Mesh {
                    triangles,
                    records,
                    smooth,
                    ..
                } => d.triangle(i, triangles, records, *smooth, u_tri[i]),
                LaneLightKind::Sphere(sphere) => {
                    (spheres.sphere[i], spheres.any) = (Some(**sphere), true);
                }
            }
        }
    }

    /// `shade` and `trace_and_sum`. Each branch of `li_lanes` runs both, so that no
    /// `Shaded` is moved out of the branch (a copy LLVM did not elide: a memcpy call).
    #[inline(always)]
    fn shade_and_trace<const SPHERES: bool>(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        shaded: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        self.shade::<SPHERES>(h, ld, sd, u, shaded);
        self.trace_and_sum::<SPHERES>(h, shaded, out);
    }

    /// `shade_and_trace` for batches with a sphere light, out of line: the mesh-only kernel
    /// then compiles as it would without sphere lights.
    #[inline(never)]
    fn shade_and_trace_spheres(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        shaded: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        self.shade_and_trace::<true>(h, ld, sd, u, shaded, out)
    }

    /// The arithmetic of `light_draw`, `light_finish` and `bsdf_draw` and the rays of the two
    /// samples, for all lanes at once (lanes without a covered hit compute garbage, dropped).
    #[inline(always)]
    fn shade<const SPHERES: bool>(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
    ) {
        let s = &self.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        for i in 0..LANES {
            let (p, ng, err) = (h.p.get(i), h.ng.get(i), h.err.get(i));
            let frame = Frame::from_normal(h.ns.get(i));
            let wi = frame.to_local(-h.d.get(i));
            let diffuse = Diffuse {
                reflectance: h.reflectance.get(i),
            };
            let (drawn, wl, pdf_area, radiance, lsp) = light_sample::<SPHERES>(p, ld, sd, u, i);
            // `light_finish` before its visibility test.
            let wo = frame.to_local(wl);
            let (f, pdf_bsdf) = (diffuse.eval(wi, wo), diffuse.pdf(wi, wo));
            let p_light = ld.pmf[i] * pdf_area;
            let w = heuristic(s.heuristic, ne * p_light, nb * pdf_bsdf);
            o.light.set(i, f * radiance * (w / p_light));
            o.light_ok[i] = drawn && f != Rgb::ZERO && radiance != Rgb::ZERO;
            let lp = lsp.p;
            let so = offset_origin(p, ng, err, lp - p);
            o.shadow_o.set(i, so);
            o.shadow_target
                .set(i, offset_origin(lp, lsp.ng, lsp.err_scale, so - lp));
            // BSDF sample and `Scene::bsdf_ray`'s origin.
            let bs = diffuse.sample(wi, Vec2::new(u[5][i], u[6][i]));
            let (bsdf_ok, wo, pdf) = match bs {
                Some(bs) => (true, bs.wo, bs.pdf),
                None => (false, Vec3::Z, 0.0),
            };
            o.bsdf_ok[i] = bsdf_ok;
            o.bsdf_pdf[i] = pdf;
            o.bsdf_weight.set(i, diffuse.reflectance);
            let d = frame.to_world(wo);
            o.bsdf_d.set(i, d);
            o.bsdf_o.set(i, offset_origin(p, ng, err, d));
        }
    }

    /// The traversals (the shadow rays as one packet, then the BSDF rays one at a time) and
    /// the estimate of each covered lane, summed in `li`'s order.
    #[inline(always)]
    pub(super) fn trace_and_sum<const SPHERES: bool>(
        &self,
        h: &CameraHits,
        sh: &Shaded,
        out: &mut [Rgb; LANES],
    ) {
        let scene = self.scene;
        let s = &self.strategy;
        let (ne, nb) = (s.emitter_samples as f32, s.bsdf_samples as f32);
        let bsdf_w = |pb, pl| heuristic(s.heuristic, nb * pb, ne * pl);
        // Every lane's ray is computed; only those of covered lanes with a light sample
        // are traced.
        let shadow = Scene::shadow_rays_to(&sh.shadow_o.axes(), &sh.shadow_target.axes(), &h.skip);
        let traced = h.covered & mask_of(&sh.light_ok);
        let blocked = scene.accel.occluded8(&shadow, traced);
        // The BSDF rays, put through `bsdf_ray_hit`'s reject in lanes (without sphere lights,
        // its box reject alone): only those it lets through are traced, one by one.
        let bsdf_rays = RayPacket {
            o: sh.bsdf_o.axes(),
            d: sh.bsdf_d.axes(),
            tmin: [0.0; LANES],
            tmax: [f32::INFINITY; LANES],
            skip: h.skip,
        };
        let open = h.covered & mask_of(&sh.bsdf_ok);
        let mut bsdf = V3x8::default();
        for i in bits(scene.bsdf_rays_may_hit::<SPHERES>(&bsdf_rays, open)) {
            let ray = bsdf_rays.ray(i);
            if let Some(hit) = scene.bsdf_ray_hit_traced(&ray, h.emitter_skip[i]) {
                let bs = BsdfSample {
                    wo: Vec3::ZERO,
                    weight: sh.bsdf_weight.get(i),
                    pdf: sh.bsdf_pdf[i],
                    delta: false,
                };
                bsdf.set(i, self.bsdf_emission(h.p.get(i), ray.d, &hit, &bs, bsdf_w));
            }
        }
        // `li`'s sum, in its order, for all lanes at once; only covered lanes are kept.
        let lit = traced & !blocked;
        let mut sum = V3x8::default();
        for i in 0..LANES {
            let light = if lit >> i & 1 != 0 {
                sh.light.get(i)
            } else {
                Rgb::ZERO
            };
            sum.set(i, h.le.get(i) + light / ne + bsdf.get(i) / nb);
        }
        for i in bits(h.covered) {
            out[i] = sum.get(i);
        }
    }
}

/// The shape every hit of the packet lies on, if there are hits and they share one.
#[inline(always)]
fn one_shape<'s>(shapes: &'s [LaneShape], camera: &PacketHits) -> Option<&'s LaneShape> {
    let first = camera.shape[camera.mask.checked_ilog2()? as usize];
    let mut same = 0u32;
    for i in 0..LANES {
        same |= ((camera.shape[i] == first) as u32) << i;
    }
    (same & camera.mask == camera.mask).then(|| &shapes[first as usize])
}

/// The lanes whose flag is set, as a mask.
#[inline(always)]
fn mask_of(flags: &[bool; LANES]) -> u32 {
    let mut m = 0;
    for (i, &f) in flags.iter().enumerate() {
        m |= (f as u32) << i;
    }
    m
}

/// Lane i's light sample: the area-sampling branches of `AreaLight::sample` for the drawn
/// triangle or sphere, seen from p: whether it was drawn, its direction, its density in
/// solid angle, its radiance and the light point.
#[inline(always)]
pub(super) fn light_sample<const SPHERES: bool>(
    p: Vec3,
    ld: &LightDraws,
    sd: &SphereDraws,
    u: &[[f32; LANES]; 7],
    i: usize,
) -> (bool, Vec3, f32, Rgb, SurfacePoint) {
    let u_point = Vec2::new(u[2][i], u[3][i]);
    let sphere = if SPHERES { sd.sphere[i] } else { None };
    let lsp = if let Some(s) = sphere {
        sphere_area_point(&s, u_point, ld.shape[i])
    } else {
        let b = square_to_uniform_triangle(u_point);
        let v = [ld.v[0].get(i), ld.v[1].get(i), ld.v[2].get(i)];
        let normals = [ld.n[0].get(i), ld.n[1].get(i), ld.n[2].get(i)];
        let face = (ld.ng.get(i), ld.err.get(i));
        let normals = ld.has_normals[i].then_some(normals);
        Mesh::point_from(v, face, normals, b, ld.shape[i], ld.tri[i])
    };
    let area = ld.area[i];
    let ls = sample_at(ld.radiance.get(i), p, &lsp, |wi, dist| {
        area_pdf_along(area, &lsp, wi, dist)
    });
    match ls {
        Some(ls) => (true, ls.wi, ls.pdf, ls.li, lsp),
        None => (false, Vec3::ZERO, 0.0, Rgb::ZERO, lsp),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A fan of `n` triangles of unequal areas (the second of zero area, which the alias
    /// table must never draw), with vertex normals or without.
    fn fan(n: usize, normals: bool) -> (Mesh, AliasTable, Vec<LightTriangle>) {
        let mut positions = vec![Vec3::new(0.1, -0.2, 1.0)];
        positions.extend((0..=n).map(|k| {
            // Rim points 1 and 2 coincide: triangle 1 has no area.
            let k = if k == 2 { 1 } else { k };
            let a = k as f32 * 0.7;
            let r = 1.0 + k as f32;
            Vec3::new(r * a.cos(), r * a.sin(), 1.0 + 0.1 * k as f32)
        }));
        let indices: Vec<[u32; 3]> = (0..n as u32).map(|k| [0, k + 1, k + 2]).collect();
        let vertex_normals = normals.then(|| {
            (0..positions.len())
                .map(|k| Vec3::new(0.1 * k as f32, -0.2, 1.0).normalize())
                .collect()
        });
        let mesh = Mesh::new(positions, vertex_normals, indices);
        let areas: Vec<f64> = (0..n)
            .map(|t| {
                let [a, b, c] = mesh.vertices(t);
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .collect();
        let table = AliasTable::new(&areas).expect("a triangle of positive area");
        let records = (0..n)
            .map(|t| {
                let (ng, err) = mesh.face(t);
                LightTriangle {
                    v: mesh.vertices(t),
                    ng,
                    err,
                }
            })
            .collect();
        (mesh, table, records)
    }

    fn bits(v: &V3x8) -> [[u32; LANES]; 3] {
        v.axes().map(|a| a.map(f32::to_bits))
    }

    /// `small_mesh_triangles` draws, for every lane, bitwise what `triangle` draws with the
    /// same number: meshes of 1 to 8 triangles, flat and smooth, random numbers and edges
    /// (0, the largest below 1, the bin boundaries).
    #[test]
    fn small_mesh_draws_are_the_per_lane_draws() {
        let below_one = f32::from_bits(1.0f32.to_bits() - 1);
        let mut rng = Rng::new(3, 9);
        for n in 1..=8 {
            for normals in [false, true] {
                let (mesh, table, records) = fan(n, normals);
                let small = SmallMesh::new(&table, &records).expect("at most eight");
                let smooth = normals.then_some(&mesh);
                let edges: [f32; LANES] = std::array::from_fn(|k| match k {
                    0 => 0.0,
                    1 => below_one,
                    _ => (k as f32 - 1.0) / n as f32,
                });
                let mut batches = vec![edges];
                batches.extend((0..200).map(|_| std::array::from_fn(|_| rng.next_f32())));
                for u in batches {
                    let (mut a, mut b) = (LightDraws::default(), LightDraws::default());
                    (0..LANES).for_each(|i| a.triangle(i, &table, &records, smooth, u[i]));
                    b.small_mesh_triangles(&small, smooth, &u);
                    assert_eq!(a.tri, b.tri, "n {n}, u {u:?}");
                    assert!(a.tri.iter().all(|&t| t != 1), "the zero-area triangle");
                    for k in 0..3 {
                        assert_eq!(bits(&a.v[k]), bits(&b.v[k]));
                        assert_eq!(bits(&a.n[k]), bits(&b.n[k]));
                    }
                    assert_eq!((bits(&a.ng), bits(&a.err)), (bits(&b.ng), bits(&b.err)));
                    assert_eq!(a.has_normals, b.has_normals);
                    assert_eq!(a.has_normals, [normals; LANES]);
                }
            }
        }
    }

    /// `small_lights` draws, for every lane, bitwise what `light_draws`' per-lane loop draws
    /// with the same numbers: sphere lights (the Veach scene), mesh lights (two quads), and
    /// both in one scene, by uniform and by power choice; random numbers and the edges.
    #[test]
    fn small_lights_draws_are_the_per_lane_draws() {
        use crate::emitter::EmitterSelection;
        use crate::scene::bundled_tests::load;
        let veach = load("veach-mis/veach-mis.xml");
        let quads = load("cbox-twolights/cbox-twolights.xml");
        let mut mixed = veach.clone();
        mixed
            .shapes
            .extend(quads.shapes.iter().filter(|s| s.emitter.is_some()).cloned());
        let below_one = f32::from_bits(1.0f32.to_bits() - 1);
        let mut rng = Rng::new(4, 1);
        let mut kinds = [0; 2];
        for desc in [veach, quads, mixed] {
            let scene = Scene::build(desc).unwrap();
            for selection in [EmitterSelection::Uniform, EmitterSelection::Power] {
                let strategy = crate::integrator::Strategy::combinations()
                    .into_iter()
                    .find(|s| {
                        s.kind == crate::scene::desc::StrategyKind::Mis
                            && s.emitter_samples == 1
                            && s.selection == selection
                            && s.light_sampling == crate::emitter::LightSampling::Area
                    })
                    .unwrap();
                let direct = Direct::new(&scene, strategy);
                let lanes = direct.lanes.as_ref().expect("covered");
                let small = lanes.small_lights.as_deref().expect("two to eight lights");
                let n = scene.emitters.len() as f32;
                let edges: [f32; LANES] = std::array::from_fn(|k| match k {
                    0 => 0.0,
                    1 => below_one,
                    _ => (k as f32 - 1.0) / n,
                });
                let mut batches = vec![(edges, edges)];
                batches.extend((0..300).map(|_| {
                    let mut u = || std::array::from_fn(|_| rng.next_f32());
                    (u(), u())
                }));
                for (u_e, u_t) in batches {
                    let (mut a, mut b) = (LightDraws::default(), LightDraws::default());
                    let (mut sa, mut sb) = (SphereDraws::default(), SphereDraws::default());
                    direct.light_draws(&lanes.lights, None, &u_e, &u_t, &mut a, &mut sa);
                    direct.light_draws(&lanes.lights, Some(small), &u_e, &u_t, &mut b, &mut sb);
                    assert_eq!(a.shape, b.shape, "u {u_e:?}");
                    assert_eq!(a.pmf.map(f32::to_bits), b.pmf.map(f32::to_bits));
                    assert_eq!(a.area.map(f32::to_bits), b.area.map(f32::to_bits));
                    assert_eq!(bits(&a.radiance), bits(&b.radiance));
                    assert_eq!(sa.any, sb.any);
                    for i in 0..LANES {
                        match (sa.sphere[i], sb.sphere[i]) {
                            (Some(x), Some(y)) => {
                                assert_eq!((x.center, x.radius), (y.center, y.radius));
                                assert_eq!(x.flip_normals, y.flip_normals);
                                kinds[0] += 1;
                            }
                            (None, None) => {
                                assert_eq!(a.tri[i], b.tri[i]);
                                for k in 0..3 {
                                    assert_eq!(a.v[k].get(i), b.v[k].get(i));
                                }
                                assert_eq!(
                                    (a.ng.get(i), a.err.get(i)),
                                    (b.ng.get(i), b.err.get(i))
                                );
                                kinds[1] += 1;
                            }
                            _ => panic!("lane {i}: a sphere in one draw only"),
                        }
                    }
                }
            }
        }
        assert!(
            kinds.iter().all(|&k| k > 1000),
            "sphere and mesh lanes {kinds:?}"
        );
    }

    /// Meshes of more than eight triangles keep the per-lane tables.
    #[test]
    fn larger_meshes_have_no_small_tables() {
        let (_, table, records) = fan(9, false);
        assert!(SmallMesh::new(&table, &records).is_none());
    }
}
