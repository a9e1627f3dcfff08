//! Bounds of what an emitter (or a set of them) can send towards a point: a box, a cone of
//! emission normals, and the power. `importance` is an upper-bound-like estimate of the
//! contribution at a receiver, used by the shading-point-dependent emitter choices
//! (`exhaustive`, and the light tree's nodes). The measure follows pbrt-v4's
//! (`LightBounds::Importance`), with its distance clamp fixed: pbrt compares the squared
//! distance with the half diagonal's length, which makes the pmf change with the scene's unit;
//! here both are squared lengths, so the importance of area lights does not depend on the unit.
//! Its cosines are bounded over the box rather than its bounding sphere (see `importance`).

use super::Emitter;
use crate::geometry::{Shape, ShapeKind};
use glam::{DVec3, Vec3};

/// A cone of directions: unit axis `w` and the cosine and sine of its half-angle (cosine
/// -1: every direction). The sine is kept rather than recovered from the cosine, which near
/// 1 keeps only the square root of the precision: the importance of a flat light seen near
/// grazing then moved by 2e-3 with the rounding of its normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Unit axis.
    pub w: Vec3,
    /// Cosine of the half-angle.
    pub cos: f32,
    /// Sine of the half-angle.
    pub sin: f32,
}

/// The angle between two unit vectors, accurate near 0 and pi.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// A margin (radians) for the rounding of the normals and angles.
const MARGIN: f64 = 1e-6;

impl Cone {
    /// Every direction.
    pub const SPHERE: Cone = Cone {
        w: Vec3::Z,
        cos: -1.0,
        sin: 0.0,
    };

    /// The cone of half-angle `theta` about `w`; past a hemisphere, the whole sphere: a
    /// convex combination of directions in a cone wider than that (an interpolated vertex
    /// normal) can leave it.
    fn with_angle(w: DVec3, theta: f64) -> Cone {
        if theta >= std::f64::consts::FRAC_PI_2 {
            return Cone::SPHERE;
        }
        Cone {
            w: w.as_vec3(),
            cos: theta.cos() as f32,
            sin: theta.sin() as f32,
        }
    }

    fn theta(self) -> f64 {
        (self.sin as f64).atan2(self.cos as f64)
    }

    /// The smallest cone about the normalised mean that holds every direction of `dirs`
    /// (unit vectors).
    pub fn around(dirs: impl Iterator<Item = Vec3> + Clone) -> Cone {
        let Some(w) = dirs
            .clone()
            .map(|d| d.as_dvec3())
            .sum::<DVec3>()
            .try_normalize()
        else {
            return Cone::SPHERE;
        };
        let theta = dirs.map(|d| angle(w, d.as_dvec3())).fold(0.0f64, f64::max);
        Cone::with_angle(w, theta + MARGIN)
    }

    /// A cone holding both (pbrt-v4's `Union` of direction cones).
    pub fn union(self, o: Cone) -> Cone {
        let (ta, tb) = (self.theta(), o.theta());
        let (wa, wb) = (self.w.as_dvec3(), o.w.as_dvec3());
        let td = angle(wa, wb);
        let pi = std::f64::consts::PI;
        if (td + tb).min(pi) <= ta {
            return self;
        }
        if (td + ta).min(pi) <= tb {
            return o;
        }
        let to = (ta + td + tb) / 2.0 + MARGIN;
        let Some(axis) = wa.cross(wb).try_normalize() else {
            return Cone::SPHERE;
        };
        let w = glam::DQuat::from_axis_angle(axis, to - ta) * wa;
        Cone::with_angle(w.normalize(), to)
    }
}

/// What an emitter, or a node of the light tree, can send: its box, the cone of its
/// emission normals, the half-angle of emission about each normal (`cos_e`, 0 for one-sided
/// diffuse emitters: a hemisphere) and its power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Lower corner of the bounding box.
    pub lo: Vec3,
    /// Upper corner of the bounding box.
    pub hi: Vec3,
    /// Bounds of the emission normals.
    pub normals: Cone,
    /// Cosine of the emission half-angle about each normal.
    pub cos_e: f32,
    /// Emitted power.
    pub phi: f32,
}

#[inline]
fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

/// cos(max(0, a - b)) from the sines and cosines of a and b.
#[inline]
fn cos_sub_clamped(sin_a: f64, cos_a: f64, sin_b: f64, cos_b: f64) -> f64 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

