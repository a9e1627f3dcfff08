//! Exact cell masses of a scene's light sampling, for the chi-square test of a light probe.
//!
//! Integrating a direction density cell by cell from nodes chosen in advance misses what lies
//! between them: a light a millionth above its receiver puts all its mass within a few
//! microradians of the horizon, a tiny light beside a huge one is a spike of 1e8 contrast, a
//! light seen edge-on a sliver. Emitter triangles stay triangles in a tangent-plane window
//! (gnomonic projection), so the support is known exactly: each triangle is projected, clipped
//! to every cell it overlaps (Sutherland-Hodgman), and its own density (emitter choice pmf
//! times the emitter's pdf of the point on that triangle, times the window's cos³ measure) is
//! integrated over each clipped polygon by an adaptive degree-5 triangle rule. The density is
//! smooth inside one triangle's projection, so the rule converges; no edge is ever straddled.
//!
//! When every emitter triangle lies in one plane the window's axis is that plane's normal:
//! the projection is then an affine copy of the light, so area sampling is uniform on the
//! window and no light is a sliver, however it is seen from the receiver. (Sampled uniformly
//! in solid angle, a light over much of the sky still puts most samples in the window's
//! middle cells: the test is correct there but has little power.)

use super::probe::LightProbe;
use super::tangent::Tangent;
use crate::geometry::ShapeKind;
use crate::stats::Grid;
use glam::{DVec3, Vec2, Vec3};

/// In a window about the lights' mean direction, corners closer to the window's plane than
/// this cosine are not projected (the window would stretch without bound); the caller falls
/// back to the whole sphere.
const MIN_COS: f64 = 1e-2;
/// Halvings of a clipped triangle at most; the degree-5 rule on the pieces converges long
/// before on a density that is smooth inside one light triangle.
const MAX_DEPTH: u32 = 6;

/// One emitter triangle: its shape, index, corners and its emitter's choice pmf.
#[derive(Clone, Copy, Debug)]
pub struct LightTriangle {
    pub shape: usize,
    pub tri: usize,
    pub v: [Vec3; 3],
    pub pmf: f64,
}

/// Every emitter triangle of the probe's scene with its emitter-choice pmf; None when a light
/// is not a mesh (a sphere's silhouette is no polygon).
pub fn light_triangles(probe: &LightProbe) -> Option<Vec<LightTriangle>> {
    let s = &probe.scene;
    let mut out = Vec::new();
    for (si, shape) in s.shapes.iter().enumerate() {
        let Some(ei) = shape.emitter else { continue };
        let ShapeKind::Mesh(m) = &shape.kind else {
            return None;
        };
        let pmf = probe.selector.pmf(probe.ref_p, probe.normal, ei as usize) as f64;
        for tri in 0..m.indices.len() {
            out.push(LightTriangle {
                shape: si,
                tri,
                v: m.vertices(tri),
                pmf,
            });
        }
    }
    Some(out)
}

/// The solid-angle density the probe's sampler gives the direction `d` through triangle `t`
/// alone (pmf excluded): the emitter's pdf of the point where `d` meets the triangle's plane.
pub fn triangle_pdf(probe: &LightProbe, t: &LightTriangle, d: Vec3) -> f64 {
    let s = &probe.scene;
    let ShapeKind::Mesh(m) = &s.shapes[t.shape].kind else {
        return 0.0;
    };
    let Some(b) = barycentrics(probe.ref_p.as_dvec3(), d.as_dvec3(), t.v) else {
        return 0.0;
    };
    let sp = m.surface_point(t.tri, b, t.shape as u32);
    let e = &s.emitters[s.shapes[t.shape].emitter.expect("an emitter") as usize];
    e.pdf(&s.shapes, probe.ref_p, &sp, probe.mode) as f64
}

/// Barycentrics (b1, b2) where the ray p + t d meets the triangle's plane (f64, clamped into
/// the triangle: the quadrature's nodes lie inside it up to rounding).
fn barycentrics(p: DVec3, d: DVec3, v: [Vec3; 3]) -> Option<Vec2> {
    let v = v.map(|x| x.as_dvec3());
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let n = e1.cross(e2);
    let denom = n.dot(d);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(v[0] - p) / denom;
    if !(t > 0.0) {
        return None;
    }
    let x = p + d * t - v[0];
    let inv = 1.0 / n.length_squared();
    let b1 = (x.cross(e2).dot(n) * inv).clamp(0.0, 1.0);
    let b2 = (e1.cross(x).dot(n) * inv).clamp(0.0, 1.0 - b1);
    Some(Vec2::new(b1 as f32, b2 as f32))
}

