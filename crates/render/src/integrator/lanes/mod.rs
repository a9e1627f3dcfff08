//! The lane kernel: the direct estimator for eight camera samples of a pixel at once, in
//! vector lanes. `LaneKernel` wraps the scalar estimator (`Direct`) and never restates it.
//!
//! The camera rays and the shadow rays of the eight samples are made and traced as packets,
//! one array per component (`RayPacket`, see `geometry::packet`), the BSDF rays through a
//! reject in lanes and then one at a time. Everything between them (shading frames, light
//! points, densities, BSDF values, MIS weights, the shadow and BSDF rays) runs as loops over
//! the eight samples, in structure-of-arrays form, which the compiler turns into vector code.
//!
//! The estimators are not restated here: each is written once against
//! `strategies::Techniques`, which `Direct` implements for one hit and `shade::Lanes` for the
//! covered lanes of a batch (a light sample, a BSDF sample, both, or a per-lane choice of
//! technique, each for a mask of lanes). Each step's loop body calls the scalar code
//! `Direct`'s technique calls, in the same order, so every sample is bitwise what `li` gives
//! it (`render_lanes_tests` checks this on random scenes, for every strategy).
//!
//! There is one shading function per technique, generic over the BSDF type through the lane
//! methods of `Bsdf` (`lane_shared`, `eval_pdf_shared`, `sample_lanes`), whose defaults call
//! the BSDF's own eval, pdf and sample lane by lane: a new BSDF runs in lanes as registered.
//!
//! What runs in lanes: everything.
//! - strategy: every registered estimator (light or BSDF sampling alone, MIS with N light
//!   and M BSDF samples under either heuristic, one-sample MIS), every emitter choice (the
//!   point-dependent ones at each lane's hit; RIS's candidates drawn lane by lane with `li`'s
//!   own draw, `ris_numbers`), every sampler;
//! - lights: area sampling of mesh and sphere lights reads the lane tables (`tables`) for
//!   eight lanes at once; solid-angle sampling, point lights and any emitter the tables do
//!   not hold draw each lane's light with `Direct::candidate` inside the lane loop;
//! - per batch of eight hits: every registered BSDF that is not all-delta (diffuse, rough
//!   conductor, Nori's microfacet, plastic, rough plastic; one- or two-sided). The batch
//!   takes the BSDF type and sidedness of its first such hit. The per-lane fallback, lane by
//!   lane with `li_hit`: hits of another type or sidedness than the batch's, on all-delta
//!   BSDFs (conductor, dielectric, mirror: their estimator draws no light sample), on a rough
//!   conductor of coloured index (`Bsdf::lane_covered`), or on nothing.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

mod light;
mod shade;
mod steps;
mod tables;
#[cfg(test)]
mod tests;

use super::direct::Direct;
use super::strategies::First;
use super::Strategy;
use crate::bsdf::{Bsdf, BsdfKind, BsdfVisitor, Diffuse, Registered};
use crate::counts::Counts;
use crate::geometry::ray_packet::bits;
use crate::geometry::{Accel, PacketHits, RayPacket};
use crate::math::{Rgb, V3x8};
use crate::rng::LANES;
use crate::sampler::SamplerLanes;
use light::{LightDraws, SphereDraws};
use shade::{Lanes, Pre};
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

/// The lanes' rays and candidate contributions, before visibility. Each technique writes
/// the fields of its lanes (area sampling's and the BSDF's: every lane).
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
/// what it reads; the fields some batches write only in part are cleared per batch. They
/// are separate references in the shading functions' arguments, not fields of one
/// structure: a reference argument tells the compiler that nothing else writes its target;
/// a reference in a field does not.
#[derive(Default)]
pub struct LaneScratch {
    hits: CameraHits,
    draws: LightDraws,
    shaded: Shaded,
    /// What the batches shaded with this scratch did, camera rays included
    /// (`counts::Counts`): the render sums its workers'.
    pub counts: Counts,
}

/// Which paths the lanes took, counted for the tests (whose coverage lists need to know that
/// a configuration went where they meant it to).
#[cfg(test)]
#[derive(Default)]
pub(crate) struct Paths(pub(crate) [std::sync::atomic::AtomicU64; Paths::N]);

/// A path `Paths` counts.
#[cfg(test)]
#[derive(Clone, Copy)]
pub(crate) enum Path {
    /// A batch of one material.
    UniformBatch,
    /// A batch of several materials of one BSDF type.
    MixedBatch,
    /// A lane finished by `li_hit`.
    ScalarLane,
    /// A light step that read the lane tables.
    TableLights,
    /// A light step that drew each lane's light with `Direct::candidate`.
    PerLaneLights,
    /// Numbers drawn for some covered lanes only.
    MaskedDraw,
    /// A per-lane choice of technique.
    Split,
}

