//! The steps of the lane techniques (`shade::Techniques8`): each a loop over the eight lanes
//! that calls the scalar code `Direct`'s technique calls, in the same order, or the traversal
//! of a step's rays. Their arrays are separate reference arguments, which tell the compiler
//! that no store of the kernel changes what another argument points to.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::light::light_sample;
use super::tables::LaneTables;
#[cfg(test)]
use super::Path;
use super::{mask_of, CameraHits, LaneKernel, LightDraws, Shaded, SphereDraws};
use crate::bsdf::{Bsdf, BsdfSample, Material};
use crate::counts::Counts;
use crate::geometry::ray_packet::bits;
use crate::integrator::direct::{by_weight, Weight};
use crate::integrator::Direct;
use crate::math::{Frame, Rgb, V3x8};
use crate::rng::LANES;
use crate::sampler::{LightDims, SamplerLanes};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// What every technique of a batch reads of a lane's hit, computed once per batch: the
/// incident direction in the BSDF's one-sided frame, whether it was mirrored there
/// (`Material::side`), and the BSDF's `lane_shared` value.
#[derive(Default)]
pub(super) struct Setup {
    pub(super) wi: V3x8,
    pub(super) shared: [f32; LANES],
    pub(super) flip: [bool; LANES],
}

/// A lane's light sample before its BSDF value: drawn or not, direction, the densities its
/// weight and its estimate use, radiance, and its shadow ray's ends.
pub(super) struct LaneLight {
    pub(super) drawn: bool,
    pub(super) wi: Vec3,
    pub(super) p_light: f32,
    pub(super) p_div: f32,
    pub(super) li: Rgb,
    pub(super) delta: bool,
    pub(super) origin: Vec3,
    pub(super) target: Vec3,
}

/// Lane i's BSDF of the batch's `b`: `b[0]` for every lane of a batch of one material
/// (`U`), where the compiler then reads its parameters once for all lanes.
#[inline(always)]
pub(super) fn lane_bsdf<B, const U: bool>(b: &[B; LANES], i: usize) -> &B {
    if U {
        &b[0]
    } else {
        &b[i]
    }
}

/// A light sample at the lanes of `live` with numbers `u`, shaded and traced: each lane's
/// term in `o.light`, and the mask of those that reach their light. Out of line, as the
/// other two steps: one instance per BSDF type serves every estimator and sampler (inlined
/// into each of their call sites, the renderer's release build took 113 s instead of 21).
#[inline(never)]
#[allow(clippy::too_many_arguments)] // the lanes' arrays, each its own argument (see `LaneScratch`)
pub(super) fn light_step<B: Bsdf, const SPHERES: bool, const U: bool>(
    k: &LaneKernel,
    tables: &LaneTables,
    b: &[B; LANES],
    h: &CameraHits,
    s: &Setup,
    u: &[[f32; LANES]; 4],
    ld: &mut LightDraws,
    o: &mut Shaded,
    c: &mut Counts,
    live: u32,
    weight: Weight,
) -> u32 {
    let drawn = by_weight!(weight, |w| shade_light::<B, SPHERES, U>(
        k, tables, b, h, s, u, ld, o, live, w
    ));
    count_light(k, live, drawn, c);
    trace_light(k.direct.scene, h, o, live, c)
}

/// What `Direct::light_draw` and `light_finish` count of the light samples of `live`, the
/// BSDF evaluated at those `drawn` (RIS counts its candidates as it draws them).
#[inline(always)]
fn count_light(k: &LaneKernel, live: u32, drawn: u32, c: &mut Counts) {
    let direct = &k.direct;
    if direct.ris.is_none() {
        let n = live.count_ones() as u64;
        c.light_samples += n;
        c.choice_evals += n * direct.selector.evaluations();
    }
    c.bsdf_evals += drawn.count_ones() as u64;
}

