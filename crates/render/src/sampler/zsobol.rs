//! `zsobol`: one Owen-scrambled Sobol' sequence for the whole film, its points handed to
//! pixels in Morton (Z) order with random base-4 digit permutations (Ahmed and Wonka 2020,
//! "Screen-Space Blue-Noise Diffusion of Monte Carlo Sampling Error via Hierarchical
//! Ordering of Pixels"; pbrt-v4's default sampler, `ZSobolSampler`).
//!
//! Sample s of pixel (x, y) is Sobol' point `P(morton(x, y) * 2^m + s)`, where 2^m is the
//! run's sample count rounded up to a power of two and P permutes each base-4 digit of the
//! index with a permutation chosen by hashing the digits above it (and the dimension and the
//! seed). P maps every aligned block of 4^k indices onto an aligned block, so one pixel's
//! samples are one aligned block of the sequence (a (0, m, 2)-net in each 2D pair) and so
//! are those of each 2 x 2, 4 x 4, ... quad of pixels: neighbouring pixels receive
//! complementary points, and the error is spread as blue noise over the screen.
//!
//! Differences from pbrt-v4: the digit permutations depend on the seed as well (pbrt's do
//! not: only its value scrambles do); a group of up to four dimensions (joint allocation)
//! takes Sobol' dimensions 0-3 at one permuted index, padded draws take dimensions 0 or 0-1
//! as pbrt does. The sequence is generated here to 32 index bits (sobol_burley's stops at
//! 2^16, which a film of 256 x 256 pixels at 4 samples already exceeds), with the same
//! direction numbers (checked against the crate), and scrambled with the crate's Owen hash.
//! The whole film must fit the 2^32 points: 4^k pixels (k = log2 of the larger side,
//! rounded up) times 2^m samples; `Sampling::config` refuses larger runs.

use super::pure::{PointSet, PureLanes};
use super::{PointKind, SamplerConfig};
use crate::rng::{mix64, LANES};
use sobol_burley::parts::{hash, owen_scramble_rev, u32_to_f32_norm};
use std::sync::OnceLock;

/// pbrt-v4's ZSobol: one Owen-scrambled Sobol' sequence for the film, pixels in Morton
/// order with random base-4 digit permutations.
#[derive(Clone, Copy, Debug)]
pub struct ZSobol;

/// ZSobol in lanes.
pub type ZSobolLanes = PureLanes<ZSobol>;

/// Bits of the sequence's index.
pub const INDEX_BITS: u32 = 32;

/// Degree, coefficients and initial direction numbers of Sobol' dimensions 1-3 (Joe and
/// Kuo's table); dimension 0 is the van der Corput sequence.
const POLYNOMIALS: [(u32, u32, &[u32]); 3] = [(1, 0, &[1]), (2, 1, &[1, 3]), (3, 1, &[1, 3, 1])];

/// Column `k` (index bit k) of each of the first four dimensions' generator matrices.
fn direction_numbers() -> [[u32; 4]; INDEX_BITS as usize] {
    let mut v = [[0u32; 4]; INDEX_BITS as usize];
    for (k, col) in v.iter_mut().enumerate() {
        col[0] = 1 << (31 - k);
    }
    for (d, &(s, a, init)) in POLYNOMIALS.iter().enumerate() {
        let s = s as usize;
        let mut m = vec![0u32; INDEX_BITS as usize + 1];
        m[1..=s].copy_from_slice(init);
        for k in s + 1..=INDEX_BITS as usize {
            // m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}, with a_1
            // the highest of a's s - 1 bits.
            let mut x = m[k - s] ^ (m[k - s] << s);
            for j in 1..s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= m[k - j] << j;
                }
            }
            m[k] = x;
        }
        for k in 1..=INDEX_BITS as usize {
            v[k - 1][d + 1] = m[k] << (INDEX_BITS as usize - k);
        }
    }
    v
}

/// The four dimensions of every index as four byte tables: the sequence is linear over
/// GF(2) in the index bits, so a point is the XOR of one entry per byte of its index.
fn tables() -> &'static [[[u32; 4]; 256]; 4] {
    static T: OnceLock<[[[u32; 4]; 256]; 4]> = OnceLock::new();
    T.get_or_init(|| {
        let v = direction_numbers();
        std::array::from_fn(|byte| {
            std::array::from_fn(|b| {
                let mut p = [0u32; 4];
                for bit in 0..8 {
                    if (b >> bit) & 1 == 1 {
                        for (p, c) in p.iter_mut().zip(v[byte * 8 + bit]) {
                            *p ^= c;
                        }
                    }
                }
                p
            })
        })
    })
}

