//! The ray-tracing limit: how fast the BVH alone traces the ray mix of a power-MIS render
//! (per camera sample: one closest-hit camera ray, one shadow ray, one BSDF ray asked for the
//! emitter it ends on, with the renderer's query: see `Scene::bsdf_ray_hit`).
//!
//! The mix is replayed rather than recorded, so the render loop carries no instrumentation:
//! camera rays exactly as the renderer makes them, shadow rays to points drawn by the scene's
//! own light sampler, and BSDF rays drawn by the hit's own material. Like the renderer, the
//! mix has no shadow ray for a light sample the BSDF or the light gives zero (below a one-sided
//! surface's horizon, outside a narrow lobe) and no BSDF ray where the material draws none:
//! rays the renderer never traces would count as traversal it does not do. The camera rays
//! and the shadow rays of each pixel's groups of `LANES` samples are traced as packets, as
//! the renderer traces them (`Scene::intersect8_into`, `Accel::occluded8`); BSDF rays one by one
//! past a box reject of the group's rays in lanes (`bsdf_queries`).
//! Every timing traces the mix a chunk of 64 groups at a time, each chunk copied into cache
//! first and untimed (`Warm`): the renderer makes its rays in registers, not in a stream of
//! tens of MB from memory.

use crate::emitter::{EmitterSelection, EmitterSelector, LightSampling};
use crate::geometry::ray_packet::bits;
use crate::geometry::shape::intersect_sphere;
use crate::geometry::{Hit, PacketHits, Ray, RayPacket, ShapeKind};
use crate::math::{Frame, Rgb};
use crate::rng::{Rng, LANES};
use crate::scene::Scene;
use std::time::Instant;

/// The seed whose samples the mix holds: a render with it traces the same rays.
pub const MIX_SEED: u64 = 7;

/// The mix, each ray stored once, in the renderer's packets.
pub struct RayMix {
    /// Per group of up to `LANES` consecutive samples of a pixel: its camera and shadow rays
    /// as the renderer's packets, and each sample's BSDF ray.
    pub packets: Vec<Packets>,
    /// BSDF rays with the triangle the emitter-only structure skips for them.
    pub bsdf: Vec<(Ray, u32)>,
    pub n_camera: usize,
    pub n_shadow: usize,
}

#[derive(Clone, Copy)]
pub struct Packets {
    /// Rays, and their active-lane masks (apart: a (packet, mask) pair pads to a whole
    /// packet alignment).
    pub camera: RayPacket,
    pub shadow: RayPacket,
    pub camera_mask: u32,
    pub shadow_mask: u32,
    /// Per lane, its BSDF ray's index in `RayMix::bsdf`, or `NONE`.
    pub bsdf: [u32; LANES],
}

/// `Packets::bsdf` of a lane without a BSDF ray.
pub const NONE: u32 = u32::MAX;

#[cfg(test)]
impl RayMix {
    pub fn camera_rays(&self) -> impl Iterator<Item = Ray> + '_ {
        self.packets
            .iter()
            .flat_map(|p| lanes(&p.camera, p.camera_mask))
    }

    pub fn shadow_rays(&self) -> impl Iterator<Item = Ray> + '_ {
        self.packets
            .iter()
            .flat_map(|p| lanes(&p.shadow, p.shadow_mask))
    }
}

/// The active rays of a packet.
fn lanes(rays: &RayPacket, mask: u32) -> impl Iterator<Item = Ray> + '_ {
    (0..LANES)
        .filter(move |i| mask >> i & 1 != 0)
        .map(|i| rays.ray(i))
}

