//! `sobol` and `sobol-xor`: Sobol' points in groups of up to four dimensions, each group
//! (or, padded, each 1D/2D draw) taking the sequence's first four dimensions under its own
//! randomisation, seeded by (seed, pixel, dimension): Burley's padding by re-seeded low
//! dimensions, so no group sees the poor projections of high Sobol' dimensions and the
//! number of dimensions is unbounded.
//!
//! - `sobol` (`Sobol<true>`): sobol_burley's Owen scrambling by hashing, with its seeded
//!   shuffle of the sample order (a nested scramble of the index, which keeps every aligned
//!   block of 2^m samples a (0, m, 2)-net).
//! - `sobol-xor` (`Sobol<false>`): the unshuffled sequence with a random digital shift (XOR
//!   of all bits) per dimension: unbiased, the same strata, but a much weaker randomisation.
//!
//! **2^16 samples per seed.** sobol_burley's sequence has 2^16 points (the crate silently
//! wraps past them in release builds). Sample index `s` is point `s mod 2^16` of
//! randomisation `s / 2^16`: each block of 65,536 samples is an independent randomisation
//! of the whole sequence (its own seeds), never a repeat of the first block. Renders of up
//! to 65,536 samples per pixel see one Sobol' sequence; longer ones (references) are
//! averages of independent RQMC estimates, which converge at least at the Monte Carlo rate.

use super::pure::{by_dimension, PointSet, PureLanes};
use super::{PointKind, SamplerConfig};
use crate::rng::LANES;
use crate::rng::{mix64, Rng};
use sobol_burley::parts::{hash, owen_scramble_rev, sobol_int4_rev, u32_to_f32_norm};
use std::sync::OnceLock;

/// Samples per randomisation: the length of sobol_burley's sequence.
pub const BLOCK: u64 = 1 << 16;

/// The Sobol' family: Owen-scrambled (`OWEN = true`) or digitally shifted.
#[derive(Clone, Copy, Debug)]
pub struct Sobol<const OWEN: bool>;

/// Owen-scrambled Sobol' points in lanes (`sobol`).
pub type SobolLanes = PureLanes<Sobol<true>>;
/// Sobol' points with a random digital shift only, in lanes (`sobol-xor`).
pub type SobolXorLanes = PureLanes<Sobol<false>>;

/// The randomisation of dimensions `dim ..` in block `block` of a pixel.
#[inline(always)]
fn seed_of(pixel: u64, dim: u32, block: u64) -> u64 {
    mix64(mix64(pixel ^ dim as u64) ^ block)
}

/// Dimension set 0 of sobol_burley's sequence as two byte tables: the sequence is linear over
/// GF(2) in the index bits, so the point of a 16-bit (bit-reversed) index is the XOR of its
/// high byte's and low byte's entries. Built from the crate's own `sobol_int4_rev`; two
/// loads instead of its loop over the index's set bits.
struct Tables {
    high: [[u32; 4]; 256],
    low: [[u32; 4]; 256],
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| Tables {
        high: std::array::from_fn(|b| sobol_int4_rev((b as u32) << 24, 0).into()),
        low: std::array::from_fn(|b| sobol_int4_rev((b as u32) << 16, 0).into()),
    })
}

impl Tables {
    /// `sobol_int4_rev(index_rev, 0)`: the point's four dimensions, bit-reversed.
    #[inline(always)]
    fn point_rev(&self, index_rev: u32) -> [u32; 4] {
        let (a, b) = (
            self.high[(index_rev >> 24) as usize],
            self.low[((index_rev >> 16) & 0xff) as usize],
        );
        [a[0] ^ b[0], a[1] ^ b[1], a[2] ^ b[2], a[3] ^ b[3]]
    }
}

/// One randomisation's constants, computed once for every sample that shares it: for Owen
/// scrambling, `sobol_burley::sample_4d`'s index shuffle and per-dimension scrambles (its
/// code, split so that eight lanes hash the seed once); for the digital shift, the XOR mask.
#[derive(Clone, Copy)]
struct Randomisation {
    shuffle: u32,
    mask: [u32; 4],
}

