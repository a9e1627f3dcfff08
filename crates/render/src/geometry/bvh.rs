//! An 8-wide BVH collapsed from obvhs's binary BVH (PLOC build plus reinsertion) and traversed
//! with one 8-lane box test per node (see `lanes8`). (8 children beat 4 by 5-8 % on cbox and
//! veach-mis rays: fewer nodes on the way down, fewer unpredictable branches.)
//!
//! Why not obvhs's own CwBvh traversal: its 8-bit quantised child boxes cost a decode per node,
//! and it culls boxes entered closer than an absolute t of 1e-4, which leaks rays at small scene
//! scales. Here child boxes are plain f32 in SoA layout, the ray's tmin is honoured exactly, and
//! the slab test is made conservative with pbrt-v4's (1 + 2 gamma(3)) factor so that a ray
//! through the shared edge of two triangles in different leaves enters both leaves.

use super::lanes8::{F8, M8};
use glam::{Vec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2};
use std::mem::MaybeUninit;

/// Child slot tags: a leaf is `LEAF | leaf index`, an internal child is its node index, an
/// empty slot is `EMPTY` (its box is inverted so it is never entered).
pub(super) const LEAF: u32 = 1 << 31;
const EMPTY: u32 = u32::MAX;
/// pbrt-v4's 1 + 2 gamma(3): the slab test's far distances are scaled by it.
pub(super) const ROBUST: f32 =
    1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);
/// Stack entries the traversal keeps on its own stack; deeper trees use a heap stack.
pub(super) const STACK: usize = 64;
/// Children per node, tested together.
const W: usize = 8;

#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Node {
    /// Per plane (min x, max x, min y, max y, min z, max z), its coordinate for each child.
    b: [[f32; W]; 6],
    pub(super) child: [u32; W],
}

pub struct WideBvh {
    pub(super) nodes: Vec<Node>,
    /// The box around everything, (min, max), for `may_enter`.
    bounds: (Vec3A, Vec3A),
    /// Per leaf: its first position in the binary BVH's `primitive_indices` and its count.
    leaves: Vec<(u32, u32)>,
    /// Stack entries a traversal may need: W - 1 per level below the root, plus one.
    pub(super) stack_need: usize,
}

/// Nodes above which a tree prefetches (about 450 kB of nodes).
const PREFETCH_NODES: usize = 2048;

/// Per-ray data of the box test.
struct BoxRay {
    o: [F8; 3],
    inv: [F8; 3],
    /// Index into `Node::b` of each axis's near plane (by the direction's sign); the far one is
    /// its neighbour, `near ^ 1`.
    near: [usize; 3],
    tmin: F8,
}

/// The slab test's 1 / d. 1/0 = inf would meet a zero (b - o) and give NaN; f32::MAX keeps
/// every product ordered (0 stays 0, anything else overflows to the right infinity).
#[inline(always)]
pub(super) fn slab_inv(d: Vec3) -> Vec3A {
    (Vec3A::ONE / Vec3A::from(d)).clamp(Vec3A::splat(-f32::MAX), Vec3A::splat(f32::MAX))
}

/// `slab_inv` of one axis of eight directions, in lanes: the same IEEE operations per lane.
#[inline(always)]
pub(super) fn slab_inv8(d: &[f32; 8]) -> F8 {
    F8::splat(1.0)
        .div(F8::load(d))
        .max(F8::splat(-f32::MAX))
        .min(F8::splat(f32::MAX))
}

/// Index into `Node::b` of each axis's near plane for a ray with slab inverse `inv`: the
/// min plane where the direction is positive, the max plane where it is negative.
#[inline(always)]
pub(super) fn near_planes(inv: Vec3A) -> [usize; 3] {
    let neg = |x: f32| x.is_sign_negative() as usize;
    [neg(inv.x), 2 + neg(inv.y), 4 + neg(inv.z)]
}

