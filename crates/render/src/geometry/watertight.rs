//! The watertight ray-triangle test (Woop, Benthin and Wald 2013) with pbrt-v4's bound on the
//! rounding error of t, run on packets of four triangles (one BVH leaf) in 4-lane f32.
//!
//! The ray is mapped to +z by a permutation and shear, so neighbouring triangles evaluate their
//! shared edge with identical arithmetic and no ray slips between them. (The paper also swaps
//! x and y when d.z < 0 to keep the determinant's sign for back-face culling; without culling
//! that swap changes neither t nor the barycentrics.) Each lane does the same IEEE operations
//! a scalar test would, so a packet's answer does not depend on a triangle's lane.

use glam::{BVec4A, Vec3, Vec3A, Vec4};

/// pbrt-v4's gamma(n) for f32.
pub(super) const fn gamma(n: f32) -> f32 {
    n * f32::EPSILON * 0.5 / (1.0 - n * f32::EPSILON * 0.5)
}

/// Up to four triangles in SoA layout: `v[k][axis]` holds coordinate `axis` of vertex `k` in
/// each lane. Unused lanes repeat lane 0, so they can only report lane 0's hit again.
#[derive(Clone, Copy, Debug)]
pub struct Tri4 {
    pub(super) v: [[Vec4; 3]; 3],
}

impl Tri4 {
    /// Packs one to four triangles.
    pub fn new(tris: &[[Vec3; 3]]) -> Tri4 {
        assert!((1..=4).contains(&tris.len()), "{} triangles", tris.len());
        let mut v = [[Vec4::ZERO; 3]; 3];
        for lane in 0..4 {
            let tri = tris.get(lane).unwrap_or(&tris[0]);
            for (vk, p) in v.iter_mut().zip(tri) {
                for (axis, x) in vk.iter_mut().zip(p.to_array()) {
                    axis[lane] = x;
                }
            }
        }
        Tri4 { v }
    }

    pub(super) fn lane(&self, lane: usize) -> [Vec3A; 3] {
        self.v
            .map(|p| Vec3A::new(p[0][lane], p[1][lane], p[2][lane]))
    }
}

/// Per-ray setup of the test.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    o: Vec3A,
    /// The direction, for the f64 re-evaluation of hits too close for the f32 bound.
    d: Vec3A,
    /// Dominant axis of the direction: which cyclic permutation maps it to z.
    kz: u8,
    /// Source axis of the permuted frame's x, y and z.
    axes: [usize; 3],
    /// Origin in the permuted frame, per lane.
    o4: [Vec4; 3],
    /// (-d_x / d_z, -d_y / d_z, 1 / d_z) in the permuted frame, per lane.
    shear: [Vec4; 3],
}

/// A packet hit: lane, distance and barycentrics (b1, b2) of vertices 1 and 2.
pub type LaneHit = (usize, f32, f32, f32);