/// The ray mix of `spp` samples per pixel of the scene's camera, emitters chosen by `selection`.
pub fn ray_mix(scene: &Scene, spp: u32, selection: EmitterSelection) -> RayMix {
    let cam = &scene.camera;
    let selector = EmitterSelector::new(&scene.emitters, &scene.shapes, selection);
    let mut mix = RayMix {
        packets: Vec::new(),
        bsdf: Vec::new(),
        n_camera: 0,
        n_shadow: 0,
    };
    let empty = RayPacket::default();
    for y in 0..cam.height {
        for x in 0..cam.width {
            for s in 0..spp {
                let lane = s as usize % LANES;
                if lane == 0 {
                    mix.packets.push(Packets {
                        camera: empty,
                        shadow: empty,
                        camera_mask: 0,
                        shadow_mask: 0,
                        bsdf: [NONE; LANES],
                    });
                }
                let p = mix.packets.last_mut().expect("pushed above");
                let mut rng = Rng::for_sample(MIX_SEED, (y * cam.width + x) as u64, s as u64);
                let ray = cam.generate_ray(x, y, &mut rng);
                p.camera.set(lane, &ray);
                p.camera_mask |= 1 << lane;
                mix.n_camera += 1;
                let Some(hit) = scene.intersect(&ray) else {
                    continue;
                };
                let sp = hit.sp;
                let frame = Frame::from_normal(sp.ns);
                let wi = frame.to_local(-ray.d);
                let mat = scene.material(&sp);
                let e = selector.sample(sp.p, sp.ns, rng.next_f32());
                let (u_prim, u) = (rng.next_f32(), rng.next_2d());
                if let Some(ls) = e.and_then(|(e, _)| {
                    scene.emitters[e].sample(&scene.shapes, sp.p, u_prim, u, LightSampling::Area)
                }) {
                    let (f, _) = mat.eval_pdf(wi, frame.to_local(ls.wi));
                    if f != Rgb::ZERO && ls.li != Rgb::ZERO {
                        p.shadow.set(lane, &scene.shadow_ray(&sp, &ls));
                        p.shadow_mask |= 1 << lane;
                        mix.n_shadow += 1;
                    }
                }
                let u1 = rng.next_f32();
                if let Some(bs) = mat.sample(wi, u1, rng.next_2d()) {
                    p.bsdf[lane] = mix.bsdf.len() as u32;
                    mix.bsdf.push(scene.bsdf_ray(&sp, frame.to_world(bs.wo)));
                }
            }
        }
    }
    mix
}

pub struct RayLimit {
    /// Rays per second of closest-hit queries (camera and BSDF rays, so that directlab and
    /// obvhs trace the same queries) and of occlusion queries.
    pub closest_per_s: f64,
    pub occlusion_per_s: f64,
    /// Seconds the renderer's queries need for the mix of one camera sample, each ray type
    /// traced back to back.
    pub seconds_per_sample: f64,
}

impl RayLimit {
    /// Rates from the best (closest-hit, occlusion) seconds for the whole mix.
    fn from_seconds(mix: &RayMix, best: (f64, f64)) -> RayLimit {
        let n_closest = (mix.n_camera + mix.bsdf.len()) as f64;
        RayLimit {
            closest_per_s: n_closest / best.0,
            occlusion_per_s: mix.n_shadow as f64 / best.1,
            seconds_per_sample: (best.0 + best.1) / mix.n_camera as f64,
        }
    }
}

/// directlab's traversal of the mix against a render of the scene.
pub struct Limit {
    /// Best rates, each ray type traced back to back.
    pub by_type: RayLimit,
    /// BSDF rays per second with the renderer's emitter query.
    pub bsdf_query_per_s: f64,
    /// Best seconds per camera sample for the mix traced in the renderer's order: the
    /// camera rays of `LANES` samples of a pixel, then each sample's shadow and BSDF ray.
    pub render_order_seconds_per_sample: f64,
    /// Best samples per second of the render.
    pub render_per_s: f64,
    /// Share of render time outside traversal, median over the repetitions, with traversal
    /// timed in the renderer's order and by type. Each repetition times the mix and the
    /// render one after the other, so a slow spell of the machine hits both sides of the
    /// ratio instead of one.
    pub share_outside: f64,
    pub share_outside_by_type: f64,
    /// Render seconds per sample outside traversal (render order), median over the
    /// repetitions: the share's numerator in absolute terms, which a faster traversal does
    /// not move (it raises the share) and which compares across renderers.
    pub outside_seconds_per_sample: f64,
}

fn median(x: Vec<f64>) -> f64 {
    use statrs::statistics::{Data, Median};
    Data::new(x).median()
}

