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

/// Nori's triangle-light tests (wjakob/nori, scenes/pa4/tests/test-mesh.xml, emitters
/// polylum1..5.obj; generator scenes/pa4/tests/meshes/polylum.py). Receiver: the floor
/// y = 0 (albedo 0.5) at the origin, normal +y, seen by a 1x1-pixel camera looking down from
/// (0, 0.01, 0). Each emitter is one triangle of unit radiance in y > 0, wound so that its
/// right-hand normal faces the origin. Reference: outgoing radiance of the floor.
pub const NORI_TRIANGLE_TESTS: [([[f64; 3]; 3], f64); 5] = [
    (
        [
            [-0.443432, 0.596366, 0.495985],
            [-0.320397, 0.0677699, -0.229359],
            [0.0341197, 0.11415, -0.343049],
        ],
        0.0898394,
    ),
    (
        [
            [0.461963, 0.397843, 0.412747],
            [-0.0381582, 0.851323, -0.156872],
            [0.195443, 0.891957, -0.260672],
        ],
        0.02292,
    ),
    (
        [
            [0.100871, 0.289075, -0.422609],
            [-0.308386, 0.629587, 0.423966],
            [-0.373132, 0.237287, 0.351592],
        ],
        0.0534198,
    ),
    (
        [
            [-0.17575, 0.639397, 0.151268],
            [0.318604, 0.732996, 0.459771],
            [0.139095, 0.294498, 0.478556],
        ],
        0.0205314,
    ),
    (
        [
            [-0.17487, 0.447916, 0.367201],
            [-0.405259, 0.249607, -0.354079],
            [0.356029, 0.0918984, -0.132271],
        ],
        0.26174,
    ),
];

#[cfg(test)]
#[path = "analytic_tests.rs"]
mod tests;