/// The window for the probe's lights `tris` ([`light_triangles`]): axis their common plane's
/// normal when they are coplanar, else their mean direction; None when there are none or a
/// corner lies within [`MIN_COS`] of the window's plane.
pub fn window(probe: &LightProbe, tris: &[LightTriangle], resolution: usize) -> Option<Tangent> {
    if tris.is_empty() {
        return None;
    }
    let p = probe.ref_p.as_dvec3();
    let dirs: Vec<DVec3> = tris
        .iter()
        .flat_map(|t| t.v.map(|v| (v.as_dvec3() - p).normalize()))
        .collect();
    // In the lights' own plane's window any corner in front will do (the projection is an
    // affine copy of the plane); about another axis the cells must not stretch without bound.
    let (axis, min_cos) = match common_plane(tris, p) {
        Some(n) => (n, 0.0),
        None => (probe.extent().0, MIN_COS),
    };
    if !axis.is_finite() || dirs.iter().any(|d| !(d.dot(axis) > min_cos)) {
        return None;
    }
    Some(Tangent::fit(axis, &dirs, resolution))
}

/// The normal of the plane holding every triangle, towards it from `p`; None if they are not
/// coplanar (to 1e-6 of their size) or `p` lies in it.
fn common_plane(tris: &[LightTriangle], p: DVec3) -> Option<DVec3> {
    let first = tris.first()?;
    let v = first.v.map(|x| x.as_dvec3());
    let n = (v[1] - v[0]).cross(v[2] - v[0]).try_normalize()?;
    let size = tris
        .iter()
        .flat_map(|t| t.v)
        .map(|x| (x.as_dvec3() - v[0]).length())
        .fold(0.0, f64::max);
    let flat = tris
        .iter()
        .flat_map(|t| t.v)
        .all(|x| (x.as_dvec3() - v[0]).dot(n).abs() <= 1e-6 * size.max(1e-30));
    let h = (v[0] - p).dot(n);
    (flat && h != 0.0).then(|| n * h.signum())
}

/// Each cell's integral of the probe's direction density over the window `w`, where
/// `density(triangle, d)` is the solid-angle density through one triangle (its pmf included);
/// None when a triangle's corner is not in front of the window.
pub fn cell_masses(
    w: &Tangent,
    tris: &[LightTriangle],
    ref_p: Vec3,
    density: &dyn Fn(&LightTriangle, Vec3) -> f64,
) -> Option<Grid> {
    use crate::stats::Domain;
    let (cols, rows) = w.resolution();
    let ([x0, x1], [y0, y1]) = w.bounds();
    let (du, dv) = ((x1 - x0) / cols as f64, (y1 - y0) / rows as f64);
    let mut grid = Grid::new(cols, rows);
    let p = ref_p.as_dvec3();
    let n = w.axis();
    for t in tris {
        let mut q = [[0.0; 2]; 3];
        for (k, v) in t.v.iter().enumerate() {
            q[k] = w.project((v.as_dvec3() - p).normalize())?;
        }
        let area2 =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
        if area2 == 0.0 {
            continue; // seen edge-on: no solid angle
        }
        // The density on the window's plane: solid-angle density times cos³.
        let f = |x: f64, y: f64| {
            let d = w.direction(x, y);
            let c = d.dot(n);
            density(t, d.as_vec3()) * c * c * c
        };
        let lo = |a: f64, o: f64, step: f64, k: usize| {
            (((a - o) / step).floor().max(0.0) as usize).min(k - 1)
        };
        let xs = q.map(|v| v[0]);
        let ys = q.map(|v| v[1]);
        let min = |a: [f64; 3]| a[0].min(a[1]).min(a[2]);
        let max = |a: [f64; 3]| a[0].max(a[1]).max(a[2]);
        let (c0, c1) = (lo(min(xs), x0, du, cols), lo(max(xs), x0, du, cols));
        let (r0, r1) = (lo(min(ys), y0, dv, rows), lo(max(ys), y0, dv, rows));
        for r in r0..=r1 {
            for c in c0..=c1 {
                let rect = [
                    x0 + c as f64 * du,
                    x0 + (c + 1) as f64 * du,
                    y0 + r as f64 * dv,
                    y0 + (r + 1) as f64 * dv,
                ];
                let poly = clip(&q, rect);
                if poly.len() >= 3 {
                    grid.data[r * cols + c] += piece_mass(w, t, p, &poly, &f, &|d| density(t, d));
                }
            }
        }
    }
    Some(grid)
}

