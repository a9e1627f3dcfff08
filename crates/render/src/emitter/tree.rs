//! A light tree in the manner of pbrt-v4's `BVHLightSampler`: a binary tree over the emitters,
//! each node with the `LightBounds` of what it holds; a choice walks down from the root,
//! taking each child with probability proportional to its importance at the shading point.
//!
//! Unlike pbrt-v4, a light's pmf is found without a bit trail (pbrt's 32-bit trail limits
//! the depth): the leaves hold the emitters in tree order, every interior node stores the
//! first position of its second child, and the walk for emitter e goes to the second child
//! where e's position is at least that. The walk and the choice compute the same factors in
//! the same order, so the pmf a choice reports is bitwise `pmf`'s. Trees of any depth work;
//! the build keeps its own stack.
//!
//! The choice's single random number is rescaled at every level, in f64, so a walk keeps the
//! number's 24 bits for as long as they last; below about 24 levels of near-even splits the
//! choice among the deepest lights rests on fewer bits (pbrt shares this limit).

use super::bounds::LightBounds;
use super::rules::ChoiceRule;
use super::Emitter;
use crate::geometry::Shape;
use glam::Vec3;

const LEAF: u32 = u32::MAX;

#[derive(Clone, Debug)]
struct Node {
    bounds: LightBounds,
    /// Interior: the index of the second child (the first is the next node). Leaf: LEAF.
    second: u32,
    /// Interior: the first leaf position of the second child. Leaf: the emitter.
    split: u32,
}

#[derive(Clone, Debug)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Per emitter: its position among the leaves in tree order, or LEAF if it is not in the
    /// tree (it emits nothing).
    position: Vec<u32>,
}

/// pbrt-v4's cost of a node in the surface area orientation heuristic: power times the
/// solid angle its emission can reach times its box's area, stretched by how thin the box
/// is along the split axis.
fn cost(b: &LightBounds, whole: &LightBounds, dim: usize) -> f64 {
    use std::f64::consts::PI;
    let (cos_o, sin_o) = (b.normals.cos as f64, b.normals.sin as f64);
    let theta_o = sin_o.atan2(cos_o);
    let theta_e = (b.cos_e as f64).clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let m_omega = 2.0 * PI * (1.0 - cos_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + cos_o);
    let diag = (whole.hi - whole.lo).as_dvec3();
    let kr = if diag[dim] > 0.0 {
        diag.max_element() / diag[dim]
    } else {
        1.0
    };
    let e = (b.hi - b.lo).as_dvec3();
    let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    b.phi as f64 * m_omega * kr * area
}

const BUCKETS: usize = 12;

/// The bucket of a centroid along `dim` between the centroids' bounds `clo` and `chi`.
fn bucket_of(b: &LightBounds, dim: usize, clo: Vec3, chi: Vec3) -> usize {
    let t = (b.centroid()[dim] - clo[dim]) / (chi[dim] - clo[dim]);
    ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
}

/// The split of `items` (emitter, bounds) that pbrt-v4's bucketed SAOH prefers, as the
/// number of items that go first after `items` is reordered; None if every centroid is the
/// same (the caller halves the range).
fn split(items: &mut [(u32, LightBounds)]) -> Option<usize> {
    let whole = items[1..]
        .iter()
        .fold(items[0].1, |acc, (_, b)| acc.union(b));
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(-f32::INFINITY));
    for (_, b) in items.iter() {
        (clo, chi) = (clo.min(b.centroid()), chi.max(b.centroid()));
    }
    let mut best: Option<(f64, usize, usize)> = None;
    for dim in 0..3 {
        if !(chi[dim] > clo[dim]) {
            continue;
        }
        let bucket = |b: &LightBounds| bucket_of(b, dim, clo, chi);
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, b) in items.iter() {
            let k = bucket(b);
            buckets[k] = Some(buckets[k].map_or(*b, |x| x.union(b)));
        }
        for cut in 1..BUCKETS {
            let join = |r: &[Option<LightBounds>]| {
                r.iter()
                    .flatten()
                    .fold(None, |acc: Option<LightBounds>, b| {
                        Some(acc.map_or(*b, |a| a.union(b)))
                    })
            };
            let (Some(below), Some(above)) = (join(&buckets[..cut]), join(&buckets[cut..])) else {
                continue;
            };
            let c = cost(&below, &whole, dim) + cost(&above, &whole, dim);
            if best.is_none_or(|(bc, _, _)| c < bc) {
                best = Some((c, dim, cut));
            }
        }
    }
    let (_, dim, cut) = best?;
    let t = |b: &LightBounds| bucket_of(b, dim, clo, chi) < cut;
    // A stable partition keeps the build deterministic.
    let (mut first, second): (Vec<_>, Vec<_>) = items.iter().partition(|(_, b)| t(b));
    let n = first.len();
    first.extend(second);
    items.copy_from_slice(&first);
    (n > 0 && n < items.len()).then_some(n)
}

