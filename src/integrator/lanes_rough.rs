//! The lane kernel's shading of rough conductors: Beckmann, visible-normal sampling, a grey
//! index (`lanes::rough_covered`), the plates of the Veach scene.
//!
//! Each pass is a loop over the eight lanes that calls the scalar code of `li`'s path in the
//! same order: `RoughConductor::eval_pdf_with` for the light sample; then the visible-normal
//! sampler in its parts (`beckmann_visible_begin`, the slope inversion's fixed Halley steps,
//! the steps some lanes still need, `beckmann_visible_end`) and `RoughConductor::reflect`.
//! The parts without branches run in vector lanes; the samples stay bitwise `li`'s.

#![allow(clippy::needless_range_loop)]

use super::direct::{heuristic, Direct};
use super::lanes::{CameraHits, Shaded, V3x8, SAMPLE_COUNTS_F32};
use super::lanes_light::{light_sample, LightDraws, SphereDraws};
use crate::bsdf::fresnel::fresnel_conductor_channel;
use crate::bsdf::RoughConductor;
use crate::math::{Frame, Rgb};
use crate::rng::LANES;
use crate::sampling::microfacet::{
    beckmann_visible_y, slope_step, BeckmannVisible, Microfacet, MicrofacetDistribution,
    SlopeInversion,
};
use crate::scene::Scene;
use glam::Vec3;

impl CameraHits {
    /// Lane i's rough conductor, rebuilt from the lane arrays.
    #[inline(always)]
    fn rough_conductor(&self, i: usize) -> RoughConductor {
        RoughConductor {
            mf: Microfacet {
                distribution: MicrofacetDistribution::Beckmann,
                alpha_u: self.alpha_u[i],
                alpha_v: self.alpha_v[i],
            },
            sample_visible: true,
            eta: Rgb::splat(self.eta[i]),
            k: Rgb::splat(self.k[i]),
            specular_reflectance: self.reflectance.get(i),
        }
    }

    /// Lane i's Fresnel term times specular reflectance: `RoughConductor::fresnel` for a
    /// grey index, without its test for one.
    #[inline(always)]
    fn fresnel(&self, i: usize) -> impl Fn(f32) -> Rgb {
        let (eta, k, spec) = (self.eta[i], self.k[i], self.reflectance.get(i));
        move |c| Rgb::splat(fresnel_conductor_channel(c, eta, k)) * spec
    }
}

impl Direct<'_> {
    /// `shade_and_trace` for a batch of rough-conductor hits, out of line (see
    /// `shade_and_trace_spheres`).
    #[inline(never)]
    pub(super) fn shade_and_trace_rough(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        shaded: &mut Shaded,
        out: &mut [Rgb; LANES],
    ) {
        self.shade_rough(h, ld, sd, u, shaded);
        self.trace_and_sum::<true>(h, shaded, out);
    }

    #[inline(always)]
    fn shade_rough(
        &self,
        h: &CameraHits,
        ld: &LightDraws,
        sd: &SphereDraws,
        u: &[[f32; LANES]; 7],
        o: &mut Shaded,
    ) {
        let s = &self.strategy;
        let (ne, nb) = SAMPLE_COUNTS_F32;
        let mut wi_local = V3x8::default();
        let mut lambda_i = [0.0f32; LANES];
        for i in 0..LANES {
            let sp = h.camera.point(i);
            let (drawn, wl, pdf_area, radiance, lsp) = light_sample::<true>(sp.p, ld, sd, u, i);
            let lp = lsp.p;
            let so = sp.spawn_origin(lp - sp.p);
            let target = lsp.spawn_origin(so - lp);
            o.shadow
                .set(i, &Scene::shadow_ray_to(so, target, h.skip[i]));
            let frame = Frame::from_normal(sp.ns);
            let wi = frame.to_local(-h.d.get(i));
            let rc = h.rough_conductor(i);
            // Smith's Lambda(wi), once for both samples' evaluations.
            let lambda = rc.mf.lambda(wi);
            // `light_finish` before its visibility test; `RoughConductor::eval_pdf`'s early
            // return below the horizon is `eval_pdf_with`'s select.
            let wo = frame.to_local(wl);
            let (f, pdf_bsdf) = rc.eval_pdf_with(wi, wo, lambda, h.fresnel(i));
            let p_light = ld.pmf[i] * pdf_area;
            let w = heuristic(s.heuristic, ne * p_light, nb * pdf_bsdf);
            o.light.set(i, f * radiance * (w / p_light));
            o.light_ok[i] = drawn && f != Rgb::ZERO && radiance != Rgb::ZERO;
            wi_local.set(i, wi);
            lambda_i[i] = lambda;
        }
        let vis = VisibleX8::invert(|i| h.rough_conductor(i).mf, &wi_local, u, h.covered);
        for i in 0..LANES {
            let sp = h.camera.point(i);
            let rc = h.rough_conductor(i);
            let wi = wi_local.get(i);
            let m = rc.mf.beckmann_visible_end(&vis.get(i));
            // `RoughConductor::sample`, whose first test is wi.z > 0.
            let bs = rc.reflect(wi, m, lambda_i[i], h.fresnel(i));
            let (ok, wo, pdf, weight) = match bs {
                Some(bs) => (wi.z > 0.0, bs.wo, bs.pdf, bs.weight),
                None => (false, Vec3::Z, 0.0, Rgb::ZERO),
            };
            o.bsdf_ok[i] = ok;
            o.bsdf_pdf[i] = pdf;
            o.bsdf_weight.set(i, weight);
            let d = Frame::from_normal(sp.ns).to_world(wo);
            o.bsdf
                .set(i, &Scene::ray_from(sp.spawn_origin(d), d, h.skip[i]));
        }
    }
}

