//! A structure of at most eight spheres and no triangles (the emitter pre-test of a scene
//! whose lights are a few spheres, as the Veach scene's five): its any-hit query tests the
//! ray against every sphere at once, in vector lanes, which costs far less than walking even
//! a one-node BVH.
//!
//! Each lane computes bitwise what `intersect_sphere` computes, so a ray that query hits is
//! a hit here: the pre-test never drops a hit of the closest-hit query after it.

use super::ray_packet::{bits, RayPacket, PACKET};
use super::shape::sphere_roots;
use glam::Vec3;

/// Most spheres the lanes hold.
pub const SPHERES: usize = 8;

#[derive(Clone, Debug)]
pub struct Spheres8 {
    c: [[f32; SPHERES]; 3],
    r: [f32; SPHERES],
    /// Bit i set for a lane that holds a sphere.
    used: u32,
}

impl Spheres8 {
    /// The spheres (centre, radius) as lanes; None if there are more than eight.
    pub fn new(spheres: impl ExactSizeIterator<Item = (Vec3, f32)>) -> Option<Spheres8> {
        if spheres.len() > SPHERES {
            return None;
        }
        let mut s = Spheres8 {
            c: [[0.0; SPHERES]; 3],
            r: [0.0; SPHERES],
            used: 0,
        };
        for (i, (c, r)) in spheres.enumerate() {
            (s.c[0][i], s.c[1][i], s.c[2][i], s.r[i]) = (c.x, c.y, c.z, r);
            s.used |= 1 << i;
        }
        Some(s)
    }

    /// Whether the ray hits any of the spheres within (tmin, tmax).
    #[inline(always)]
    pub fn any(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> bool {
        // Most rays pass by every sphere: the test without divisions and square roots sends
        // them back sooner (the exact test is one long chain of dependent divisions).
        let mut near = 0u32;
        for i in 0..SPHERES {
            let c = Vec3::new(self.c[0][i], self.c[1][i], self.c[2][i]);
            near |= (may_hit_sphere(o, d, c, self.r[i]) as u32) << i;
        }
        if near & self.used == 0 {
            return false;
        }
        let mut hit = 0u32;
        for i in 0..SPHERES {
            let c = Vec3::new(self.c[0][i], self.c[1][i], self.c[2][i]);
            hit |= (hits_sphere(o, d, tmin, tmax, c, self.r[i]) as u32) << i;
        }
        hit & self.used != 0
    }

    /// `any` of each ray of a packet set in `active`, the rays in lanes and the spheres one
    /// by one: bit i is lane i's answer. A sphere's exact test only runs if one of the
    /// lanes still open passes its test without divisions (`any` leaves out the same ones).
    /// Out of line, so that inlining it does not enlarge the lane kernel of scenes without
    /// sphere lights.
    #[inline(never)]
    pub fn any8(&self, rays: &RayPacket, active: u32) -> u32 {
        let mut hit = 0u32;
        for s in bits(self.used) {
            let (c, r) = (
                Vec3::new(self.c[0][s], self.c[1][s], self.c[2][s]),
                self.r[s],
            );
            let mut near = 0u32;
            for i in 0..PACKET {
                near |= (may_hit_sphere(rays.o(i), rays.d(i), c, r) as u32) << i;
            }
            if near & active & !hit == 0 {
                continue;
            }
            for i in 0..PACKET {
                let h = hits_sphere(rays.o(i), rays.d(i), rays.tmin[i], rays.tmax[i], c, r);
                hit |= (h as u32) << i;
            }
        }
        hit & active
    }
}

/// False only if the line through o along d passes the sphere so far from its centre that
/// `hits_sphere` misses it. The squared distance is |f x d|^2 / |d|^2 (f = o - c); f32
/// puts the computed distance, here and in `hits_sphere`'s f - (b / a) d, within ~6 ulps of
/// |f| of the true one, so a line is kept out to (r + k |f|) with k = 64 ulps, bounded
/// without a square root by 2 r^2 + 2 k^2 |f|^2.
#[inline(always)]
fn may_hit_sphere(o: Vec3, d: Vec3, c: Vec3, r: f32) -> bool {
    const K2: f32 = (64.0 * f32::EPSILON) * (64.0 * f32::EPSILON);
    let f = o - c;
    let x = f.cross(d);
    x.dot(x) <= d.dot(d) * (2.0 * (r * r) + 2.0 * K2 * f.dot(f))
}

/// `intersect_sphere(..).is_some()` with selects for its branches.
#[inline(always)]
fn hits_sphere(o: Vec3, d: Vec3, tmin: f32, tmax: f32, c: Vec3, r: f32) -> bool {
    let (disc, q, t0, t1) = sphere_roots(o, d, c, r);
    let inside = |t: f32| t > tmin && t < tmax;
    !(disc < 0.0) & (q != 0.0) & (inside(t0) | inside(t1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shape::intersect_sphere;
    use crate::geometry::Ray;
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_uniform_sphere;

    /// Rays aimed at, near and past the rim of spheres of radii 1e-3 to 1e2, from inside and
    /// outside, with intervals that end before, inside and after them: the lanes answer
    /// exactly as `intersect_sphere` does, ray by ray and sphere by sphere.
    #[test]
    fn lanes_answer_as_intersect_sphere() {
        let mut rng = Rng::new(3, 9);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let spheres = random_spheres(&mut rng);
            let lanes = Spheres8::new(spheres.iter().copied()).unwrap();
            let (o, d, tmin, tmax) = random_ray(&mut rng, &spheres);
            let want = spheres
                .iter()
                .any(|&(c, r)| intersect_sphere(o, d, tmin, tmax, c, r).is_some());
            assert_eq!(
                lanes.any(o, d, tmin, tmax),
                want,
                "o {o} d {d} [{tmin}, {tmax}]"
            );
            if want {
                hits += 1
            } else {
                misses += 1
            }
        }
        assert!(
            hits > 5_000 && misses > 5_000,
            "{hits} hits, {misses} misses"
        );
    }

    /// Packets of such rays, each lane aimed at a sphere of its own, under random active
    /// masks: `any8` answers lane by lane as `any` does, and nothing for inactive lanes.
    #[test]
    fn packets_answer_as_any() {
        let mut rng = Rng::new(4, 1);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..5_000 {
            let spheres = random_spheres(&mut rng);
            let lanes = Spheres8::new(spheres.iter().copied()).unwrap();
            let mut rays = RayPacket::default();
            for i in 0..PACKET {
                let (o, d, tmin, tmax) = random_ray(&mut rng, &spheres);
                rays.set(
                    i,
                    &Ray {
                        o,
                        d,
                        tmin,
                        tmax,
                        skip: 0,
                    },
                );
            }
            let active = rng.next_u32() & 0xff;
            let got = lanes.any8(&rays, active);
            for i in 0..PACKET {
                let r = rays.ray(i);
                let want = active >> i & 1 != 0 && lanes.any(r.o, r.d, r.tmin, r.tmax);
                assert_eq!(got >> i & 1 != 0, want, "lane {i} of {active:#x}: {r:?}");
                hits += want as u32;
                misses += (active >> i & 1 != 0 && !want) as u32;
            }
        }
        assert!(
            hits > 5_000 && misses > 5_000,
            "{hits} hits, {misses} misses"
        );
    }

    /// One to eight spheres of radii 1e-3 to 1e2 in a box 20 wide.
    fn random_spheres(rng: &mut Rng) -> Vec<(Vec3, f32)> {
        let n = 1 + rng.next_u32() as usize % SPHERES;
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
                (c, 10f32.powf(rng.next_f32() * 5.0 - 3.0))
            })
            .collect()
    }

