//! The renderer's random streams: neighbouring samples, pixels and seeds draw independent
//! numbers (a chi-square test of pairs, with the harness's statistics).

use crate::rng::Rng;

/// A pixel's samples share a stream and each seed's pixels are hashed apart: the draws
/// of neighbouring samples, pixels and seeds (same draw index) must look independent.
/// Pearson test of the 16x16 histogram of (draw k of one, draw k of its neighbour),
/// uniform under independence: 2^16 pairs per test, 3 neighbours x 3 draw indices,
/// family-wise significance 1e-3 (Sidak). Unmixed starts (state = key ^ sample) fail it.
#[test]
fn neighbouring_samples_pixels_and_seeds_are_independent() {
    use crate::stats::chi2::{chi2_sf, pearson};
    use crate::stats::ttest::sidak;
    type Pair = fn(u64) -> (Rng, Rng);
    let neighbours: [(&str, Pair); 3] = [
        ("samples", |i| {
            (Rng::for_sample(3, 40, i), Rng::for_sample(3, 40, i + 1))
        }),
        ("pixels", |i| {
            (Rng::for_sample(3, i, 7), Rng::for_sample(3, i + 1, 7))
        }),
        ("seeds", |i| {
            (Rng::for_sample(i, 40, 7), Rng::for_sample(i + 1, 40, 7))
        }),
    ];
    let draws = [0, 1, 8];
    let level = sidak(1e-3, neighbours.len() * draws.len());
    let (n, side) = (1u64 << 16, 16usize);
    for (what, pair) in neighbours {
        for k in draws {
            let mut counts = vec![0u32; side * side];
            for i in 0..n {
                let (mut a, mut b) = pair(i);
                (0..k).for_each(|_| (_, _) = (a.next_u32(), b.next_u32()));
                let cell = |r: &mut Rng| (r.next_f32() * side as f32) as usize;
                counts[cell(&mut a) * side + cell(&mut b)] += 1;
            }
            let expected = n as f64 / (side * side) as f64;
            let mut cells: Vec<(f64, f64)> = counts.iter().map(|&c| (c as f64, expected)).collect();
            let t = pearson(&mut cells, 5.0).unwrap();
            let p = chi2_sf(t.statistic, t.dof);
            assert!(p > level, "{what}, draw {k}: p = {p:.2e} < {level:.2e}");
        }
    }
}