impl LightTree {
    /// The tree over the emitters whose bounds are given (None: never chosen).
    pub fn build(bounds: &[Option<LightBounds>]) -> LightTree {
        let mut items: Vec<(u32, LightBounds)> = bounds
            .iter()
            .enumerate()
            .filter_map(|(e, b)| b.map(|b| (e as u32, b)))
            .collect();
        let mut nodes: Vec<Node> = Vec::with_capacity(2 * items.len());
        // (start, end, parent whose `second` this node is)
        let mut stack = vec![(0usize, items.len(), None::<usize>)];
        if items.is_empty() {
            stack.clear();
        }
        while let Some((start, end, parent)) = stack.pop() {
            let index = nodes.len();
            if let Some(p) = parent {
                nodes[p].second = index as u32;
            }
            let range = &mut items[start..end];
            if range.len() == 1 {
                nodes.push(Node {
                    bounds: range[0].1,
                    second: LEAF,
                    split: range[0].0,
                });
                continue;
            }
            let mid = start + split(range).unwrap_or(range.len() / 2);
            let range = &items[start..end];
            let b = range[1..]
                .iter()
                .fold(range[0].1, |acc, (_, b)| acc.union(b));
            nodes.push(Node {
                bounds: b,
                second: 0,
                split: mid as u32,
            });
            // The first child is built next (it is node index + 1).
            stack.push((mid, end, Some(index)));
            stack.push((start, mid, None));
        }
        let mut position = vec![LEAF; bounds.len()];
        for (k, (e, _)) in items.iter().enumerate() {
            position[*e as usize] = k as u32;
        }
        LightTree { nodes, position }
    }

    /// The number of levels (a lone leaf: 1; no emitter: 0).
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(0usize, 1usize)];
        if self.nodes.is_empty() {
            return 0;
        }
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            let n = &self.nodes[i];
            if n.second != LEAF {
                stack.push((i + 1, d + 1));
                stack.push((n.second as usize, d + 1));
            }
        }
        deepest
    }

    /// The probabilities of a node's two children at (p, n), or None if neither can
    /// contribute.
    #[inline]
    fn children(&self, i: usize, p: Vec3, n: Vec3) -> Option<(f64, f64)> {
        let node = &self.nodes[i];
        let c0 = self.nodes[i + 1].bounds.importance(p, n);
        let c1 = self.nodes[node.second as usize].bounds.importance(p, n);
        let total = c0 + c1;
        (total > 0.0).then(|| (c0 / total, c1 / total))
    }

    /// An emitter and its pmf at shading point `p` with normal `n`, or None: no emitter
    /// can contribute there (the probability of that is 1 - the sum of the pmfs).
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        let root = self.nodes.first()?;
        if root.second == LEAF {
            return (root.bounds.importance(p, n) > 0.0).then_some((root.split as usize, 1.0));
        }
        let (mut i, mut pmf, mut u) = (0usize, 1.0f64, u as f64);
        const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;
        loop {
            let node = &self.nodes[i];
            if node.second == LEAF {
                return Some((node.split as usize, pmf as f32));
            }
            let (p0, p1) = self.children(i, p, n)?;
            if u < p0 {
                u = (u / p0).min(BELOW_ONE);
                pmf *= p0;
                i += 1;
            } else {
                u = ((u - p0) / p1).min(BELOW_ONE);
                pmf *= p1;
                i = node.second as usize;
            }
        }
    }

    /// The pmf with which `sample` at (p, n) chooses emitter `e`.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, e: usize) -> f32 {
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let pos = self.position[e];
        if pos == LEAF {
            return 0.0;
        }
        if root.second == LEAF {
            return if root.bounds.importance(p, n) > 0.0 {
                1.0
            } else {
                0.0
            };
        }
        let (mut i, mut pmf) = (0usize, 1.0f64);
        loop {
            let node = &self.nodes[i];
            if node.second == LEAF {
                return pmf as f32;
            }
            let Some((p0, p1)) = self.children(i, p, n) else {
                return 0.0;
            };
            if pos < node.split {
                pmf *= p0;
                i += 1;
            } else {
                pmf *= p1;
                i = node.second as usize;
            }
            if pmf == 0.0 {
                return 0.0;
            }
        }
    }

    /// The probability that `sample` at (p, n) chooses nothing: the mass of the walks that
    /// end at a node whose children both have importance 0 (tests; visits every node).
    pub fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
        let Some(root) = self.nodes.first() else {
            return 1.0;
        };
        if root.second == LEAF {
            return if root.bounds.importance(p, n) > 0.0 {
                0.0
            } else {
                1.0
            };
        }
        let mut none = 0.0;
        let mut stack = vec![(0usize, 1.0f64)];
        while let Some((i, mass)) = stack.pop() {
            let node = &self.nodes[i];
            if node.second == LEAF || mass == 0.0 {
                continue;
            }
            match self.children(i, p, n) {
                None => none += mass,
                Some((p0, p1)) => {
                    stack.push((i + 1, mass * p0));
                    stack.push((node.second as usize, mass * p1));
                }
            }
        }
        none
    }

    /// Bytes the tree takes (the bench's memory column).
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.position.len() * 4
    }
}

/// The light tree as an emitter-choice rule (`bvh`).
impl ChoiceRule for LightTree {
    const POINT_INDEPENDENT: bool = false;

    fn build(emitters: &[Emitter], shapes: &[Shape]) -> Self {
        let bounds: Vec<Option<LightBounds>> = emitters
            .iter()
            .map(|e| LightBounds::of(e, shapes))
            .collect();
        LightTree::build(&bounds)
    }

    #[inline]
    fn sample(&self, _: usize, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        LightTree::sample(self, p, n, u)
    }

    #[inline]
    fn pmf(&self, _: usize, p: Vec3, n: Vec3, i: usize) -> f32 {
        LightTree::pmf(self, p, n, i)
    }

    fn none_probability(&self, p: Vec3, n: Vec3) -> f64 {
        LightTree::none_probability(self, p, n)
    }

    fn tree_stats(&self) -> Option<(usize, usize)> {
        Some((self.depth(), self.bytes()))
    }

    /// The two children of each inner node on a root-to-leaf path, counted at the tree's
    /// depth (paths are shorter in an unbalanced tree: an upper bound, the same for every
    /// draw); a tree of one leaf weighs that leaf.
    fn evaluations(&self, _count: usize) -> u64 {
        (2 * (self.depth() as u64).saturating_sub(1)).max(1)
    }
}