impl BoxRay {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3, tmin: f32) -> Self {
        let inv = slab_inv(d);
        let near = near_planes(inv);
        BoxRay {
            o: [F8::splat(o.x), F8::splat(o.y), F8::splat(o.z)],
            inv: [F8::splat(inv.x), F8::splat(inv.y), F8::splat(inv.z)],
            near,
            tmin: F8::splat(tmin),
        }
    }

    /// Entry distances of the children and the mask of those entered before `tmax`.
    #[inline(always)]
    fn test(&self, n: &Node, tmax: f32) -> (u32, [f32; W]) {
        let (mask, tn) = self.test8(n, tmax);
        (mask.bitmask(), tn.to_array())
    }

    /// `test` with its answers in lanes.
    #[inline(always)]
    fn test8(&self, n: &Node, tmax: f32) -> (M8, F8) {
        slab_test(n, &self.o, &self.inv, self.near, self.tmin, tmax)
    }
}

/// The node test of one ray, its origin, slab inverse and tmin given in every lane: entry
/// distances of the children and the lanes of those entered before `tmax`.
#[inline(always)]
pub(super) fn slab_test(
    n: &Node,
    o: &[F8; 3],
    inv: &[F8; 3],
    near: [usize; 3],
    tmin: F8,
    tmax: f32,
) -> (M8, F8) {
    let t = |i: usize, a: usize| F8::load(&n.b[i]).sub(o[a]).mul(inv[a]);
    let tn = t(near[0], 0)
        .max(t(near[1], 1))
        .max(t(near[2], 2))
        .max(tmin);
    let tf = t(near[0] ^ 1, 0)
        .min(t(near[1] ^ 1, 1))
        .min(t(near[2] ^ 1, 2))
        .min(F8::splat(tmax));
    (tn.le(tf.mul(F8::splat(ROBUST))), tn)
}

/// Pushes `entry` onto a closest-hit traversal's stack of children waiting since `base`,
/// keeping them farthest deepest by `key`; returns the new stack pointer.
#[inline(always)]
pub(super) fn push_by_distance<T: Copy>(
    stack: &mut [MaybeUninit<T>],
    base: usize,
    sp: usize,
    entry: T,
    key: impl Fn(&T) -> f32,
) -> usize {
    let mut k = sp;
    while k > base && key(&unsafe { read(stack, k - 1) }) < key(&entry) {
        stack[k] = stack[k - 1];
        k -= 1;
    }
    stack[k] = MaybeUninit::new(entry);
    sp + 1
}

/// Entry `i` of a traversal stack.
///
/// # Safety
/// Entry `i` must have been written: the traversals read only entries below their stack
/// pointer, each written when it was pushed.
#[inline(always)]
pub(super) unsafe fn read<T: Copy>(stack: &[MaybeUninit<T>], i: usize) -> T {
    unsafe { stack[i].assume_init() }
}

impl WideBvh {
    pub fn empty() -> WideBvh {
        WideBvh {
            nodes: Vec::new(),
            // Inverted: no ray enters an empty tree.
            bounds: (Vec3A::INFINITY, Vec3A::NEG_INFINITY),
            leaves: Vec::new(),
            stack_need: 1,
        }
    }

    /// Whether the packet traversals' callers prefetch entered children (`Accel::prefetch`):
    /// for trees larger than the caches near the core.
    #[inline(always)]
    pub(super) fn prefetches(&self) -> bool {
        self.nodes.len() > PREFETCH_NODES
    }

    /// Collapses a binary BVH. Leaves are numbered in the order `leaves()` lists them.
    pub fn from_bvh2(bvh: &Bvh2) -> WideBvh {
        let mut out = WideBvh::empty();
        if bvh.nodes.is_empty() {
            return out;
        }
        let depth = out.collapse(bvh, 0, true);
        out.stack_need = (W - 1) * depth + 1;
        let Aabb { min, max } = *bvh.nodes[0].aabb();
        out.bounds = (min, max);
        out
    }

