//! `independent`: every number drawn fresh from the sample's own PCG32 generator
//! (`Rng::for_pixel_sample`), group after group in the order of the dimension allocation.

use super::{BsdfDims, LightDims, Sampler, SamplerConfig, SamplerLanes};
use crate::rng::{Rng, LANES};
use glam::Vec2;

impl Sampler for Rng {
    #[inline(always)]
    fn film(&mut self) -> Vec2 {
        self.next_2d()
    }

    #[inline(always)]
    fn technique(&mut self) -> f32 {
        self.next_f32()
    }

    #[inline(always)]
    fn light(&mut self) -> LightDims {
        let select = self.next_f32();
        let primitive = self.next_f32();
        LightDims {
            select,
            primitive,
            point: self.next_2d(),
        }
    }

    #[inline(always)]
    fn bsdf(&mut self) -> BsdfDims {
        let lobe = self.next_f32();
        BsdfDims {
            lobe,
            direction: self.next_2d(),
        }
    }
}

/// `LANES` per-sample generators stepped together, lane i being `for_pixel_sample(key, s0 + i)`.
/// Plain loops over arrays, which the compiler turns into vector instructions: the seeding
/// (64-bit multiplications) and the camera's draws cost about an eighth.
///
/// Cache-line aligned, its states first, as `PacketHits`: they are one 64-byte vector.
#[derive(Clone)]
#[repr(C, align(64))]
pub struct IndependentLanes {
    state: [u64; LANES],
    /// The pixel's stream, shared by its samples.
    inc: u64,
}

impl IndependentLanes {
    /// The lanes of samples `s0 .. s0 + LANES` of the pixel `pixel_key`.
    #[inline]
    pub fn for_pixel_samples(pixel_key: u64, s0: u64) -> Self {
        let inc = Rng::pixel_stream(pixel_key);
        let state =
            std::array::from_fn(|i| Rng::in_pixel_stream(inc, pixel_key, s0 + i as u64).state());
        IndependentLanes { state, inc }
    }

    /// One number per lane.
    #[inline]
    pub fn next_f32(&mut self) -> [f32; LANES] {
        let mut out = [0.0; LANES];
        for (i, o) in out.iter_mut().enumerate() {
            let mut r = self.lane(i);
            *o = r.next_f32();
            self.state[i] = r.state();
        }
        out
    }
}

impl SamplerLanes for IndependentLanes {
    type One = Rng;
    type Pixel = u64;

    #[inline]
    fn pixel(cfg: &SamplerConfig, x: u32, y: u32) -> u64 {
        Rng::pixel_key(cfg.seed, cfg.pixel_index(x, y))
    }

    #[inline]
    fn start(pixel_key: u64, s0: u64) -> Self {
        IndependentLanes::for_pixel_samples(pixel_key, s0)
    }

    #[inline(always)]
    fn film(&mut self) -> [[f32; LANES]; 2] {
        std::array::from_fn(|_| self.next_f32())
    }

    #[inline(always)]
    fn light(&mut self) -> [[f32; LANES]; 4] {
        std::array::from_fn(|_| self.next_f32())
    }

    #[inline(always)]
    fn bsdf(&mut self) -> [[f32; LANES]; 3] {
        std::array::from_fn(|_| self.next_f32())
    }

    #[inline(always)]
    fn lane(&self, i: usize) -> Rng {
        Rng::from_parts(self.state[i], self.inc)
    }

    #[inline(always)]
    fn set_lane(&mut self, i: usize, r: &Rng) {
        self.state[i] = r.state();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_the_per_sample_generators() {
        for (key, s0) in [(0, 0), (Rng::pixel_key(7, 123), 8), (u64::MAX, 1 << 40)] {
            let mut lanes = IndependentLanes::for_pixel_samples(key, s0);
            let mut one: Vec<Rng> = (0..LANES as u64)
                .map(|i| Rng::for_pixel_sample(key, s0 + i))
                .collect();
            for _ in 0..5 {
                let l = lanes.next_f32();
                assert!((0..LANES).all(|i| l[i] == one[i].next_f32()));
            }
            assert!((0..LANES).all(|i| lanes.lane(i).next_u32() == one[i].next_u32()));
        }
    }

    /// Each group, on either path, is the next numbers of the sample's generator in the
    /// order the allocation lists them: film, technique, light, BSDF.
    #[test]
    fn groups_draw_the_stream_in_allocation_order() {
        let key = Rng::pixel_key(5, 77);
        let cfg = SamplerConfig {
            dims: crate::sampler::DimAlloc::Joint,
            seed: 5,
            run_samples: 64,
            width: 100,
            height: 100,
        };
        let mut lanes = IndependentLanes::start(IndependentLanes::pixel(&cfg, 77, 0), 16);
        let [fx, fy] = lanes.film();
        let [sel, prim, px, py] = lanes.light();
        let [lobe, dx, dy] = lanes.bsdf();
        let t = lanes.next_f32();
        for i in 0..LANES {
            let mut raw = Rng::for_pixel_sample(key, 16 + i as u64);
            let want: Vec<f32> = (0..11).map(|_| raw.next_f32()).collect();
            let mut s = Rng::for_pixel_sample(key, 16 + i as u64);
            let (f, tq, l, b) = (s.film(), s.technique(), s.light(), s.bsdf());
            let scalar = [f.x, f.y, tq, l.select, l.primitive, l.point.x, l.point.y];
            let scalar = [&scalar[..], &[b.lobe, b.direction.x, b.direction.y]].concat();
            assert_eq!(scalar, want[..10]);
            let lane = [
                fx[i], fy[i], sel[i], prim[i], px[i], py[i], lobe[i], dx[i], dy[i], t[i],
            ];
            assert_eq!(lane, want[..10]);
        }
    }
}
