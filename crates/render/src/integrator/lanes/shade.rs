//! The lane kernel's one shading function, generic over the BSDF type, and the traversals
//! and sums that finish a batch.

// Lane loops index a dozen structure-of-arrays fields by the same lane number; iterators
// over one of them would hide that symmetry.
#![allow(clippy::needless_range_loop)]

use super::light::light_sample;
use super::tables::SAMPLE_COUNTS;
use super::{mask_of, CameraHits, LaneKernel, LightDraws, Shaded, SphereDraws};
use crate::bsdf::{Bsdf, BsdfSample, Material, Registered};
use crate::geometry::ray_packet::bits;
use crate::integrator::direct::heuristic;
use crate::math::{Frame, Rgb, V3x8};
use crate::rng::LANES;
use crate::scene::Scene;
use glam::Vec3;

/// `SAMPLE_COUNTS` as the f32 factors `li` uses.
const SAMPLE_COUNTS_F32: (f32, f32) = (SAMPLE_COUNTS.0 as f32, SAMPLE_COUNTS.1 as f32);

impl LaneKernel<'_> {
    /// `shade` for a batch whose covered lanes have BSDFs of type `B`, copied here: read
    /// where the scene keeps them, their fields were reloaded in every lane, since the
    /// compiler could not tell that the kernel's stores leave them alone, and the loops ran
    /// lane by lane. For the same reason the
    /// arrays are separate arguments, not fields of one structure: a reference argument
    /// tells the compiler that nothing else writes its target; a reference in a field
    /// does not.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // see `shade_batch`
    pub(super) fn shade_batch<B: Bsdf + Registered, const SPHERES: bool>(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        let materials = &self.direct.scene.materials;
        let first = *B::view(&materials[h.first as usize].kind)
            .expect("the batch's first material has the batch's type");
        match h.uniform {
            true => self.shade::<B, SPHERES>(|_| &first, h, ld, sd, u, o, out),
            false => self.shade_mixed::<B, SPHERES>(h, ld, sd, u, o, out),
        }
    }

    /// `shade_batch`, out of line (see `li_lanes`).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)] // see `shade_batch`
    pub(super) fn shade_batch_out_of_line<B: Bsdf + Registered, const SPHERES: bool>(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        self.shade_batch::<B, SPHERES>(h, ld, sd, u, o, out)
    }

    /// `shade_batch` for a batch of several materials (at a pixel straddling two), out of
    /// line, so that the instance for one material, which nearly every batch takes,
    /// compiles as it would alone.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)] // see `shade_batch`
    fn shade_mixed<B: Bsdf + Registered, const SPHERES: bool>(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        let materials = &self.direct.scene.materials;
        let first = *B::view(&materials[h.first as usize].kind).expect("the batch's type");
        // Each lane's BSDF; the first material's for lanes not covered.
        let mut b = [first; LANES];
        for i in bits(h.covered) {
            b[i] = *B::view(&materials[h.material[i] as usize].kind).unwrap_or(&first);
        }
        self.shade::<B, SPHERES>(|i| &b[i], h, ld, sd, u, o, out)
    }

    /// The arithmetic of `Direct`'s `light_draw`, `light_finish` and `bsdf_draw` and the rays
    /// of the two samples, for all lanes at once (lanes without a covered hit compute garbage,
    /// dropped), then `trace_and_sum`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // see `shade_batch`
    fn shade<'b, B: Bsdf + 'b, const SPHERES: bool>(
        &self,
        b: impl Fn(usize) -> &'b B + Copy,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        let s = &self.direct.strategy;
        let (ne, nb) = SAMPLE_COUNTS_F32;
        let mut wi_up = V3x8::default();
        let mut shared = [0.0f32; LANES];
        let mut flip = [false; LANES];
        let ris = self.direct.ris.is_some();
        for i in 0..LANES {
            let sp = h.camera.point(i);
            let (p, frame) = (sp.p, Frame::from_normal(sp.ns));
            // `Material::eval_pdf`'s orientation, once for both samples.
            let (wi, flipped) = Material::side(h.two_sided, frame.to_local(-h.d.get(i)));
            let lane_shared = b(i).lane_shared(wi);
            let (drawn, wl, pdf_area, radiance, lsp) = light_sample::<SPHERES>(p, ld, sd, u, i);
            // `light_finish` before its visibility test.
            let wo = Material::mirror(flipped, frame.to_local(wl));
            let (f, pdf_bsdf) = b(i).eval_pdf_shared(wi, wo, lane_shared);
            let p_light = ld.pmf[i] * pdf_area;
            let w = heuristic(s.heuristic, ne * p_light, nb * pdf_bsdf);
            // RIS divides by its own density; the MIS weight takes pmf * pdf (see `LightDraw`).
            let p_div = if ris { ld.p_div[i] } else { p_light };
            o.light.set(i, f * radiance * (w / p_div));
            o.light_ok[i] = drawn && f != Rgb::ZERO && radiance != Rgb::ZERO;
            let lp = lsp.p;
            let so = sp.spawn_origin(lp - p);
            let target = lsp.spawn_origin(so - lp);
            o.shadow
                .set(i, &Scene::shadow_ray_to(so, target, h.skip[i]));
            wi_up.set(i, wi);
            (shared[i], flip[i]) = (lane_shared, flipped);
        }
        // `bsdf_draw`: `Material::sample` with the orientation above.
        let bs = B::sample_lanes(b, &wi_up, &shared, &[u[4], u[5], u[6]], h.covered);
        for i in 0..LANES {
            let sp = h.camera.point(i);
            (o.bsdf_ok[i], o.bsdf_pdf[i], o.bsdf_delta[i]) = (bs.ok[i], bs.pdf[i], bs.delta[i]);
            o.bsdf_weight.set(i, bs.weight.get(i));
            // `bsdf_finish`'s ray (`Scene::bsdf_ray`).
            let d = Frame::from_normal(sp.ns).to_world(Material::mirror(flip[i], bs.wo.get(i)));
            o.bsdf
                .set(i, &Scene::ray_from(sp.spawn_origin(d), d, h.skip[i]));
        }
        self.trace_and_sum::<SPHERES>(h, o, out);
    }

    /// The traversals (the shadow rays as one packet, then the BSDF rays one at a time) and
    /// the estimate of each covered lane, summed in `li`'s order.
    #[inline(always)]
    fn trace_and_sum<const SPHERES: bool>(
        &self,
        h: &CameraHits,
        sh: &Shaded,
        out: &mut [Rgb; LANES],
    ) {
        let direct = &self.direct;
        let scene = direct.scene;
        let s = &direct.strategy;
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
                    delta: sh.bsdf_delta[i],
                };
                let from = h.camera.point(i);
                bsdf.set(i, direct.bsdf_emission(&from, ray.d, &hit, &bs, bsdf_w));
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