    /// False only if no query of this ray can enter any node: the node test's arithmetic on
    /// the box around everything, which contains every child box, so every plane distance it
    /// rounds lies at least as far out. A scalar reject costing a tenth of a traversal's set-up,
    /// for structures most rays miss (the emitter pre-test's).
    #[inline(always)]
    pub fn may_enter(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> bool {
        let inv = slab_inv(d);
        let o = Vec3A::from(o);
        let (t0, t1) = ((self.bounds.0 - o) * inv, (self.bounds.1 - o) * inv);
        // No NaN can arise (finite times finite), so min and max pick the plane the node test
        // picks by the sign of inv.
        let tn = t0.min(t1).max_element().max(tmin);
        let tf = t0.max(t1).min_element().min(tmax);
        tn <= tf * ROBUST
    }

    /// `may_enter` of eight rays, given one array per component, in lanes: bit i is lane
    /// i's answer. The same IEEE operations per lane (min and max may differ from the scalar
    /// order only in the sign of a zero, which `<=` does not see).
    #[inline(always)]
    pub fn may_enter8(
        &self,
        o: &[[f32; 8]; 3],
        d: &[[f32; 8]; 3],
        tmin: &[f32; 8],
        tmax: &[f32; 8],
    ) -> u32 {
        let (mut tn, mut tf) = (F8::load(tmin), F8::load(tmax));
        for a in 0..3 {
            let inv = slab_inv8(&d[a]);
            let o = F8::load(&o[a]);
            let t0 = F8::splat(self.bounds.0[a]).sub(o).mul(inv);
            let t1 = F8::splat(self.bounds.1[a]).sub(o).mul(inv);
            tn = tn.max(t0.min(t1));
            tf = tf.min(t0.max(t1));
        }
        tn.le_mask(tf.mul(F8::splat(ROBUST)))
    }

    /// Appends the wide node standing for binary node `i` (or, for the root leaf, a node
    /// holding it) and returns the depth of the subtree in wide nodes.
    fn collapse(&mut self, bvh: &Bvh2, i: usize, root: bool) -> usize {
        let mut kids: Vec<usize> = if bvh.nodes[i].is_leaf() {
            debug_assert!(root);
            vec![i]
        } else {
            let f = bvh.nodes[i].first_index as usize;
            vec![f, f + 1]
        };
        // Open the largest internal child until there are four.
        while kids.len() < W {
            let Some(k) = (0..kids.len())
                .filter(|&k| !bvh.nodes[kids[k]].is_leaf())
                .max_by(|&a, &b| {
                    let area = |k: usize| bvh.nodes[kids[k]].aabb().half_area();
                    area(a).total_cmp(&area(b))
                })
            else {
                break;
            };
            let f = bvh.nodes[kids[k]].first_index as usize;
            kids[k] = f;
            kids.push(f + 1);
        }
        let me = self.nodes.len();
        self.nodes.push(Node {
            b: [
                [f32::INFINITY; W],
                [f32::NEG_INFINITY; W],
                [f32::INFINITY; W],
                [f32::NEG_INFINITY; W],
                [f32::INFINITY; W],
                [f32::NEG_INFINITY; W],
            ],
            child: [EMPTY; W],
        });
        let mut depth = 1;
        for (lane, &k) in kids.iter().enumerate() {
            let n = &bvh.nodes[k];
            let child = if n.is_leaf() {
                self.leaves.push((n.first_index, n.prim_count));
                LEAF | (self.leaves.len() - 1) as u32
            } else {
                let c = self.nodes.len() as u32;
                depth = depth.max(1 + self.collapse(bvh, k, false));
                c
            };
            let Aabb { min, max } = *n.aabb();
            let node = &mut self.nodes[me];
            node.child[lane] = child;
            for (axis, (lo, hi)) in [(min.x, max.x), (min.y, max.y), (min.z, max.z)]
                .into_iter()
                .enumerate()
            {
                node.b[2 * axis][lane] = lo;
                node.b[2 * axis + 1][lane] = hi;
            }
        }
        depth
    }

    /// The box around everything (inverted for an empty tree).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.bounds.0.into(), self.bounds.1.into())
    }