    /// A ray at one of the spheres, from inside, near or far, through a point near its rim
    /// (about half hit), with an interval that ends before, inside or after it.
    fn random_ray(rng: &mut Rng, spheres: &[(Vec3, f32)]) -> (Vec3, Vec3, f32, f32) {
        let (c, r) = spheres[rng.next_u32() as usize % spheres.len()];
        // Up to 1e6 radii away, where f32 loses the most.
        let far = [4.0 * rng.next_f32(), 10f32.powf(6.0 * rng.next_f32())];
        let o = c + square_to_uniform_sphere(rng.next_2d()) * r * far[rng.next_u32() as usize % 2];
        let rim = c + square_to_uniform_sphere(rng.next_2d()) * r * (0.9 + 0.2 * rng.next_f32());
        let d = (rim - o) * (0.1 + 10.0 * rng.next_f32());
        let tmin = [0.0, 1e-4, 0.5][rng.next_u32() as usize % 3];
        let tmax = [f32::INFINITY, 1.0, 0.3][rng.next_u32() as usize % 3];
        (o, d, tmin, tmax)
    }

    /// Lines aimed within 1e-3 of the rim, from 1 to 1e7 radii away: every one the exact test
    /// hits passes the test without divisions, which still turns away lines at twice the
    /// radius (it is not a test that keeps everything).
    #[test]
    fn quick_test_keeps_every_hit() {
        let mut rng = Rng::new(5, 2);
        let (mut hits, mut turned_away) = (0, 0);
        for k in 0..200_000 {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 200.0 - 100.0;
            let r = 10f32.powf(rng.next_f32() * 4.0 - 3.0);
            let dist = r * 10f32.powf(7.0 * rng.next_f32());
            let o = c + square_to_uniform_sphere(rng.next_2d()) * dist;
            let aim = if k % 4 == 0 {
                2.0
            } else {
                1.0 + (rng.next_f32() - 0.5) * 2e-3
            };
            let rim = c + square_to_uniform_sphere(rng.next_2d()) * r * aim;
            let d = (rim - o) * 10f32.powf(rng.next_f32() * 4.0 - 2.0);
            let exact = hits_sphere(o, d, 0.0, f32::INFINITY, c, r);
            let quick = may_hit_sphere(o, d, c, r);
            assert!(
                quick || !exact,
                "o {o} d {d} c {c} r {r}: hit, but turned away"
            );
            hits += exact as u32;
            turned_away += (k % 4 == 0 && !quick) as u32;
        }
        assert!(hits > 20_000, "{hits} hits");
        assert!(
            turned_away > 20_000,
            "{turned_away} of 50000 lines at 2 r turned away"
        );
    }

    #[test]
    fn more_than_eight_do_not_fit_and_unused_lanes_never_hit() {
        let nine = (0..9).map(|i| (Vec3::X * i as f32, 0.5));
        assert!(Spheres8::new(nine).is_none());
        let one = Spheres8::new([(Vec3::new(0.0, 0.0, 5.0), 1.0)].into_iter()).unwrap();
        assert!(one.any(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY));
        // The empty lanes hold spheres of radius 0 at the origin, which this ray passes
        // through: they must not count.
        assert!(!one.any(Vec3::new(0.0, 0.0, -1.0), -Vec3::Z, 0.0, f32::INFINITY));
        let through_empty = Ray::new(Vec3::new(0.0, 0.0, -1.0), -Vec3::Z);
        assert_eq!(one.any8(&RayPacket::splat(&through_empty), 0xff), 0);
        let none = Spheres8::new(std::iter::empty()).unwrap();
        assert!(!none.any(Vec3::new(0.0, 0.0, -1.0), Vec3::Z, 0.0, f32::INFINITY));
        assert_eq!(none.any8(&RayPacket::default(), 0xff), 0);
    }
}