/// The probability of the window polygon `poly` (inside triangle `t`'s projection, seen from
/// `p`). A light sampler's density is usually constant per unit solid angle (solid-angle
/// sampling) or per unit light area (area sampling), and then peaks on the window where no
/// node may fall: a hemisphere-wide light sampled in solid angle is a spike of width 1 in a
/// window 1e6 wide. So the density is first read at the polygon's corners and centroid in
/// both measures; if one of them is constant there, the mass is that constant times the
/// polygon's exact solid angle or light area. Otherwise the window density `f` is
/// integrated by the adaptive rule.
fn piece_mass(
    w: &Tangent,
    t: &LightTriangle,
    p: DVec3,
    poly: &[[f64; 2]],
    f: &impl Fn(f64, f64) -> f64,
    density: &dyn Fn(Vec3) -> f64,
) -> f64 {
    let dirs: Vec<DVec3> = poly.iter().map(|v| w.direction(v[0], v[1])).collect();
    let k = poly.len() as f64;
    let centre = poly
        .iter()
        .fold([0.0, 0.0], |a, v| [a[0] + v[0] / k, a[1] + v[1] / k]);
    let mut nodes = dirs.clone();
    nodes.push(w.direction(centre[0], centre[1]));
    let v = t.v.map(|x| x.as_dvec3() - p);
    let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    let h = v[0].dot(normal);
    // Where the direction d meets the light's plane, relative to p.
    let on_plane = |d: DVec3| d * (h / d.dot(normal));
    let per_sr: Vec<f64> = nodes.iter().map(|d| density(d.as_vec3())).collect();
    let per_area: Vec<f64> = nodes
        .iter()
        .zip(&per_sr)
        .map(|(d, s)| {
            let x = on_plane(*d);
            s * d.dot(normal).abs() / x.length_squared()
        })
        .collect();
    let flat = |v: &[f64]| {
        let (a, b) = v
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(*x), b.max(*x)));
        a >= 0.0 && b - a <= 1e-5 * b
    };
    if flat(&per_sr) {
        let mean = per_sr.iter().sum::<f64>() / per_sr.len() as f64;
        return mean * spherical_polygon_area(&dirs);
    }
    if flat(&per_area) {
        let mean = per_area.iter().sum::<f64>() / per_area.len() as f64;
        let pts: Vec<DVec3> = dirs.iter().map(|d| on_plane(*d)).collect();
        return mean * polygon_area(&pts);
    }
    (1..poly.len() - 1)
        .map(|i| {
            let piece = [poly[0], poly[i], poly[i + 1]];
            adapt(f, piece, rule(f, piece), MAX_DEPTH)
        })
        .sum()
}

/// The solid angle of the convex spherical polygon with unit corners `d` (a fan of
/// Van Oosterom-Strackee triangles).
fn spherical_polygon_area(d: &[DVec3]) -> f64 {
    (1..d.len() - 1)
        .map(|i| {
            let (a, b, c) = (d[0], d[i], d[i + 1]);
            let num = a.dot(b.cross(c)).abs();
            let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
            2.0 * num.atan2(den)
        })
        .sum()
}

/// The area of the planar polygon with corners `pts`.
fn polygon_area(pts: &[DVec3]) -> f64 {
    (1..pts.len() - 1)
        .map(|i| 0.5 * (pts[i] - pts[0]).cross(pts[i + 1] - pts[0]).length())
        .sum()
}

