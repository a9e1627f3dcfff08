//! Testing narrow lobes (microfacet roughness down to 1e-3) in a window fitted to them.
//!
//! On the whole sphere a lobe of width 1e-3 falls into one cell. Instead the test looks
//! through a tangent-plane window holding the lobe's core, and every sample outside it counts
//! as lost: the lost category's expected count is then N (1 - pdf mass inside the window),
//! so the tail outside is still accounted for, as long as the pdf integrates to the
//! sampler's success rate over the whole sphere (which the BSDF's own tests check).

use super::tangent::Tangent;
use super::CaseConfig;
use super::{run_continuous, Check, Outcome};
use crate::rng::Rng;
use glam::{DVec3, Vec3};

/// Lobes with both roughnesses above this are tested on the whole sphere.
pub const WINDOW_BELOW_ALPHA: f32 = 0.2;

/// Refinement depth in windows (cells / 2^6 at the support's edges).
pub const WINDOW_MAX_DEPTH: u32 = 6;

/// Slopes out to this many alphas are inside the window (Beckmann: all but e^-16 of the
/// normals; GGX: all but 1/17, its tail then goes to the lost category).
const SLOPES: f64 = 4.0;

/// Microfacet normals with slopes `SLOPES * alpha` in eight azimuths.
fn rim_normals(alpha: (f32, f32)) -> Vec<DVec3> {
    (0..8)
        .map(|k| {
            let phi = k as f64 * std::f64::consts::FRAC_PI_4;
            let (x, y) = (
                SLOPES * alpha.0 as f64 * phi.cos(),
                SLOPES * alpha.1 as f64 * phi.sin(),
            );
            DVec3::new(-x, -y, 1.0).normalize()
        })
        .collect()
}

/// Whether a distribution of roughness `alpha` is tested in a window (see [`normal_window`]).
pub fn narrow(alpha: (f32, f32)) -> bool {
    alpha.0.max(alpha.1) < WINDOW_BELOW_ALPHA
}

/// Window around +z holding the normals of a distribution of roughness `alpha`.
pub fn normal_window(alpha: (f32, f32), resolution: usize) -> Option<Tangent> {
    narrow(alpha).then(|| Tangent::fit(DVec3::Z, &rim_normals(alpha), resolution))
}

/// Window around the mirror direction of `wi` holding the reflections of `wi` about the
/// normals of a distribution of roughness `alpha` (flattened at grazing incidence, which
/// the fit follows).
pub fn reflection_window(wi: Vec3, alpha: (f32, f32), resolution: usize) -> Option<Tangent> {
    if !narrow(alpha) || wi.z <= 0.0 {
        return None;
    }
    let wi = wi.as_dvec3().normalize();
    let axis = DVec3::new(-wi.x, -wi.y, wi.z);
    let dirs: Vec<DVec3> = rim_normals(alpha)
        .into_iter()
        .map(|m| 2.0 * wi.dot(m) * m - wi)
        .chain([axis])
        .collect();
    Some(Tangent::fit(axis, &dirs, resolution))
}

/// Tests `sampler` against `pdf` (solid angle) in `window`, or on the whole sphere.
pub fn run_windowed(
    name: &str,
    window: Option<Tangent>,
    sampler: impl Fn(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
    cfg: &CaseConfig,
    extra: Vec<Check>,
) -> Outcome {
    use crate::stats::Domain;
    match window {
        Some(w) => {
            let inside = |r: &mut Rng| sampler(r).filter(|d| w.locate(*d).is_ok());
            // A window a few 1e-5 rad across sits near the f32 resolution of directions: the
            // pdf is noisy at the finest scales and refinement to depth 8 never settles.
            let mut cfg = *cfg;
            cfg.integration.max_depth = cfg.integration.max_depth.min(WINDOW_MAX_DEPTH);
            run_continuous(name, &w, inside, w.plane_pdf(pdf), &cfg, extra)
        }
        None => run_continuous(name, &cfg.sphere(), sampler, pdf, cfg, extra),
    }
}