/// Times the mix on one thread and `render` (one 1-thread render, returning its samples per
/// second), alternately, `repeat` times.
pub fn measure(scene: &Scene, mix: &RayMix, repeat: u32, mut render: impl FnMut() -> f64) -> Limit {
    // Best seconds of: camera rays, BSDF rays as closest hits, BSDF rays as the renderer
    // asks them, shadow rays, and the whole mix in the renderer's order.
    let mut best = [f64::INFINITY; 5];
    let mut best_render = 0.0f64;
    let (mut shares, mut shares_by_type, mut outside) = (Vec::new(), Vec::new(), Vec::new());
    let mut sink = 0usize;
    let n = mix.n_camera as f64;
    let (mut warm, mut hits) = (Warm::default(), PacketHits::default());
    for _ in 0..repeat.max(1) {
        // Each ray type back to back, within each warm chunk.
        let mut by_type = [0.0; 4];
        for chunk in mix.packets.chunks(CHUNK) {
            let w = warm.load(mix, chunk);
            let t = Instant::now();
            for p in &w.packets {
                sink += packet_prims(scene, &p.camera, p.camera_mask, &mut hits);
            }
            let t1 = Instant::now();
            for (r, _) in &w.bsdf {
                sink += prim(scene.intersect(r));
            }
            let t2 = Instant::now();
            for b in &w.bsdf_packets {
                sink += bsdf_queries(scene, b);
            }
            let t3 = Instant::now();
            for p in &w.packets {
                sink += scene.accel.occluded8(&p.shadow, p.shadow_mask) as usize;
            }
            let t4 = Instant::now();
            for (k, (a, b)) in [(t, t1), (t1, t2), (t2, t3), (t3, t4)]
                .into_iter()
                .enumerate()
            {
                by_type[k] += (b - a).as_secs_f64();
            }
        }
        let [camera, bsdf_closest, bsdf_query, occl] = by_type;
        let (s, in_order) = trace_in_order(scene, mix, mix.packets.chunks(CHUNK));
        sink += s;
        let render_per_s = render();
        shares.push(1.0 - in_order / n * render_per_s);
        outside.push(1.0 / render_per_s - in_order / n);
        shares_by_type.push(1.0 - (camera + bsdf_query + occl) / n * render_per_s);
        best_render = best_render.max(render_per_s);
        for (b, x) in best
            .iter_mut()
            .zip([camera, bsdf_closest, bsdf_query, occl, in_order])
        {
            *b = b.min(x);
        }
    }
    std::hint::black_box(sink);
    let [camera, bsdf_closest, bsdf_query, occl, in_order] = best;
    Limit {
        by_type: RayLimit {
            closest_per_s: (mix.n_camera + mix.bsdf.len()) as f64 / (camera + bsdf_closest),
            occlusion_per_s: mix.n_shadow as f64 / occl,
            seconds_per_sample: (camera + bsdf_query + occl) / n,
        },
        bsdf_query_per_s: mix.bsdf.len() as f64 / bsdf_query,
        render_order_seconds_per_sample: in_order / n,
        render_per_s: best_render,
        share_outside: median(shares),
        share_outside_by_type: median(shares_by_type),
        outside_seconds_per_sample: median(outside),
    }
}

/// A checksum bit of a hit, so that no query's answer goes unused.
fn prim(h: Option<Hit>) -> usize {
    h.map_or(0, |h| h.sp.prim as usize & 1)
}

/// The camera packet's hits, traced as the renderer traces them: into hits reused from
/// packet to packet (`LaneScratch`).
fn packet_prims(scene: &Scene, rays: &RayPacket, active: u32, h: &mut PacketHits) -> usize {
    scene.intersect8_into(rays, active, h);
    (0..LANES).map(|i| prim(h.get(i))).sum()
}

/// Groups per warm chunk: their rays (about 70 kB) fit a core's L2 cache (512 kB on the
/// EPYC) with room to spare for the BVH.
const CHUNK: usize = 64;

