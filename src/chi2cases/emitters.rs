//! Emitter direction sampling seen from a reference point: one light of each kind from four
//! distances and angles, by area and by solid angle, and a whole scene of lights with the
//! emitter-choice pmf included.
//!
//! Every light is about one unit across, centred at the origin and emitting towards +z;
//! "close" is 1e-3 of that size from an edge (1e-3 above a sphere), where the area pdf spans
//! many orders of magnitude and the silhouette runs along the horizon; "far" is 1e3 sizes
//! away; "grazing" sees the light at cos(theta_light) of about 0.01. Small or thin lights are tested in a window
//! fitted to them ([`Tangent`]); lights covering much of the sky on the whole sphere.

use super::exact::{self, triangle_pdf, LightTriangle};
use super::probe::LightProbe;
use super::run_given;
use super::tangent::Tangent;
use super::{run_continuous, Case, CaseConfig, Outcome};
use crate::emitter::{EmitterSelection, LightSampling};
use crate::scene::desc::{Rgb, ShapeDesc};
use crate::scene::{fixtures, Scene};
use glam::Vec3;
use std::sync::Arc;

/// Largest angle (from the window's axis) a tangent-plane window is used for; beyond it the
/// projection stretches cells too much and the whole sphere is the better domain.
const WINDOW_MAX_ANGLE_DEG: f64 = 60.0;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn light_mesh(positions: Vec<Vec3>, indices: Vec<[u32; 3]>, radiance: f32) -> ShapeDesc {
    fixtures::mesh(
        positions,
        indices,
        fixtures::diffuse(0.0),
        Some(Rgb::splat(radiance)),
    )
}

pub fn triangle() -> ShapeDesc {
    light_mesh(
        vec![v(-0.5, -0.4, 0.0), v(0.5, -0.3, 0.0), v(0.1, 0.5, 0.0)],
        vec![[0, 1, 2]],
        1.0,
    )
}

