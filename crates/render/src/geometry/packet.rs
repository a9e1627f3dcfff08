//! Ray packets: up to eight rays (the camera or shadow rays of a pixel's eight samples)
//! traced through the BVH together.
//!
//! One stack and one walk serve the packet: each node is fetched once and tested against
//! every ray still in it (each ray with its own one-ray box test, so a ray enters exactly
//! the children it would enter alone), and a leaf's triangles are tested one at a time
//! against all its rays at once (`watertight8`) when the rays share a dominant axis, else
//! ray by ray with the one-ray test. Both tests give a ray bitwise the same hit, so a
//! packet's occlusion answers are those of `occluded`. Closest hits are too, except that two
//! hits within f32's error bound of each other (a ray exactly through an edge shared by two
//! leaves) may be visited in another order and resolved the other way, as by any other BVH.

use super::accel::{surface_point, Accel};
use super::bvh::{push_by_distance, read, slab_inv8, slab_test, Node, WideBvh};
use super::bvh::{LEAF, ROBUST, STACK};
use super::lanes8::{F8, M8};
use super::ray_packet::{bits, PACKET};
use super::ray_packet::{PacketHits, RayPacket};
use super::shape::{intersect_sphere, ShapeKind};
use super::watertight8::{Lanes3, Rays8, WatertightRay8};
use super::{Ray, Shape};
use glam::Vec2;
use std::mem::MaybeUninit;

/// Transposes an 8x8 bit matrix: bit 8r + c goes to bit 8c + r (Hacker's Delight 7-3).
#[inline(always)]
fn transpose8(mut x: u64) -> u64 {
    let t = (x ^ (x >> 7)) & 0x00AA_00AA_00AA_00AA;
    x ^= t ^ (t << 7);
    let t = (x ^ (x >> 14)) & 0x0000_CCCC_0000_CCCC;
    x ^= t ^ (t << 14);
    let t = (x ^ (x >> 28)) & 0x0000_0000_F0F0_F0F0;
    x ^ t ^ (t << 28)
}

/// The node test's set-up of a packet's rays: `BoxRay`'s, per ray, computed in lanes (the
/// same IEEE division and clamp per lane as `slab_inv`).
pub struct Boxes {
    o: [[f32; PACKET]; 3],
    inv: [[f32; PACKET]; 3],
    /// Per axis, the rays whose slab inverse is negative: their near plane is the max plane
    /// (`near_planes`).
    neg: [u32; 3],
    tmin: [f32; PACKET],
}

impl Boxes {
    /// The slab-test setup of the rays (origins `o`, directions `d`, interval starts `tmin`).
    #[inline(always)]
    pub fn new(o: &Lanes3, d: &Lanes3, tmin: &[f32; PACKET]) -> Self {
        let mut b = Boxes {
            o: *o,
            inv: [[0.0; PACKET]; 3],
            neg: [0; 3],
            tmin: *tmin,
        };
        for (a, d) in d.iter().enumerate() {
            let inv = slab_inv8(d);
            inv.store(&mut b.inv[a]);
            b.neg[a] = inv.sign_mask();
        }
        b
    }

    /// Ray r's near planes, as `near_planes` gives them.
    #[inline(always)]
    fn near(&self, r: usize) -> [usize; 3] {
        [0, 1, 2].map(|a| 2 * a + (self.neg[a] >> r & 1) as usize)
    }

    /// Children of node `n` entered by the rays in `mask`: per child, the mask of rays
    /// entering it (byte c of the result) and the nearest of their entry distances.
    #[inline(always)]
    fn enter(&self, n: &Node, mask: u32, tmax: &[f32; PACKET]) -> (u64, [f32; 8]) {
        let mut by_ray = 0u64;
        let mut key = F8::splat(f32::INFINITY);
        for r in bits(mask) {
            let o = [0, 1, 2].map(|a| F8::splat(self.o[a][r]));
            let inv = [0, 1, 2].map(|a| F8::splat(self.inv[a][r]));
            let (m, tn) = slab_test(n, &o, &inv, self.near(r), F8::splat(self.tmin[r]), tmax[r]);
            by_ray |= (m.bitmask() as u64) << (8 * r);
            key = F8::select(m, key.min(tn), key);
        }
        (transpose8(by_ray), key.to_array())
    }
}