#[cfg(test)]
impl Paths {
    const N: usize = 7;
    /// The paths' names, in `Path`'s order.
    pub(crate) const NAMES: [&str; Paths::N] = [
        "uniform batch",
        "mixed batch",
        "scalar lane",
        "table lights",
        "per-lane lights",
        "masked draw",
        "split",
    ];
    pub(crate) fn note(&self, what: Path, n: u64) {
        self.0[what as usize].fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    }
    /// The counts by name.
    pub(crate) fn counts(&self) -> Vec<(&'static str, u64)> {
        let get = |a: &std::sync::atomic::AtomicU64| a.load(std::sync::atomic::Ordering::Relaxed);
        Self::NAMES
            .iter()
            .zip(&self.0)
            .map(|(n, a)| (*n, get(a)))
            .collect()
    }
}

/// The direct estimator with its lane kernel: `li_lanes` shades eight camera samples at once
/// where the module comment's rule covers them, and leaves the rest to `Direct::li`.
pub struct LaneKernel<'a> {
    #[cfg(test)]
    pub(crate) paths: Paths,
    /// The scalar estimator, for the samples the lanes do not cover.
    pub direct: Direct<'a>,
    /// The tables the lanes read.
    tables: LaneTables<'a>,
    /// The estimator's first call, whose numbers `li_lanes` draws before tracing.
    first: First,
}

impl<'a> LaneKernel<'a> {
    /// The estimator of `strategy` on `scene`, with its lane tables.
    pub fn new(scene: &'a crate::scene::Scene, strategy: Strategy) -> Self {
        let direct = Direct::new(scene, strategy);
        let tables = tables::lane_setup(scene, &direct.strategy, &direct.selector);
        // RIS draws its candidates lane by lane from each lane's sampler.
        let first = match direct.ris {
            Some(_) => First::Other,
            None => First::of(strategy),
        };
        LaneKernel {
            #[cfg(test)]
            paths: Paths::default(),
            direct,
            tables,
            first,
        }
    }

    /// `li` of the first `n` rays, each with its lane of `rng` (which must stand where `li`
    /// would receive it): in lanes, but for the hits the module comment leaves to `li_hit`.
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
        let (direct, tables) = (&self.direct, &self.tables);
        let LaneScratch {
            hits,
            draws,
            shaded,
            counts,
        } = scratch;
        counts.camera_rays += n as u64;
        let mut out = [Rgb::ZERO; LANES];
        // The numbers of the estimator's first call, drawn from a copy that lanes left to
        // `li_hit` do not see.
        let at_hit = rng.clone();
        let pre = Pre::draw(self.first, rng);
        let scene = direct.scene;
        scene.intersect8_into(rays, (1 << n) - 1, &mut hits.camera);
        self.camera_hits(&tables.shapes, rays, &at_hit, &mut out, hits, counts);
        if hits.covered == 0 {
            return out;
        }
        let kind = &scene.materials[hits.first as usize].kind;
        macro_rules! lanes {
            ($spheres:literal) => {
                Lanes::<L, $spheres> {
                    kernel: self,
                    tables,
                    h: hits,
                    rng,
                    at_hit: &at_hit,
                    pre,
                    draws,
                    o: shaded,
                    c: counts,
                }
            };
        }
        // The study's diffuse batches lit by meshes inline here; every other BSDF type, and
        // scenes with a sphere light (a branch per lane), shade out of line, so that this
        // instance compiles as it would alone.
        match (kind, tables.spheres) {
            (BsdfKind::Diffuse(_), false) => {
                self.shade_batch::<Diffuse, L, false>(lanes!(false), &mut out)
            }
            (kind, false) => kind.visit(Batch {
                x: lanes!(false),
                out: &mut out,
            }),
            (kind, true) => kind.visit(Batch {
                x: lanes!(true),
                out: &mut out,
            }),
        }
        out
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
        c: &mut Counts,
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
                #[cfg(test)]
                self.paths.note(Path::ScalarLane, 1);
                out[i] = direct.li_hit(&rays.ray(i), &camera.point(i), &mut rng.lane(i), c);
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
struct Batch<'k, 'a, 'o, L: SamplerLanes, const SPHERES: bool> {
    x: Lanes<'k, 'a, L, SPHERES>,
    out: &'o mut [Rgb; LANES],
}

impl<L: SamplerLanes, const SPHERES: bool> BsdfVisitor for Batch<'_, '_, '_, L, SPHERES> {
    type Out = ();

    #[inline(always)]
    fn visit<B: Bsdf + Registered>(self, _: &B) {
        // All-delta BSDFs never start a batch (`tables::lane_setup`).
        if B::DELTA {
            return;
        }
        let Lanes {
            kernel,
            tables,
            h,
            rng,
            at_hit,
            pre,
            draws,
            o,
            c,
            ..
        } = self.x;
        kernel.shade_batch_out_of_line::<B, L, SPHERES>(
            tables, h, rng, at_hit, pre, draws, o, c, self.out,
        )
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
