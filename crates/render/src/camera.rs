//! Perspective pinhole camera with filter importance sampling.
//!
//! Instead of splatting each sample into neighbouring pixels, the sub-pixel offset is drawn
//! from the reconstruction filter (pbrt-v4's approach). The expected image is the same as
//! with splatting, but every pixel is the plain mean of its own independent samples, so
//! per-pixel variance and error are meaningful for the harness.

use crate::geometry::{Ray, RayPacket, NO_SKIP};
use crate::rng::LANES;
use crate::sampler::{Sampler, SamplerLanes};
use crate::scene::desc::{CameraDesc, FilmDesc, FilterDesc, FovAxis};
use glam::{Vec2, Vec3};

/// A perspective pinhole camera with its film: turns film samples into rays.
#[derive(Clone, Debug)]
pub struct Camera {
    origin: Vec3,
    /// The world direction (camera depth 1, unnormalised) through film point (x, y), in
    /// pixels from the top left corner, is `corner + x * step_x + y * step_y`: two
    /// multiply-adds per component, where dividing by the film size took two divisions in
    /// each camera ray's chain of dependent operations before traversal.
    corner: Vec3,
    step_x: Vec3,
    step_y: Vec3,
    /// Film width in pixels.
    pub width: u32,
    /// Film height in pixels.
    pub height: u32,
    near: f32,
    far: f32,
    filter: FilterDesc,
}

impl Camera {
    /// The camera of `desc` over the film `film` (field of view along its axis, clip planes,
    /// reconstruction filter).
    pub fn new(desc: &CameraDesc, film: &FilmDesc) -> Self {
        let (w, h) = (film.width as f32, film.height as f32);
        let t = (desc.fov_degrees.to_radians() * 0.5).tan();
        let axis = match desc.fov_axis {
            FovAxis::Smaller if w <= h => FovAxis::X,
            FovAxis::Smaller => FovAxis::Y,
            FovAxis::Larger if w >= h => FovAxis::X,
            FovAxis::Larger => FovAxis::Y,
            a => a,
        };
        let tan_half = match axis {
            FovAxis::X => Vec2::new(t, t * h / w),
            FovAxis::Y => Vec2::new(t * w / h, t),
            _ => {
                let diag = (w * w + h * h).sqrt();
                Vec2::new(t * w / diag, t * h / diag)
            }
        };
        let m = desc.to_world;
        // Camera +x is the image's left (Mitsuba/Nori convention), +y is up.
        let [ax, ay, az] = [m.x_axis, m.y_axis, m.z_axis].map(|a| a.truncate());
        Camera {
            origin: desc.to_world.transform_point3(Vec3::ZERO),
            corner: az + ax * tan_half.x + ay * tan_half.y,
            step_x: ax * (-2.0 * tan_half.x / w),
            step_y: ay * (-2.0 * tan_half.y / h),
            width: film.width,
            height: film.height,
            near: desc.near_clip,
            far: desc.far_clip,
            filter: film.filter,
        }
    }

    /// Sub-pixel offset from the pixel centre, distributed like the filter.
    #[inline]
    fn filter_offset(&self, sampler: &mut impl Sampler) -> Vec2 {
        match self.filter {
            FilterDesc::Box => sampler.film() - Vec2::splat(0.5),
            FilterDesc::Tent { radius } => {
                crate::sampling::warps::square_to_tent(sampler.film()) * radius
            }
            FilterDesc::Gaussian { stddev, radius } => {
                // Each axis by inverting the CDF of the Gaussian truncated to the radius: the
                // density of rejecting Box-Muller samples outside the square (the Gaussian is
                // separable), in constant time however small the radius is against stddev.
                use crate::sampling::erf::{erf, erfinv};
                let s = std::f32::consts::SQRT_2 * stddev;
                let e = erf(radius / s);
                let u = sampler.film();
                let inv = |u: f32| (s * erfinv((2.0 * u - 1.0) * e)).clamp(-radius, radius);
                Vec2::new(inv(u.x), inv(u.y))
            }
        }
    }

