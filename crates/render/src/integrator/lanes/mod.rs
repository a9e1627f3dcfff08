//! The lane kernel: the direct estimator for eight camera samples of a pixel at once, in
//! vector lanes. `LaneKernel` wraps the scalar estimator (`Direct`) and never restates it.
//!
//! The camera rays and the shadow rays of the eight samples are made and traced as packets,
//! one array per component (`RayPacket`, see `geometry::packet`), the BSDF rays one at a
//! time. Everything between them (shading frames, light points, densities, BSDF values, MIS
//! weights, the shadow and BSDF rays) runs as loops over the eight samples, in
//! structure-of-arrays form, which the compiler turns into vector code. Each loop body calls
//! the scalar code `Direct::li` calls, in the same order, so every sample is bitwise what
//! `li` gives it (`render_lanes_tests` checks this on random scenes).
//!
//! There is one shading function (`shade`), generic over the BSDF type through the lane
//! methods of `Bsdf` (`lane_shared`, `eval_pdf_shared`, `sample_lanes`), whose defaults call
//! the BSDF's own eval, pdf and sample lane by lane: a new BSDF runs in lanes as registered.
//!
//! What runs in lanes (the rule `tables::lane_setup` and `camera_hits` apply):
//! - strategy: MIS with one light and one BSDF sample (balance or power heuristic; every
//!   emitter choice, the point-dependent ones at each lane's hit; RIS's candidates drawn lane
//!   by lane with `li`'s own draw, `ris_numbers`), area sampling, every emitter an area light
//!   on a mesh or a sphere. Other strategies (light or BSDF only, N+M samples, one-sample
//!   MIS, solid-angle sampling) and scenes with point lights render every sample with `li`;
//! - per batch of eight hits: every registered BSDF that is not all-delta (diffuse, rough
//!   conductor, Nori's microfacet, plastic, rough plastic; one- or two-sided). The batch
//!   takes the BSDF type and sidedness of its first such hit; hits of another type or
//!   sidedness, on all-delta BSDFs (conductor, dielectric, mirror: their estimator draws no
//!   light sample), or on nothing, are finished lane by lane with `li_hit`.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

mod light;
mod shade;
mod tables;
#[cfg(test)]
mod tests;

use super::direct::Direct;
use super::Strategy;
use crate::bsdf::{Bsdf, BsdfKind, BsdfVisitor, Diffuse, Registered};
use crate::geometry::ray_packet::bits;
use crate::geometry::{Accel, PacketHits, RayPacket};
use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use crate::sampler::SamplerLanes;
use crate::scene::Scene;
use light::{LightDraws, SphereDraws};
use tables::{LaneShape, LaneTables};

// A pixel's eight samples trace their camera and shadow rays as one packet.
const _: () = assert!(LANES == crate::geometry::ray_packet::PACKET);

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
    /// Each covered lane's material (an index into `Scene::materials`).
    material: [u32; LANES],
    /// The batch's first material, whose BSDF type and sidedness every covered lane has.
    first: u32,
    /// Whether every covered lane has the material `first`.
    uniform: bool,
    pub(super) two_sided: bool,
    /// Accelerator skip ids of the hit triangle (all rays, emitter-only structure).
    pub(super) skip: [u32; LANES],
    emitter_skip: [u32; LANES],
    /// Their estimate so far (the emission seen at the hit).
    le: V3x8,
    /// The lanes shaded here.
    pub(super) covered: u32,
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
    pub(super) bsdf_delta: [bool; LANES],
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

/// The direct estimator with its lane kernel: `li_lanes` shades eight camera samples at once
/// where the module comment's rule covers them, and leaves the rest to `Direct::li`.
pub struct LaneKernel<'a> {
    /// The scalar estimator, for the samples the lanes do not cover.
    pub direct: Direct<'a>,
    /// The tables the lanes read, if they cover the scene and strategy.
    tables: Option<LaneTables<'a>>,
}

