//! The watertight ray-triangle test of `watertight` turned on its side: one triangle against
//! eight rays, one ray per lane, for ray packets (`packet`). It needs the eight rays to share
//! their dominant axis (the permutation is then the same in every lane); packets whose rays
//! do not take `watertight`'s one-ray test instead.
//!
//! Every lane runs the four-lane test's IEEE operations in the same order on the same inputs
//! (the per-ray set-up is `WatertightRay`'s own, gathered), so a ray's answer here is bitwise
//! its answer there, and a renderer may switch between the two per packet.

use super::lanes8::{F8, M8};
use super::refine::distance_f64;
use super::watertight::{gamma, setup, Tri4, WatertightRay, AXES};
use glam::Vec3;

/// Eight rays' set-up for either test: `WatertightRay`'s, per ray.
pub struct Rays8 {
    o: [Vec3; 8],
    d: [Vec3; 8],
    kz: [u8; 8],
    o_perm: [[f32; 3]; 8],
    shear: [[f32; 3]; 8],
}

impl Rays8 {
    #[inline(always)]
    pub fn new(o: [Vec3; 8], d: [Vec3; 8]) -> Self {
        let mut r = Rays8 {
            o,
            d,
            kz: [0; 8],
            o_perm: [[0.0; 3]; 8],
            shear: [[0.0; 3]; 8],
        };
        for i in 0..8 {
            (r.kz[i], r.o_perm[i], r.shear[i]) = setup(o[i], d[i]);
        }
        r
    }

    /// Ray i's one-ray test: bitwise `WatertightRay::new` of it.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> WatertightRay {
        WatertightRay::from_parts(
            self.o[i],
            self.d[i],
            self.kz[i],
            self.o_perm[i],
            self.shear[i],
        )
    }

    /// The rays set in `active` as one eight-ray test, if they share a dominant axis.
    #[inline(always)]
    pub fn packet(&self, active: u32) -> Option<WatertightRay8> {
        if active == 0 {
            return None;
        }
        let kz = self.kz[active.trailing_zeros() as usize];
        let mut same = true;
        for i in 0..8 {
            same &= active >> i & 1 == 0 || self.kz[i] == kz;
        }
        if !same {
            return None;
        }
        #[inline(always)]
        fn lanes(f: impl Fn(usize) -> f32) -> F8 {
            let mut x = [0.0; 8];
            for (i, x) in x.iter_mut().enumerate() {
                *x = f(i);
            }
            F8::load(&x)
        }
        Some(WatertightRay8 {
            o: self.o,
            d: self.d,
            kz,
            axes: AXES[kz as usize],
            o8: [0, 1, 2].map(|k| lanes(|i| self.o_perm[i][k])),
            shear: [0, 1, 2].map(|k| lanes(|i| self.shear[i][k])),
        })
    }
}

/// Eight rays that share a dominant axis, one per lane.
#[derive(Clone, Copy)]
pub struct WatertightRay8 {
    /// Per ray, origin and direction (for the f64 re-evaluation).
    o: [Vec3; 8],
    d: [Vec3; 8],
    kz: u8,
    axes: [usize; 3],
    /// Origin in the permuted frame.
    o8: [F8; 3],
    /// (-d_x / d_z, -d_y / d_z, 1 / d_z) in the permuted frame.
    shear: [F8; 3],
}

/// Per lane: hit mask, distance and barycentrics (b1, b2) of vertices 1 and 2.
pub type Hits8 = (u32, F8, F8, F8);

