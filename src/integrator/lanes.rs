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
//! to `li`. The light draws (emitter, triangle, light point) are in `lanes_light`; the tables
//! their lookups read are built once per render in `lane_tables`.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::direct::{heuristic, Direct};
use super::lane_tables::{LaneMaterial, LaneShape};
use super::lanes_light::{light_sample, LightDraws, SphereDraws};
use crate::bsdf::{BsdfSample, Diffuse};
use crate::geometry::ray_packet::bits;
use crate::geometry::{Accel, PacketHits, RayPacket};
use crate::math::{Frame, Rgb};
use crate::rng::LANES;
use crate::sampler::SamplerLanes;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

// A pixel's eight samples trace their camera and shadow rays as one packet.
const _: () = assert!(LANES == crate::geometry::ray_packet::PACKET);

/// The light and BSDF sample counts of the only strategies the lanes cover
/// (`lane_tables::lane_lights`). As constants, `li`'s divisions by them (six per batch) and
/// multiplications compile to nothing, which dividing by a 1 read from the strategy did not.
/// x / 1 and 1 * x are x exactly, so every sample is still bitwise `li`'s.
pub(super) const SAMPLE_COUNTS: (u32, u32) = (1, 1);

/// `SAMPLE_COUNTS` as the f32 factors `li` uses.
pub(super) const SAMPLE_COUNTS_F32: (f32, f32) = (SAMPLE_COUNTS.0 as f32, SAMPLE_COUNTS.1 as f32);

/// Eight 3-vectors, one array per component. The kernel's lane arrays are 32-byte aligned
/// and their structures `repr(C)` with flags last, for the reason `PacketHits` gives.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
pub(super) struct V3x8 {
    pub(super) x: [f32; LANES],
    pub(super) y: [f32; LANES],
    pub(super) z: [f32; LANES],
}

