//! Discrete distributions against their pmfs: the alias table, the emitter choice (uniform
//! and by power), a mesh light's triangle choice by area, and a dielectric's choice between
//! reflection and refraction.
//!
//! The test is the same Pearson statistic as for continuous cases (Nori's pooling included),
//! on one category per index; an index drawn whose pmf is 0 fails at once. The expected pmf
//! is computed here independently (from weights, powers, areas), not read back from the
//! table, so a table that stores a wrong pmf is caught too.

use super::{emitters, Case, CaseConfig, Outcome};
use crate::bsdf::{BsdfKind, Dielectric, Material};
use crate::emitter::{AreaLight, Emitter, EmitterSelection, EmitterSelector};
use crate::geometry::ShapeKind;
use crate::math::luminance;
use crate::rng::Rng;
use crate::sampling::AliasTable;
use crate::stats::chi2::{chi2_sf, pearson};
use crate::stats::{Chi2Result, Grid, Verdict};

/// Draws `cfg.samples` indices and tests their frequencies against `pmf` at `cfg.alpha`.
pub fn discrete_test(
    name: &str,
    pmf: &[f64],
    mut sampler: impl FnMut(&mut Rng) -> usize,
    cfg: &CaseConfig,
) -> Outcome {
    let k = pmf.len();
    let n = cfg.samples;
    let total: f64 = pmf.iter().sum();
    let mut observed = Grid::new(k, 1);
    let mut rng = Rng::new(cfg.seed, 0);
    let mut outside = 0u64;
    for _ in 0..n {
        let i = sampler(&mut rng);
        if i < k {
            observed.data[i] += 1.0;
        } else {
            outside += 1;
        }
    }
    let expected = Grid {
        data: pmf.iter().map(|p| p * n as f64).collect(),
        ..Grid::new(k, 1)
    };
    let mut r = Chi2Result {
        domain: "indices",
        axes: ["index", ""],
        statistic: f64::NAN,
        dof: 0,
        p_value: 0.0,
        threshold: cfg.alpha,
        verdict: Verdict::Fail,
        reason: String::new(),
        observed,
        expected,
        samples: n,
        lost: 0,
        outside,
        pdf_integral: total,
    };
    let impossible = (0..k).find(|&i| pmf[i] == 0.0 && r.observed.data[i] > 0.0);
    if outside > 0 {
        r.reason = format!("{outside} indices beyond the {k} entries");
    } else if let Some(i) = impossible {
        r.reason = format!(
            "index {i} drawn {} times but its pmf is 0",
            r.observed.data[i]
        );
    } else if (total - 1.0).abs() > 1e-9 {
        r.reason = format!("pmf sums to {total}, not 1");
    } else {
        let mut cells: Vec<(f64, f64)> = (0..k)
            .filter(|&i| pmf[i] > 0.0)
            .map(|i| (r.observed.data[i], r.expected.data[i]))
            .collect();
        match pearson(&mut cells, 5.0) {
            // One possible index (total internal reflection), always drawn: nothing to test.
            None if cells.len() == 1 => {
                r.verdict = Verdict::Pass;
                r.p_value = 1.0;
                r.reason = "a single possible index, always drawn".into();
            }
            None => r.reason = "fewer than two usable categories".into(),
            Some(p) => {
                r.statistic = p.statistic;
                r.dof = p.dof;
                r.p_value = chi2_sf(p.statistic, p.dof);
                let summary = format!(
                    "chi2 = {:.2}, dof = {}, p = {:.4e} vs threshold {:.4e}",
                    p.statistic, p.dof, r.p_value, cfg.alpha
                );
                if r.p_value >= cfg.alpha {
                    r.verdict = Verdict::Pass;
                    r.reason = summary;
                } else {
                    r.reason = format!("rejected: frequencies do not match the pmf ({summary})");
                }
            }
        }
    }
    Outcome {
        name: name.to_string(),
        chi2: r,
        checks: vec![],
    }
}

fn normalised(w: &[f64]) -> Vec<f64> {
    let t: f64 = w.iter().sum();
    w.iter().map(|x| x / t).collect()
}