impl WatertightRay8 {
    /// Triangle `k` of the packet `tri` against the rays in `active`, strictly inside each
    /// ray's (tmin, tmax); lanes in `skip` never hit. The hit mask only has `active` lanes.
    #[inline(always)]
    pub fn hits(&self, tri: &Tri4, k: usize, tmin: F8, tmax: F8, active: u32, skip: M8) -> Hits8 {
        let [px, py, pz] = self.axes;
        let rel = |j: usize| {
            let v = &tri.v[j];
            (
                F8::splat(v[px][k]).sub(self.o8[0]),
                F8::splat(v[py][k]).sub(self.o8[1]),
                F8::splat(v[pz][k]).sub(self.o8[2]),
            )
        };
        let (a, b, c) = (rel(0), rel(1), rel(2));
        let [sx, sy, sz] = self.shear;
        let (ax, ay) = (a.0.add(sx.mul(a.2)), a.1.add(sy.mul(a.2)));
        let (bx, by) = (b.0.add(sx.mul(b.2)), b.1.add(sy.mul(b.2)));
        let (cx, cy) = (c.0.add(sx.mul(c.2)), c.1.add(sy.mul(c.2)));
        let mut u = cx.mul(by).sub(cy.mul(bx));
        let mut v = ax.mul(cy).sub(ay.mul(cx));
        let mut w = bx.mul(ay).sub(by.mul(ax));
        let zero = F8::splat(0.0);
        let on_edge = u.eq(zero).or(v.eq(zero)).or(w.eq(zero)).bitmask() & active;
        if on_edge != 0 {
            // Exactly on an edge in f32: decide in f64 so both neighbours agree.
            let f =
                |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            let [ax_, ay_, bx_, by_, cx_, cy_] = [ax, ay, bx, by, cx, cy].map(F8::to_array);
            let (mut ua, mut va, mut wa) = (u.to_array(), v.to_array(), w.to_array());
            let mut m = on_edge;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                ua[l] = f(cx_[l], by_[l], cy_[l], bx_[l]);
                va[l] = f(ax_[l], cy_[l], ay_[l], cx_[l]);
                wa[l] = f(bx_[l], ay_[l], by_[l], ax_[l]);
            }
            (u, v, w) = (F8::load(&ua), F8::load(&va), F8::load(&wa));
        }
        let neg = u.lt(zero).or(v.lt(zero)).or(w.lt(zero));
        let pos = u.gt(zero).or(v.gt(zero)).or(w.gt(zero));
        let det = u.add(v).add(w);
        let valid = det
            .ne(zero)
            .and_not(neg.and(pos))
            .and_not(skip)
            .and(M8::from_bits(active));
        if valid.bitmask() == 0 {
            return (0, zero, zero, zero);
        }
        let (az, bz, cz) = (sz.mul(a.2), sz.mul(b.2), sz.mul(c.2));
        let t_scaled = u.mul(az).add(v.mul(bz)).add(w.mul(cz));
        let inv = F8::splat(1.0).div(det);
        let mut t = t_scaled.mul(inv);
        // pbrt-v4's conservative bound on the rounding error of t (see `watertight`).
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let g = |n: f32| F8::splat(gamma(n));
        let delta_z = g(3.0).mul(max_z);
        let delta_x = g(5.0).mul(max_x.add(max_z));
        let delta_y = g(5.0).mul(max_y.add(max_z));
        let delta_e = F8::splat(2.0).mul(
            g(2.0)
                .mul(max_x)
                .mul(max_y)
                .add(delta_y.mul(max_x))
                .add(delta_x.mul(max_y)),
        );
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = F8::splat(3.0)
            .mul(
                g(3.0)
                    .mul(max_e)
                    .mul(max_z)
                    .add(delta_e.mul(max_z))
                    .add(delta_z.mul(max_e)),
            )
            .mul(inv.abs());
        let near = |x: F8| x.abs().le(delta_t);
        let unsure = valid.and(near(t).or(near(t.sub(tmin))).or(near(t.sub(tmax))));
        let sure = valid.and_not(unsure).and(t.gt(tmin)).and(t.lt(tmax));
        let mut hit = sure.bitmask();
        let unsure = unsure.bitmask();
        if unsure != 0 {
            hit |= self.refine(tri, k, unsure, &mut t, tmin, tmax);
        }
        (hit, t, v.mul(inv), w.mul(inv))
    }

    /// Lanes whose hit the f32 bound could not decide: f64 decides, and sets their t.
    #[cold]
    #[inline(never)]
    fn refine(&self, tri: &Tri4, k: usize, unsure: u32, t: &mut F8, tmin: F8, tmax: F8) -> u32 {
        let (mut ts, lo, hi) = (t.to_array(), tmin.to_array(), tmax.to_array());
        let mut hit = 0;
        let mut m = unsure;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let (o, d) = (self.o[l].into(), self.d[l].into());
            let exact = distance_f64(o, d, self.kz, tri.lane(k));
            if let Some(x) = exact.filter(|&x| x > lo[l] as f64 && x < hi[l] as f64) {
                ts[l] = x as f32;
                hit |= 1 << l;
            }
        }
        *t = F8::load(&ts);
        hit
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use glam::BVec4A;

    /// Per ray and triangle, the eight-ray test's hit, distance and barycentrics are bitwise
    /// the four-lane test's, also for rays through shared edges and vertices, rays whose hit
    /// lies at tmin or tmax, and skipped triangles.
    #[test]
    fn matches_the_four_lane_test_bitwise() {
        let mut rng = Rng::new(17, 2);
        let mut r3 = |s: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * s;
        let (mut hits, mut packets) = (0, 0);
        for round in 0..4000 {
            // A fan of four triangles around a shared vertex: rays aimed at its edges.
            let c = r3(2.0) - 1.0;
            let corners: Vec<Vec3> = (0..5).map(|_| c + r3(2.0) - 1.0).collect();
            let tris: Vec<[Vec3; 3]> = (0..4).map(|k| [c, corners[k], corners[k + 1]]).collect();
            let packet = Tri4::new(&tris);
            let o = r3(6.0) - 3.0;
            let dirs: [Vec3; 8] = std::array::from_fn(|i| {
                let target = match (round + i) % 4 {
                    0 => c,
                    1 => (c + corners[i % 5]) * 0.5,
                    _ => c + (r3(2.0) - 1.0) * 0.7,
                };
                (target - o) * (0.5 + i as f32 * 0.25)
            });
            let rays: [WatertightRay; 8] = dirs.map(|d| WatertightRay::new(o, d));
            let active = (round as u32 * 37) & 0xff | 1;
            let set = Rays8::new([o; 8], dirs);
            let Some(r8) = set.packet(active) else {
                continue;
            };
            packets += 1;
            let tmin: [f32; 8] = std::array::from_fn(|i| if i % 3 == 0 { 0.0 } else { 0.3 });
            let tmax: [f32; 8] = std::array::from_fn(|i| [f32::INFINITY, 1.5, 2.0][i % 3]);
            let skip_id = round % 5;
            for k in 0..4 {
                let skip8 = M8::from_bits(if skip_id == k { 0b1010_1010 } else { 0 });
                let (hit, t, b1, b2) =
                    r8.hits(&packet, k, F8::load(&tmin), F8::load(&tmax), active, skip8);
                let (t, b1, b2) = (t.to_array(), b1.to_array(), b2.to_array());
                for i in 0..8 {
                    let skip = skip_id == k && i % 2 == 1;
                    let mut lane_skip = [true; 4];
                    lane_skip[k] = skip;
                    let skip4 = BVec4A::from_array(lane_skip);
                    let want = rays[i].closest(&packet, tmin[i], tmax[i], skip4);
                    let same = set.ray(i).closest(&packet, tmin[i], tmax[i], skip4);
                    let got = (active >> i & 1 != 0 && hit >> i & 1 != 0)
                        .then(|| (k, t[i], b1[i], b2[i]));
                    if active >> i & 1 == 0 {
                        assert_eq!(hit >> i & 1, 0, "inactive lane {i} hit");
                        continue;
                    }
                    let bits = |h: Option<(usize, f32, f32, f32)>| {
                        h.map(|h| (h.0, h.1.to_bits(), h.2.to_bits(), h.3.to_bits()))
                    };
                    assert_eq!(
                        bits(got),
                        bits(want),
                        "round {round}, ray {i}, triangle {k}"
                    );
                    assert_eq!(bits(same), bits(want), "round {round}, ray {i}: set-up");
                    hits += got.is_some() as u32;
                }
            }
        }
        assert!(
            packets > 1500 && hits > 3000,
            "{packets} packets, {hits} hits"
        );
    }
}