/// A BSDF sample at the lanes of `live` with numbers `u`, shaded and traced: each lane's
/// weighted emission (zero where none is reached).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(super) fn bsdf_step<B: Bsdf, const SPHERES: bool, const U: bool>(
    k: &LaneKernel,
    b: &[B; LANES],
    h: &CameraHits,
    s: &Setup,
    u: &[[f32; LANES]; 3],
    o: &mut Shaded,
    c: &mut Counts,
    live: u32,
    weight: Weight,
) -> V3x8 {
    c.bsdf_samples += live.count_ones() as u64;
    shade_bsdf::<B, U>(b, h, s, u, o, live);
    trace_bsdf::<SPHERES>(&k.direct, h, o, live, weight, c)
}

/// `light_step` and then `bsdf_step` at every covered lane, both shaded before either traces
/// its rays, so that their arithmetic overlaps instead of waiting behind a traversal.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(super) fn pair_step<B: Bsdf, const SPHERES: bool, const U: bool>(
    k: &LaneKernel,
    tables: &LaneTables,
    b: &[B; LANES],
    h: &CameraHits,
    s: &Setup,
    ul: &[[f32; LANES]; 4],
    ub: &[[f32; LANES]; 3],
    ld: &mut LightDraws,
    o: &mut Shaded,
    c: &mut Counts,
    light_weight: Weight,
    bsdf_weight: Weight,
) -> (u32, V3x8) {
    let live = h.covered;
    let drawn = by_weight!(light_weight, |w| shade_light::<B, SPHERES, U>(
        k, tables, b, h, s, ul, ld, o, live, w
    ));
    count_light(k, live, drawn, c);
    c.bsdf_samples += live.count_ones() as u64;
    shade_bsdf::<B, U>(b, h, s, ub, o, live);
    let lit = trace_light(k.direct.scene, h, o, live, c);
    (
        lit,
        trace_bsdf::<SPHERES>(&k.direct, h, o, live, bsdf_weight, c),
    )
}

/// Each lane's `Setup`.
#[inline(always)]
pub(super) fn setup<B: Bsdf, const U: bool>(b: &[B; LANES], h: &CameraHits) -> Setup {
    let mut s = Setup::default();
    for i in 0..LANES {
        let frame = Frame::from_normal(h.camera.point(i).ns);
        // `Material::eval_pdf`'s orientation, once for every sample of the hit.
        let (wi, flipped) = Material::side(h.two_sided, frame.to_local(-h.d.get(i)));
        s.wi.set(i, wi);
        (s.shared[i], s.flip[i]) = (lane_bsdf::<B, U>(b, i).lane_shared(wi), flipped);
    }
    s
}

