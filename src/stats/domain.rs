//! Sample domains of the chi-square test: how points map to cells, and how each cell is
//! parameterised for integrating the pdf.
//!
//! Every domain is a rectangle `[u0,u1] x [v0,v1]` of parameters cut into `cols x rows`
//! equal cells; the measure the pdf is expressed in is `jacobian() * du dv`. The
//! parameterisations are chosen so that the Jacobian is constant and uniform pdfs give equal
//! expected counts, which keeps the test's power the same everywhere.

use glam::{DVec2, DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

/// Slack for f32 samples that sit on the domain's boundary up to rounding.
const BOUNDARY_EPS: f64 = 1e-5;

/// A parameterised sample domain cut into a grid of cells.
pub trait Domain {
    /// What samplers return and pdfs take.
    type Point: Copy;
    /// Short name for reports.
    fn name(&self) -> &'static str;
    /// What u (columns, left to right) and v (rows, bottom to top) are, for heat maps.
    fn axes(&self) -> [&'static str; 2] {
        ["u", "v"]
    }
    /// Grid size `(cols, rows)`: cols along u, rows along v.
    fn resolution(&self) -> (usize, usize);
    /// Parameter rectangle `([u0, u1], [v0, v1])`.
    fn bounds(&self) -> ([f64; 2], [f64; 2]);
    /// Ratio of the pdf's measure to `du dv`.
    fn jacobian(&self) -> f64;
    /// The point with parameters (u, v), or None where the parameter rectangle covers more
    /// than the domain (the triangle's upper half).
    fn point(&self, u: f64, v: f64) -> Option<Self::Point>;
    /// Parameters of a sampled point, or why the point is not in the domain.
    fn locate(&self, p: Self::Point) -> Result<(f64, f64), String>;

    /// Cell `(col, row)` holding a sampled point.
    fn cell_of(&self, p: Self::Point) -> Result<(usize, usize), String> {
        let (u, v) = self.locate(p)?;
        let ([u0, u1], [v0, v1]) = self.bounds();
        let (cols, rows) = self.resolution();
        let index = |x: f64, lo: f64, hi: f64, n: usize| {
            (((x - lo) / (hi - lo) * n as f64).floor().max(0.0) as usize).min(n - 1)
        };
        Ok((index(u, u0, u1, cols), index(v, v0, v1, rows)))
    }
}

fn finite2(p: Vec2) -> Result<DVec2, String> {
    if p.is_finite() {
        Ok(p.as_dvec2())
    } else {
        Err(format!("non-finite sample {p}"))
    }
}

/// Azimuth in [0, 2 pi).
fn azimuth(y: f64, x: f64) -> f64 {
    let phi = y.atan2(x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

/// Unit sphere of directions, cells equal in solid angle: u = phi in [0, 2 pi),
/// v = cos theta in [-1, 1], so d(omega) = dphi dcos(theta) and the Jacobian is 1.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub n_phi: usize,
    /// Keep this odd so no cell boundary lies on the equator, where hemispherical pdfs jump.
    pub n_cos: usize,
}

impl Default for Sphere {
    fn default() -> Self {
        Sphere {
            n_phi: 51,
            n_cos: 101,
        }
    }
}

impl Domain for Sphere {
    type Point = Vec3;
    fn name(&self) -> &'static str {
        "sphere"
    }
    fn axes(&self) -> [&'static str; 2] {
        ["phi 0..2pi", "cos theta -1..1"]
    }
    fn resolution(&self) -> (usize, usize) {
        (self.n_phi, self.n_cos)
    }
    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        ([0.0, TAU], [-1.0, 1.0])
    }
    fn jacobian(&self) -> f64 {
        1.0
    }
    fn point(&self, phi: f64, cos_theta: f64) -> Option<Vec3> {
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Some(DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta).as_vec3())
    }
    fn locate(&self, p: Vec3) -> Result<(f64, f64), String> {
        let d = p.as_dvec3();
        let len = d.length();
        // A sloppy normalisation means the pdf was evaluated at another direction.
        if !len.is_finite() || (len - 1.0).abs() > 1e-3 {
            return Err(format!("direction {p} is not unit length (|d| = {len})"));
        }
        let d = d / len;
        Ok((azimuth(d.y, d.x), d.z.clamp(-1.0, 1.0)))
    }
}

