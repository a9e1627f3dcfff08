//! The watertight ray-triangle test of `watertight` turned on its side: one triangle against
//! eight rays, one ray per lane, for ray packets (`packet`). It needs the eight rays to share
//! their dominant axis (the permutation is then the same in every lane); packets whose rays
//! do not take `watertight`'s one-ray test instead.
//!
//! Every lane runs the four-lane test's IEEE operations in the same order on the same inputs
//! (the per-ray set-up, computed in lanes, is bitwise `WatertightRay`'s), so a ray's answer
//! here is bitwise its answer there, and a renderer may switch between the two per packet.

use super::lanes8::{F8, M8};
use super::refine::distance_f64;
use super::watertight::{gamma, Tri4, WatertightRay, AXES};
use glam::Vec3;

/// Eight 3-vectors by axis: `v[a][i]` is component a of vector i.
pub type Lanes3 = [[f32; 8]; 3];

/// Eight rays' set-up for either test: `WatertightRay`'s, per ray, computed in lanes.
pub struct Rays8 {
    o: Lanes3,
    d: Lanes3,
    /// Rays whose dominant axis is x, y, z (`setup`'s kz), as bit masks.
    kz_bits: [u32; 3],
    /// Per permuted axis, per ray: the origin and the shear.
    o_perm: Lanes3,
    shear: Lanes3,
}

impl Rays8 {
    /// `setup` for eight rays at once: the same comparisons pick the dominant axis, selects
    /// (exact) permute, and the divisions are the same IEEE divisions, so each ray's set-up is
    /// bitwise `setup`'s.
    #[inline(always)]
    pub fn new(o: &Lanes3, d: &Lanes3) -> Self {
        let ov = [F8::load(&o[0]), F8::load(&o[1]), F8::load(&o[2])];
        let dv = [F8::load(&d[0]), F8::load(&d[1]), F8::load(&d[2])];
        let [ax, ay, az] = [dv[0].abs(), dv[1].abs(), dv[2].abs()];
        // kz = 0 where a.x > a.y and a.x > a.z; 1 where not a.x > a.y and a.y > a.z; else 2.
        let x_gt_y = ax.gt(ay);
        let kz0 = x_gt_y.and(ax.gt(az));
        let kz1 = ay.gt(az).and_not(x_gt_y);
        let (b0, b1) = (kz0.bitmask(), kz1.bitmask());
        // Permuted axis k of each lane: `AXES[kz][k]` of the source.
        let perm = |v: &[F8; 3], k: usize| {
            let src = |kz: usize| v[AXES[kz][k]];
            F8::select(kz0, src(0), F8::select(kz1, src(1), src(2)))
        };
        let mut r = Rays8 {
            o: *o,
            d: *d,
            kz_bits: [b0, b1, !(b0 | b1) & 0xff],
            o_perm: [[0.0; 8]; 3],
            shear: [[0.0; 8]; 3],
        };
        for k in 0..3 {
            perm(&ov, k).store(&mut r.o_perm[k]);
        }
        let (dx, dy, dz) = (perm(&dv, 0), perm(&dv, 1), perm(&dv, 2));
        dx.neg().div(dz).store(&mut r.shear[0]);
        dy.neg().div(dz).store(&mut r.shear[1]);
        F8::splat(1.0).div(dz).store(&mut r.shear[2]);
        r
    }

    /// Ray i's dominant axis.
    #[inline(always)]
    fn kz(&self, i: usize) -> u8 {
        (0..3).find(|&k| self.kz_bits[k] >> i & 1 != 0).unwrap_or(2) as u8
    }

    /// Ray i's one-ray test: bitwise `WatertightRay::new` of it.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> WatertightRay {
        WatertightRay::from_parts(
            lane(&self.o, i),
            lane(&self.d, i),
            self.kz(i),
            self.o_perm.map(|a| a[i]),
            self.shear.map(|a| a[i]),
        )
    }

    /// The rays set in `active` as one eight-ray test, if they share a dominant axis.
    #[inline(always)]
    pub fn packet(&self, active: u32) -> Option<WatertightRay8<'_>> {
        if active == 0 {
            return None;
        }
        let kz = (0..3).find(|&k| active & !self.kz_bits[k] == 0)?;
        Some(WatertightRay8 {
            o: &self.o,
            d: &self.d,
            kz: kz as u8,
            axes: AXES[kz],
            o8: self.o_perm.map(|a| F8::load(&a)),
            shear: self.shear.map(|a| F8::load(&a)),
        })
    }
}