/// One chunk of groups and its BSDF rays, copied into small buffers before they are traced.
///
/// The renderer makes each ray in registers just before tracing it; the mix is tens of MB
/// in memory. Streamed from memory, the replay traced the Cornell box's mix at 10.4 to 18.4 M
/// samples/s in bench runs where the render kept its speed, and 14 % slower than the same
/// rays copied chunk by chunk (median of 15 interleaved pairs, slower in 13). The copy
/// (untimed) brings the chunk's rays into cache; only the tracing is timed.
#[derive(Default)]
struct Warm {
    packets: Vec<Packets>,
    /// The chunk's BSDF rays; the copied packets' `bsdf` indices point here.
    bsdf: Vec<(Ray, u32)>,
    /// Per packet, its BSDF rays as the renderer holds them (see `bsdf_queries`).
    bsdf_packets: Vec<BsdfPacket>,
}

/// A group's BSDF rays in lanes, each lane's emitter skip id, and the mask of lanes with one.
type BsdfPacket = (RayPacket, [u32; LANES], u32);

/// The renderer's emitter queries of a group's BSDF rays: `Scene::bsdf_rays_may_hit` in
/// lanes, then `bsdf_ray_hit_traced` of each ray it lets through.
#[inline(always)]
fn bsdf_queries(scene: &Scene, (rays, skips, active): &BsdfPacket) -> usize {
    bits(scene.bsdf_rays_may_hit::<true>(rays, *active))
        .map(|i| prim(scene.bsdf_ray_hit_traced(&rays.ray(i), skips[i])))
        .sum()
}

impl Warm {
    fn load(&mut self, mix: &RayMix, chunk: &[Packets]) -> &Warm {
        // A chunk's BSDF rays are one run of `mix.bsdf`, in order.
        let mut ids = chunk.iter().flat_map(|p| p.bsdf).filter(|&b| b != NONE);
        let first = ids.next();
        let lo = first.map_or(0, |b| b as usize);
        let hi = ids.next_back().or(first).map_or(lo, |b| b as usize + 1);
        self.packets.clear();
        self.packets.extend(chunk.iter().map(|p| {
            let mut p = *p;
            for b in p.bsdf.iter_mut().filter(|b| **b != NONE) {
                *b -= lo as u32;
            }
            p
        }));
        self.bsdf.clear();
        self.bsdf.extend_from_slice(&mix.bsdf[lo..hi]);
        self.bsdf_packets.clear();
        for p in &self.packets {
            let mut b: BsdfPacket = (RayPacket::default(), [0; LANES], 0);
            for (i, &k) in p.bsdf.iter().enumerate().filter(|(_, &k)| k != NONE) {
                let (ray, skip) = &self.bsdf[k as usize];
                b.0.set(i, ray);
                (b.1[i], b.2) = (*skip, b.2 | 1 << i);
            }
            self.bsdf_packets.push(b);
        }
        self
    }
}

/// The groups in the renderer's order, chunk by warm chunk: each group's camera packet, its
/// shadow packet, then its BSDF rays, as the renderer's queries. Returns a
/// checksum of the answers and the seconds spent tracing.
fn trace_in_order<'a>(
    scene: &Scene,
    mix: &RayMix,
    chunks: impl Iterator<Item = &'a [Packets]>,
) -> (usize, f64) {
    let (mut sink, mut seconds) = (0, 0.0);
    let (mut warm, mut hits) = (Warm::default(), PacketHits::default());
    for chunk in chunks {
        let w = warm.load(mix, chunk);
        let t = Instant::now();
        for (p, b) in w.packets.iter().zip(&w.bsdf_packets) {
            sink += packet_prims(scene, &p.camera, p.camera_mask, &mut hits);
            sink += scene.accel.occluded8(&p.shadow, p.shadow_mask) as usize;
            sink += bsdf_queries(scene, b);
        }
        seconds += t.elapsed().as_secs_f64();
    }
    (sink, seconds)
}