/// Weights spanning four orders of magnitude, with a zero.
pub const ALIAS_WEIGHTS: [f64; 8] = [1.0, 0.0, 3.0, 0.5, 10.0, 2.5, 1e-3, 7.0];

fn emitter_choice(selection: EmitterSelection) -> Case {
    let scene = emitters::build(emitters::scene_lights());
    let label = selection.name();
    let selector = EmitterSelector::new(&scene.emitters, &scene.shapes, selection);
    // The expected weights from first principles where the rule has them; a newly
    // registered rule is checked against its own pmf (consistency of sample and pmf).
    let weights: Vec<f64> = match selection {
        EmitterSelection::Uniform => vec![1.0; scene.emitters.len()],
        EmitterSelection::Power => scene
            .emitters
            .iter()
            .map(|e| match e {
                // pi * area * luminance, area recomputed from the geometry.
                Emitter::Area(a) => {
                    std::f64::consts::PI * shape_area(&scene, a) * luminance(a.radiance) as f64
                }
                Emitter::Point(p) => 4.0 * std::f64::consts::PI * luminance(p.intensity) as f64,
            })
            .collect(),
        _ => (0..scene.emitters.len())
            .map(|i| selector.pmf(glam::Vec3::ZERO, glam::Vec3::ZERO, i) as f64)
            .collect(),
    };
    let name = format!("discrete/emitter-choice-{label}");
    let pmf = normalised(&weights);
    Case::new(
        name.clone(),
        format!("EmitterSelector ({label}) over the five-light scene"),
        move |cfg| {
            discrete_test(
                &name,
                &pmf,
                |r| {
                    selector
                        .sample(glam::Vec3::ZERO, glam::Vec3::ZERO, r.next_f32())
                        .map_or(usize::MAX, |s| s.0)
                },
                cfg,
            )
        },
    )
}

fn shape_area(scene: &crate::scene::Scene, a: &AreaLight) -> f64 {
    match &scene.shapes[a.shape as usize].kind {
        ShapeKind::Mesh(m) => (0..m.indices.len())
            .map(|t| triangle_area_f64(m.vertices(t)))
            .sum(),
        ShapeKind::Sphere(s) => 4.0 * std::f64::consts::PI * (s.radius as f64).powi(2),
    }
}

