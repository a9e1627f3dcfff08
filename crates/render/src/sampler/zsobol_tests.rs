use super::*;
use crate::sampler::pure::PureSample;
use crate::sampler::{is_02_net, DimAlloc, Sampler, SamplerLanes, Sampling};
use sobol_burley::parts::sobol_int4_rev;

fn cfg(seed: u64, run_samples: u64, (width, height): (u32, u32)) -> SamplerConfig {
    SamplerConfig {
        dims: DimAlloc::Joint,
        seed,
        run_samples,
        width,
        height,
    }
}

fn film(px: ZPixel, s: u64) -> (f32, f32) {
    let p = crate::sampler::pure::PurePixel::<ZSobol> {
        inner: px,
        joint: true,
    };
    let f = PureSample::new(p, s).film();
    (f.x, f.y)
}

/// The 32-bit generator is sobol_burley's sequence where the crate has one (16 index
/// bits), and a (0, 2)-sequence in dimensions 0-1 beyond: every aligned block of 2^m
/// points is a (0, m, 2)-net, at indices far past 2^16 too.
#[test]
fn generator_is_the_crates_sequence_and_a_02_sequence_beyond_it() {
    for i in 0..1u32 << 16 {
        let want: [u32; 4] = sobol_int4_rev(i.reverse_bits(), 0).reverse_bits().into();
        assert_eq!(sobol4(i), want, "index {i}");
    }
    let unit = sobol_burley::parts::u32_to_f32_norm;
    for m in [1, 4, 7, 10] {
        for block in [3u64, 0x1234, 0x9_8765, (1 << (32 - m)) - 1] {
            let pts: Vec<(f32, f32)> = (0..1u64 << m)
                .map(|j| {
                    let v = sobol4(((block << m) + j) as u32);
                    (unit(v[0]), unit(v[1]))
                })
                .collect();
            assert!(is_02_net(&pts, m), "m {m} block {block:#x}");
        }
    }
    assert_eq!(PERMUTATIONS.len(), 24);
    let mut seen = PERMUTATIONS.to_vec();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), 24);
}

#[test]
fn morton_interleaves_x_in_even_bits() {
    assert_eq!(morton2(0b11, 0), 0b0101);
    assert_eq!(morton2(0, 0b11), 0b1010);
    assert_eq!(morton2(5, 3), 0b01_1011);
    assert_eq!(morton2(u32::MAX, 0), 0x5555_5555_5555_5555);
}

/// The digit permutations are a bijection of the index space that gives each pixel an
/// aligned block of 2^m indices: for even and odd m, on a film that is not square.
#[test]
fn every_pixel_takes_its_own_aligned_block() {
    for spp in [1u64, 2, 4, 8, 32] {
        let (w, h) = (8, 5);
        let c = cfg(11, spp, (w, h));
        for dim in [0, 3, 9] {
            let mut all = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    let px = ZSobol::pixel(&c, x, y);
                    let mut block: Vec<u64> = (0..spp)
                        .map(|s| px.permute_digits(px.morton(s), dim, 0, u32::MAX))
                        .collect();
                    block.sort();
                    let first = block[0];
                    assert_eq!(first % spp, 0, "spp {spp} dim {dim} pixel ({x}, {y})");
                    assert_eq!(block, (first..first + spp).collect::<Vec<_>>());
                    all.extend(block);
                }
            }
            let n = all.len();
            all.sort();
            all.dedup();
            assert_eq!(
                all.len(),
                n,
                "spp {spp} dim {dim}: two pixels share an index"
            );
            assert!(all.iter().all(|&i| i < 64 * spp));
        }
    }
}