impl<'a> LaneKernel<'a> {
    /// The estimator of `strategy` on `scene`, with the lane tables where they cover it.
    pub fn new(scene: &'a Scene, strategy: Strategy) -> Self {
        let direct = Direct::new(scene, strategy);
        let tables = tables::lane_setup(scene, &direct.strategy, &direct.selector);
        LaneKernel { direct, tables }
    }

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
        let direct = &self.direct;
        let Some(tables) = &self.tables else {
            return std::array::from_fn(|i| match i < n {
                true => direct.li(&rays.ray(i), &mut rng.lane(i)),
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
        let mut u = [u0, u1, u2, u3, u4, u5, u6];
        let scene = direct.scene;
        scene.intersect8_into(rays, (1 << n) - 1, &mut hits.camera);
        self.camera_hits(&tables.shapes, rays, &at_hit, &mut out, hits);
        if hits.covered == 0 {
            return out;
        }
        if direct.ris.is_some() {
            ris_numbers(direct, &at_hit, hits, &mut u, &mut draws.p_div);
        }
        let mut spheres = SphereDraws::default();
        let small = tables.small_lights.as_deref();
        let selector = &direct.selector;
        LightDraws::draw(
            selector,
            &tables.lights,
            small,
            &u[0],
            &u[1],
            &hits.camera,
            draws,
            &mut spheres,
        );
        let (h, ld, sd) = (&*hits, &*draws, &spheres);
        // The study's diffuse batches lit by meshes inline here; every other BSDF type, and
        // batches with a sphere light (a branch per lane), shade out of line, so that this
        // instance compiles as it would alone.
        match &scene.materials[hits.first as usize].kind {
            BsdfKind::Diffuse(_) if !spheres.any => {
                self.shade_batch::<Diffuse, false>(h, ld, sd, &u, shaded, &mut out)
            }
            kind => kind.visit(Batch {
                kernel: self,
                h,
                ld,
                sd,
                u: &u,
                shaded,
                out: &mut out,
            }),
        }
        out
    }

    /// Whether `li_lanes` shades in lanes for this scene and strategy.
    pub fn has_lanes(&self) -> bool {
        self.tables.is_some()
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
        let direct = &self.direct;
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
            // The batch takes the BSDF type and sidedness of its first covered hit; hits of
            // another (at a pixel straddling two materials) and uncovered materials take the
            // scalar path.
            let covered = shape
                .material
                .is_some_and(|m| m.key == batch.get_or_insert(m).key);
            if !covered {
                out[i] = direct.li_hit(&rays.ray(i), &camera.point(i), &mut rng.lane(i));
                continue;
            }
            h.material[i] = shape.material.map_or(0, |m| m.index);
            let mut l = Rgb::ZERO;
            if !direct.strategy.hide_emitters {
                if let Some(e) = shape.emitter {
                    l += direct.scene.emitters[e as usize].le(&camera.point(i), -rays.d(i));
                }
            }
            h.le.set(i, l);
            h.covered |= 1 << i;
            h.skip[i] = Accel::skip_from(shape.skip_base, prim);
            h.emitter_skip[i] = Accel::skip_from(shape.emitter_skip_base, prim);
        }
        if let Some(m) = batch {
            (h.first, h.two_sided, h.uniform) = (m.index, m.two_sided, false);
        }
    }

    /// `camera_hits`'s loop for hits that all lie on one shape (most pixels' eight samples):
    /// its row read once for all lanes. False, with `h` untouched, for a material the lanes
    /// do not cover. It spells out the loop's material match and cover steps for all lanes
    /// at once: helpers shared with the loop, per lane or per lane mask, cost measurably more
    /// instructions on the bundled scenes.
    #[inline(always)]
    fn fill_one_shape(&self, shape: &LaneShape, rays: &RayPacket, h: &mut CameraHits) -> bool {
        let direct = &self.direct;
        let camera = &h.camera;
        let Some(m) = shape.material else {
            return false;
        };
        // Lanes without a hit take the material too: their samples are computed and dropped.
        (h.first, h.two_sided, h.uniform) = (m.index, m.two_sided, true);
        if !direct.strategy.hide_emitters {
            if let Some(e) = shape.emitter {
                let emitter = &direct.scene.emitters[e as usize];
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
}

/// A batch handed to the code of its BSDF type (`BsdfKind::visit`).
struct Batch<'k, 'a> {
    kernel: &'k LaneKernel<'a>,
    h: &'k CameraHits,
    ld: &'k LightDraws,
    sd: &'k SphereDraws,
    u: &'k [[f32; LANES]; 7],
    shaded: &'k mut Shaded,
    out: &'k mut [Rgb; LANES],
}

impl BsdfVisitor for Batch<'_, '_> {
    type Out = ();

    #[inline(always)]
    fn visit<B: Bsdf + Registered>(self, _: &B) {
        // All-delta BSDFs never start a batch (`tables::lane_setup`).
        if B::DELTA {
            return;
        }
        let Batch {
            kernel,
            h,
            ld,
            sd,
            u,
            shaded,
            out,
        } = self;
        match sd.any {
            true => kernel.shade_batch_out_of_line::<B, true>(h, ld, sd, u, shaded, out),
            false => kernel.shade_batch_out_of_line::<B, false>(h, ld, sd, u, shaded, out),
        }
    }
}

/// RIS over several candidates, whose draw `li` makes with 4M + 1 numbers: each covered
/// lane's draw is `Direct::ris_for_lane` from the lane's own sampler. The kept candidate's
/// numbers replace the lane's light numbers (the lane draw takes it again, bitwise as the
/// scalar candidate), the numbers that follow are its BSDF numbers, and `p_div` is the
/// density the lane's light estimate divides by. A lane that kept no candidate divides by
/// infinity: its light sample, drawn from its unused numbers, adds zero, as in `li`.
#[inline(never)]
fn ris_numbers<L: SamplerLanes>(
    direct: &Direct,
    at_hit: &L,
    h: &CameraHits,
    u: &mut [[f32; LANES]; 7],
    p_div: &mut [f32; LANES],
) {
    use crate::sampler::Sampler;
    for i in bits(h.covered) {
        let mut one = at_hit.lane(i);
        match direct.ris_for_lane(&h.camera.point(i), h.d.get(i), &mut one) {
            Some((dims, p)) => {
                [u[0][i], u[1][i], u[2][i], u[3][i]] =
                    [dims.select, dims.primitive, dims.point.x, dims.point.y];
                p_div[i] = p;
            }
            None => p_div[i] = f32::INFINITY,
        }
        let b = one.bsdf();
        [u[4][i], u[5][i], u[6][i]] = [b.lobe, b.direction.x, b.direction.y];
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
pub(super) fn mask_of(flags: &[bool; LANES]) -> u32 {
    let mut m = 0;
    for (i, &f) in flags.iter().enumerate() {
        m |= (f as u32) << i;
    }
    m
}