fn triangle_area_f64(v: [glam::Vec3; 3]) -> f64 {
    let [a, b, c] = v.map(|p| p.as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

fn triangle_choice() -> Case {
    let scene = emitters::build(vec![emitters::unequal_mesh()]);
    let Emitter::Area(light) = scene.emitters[0].clone() else {
        unreachable!("the fixture is an area light")
    };
    let ShapeKind::Mesh(m) = &scene.shapes[0].kind else {
        unreachable!("the fixture is a mesh")
    };
    let pmf = normalised(
        &(0..m.indices.len())
            .map(|t| triangle_area_f64(m.vertices(t)))
            .collect::<Vec<_>>(),
    );
    let name = "discrete/triangle-by-area";
    Case::new(
        name,
        "a mesh light's triangle choice against triangle areas",
        move |cfg| {
            let table = light
                .triangles
                .as_ref()
                .expect("mesh lights have a triangle table");
            discrete_test(name, &pmf, |r| table.sample(r.next_f32()), cfg)
        },
    )
}

/// Unpolarised Fresnel reflectance of a smooth dielectric, written out independently of
/// `bsdf::fresnel` in f64: `cos_i` < 0 means from inside (relative index `eta` below).
fn fresnel_reflectance(cos_i: f64, eta: f64) -> f64 {
    let (n1, n2, c) = if cos_i > 0.0 {
        (1.0, eta, cos_i)
    } else {
        (eta, 1.0, -cos_i)
    };
    let sin_t = n1 / n2 * (1.0 - c * c).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * c - n2 * cos_t) / (n1 * c + n2 * cos_t);
    let rp = (n2 * c - n1 * cos_t) / (n2 * c + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The dielectric's choice between its two delta lobes (index 0 reflection, 1 refraction)
/// against the Fresnel reflectance, from outside (normal, oblique, grazing) and inside
/// (partial reflection, and total internal reflection).
fn dielectric_lobes() -> Vec<Case> {
    let eta = 1.5046f32 / 1.000277;
    let views = [
        ("normal", 1.0f32),
        ("oblique", 0.5),
        ("grazing", 0.01),
        ("inside", -0.9),
        ("inside-tir", -0.5),
    ];
    views
        .into_iter()
        .map(|(label, c)| {
            let name = format!("discrete/dielectric-lobes-{label}");
            let wi = glam::Vec3::new((1.0 - c * c).max(0.0).sqrt(), 0.0, c);
            let r = fresnel_reflectance(c as f64, eta as f64);
            let pmf = vec![r, 1.0 - r];
            let m = Material {
                kind: BsdfKind::Dielectric(Dielectric { eta }),
                two_sided: false,
            };
            let about = format!("reflect vs refract for cos(theta_i) = {c} against Fresnel");
            let label = name.clone();
            Case::new(name, about, move |cfg| {
                let lobe = |rng: &mut Rng| match m.sample(wi, rng.next_f32(), rng.next_2d()) {
                    Some(s) if s.wo.z * wi.z > 0.0 => 0,
                    Some(_) => 1,
                    None => usize::MAX,
                };
                discrete_test(&label, &pmf, lobe, cfg)
            })
        })
        .collect()
}

/// The shading-point-dependent choices (exhaustive, the light tree) over the five-light scene,
/// at two shading points: their choices against their own pmfs, with a last bin for choosing
/// nothing (the pmfs need not sum to 1).
fn point_choices() -> Vec<Case> {
    use glam::Vec3;
    let points = [
        ("origin-up", Vec3::ZERO, Vec3::Z),
        ("off-centre", Vec3::new(0.3, -0.2, 0.1), Vec3::ZERO),
    ];
    let mut out = Vec::new();
    let at_point = crate::emitter::RULES
        .iter()
        .map(|r| r.value)
        .filter(|r| r.at_point());
    for selection in at_point {
        for (view, p, n) in points {
            let scene = emitters::build(emitters::scene_lights());
            let selector = EmitterSelector::new(&scene.emitters, &scene.shapes, selection);
            let k = scene.emitters.len();
            let mut pmf: Vec<f64> = (0..k).map(|i| selector.pmf(p, n, i) as f64).collect();
            pmf.push(selector.none_probability(p, n));
            // The pmfs are f32: their sum is 1 to about 1e-7 (the unit tests check 1e-6),
            // which this test's sum check (for pmfs computed in f64) would take for an error.
            let total: f64 = pmf.iter().sum();
            assert!(
                (total - 1.0).abs() < 1e-6,
                "{}: pmfs sum to {total}",
                selection.name()
            );
            pmf.iter_mut().for_each(|q| *q /= total);
            let name = format!("discrete/emitter-choice-{}-{view}", selection.name());
            out.push(Case::new(
                name.clone(),
                format!(
                    "EmitterSelector ({}) over the five-light scene at {p} (normal {n}), a bin for none",
                    selection.name()
                ),
                move |cfg| {
                    discrete_test(
                        &name,
                        &pmf,
                        |r| selector.sample(p, n, r.next_f32()).map_or(k, |s| s.0),
                        cfg,
                    )
                },
            ));
        }
    }
    out
}

pub fn cases() -> Vec<Case> {
    let pmf = normalised(&ALIAS_WEIGHTS);
    let table = AliasTable::new(&ALIAS_WEIGHTS).expect("positive weights");
    vec![Case::new(
        "discrete/alias-table",
        "Walker/Vose alias table over eight weights (one zero)",
        move |cfg| {
            discrete_test(
                "discrete/alias-table",
                &pmf,
                |r| table.sample(r.next_f32()),
                cfg,
            )
        },
    )]
    .into_iter()
    .chain(
        // Every registered rule blind to the shading point; the others at points below.
        crate::emitter::RULES
            .iter()
            .filter(|r| !r.value.at_point())
            .map(|r| emitter_choice(r.value)),
    )
    .chain([triangle_choice()])
    .chain(point_choices())
    .chain(dielectric_lobes())
    .collect()
}
