//! BSDF sampling against pdf(), at incident directions from normal to grazing, with every
//! sample's weight checked against eval / pdf (and its pdf against pdf()).
//!
//! Outgoing directions are tested on the whole sphere of the local frame, or for narrow
//! reflection lobes (roughness below 0.2) in a window fitted to the lobe
//! ([`super::lobe`]). Materials come from [`materials`]: add new BSDFs there and every
//! incident direction is tested.

use super::checks::WeightCheck;
use super::lobe::{reflection_window, run_windowed};
use super::{Case, CaseConfig, Outcome};
use crate::bsdf::{
    BsdfKind, Diffuse, Material, NoriMicrofacet, Plastic, RoughConductor, RoughPlastic,
};
use crate::math::Rgb;
use crate::rng::Rng;
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
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

/// A material under test and the roughness of its reflection lobe, if it has one narrow
/// enough to need a window.
#[derive(Clone, Debug)]
pub struct Entry {
    pub name: String,
    pub material: Material,
    pub lobe: Option<(f32, f32)>,
}

fn entry(name: String, kind: BsdfKind, two_sided: bool, lobe: Option<(f32, f32)>) -> Entry {
    Entry {
        name,
        material: Material { kind, two_sided },
        lobe,
    }
}

/// Roughnesses of the microfacet cases: the range 1e-3 .. 1, and one anisotropic.
pub const ROUGHNESS: [(f32, f32); 6] = [
    (1e-3, 1e-3),
    (1e-2, 1e-2),
    (0.1, 0.1),
    (0.5, 0.5),
    (1.0, 1.0),
    (0.05, 0.4),
];

pub fn alpha_name(a: (f32, f32)) -> String {
    if a.0 == a.1 {
        format!("a{}", a.0)
    } else {
        format!("a{}x{}", a.0, a.1)
    }
}

/// Materials under test. Delta BSDFs (mirror, smooth conductor, dielectric) have no
/// density to test; add any new non-delta BSDF here.
pub fn materials() -> Vec<Entry> {
    let diffuse = Diffuse {
        reflectance: Rgb::new(0.2, 0.5, 0.9),
    };
    let mut v = vec![
        entry("diffuse".into(), BsdfKind::Diffuse(diffuse), false, None),
        entry(
            "diffuse-twosided".into(),
            BsdfKind::Diffuse(diffuse),
            true,
            None,
        ),
    ];
    for d in [
        MicrofacetDistribution::Beckmann,
        MicrofacetDistribution::Ggx,
    ] {
        let dn = format!("{d:?}").to_lowercase();
        for a in ROUGHNESS {
            for visible in [true, false] {
                let kind = BsdfKind::RoughConductor(RoughConductor {
                    mf: Microfacet::new(d, a.0, a.1),
                    sample_visible: visible,
                    // Gold: coloured Fresnel, so eval's channels differ.
                    eta: Rgb::new(0.143119, 0.374957, 1.44248),
                    k: Rgb::new(3.98316, 2.38572, 1.60322),
                    specular_reflectance: Rgb::ONE,
                });
                let how = if visible { "vndf" } else { "dcos" };
                let name = format!("roughconductor-{dn}-{}-{how}", alpha_name(a));
                v.push(entry(name, kind, false, Some(a)));
            }
        }
    }
    // Nori's microfacet mixes a diffuse lobe into every direction; in a window the diffuse
    // mass outside it goes to the lost category.
    for a in [1e-2f32, 0.1, 0.5] {
        let kind = BsdfKind::NoriMicrofacet(NoriMicrofacet::new(a, 1.5, 1.0, Rgb::splat(0.3)));
        v.push(entry(
            format!("nori-microfacet-a{a}"),
            kind,
            false,
            Some((a, a)),
        ));
    }
    // Plastic's coating is a delta lobe (counted as lost); the diffuse lobe's mass is its
    // probability, which depends on the incidence through the Fresnel term.
    for (eta, nonlinear) in [(1.49f32, false), (2.0, true)] {
        let kind = BsdfKind::Plastic(Plastic::new(
            eta,
            Rgb::new(0.2, 0.5, 0.9),
            Rgb::splat(0.8),
            nonlinear,
        ));
        v.push(entry(format!("plastic-eta{eta}"), kind, false, None));
    }
    // Rough plastic: a glossy coating over the diffuse base, both with a density.
    for (d, a, visible) in [
        (MicrofacetDistribution::Beckmann, 0.05f32, true),
        (MicrofacetDistribution::Ggx, 0.3, false),
    ] {
        let dn = format!("{d:?}").to_lowercase();
        let kind = BsdfKind::RoughPlastic(RoughPlastic::new(
            Microfacet::new(d, a, a),
            visible,
            1.49,
            Rgb::new(0.2, 0.5, 0.9),
            Rgb::splat(0.8),
            false,
        ));
        let name = format!("roughplastic-{dn}-a{a}");
        v.push(entry(name, kind, false, Some((a, a))));
    }
    v
}

/// Chi-square of `m.sample(wi)` against `m.pdf(wi, .)` plus the integral and weight checks.
/// Delta samples are not directions with a density: they are counted as lost and their
/// weight is not checked.
pub fn run_bsdf(
    name: &str,
    m: &Material,
    lobe: Option<(f32, f32)>,
    wi: Vec3,
    cfg: &CaseConfig,
) -> Outcome {
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
    let window = lobe.and_then(|a| reflection_window(wi, a, cfg.resolution));
    let mut out = run_windowed(name, window, sampler, pdf, cfg, vec![]);
    // A sampler that (rightly) never succeeds has nothing to check per sample.
    let w = weights.into_inner();
    if w.checked > 0 || out.chi2.lost < out.chi2.samples {
        out.checks.push(w.check());
    }
    out
}

pub fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for e in materials() {
        for (wname, wi) in incident() {
            let name = format!("bsdf/{}-{wname}", e.name);
            let about = format!("{} sampled for wi = {wi}", e.name);
            let (m, lobe) = (e.material.clone(), e.lobe);
            let label = name.clone();
            out.push(Case::new(name, about, move |cfg| {
                run_bsdf(&label, &m, lobe, wi, cfg)
            }));
        }
    }
    out
}
