use super::*;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::BvhBuildParams;
use std::time::Duration;

fn boxes(n: usize, seed: u64) -> Vec<Aabb> {
    let mut rng = crate::rng::Rng::new(seed, 3);
    (0..n)
        .map(|_| {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
            let h = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.5;
            Aabb::new((c - h).into(), (c + h).into())
        })
        .collect()
}

fn build(aabbs: &[Aabb]) -> (Bvh2, WideBvh) {
    let params = BvhBuildParams {
        max_prims_per_leaf: 4,
        ..BvhBuildParams::medium_build()
    };
    let bvh2 = build_bvh2(aabbs, params, &mut Duration::default());
    let bvh = WideBvh::from_bvh2(&bvh2);
    (bvh2, bvh)
}

/// Every primitive is reachable exactly once, and every node's boxes contain its children's.
#[test]
fn collapse_keeps_every_primitive_once() {
    for n in [1, 2, 5, 17, 1000] {
        let aabbs = boxes(n, n as u64);
        let (bvh2, bvh) = build(&aabbs);
        let mut seen = vec![0; bvh2.primitive_indices.len()];
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &bvh.nodes[i as usize];
            for lane in 0..W {
                let c = node.child[lane];
                if c == EMPTY {
                    assert!(node.b[0][lane] > node.b[1][lane]);
                } else if c & LEAF != 0 {
                    let (first, count) = bvh.leaves[(c & !LEAF) as usize];
                    for p in first as usize..(first + count) as usize {
                        seen[p] += 1;
                        let b = aabbs[bvh2.primitive_indices[p] as usize];
                        assert!(node.b[0][lane] <= b.min.x && b.max.x <= node.b[1][lane]);
                        assert!(node.b[4][lane] <= b.min.z && b.max.z <= node.b[5][lane]);
                    }
                } else {
                    stack.push(c);
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "n = {n}: {seen:?}");
    }
}

/// Closest and any-hit queries against boxes agree with brute force, including rays with
/// zero direction components and rays starting inside boxes.
#[test]
fn queries_match_brute_force() {
    let aabbs = boxes(300, 7);
    let (bvh2, bvh) = build(&aabbs);
    let mut rng = crate::rng::Rng::new(11, 4);
    let slab = |b: &Aabb, o: Vec3, d: Vec3, tmin: f32, tmax: f32| {
        let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
        let mut t0 = tmin;
        let mut t1 = tmax;
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    return f32::INFINITY;
                }
                continue;
            }
            let (mut n, mut f) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
            if n > f {
                std::mem::swap(&mut n, &mut f);
            }
            t0 = t0.max(n);
            t1 = t1.min(f);
        }
        if t0 <= t1 {
            t0
        } else {
            f32::INFINITY
        }
    };
    for k in 0..3000 {
        let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
        let mut d = Vec3::new(
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
        );
        if k % 3 == 0 {
            d[k % 9 / 3] = 0.0;
        }
        let d = d.normalize();
        let (tmin, tmax) = (0.0, if k % 2 == 0 { f32::INFINITY } else { 5.0 });
        let prim = |i: usize, tmax: f32| {
            let t = slab(&aabbs[bvh2.primitive_indices[i] as usize], o, d, tmin, tmax);
            if t < tmax {
                t
            } else {
                f32::INFINITY
            }
        };
        let leaf = |l: usize, tmax: f32| {
            let (first, count) = bvh.leaves()[l];
            (first..first + count)
                .map(|i| prim(i as usize, tmax))
                .fold(f32::INFINITY, f32::min)
        };
        let brute = (0..aabbs.len())
            .map(|i| prim(i, tmax))
            .fold(f32::INFINITY, f32::min);
        let got = bvh.closest(o, d, tmin, tmax, leaf);
        assert_eq!(got.unwrap_or(f32::INFINITY), brute, "ray {k}");
        let any = bvh.any(o, d, tmin, tmax, |l, tmax| leaf(l, tmax) < tmax);
        assert_eq!(any, brute.is_finite());
    }
}

/// The root reject never drops a ray that enters a leaf, also for rays aimed exactly at
/// the bounding box's faces and corners, and it does reject the rays that miss.
#[test]
fn may_enter_never_rejects_an_entered_leaf() {
    let aabbs: Vec<Aabb> = boxes(40, 5)
        .iter()
        .map(|b| Aabb::new(b.min * 0.1 + 4.0, b.max * 0.1 + 4.0))
        .collect();
    let (_, bvh) = build(&aabbs);
    let (lo, hi) = (Vec3::from(bvh.bounds.0), Vec3::from(bvh.bounds.1));
    let mut rng = crate::rng::Rng::new(5, 9);
    let (mut entered, mut rejected) = (0, 0);
    // Every eighth ray, the eight rays so far in lanes, for `may_enter8`.
    let (mut o8, mut d8, mut tmin8, mut tmax8) = ([[0.0; 8]; 3], [[0.0; 8]; 3], [0.0; 8], [0.0; 8]);
    let mut want8 = 0u32;
    for k in 0..20_000 {
        let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
        // Aim at the box, with coordinates snapped to its faces on some axes.
        let mut target = lo
            + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.4
            - (hi - lo) * 0.2;
        for a in 0..3 {
            match (k >> (2 * a)) & 3 {
                0 => target[a] = lo[a],
                1 => target[a] = hi[a],
                _ => {}
            }
        }
        let d = target - o;
        let (tmin, tmax) = (0.0, if k % 2 == 0 { f32::INFINITY } else { 1.0 });
        let any = bvh.any(o, d, tmin, tmax, |_, _| true);
        let may = bvh.may_enter(o, d, tmin, tmax);
        assert!(may || !any, "ray {k} enters a leaf but was rejected");
        let lane = k % 8;
        for a in 0..3 {
            (o8[a][lane], d8[a][lane]) = (o[a], d[a]);
        }
        (tmin8[lane], tmax8[lane]) = (tmin, tmax);
        want8 = want8 & !(1 << lane) | (may as u32) << lane;
        if lane == 7 {
            let got = bvh.may_enter8(&o8, &d8, &tmin8, &tmax8);
            assert_eq!(got, want8, "rays {} to {k} in lanes", k - 7);
        }
        entered += any as u32;
        rejected += !may as u32;
    }
    assert!(
        entered > 2000 && rejected > 2000,
        "{entered} entered, {rejected} rejected"
    );
}