    /// Per leaf: its first position in the binary BVH's `primitive_indices` and its count.
    pub fn leaves(&self) -> &[(u32, u32)] {
        &self.leaves
    }

    /// Distance to the closest hit in (tmin, tmax): `leaf(i, tmax)` returns the distance to the
    /// closest hit in leaf `i` inside (tmin, tmax), else infinity.
    #[inline(always)]
    pub fn closest<F: FnMut(usize, f32) -> f32>(
        &self,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        leaf: F,
    ) -> Option<f32> {
        // Uninitialised: zeroing 512 bytes per ray cost more than a node test on small scenes.
        if self.stack_need <= STACK {
            let mut stack = [MaybeUninit::uninit(); STACK];
            self.closest_with(&mut stack, o, d, tmin, tmax, leaf)
        } else {
            let mut stack = vec![MaybeUninit::uninit(); self.stack_need];
            self.closest_with(&mut stack, o, d, tmin, tmax, leaf)
        }
    }

    /// True if `leaf(i, tmax)` reports a hit for any leaf whose box the ray enters.
    #[inline(always)]
    pub fn any<F: FnMut(usize, f32) -> bool>(
        &self,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        leaf: F,
    ) -> bool {
        if self.stack_need <= STACK {
            let mut stack = [MaybeUninit::uninit(); STACK];
            self.any_with(&mut stack, o, d, tmin, tmax, leaf)
        } else {
            let mut stack = vec![MaybeUninit::uninit(); self.stack_need];
            self.any_with(&mut stack, o, d, tmin, tmax, leaf)
        }
    }

    #[inline(always)]
    fn closest_with<F: FnMut(usize, f32) -> f32>(
        &self,
        stack: &mut [MaybeUninit<(u32, f32)>],
        o: Vec3,
        d: Vec3,
        tmin: f32,
        mut tmax: f32,
        mut leaf: F,
    ) -> Option<f32> {
        if self.nodes.is_empty() {
            return None;
        }
        let ray = BoxRay::new(o, d, tmin);
        let mut best = None;
        let mut sp = 0;
        let mut cur = 0u32;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (mut mask, tn) = ray.test(n, tmax);
                if mask != 0 {
                    // The nearest entered child is visited next; the others wait on the stack,
                    // farthest deepest.
                    let base = sp;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let entry = (n.child[lane], tn[lane]);
                        sp = push_by_distance(stack, base, sp, entry, |e| e.1);
                    }
                    sp -= 1;
                    cur = unsafe { read(stack, sp) }.0;
                    continue;
                }
            } else {
                let t = leaf((cur & !LEAF) as usize, tmax);
                if t < tmax {
                    tmax = t;
                    best = Some(t);
                }
            }
            // Next waiting child still entered before the current closest hit.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (child, t) = unsafe { read(stack, sp) };
                if t <= tmax * ROBUST {
                    cur = child;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any_with<F: FnMut(usize, f32) -> bool>(
        &self,
        stack: &mut [MaybeUninit<u32>],
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        mut leaf: F,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let ray = BoxRay::new(o, d, tmin);
        let mut sp = 0;
        let mut cur = 0u32;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (mut mask, _) = ray.test(n, tmax);
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack[sp] = MaybeUninit::new(n.child[lane]);
                    sp += 1;
                }
            } else if leaf((cur & !LEAF) as usize, tmax) {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = unsafe { read(stack, sp) };
        }
    }
}

#[cfg(test)]
#[path = "bvh_tests.rs"]
mod tests;