impl LightBounds {
    /// The bounds of emitter `e`, or None if it emits nothing (zero or non-finite power, or
    /// no triangle of positive area): such an emitter is never chosen.
    pub fn of(e: &Emitter, shapes: &[Shape]) -> Option<LightBounds> {
        let phi = e.power() as f32;
        if !(phi > 0.0 && phi.is_finite()) {
            return None;
        }
        let (lo, hi, normals) = match e {
            Emitter::Point(p) => (p.position, p.position, Cone::SPHERE),
            Emitter::Area(a) => match &shapes[a.shape as usize].kind {
                ShapeKind::Sphere(s) => {
                    let r = Vec3::splat(s.radius);
                    (s.center - r, s.center + r, Cone::SPHERE)
                }
                ShapeKind::Mesh(m) => {
                    let live: Vec<usize> = (0..m.indices.len())
                        .filter(|&t| m.triangle_area(t) > 0.0)
                        .collect();
                    if live.is_empty() {
                        return None;
                    }
                    let (mut lo, mut hi) =
                        (Vec3::splat(f32::INFINITY), -Vec3::splat(f32::INFINITY));
                    let mut dirs = Vec::new();
                    for &t in &live {
                        for v in m.vertices(t) {
                            (lo, hi) = (lo.min(v), hi.max(v));
                        }
                        // A light point's emission side is its shading normal: the face
                        // normal, or the interpolated vertex normals (inside their cone),
                        // with the face normal where they cancel (`Mesh::point_from`).
                        dirs.push(m.face(t).0);
                        if let Some(ns) = m.vertex_normals(t) {
                            dirs.extend(ns.iter().filter_map(|n| n.try_normalize()));
                        }
                    }
                    (lo, hi, Cone::around(dirs.iter().copied()))
                }
            },
        };
        Some(LightBounds {
            lo,
            hi,
            normals,
            cos_e: 0.0,
            phi,
        })
    }

    /// Bounds of both lights (a light tree's inner node).
    pub fn union(&self, o: &LightBounds) -> LightBounds {
        LightBounds {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
            normals: self.normals.union(o.normals),
            cos_e: self.cos_e.min(o.cos_e),
            phi: self.phi + o.phi,
        }
    }

    /// Centre of the bounding box.
    pub fn centroid(&self) -> Vec3 {
        (self.lo + self.hi) * 0.5
    }

    /// An estimate of the contribution at point `p` with normal `n` (zero vector: no
    /// receiver cosine), which is 0 only where nothing inside the bounds can send light to
    /// `p`: `p` outside every emission cone, or every point of the box in `p`'s tangent
    /// plane.
    ///
    /// pbrt-v4's form, power x emission cosine x receiver cosine / squared distance, with two
    /// changes. The distance clamp is unit-free (see the module comment). The cosines are
    /// bounded over the box itself rather than over its bounding sphere's cone: for each,
    /// the largest dot product of a box point with the axis (a box's corner) over the
    /// nearest distance to the box. Seen at a grazing angle, a wide flat node of lights then
    /// has the small cosines its lights have, where the sphere's cone gave it cosines of 1:
    /// on a grid of lights over a floor the tree's pmf followed the 1/d^2 of the nodes'
    /// centres instead of each light's falloff, and did little better than power choice.
    /// In f64: sines recovered from cosines near 1 keep only the square root of f32's
    /// precision.
    #[inline]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f64 {
        let (lo, hi) = (self.lo.as_dvec3(), self.hi.as_dvec3());
        let pd = p.as_dvec3();
        let pc = (lo + hi) * 0.5;
        let d2 = (pd - pc).length_squared();
        // The squared radius of the box's bounding sphere clamps the distance: a point
        // inside would make the importance unbounded.
        let r2 = 0.25 * (hi - lo).length_squared();
        let d_min = (pd - pd.clamp(lo, hi)).length();
        // Upper bound of cos(w, p - x) over the box points x: the largest w . (p - x) (at a
        // corner) over the nearest distance, or if it is negative over the farthest.
        let w = self.normals.w.as_dvec3();
        let cos_w = if d_min > 0.0 {
            let top = w.dot(pd) - (w * lo).min(w * hi).element_sum();
            if top >= 0.0 {
                (top / d_min).min(1.0)
            } else {
                let far = DVec3::select(pd.cmplt(pc), hi, lo);
                (top / (pd - far).length()).max(-1.0)
            }
        } else {
            1.0
        };
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        let (cos_o, sin_o) = (self.normals.cos as f64, self.normals.sin as f64);
        // The smallest angle from a normal in the cone to p.
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        if cos_x <= self.cos_e as f64 {
            return 0.0;
        }
        let mut importance = self.phi as f64 * cos_x / d2.max(r2).max(f64::MIN_POSITIVE);
        if n != Vec3::ZERO && d_min > 0.0 {
            // Upper bound of |cos(n, x - p)| over the box.
            let nd = n.as_dvec3();
            let (x, y) = (nd * lo, nd * hi);
            let (top, bottom) = (x.max(y).element_sum(), x.min(y).element_sum());
            let np = nd.dot(pd);
            let reach = (top - np).abs().max((bottom - np).abs());
            importance *= (reach / d_min).min(1.0);
        }
        importance.max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_uniform_sphere;

