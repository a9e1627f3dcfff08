//! Small geometric helpers shared by every module.

use crate::rng::LANES;
use glam::{Vec3, Vec3A};

/// Linear RGB triple used for colours, radiance and intensities.
pub type Rgb = glam::Vec3;

/// pi, in f32.
pub const PI: f32 = std::f32::consts::PI;
/// 1 / pi, in f32.
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;

/// Rec. 709 luminance, the weight the study uses for emitter power.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// Orthonormal frame around a unit normal; local z is the normal.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent.
    pub t: Vec3,
    /// Normal.
    pub n: Vec3,
}

/// Eight 3-vectors, one array per component: the lane kernel's and the BSDFs' lane code
/// loop over them, which the compiler turns into vector code. 32-byte aligned, for the
/// reason `geometry::PacketHits` gives.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
pub struct V3x8 {
    /// x components.
    pub x: [f32; LANES],
    /// y components.
    pub y: [f32; LANES],
    /// z components.
    pub z: [f32; LANES],
}

impl V3x8 {
    /// `v` in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3x8 {
            x: [v.x; LANES],
            y: [v.y; LANES],
            z: [v.z; LANES],
        }
    }

    /// Lane i.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets lane i to `v`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }

    /// The components as a ray packet holds them.
    #[cfg(test)]
    pub fn axes(&self) -> [[f32; LANES]; 3] {
        [self.x, self.y, self.z]
    }

    /// Copies the components from a ray packet's layout, axis by axis: built as a whole
    /// value, the copy went through a stack temporary whose 32-byte stores were read back
    /// as 64-byte loads, which cannot be forwarded from them (a stall of each copy).
    #[inline(always)]
    pub fn copy_axes(&mut self, [x, y, z]: &[[f32; LANES]; 3]) {
        (self.x, self.y, self.z) = (*x, *y, *z);
    }
}

/// `v / s`, all three quotients in one SIMD division (each correctly rounded, so bitwise the
/// same as three scalar ones, at a third of the latency-bound cost).
#[inline(always)]
pub fn div3(v: Vec3, s: f32) -> Vec3 {
    (Vec3A::from(v) / s).into()
}

impl Frame {
    /// Duff et al. 2017: branchless and continuous except at n.z = -0 vs +0.
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// `v` in the frame's coordinates (normal along z).
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// `v` from the frame's coordinates to world space.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Largest absolute component.
#[inline]
pub fn max_abs(p: Vec3) -> f32 {
    p.abs().max_element()
}

/// Offset, relative to a point's error scale, that moves a spawned ray's origin clear of its
/// own surface. A point recomputed from barycentrics is off in component c by at most
/// gamma(7) ~ 4.2e-7 of its vertices' largest |c| (pbrt-v4's bound), so along the unit
/// normal n by at most gamma(7) dot(|n|, err_scale); 2^-19 (1.9e-6) covers it 2.6 times over.
/// The triangle test itself rejects hits within its own error bound on t, so the offset need
/// not cover that too.
pub const SPAWN_REL_OFFSET: f32 = 1.0 / 524_288.0;

/// Origin for a ray leaving `p` (geometric normal `ng`, per-component position error scale
/// `err_scale`) towards direction `d`.
///
/// The bound is taken per component, as pbrt's, not as one scalar for the whole point: a
/// floor at z = 0 has no error in z however wide it is, so its rays start at z ~ 0 and a
/// light 1e-6 above it is still above their origin (a scalar bound of the floor's size put
/// the origin beyond such a light, and BSDF samples never reached it).
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, err_scale: Vec3, d: Vec3) -> Vec3 {
    let delta = (ng.abs().dot(err_scale) * SPAWN_REL_OFFSET).max(f32::MIN_POSITIVE);
    let off = ng * delta;
    if d.dot(ng) >= 0.0 {
        p + off
    } else {
        p - off
    }
}

/// Camera-to-world matrix looking from `origin` at `target` (Mitsuba/Nori convention: the
/// camera looks along +z and its +x is `up x dir`, the image's left).
pub fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> glam::Mat4 {
    let dir = (target - origin).normalize();
    let left = up.cross(dir).normalize();
    let new_up = dir.cross(left);
    glam::Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_many_normals() {
        let normals = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.81).normalize(),
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
        ];
        for n in normals {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            // Right-handed, so local z really is the normal.
            assert!((f.s.cross(f.t) - n).length() < 1e-5);
            let v = Vec3::new(0.2, -0.7, 0.4);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