/// The unit square [0,1]^2 in n x n cells; the pdf is per unit area.
#[derive(Clone, Copy, Debug)]
pub struct UnitSquare {
    pub n: usize,
}

impl Default for UnitSquare {
    fn default() -> Self {
        UnitSquare { n: 51 }
    }
}

fn in_unit_square(p: DVec2) -> bool {
    (-BOUNDARY_EPS..=1.0 + BOUNDARY_EPS).contains(&p.x)
        && (-BOUNDARY_EPS..=1.0 + BOUNDARY_EPS).contains(&p.y)
}

impl Domain for UnitSquare {
    type Point = Vec2;
    fn name(&self) -> &'static str {
        "unit square"
    }
    fn axes(&self) -> [&'static str; 2] {
        ["x 0..1", "y 0..1"]
    }
    fn resolution(&self) -> (usize, usize) {
        (self.n, self.n)
    }
    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        ([0.0, 1.0], [0.0, 1.0])
    }
    fn jacobian(&self) -> f64 {
        1.0
    }
    fn point(&self, u: f64, v: f64) -> Option<Vec2> {
        Some(Vec2::new(u as f32, v as f32))
    }
    fn locate(&self, p: Vec2) -> Result<(f64, f64), String> {
        let d = finite2(p)?;
        if !in_unit_square(d) {
            return Err(format!("sample {p} outside the unit square"));
        }
        Ok((d.x, d.y))
    }
}

/// The unit disk in polar cells equal in area: u = phi in [0, 2 pi), v = r^2 in [0, 1].
/// dA = r dr dphi = 1/2 d(r^2) dphi, so the Jacobian is 1/2. Polar cells (rather than a
/// square grid) make every cell lie inside the disk, so a sample beyond r = 1 is reported as
/// outside the domain, and the pdf is only ever evaluated inside the disk.
#[derive(Clone, Copy, Debug)]
pub struct Disk {
    pub n_phi: usize,
    pub n_r2: usize,
}

impl Default for Disk {
    fn default() -> Self {
        Disk {
            n_phi: 51,
            n_r2: 51,
        }
    }
}

impl Domain for Disk {
    type Point = Vec2;
    fn name(&self) -> &'static str {
        "unit disk"
    }
    fn axes(&self) -> [&'static str; 2] {
        ["phi 0..2pi", "r^2 0..1"]
    }
    fn resolution(&self) -> (usize, usize) {
        (self.n_phi, self.n_r2)
    }
    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        ([0.0, TAU], [0.0, 1.0])
    }
    fn jacobian(&self) -> f64 {
        0.5
    }
    fn point(&self, phi: f64, r2: f64) -> Option<Vec2> {
        let r = r2.max(0.0).sqrt();
        Some(Vec2::new((r * phi.cos()) as f32, (r * phi.sin()) as f32))
    }
    fn locate(&self, p: Vec2) -> Result<(f64, f64), String> {
        let d = finite2(p)?;
        let r2 = d.length_squared();
        if r2 > 1.0 + BOUNDARY_EPS {
            return Err(format!(
                "sample {p} outside the unit disk (r = {})",
                r2.sqrt()
            ));
        }
        Ok((azimuth(d.y, d.x), r2.min(1.0)))
    }
}

/// The right triangle (0,0), (1,0), (0,1) on an n x n square grid; cells above the diagonal
/// get expected count 0 and the diagonal cells are integrated over their lower part only.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub n: usize,
}

impl Default for Triangle {
    fn default() -> Self {
        Triangle { n: 51 }
    }
}