/// Sobol' point `i` in dimensions 0-3, unscrambled (32-bit fixed point).
#[inline(always)]
pub fn sobol4(i: u32) -> [u32; 4] {
    let t = tables();
    let b = i.to_le_bytes();
    let (p, q, r, s) = (
        t[0][b[0] as usize],
        t[1][b[1] as usize],
        t[2][b[2] as usize],
        t[3][b[3] as usize],
    );
    std::array::from_fn(|j| p[j] ^ q[j] ^ r[j] ^ s[j])
}

/// The 24 permutations of a base-4 digit.
const PERMUTATIONS: [[u8; 4]; 24] = {
    let mut out = [[0u8; 4]; 24];
    let mut n = 0;
    let mut a = 0;
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                if a != b && b != c && a != c {
                    out[n] = [a, b, c, 6 - a - b - c];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    out
};

/// What a pixel's samples share.
#[derive(Clone, Copy, Debug)]
pub struct ZPixel {
    /// The pixel's Morton code shifted above its samples' bits.
    base: u64,
    /// log2 of the samples per pixel, rounded up to a power of two.
    log2_spp: u32,
    /// Base-4 digits of the index (the lowest is one bit when `log2_spp` is odd).
    digits: u32,
    seed: u64,
}

/// log2 of `n` rounded up (0 for n <= 1).
pub fn ceil_log2(n: u64) -> u32 {
    n.max(1).next_power_of_two().trailing_zeros()
}

/// Index bits a film of `width x height` at `run_samples` samples per pixel takes.
pub fn index_bits(width: u32, height: u32, run_samples: u64) -> u32 {
    2 * ceil_log2(width.max(height) as u64) + ceil_log2(run_samples)
}

/// Spreads the 32 bits of `x` to the even bits of a u64.
fn spread(x: u32) -> u64 {
    let mut x = x as u64;
    x = (x | (x << 16)) & 0x0000_ffff_0000_ffff;
    x = (x | (x << 8)) & 0x00ff_00ff_00ff_00ff;
    x = (x | (x << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
    x = (x | (x << 2)) & 0x3333_3333_3333_3333;
    (x | (x << 1)) & 0x5555_5555_5555_5555
}

/// The Morton code of (x, y): x in the even bits, y in the odd ones.
pub fn morton2(x: u32, y: u32) -> u64 {
    spread(x) | (spread(y) << 1)
}

impl ZPixel {
    /// Morton index `m` with its digits whose lowest bit lies in `from .. to` permuted,
    /// the others 0: each digit by a permutation that the digits above it (and the
    /// dimension and the seed) choose. The lowest digit is one bit when `log2_spp` is odd.
    #[inline(always)]
    fn permute_digits(&self, m: u64, dim: u32, from: u32, to: u32) -> u64 {
        let odd = self.log2_spp & 1;
        let salt = self.salt(dim);
        let mut out = 0;
        for i in odd..self.digits {
            let shift = 2 * i - odd;
            if shift < from {
                continue;
            }
            if shift >= to {
                break;
            }
            let digit = (m >> shift) & 3;
            let p = (mix64((m >> (shift + 2)) ^ salt) >> 40) % 24;
            out |= (PERMUTATIONS[p as usize][digit as usize] as u64) << shift;
        }
        if odd == 1 && from == 0 {
            out |= (m & 1) ^ (mix64((m >> 1) ^ salt) >> 63);
        }
        out
    }

    /// What a dimension's digit permutations are keyed by.
    #[inline(always)]
    fn salt(&self, dim: u32) -> u64 {
        self.seed ^ (dim as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
    }

    /// Sample `index` of the pixel in the sequence's index space (lanes past the run's
    /// last sample, drawn and dropped, wrap into the pixel's block).
    #[inline(always)]
    fn morton(&self, index: u64) -> u64 {
        self.base | (index & ((1u64 << self.log2_spp) - 1))
    }

    /// The Owen scrambles of dimension set `dim`'s four values.
    #[inline(always)]
    fn masks(&self, dim: u32) -> [u32; 4] {
        let key = (mix64(self.seed ^ dim as u64) >> 32) as u32;
        [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8].map(|k| hash(key ^ k))
    }

    /// Sobol' dimensions 0 .. k at permuted index `i`, scrambled by `masks` (the rest 0).
    #[inline(always)]
    fn point(i: u64, masks: &[u32; 4], k: usize) -> [f32; 4] {
        let v = sobol4(i as u32);
        let mut out = [0.0; 4];
        for j in 0..k.min(4) {
            out[j] =
                u32_to_f32_norm(owen_scramble_rev(v[j].reverse_bits(), masks[j]).reverse_bits());
        }
        out
    }
}

impl PointSet for ZSobol {
    type Pixel = ZPixel;
    const JOINT: bool = true;
    const NEEDS_SAMPLE_COUNT: bool = true;
    const ALLOCATES_DIMS: bool = true;
    const POINTS: PointKind = PointKind::ScrambledNet;

    fn check_run(run_samples: u64, width: u32, height: u32) -> Result<(), String> {
        let bits = index_bits(width, height, run_samples);
        if bits <= INDEX_BITS {
            return Ok(());
        }
        let pixel_bits = bits - ceil_log2(run_samples);
        let most = match INDEX_BITS.checked_sub(pixel_bits) {
            Some(b) => format!("at most {} samples per pixel", 1u64 << b),
            None => "no samples (its side is over 65,536 pixels)".to_string(),
        };
        Err(format!(
            "the zsobol sampler numbers every sample of the film in one sequence of 2^{} \
             points: a {width}x{height} film takes {most} ({run_samples} asked for)",
            INDEX_BITS
        ))
    }

    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> ZPixel {
        let log2_spp = ceil_log2(cfg.run_samples);
        let log2_res = ceil_log2(cfg.width.max(cfg.height) as u64);
        ZPixel {
            base: morton2(x, y) << log2_spp,
            log2_spp,
            digits: log2_res + log2_spp.div_ceil(2),
            seed: mix64(cfg.seed ^ 0x2505_0b01_0000_0001),
        }
    }

    #[inline(always)]
    fn draw(px: &ZPixel, index: u64, dim: u32, k: usize) -> [f32; 4] {
        let i = px.permute_digits(px.morton(index), dim, 0, u32::MAX);
        ZPixel::point(i, &px.masks(dim), k)
    }

    /// The lanes share every digit above their own bits: those digits are permuted once,
    /// and each low digit's permutation once per value of the bits above it.
    #[inline(always)]
    fn draw_lanes(px: &ZPixel, s0: u64, dim: u32, k: usize) -> [[f32; LANES]; 4] {
        let m0 = px.morton(s0);
        let index: [u64; LANES] = if px.log2_spp >= LOW && m0.is_multiple_of(LANES as u64) {
            let high = px.permute_digits(m0, dim, LOW, u32::MAX);
            px.low_lanes(m0, dim).map(|low| high | low)
        } else {
            std::array::from_fn(|l| px.permute_digits(px.morton(s0 + l as u64), dim, 0, u32::MAX))
        };
        let masks = px.masks(dim);
        let mut v = [[0u32; LANES]; 4];
        for (l, &i) in index.iter().enumerate() {
            for (v, p) in v.iter_mut().zip(sobol4(i as u32)) {
                v[l] = p;
            }
        }
        let mut out = [[0.0; LANES]; 4];
        for j in 0..k.min(4) {
            for l in 0..LANES {
                out[j][l] = u32_to_f32_norm(
                    owen_scramble_rev(v[j][l].reverse_bits(), masks[j]).reverse_bits(),
                );
            }
        }
        out
    }
}

/// Index bits that the `LANES` consecutive samples of a lane batch differ in.
const LOW: u32 = LANES.trailing_zeros();

impl ZPixel {
    /// [`permute_digits`](ZPixel::permute_digits) below bit `LOW` of the `LANES` indices
    /// `m0 ..` (`m0` aligned): the permutation of the digit at `shift` is chosen by the
    /// bits from `shift + 2` up, which take `LANES >> (shift + 2)` values (at least one)
    /// among the lanes; each is hashed once.
    #[inline(always)]
    fn low_lanes(&self, m0: u64, dim: u32) -> [u64; LANES] {
        let odd = self.log2_spp & 1;
        let salt = self.salt(dim);
        let mut out = [0u64; LANES];
        let mut i = odd;
        while 2 * i - odd < LOW {
            let shift = 2 * i - odd;
            let above = shift + 2;
            let mut p = [0usize; LANES];
            for (g, p) in p.iter_mut().enumerate().take((LANES >> above).max(1)) {
                *p = ((mix64(((m0 >> above) + g as u64) ^ salt) >> 40) % 24) as usize;
            }
            for (l, o) in out.iter_mut().enumerate() {
                let digit = ((m0 + l as u64) >> shift) & 3;
                *o |= (PERMUTATIONS[p[l >> above]][digit as usize] as u64) << shift;
            }
            i += 1;
        }
        if odd == 1 {
            let mut flip = [0u64; LANES];
            for (g, f) in flip.iter_mut().enumerate().take(LANES >> 1) {
                *f = mix64(((m0 >> 1) + g as u64) ^ salt) >> 63;
            }
            for (l, o) in out.iter_mut().enumerate() {
                *o |= (l as u64 & 1) ^ flip[l >> 1];
            }
        }
        out
    }
}

#[cfg(test)]
#[path = "zsobol_tests.rs"]
mod tests;