    /// The camera ray for one sample of pixel (px, py); image y grows downwards.
    #[inline]
    pub fn generate_ray(&self, px: u32, py: u32, sampler: &mut impl Sampler) -> Ray {
        let off = self.filter_offset(sampler);
        let (fx, fy) = (px as f32 + 0.5 + off.x, py as f32 + 0.5 + off.y);
        let d = self.direction(fx, fy);
        let len = d.length();
        // The clip planes sit at camera-space depths near and far; d has depth 1, so they
        // are near*|d| and far*|d| along the unit world ray.
        Ray {
            o: self.origin,
            d: d * len.recip(),
            tmin: self.near * len,
            tmax: self.far * len,
            skip: NO_SKIP,
        }
    }

    /// The unnormalised world direction through film point (fx, fy), in pixels.
    #[inline(always)]
    fn direction(&self, fx: f32, fy: f32) -> Vec3 {
        self.corner + self.step_x * fx + self.step_y * fy
    }

    /// `generate_ray` for `LANES` samples of pixel (px, py), lane i drawing from lane i of
    /// `rng`: the same IEEE operations in the same order (glam's `length` is
    /// (x*x + y*y) + z*z), so every ray is bitwise the one `generate_ray` gives, computed
    /// eight at a time.
    #[inline]
    pub fn generate_rays<L: SamplerLanes>(&self, px: u32, py: u32, rng: &mut L) -> RayPacket {
        let (ox, oy) = match self.filter {
            FilterDesc::Box => {
                let [ux, uy] = rng.film();
                (ux.map(|u| u - 0.5), uy.map(|u| u - 0.5))
            }
            _ => {
                let (mut ox, mut oy) = ([0.0; LANES], [0.0; LANES]);
                for i in 0..LANES {
                    let mut r = rng.lane(i);
                    let o = self.filter_offset(&mut r);
                    (ox[i], oy[i]) = (o.x, o.y);
                    rng.set_lane(i, &r);
                }
                (ox, oy)
            }
        };
        let (cx, cy) = (px as f32 + 0.5, py as f32 + 0.5);
        let [corner, step_x, step_y] =
            [self.corner, self.step_x, self.step_y].map(|v| v.to_array());
        let mut d = [[0.0f32; LANES]; 3];
        let mut len = [0.0f32; LANES];
        for i in 0..LANES {
            let (fx, fy) = (cx + ox[i], cy + oy[i]);
            for (c, d) in d.iter_mut().enumerate() {
                d[i] = corner[c] + step_x[c] * fx + step_y[c] * fy;
            }
            len[i] = (d[0][i] * d[0][i] + d[1][i] * d[1][i] + d[2][i] * d[2][i]).sqrt();
        }
        let mut rays = RayPacket::splat(&Ray::new(self.origin, Vec3::Z));
        for i in 0..LANES {
            let inv = len[i].recip();
            for (unit, d) in rays.d.iter_mut().zip(&d) {
                unit[i] = d[i] * inv;
            }
            (rays.tmin[i], rays.tmax[i]) = (self.near * len[i], self.far * len[i]);
        }
        rays
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampler::IndependentLanes;

    fn camera(fov_axis: FovAxis, w: u32, h: u32) -> Camera {
        let desc = CameraDesc {
            to_world: crate::math::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y),
            fov_degrees: 90.0,
            fov_axis,
            near_clip: 0.01,
            far_clip: 100.0,
        };
        let film = FilmDesc {
            width: w,
            height: h,
            filter: FilterDesc::Box,
        };
        Camera::new(&desc, &film)
    }

    /// Mitsuba's conventions, computed by hand: film point (fx, fy), in pixels from the top
    /// left, looks along (tx (1 - 2 fx / w), ty (1 - 2 fy / h), 1) in camera space (image left
    /// is camera +x, image top is +y), where the half-angle tangents (tx, ty) follow the fov
    /// axis rule: `x` and `y` fix that axis, `smaller` / `larger` pick the film's smaller /
    /// larger side, `diagonal` fixes the half diagonal. Checked at the four corners and a
    /// pixel centre, on landscape and portrait films, with fov 90 degrees (tangent 1).
    #[test]
    fn fov_axes_on_landscape_and_portrait_films() {
        use FovAxis::*;
        let cases = [
            (X, 200, 100, (1.0, 0.5)),
            (X, 100, 200, (1.0, 2.0)),
            (Y, 200, 100, (2.0, 1.0)),
            (Y, 100, 200, (0.5, 1.0)),
            (Smaller, 200, 100, (2.0, 1.0)),
            (Smaller, 100, 200, (1.0, 2.0)),
            (Larger, 200, 100, (1.0, 0.5)),
            (Larger, 100, 200, (0.5, 1.0)),
            (Diagonal, 300, 400, (0.6, 0.8)),
            (Diagonal, 400, 300, (0.8, 0.6)),
        ];
        for (axis, w, h, (tx, ty)) in cases {
            let c = camera(axis, w, h);
            let (wf, hf) = (w as f32, h as f32);
            let points = [(0.0, 0.0), (wf, 0.0), (0.0, hf), (wf, hf), (10.5, 20.5)];
            for (fx, fy) in points {
                let want = Vec3::new(tx * (1.0 - 2.0 * fx / wf), ty * (1.0 - 2.0 * fy / hf), 1.0);
                let d = c.direction(fx, fy);
                assert!(
                    (d - want).length() < 1e-5,
                    "{axis:?} {w}x{h} at ({fx}, {fy}): {d} vs {want}"
                );
            }
        }
    }

