//! Building blocks of the extreme cases: a receiver floor, quad lights, and a one-pixel probe
//! camera. Every case is a floor at z = 0 (normal +z) seen at one point, so a closed form
//! (or a quadrature) of that point's outgoing radiance exists.

use crate::math::Rgb;
use crate::scene::desc::{BsdfDesc, SceneDesc, ShapeDesc};
use crate::scene::fixtures;
use glam::Vec3;

/// A parallelogram light `center ± u ± v`; it emits towards `u x v`.
#[derive(Clone, Copy, Debug)]
pub struct Quad {
    pub center: Vec3,
    pub u: Vec3,
    pub v: Vec3,
}

impl Quad {
    /// Counter-clockwise seen from the emitting side.
    pub fn corners(&self) -> [Vec3; 4] {
        let (c, u, v) = (self.center, self.u, self.v);
        [c - u - v, c + u - v, c + u + v, c - u + v]
    }

    /// An axis-aligned square of side `side` at height `z`, emitting downwards.
    pub fn ceiling(center: Vec3, side: f32) -> Quad {
        let h = side * 0.5;
        Quad {
            center,
            u: Vec3::new(0.0, h, 0.0),
            v: Vec3::new(h, 0.0, 0.0),
        }
    }

    pub fn shape(&self, radiance: f32) -> ShapeDesc {
        fixtures::mesh(
            self.corners().to_vec(),
            vec![[0, 1, 2], [0, 2, 3]],
            fixtures::diffuse(0.0),
            Some(Rgb::splat(radiance)),
        )
    }
}

/// Where the one-pixel camera sits and what it looks at.
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    pub eye: Vec3,
    pub target: Vec3,
    /// Near clip in camera-space depth; tiny when the camera sits inside a thin gap.
    pub near: f32,
    /// Film side in pixels (all pixels see the target: the field of view is 1e-3 degrees).
    pub pixels: u32,
}

impl Probe {
    /// Looking straight down at `target` from height `h`.
    pub fn above(target: Vec3, h: f32) -> Probe {
        Probe {
            eye: target + Vec3::Z * h,
            target,
            near: 1e-4,
            pixels: 1,
        }
    }
}

/// A square floor of half-size `half` (centred at the origin, normal +z) made of `floor`, the
/// given lights, and the probe camera.
pub fn probe_scene(half: f32, floor: BsdfDesc, lights: Vec<ShapeDesc>, probe: Probe) -> SceneDesc {
    let floor_quad = Quad {
        center: Vec3::ZERO,
        u: Vec3::new(half, 0.0, 0.0),
        v: Vec3::new(0.0, half, 0.0),
    };
    let mut floor_shape = floor_quad.shape(0.0);
    floor_shape.emitter = None;
    floor_shape.bsdf = floor;
    let mut lights = lights.into_iter();
    let first = lights.next().expect("a case has at least one light");
    let mut desc = fixtures::light_over_floor(first, 0.5, probe.target, probe.eye);
    desc.shapes[0] = floor_shape;
    desc.shapes.extend(lights);
    desc.camera.near_clip = probe.near;
    desc.film.width = probe.pixels;
    desc.film.height = probe.pixels;
    desc
}