    fn dir(rng: &mut Rng) -> Vec3 {
        square_to_uniform_sphere(rng.next_2d())
    }

    /// `around` and `union` hold every direction they were given (random sets and cones).
    #[test]
    fn cones_hold_their_directions() {
        let mut rng = Rng::new(4, 1);
        for _ in 0..2000 {
            let centre = dir(&mut rng);
            let spread = rng.next_f32() * 1.2;
            let dirs: Vec<Vec3> = (0..5)
                .map(|_| (centre + dir(&mut rng) * spread).normalize())
                .collect();
            let (a, b) = (
                Cone::around(dirs[..3].iter().copied()),
                Cone::around(dirs[3..].iter().copied()),
            );
            let u = a.union(b);
            for (k, d) in dirs.iter().enumerate() {
                let c = if k < 3 { a } else { b };
                let d = d.as_dvec3();
                for c in [c, u] {
                    assert!(
                        c.cos == -1.0 || angle(c.w.as_dvec3(), d) <= c.theta(),
                        "{c:?} {d}"
                    );
                }
            }
            assert!(
                a.cos == -1.0 || a.cos > 0.0,
                "a cone is a hemisphere at most"
            );
            let t = a.theta();
            assert!((t.cos() as f32 - a.cos).abs() < 1e-6 && (t.sin() as f32 - a.sin).abs() < 1e-6);
        }
        assert_eq!(Cone::around([Vec3::X, -Vec3::X].into_iter()), Cone::SPHERE);
        let flat = Cone::around([Vec3::Z; 4].into_iter());
        assert!(flat.w == Vec3::Z && flat.cos > 0.999_99);
    }

    /// A one-sided quad facing down (+-1 in x and y at height 1, normal -z): its importance
    /// is positive below it, 0 above its plane and far enough to the side, and unchanged
    /// when the scene's unit changes (pbrt-v4's clamp is not).
    #[test]
    fn importance_of_a_quad() {
        let b = LightBounds {
            lo: Vec3::new(-1.0, -1.0, 1.0),
            hi: Vec3::new(1.0, 1.0, 1.0),
            normals: Cone::around([-Vec3::Z].into_iter()),
            cos_e: 0.0,
            phi: 4.0 * std::f32::consts::PI,
        };
        assert!(b.importance(Vec3::ZERO, Vec3::Z) > 0.0);
        assert!(b.importance(Vec3::new(0.0, 0.0, 0.5), Vec3::ZERO) > 0.0);
        assert_eq!(b.importance(Vec3::new(0.0, 0.0, 3.0), Vec3::Z), 0.0);
        assert_eq!(b.importance(Vec3::new(100.0, 0.0, 5.0), Vec3::ZERO), 0.0);
        // Far below, about phi cos / d^2.
        let far = b.importance(Vec3::new(0.0, 0.0, -999.0), Vec3::ZERO);
        let want = b.phi as f64 / 1.0e6;
        assert!((far / want - 1.0).abs() < 1e-3, "{far} {want}");
        for s in [1e-3f32, 1e3] {
            let scaled = LightBounds {
                lo: b.lo * s,
                hi: b.hi * s,
                phi: b.phi * s * s,
                ..b
            };
            for p in [
                Vec3::ZERO,
                Vec3::new(0.3, 1.7, 0.9),
                Vec3::new(5.0, -2.0, -3.0),
            ] {
                let (a, c) = (b.importance(p, Vec3::Y), scaled.importance(p * s, Vec3::Y));
                assert!((a - c).abs() <= 1e-5 * a, "scale {s}, {p}: {a} {c}");
            }
        }
    }
}