/// The share outside traversal on `threads` threads, and that time per sample in thread time
/// (seconds per sample times `threads`): the mix traced in the renderer's order by `threads`
/// threads at once, each taking every `threads`-th run of `CHUNK` groups, against `render`
/// (one render on `threads` threads, returning its samples per second), alternately,
/// `repeat` times; medians. Traversal is the tracing time `trace_in_order` counts, summed
/// over the threads. Mitsuba renders on no fewer than two threads: this is the number its
/// script's share compares with.
pub fn measure_threads(
    scene: &Scene,
    mix: &RayMix,
    threads: usize,
    repeat: u32,
    mut render: impl FnMut() -> f64,
) -> (f64, f64) {
    let n = mix.n_camera as f64;
    let (mut shares, mut outside) = (Vec::new(), Vec::new());
    let mut sink = 0usize;
    for _ in 0..repeat.max(1) {
        let (s, thread_seconds) = std::thread::scope(|s| {
            let runs: Vec<_> = (0..threads)
                .map(|k| {
                    s.spawn(move || {
                        let mine = mix.packets.chunks(CHUNK).skip(k).step_by(threads);
                        trace_in_order(scene, mix, mine)
                    })
                })
                .collect();
            runs.into_iter()
                .map(|r| r.join().expect("tracing thread"))
                .fold((0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
        });
        sink += s;
        let render_seconds = threads as f64 / render();
        shares.push(1.0 - thread_seconds / n / render_seconds);
        outside.push(render_seconds - thread_seconds / n);
    }
    std::hint::black_box(sink);
    (median(shares), median(outside))
}

/// Image rows per band of `measure_interleaved`.
pub const BAND_ROWS: u32 = 8;

/// The share outside traversal with the mix's tracing and the render paired band by band
/// (`BAND_ROWS` image rows, 10-80 ms each at the bench's 64 spp): each band's rays traced in the renderer's order,
/// then the same band rendered at `spp` samples per pixel and the mix's seed (so that its
/// first `mix_spp` samples are the rays traced), the order swapped every other band. On
/// `threads` threads, each takes every `threads`-th band, and both sides count thread time.
/// `measure` and `measure_threads` alternate a whole render and a whole replay, seconds
/// apart, and a slow spell of this VM that hits one of them moved their share by ten points
/// or more between runs; here both sides of each band see the same spell. Returns the median
/// over `repeat` passes of (share, seconds of thread time per sample outside traversal).
/// `mix_spp` must be the mix's.
pub fn measure_interleaved(
    kernel: &crate::integrator::LaneKernel,
    mix: &RayMix,
    (mix_spp, spp): (u32, u32),
    threads: usize,
    repeat: u32,
) -> (f64, f64) {
    use crate::render::{render_rows, RenderSettings};
    let (scene, threads) = (kernel.direct.scene, threads.max(1));
    let (w, h) = (scene.camera.width, scene.camera.height);
    let per_row = w as usize * (mix_spp as usize).div_ceil(LANES);
    assert_eq!(
        mix.packets.len(),
        per_row * h as usize,
        "a mix of {mix_spp} spp"
    );
    let settings = RenderSettings {
        spp,
        seed: MIX_SEED,
        first_sample: 0,
        threads: Some(1),
        progress: None,
        sampling: Default::default(),
    };
    let bands: Vec<_> = (0..h)
        .step_by(BAND_ROWS as usize)
        .map(|y0| y0..(y0 + BAND_ROWS).min(h))
        .collect();
    // One thread's bands: (sink, seconds tracing, seconds rendering).
    let run = |mine: &mut dyn Iterator<Item = &std::ops::Range<u32>>| {
        let mut scratch = crate::integrator::LaneScratch::default();
        let (mut sink, mut traced, mut rendered) = (0.0, 0.0, 0.0);
        for (k, rows) in mine.enumerate() {
            let band = &mix.packets[rows.start as usize * per_row..rows.end as usize * per_row];
            // Trace then render on even bands, render then trace on odd ones.
            for trace in [k % 2 == 0, k % 2 == 1] {
                if trace {
                    let (s, seconds) = trace_in_order(scene, mix, band.chunks(CHUNK));
                    (sink, traced) = (sink + s as f64, traced + seconds);
                } else {
                    let t = Instant::now();
                    sink += render_rows(kernel, rows.clone(), &settings, &mut scratch);
                    rendered += t.elapsed().as_secs_f64();
                }
            }
        }
        (sink, traced, rendered)
    };
    let (mut shares, mut outside) = (Vec::new(), Vec::new());
    let mut sink = 0.0;
    for _ in 0..repeat.max(1) {
        let (s, traced, rendered) = std::thread::scope(|sc| {
            let runs: Vec<_> = (0..threads)
                .map(|t| {
                    let (run, bands) = (&run, &bands);
                    sc.spawn(move || run(&mut bands.iter().skip(t).step_by(threads)))
                })
                .collect();
            runs.into_iter()
                .map(|r| r.join().expect("band thread"))
                .fold((0.0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2))
        });
        sink += s;
        let traced = traced / mix.n_camera as f64;
        let rendered = rendered / (w as f64 * h as f64 * spp as f64);
        shares.push(1.0 - traced / rendered);
        outside.push(rendered - traced);
    }
    std::hint::black_box(sink);
    (median(shares), median(outside))
}

/// The same mix through obvhs's own CwBvh traversal and triangle test (spheres use
/// directlab's sphere test): what the library gives without directlab's traversal. Not a
/// renderer: its triangle test is not watertight and it culls hits closer than t = 1e-4.
pub fn measure_obvhs(scene: &Scene, mix: &RayMix, repeat: u32) -> RayLimit {
    use obvhs::{aabb::Aabb, cwbvh::builder::build_cwbvh, triangle::Triangle, BvhBuildParams};
    enum Prim {
        Tri(Triangle),
        Sphere(glam::Vec3, f32),
    }
    let mut prims = Vec::new();
    for s in &scene.shapes {
        match &s.kind {
            ShapeKind::Mesh(m) => prims.extend((0..m.indices.len()).map(|t| {
                let [v0, v1, v2] = m.vertices(t).map(Into::into);
                Prim::Tri(Triangle { v0, v1, v2 })
            })),
            ShapeKind::Sphere(s) => prims.push(Prim::Sphere(s.center, s.radius)),
        }
    }
    let aabbs: Vec<Aabb> = prims
        .iter()
        .map(|p| match p {
            Prim::Tri(t) => Aabb::from_points(&[t.v0, t.v1, t.v2]),
            Prim::Sphere(c, r) => {
                let (c, r) = (glam::Vec3A::from(*c), glam::Vec3A::splat(*r));
                Aabb::new(c - r, c + r)
            }
        })
        .collect();
    let bvh = build_cwbvh(
        &aabbs,
        BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let ray = |r: &Ray| obvhs::ray::Ray::new(r.o.into(), r.d.into(), r.tmin, r.tmax);
    let prim = |r: &obvhs::ray::Ray, i: usize| match &prims[bvh.primitive_indices[i] as usize] {
        Prim::Tri(t) => t.intersect(r),
        Prim::Sphere(c, rad) => {
            let (o, d) = (r.origin.into(), r.direction.into());
            intersect_sphere(o, d, r.tmin, r.tmax, *c, *rad).unwrap_or(f32::INFINITY)
        }
    };
    let mut best = (f64::INFINITY, f64::INFINITY);
    let mut sink = 0usize;
    let mut warm = Warm::default();
    for _ in 0..repeat.max(1) {
        let (mut closest, mut occl) = (0.0, 0.0);
        for chunk in mix.packets.chunks(CHUNK) {
            let w = warm.load(mix, chunk);
            let t = Instant::now();
            let camera = w
                .packets
                .iter()
                .flat_map(|p| lanes(&p.camera, p.camera_mask));
            for r in camera.chain(w.bsdf.iter().map(|b| b.0)) {
                let mut hit = obvhs::ray::RayHit::none();
                sink += bvh.ray_traverse(ray(&r), &mut hit, prim) as usize;
            }
            let t1 = Instant::now();
            for r in w
                .packets
                .iter()
                .flat_map(|p| lanes(&p.shadow, p.shadow_mask))
            {
                sink += !bvh.ray_traverse_miss(ray(&r), prim) as usize;
            }
            closest += (t1 - t).as_secs_f64();
            occl += t1.elapsed().as_secs_f64();
        }
        best = (best.0.min(closest), best.1.min(occl));
    }
    std::hint::black_box(sink);
    RayLimit::from_seconds(mix, best)
}

#[cfg(test)]
#[path = "raylimit_tests.rs"]
mod tests;