impl WideBvh {
    /// `closest` for the rays set in `active`: on return `tmax[i]` is ray i's closest hit
    /// distance if it has one. `leaf(l, mask, tmax)` tests leaf `l` against the rays in
    /// `mask`, lowering their `tmax` to the hits it finds. `hint(c)` is told of every child
    /// slot it pushes, the next one visited included (for prefetching).
    #[inline(always)]
    pub fn closest8<F: FnMut(usize, u32, &mut [f32; PACKET])>(
        &self,
        rays: &Boxes,
        active: u32,
        tmax: &mut [f32; PACKET],
        mut leaf: F,
        hint: impl Fn(u32),
    ) {
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        let mut heap = Vec::new();
        let mut local = [MaybeUninit::<(u32, u32, f32)>::uninit(); STACK];
        let stack: &mut [_] = if self.stack_need <= STACK {
            &mut local
        } else {
            heap.resize(self.stack_need, MaybeUninit::uninit());
            &mut heap
        };
        let (mut sp, mut cur, mut cur_mask) = (0, 0u32, active);
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (by_child, keys) = rays.enter(n, cur_mask, tmax);
                if by_child != 0 {
                    // Nearest next, the others farthest deepest, as in `closest`.
                    let base = sp;
                    for (c, key) in keys.into_iter().enumerate() {
                        let m = (by_child >> (8 * c)) as u32 & 0xff;
                        if m == 0 {
                            continue;
                        }
                        hint(n.child[c]);
                        sp = push_by_distance(stack, base, sp, (n.child[c], m, key), |e| e.2);
                    }
                    sp -= 1;
                    (cur, cur_mask, _) = unsafe { read(stack, sp) };
                    continue;
                }
            } else {
                leaf((cur & !LEAF) as usize, cur_mask, tmax);
            }
            // Next waiting child with a ray whose closest hit may lie inside it.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (child, mask, key) = unsafe { read(stack, sp) };
                let live = F8::splat(key).le_mask(F8::load(tmax).mul(F8::splat(ROBUST))) & mask;
                if live != 0 {
                    (cur, cur_mask) = (child, live);
                    break;
                }
            }
        }
    }

    /// `any` for the rays set in `active`: the mask of those for which `leaf(l, mask)`
    /// reports a hit (it returns the mask of rays in `mask` it found blocked); `hint` as in
    /// `closest8`.
    #[inline(always)]
    pub fn any8<F: FnMut(usize, u32) -> u32>(
        &self,
        rays: &Boxes,
        active: u32,
        tmax: &[f32; PACKET],
        mut leaf: F,
        hint: impl Fn(u32),
    ) -> u32 {
        if self.nodes.is_empty() || active == 0 {
            return 0;
        }
        let mut heap = Vec::new();
        let mut local = [MaybeUninit::<(u32, u32)>::uninit(); STACK];
        let stack: &mut [_] = if self.stack_need <= STACK {
            &mut local
        } else {
            heap.resize(self.stack_need, MaybeUninit::uninit());
            &mut heap
        };
        let (mut sp, mut cur, mut cur_mask, mut done) = (0, 0u32, active, 0u32);
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (by_child, _) = rays.enter(n, cur_mask, tmax);
                for c in 0..8 {
                    let m = (by_child >> (8 * c)) as u32 & 0xff;
                    if m != 0 {
                        hint(n.child[c]);
                        stack[sp] = MaybeUninit::new((n.child[c], m));
                        sp += 1;
                    }
                }
            } else {
                done |= leaf((cur & !LEAF) as usize, cur_mask);
                if done == active {
                    return done;
                }
            }
            loop {
                if sp == 0 {
                    return done;
                }
                sp -= 1;
                let (child, mask) = unsafe { read(stack, sp) };
                if mask & !done != 0 {
                    (cur, cur_mask) = (child, mask & !done);
                    break;
                }
            }
        }
    }
}

/// A packet's per-ray set-up.
struct Rays<'a> {
    rays: &'a RayPacket,
    boxes: Boxes,
    tests: Rays8,
    /// The packet's active rays, for the eight-ray triangle test.
    active: u32,
}

impl<'a> Rays<'a> {
    #[inline(always)]
    fn new(rays: &'a RayPacket, active: u32) -> Self {
        Rays {
            rays,
            boxes: Boxes::new(&rays.o, &rays.d, &rays.tmin),
            tests: Rays8::new(&rays.o, &rays.d),
            active,
        }
    }

    #[inline(always)]
    fn tmin8(&self) -> F8 {
        F8::load(&self.boxes.tmin)
    }

