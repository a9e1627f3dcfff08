//! `directlab chi2 --scene SCENE.xml`: the cases of one scene. Every BSDF of the scene at its
//! own parameters, at the registry's incident directions (normal, oblique, grazing, below),
//! and the scene's light sampling (its emitter choice, pmf included, and light sampling mode)
//! seen from receiver points on its surfaces: the first hits of camera rays through five
//! points of the film.

use super::bsdfs::{incident, run_bsdf};
use super::emitters::run_probe;
use super::probe::LightProbe;
use super::Case;
use crate::emitter::{EmitterSelection, LightSampling};
use crate::rng::Rng;
use crate::scene::Scene;
use std::sync::Arc;

/// The largest count of emitter triangles whose light sampling is tested: the density of a
/// direction visits every one of them, for every cell of the chi-square grid.
pub const MAX_EMITTER_TRIANGLES: usize = 2000;

/// The scene's cases, and what was left out with the reason.
pub fn cases(
    scene: Arc<Scene>,
    selection: EmitterSelection,
    mode: LightSampling,
) -> (Vec<Case>, Vec<String>) {
    let mut out = Vec::new();
    let mut left = Vec::new();
    // A BSDF shared by many shapes (a grid of lights over one floor) is tested once.
    let mut distinct: Vec<usize> = Vec::new();
    let mut repeats = 0;
    for (k, m) in scene.materials.iter().enumerate() {
        let ty = m.kind.type_name();
        if distinct.iter().any(|&j| scene.materials[j] == *m) {
            repeats += 1;
            continue;
        }
        distinct.push(k);
        if m.kind.is_delta() {
            left.push(format!(
                "material {k} ({ty}): all-delta, it has no density to test"
            ));
            continue;
        }
        for (wname, wi) in incident() {
            let name = format!("scene/bsdf{k}-{ty}-{wname}");
            let about = format!("material {k} ({ty}) of the scene sampled for wi = {wi}");
            let (m, label) = (m.clone(), name.clone());
            out.push(Case::new(name, about, move |cfg| {
                run_bsdf(&label, &m, m.kind.glossy_lobe(), wi, cfg)
            }));
        }
    }
    if repeats > 0 {
        left.push(format!(
            "{repeats} material(s) with the same BSDF and parameters as one tested already"
        ));
    }
    let has_sphere_light = scene
        .shapes
        .iter()
        .any(|s| s.emitter.is_some() && matches!(s.kind, crate::geometry::ShapeKind::Sphere(_)));
    let triangles: usize = scene
        .shapes
        .iter()
        .filter(|s| s.emitter.is_some())
        .map(|s| match &s.kind {
            crate::geometry::ShapeKind::Mesh(m) => m.indices.len(),
            crate::geometry::ShapeKind::Sphere(_) => 1,
        })
        .sum();
    if scene.emitters.iter().any(|e| e.is_delta()) {
        left.push(
            "light sampling: the scene has point lights, whose directions have no density".into(),
        );
    } else if triangles > MAX_EMITTER_TRIANGLES {
        left.push(format!(
            "light sampling: {triangles} emitter triangles, more than the {MAX_EMITTER_TRIANGLES} \
             whose density the grid can afford"
        ));
    } else {
        let (probes, why) = receivers(&scene, selection, mode);
        left.extend(why);
        for (k, about, probe) in probes {
            let name = format!("scene/lights-{}-receiver{k}", selection.name());
            let label = name.clone();
            // Triangle lights are tested against exact cell masses in a window fitted to them
            // ([`super::exact`]). Spheres stay on the whole sphere: a window fitted from a
            // point near one (Veach's plates under its spheres) can miss the edge of its
            // silhouette, and a sample outside the window fails a correct sampler.
            let window = !has_sphere_light;
            out.push(Case::new(name, about, move |cfg| {
                run_probe(&label, &probe, cfg, window)
            }));
        }
    }
    (out, left)
}

/// The light probes of the scene's receivers, the first hits of camera rays through five
/// points of the film, as (index, description, probe), and the receivers left out with why.
pub fn receivers(
    scene: &Arc<Scene>,
    selection: EmitterSelection,
    mode: LightSampling,
) -> (Vec<(usize, String, LightProbe)>, Vec<String>) {
    let (mut out, mut left) = (Vec::new(), Vec::new());
    let (w, h) = (scene.camera.width, scene.camera.height);
    let film = [
        (0.5, 0.5),
        (0.25, 0.25),
        (0.75, 0.25),
        (0.25, 0.75),
        (0.75, 0.75),
    ];
    let mut rng = Rng::new(0, 7);
    for (k, (fx, fy)) in film.into_iter().enumerate() {
        let (px, py) = ((fx * w as f32) as u32, (fy * h as f32) as u32);
        let ray = scene
            .camera
            .generate_ray(px.min(w - 1), py.min(h - 1), &mut rng);
        let Some(hit) = scene.intersect(&ray) else {
            left.push(format!(
                "receiver {k}: the camera ray through ({px}, {py}) hits nothing"
            ));
            continue;
        };
        if scene.emitter_at(&hit.sp).is_some() {
            left.push(format!(
                "receiver {k}: the camera ray through ({px}, {py}) hits an emitter"
            ));
            continue;
        }
        let sp = hit.sp;
        let mut probe = LightProbe::new(scene.clone(), selection, sp.p, mode);
        probe.normal = sp.ns;
        let about = format!(
            "the scene's lights chosen by {}, sampled from {} (normal {}) at pixel ({px}, {py})",
            selection.name(),
            sp.p,
            sp.ns
        );
        out.push((k, about, probe));
    }
    (out, left)
}

#[cfg(test)]
#[path = "scene_tests.rs"]
mod tests;
