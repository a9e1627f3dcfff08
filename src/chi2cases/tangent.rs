//! A window of directions seen through the plane tangent to the unit sphere at an axis
//! (gnomonic projection): direction d maps to (x, y) = (d.s, d.t) / (d.n).
//!
//! A light 1000 sizes away covers ~1e-6 sr, a light seen at grazing angles a thin sliver:
//! on the whole sphere either falls into one or two cells and the test has no power. The
//! window is fitted to the light's projection (a polygon stays a polygon under this map), so
//! its cells resolve the light whatever its size.
//!
//! Solid angle is dω = cos³θ dx dy (θ from the axis), not constant as [`Domain`] requires,
//! so the measure goes into the pdf instead: test against [`Tangent::plane_pdf`].

use crate::stats::Domain;
use glam::{DVec3, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Tangent {
    s: DVec3,
    t: DVec3,
    n: DVec3,
    x: [f64; 2],
    y: [f64; 2],
    cols: usize,
    rows: usize,
}

/// Fewest cells across a window's short side.
const MIN_ROWS: usize = 9;
/// Widening of the fitted bounding box on every side, as a fraction of its size.
const MARGIN: f64 = 0.04;

impl Tangent {
    /// The window around `axis` holding every direction in `dirs` (all within 90 degrees of
    /// the axis), with `resolution` cells along its long side. The frame's first axis is the
    /// principal axis of the projected directions, so slivers lie along the grid's rows.
    pub fn fit(axis: DVec3, dirs: &[DVec3], resolution: usize) -> Tangent {
        let n = axis.normalize();
        let proj = |d: DVec3| {
            let z = d.dot(n);
            assert!(z > 0.0, "direction {d} is not in front of the axis {n}");
            d / z - n
        };
        let e1 = n.any_orthonormal_vector();
        let e2 = n.cross(e1);
        let pts: Vec<(f64, f64)> = dirs
            .iter()
            .map(|d| {
                let p = proj(*d);
                (p.dot(e1), p.dot(e2))
            })
            .collect();
        let k = pts.len().max(1) as f64;
        let (mx, my) = pts
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / k, b + y / k));
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for (x, y) in &pts {
            let (dx, dy) = (x - mx, y - my);
            sxx += dx * dx;
            syy += dy * dy;
            sxy += dx * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let s = e1 * angle.cos() + e2 * angle.sin();
        let t = n.cross(s);
        let (mut x, mut y) = (
            [f64::INFINITY, -f64::INFINITY],
            [f64::INFINITY, -f64::INFINITY],
        );
        for d in dirs {
            let p = proj(*d);
            let (px, py) = (p.dot(s), p.dot(t));
            x = [x[0].min(px), x[1].max(px)];
            y = [y[0].min(py), y[1].max(py)];
        }
        // Each side grows with its own extent, so a sliver's window stays a sliver.
        let (px, py) = (MARGIN * (x[1] - x[0]), MARGIN * (y[1] - y[0]));
        let x = [x[0] - px, x[1] + px];
        let y = [y[0] - py, y[1] + py];
        let (w, h) = (x[1] - x[0], y[1] - y[0]);
        let r = resolution.max(MIN_ROWS);
        let short = |a: f64, b: f64| ((r as f64 * a / b).round() as usize).clamp(MIN_ROWS, r);
        let (cols, rows) = if w >= h {
            (r, short(h, w))
        } else {
            (short(w, h), r)
        };
        Tangent {
            s,
            t,
            n,
            x,
            y,
            cols,
            rows,
        }
    }

    /// The window holding the cone of half-angle `half_angle` (radians, below 90 degrees).
    pub fn cone(axis: DVec3, half_angle: f64, resolution: usize) -> Tangent {
        let n = axis.normalize();
        let s = n.any_orthonormal_vector();
        let t = n.cross(s);
        let (sin, cos) = half_angle.sin_cos();
        let rim: Vec<DVec3> = [s, -s, t, -t].iter().map(|e| n * cos + *e * sin).collect();
        Tangent::fit(n, &rim, resolution)
    }

    /// The window's axis.
    pub fn axis(&self) -> DVec3 {
        self.n
    }

    /// Where the direction `d` meets the window's plane, in its (x, y); None for directions
    /// not in front of it.
    pub fn project(&self, d: DVec3) -> Option<[f64; 2]> {
        let z = d.dot(self.n);
        (z > 0.0).then(|| [d.dot(self.s) / z, d.dot(self.t) / z])
    }

    /// The unit direction through the window's point (x, y), in f64.
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        (self.n + x * self.s + y * self.t).normalize()
    }

    /// Converts a solid-angle pdf into a density per unit area of the window's plane.
    pub fn plane_pdf(&self, pdf: impl Fn(Vec3) -> f64) -> impl Fn(Vec3) -> f64 {
        let n = self.n;
        move |d: Vec3| {
            let c = d.as_dvec3().normalize().dot(n);
            if c <= 0.0 {
                0.0
            } else {
                pdf(d) * c * c * c
            }
        }
    }
}