impl WatertightRay {
    /// The ray's shear and permutation, computed once for every triangle it is tested against.
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let (kz, o_perm, shear) = setup(o, d);
        Self::from_parts(o, d, kz, o_perm, shear)
    }

    /// The ray from `setup`'s results.
    #[inline(always)]
    pub(super) fn from_parts(o: Vec3, d: Vec3, kz: u8, o_perm: [f32; 3], shear: [f32; 3]) -> Self {
        WatertightRay {
            o: o.into(),
            d: d.into(),
            kz,
            axes: AXES[kz as usize],
            o4: o_perm.map(Vec4::splat),
            shear: shear.map(Vec4::splat),
        }
    }

    /// The closest hit among the packet's triangles strictly inside (tmin, tmax); ties go to
    /// the lowest lane.
    #[inline(always)]
    pub fn closest(&self, tri: &Tri4, tmin: f32, tmax: f32, skip: BVec4A) -> Option<LaneHit> {
        let (mut hit, t, b1, b2) = self.lanes(tri, tmin, tmax, skip)?;
        let (t, b1, b2) = (t.to_array(), b1.to_array(), b2.to_array());
        let mut best: Option<LaneHit> = None;
        while hit != 0 {
            let lane = hit.trailing_zeros() as usize;
            hit &= hit - 1;
            if best.is_none_or(|b| t[lane] < b.1) {
                best = Some((lane, t[lane], b1[lane], b2[lane]));
            }
        }
        best
    }

    /// True if any of the packet's triangles is hit strictly inside (tmin, tmax).
    #[inline(always)]
    pub fn any(&self, tri: &Tri4, tmin: f32, tmax: f32, skip: BVec4A) -> bool {
        self.lanes(tri, tmin, tmax, skip).is_some_and(|h| h.0 != 0)
    }

    /// Mask of lanes hit inside (tmin, tmax), with per-lane t and barycentrics; lanes set in
    /// `skip` never hit.
    #[inline(always)]
    fn lanes(
        &self,
        tri: &Tri4,
        tmin: f32,
        tmax: f32,
        skip: BVec4A,
    ) -> Option<(u32, Vec4, Vec4, Vec4)> {
        let [px, py, pz] = self.axes;
        let rel = |k: usize| {
            let v = &tri.v[k];
            (v[px] - self.o4[0], v[py] - self.o4[1], v[pz] - self.o4[2])
        };
        let (a, b, c) = (rel(0), rel(1), rel(2));
        let [sx, sy, sz] = self.shear;
        let (ax, ay) = (a.0 + sx * a.2, a.1 + sy * a.2);
        let (bx, by) = (b.0 + sx * b.2, b.1 + sy * b.2);
        let (cx, cy) = (c.0 + sx * c.2, c.1 + sy * c.2);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        if on_edge.any() {
            // Exactly on an edge in f32: decide in f64 so both neighbours agree.
            let f =
                |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            for l in 0..4 {
                if on_edge.test(l) {
                    u[l] = f(cx[l], by[l], cy[l], bx[l]);
                    v[l] = f(ax[l], cy[l], ay[l], cx[l]);
                    w[l] = f(bx[l], ay[l], by[l], ax[l]);
                }
            }
        }
        let neg = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let pos = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let det = u + v + w;
        let valid = !(neg & pos) & det.cmpne(zero) & !skip;
        if !valid.any() {
            return None;
        }
        let (az, bz, cz) = (sz * a.2, sz * b.2, sz * c.2);
        let t_scaled = u * az + v * bz + w * cz;
        let inv = Vec4::ONE / det;
        let mut t = t_scaled * inv;
        // pbrt-v4's conservative bound on the rounding error of t.
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = gamma(3.0) * max_z;
        let delta_x = gamma(5.0) * (max_x + max_z);
        let delta_y = gamma(5.0) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t =
            3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv.abs();
        // Within delta_t of 0 the hit may be the ray's own surface (this is what makes small
        // spawn offsets safe); within delta_t of tmin or tmax f32 cannot tell on which side
        // of the interval it lies (a shadow ray ending 1e-7 short of a light whose vertices
        // are 1e5 away "hit" that light at t = 0.99). The bound grows with the vertices'
        // distance from the origin, not with the distance being decided, so both happen at
        // geometry 1e-6 of the scene apart. f64 shrinks the bound 5e8-fold and decides; the
        // inside test stays f32's, so shared edges remain watertight. Below -delta_t the hit
        // is surely behind the origin.
        let (lo, hi) = (Vec4::splat(tmin), Vec4::splat(tmax));
        let near = |x: Vec4| x.abs().cmple(delta_t);
        let unsure = valid & (near(t) | near(t - lo) | near(t - hi));
        let mut hit = (valid & !unsure & t.cmpgt(lo) & t.cmplt(hi)).bitmask();
        if unsure.any() {
            hit |= self.refine(tri, unsure, &mut t, tmin, tmax);
        }
        Some((hit, t, v * inv, w * inv))
    }

    /// Lanes whose hit the f32 bound could not decide: f64 decides, and sets their t.
    #[cold]
    #[inline(never)]
    fn refine(&self, tri: &Tri4, unsure: BVec4A, t: &mut Vec4, tmin: f32, tmax: f32) -> u32 {
        let mut hit = 0;
        for l in 0..4 {
            if !unsure.test(l) {
                continue;
            }
            let exact = super::refine::distance_f64(self.o, self.d, self.kz, tri.lane(l));
            if let Some(x) = exact.filter(|&x| x > tmin as f64 && x < tmax as f64) {
                t[l] = x as f32;
                hit |= 1 << l;
            }
        }
        hit
    }
}

/// The per-ray set-up: the direction's dominant axis, the origin in the permuted frame, and
/// (-d_x / d_z, -d_y / d_z, 1 / d_z) in that frame.
#[inline(always)]
pub(super) fn setup(o: Vec3, d: Vec3) -> (u8, [f32; 3], [f32; 3]) {
    let a = d.abs();
    let kz = if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let axes = AXES[kz as usize];
    // Arrays, not glam's Index: a runtime index into a Vec3 compiles to a branch chain.
    let (oa, da) = (o.to_array(), d.to_array());
    let dp = Vec3::new(da[axes[0]], da[axes[1]], da[axes[2]]);
    let shear = crate::math::div3(Vec3::new(-dp.x, -dp.y, 1.0), dp.z);
    (kz, axes.map(|i| oa[i]), shear.to_array())
}

/// Source axes of the cyclic permutation that moves axis `kz` to z.
pub(super) const AXES: [[usize; 3]; 3] = [[1, 2, 0], [2, 0, 1], [0, 1, 2]];