impl V3x8 {
    #[inline(always)]
    pub(super) fn splat(v: Vec3) -> Self {
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
    #[cfg(test)]
    pub(super) fn axes(&self) -> [[f32; LANES]; 3] {
        [self.x, self.y, self.z]
    }

    /// Copies the components from a ray packet's layout, axis by axis: built as a whole
    /// value, the copy went through a stack temporary whose 32-byte stores were read back
    /// as 64-byte loads, which cannot be forwarded from them (a stall of each copy).
    #[inline(always)]
    fn copy_axes(&mut self, [x, y, z]: &[[f32; LANES]; 3]) {
        (self.x, self.y, self.z) = (*x, *y, *z);
    }
}

/// What the camera hits of the eight samples leave for shading.
#[derive(Default)]
#[repr(C)]
pub(super) struct CameraHits {
    /// The camera packet's hits, filled in place (`Accel::intersect8_into`) and read where
    /// they lie: a copy of their points and normals into lane arrays stalled on the
    /// traversal's last stores, one lane wide, which a wide load cannot take forwarded
    /// (about a third of `li_lanes`'s own time on the Veach scene, perf).
    pub(super) camera: PacketHits,
    /// Camera ray direction.
    pub(super) d: V3x8,
    /// Diffuse reflectance, or a rough conductor's specular reflectance.
    pub(super) reflectance: V3x8,
    /// A rough conductor's roughness and its grey complex index of refraction.
    pub(super) alpha_u: [f32; LANES],
    pub(super) alpha_v: [f32; LANES],
    pub(super) eta: [f32; LANES],
    pub(super) k: [f32; LANES],
    /// Accelerator skip ids of the hit triangle (all rays, emitter-only structure).
    pub(super) skip: [u32; LANES],
    emitter_skip: [u32; LANES],
    /// Their estimate so far (the emission seen at the hit).
    le: V3x8,
    /// The lanes shaded here.
    pub(super) covered: u32,
    /// Whether this batch's lanes are rough conductors (`lanes_rough`), else diffuse.
    pub(super) rough: bool,
}

/// The lanes' rays and candidate contributions, before visibility. Every shading pass writes
/// every field of every lane.
#[derive(Default)]
#[repr(C)]
pub(super) struct Shaded {
    /// The shadow and BSDF rays, made in the packets that are traced: made in lane arrays
    /// and copied into packets, their copies stalled as the camera hits' did (see
    /// `CameraHits::camera`).
    pub(super) shadow: RayPacket,
    pub(super) light: V3x8,
    pub(super) bsdf: RayPacket,
    pub(super) bsdf_pdf: [f32; LANES],
    pub(super) bsdf_weight: V3x8,
    pub(super) light_ok: [bool; LANES],
    pub(super) bsdf_ok: [bool; LANES],
}

/// The working arrays of `li_lanes`, made once by the caller and reused by every batch: made
/// per batch, they were copied out of the calls that fill them (a 872-byte memcpy) or zeroed
/// (three memset calls per eight samples, 2.6 % of Cornell render time). Each batch writes
/// what it reads; the fields some batches write only in part are cleared per batch.
#[derive(Default)]
pub struct LaneScratch {
    hits: CameraHits,
    draws: LightDraws,
    shaded: Shaded,
}

impl Direct<'_> {
    /// `li` of the first `n` rays, each with its lane of `rng` (which must stand where `li`
    /// would receive it): in lanes where they cover the scene and strategy, else one by one.
    ///
    /// Inlined into `render_pixel`: called, it read the lanes' generator states (left by the
    /// camera's draws half in one 32-byte store, half in 8-byte ones) and returned the
    /// estimates through memory, both read back at once by loads too wide to be forwarded.
    #[inline(always)]
    pub fn li_lanes<L: SamplerLanes>(
        &self,
        rays: &RayPacket,
        n: usize,
        rng: &mut L,
        scratch: &mut LaneScratch,
    ) -> [Rgb; LANES] {
        let Some(lanes) = &self.lanes else {
            return std::array::from_fn(|i| match i < n {
                true => self.li(&rays.ray(i), &mut rng.lane(i)),
                false => Rgb::ZERO,
            });
        };
        let LaneScratch {
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
        let [u0, u1, u2, u3] = rng.light();
        let [u4, u5, u6] = rng.bsdf();
        let u = [u0, u1, u2, u3, u4, u5, u6];
        self.scene
            .intersect8_into(rays, (1 << n) - 1, &mut hits.camera);
        self.camera_hits(&lanes.shapes, rays, &at_hit, &mut out, hits);
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
    fn camera_hits<L: SamplerLanes>(
        &self,
        shapes: &[LaneShape],
        rays: &RayPacket,
        rng: &L,
        out: &mut [Rgb; LANES],
        h: &mut CameraHits,
    ) {
        let scene = self.scene;
        // What the paths below write for some lanes only, or not at all.
        (h.le, h.covered) = (V3x8::default(), 0);
        // Taken whole; lanes the loop below does not cover are dropped later.
        h.d.copy_axes(&rays.d);
        if let Some(shape) = one_shape(shapes, &h.camera) {
            if self.fill_one_shape(shape, rays, h) {
                return;
            }
        }
        let camera = &h.camera;
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
    /// at once: helpers shared with the loop, per lane or per lane mask, cost measurably more
    /// instructions on the bundled scenes.
    #[inline(always)]
    fn fill_one_shape(&self, shape: &LaneShape, rays: &RayPacket, h: &mut CameraHits) -> bool {
        let camera = &h.camera;
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
        let (ne, nb) = SAMPLE_COUNTS_F32;
        for i in 0..LANES {
            let sp = h.camera.point(i);
            let (p, frame) = (sp.p, Frame::from_normal(sp.ns));
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
            let so = sp.spawn_origin(lp - p);
            let target = lsp.spawn_origin(so - lp);
            o.shadow
                .set(i, &Scene::shadow_ray_to(so, target, h.skip[i]));
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
            o.bsdf
                .set(i, &Scene::ray_from(sp.spawn_origin(d), d, h.skip[i]));
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
        let (ne, nb) = SAMPLE_COUNTS_F32;
        let bsdf_w = |pb, pl| heuristic(s.heuristic, nb * pb, ne * pl);
        // Every lane's ray is computed; only those of covered lanes with a light sample
        // are traced.
        let traced = h.covered & mask_of(&sh.light_ok);
        let blocked = scene.accel.occluded8(&sh.shadow, traced);
        // The BSDF rays, put through `bsdf_ray_hit`'s reject in lanes (without sphere lights,
        // its box reject alone): only those it lets through are traced, one by one.
        let bsdf_rays = &sh.bsdf;
        let open = h.covered & mask_of(&sh.bsdf_ok);
        let mut bsdf = V3x8::default();
        for i in bits(scene.bsdf_rays_may_hit::<SPHERES>(bsdf_rays, open)) {
            let ray = bsdf_rays.ray(i);
            if let Some(hit) = scene.bsdf_ray_hit_traced(&ray, h.emitter_skip[i]) {
                let bs = BsdfSample {
                    wo: Vec3::ZERO,
                    weight: sh.bsdf_weight.get(i),
                    pdf: sh.bsdf_pdf[i],
                    delta: false,
                };
                bsdf.set(
                    i,
                    self.bsdf_emission(h.camera.point(i).p, ray.d, &hit, &bs, bsdf_w),
                );
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