impl Domain for Tangent {
    type Point = Vec3;

    fn name(&self) -> &'static str {
        "tangent-plane window"
    }

    fn axes(&self) -> [&'static str; 2] {
        ["s (tangent plane, long axis)", "t (short axis)"]
    }

    fn resolution(&self) -> (usize, usize) {
        (self.cols, self.rows)
    }

    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        (self.x, self.y)
    }

    fn jacobian(&self) -> f64 {
        1.0
    }

    fn point(&self, x: f64, y: f64) -> Option<Vec3> {
        Some((self.n + x * self.s + y * self.t).normalize().as_vec3())
    }

    fn locate(&self, p: Vec3) -> Result<(f64, f64), String> {
        let d = p.as_dvec3();
        let len = d.length();
        if !len.is_finite() || (len - 1.0).abs() > 1e-3 {
            return Err(format!("direction {p} is not unit length (|d| = {len})"));
        }
        let z = d.dot(self.n);
        if !(z > 0.0) {
            return Err(format!("direction {p} points away from the window"));
        }
        let (x, y) = (d.dot(self.s) / z, d.dot(self.t) / z);
        let inside = |v: f64, [a, b]: [f64; 2]| v >= a && v <= b;
        if !(inside(x, self.x) && inside(y, self.y)) {
            return Err(format!(
                "direction {p} outside the window (x {x:.3e} in {:?}, y {y:.3e} in {:?})",
                self.x, self.y
            ));
        }
        Ok((x, y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_contains_its_directions_and_round_trips() {
        let axis = DVec3::new(0.2, -0.1, 1.0);
        let dirs: Vec<DVec3> = [(0.1, 0.0), (0.0, 0.02), (-0.05, -0.01)]
            .iter()
            .map(|&(a, b)| (axis.normalize() + DVec3::new(a, b, 0.0)).normalize())
            .collect();
        let w = Tangent::fit(axis, &dirs, 51);
        for d in &dirs {
            let (x, y) = w.locate(d.as_vec3()).unwrap();
            let back = w.point(x, y).unwrap().as_dvec3();
            assert!((back - *d).length() < 1e-6);
        }
        assert!(w.locate((-axis).normalize().as_vec3()).is_err());
        let (c, r) = w.resolution();
        assert_eq!(c.max(r), 51);
        assert!(c.min(r) >= MIN_ROWS);
    }

    #[test]
    fn plane_pdf_of_uniform_cone_integrates_to_one() {
        // Uniform density over a cone of half-angle 0.3: its plane density times dx dy must
        // integrate to 1 (midpoint rule on 400^2 points; the rim is the only error).
        let half = 0.3f64;
        let w = Tangent::cone(DVec3::Z, half, 21);
        let inv = 1.0 / (std::f64::consts::TAU * (1.0 - half.cos()));
        let pdf = w.plane_pdf(move |d| if (d.z as f64) >= half.cos() { inv } else { 0.0 });
        let ([x0, x1], [y0, y1]) = w.bounds();
        let m = 400;
        let (dx, dy) = ((x1 - x0) / m as f64, (y1 - y0) / m as f64);
        let mut s = 0.0;
        for i in 0..m {
            for j in 0..m {
                let p = w.point(x0 + (i as f64 + 0.5) * dx, y0 + (j as f64 + 0.5) * dy);
                s += pdf(p.unwrap()) * dx * dy;
            }
        }
        assert!((s - 1.0).abs() < 5e-3, "{s}");
    }
}