/// Blue noise by construction: one pixel's 2^m film points are a (0, m, 2)-net, and so
/// are the 4 * 2^m points of each aligned 2 x 2 quad of pixels and the 16 * 2^m of each
/// 4 x 4 one (their values, not their positions on the film).
#[test]
fn pixels_and_their_quads_are_nets() {
    for (m, seed) in [(0u32, 1u64), (1, 2), (2, 3), (3, 4), (4, 5)] {
        let c = cfg(seed, 1 << m, (16, 16));
        for k in [0u32, 1, 2] {
            let side = 1u32 << k;
            for (qx, qy) in [(0, 0), (side, side), (8, 4 * side % 16)] {
                let mut pts = Vec::new();
                for y in qy..qy + side {
                    for x in qx..qx + side {
                        let px = ZSobol::pixel(&c, x, y);
                        pts.extend((0..1u64 << m).map(|s| film(px, s)));
                    }
                }
                assert!(
                    is_02_net(&pts, m + 2 * k),
                    "m {m}, {side}x{side} quad at ({qx}, {qy})"
                );
            }
        }
    }
    // The check itself: two pixels that are not a quad's halves are not a net together.
    let c = cfg(1, 4, (16, 16));
    let two: Vec<(f32, f32)> = [(0, 0), (3, 5), (8, 1), (13, 2)]
        .iter()
        .flat_map(|&(x, y)| (0..4).map(move |s| film(ZSobol::pixel(&c, x, y), s)))
        .collect();
    assert!(!is_02_net(&two, 4));
}

/// Lanes give each sample the scalar sample's numbers, aligned or not, and for sample
/// counts below a lane batch (lanes past the last sample wrap and are dropped).
#[test]
fn lanes_match_scalar_samples() {
    for (spp, s0) in [
        (64u64, 0u64),
        (64, 8),
        (64, 5),
        (4, 0),
        (2, 0),
        (1 << 10, 1000),
    ] {
        for dims in [DimAlloc::Joint, DimAlloc::Padded] {
            let c = SamplerConfig {
                dims,
                ..cfg(7, spp, (20, 12))
            };
            let px = ZSobolLanes::pixel(&c, 13, 9);
            let mut lanes = ZSobolLanes::start(px, s0);
            let (f, l, b) = (lanes.film(), lanes.light(), lanes.bsdf());
            for i in (0..LANES).rev() {
                let mut one = PureSample::new(px, s0 + i as u64);
                let (fo, lo, bo) = (one.film(), one.light(), one.bsdf());
                assert_eq!(
                    [f[0][i], f[1][i]],
                    [fo.x, fo.y],
                    "spp {spp} s0 {s0} lane {i}"
                );
                assert_eq!(
                    [l[0][i], l[1][i], l[2][i], l[3][i]],
                    [lo.select, lo.primitive, lo.point.x, lo.point.y]
                );
                assert_eq!(
                    [b[0][i], b[1][i], b[2][i]],
                    [bo.lobe, bo.direction.x, bo.direction.y]
                );
            }
        }
    }
}

/// Every dimension of every group changes with the seed, in both allocations.
#[test]
fn every_dimension_changes_with_the_seed() {
    for dims in [DimAlloc::Joint, DimAlloc::Padded] {
        let draw = |seed: u64| {
            let c = SamplerConfig {
                dims,
                ..cfg(seed, 16, (8, 8))
            };
            let px = ZSobolLanes::pixel(&c, 2, 5);
            crate::sampler::all_values(&mut PureSample::new(px, 3))
        };
        let (a, b) = (draw(1), draw(2));
        for k in 0..a.len() {
            assert_ne!(a[k], b[k], "{dims:?}: dimension {k}");
        }
    }
}

/// A run must fit the 2^32 points: the largest sample count is accepted, one more sample
/// (the next power of two) is refused with the film and the limit named.
#[test]
fn runs_past_the_sequence_are_refused() {
    let s = Sampling {
        kind: crate::sampler::SamplerKind::ZSobol,
        dims: DimAlloc::Joint,
        run_samples: None,
    };
    assert!(s.config(0, 0, 1 << 16, (256, 200)).is_ok());
    let e = s.config(0, 0, (1 << 16) + 1, (256, 200)).unwrap_err();
    assert!(e.contains("256x200") && e.contains("at most 65536"), "{e}");
    assert!(s.config(0, 1 << 16, 1, (256, 200)).is_err());
    let e = s.config(0, 0, 1, (100_000, 2)).unwrap_err();
    assert!(e.contains("no samples"), "{e}");
    assert_eq!(index_bits(256, 200, 3), 16 + 2);
    assert_eq!(ceil_log2(1), 0);
    assert_eq!(ceil_log2(5), 3);
}
