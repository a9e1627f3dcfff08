//! Closed-form references for direct lighting tests: irradiance from a uniformly emitting
//! polygon (Lambert), and solid angles of triangles and spheres.
//!
//! Everything is f64: these values are what renders are judged against.

use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Why a closed form does not apply.
#[derive(Clone, Debug, PartialEq)]
pub enum AnalyticError {
    /// Fewer than three vertices.
    Degenerate,
    /// Vertex `index` lies below the receiver's tangent plane; Lambert's formula would
    /// count the hidden part with negative cosine, so it needs the polygon clipped first.
    BelowHorizon { index: usize, height: f64 },
}

impl std::fmt::Display for AnalyticError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AnalyticError::Degenerate => write!(f, "polygon needs at least three vertices"),
            AnalyticError::BelowHorizon { index, height } => write!(
                f,
                "vertex {index} is {height:e} below the receiver's tangent plane; clip the \
                 polygon to the horizon first"
            ),
        }
    }
}

impl std::error::Error for AnalyticError {}

/// Area-weighted normal by Newell's method (robust for slightly non-planar polygons); points
/// to the side from which the vertices appear counter-clockwise.
pub fn polygon_normal(verts: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (k, a) in verts.iter().enumerate() {
        let b = verts[(k + 1) % verts.len()];
        n += a.cross(b);
    }
    0.5 * n
}

/// Irradiance at `x` (surface normal `n`, unit) from a planar polygon of constant radiance
/// emitting on one side only: the side its vertices' counter-clockwise winding faces
/// (right-hand rule). Lambert's formula, E = L/2 * sum_k Theta_k (g_k . n), with Theta_k the
/// angle edge k subtends at x and g_k the unit normal of the plane through x and edge k.
///
/// Returns 0 when x is behind the emitting side (or in its plane). The formula assumes the
/// whole polygon lies on or above x's tangent plane; otherwise this returns
/// [`AnalyticError::BelowHorizon`] rather than a wrong number.
pub fn polygon_irradiance(
    x: DVec3,
    n: DVec3,
    verts: &[DVec3],
    radiance: f64,
) -> Result<f64, AnalyticError> {
    if verts.len() < 3 {
        return Err(AnalyticError::Degenerate);
    }
    let scale = verts.iter().map(|v| (*v - x).length()).fold(0.0, f64::max);
    for (index, v) in verts.iter().enumerate() {
        let height = (*v - x).dot(n);
        if height < -1e-12 * scale {
            return Err(AnalyticError::BelowHorizon {
                index,
                height: -height,
            });
        }
    }
    if (x - verts[0]).dot(polygon_normal(verts)) <= 0.0 {
        return Ok(0.0);
    }
    let mut sum = 0.0;
    for k in 0..verts.len() {
        let a = verts[k] - x;
        let b = verts[(k + 1) % verts.len()] - x;
        let c = a.cross(b);
        let len = c.length();
        if len == 0.0 {
            continue; // x on the edge's line: the edge subtends no area.
        }
        let theta = len.atan2(a.dot(b));
        sum += theta * c.dot(n) / len;
    }
    // Seen from the emitting side the winding is counter-clockwise, so every a x b points
    // away from the polygon: the sum is negative for a visible emitter.
    Ok((-0.5 * radiance * sum).max(0.0))
}

/// Outgoing radiance of a Lambertian receiver lit with irradiance `e`.
pub fn diffuse_radiance(albedo: f64, e: f64) -> f64 {
    albedo / PI * e
}

/// Solid angle of triangle (a, b, c) seen from p (Van Oosterom & Strackee 1983),
/// in [0, 2 pi]; independent of winding.
pub fn triangle_solid_angle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (a, b, c) = (
        (a - p).normalize(),
        (b - p).normalize(),
        (c - p).normalize(),
    );
    let numer = a.dot(b.cross(c)).abs();
    let denom = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * numer.atan2(denom)
}

/// Solid angle of a cone of directions with half-angle theta: 2 pi (1 - cos theta).
pub fn cone_solid_angle(cos_theta: f64) -> f64 {
    TAU * (1.0 - cos_theta)
}

/// Solid angle a sphere subtends from p: the cap of directions that hit it,
/// 2 pi (1 - cos theta_max) with sin theta_max = radius / distance; 4 pi from inside.
pub fn sphere_cap_solid_angle(p: DVec3, center: DVec3, radius: f64) -> f64 {
    let d2 = (center - p).length_squared();
    let r2 = radius * radius;
    if d2 <= r2 {
        return 2.0 * TAU;
    }
    // 1 - cos = sin^2 / (1 + cos) avoids cancellation for distant, small spheres.
    let sin2 = r2 / d2;
    let cos = (1.0 - sin2).sqrt();
    TAU * sin2 / (1.0 + cos)
}

#[cfg(test)]
#[path = "analytic_tests.rs"]
mod tests;
