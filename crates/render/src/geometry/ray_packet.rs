//! A packet's rays and closest hits, one array per component: the form the packet tests
//! read and write, and the form the lane kernel and the camera compute in, so that nothing is
//! transposed between them.

use super::{Hit, Ray, SurfacePoint};

/// Rays per packet.
pub const PACKET: usize = 8;

/// Iterates the set bits of a mask, lowest first.
#[inline(always)]
pub fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            i
        })
    })
}
use glam::Vec3;

/// Lane i of three arrays.
#[inline(always)]
fn lane(v: &[[f32; PACKET]; 3], i: usize) -> Vec3 {
    Vec3::new(v[0][i], v[1][i], v[2][i])
}

/// Up to eight rays, one array per component. Packets are traced in this form, and the lane
/// kernel and the camera compute their rays in it, so no packet is transposed on the way.
/// Lanes outside a query's active mask may hold anything (even NaN): no answer reads them.
/// 32-byte aligned, for its vectors as `PacketHits`; not to a cache line, which would pad
/// its 288 bytes to 320 and the bench's stored ray mix by a third (peak memory 503 -> 656
/// MiB) for no measured gain.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct RayPacket {
    /// Origins, by component then lane.
    pub o: [[f32; PACKET]; 3],
    /// Directions, by component then lane.
    pub d: [[f32; PACKET]; 3],
    /// Interval starts.
    pub tmin: [f32; PACKET],
    /// Interval ends.
    pub tmax: [f32; PACKET],
    /// Per lane, the primitive to skip (`Ray::skip`).
    pub skip: [u32; PACKET],
}

impl RayPacket {
    /// Eight copies of a ray.
    pub fn splat(r: &Ray) -> Self {
        RayPacket {
            o: r.o.to_array().map(|c| [c; PACKET]),
            d: r.d.to_array().map(|c| [c; PACKET]),
            tmin: [r.tmin; PACKET],
            tmax: [r.tmax; PACKET],
            skip: [r.skip; PACKET],
        }
    }

    /// Lane i as a ray.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        Ray {
            o: self.o(i),
            d: self.d(i),
            tmin: self.tmin[i],
            tmax: self.tmax[i],
            skip: self.skip[i],
        }
    }

    /// Lane i's origin.
    #[inline(always)]
    pub fn o(&self, i: usize) -> Vec3 {
        lane(&self.o, i)
    }

    /// Lane i's direction.
    #[inline(always)]
    pub fn d(&self, i: usize) -> Vec3 {
        lane(&self.d, i)
    }

    /// Sets lane i to `r`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, r: &Ray) {
        for a in 0..3 {
            (self.o[a][i], self.d[a][i]) = (r.o[a], r.d[a]);
        }
        (self.tmin[i], self.tmax[i], self.skip[i]) = (r.tmin, r.tmax, r.skip);
    }
}

impl Default for RayPacket {
    /// Eight copies of an unbounded ray along +z from the origin.
    fn default() -> Self {
        RayPacket::splat(&Ray::new(Vec3::ZERO, Vec3::Z))
    }
}

/// A packet's closest hits. Lanes outside `mask` hold anything.
///
/// Cache-line aligned, its arrays first: the render loop moves them in 32- and 64-byte
/// vectors, and a vector that splits two lines costs a stalled store or load. Left to the
/// build's stack layout, which any change elsewhere could move, that cost the Cornell box 5 %.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub struct PacketHits {
    /// Distances of the hits.
    pub t: [f32; PACKET],
    /// Positions, by component then lane.
    pub p: [[f32; PACKET]; 3],
    /// Geometric normals, by component then lane.
    pub ng: [[f32; PACKET]; 3],
    /// Shading normals, by component then lane.
    pub ns: [[f32; PACKET]; 3],
    /// Error scales of the positions, by component then lane.
    pub err: [[f32; PACKET]; 3],
    /// Shape indices.
    pub shape: [u32; PACKET],
    /// Primitive indices within their shapes.
    pub prim: [u32; PACKET],
    /// The lanes with a hit.
    pub mask: u32,
}

impl PacketHits {
    /// Lane i's hit, if it has one.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Option<Hit> {
        (self.mask >> i & 1 != 0).then(|| Hit {
            t: self.t[i],
            sp: self.point(i),
        })
    }

    /// Lane i's surface point (anything if lane i has no hit).
    #[inline(always)]
    pub fn point(&self, i: usize) -> SurfacePoint {
        SurfacePoint {
            p: lane(&self.p, i),
            ng: lane(&self.ng, i),
            ns: lane(&self.ns, i),
            shape: self.shape[i],
            prim: self.prim[i],
            err_scale: lane(&self.err, i),
        }
    }

    /// Sets lane i to `hit` and marks it hit.
    #[inline(always)]
    pub fn set(&mut self, i: usize, hit: &Hit) {
        self.mask |= 1 << i;
        self.t[i] = hit.t;
        self.set_point(i, &hit.sp);
    }

    /// Lane i's surface point, leaving its mask bit and distance alone.
    #[inline(always)]
    pub fn set_point(&mut self, i: usize, sp: &SurfacePoint) {
        for a in 0..3 {
            (self.p[a][i], self.ng[a][i]) = (sp.p[a], sp.ng[a]);
            (self.ns[a][i], self.err[a][i]) = (sp.ns[a], sp.err_scale[a]);
        }
        (self.shape[i], self.prim[i]) = (sp.shape, sp.prim);
    }
}