/// Eight `BeckmannVisible`s, one array per field: the loops over them then run in vector
/// lanes, which they did not over an array of the structures.
#[derive(Default)]
#[repr(C, align(32))] // see `V3x8`
struct VisibleX8 {
    cos_phi: [f32; LANES],
    sin_phi: [f32; LANES],
    y: [f32; LANES],
    x: [f32; LANES],
    lo: [f32; LANES],
    hi: [f32; LANES],
    target: [f32; LANES],
    tan_t: [f32; LANES],
    k: [f32; LANES],
    done: [bool; LANES],
}

impl VisibleX8 {
    /// `Microfacet::beckmann_visible_begin` and the slope inversion for eight lanes: the
    /// fixed steps and one more in vector lanes, then the scalar steps the lanes in `live`
    /// still need. Lanes outside `live` stop after the vector steps (their samples are
    /// dropped; garbage would bisect to the step limit).
    #[inline(always)]
    fn invert(
        mf: impl Fn(usize) -> Microfacet,
        wi: &V3x8,
        u: &[[f32; LANES]; 7],
        live: u32,
    ) -> VisibleX8 {
        let mut vis = VisibleX8::default();
        for i in 0..LANES {
            vis.y[i] = beckmann_visible_y(u[6][i]);
        }
        for i in 0..LANES {
            let (cos_phi, sin_phi, tan_t) = mf(i).beckmann_visible_azimuth(wi.get(i));
            (vis.cos_phi[i], vis.sin_phi[i], vis.tan_t[i]) = (cos_phi, sin_phi, tan_t);
        }
        for i in 0..LANES {
            let b = SlopeInversion::new(vis.tan_t[i], u[5][i]);
            (vis.x[i], vis.lo[i], vis.hi[i], vis.done[i]) = (b.x, b.lo, b.hi, b.done);
            (vis.target[i], vis.k[i]) = (b.target, b.k);
        }
        for _ in 0..SlopeInversion::FIXED_STEPS {
            vis.step(false);
        }
        let short = |v: &VisibleX8, i: usize| !v.done[i] && live >> i & 1 != 0;
        // One more step in vector lanes, where any lane needs it.
        let taken = if (0..LANES).any(|i| short(&vis, i)) {
            #[cfg(test)]
            crate::sampling::microfacet::ITERS
                .with(|c| c.set(c.get() + (0..LANES).filter(|&i| short(&vis, i)).count() as u64));
            vis.step(true);
            SlopeInversion::FIXED_STEPS + 1
        } else {
            SlopeInversion::FIXED_STEPS
        };
        for i in 0..LANES {
            if short(&vis, i) {
                let mut b = vis.get(i);
                b.slope.finish(taken);
                vis.set(i, b);
            }
        }
        vis
    }

    /// One slope step in every lane. With `keep_converged`, lanes whose last step converged
    /// keep their point, as `SlopeInversion::finish` would leave them.
    #[inline(always)]
    fn step(&mut self, keep_converged: bool) {
        for i in 0..LANES {
            let (x, lo, hi, done) = slope_step(
                self.x[i],
                self.lo[i],
                self.hi[i],
                self.target[i],
                self.tan_t[i],
                self.k[i],
            );
            let keep = keep_converged && self.done[i];
            self.x[i] = if keep { self.x[i] } else { x };
            self.lo[i] = if keep { self.lo[i] } else { lo };
            self.hi[i] = if keep { self.hi[i] } else { hi };
            self.done[i] = keep || done;
        }
    }

    #[inline(always)]
    fn set(&mut self, i: usize, b: BeckmannVisible) {
        (self.cos_phi[i], self.sin_phi[i], self.y[i]) = (b.cos_phi, b.sin_phi, b.y);
        let s = b.slope;
        (self.x[i], self.lo[i], self.hi[i], self.done[i]) = (s.x, s.lo, s.hi, s.done);
        (self.target[i], self.tan_t[i], self.k[i]) = (s.target, s.tan_t, s.k);
    }