impl Randomisation {
    #[inline(always)]
    fn new<const OWEN: bool>(seed: u64) -> Self {
        if OWEN {
            let seed = (seed >> 32) as u32;
            let s = seed.wrapping_mul(0x9c8f2d3b);
            let k = [0x912f69ba, 0x174f18ab, 0x691e72ca, 0xb40cc1b8];
            Randomisation {
                shuffle: hash(seed ^ 0x79c68e4a),
                mask: k.map(|k| hash(s ^ k)),
            }
        } else {
            let more = mix64(seed);
            Randomisation {
                shuffle: 0,
                mask: [
                    seed as u32,
                    (seed >> 32) as u32,
                    more as u32,
                    (more >> 32) as u32,
                ],
            }
        }
    }

    /// Point `i` (< 2^16) of the randomised sequence.
    #[inline(always)]
    fn point<const OWEN: bool>(&self, t: &Tables, i: u32) -> [f32; 4] {
        if OWEN {
            let v = t.point_rev(owen_scramble_rev(i.reverse_bits(), self.shuffle));
            std::array::from_fn(|j| {
                u32_to_f32_norm(owen_scramble_rev(v[j], self.mask[j]).reverse_bits())
            })
        } else {
            let v = t.point_rev(i.reverse_bits());
            std::array::from_fn(|j| u32_to_f32_norm(v[j].reverse_bits() ^ self.mask[j]))
        }
    }
}

impl<const OWEN: bool> PointSet for Sobol<OWEN> {
    type Pixel = u64;
    const JOINT: bool = true;
    const ALLOCATES_DIMS: bool = true;
    const POINTS: PointKind = if OWEN {
        PointKind::ScrambledNet
    } else {
        PointKind::ShiftedNet
    };

    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> u64 {
        // Salted: the same seed gives the Sobol' samplers and `independent` unrelated keys.
        mix64(Rng::pixel_key(cfg.seed, cfg.pixel_index(x, y)) ^ 0x50b0_1000_0000_0001)
    }

    #[inline(always)]
    fn draw(pixel: &u64, index: u64, dim: u32, _k: usize) -> [f32; 4] {
        let (block, i) = (index / BLOCK, (index % BLOCK) as u32);
        Randomisation::new::<OWEN>(seed_of(*pixel, dim, block)).point::<OWEN>(tables(), i)
    }