/// The arithmetic of `Direct::light_draw` and `light_finish` before its visibility test, for
/// the lanes of `live` with numbers `u`: each lane's term, whether it may be nonzero, and
/// its shadow ray, in `o`. Area sampling of area lights reads the lane tables for all lanes
/// at once (lanes outside `live` compute garbage, dropped); anything else draws each live
/// lane's light with `Direct::candidate`. Returns the lanes of `live` that drew a light
/// sample (`Direct::light_draw`'s Some).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the lanes' arrays, each its own argument (see `LaneScratch`)
fn shade_light<B: Bsdf, const SPHERES: bool, const U: bool>(
    k: &LaneKernel,
    tables: &LaneTables,
    b: &[B; LANES],
    h: &CameraHits,
    s: &Setup,
    u: &[[f32; LANES]; 4],
    ld: &mut LightDraws,
    o: &mut Shaded,
    live: u32,
    weight: impl Fn(f32, f32) -> f32 + Copy,
) -> u32 {
    let direct = &k.direct;
    let ris = direct.ris.is_some();
    let mut drawn_lanes = 0;
    #[cfg(test)]
    k.paths.note(
        match tables.area() {
            true => Path::TableLights,
            false => Path::PerLaneLights,
        },
        1,
    );
    if tables.area() {
        let mut spheres = SphereDraws::default();
        let small = tables.small_lights.as_deref();
        let selector = &direct.selector;
        LightDraws::draw(
            selector,
            &tables.lights,
            small,
            &u[0],
            &u[1],
            &h.camera,
            ld,
            &mut spheres,
        );
        let (ld, sd) = (&*ld, &spheres);
        for i in 0..LANES {
            let sp = h.camera.point(i);
            let (drawn, wi, pdf_area, li, lsp) = light_sample::<SPHERES>(sp.p, ld, sd, u, i);
            // A RIS lane that kept no candidate drew from numbers 0: no sample (`li`).
            let drawn = drawn && !(ris && ld.p_div[i] == f32::INFINITY);
            drawn_lanes |= (drawn as u32) << i;
            let p_light = ld.pmf[i] * pdf_area;
            let origin = sp.spawn_origin(lsp.p - sp.p);
            let light = LaneLight {
                drawn,
                wi,
                p_light,
                // RIS divides by its own density; the MIS weight takes pmf * pdf (see
                // `LightDraw`).
                p_div: if ris { ld.p_div[i] } else { p_light },
                li,
                delta: false,
                origin,
                target: lsp.spawn_origin(origin - lsp.p),
            };
            light_lane(
                lane_bsdf::<B, U>(b, i),
                s,
                i,
                &sp,
                h.skip[i],
                &light,
                weight,
                o,
            );
        }
        return drawn_lanes & live & !ld.unchosen;
    }
    for i in bits(live) {
        let sp = h.camera.point(i);
        let dims = LightDims {
            select: u[0][i],
            primitive: u[1][i],
            point: Vec2::new(u[2][i], u[3][i]),
        };
        // A RIS lane that kept no candidate has no light sample (`li`): nothing to draw.
        let kept = !(ris && ld.p_div[i] == f32::INFINITY);
        let Some((ls, pmf)) = kept.then(|| direct.candidate(&sp, dims)).flatten() else {
            o.light_ok[i] = false;
            continue;
        };
        drawn_lanes |= 1 << i;
        let (origin, target) = Scene::shadow_ends(&sp, &ls);
        let p_light = pmf * ls.pdf;
        let light = LaneLight {
            drawn: true,
            wi: ls.wi,
            p_light,
            p_div: if ris { ld.p_div[i] } else { p_light },
            li: ls.li,
            delta: ls.delta,
            origin,
            target,
        };
        light_lane(
            lane_bsdf::<B, U>(b, i),
            s,
            i,
            &sp,
            h.skip[i],
            &light,
            weight,
            o,
        );
    }
    drawn_lanes
}

/// `light_finish` before its visibility test, for lane i.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn light_lane<B: Bsdf>(
    b: &B,
    s: &Setup,
    i: usize,
    sp: &crate::geometry::SurfacePoint,
    skip: u32,
    l: &LaneLight,
    weight: impl Fn(f32, f32) -> f32 + Copy,
    o: &mut Shaded,
) {
    let frame = Frame::from_normal(sp.ns);
    let wo = Material::mirror(s.flip[i], frame.to_local(l.wi));
    let (f, pdf) = b.eval_pdf_shared(s.wi.get(i), wo, s.shared[i]);
    let p_bsdf = if l.delta { 0.0 } else { pdf };
    let w = weight(l.p_light, p_bsdf);
    o.light.set(i, f * l.li * (w / l.p_div));
    o.light_ok[i] = l.drawn && f != Rgb::ZERO && l.li != Rgb::ZERO;
    o.shadow
        .set(i, &Scene::shadow_ray_to(l.origin, l.target, skip));
}

/// The shadow rays of the lanes of `live` with a possible term, as one packet: the mask of
/// those that reach their light.
#[inline(always)]
fn trace_light(scene: &Scene, h: &CameraHits, o: &Shaded, live: u32, c: &mut Counts) -> u32 {
    let traced = live & h.covered & mask_of(&o.light_ok);
    c.shadow_rays += traced.count_ones() as u64;
    traced & !scene.accel.occluded8(&o.shadow, traced)
}