    #[inline(always)]
    fn get(&self, i: usize) -> BeckmannVisible {
        BeckmannVisible {
            cos_phi: self.cos_phi[i],
            sin_phi: self.sin_phi[i],
            y: self.y[i],
            slope: SlopeInversion {
                x: self.x[i],
                lo: self.lo[i],
                hi: self.hi[i],
                target: self.target[i],
                tan_t: self.tan_t[i],
                k: self.k[i],
                done: self.done[i],
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::bsdf::BsdfKind;
    use crate::geometry::{Ray, RayPacket};
    use crate::integrator::{Direct, Strategy};
    use crate::rng::{Rng, LANES};
    use crate::sampler::IndependentLanes;
    use crate::sampling::microfacet::ITERS;
    use crate::scene::desc::StrategyKind;
    use crate::scene::Scene;
    use glam::Vec3;

    /// The lanes' inversion is the scalar sampler's, bitwise, also for lanes that need
    /// scalar steps after the vector ones (grazing incidence with u near 0, found by counting
    /// the scalar steps), and whichever lanes are live.
    #[test]
    fn lane_inversion_is_the_scalar_one_for_slow_lanes() {
        use super::{V3x8, VisibleX8};
        use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
        use glam::Vec2;
        let mut cases = Vec::new();
        let mut slow = 0;
        for alpha in [0.05f32, 0.5] {
            let mf = Microfacet::new(MicrofacetDistribution::Beckmann, alpha, alpha * 1.5);
            for cos in [1e-7f32, 1e-6, 1e-5, 1e-3, 0.3, 1.0] {
                for u5 in [
                    0.0f32,
                    1e-30,
                    1e-10,
                    1e-7,
                    1e-5,
                    0.3,
                    0.99999,
                    1.0 - f32::EPSILON,
                ] {
                    let wi = Vec3::new(0.6, 0.8, 0.0) * (1.0 - cos * cos).sqrt() + Vec3::Z * cos;
                    let u = Vec2::new(u5, 0.37);
                    ITERS.with(|c| c.set(0));
                    let m = mf.sample_visible(wi, u);
                    let steps = ITERS.with(|c| c.get()) as usize;
                    slow += (steps > crate::sampling::microfacet::SlopeInversion::FIXED_STEPS + 1)
                        as usize;
                    cases.push((mf, wi, u, m));
                }
            }
        }
        assert!(slow >= 8, "only {slow} cases need scalar steps");
        for (b, batch) in cases.chunks(LANES).enumerate() {
            let lane = |i: usize| &batch[i % batch.len()];
            let mut wi = V3x8::default();
            let mut u = [[0.0f32; LANES]; 7];
            for i in 0..LANES {
                wi.set(i, lane(i).1);
                (u[5][i], u[6][i]) = (lane(i).2.x, lane(i).2.y);
            }
            for live in [0xff, 0x55 << (b % 2)] {
                let vis = VisibleX8::invert(|i| lane(i).0, &wi, &u, live);
                for i in (0..LANES).filter(|i| live >> i & 1 != 0) {
                    let (mf, _, _, want) = lane(i);
                    let got = mf.beckmann_visible_end(&vis.get(i));
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits)
                    );
                }
            }
        }
    }

    /// Cost guard: in a batch of rough-conductor hits, lanes without a covered hit (rays
    /// that leave the scene) take no slope steps past the fixed ones. Their inversions are
    /// garbage (NaN), which used to bisect to the 64-step limit: 61 steps per empty lane.
    #[test]
    fn empty_lanes_of_a_rough_batch_take_no_further_steps() {
        let scene = Scene::build(crate::scene::bundled_tests::load("veach-mis/veach-mis.xml"))
            .unwrap_or_else(|e| panic!("{e}"));
        let mis = Strategy::combinations()
            .into_iter()
            .find(|s| s.kind == StrategyKind::Mis && s.emitter_samples == 1)
            .unwrap();
        let direct = Direct::new(&scene, mis);
        assert!(direct.has_lanes());
        let cam = &scene.camera;
        let mut rng = Rng::new(2, 7);
        // A camera ray onto a plate, down the middle column of the image.
        let plate = (0..cam.height)
            .map(|y| cam.generate_ray(cam.width / 2, y, &mut rng))
            .find(|r| {
                scene.intersect(r).is_some_and(|h| {
                    matches!(scene.material(&h.sp).kind, BsdfKind::RoughConductor(_))
                })
            })
            .expect("a ray onto a plate");
        let away = Ray::new(plate.o, Vec3::Y);
        assert!(scene.intersect(&away).is_none());
        let mut rays = RayPacket::splat(&away);
        (0..4).for_each(|i| rays.set(i, &plate));
        let batches = 64;
        let mut scratch = crate::integrator::LaneScratch::default();
        ITERS.with(|c| c.set(0));
        for b in 0..batches {
            let mut lanes = IndependentLanes::for_pixel_samples(9, 8 * b);
            direct.li_lanes(&rays, LANES, &mut lanes, &mut scratch);
        }
        let per_batch = ITERS.with(|c| c.get()) as f64 / batches as f64;
        eprintln!("{per_batch} steps past the fixed ones per batch");
        // The four plate lanes converge within the fixed steps in these batches (with
        // Newton steps a fourth was needed about 4 % of the time).
        assert!(per_batch < 1.0, "{per_batch} further steps per batch");
    }
}
