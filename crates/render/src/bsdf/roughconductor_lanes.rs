//! The rough conductor's BSDF samples for eight lanes (`Bsdf::sample_lanes`): Beckmann
//! visible-normal sampling with the slope inversion's parts in vector lanes
//! (`beckmann_visible_begin`, the fixed Halley steps, the steps some lanes still need,
//! `beckmann_visible_end`), then `RoughConductor::reflect`: bitwise `RoughConductor::sample`.
//! Other distributions and samplers take `sample` lane by lane.

#![allow(clippy::needless_range_loop)]

use super::{sample_each, BsdfSamples, RoughConductor};
use crate::math::V3x8;
use crate::rng::LANES;
use crate::sampling::microfacet::{
    beckmann_visible_y, slope_step, BeckmannVisible, Microfacet, MicrofacetDistribution,
    SlopeInversion,
};

/// `RoughConductor::sample` of every lane in `live` (`Bsdf::sample_lanes`), given each lane's
/// Smith Lambda(wi), for grey indices (`Bsdf::lane_covered`). Lanes outside `live` hold the
/// batch's material and garbage directions.
#[inline(always)]
pub(super) fn sample_lanes<'b>(
    b: impl Fn(usize) -> &'b RoughConductor + Copy,
    wi: &V3x8,
    lambda_i: &[f32; LANES],
    u: &[[f32; LANES]; 3],
    live: u32,
) -> BsdfSamples {
    let visible_beckmann = |rc: &RoughConductor| {
        rc.sample_visible && rc.mf.distribution == MicrofacetDistribution::Beckmann
    };
    if !(0..LANES).all(|i| visible_beckmann(b(i))) {
        return sample_each(b, wi, u, live);
    }
    let vis = VisibleX8::invert(|i| b(i).mf, wi, u, live);
    let mut out = BsdfSamples::default();
    for i in 0..LANES {
        let (rc, wi) = (b(i), wi.get(i));
        let m = rc.mf.beckmann_visible_end(&vis.get(i));
        // `RoughConductor::sample`, whose first test is wi.z > 0.
        let bs = rc.reflect(wi, m, lambda_i[i], |c| rc.fresnel_grey(c));
        out.set(i, bs, wi.z > 0.0 && live >> i & 1 != 0);
    }
    out
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
        u: &[[f32; LANES]; 3],
        live: u32,
    ) -> VisibleX8 {
        let mut vis = VisibleX8::default();
        for i in 0..LANES {
            vis.y[i] = beckmann_visible_y(u[2][i]);
        }
        for i in 0..LANES {
            let (cos_phi, sin_phi, tan_t) = mf(i).beckmann_visible_azimuth(wi.get(i));
            (vis.cos_phi[i], vis.sin_phi[i], vis.tan_t[i]) = (cos_phi, sin_phi, tan_t);
        }
        for i in 0..LANES {
            let b = SlopeInversion::new(vis.tan_t[i], u[1][i]);
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
    use crate::math::V3x8;
    use crate::rng::LANES;
    use crate::sampling::microfacet::ITERS;
    use glam::Vec3;

    /// `Bsdf::sample_lanes` of the rough conductor is `sample` lane by lane, bitwise, for
    /// the lanes in `live`, and gives nothing for the others: grey Beckmann with visible
    /// normals (the vector path) and the per-lane fallback (GGX, all-normal sampling), wi
    /// above, on and below the horizon, every live mask of a set.
    #[test]
    fn lane_samples_are_the_scalar_samples_of_live_lanes() {
        use crate::bsdf::{Bsdf, RoughConductor};
        use crate::math::Rgb;
        use crate::rng::Rng;
        use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
        use crate::sampling::warps::square_to_uniform_sphere;
        use glam::Vec2;
        let mut rng = Rng::new(8, 3);
        let mut seen = [0u32; 3];
        for (dist, visible) in [
            (MicrofacetDistribution::Beckmann, true),
            (MicrofacetDistribution::Ggx, true),
            (MicrofacetDistribution::Beckmann, false),
        ] {
            let rc = RoughConductor {
                mf: Microfacet::new(dist, 0.3, 0.15),
                sample_visible: visible,
                eta: Rgb::splat(0.2),
                k: Rgb::splat(3.0),
                specular_reflectance: Rgb::new(0.9, 0.8, 0.7),
            };
            for batch in 0..200 {
                let mut wi = V3x8::default();
                let mut u = [[0.0f32; LANES]; 3];
                let mut lambda = [0.0f32; LANES];
                for i in 0..LANES {
                    let mut w = square_to_uniform_sphere(rng.next_2d());
                    if i == 7 {
                        w = Vec3::new(w.x, w.y, 0.0).normalize();
                    }
                    wi.set(i, w);
                    lambda[i] = rc.lane_shared(w);
                    u.iter_mut().for_each(|u| u[i] = rng.next_f32());
                }
                let live = [0xff, 0x5a, 0x81][batch % 3];
                let got = RoughConductor::sample_lanes(|_| &rc, &wi, &lambda, &u, live);
                for i in 0..LANES {
                    let want = Bsdf::sample(&rc, wi.get(i), u[0][i], Vec2::new(u[1][i], u[2][i]));
                    match (live >> i & 1 != 0, want) {
                        (true, Some(w)) => {
                            assert!(got.ok[i], "lane {i} wi {}", wi.get(i));
                            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                            assert_eq!(bits(got.wo.get(i)), bits(w.wo));
                            assert_eq!(bits(got.weight.get(i)), bits(w.weight));
                            assert_eq!(got.pdf[i].to_bits(), w.pdf.to_bits());
                            assert!(!got.delta[i]);
                            seen[0] += 1;
                        }
                        (true, None) => {
                            assert!(!got.ok[i], "lane {i} wi {}: a sample", wi.get(i));
                            seen[1] += 1;
                        }
                        (false, _) => {
                            assert!(!got.ok[i], "lane {i} outside live {live:#x}");
                            seen[2] += 1;
                        }
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
    }

    /// The lanes' inversion is the scalar sampler's, bitwise, also for lanes that need
    /// scalar steps after the vector ones (grazing incidence with u near 0, found by counting
    /// the scalar steps), and whichever lanes are live.
    #[test]
    fn lane_inversion_is_the_scalar_one_for_slow_lanes() {
        use super::VisibleX8;
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
            let mut u = [[0.0f32; LANES]; 3];
            for i in 0..LANES {
                wi.set(i, lane(i).1);
                (u[1][i], u[2][i]) = (lane(i).2.x, lane(i).2.y);
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
}