/// `bsdf_draw` (`Material::sample` with `Setup`'s orientation) and `bsdf_finish`'s ray, for
/// the lanes of `live` with numbers `u`, in `o`.
#[inline(always)]
fn shade_bsdf<B: Bsdf, const U: bool>(
    b: &[B; LANES],
    h: &CameraHits,
    s: &Setup,
    u: &[[f32; LANES]; 3],
    o: &mut Shaded,
    live: u32,
) {
    let bs = B::sample_lanes(|i| lane_bsdf::<B, U>(b, i), &s.wi, &s.shared, u, live);
    for i in 0..LANES {
        let sp = h.camera.point(i);
        (o.bsdf_ok[i], o.bsdf_pdf[i], o.bsdf_delta[i]) = (bs.ok[i], bs.pdf[i], bs.delta[i]);
        o.bsdf_weight.set(i, bs.weight.get(i));
        // `bsdf_finish`'s ray (`Scene::bsdf_ray`).
        let d = Frame::from_normal(sp.ns).to_world(Material::mirror(s.flip[i], bs.wo.get(i)));
        o.bsdf
            .set(i, &Scene::ray_from(sp.spawn_origin(d), d, h.skip[i]));
    }
}

/// The BSDF rays of the lanes of `live`, put through `bsdf_ray_hit`'s reject in lanes
/// (without sphere lights, its box reject alone); those it lets through are traced one by
/// one. Each lane's weighted emission (zero where none is reached).
#[inline(always)]
fn trace_bsdf<const SPHERES: bool>(
    direct: &Direct,
    h: &CameraHits,
    o: &Shaded,
    live: u32,
    weight: Weight,
    c: &mut Counts,
) -> V3x8 {
    let scene = direct.scene;
    let rays = &o.bsdf;
    let open = live & h.covered & mask_of(&o.bsdf_ok);
    let mut out = V3x8::default();
    let traced = scene.bsdf_rays_may_hit::<SPHERES>(rays, open);
    c.bsdf_rays += traced.count_ones() as u64;
    c.bsdf_rejected += (open & !traced).count_ones() as u64;
    for i in bits(traced) {
        let ray = rays.ray(i);
        if let Some(hit) = scene.bsdf_ray_hit_traced(&ray, h.emitter_skip[i]) {
            let bs = BsdfSample {
                wo: Vec3::ZERO,
                weight: o.bsdf_weight.get(i),
                pdf: o.bsdf_pdf[i],
                delta: o.bsdf_delta[i],
            };
            let from = h.camera.point(i);
            out.set(i, direct.bsdf_emission(&from, ray.d, &hit, &bs, weight, c));
        }
    }
    out
}

/// RIS over several candidates, whose draw `li` makes with 4M + 1 numbers: each lane of
/// `live` draws with `Direct::ris_for_lane` from its own sampler, which is left after the
/// draw. The kept candidate's numbers are the lane's light numbers (the lane's light draw
/// takes it again, bitwise as the scalar candidate) and `p_div` the density the lane's
/// estimate divides by. A lane that kept no candidate divides by infinity: its light
/// sample, drawn from numbers 0, adds zero, as in `li`.
#[inline(never)]
pub(super) fn ris_numbers<L: SamplerLanes>(
    direct: &Direct,
    rng: &mut L,
    h: &CameraHits,
    live: u32,
    u: &mut [[f32; LANES]; 4],
    p_div: &mut [f32; LANES],
    c: &mut Counts,
) {
    for i in bits(live) {
        let mut one = rng.lane(i);
        match direct.ris_for_lane(&h.camera.point(i), h.d.get(i), &mut one, c) {
            Some((dims, p)) => {
                [u[0][i], u[1][i], u[2][i], u[3][i]] =
                    [dims.select, dims.primitive, dims.point.x, dims.point.y];
                p_div[i] = p;
            }
            None => p_div[i] = f32::INFINITY,
        }
        rng.set_lane(i, &one);
    }
}
