//! BSDF sampling against pdf(), at incident directions from normal to grazing, with every
//! sample's weight checked against eval / pdf (and its pdf against pdf()).
//!
//! Outgoing directions are tested on the whole sphere of the local frame. Materials come
//! from [`materials`]: add new BSDFs there and every incident direction is tested.

use super::checks::WeightCheck;
use super::{run_continuous, Case, CaseConfig, Outcome};
use crate::bsdf::{BsdfKind, Diffuse, Material};
use crate::math::Rgb;
use crate::rng::Rng;
use glam::Vec3;
use std::cell::RefCell;

/// Incident directions (name, wi) in the local frame: normal, 60 degrees, grazing at
/// cos(theta) = 0.01, and from below (where one-sided BSDFs must sample nothing).
pub fn incident() -> Vec<(&'static str, Vec3)> {
    let at = |c: f32, phi: f32| {
        let s = (1.0 - c * c).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    };
    vec![
        ("normal", at(1.0, 0.0)),
        ("oblique", at(0.5, 0.7)),
        ("grazing", at(0.01, 2.0)),
        ("below", at(-0.5, 4.0)),
    ]
}

/// Materials under test (name, material).
///
/// PLUG-IN POINT for the BSDFs of branch `wt-bsdf` (rough conductor with Beckmann/GGX,
/// roughness 1e-3 .. 1, visible-normal sampling on and off; Nori's microfacet): once they are
/// on main, add one entry per (BSDF, roughness). Lobes narrower than ~0.05 need a
/// tangent-plane window around the specular direction (see `warps::microfacet_cases`).
pub fn materials() -> Vec<(String, Material)> {
    let diffuse = Diffuse {
        reflectance: Rgb::new(0.2, 0.5, 0.9),
    };
    vec![
        (
            "diffuse".into(),
            Material {
                kind: BsdfKind::Diffuse(diffuse.clone()),
                two_sided: false,
            },
        ),
        (
            "diffuse-twosided".into(),
            Material {
                kind: BsdfKind::Diffuse(diffuse),
                two_sided: true,
            },
        ),
    ]
}

/// Chi-square of `m.sample(wi)` against `m.pdf(wi, .)` plus the integral and weight checks.
/// Delta samples are not directions with a density: they are counted as lost and their
/// weight is not checked.
pub fn run_bsdf(name: &str, m: &Material, wi: Vec3, cfg: &CaseConfig) -> Outcome {
    let weights = RefCell::new(WeightCheck::default());
    let sampler = |r: &mut Rng| {
        let s = m.sample(wi, r.next_f32(), r.next_2d())?;
        if s.delta {
            return None;
        }
        let eval = m.eval(wi, s.wo).max_element() as f64;
        weights.borrow_mut().record(
            s.weight.max_element() as f64,
            eval,
            s.pdf as f64,
            m.pdf(wi, s.wo) as f64,
        );
        Some(s.wo)
    };
    let pdf = |wo: Vec3| m.pdf(wi, wo) as f64;
    let mut out = run_continuous(name, &cfg.sphere(), sampler, pdf, cfg, vec![]);
    // A sampler that (rightly) never succeeds has nothing to check per sample.
    let w = weights.into_inner();
    if w.checked > 0 || out.chi2.lost < out.chi2.samples {
        out.checks.push(w.check());
    }
    out
}

pub fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for (mname, m) in materials() {
        for (wname, wi) in incident() {
            let name = format!("bsdf/{mname}-{wname}");
            let about = format!("{mname} sampled for wi = {wi}");
            let m = m.clone();
            let label = name.clone();
            out.push(Case::new(name, about, move |cfg| {
                run_bsdf(&label, &m, wi, cfg)
            }));
        }
    }
    out
}