pub fn quad() -> ShapeDesc {
    light_mesh(
        vec![
            v(-0.5, -0.5, 0.0),
            v(0.5, -0.5, 0.0),
            v(0.5, 0.5, 0.0),
            v(-0.5, 0.5, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        1.0,
    )
}

/// A bent, non-planar mesh of triangles with areas about 0.40, 0.51 and 0.03: picking them
/// uniformly instead of by area is a large error.
pub fn unequal_mesh_positions() -> Vec<Vec3> {
    vec![
        v(-0.5, -0.5, 0.0),
        v(0.3, -0.5, 0.0),
        v(0.5, 0.5, 0.15),
        v(-0.5, 0.5, 0.0),
        v(0.35, -0.5, 0.02),
    ]
}

pub const UNEQUAL_MESH_INDICES: [[u32; 3]; 3] = [[0, 1, 2], [0, 2, 3], [1, 4, 2]];

pub fn unequal_mesh() -> ShapeDesc {
    light_mesh(unequal_mesh_positions(), UNEQUAL_MESH_INDICES.to_vec(), 1.0)
}

pub fn sphere() -> ShapeDesc {
    fixtures::sphere_light(Vec3::ZERO, 0.5, 1.0)
}

/// A point 1e-3 from the middle of edge (a, b) of triangle (a, b, c), outside the triangle
/// and on its emitting side, 45 degrees above its plane.
fn edge_view(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let n = (b - a).cross(c - a).normalize();
    let mut out = n.cross(b - a).normalize();
    if out.dot(c - a) > 0.0 {
        out = -out;
    }
    0.5 * (a + b) + (out + n) * (1e-3 / 2f32.sqrt())
}

/// Reference points (name, position) for a light of the given shape kind.
pub(crate) fn viewpoints(kind: &str) -> Vec<(&'static str, Vec3)> {
    let m = unequal_mesh_positions();
    let (close, grazing) = match kind {
        "triangle" => (
            edge_view(v(0.5, -0.3, 0.0), v(0.1, 0.5, 0.0), v(-0.5, -0.4, 0.0)),
            Some(v(2.0, 0.2, 0.02)),
        ),
        "quad" => (
            edge_view(v(0.5, -0.5, 0.0), v(0.5, 0.5, 0.0), v(-0.5, 0.5, 0.0)),
            Some(v(2.0, 0.2, 0.02)),
        ),
        // Triangle [0, 2, 3], the largest, seen at cos(theta) 0.01 along its own plane; the
        // others then face away.
        "mesh" => {
            let (a, b, c) = (m[0], m[2], m[3]);
            let n = (b - a).cross(c - a).normalize();
            let t = n.cross(Vec3::Y).normalize();
            (
                edge_view(c, a, b),
                Some((a + b + c) / 3.0 + t * 2.0 + n * 0.02),
            )
        }
        // A sphere looks the same from every side: it has no grazing view.
        _ => (v(0.0, 0.0, 0.501), None),
    };
    let mut pts = vec![
        ("head-on", v(0.05, 0.03, 1.0)),
        ("close", close),
        ("far", v(20.0, 10.0, 1000.0)),
    ];
    if let Some(g) = grazing {
        pts.insert(1, ("grazing", g));
    }
    pts
}

/// Builds one light fixture.
type LightFn = fn() -> ShapeDesc;

fn mode_name(m: LightSampling) -> &'static str {
    crate::named::Named::name(m)
}

/// Tests a probe: triangle lights against exact cell masses in a window fitted to them
/// ([`run_exact`]), others by [`run_integrated`].
pub fn run_probe(name: &str, probe: &LightProbe, cfg: &CaseConfig, window: bool) -> Outcome {
    if window {
        if let Some(out) = run_exact(name, probe, cfg, &|t, d| triangle_pdf(probe, t, d)) {
            return out;
        }
    }
    run_integrated(name, probe, cfg, window)
}

/// Tests a probe against cell masses integrated numerically from its pdf: in a window fitted
/// to its lights when they are small enough, else on the whole sphere.
pub fn run_integrated(name: &str, probe: &LightProbe, cfg: &CaseConfig, window: bool) -> Outcome {
    let (axis, dirs, max_angle) = probe.extent();
    if window && max_angle.to_degrees() < WINDOW_MAX_ANGLE_DEG {
        let w = Tangent::fit(axis, &dirs, cfg.resolution);
        let pdf = w.plane_pdf(|d| probe.pdf(d));
        run_continuous(name, &w, |r| probe.sample(r), pdf, cfg, vec![])
    } else {
        run_continuous(
            name,
            &cfg.sphere(),
            |r| probe.sample(r),
            |d| probe.pdf(d),
            cfg,
            vec![],
        )
    }
}

/// Tests a probe of triangle lights against exact cell masses ([`super::exact`]), with
/// `pdf(triangle, d)` the density through one triangle (its pmf excluded); None when its
/// lights are not all triangles in front of one window.
pub fn run_exact(
    name: &str,
    probe: &LightProbe,
    cfg: &CaseConfig,
    pdf: &dyn Fn(&LightTriangle, Vec3) -> f64,
) -> Option<Outcome> {
    let tris = exact::light_triangles(probe)?;
    let w = exact::window(probe, &tris, cfg.resolution)?;
    let masses = exact::cell_masses(&w, &tris, probe.ref_p, &|t, d| t.pmf * pdf(t, d))?;
    Some(run_given(name, &w, |r| probe.sample(r), &masses, cfg))
}

fn probe_case(name: String, about: String, probe: LightProbe, window: bool) -> Case {
    let label = name.clone();
    Case::new(name, about, move |cfg| {
        run_probe(&label, &probe, cfg, window)
    })
}

pub fn build(shapes: Vec<ShapeDesc>) -> Arc<Scene> {
    Arc::new(Scene::build(fixtures::shapes_only(shapes)).expect("fixture scene builds"))
}

/// Five lights around the origin: a large quad overhead with a sphere in front of it (so
/// directions cross two emitters), a triangle and the bent mesh on either side, and a quad
/// that faces away (its samples must all fail). Radiances differ so that power-proportional
/// choice differs from uniform.
pub fn scene_lights() -> Vec<ShapeDesc> {
    let big = light_mesh(
        vec![
            v(-2.0, -2.0, 3.0),
            v(-2.0, 2.0, 3.0),
            v(2.0, 2.0, 3.0),
            v(2.0, -2.0, 3.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        1.0,
    );
    let ball = fixtures::sphere_light(v(0.5, 0.3, 1.5), 0.4, 2.0);
    let side = light_mesh(
        vec![v(2.0, -1.0, 0.2), v(2.0, 0.0, 1.5), v(2.0, 1.0, 0.5)],
        vec![[0, 1, 2]],
        4.0,
    );
    // The bent mesh turned so its +z side faces +x, on the -x side of the origin.
    let turned = unequal_mesh_positions()
        .into_iter()
        .map(|p| v(p.z - 1.5, p.y, 0.8 - p.x))
        .collect();
    let bent = light_mesh(turned, UNEQUAL_MESH_INDICES.to_vec(), 0.7);
    let away = light_mesh(
        vec![
            v(-0.5, 2.0, 0.5),
            v(-0.5, 2.0, 1.5),
            v(0.5, 2.0, 1.5),
            v(0.5, 2.0, 0.5),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        3.0,
    );
    vec![big, ball, side, bent, away]
}

pub fn cases() -> Vec<Case> {
    let modes = <LightSampling as crate::named::Named>::all();
    let lights: [(&str, LightFn); 4] = [
        ("triangle", triangle),
        ("quad", quad),
        ("mesh", unequal_mesh),
        ("sphere", sphere),
    ];
    let mut out = Vec::new();
    for (kind, shape) in lights {
        let scene = build(vec![shape()]);
        for &mode in &modes {
            for (view, p) in viewpoints(kind) {
                let name = format!("emitter/{kind}-{}-{view}", mode_name(mode));
                let about = format!("{kind} light sampled by {}, seen from {p}", mode_name(mode));
                let probe = LightProbe::new(scene.clone(), EmitterSelection::Uniform, p, mode);
                out.push(probe_case(name, about, probe, true));
            }
        }
    }
    let scene = build(scene_lights());
    for selection in [EmitterSelection::Uniform, EmitterSelection::Power] {
        let sel = selection.name();
        for &mode in &modes {
            let name = format!("emitter/scene-{sel}-{}", mode_name(mode));
            let about = format!(
                "five lights (one facing away) chosen {sel}, sampled by {}, from the origin",
                mode_name(mode)
            );
            let probe = LightProbe::new(scene.clone(), selection, Vec3::ZERO, mode);
            out.push(probe_case(name, about, probe, false));
        }
    }
    out
}