/// Vector i of eight by axis.
#[inline(always)]
fn lane(v: &Lanes3, i: usize) -> Vec3 {
    Vec3::new(v[0][i], v[1][i], v[2][i])
}

/// Eight rays that share a dominant axis, one per lane.
#[derive(Clone, Copy)]
pub struct WatertightRay8<'a> {
    /// Per ray, origin and direction (for the f64 re-evaluation), borrowed from the set-up:
    /// copied, they were a fifth of a camera packet's set-up.
    o: &'a Lanes3,
    d: &'a Lanes3,
    kz: u8,
    axes: [usize; 3],
    /// Origin in the permuted frame.
    o8: [F8; 3],
    /// (-d_x / d_z, -d_y / d_z, 1 / d_z) in the permuted frame.
    shear: [F8; 3],
}

/// Per lane: hit mask, distance and barycentrics (b1, b2) of vertices 1 and 2.
pub type Hits8 = (u32, F8, F8, F8);

impl WatertightRay8<'_> {
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
            let (o, d) = (lane(self.o, l).into(), lane(self.d, l).into());
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

    fn by_axis(v: [Vec3; 8]) -> Lanes3 {
        [0, 1, 2].map(|a| v.map(|v| v[a]))
    }

    /// Each ray's set-up in lanes is bitwise the one-ray `setup`, for every dominant axis,
    /// ties between axes (which `setup` breaks by its comparison order), zero and negative
    /// zero components, and packets that mix axes.
    #[test]
    fn lane_set_up_is_the_one_ray_set_up() {
        use crate::geometry::watertight::setup;
        let mut rng = Rng::new(3, 9);
        let mut f = || rng.next_f32() * 4.0 - 2.0;
        let special = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5];
        let mut axes_seen = [0; 3];
        for round in 0..2000 {
            let o: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(f(), f(), f()));
            let d: [Vec3; 8] = std::array::from_fn(|i| {
                let mut c = [f(), f(), f()];
                // Ties and zeros: copy or pick special values for some components.
                match (round + i) % 5 {
                    0 => c[1] = -c[0],
                    1 => c[2] = c[1],
                    2 => c[(round + i) % 3] = special[(round * 7 + i) % special.len()],
                    3 => c = [c[0], c[0], -c[0]],
                    _ => {}
                }
                Vec3::from_array(c)
            });
            let set = Rays8::new(&by_axis(o), &by_axis(d));
            for i in 0..8 {
                let (kz, op, sh) = setup(o[i], d[i]);
                axes_seen[kz as usize] += 1;
                assert_eq!(set.kz(i), kz, "round {round}, ray {i}: {:?}", d[i]);
                let bits = |a: [f32; 3]| a.map(f32::to_bits);
                assert_eq!(
                    bits(set.o_perm.map(|a| a[i])),
                    bits(op),
                    "round {round}, ray {i}"
                );
                assert_eq!(
                    bits(set.shear.map(|a| a[i])),
                    bits(sh),
                    "round {round}, ray {i}"
                );
            }
            for active in [0xff, 0x0f, 0x81, 0b0110_0000, 1 << (round % 8)] {
                let mut kz = (0..8)
                    .filter(|i| active >> i & 1 != 0)
                    .map(|i| setup(o[i], d[i]).0);
                let k0 = kz.next();
                let shared = k0.filter(|&k| kz.all(|k2| k2 == k));
                let got = set.packet(active).map(|p| p.kz);
                assert_eq!(got, shared, "round {round}, active {active:#b}");
            }
        }
        assert!(axes_seen.iter().all(|&n| n > 2000), "{axes_seen:?}");
    }

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
            let set = Rays8::new(&by_axis([o; 8]), &by_axis(dirs));
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