    /// Handedness through to_world: a camera at (1, 2, 3) looking along world -x with up +y
    /// (Mitsuba's look_at: left = up x forward = +z) sees world +z at the image's left edge and
    /// +y at its top, and the centre ray starts at the origin.
    #[test]
    fn look_at_orientation_is_mitsubas() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let c = Camera::new(
            &CameraDesc {
                to_world: crate::math::look_at(eye, eye - Vec3::X, Vec3::Y),
                fov_degrees: 90.0,
                fov_axis: FovAxis::X,
                near_clip: 0.01,
                far_clip: 100.0,
            },
            &FilmDesc {
                width: 64,
                height: 32,
                filter: FilterDesc::Box,
            },
        );
        let n = |v: Vec3| v.normalize();
        let close = |a: Vec3, b: Vec3| (n(a) - n(b)).length() < 1e-5;
        assert!(close(c.direction(32.0, 16.0), -Vec3::X));
        assert!(
            close(c.direction(0.0, 16.0), Vec3::new(-1.0, 0.0, 1.0)),
            "left is +z"
        );
        assert!(close(c.direction(64.0, 16.0), Vec3::new(-1.0, 0.0, -1.0)));
        assert!(
            close(c.direction(32.0, 0.0), Vec3::new(-1.0, 0.5, 0.0)),
            "top is +y"
        );
        assert!(close(c.direction(32.0, 32.0), Vec3::new(-1.0, -0.5, 0.0)));
        let r = c.generate_ray(31, 15, &mut Rng::new(1, 2));
        assert_eq!(r.o, eye);
    }

    #[test]
    fn centre_ray_looks_forward_and_left_pixel_looks_to_plus_x() {
        let c = Camera::new(
            &CameraDesc {
                to_world: glam::Mat4::IDENTITY,
                fov_degrees: 90.0,
                fov_axis: FovAxis::X,
                near_clip: 0.5,
                far_clip: 10.0,
            },
            &FilmDesc {
                width: 101,
                height: 101,
                filter: FilterDesc::Box,
            },
        );
        let mut rng = Rng::new(0, 0);
        let r = c.generate_ray(50, 50, &mut rng);
        assert!(r.d.z > 0.9999);
        let left = c.generate_ray(0, 50, &mut rng);
        assert!(left.d.x > 0.6, "image left is camera +x: {:?}", left.d);
        let top = c.generate_ray(50, 0, &mut rng);
        assert!(top.d.y > 0.6, "image top is camera +y: {:?}", top.d);
        // Near plane at depth 0.5 along the axis.
        assert!((r.tmin * r.d.z - 0.5).abs() < 1e-3);
        assert!((left.tmin * left.d.z - 0.5).abs() < 1e-4);
    }

    /// Kolmogorov-Smirnov test of every filter's offsets against the filter's CDF per axis
    /// (box: uniform on [-1/2, 1/2]; tent: triangular on [-r, r]; Gaussian: truncated to
    /// the radius), at alpha = 0.01 (critical D = 1.628 / sqrt(n)), n = 20000, for wide and
    /// narrow radii (a Gaussian radius far below its sd must not need rejection).
    #[test]
    fn filter_offsets_follow_the_filter() {
        use crate::sampling::erf::erf;
        let n = 20_000;
        let gaussian = |stddev: f32, radius: f32| FilterDesc::Gaussian { stddev, radius };
        let filters = [
            FilterDesc::Box,
            FilterDesc::Tent { radius: 0.5 },
            FilterDesc::Tent { radius: 2.5 },
            gaussian(0.5, 2.0),
            gaussian(0.5, 0.6),
            gaussian(50.0, 0.5),
        ];
        for filter in filters {
            let cdf = |x: f64| -> f64 {
                let f = match filter {
                    FilterDesc::Box => x + 0.5,
                    FilterDesc::Tent { radius } => {
                        let t = x / radius as f64;
                        match t < 0.0 {
                            true => 0.5 * (1.0 + t).powi(2),
                            false => 1.0 - 0.5 * (1.0 - t).powi(2),
                        }
                    }
                    FilterDesc::Gaussian { stddev, radius } => {
                        let s = std::f64::consts::SQRT_2 * stddev as f64;
                        let e = erf((radius as f64 / s) as f32) as f64;
                        (erf((x / s) as f32) as f64 + e) / (2.0 * e)
                    }
                };
                f.clamp(0.0, 1.0)
            };
            let reach = match filter {
                FilterDesc::Box => 0.5,
                FilterDesc::Tent { radius } | FilterDesc::Gaussian { radius, .. } => radius,
            };
            let c = Camera {
                filter,
                ..Camera::new(
                    &CameraDesc {
                        to_world: glam::Mat4::IDENTITY,
                        fov_degrees: 40.0,
                        fov_axis: FovAxis::X,
                        near_clip: 0.01,
                        far_clip: 1e4,
                    },
                    &FilmDesc {
                        width: 4,
                        height: 4,
                        filter: FilterDesc::Box,
                    },
                )
            };
            let mut rng = Rng::new(3, 9);
            let (mut xs, mut ys): (Vec<f64>, Vec<f64>) = (0..n)
                .map(|_| c.filter_offset(&mut rng))
                .map(|o| (o.x as f64, o.y as f64))
                .unzip();
            for v in [&mut xs, &mut ys] {
                assert!(v.iter().all(|x| x.abs() <= reach as f64), "{filter:?}");
                v.sort_by(f64::total_cmp);
                let d = v
                    .iter()
                    .enumerate()
                    .map(|(i, &x)| {
                        let f = cdf(x);
                        (f - i as f64 / n as f64)
                            .abs()
                            .max(((i + 1) as f64 / n as f64 - f).abs())
                    })
                    .fold(0.0, f64::max);
                assert!(d < 1.628 / (n as f64).sqrt(), "{filter:?}: D = {d}");
            }
        }
    }

    #[test]
    fn lane_rays_are_bitwise_the_scalar_rays() {
        let filters = [
            FilterDesc::Box,
            FilterDesc::Tent { radius: 1.0 },
            FilterDesc::Gaussian {
                stddev: 0.5,
                radius: 2.0,
            },
        ];
        for filter in filters {
            let c = Camera::new(
                &CameraDesc {
                    to_world: crate::math::look_at(
                        Vec3::new(0.3, 1.7, -4.1),
                        Vec3::new(-0.2, 0.9, 0.4),
                        Vec3::new(0.1, 1.0, 0.05),
                    ),
                    fov_degrees: 39.3,
                    fov_axis: FovAxis::X,
                    near_clip: 0.01,
                    far_clip: 1e4,
                },
                &FilmDesc {
                    width: 97,
                    height: 61,
                    filter,
                },
            );
            for (px, py, s0) in [(0, 0, 0), (96, 60, 8), (13, 47, 4096)] {
                let key = Rng::pixel_key(11, py as u64 * 97 + px as u64);
                let mut lanes = IndependentLanes::for_pixel_samples(key, s0);
                let rays = c.generate_rays(px, py, &mut lanes);
                for i in 0..LANES {
                    let r = &rays.ray(i);
                    let mut one = Rng::for_pixel_sample(key, s0 + i as u64);
                    let want = c.generate_ray(px, py, &mut one);
                    let bits = |r: &Ray| {
                        (
                            r.o.to_array().map(f32::to_bits),
                            r.d.to_array().map(f32::to_bits),
                        )
                    };
                    assert_eq!(bits(r), bits(&want), "{filter:?} lane {i}");
                    assert_eq!((r.tmin, r.tmax), (want.tmin, want.tmax));
                    assert_eq!(lanes.lane(i).next_u32(), one.next_u32(), "rng left in step");
                }
            }
        }
    }
}