    /// Eight consecutive samples of one group share its randomisation unless they straddle
    /// a block: the seed is hashed once, not per lane, and the lanes are computed side by
    /// side (`Randomisation::point`'s steps, lane-major).
    #[inline(always)]
    fn draw_lanes(pixel: &u64, s0: u64, dim: u32, k: usize) -> [[f32; LANES]; 4] {
        let block = s0 / BLOCK;
        if (s0 + LANES as u64 - 1) / BLOCK != block {
            return by_dimension(|l| Self::draw(pixel, s0 + l as u64, dim, k));
        }
        let r = Randomisation::new::<OWEN>(seed_of(*pixel, dim, block));
        let (t, i0) = (tables(), (s0 % BLOCK) as u32);
        let mut v = [[0u32; LANES]; 4];
        for l in 0..LANES {
            let rev = (i0 + l as u32).reverse_bits();
            let p = t.point_rev(if OWEN {
                owen_scramble_rev(rev, r.shuffle)
            } else {
                rev
            });
            for (v, p) in v.iter_mut().zip(p) {
                v[l] = p;
            }
        }
        let mut out = [[0.0; LANES]; 4];
        for j in 0..4 {
            for l in 0..LANES {
                let x = if OWEN {
                    owen_scramble_rev(v[j][l], r.mask[j]).reverse_bits()
                } else {
                    v[j][l].reverse_bits() ^ r.mask[j]
                };
                out[j][l] = u32_to_f32_norm(x);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::LANES;
    use crate::sampler::pure::PureSample;
    use crate::sampler::{is_02_net, DimAlloc, Sampler, SamplerLanes};

    fn cfg(seed: u64, dims: DimAlloc) -> SamplerConfig {
        SamplerConfig {
            dims,
            seed,
            run_samples: 1 << 20,
            width: 64,
            height: 64,
        }
    }

    /// The film pair of samples `first .. first + 2^m` of a pixel.
    fn film_points<const OWEN: bool>(
        c: &SamplerConfig,
        x: u32,
        first: u64,
        m: u32,
    ) -> Vec<(f32, f32)> {
        let px = PureLanes::<Sobol<OWEN>>::pixel(c, x, 3);
        (first..first + (1 << m))
            .map(|s| {
                let f = PureSample::new(px, s).film();
                (f.x, f.y)
            })
            .collect()
    }

    #[test]
    fn aligned_blocks_of_film_samples_are_02_nets() {
        for m in 0..=10 {
            for (seed, x) in [(0, 0), (7, 5), (123_456, 63)] {
                let c = cfg(seed, DimAlloc::Joint);
                for first in [0, 1 << m, 5 << m, BLOCK, 3 * BLOCK + (2 << m)] {
                    assert!(
                        is_02_net(&film_points::<true>(&c, x, first, m), m),
                        "owen m={m} first={first}"
                    );
                    assert!(
                        is_02_net(&film_points::<false>(&c, x, first, m), m),
                        "xor m={m} first={first}"
                    );
                }
            }
        }
        // The check itself: 4 independent points are not a net.
        let c = cfg(1, DimAlloc::Joint);
        let mut r = Rng::for_sample(1, 2, 3);
        let random: Vec<(f32, f32)> = (0..16).map(|_| (r.next_f32(), r.next_f32())).collect();
        assert!(!is_02_net(&random, 4));
        assert!(is_02_net(&film_points::<true>(&c, 0, 0, 4), 4));
    }

    #[test]
    fn owen_values_are_sobol_burleys() {
        let p = 0x1234_5678_9abc_def0;
        for (index, dim) in [(0u64, 0u32), (1, 4), (1000, 9), (65535, 2)] {
            let seed = (seed_of(p, dim, 0) >> 32) as u32;
            let want: Vec<f32> = (0..4)
                .map(|j| sobol_burley::sample(index as u32, j, seed))
                .collect();
            assert_eq!(Sobol::<true>::draw(&p, index, dim, 4).to_vec(), want);
        }
    }

    /// The byte tables and the split-out randomisation are the crate's sequence bit for
    /// bit: every one of the 2^16 indices under several seeds, against `sample_4d` (Owen)
    /// and against `sobol_int4_rev` with the shift (xor); and eight lanes drawn together
    /// equal eight single draws, across a block boundary too.
    #[test]
    fn tables_are_the_crates_sequence_at_every_index() {
        for seed in [0u64, 0x9e37_79b9_7f4a_7c15, u64::MAX] {
            let r = Randomisation::new::<true>(seed);
            let x = Randomisation::new::<false>(seed);
            for i in 0..BLOCK as u32 {
                let owen = sobol_burley::sample_4d(i, 0, (seed >> 32) as u32);
                assert_eq!(r.point::<true>(tables(), i), owen, "index {i}");
                let v: [u32; 4] = sobol_int4_rev(i.reverse_bits(), 0).reverse_bits().into();
                let want: [f32; 4] = std::array::from_fn(|j| u32_to_f32_norm(v[j] ^ x.mask[j]));
                assert_eq!(x.point::<false>(tables(), i), want, "index {i}");
            }
        }
        for s0 in [0, 8, 1000, BLOCK - 3, 5 * BLOCK + 16] {
            let lanes = Sobol::<true>::draw_lanes(&7, s0, 5, 4);
            let xor = Sobol::<false>::draw_lanes(&7, s0, 5, 4);
            for l in 0..LANES {
                let (a, b) = (
                    Sobol::<true>::draw(&7, s0 + l as u64, 5, 4),
                    Sobol::<false>::draw(&7, s0 + l as u64, 5, 4),
                );
                for j in 0..4 {
                    assert_eq!(lanes[j][l], a[j], "{s0} {l}");
                    assert_eq!(xor[j][l], b[j], "{s0} {l}");
                }
            }
        }
    }

    /// Past 2^16 samples the sequence is re-randomised, not repeated.
    #[test]
    fn sample_65536_is_not_sample_0() {
        for owen in [true, false] {
            for dim in [0, 2, 13] {
                let (a, b) = if owen {
                    (
                        Sobol::<true>::draw(&9, 0, dim, 4),
                        Sobol::<true>::draw(&9, BLOCK, dim, 4),
                    )
                } else {
                    (
                        Sobol::<false>::draw(&9, 0, dim, 4),
                        Sobol::<false>::draw(&9, BLOCK, dim, 4),
                    )
                };
                assert_ne!(a, b, "owen {owen} dim {dim}");
            }
        }
    }

    /// Every dimension of every group changes with the seed, in both allocations.
    #[test]
    fn every_dimension_changes_with_the_seed() {
        for dims in [DimAlloc::Joint, DimAlloc::Padded] {
            let draw = |seed: u64| {
                let px = SobolLanes::pixel(&cfg(seed, dims), 2, 2);
                crate::sampler::all_values(&mut PureSample::new(px, 3))
            };
            let (a, b) = (draw(1), draw(2));
            for k in 0..a.len() {
                assert_ne!(a[k], b[k], "{dims:?}: dimension {k}");
            }
        }
    }

    /// Lanes give each sample exactly the scalar sample's numbers, whatever order the
    /// samples are visited in.
    #[test]
    fn lanes_match_scalar_samples_in_any_order() {
        for dims in [DimAlloc::Joint, DimAlloc::Padded] {
            let c = cfg(5, dims);
            let px = SobolXorLanes::pixel(&c, 1, 1);
            let mut lanes = SobolXorLanes::start(px, 16);
            let film = lanes.film();
            let light = lanes.light();
            let bsdf = lanes.bsdf();
            for i in (0..LANES).rev() {
                let mut one = PureSample::new(px, 16 + i as u64);
                let (f, l, b) = (one.film(), one.light(), one.bsdf());
                assert_eq!([film[0][i], film[1][i]], [f.x, f.y]);
                assert_eq!(
                    [light[0][i], light[1][i], light[2][i], light[3][i]],
                    [l.select, l.primitive, l.point.x, l.point.y]
                );
                assert_eq!(
                    [bsdf[0][i], bsdf[1][i], bsdf[2][i]],
                    [b.lobe, b.direction.x, b.direction.y]
                );
                assert_eq!(lanes.lane(i).dimension(), one.dimension());
            }
        }
    }

    /// Joint: a light sample's four numbers are one 4D Sobol' point, so its emitter choice
    /// and its point are stratified together; padded: the choice and the point come from
    /// independent randomisations.
    #[test]
    fn joint_light_groups_are_one_sobol_point() {
        let joint = cfg(3, DimAlloc::Joint);
        let padded = cfg(3, DimAlloc::Padded);
        let (pj, pp) = (
            SobolLanes::pixel(&joint, 0, 0),
            SobolLanes::pixel(&padded, 0, 0),
        );
        for s in 0..64 {
            let mut a = PureSample::new(pj, s);
            a.film();
            let l = a.light();
            assert_eq!(
                [l.select, l.primitive, l.point.x, l.point.y],
                Sobol::<true>::draw(&pj.inner, s, 2, 4)
            );
            let mut b = PureSample::new(pp, s);
            b.film();
            let l = b.light();
            assert_eq!(l.select, Sobol::<true>::draw(&pp.inner, s, 2, 1)[0]);
            assert_eq!(l.primitive, Sobol::<true>::draw(&pp.inner, s, 3, 1)[0]);
            assert_eq!(
                [l.point.x, l.point.y],
                Sobol::<true>::draw(&pp.inner, s, 4, 2)[..2]
            );
        }
    }
}