/// The polygon `poly` clipped to the rectangle [x0, x1] x [y0, y1] (Sutherland-Hodgman).
pub fn clip(poly: &[[f64; 2]], [x0, x1, y0, y1]: [f64; 4]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = poly.to_vec();
    // Each edge as (axis, bound, keep the side above it).
    for (axis, bound, above) in [(0, x0, true), (0, x1, false), (1, y0, true), (1, y1, false)] {
        let inside = |p: &[f64; 2]| {
            if above {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        let input = std::mem::take(&mut out);
        for (i, b) in input.iter().enumerate() {
            let a = &input[(i + input.len() - 1) % input.len()];
            let cross = |a: &[f64; 2], b: &[f64; 2]| {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                let mut p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                p[axis] = bound;
                p
            };
            match (inside(a), inside(b)) {
                (true, true) => out.push(*b),
                (true, false) => out.push(cross(a, b)),
                (false, true) => {
                    out.push(cross(a, b));
                    out.push(*b);
                }
                (false, false) => {}
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

/// Dunavant's 7-point rule (exact for degree 5): barycentric nodes and weights.
const RULE: [([f64; 3], f64); 7] = {
    const A1: f64 = 0.059_715_871_789_769_8;
    const B1: f64 = 0.470_142_064_105_115_1;
    const A2: f64 = 0.797_426_985_353_087_3;
    const B2: f64 = 0.101_286_507_323_456_3;
    const W1: f64 = 0.132_394_152_788_506_2;
    const W2: f64 = 0.125_939_180_544_827_2;
    [
        ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
        ([A1, B1, B1], W1),
        ([B1, A1, B1], W1),
        ([B1, B1, A1], W1),
        ([A2, B2, B2], W2),
        ([B2, A2, B2], W2),
        ([B2, B2, A2], W2),
    ]
};

fn rule(f: &impl Fn(f64, f64) -> f64, t: [[f64; 2]; 3]) -> f64 {
    let area = 0.5
        * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
            .abs();
    if area == 0.0 {
        return 0.0;
    }
    let s: f64 = RULE
        .iter()
        .map(|(b, w)| {
            let x = b[0] * t[0][0] + b[1] * t[1][0] + b[2] * t[2][0];
            let y = b[0] * t[0][1] + b[1] * t[1][1] + b[2] * t[2][1];
            w * f(x, y)
        })
        .sum();
    s * area
}

/// The rule on the triangle's four midpoint children, recursing into them until the sum
/// agrees with the parent's value to 1e-7 of it.
fn adapt(f: &impl Fn(f64, f64) -> f64, t: [[f64; 2]; 3], whole: f64, depth: u32) -> f64 {
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let (m01, m12, m20) = (mid(t[0], t[1]), mid(t[1], t[2]), mid(t[2], t[0]));
    let kids = [
        [t[0], m01, m20],
        [m01, t[1], m12],
        [m20, m12, t[2]],
        [m01, m12, m20],
    ];
    let q = kids.map(|k| rule(f, k));
    let sum: f64 = q.iter().sum();
    if depth == 0 || (sum - whole).abs() <= 1e-7 * sum.abs().max(1e-300) {
        return sum;
    }
    kids.iter()
        .zip(q)
        .map(|(k, qk)| adapt(f, *k, qk, depth - 1))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_the_part_inside_the_rectangle() {
        let tri = [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]];
        let area = |p: &[[f64; 2]]| {
            0.5 * (0..p.len())
                .map(|i| {
                    let (a, b) = (p[i], p[(i + 1) % p.len()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
                .abs()
        };
        assert_eq!(area(&clip(&tri, [0.0, 1.0, 0.0, 1.0])), 1.0);
        assert!((area(&clip(&tri, [1.0, 3.0, 1.0, 3.0])) - 2.0).abs() < 1e-12);
        assert!(clip(&tri, [5.0, 6.0, 0.0, 1.0]).is_empty());
        // The four quadrants of a square around the triangle add up to it.
        let total: f64 = [
            [0.0, 2.0, 0.0, 2.0],
            [2.0, 4.0, 0.0, 2.0],
            [0.0, 2.0, 2.0, 4.0],
            [2.0, 4.0, 2.0, 4.0],
        ]
        .iter()
        .map(|r| area(&clip(&tri, *r)))
        .sum();
        assert!((total - 8.0).abs() < 1e-12, "{total}");
    }

    #[test]
    fn the_rule_is_exact_for_quintics_and_adapts_to_steep_densities() {
        let t = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // x^5 over the unit right triangle: 1/42.
        let q = rule(&|x: f64, _| x.powi(5), t);
        assert!((q - 1.0 / 42.0).abs() < 1e-15, "{q}");
        // 1/(x + 0.001)^3 is far from polynomial; adapt gets within 1e-6. The integral over
        // the triangle is int_0^1 (1 - x)/(x + e)^3 dx.
        let e: f64 = 1e-3;
        let f = |x: f64, _y: f64| 1.0 / (x + e).powi(3);
        let exact = {
            // (1 - x)/(x+e)^3 = (1 + e)/(x+e)^3 - 1/(x+e)^2
            let a = (1.0 + e) * 0.5 * (1.0 / e.powi(2) - 1.0 / (1.0 + e).powi(2));
            let b = 1.0 / e - 1.0 / (1.0 + e);
            a - b
        };
        let got = adapt(&f, t, rule(&f, t), 12);
        assert!((got / exact - 1.0).abs() < 1e-6, "{got} vs {exact}");
    }
}