    /// The eight-ray test for a leaf reached by the rays in `mask`, if the packet's rays share
    /// a dominant axis and it pays: with one or two rays, the one-ray test (four triangles per
    /// instruction) is cheaper.
    #[inline(always)]
    fn wide(&self, mask: u32) -> Option<WatertightRay8<'_>> {
        if mask.count_ones() > 2 {
            self.tests.packet(self.active)
        } else {
            None
        }
    }

    /// Lanes of rays that skip triangle `id`.
    #[inline(always)]
    fn skipping(&self, id: u32) -> M8 {
        let mut m = 0;
        for (i, &skip) in self.rays.skip.iter().enumerate() {
            m |= ((skip == id) as u32) << i;
        }
        M8::from_bits(m)
    }
}

impl Accel {
    /// `intersect8_into` a fresh `PacketHits`, for tests.
    #[cfg(test)]
    pub fn intersect8(&self, rays: &RayPacket, active: u32, shapes: &[Shape]) -> PacketHits {
        let mut out = PacketHits::default();
        self.intersect8_into(rays, active, shapes, &mut out);
        out
    }

    /// `intersect` for each ray set in `active`, traced as one packet, into `out` (all of it
    /// overwritten): returned by value, the 484-byte hits were copied out by a `memcpy` call
    /// on every packet (LLVM did not build them in place, even inlined).
    pub fn intersect8_into(
        &self,
        rays: &RayPacket,
        active: u32,
        shapes: &[Shape],
        out: &mut PacketHits,
    ) {
        *out = PacketHits::default();
        if active.count_ones() <= 1 {
            for i in bits(active) {
                if let Some(hit) = self.intersect(&rays.ray(i), shapes) {
                    out.set(i, &hit);
                }
            }
            return;
        }
        let r = Rays::new(rays, active);
        let tmin8 = r.tmin8();
        let mut tmax = rays.tmax;
        // Per ray, the best primitive and its barycentrics.
        let mut best = [(u32::MAX, Vec2::ZERO); PACKET];
        self.bvh.closest8(
            &r.boxes,
            active,
            &mut tmax,
            |l, mask, tmax| {
                let leaf = &self.leaves[l];
                if leaf.n_tris > 0 {
                    if let Some(w8) = r.wide(mask) {
                        // Tri4's `closest` per ray: the lowest t over the leaf, ties to the lowest
                        // triangle, every triangle tested against the same tmax.
                        let tmax8 = F8::load(tmax);
                        let inf = F8::splat(f32::INFINITY);
                        let (mut bt, mut bk, mut bb1, mut bb2) = (inf, inf, inf, inf);
                        let mut any = 0;
                        for k in 0..leaf.n_tris as usize {
                            let skip = r.skipping(leaf.tri_ref[k]);
                            let (hit, t, b1, b2) = w8.hits(&leaf.tris, k, tmin8, tmax8, mask, skip);
                            if hit == 0 {
                                continue;
                            }
                            let better = M8::from_bits(hit).and(t.lt(bt));
                            bt = F8::select(better, t, bt);
                            // The triangle's number as a bit pattern: selects move it exactly.
                            bk = F8::select(better, F8::splat(f32::from_bits(k as u32)), bk);
                            bb1 = F8::select(better, b1, bb1);
                            bb2 = F8::select(better, b2, bb2);
                            any |= hit;
                        }
                        let [bt, bk, bb1, bb2] = [bt, bk, bb1, bb2].map(F8::to_array);
                        for i in bits(any) {
                            tmax[i] = bt[i];
                            let k = bk[i].to_bits() as usize;
                            best[i] = (leaf.tri_ref[k], Vec2::new(bb1[i], bb2[i]));
                        }
                    } else {
                        for i in bits(mask) {
                            let skip = leaf.skip(r.rays.skip[i]);
                            if let Some((lane, t, b1, b2)) =
                                r.tests
                                    .ray(i)
                                    .closest(&leaf.tris, r.rays.tmin[i], tmax[i], skip)
                            {
                                tmax[i] = t;
                                best[i] = (leaf.tri_ref[lane], Vec2::new(b1, b2));
                            }
                        }
                    }
                }
                for &(c, rad, id) in &self.spheres[leaf.spheres.0 as usize..leaf.spheres.1 as usize]
                {
                    for i in bits(mask) {
                        let Ray { o, d, tmin, .. } = r.rays.ray(i);
                        if let Some(t) = intersect_sphere(o, d, tmin, tmax[i], c, rad) {
                            tmax[i] = t;
                            best[i] = (id, Vec2::ZERO);
                        }
                    }
                }
            },
            |c| self.prefetch(c),
        );
        self.fill_hits(rays, active, shapes, (&best, &tmax), out);
    }