impl Domain for Triangle {
    type Point = Vec2;
    fn name(&self) -> &'static str {
        "unit triangle"
    }
    fn axes(&self) -> [&'static str; 2] {
        ["x 0..1", "y 0..1 (x + y <= 1)"]
    }
    fn resolution(&self) -> (usize, usize) {
        (self.n, self.n)
    }
    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        ([0.0, 1.0], [0.0, 1.0])
    }
    fn jacobian(&self) -> f64 {
        1.0
    }
    fn point(&self, u: f64, v: f64) -> Option<Vec2> {
        (u + v <= 1.0).then(|| Vec2::new(u as f32, v as f32))
    }
    fn locate(&self, p: Vec2) -> Result<(f64, f64), String> {
        let d = finite2(p)?;
        if !in_unit_square(d) || d.x + d.y > 1.0 + BOUNDARY_EPS {
            return Err(format!("sample {p} outside the unit triangle"));
        }
        Ok((d.x.clamp(0.0, 1.0), d.y.clamp(0.0, 1.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn sphere_round_trip() {
        let s = Sphere::default();
        for (phi, c) in [(0.1, -0.99), (3.0, 0.0), (6.2, 0.7)] {
            let (u, v) = s.locate(s.point(phi, c).unwrap()).unwrap();
            assert!((u - phi).abs() < 1e-6 && (v - c).abs() < 1e-6);
        }
        assert!(s.locate(Vec3::new(0.0, 0.0, 2.0)).is_err());
        assert!(s.locate(Vec3::NAN).is_err());
        assert_eq!(s.cell_of(Vec3::Z).unwrap(), (0, 100));
        assert_eq!(s.cell_of(-Vec3::Z).unwrap().1, 0);
    }

    #[test]
    fn disk_and_triangle_reject_outside() {
        let d = Disk::default();
        assert!(d.locate(Vec2::new(0.8, 0.8)).is_err());
        let (phi, r2) = d.locate(Vec2::new(0.0, -0.5)).unwrap();
        assert!((phi - 1.5 * PI).abs() < 1e-6 && (r2 - 0.25).abs() < 1e-7);
        let t = Triangle::default();
        assert!(t.locate(Vec2::new(0.6, 0.6)).is_err());
        assert!(t.point(0.6, 0.6).is_none());
        assert_eq!(t.cell_of(Vec2::new(1.0, 0.0)).unwrap(), (50, 0));
    }

    /// Every domain maps a point to its (u, v) and back to the same point, at points spread
    /// over it (a pdf that is constant on the domain cannot see a wrong `point`).
    #[test]
    fn every_domain_round_trips_its_points() {
        let d = Disk::default();
        for p in [
            Vec2::new(0.3, -0.6),
            Vec2::new(-0.9, 0.1),
            Vec2::new(0.05, 0.7),
        ] {
            let (u, v) = d.locate(p).unwrap();
            let q = d.point(u, v).unwrap();
            assert!((q - p).length() < 1e-6, "disk {p} -> ({u}, {v}) -> {q}");
        }
        let sq = UnitSquare::default();
        let t = Triangle::default();
        for p in [
            Vec2::new(0.2, 0.7),
            Vec2::new(0.9, 0.05),
            Vec2::new(0.4, 0.4),
        ] {
            let (u, v) = sq.locate(p).unwrap();
            assert_eq!(sq.point(u, v).unwrap(), p);
            let (u, v) = t.locate(p).unwrap();
            assert_eq!(t.point(u, v).unwrap(), p);
        }
        // A direction a little off unit length is normalised before it is located.
        let s = Sphere::default();
        let dir = Vec3::new(0.36, 0.48, 0.8);
        let (u0, v0) = s.locate(dir).unwrap();
        let (u1, v1) = s.locate(dir * 1.0008).unwrap();
        assert!(
            (u0 - u1).abs() < 1e-6 && (v0 - v1).abs() < 1e-6,
            "{v0} vs {v1}"
        );
    }

    #[test]
    fn the_unit_square_refuses_either_coordinate_outside() {
        let sq = UnitSquare::default();
        for p in [
            Vec2::new(1.5, 0.5),
            Vec2::new(0.5, -0.2),
            Vec2::new(-0.1, 2.0),
        ] {
            assert!(sq.locate(p).is_err(), "{p}");
        }
        assert!(sq.locate(Vec2::new(0.0, 1.0)).is_ok());
    }

    /// Reports and heat maps name the domain.
    #[test]
    fn domains_have_their_names() {
        assert_eq!(Sphere::default().name(), "sphere");
        assert_eq!(UnitSquare::default().name(), "unit square");
        assert_eq!(Disk::default().name(), "unit disk");
        assert_eq!(Triangle::default().name(), "unit triangle");
    }
}
