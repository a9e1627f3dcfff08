//! Geometry: shapes in world space, their intersection, and the BVH over all of them.

pub mod accel;
mod bvh;
mod lanes8;
pub mod packet;
pub mod ray_packet;
mod refine;
pub mod shape;
mod sphere8;
pub mod watertight;
mod watertight8;

pub use accel::Accel;
pub use lanes8::lookup8;
pub use ray_packet::{PacketHits, RayPacket};
pub use shape::{Mesh, Shape, ShapeKind, Sphere};

use glam::Vec3;

/// A ray with an explicit parametric interval; `d` need not be unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
    /// Start of the interval.
    pub tmin: f32,
    /// End of the interval.
    pub tmax: f32,
    /// Accelerator id of a flat triangle the ray cannot hit inside its interval (the one it
    /// leaves, or the one a shadow ray ends on), or `NO_SKIP`. Skipping it spares the f64
    /// re-check of a hit at t = 0 that the f32 error bound cannot place (see `watertight`).
    pub skip: u32,
}

/// `Ray::skip` of a ray that may hit every primitive.
pub const NO_SKIP: u32 = u32::MAX;

impl Ray {
    /// A ray from `o` along `d` over (0, infinity), skipping nothing.
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray {
            o,
            d,
            tmin: 0.0,
            tmax: f32::INFINITY,
            skip: NO_SKIP,
        }
    }
}

/// A surface point found by a ray or drawn by a light sampler.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Position in world space.
    pub p: Vec3,
    /// Geometric normal, oriented to agree with the shading normal.
    pub ng: Vec3,
    /// Shading normal (interpolated vertex normals, or `ng`).
    pub ns: Vec3,
    /// Index of the shape in the scene.
    pub shape: u32,
    /// Triangle index within the shape (0 for spheres).
    pub prim: u32,
    /// Per component, the magnitude of the values `p` was computed from (vertices, sphere
    /// centre and radius): its rounding error is proportional to this, not to |p|.
    pub err_scale: Vec3,
}

impl SurfacePoint {
    /// Origin for a ray leaving this point in direction `d`, clear of the surface.
    #[inline]
    pub fn spawn_origin(&self, d: Vec3) -> Vec3 {
        crate::math::offset_origin(self.p, self.ng, self.err_scale, d)
    }
}

/// A ray's closest hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Parametric distance along the ray.
    pub t: f32,
    /// The surface point hit.
    pub sp: SurfacePoint,
}