    /// `intersect8_into` after traversal: each ray's best primitive and its distance into
    /// `out`. Hits on meshes without vertex normals (flat shading) gather their triangle here
    /// and get their points in lanes below; others get `surface_point`'s, one by one.
    #[inline(always)]
    fn fill_hits(
        &self,
        rays: &RayPacket,
        active: u32,
        shapes: &[Shape],
        (best, tmax): (&[(u32, Vec2); PACKET], &[f32; PACKET]),
        out: &mut PacketHits,
    ) {
        let (mut flat, mut v) = (0u32, [[[0.0; PACKET]; 3]; 3]);
        let (mut b1, mut b2) = ([0.0; PACKET], [0.0; PACKET]);
        for i in bits(active) {
            // As `closest`: a hit only if it shortened the ray.
            if best[i].0 == u32::MAX || !(tmax[i] < rays.tmax[i]) {
                continue;
            }
            let (shape, local) = self.refs[best[i].0 as usize];
            (out.t[i], out.shape[i], out.prim[i]) = (tmax[i], shape, local);
            out.mask |= 1 << i;
            match &shapes[shape as usize].kind {
                ShapeKind::Mesh(m) if m.normals.is_none() => {
                    for (k, p) in m.vertices(local as usize).into_iter().enumerate() {
                        for a in 0..3 {
                            v[k][a][i] = p[a];
                        }
                    }
                    let (ng, err) = m.face(local as usize);
                    for a in 0..3 {
                        (out.ng[a][i], out.ns[a][i], out.err[a][i]) = (ng[a], ng[a], err[a]);
                    }
                    (b1[i], b2[i]) = (best[i].1.x, best[i].1.y);
                    flat |= 1 << i;
                }
                _ => {
                    let sp =
                        surface_point(shapes, (shape, local), best[i].1, &rays.ray(i), tmax[i]);
                    out.set_point(i, &sp);
                }
            }
        }
        if flat != 0 {
            // `Mesh::point_from`'s position, the same IEEE operations in each lane.
            let (b1, b2) = (F8::load(&b1), F8::load(&b2));
            let b0 = F8::splat(1.0).sub(b1).sub(b2);
            let m = M8::from_bits(flat);
            for (a, out_p) in out.p.iter_mut().enumerate() {
                let p = F8::load(&v[0][a])
                    .mul(b0)
                    .add(F8::load(&v[1][a]).mul(b1))
                    .add(F8::load(&v[2][a]).mul(b2));
                F8::select(m, p, F8::load(out_p)).store(out_p);
            }
        }
    }

    /// `occluded` for each ray set in `active`, traced as one packet: the mask of those blocked.
    pub fn occluded8(&self, rays: &RayPacket, active: u32) -> u32 {
        if active.count_ones() <= 1 {
            return bits(active)
                .filter(|&i| self.occluded(&rays.ray(i)))
                .fold(0, |m, i| m | 1 << i);
        }
        let r = Rays::new(rays, active);
        let tmax = rays.tmax;
        let (tmin8, tmax8) = (r.tmin8(), F8::load(&tmax));
        self.bvh.any8(
            &r.boxes,
            active,
            &tmax,
            |l, mask| {
                let leaf = &self.leaves[l];
                let mut blocked = 0;
                if leaf.n_tris > 0 {
                    if let Some(w8) = r.wide(mask) {
                        for k in 0..leaf.n_tris as usize {
                            let skip = r.skipping(leaf.tri_ref[k]);
                            let open = mask & !blocked;
                            blocked |= w8.hits(&leaf.tris, k, tmin8, tmax8, open, skip).0;
                            if blocked == mask {
                                return blocked;
                            }
                        }
                    } else {
                        for i in bits(mask) {
                            let skip = leaf.skip(r.rays.skip[i]);
                            if r.tests
                                .ray(i)
                                .any(&leaf.tris, r.rays.tmin[i], tmax[i], skip)
                            {
                                blocked |= 1 << i;
                            }
                        }
                    }
                }
                for &(c, rad, _) in &self.spheres[leaf.spheres.0 as usize..leaf.spheres.1 as usize]
                {
                    for i in bits(mask & !blocked) {
                        let Ray { o, d, tmin, .. } = r.rays.ray(i);
                        if intersect_sphere(o, d, tmin, tmax[i], c, rad).is_some() {
                            blocked |= 1 << i;
                        }
                    }
                }
                blocked
            },
            |c| self.prefetch(c),
        )
    }
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