/// The watertight test for a single triangle: (t, b1, b2) of a hit inside (tmin, tmax).
#[inline]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    tmin: f32,
    tmax: f32,
    v: [Vec3; 3],
) -> Option<(f32, f32, f32)> {
    let ray = WatertightRay::new(o, d);
    let (_, t, b1, b2) = ray.closest(&Tri4::new(&[v]), tmin, tmax, BVec4A::FALSE)?;
    Some((t, b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_hit_and_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let o = Vec3::new(0.25, 0.5, 1.0);
        let (t, u, v) = intersect_triangle(o, -Vec3::Z, 0.0, 10.0, tri).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6);
        assert!(intersect_triangle(o, Vec3::Z, 0.0, 10.0, tri).is_none());
        assert!(intersect_triangle(o, -Vec3::Z, 0.0, 0.5, tri).is_none());
        let outside = Vec3::new(0.8, 0.8, 1.0);
        assert!(intersect_triangle(outside, -Vec3::Z, 0.0, 10.0, tri).is_none());
        // Seen from below, with a reversed winding, and along other axes: still hit.
        let (t, ..) =
            intersect_triangle(Vec3::new(0.25, 0.5, -2.0), Vec3::Z, 0.0, 10.0, tri).unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        assert!(intersect_triangle(o, -Vec3::Z, 0.0, 10.0, [tri[0], tri[2], tri[1]]).is_some());
        let side = Vec3::new(-1.0, 0.2, 0.0);
        assert!(intersect_triangle(
            Vec3::new(3.0, 0.05, 0.3),
            side.normalize(),
            0.0,
            10.0,
            [Vec3::ZERO, Vec3::Y, Vec3::Z]
        )
        .is_some());
    }

    /// The defect that motivated the watertight test: rays aimed at the shared diagonal of
    /// two huge coplanar triangles must hit one of them, every time.
    #[test]
    fn no_ray_slips_through_a_shared_edge() {
        let s = 1e3;
        let p = [
            Vec3::new(-s, -s, 0.0),
            Vec3::new(s, -s, 0.0),
            Vec3::new(s, s, 0.0),
            Vec3::new(-s, s, 0.0),
        ];
        let tris = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
        let eye = Vec3::new(3.0, 0.0, 1.0);
        let mut rng = crate::rng::Rng::new(4, 4);
        for _ in 0..100_000 {
            let x = (rng.next_f32() - 0.5) * 1e-3;
            let target = Vec3::new(x, x + (rng.next_f32() - 0.5) * 1e-6, 0.0);
            let d = (target - eye).normalize();
            let hits = tris
                .iter()
                .filter(|t| intersect_triangle(eye, d, 0.0, f32::INFINITY, **t).is_some())
                .count();
            assert!(
                hits >= 1,
                "ray towards {target} slipped through the shared edge"
            );
        }
    }

    /// A packet answers for each triangle what a packet of that triangle alone answers,
    /// whatever its lane and neighbours: the closest lane is the minimum over single tests,
    /// with the same t and barycentrics, and `any` agrees. A skipped triangle (with the
    /// unused lanes that repeat it) is never reported.
    #[test]
    fn packet_lanes_agree_with_single_triangles() {
        let mut rng = crate::rng::Rng::new(21, 2);
        let mut p = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let mut hits = 0;
        for k in 0..20_000 {
            let n = 1 + k % 4;
            let tris: Vec<[Vec3; 3]> = (0..n).map(|_| [p(), p(), p()]).collect();
            // Aimed near the last triangle, so that most rays hit something.
            let o = p() * 3.0;
            let [a, b, c] = tris[n - 1];
            let d = ((a + b + c) / 3.0 + p() * 0.3 - o).normalize();
            let tmax = if k % 3 == 0 { 2.0 } else { f32::INFINITY };
            // Every other case skips one triangle; unused lanes repeat lane 0.
            let skipped = (k % 2 == 0).then_some(k / 2 % n);
            let lane_tri = |l: usize| if l < n { l } else { 0 };
            let skip = BVec4A::new(
                skipped == Some(lane_tri(0)),
                skipped == Some(lane_tri(1)),
                skipped == Some(lane_tri(2)),
                skipped == Some(lane_tri(3)),
            );
            let single: Vec<_> = tris
                .iter()
                .enumerate()
                .map(|(l, t)| {
                    intersect_triangle(o, d, 0.0, tmax, *t).filter(|_| skipped != Some(l))
                })
                .collect();
            let expected = single
                .iter()
                .enumerate()
                .filter_map(|(l, h)| h.map(|h| (l, h)))
                .fold(None, |b: Option<(usize, (f32, f32, f32))>, (l, h)| {
                    if b.is_none_or(|b| h.0 < b.1 .0) {
                        Some((l, h))
                    } else {
                        b
                    }
                });
            let wr = WatertightRay::new(o, d);
            let packet = Tri4::new(&tris);
            let got = wr.closest(&packet, 0.0, tmax, skip);
            assert_eq!(got.map(|h| (h.0, (h.1, h.2, h.3))), expected, "case {k}");
            assert_eq!(wr.any(&packet, 0.0, tmax, skip), expected.is_some());
            hits += expected.is_some() as u32;
        }
        assert!(hits > 5000, "only {hits} hits");
    }
}
