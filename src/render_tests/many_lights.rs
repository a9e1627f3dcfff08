//! Many lights: every emitter choice, under every light-sampling strategy and both MIS
//! heuristics, against the exact answer (a grid of lights facing a floor, Lambert's formula
//! summed over the lights), and RIS with one candidate as its source strategy.

use super::{settings, ALPHA};
use crate::analytic::{diffuse_radiance, polygon_irradiance};
use crate::emitter::{EmitterSelection, LightSampling};
use crate::integrator::Strategy;
use crate::render::render;
use crate::scene::desc::{Heuristic, SceneDesc, StrategyKind};
use crate::scene::{fixtures, Scene};
use glam::{DVec3, Vec3};

/// A 16 x 16 grid of lights (pitch 0.5, half-size 0.1, height 0.6) with radiances over two
/// orders of magnitude, over a floor of albedo 0.5; the one-pixel camera looks at `x`.
fn grid_probe(x: Vec3) -> (SceneDesc, f64) {
    let lights = fixtures::light_grid(16, 0.5, 0.1, 0.6, |i, j| {
        0.2 + 20.0 * (((i * 7 + j * 13) % 17) as f32 / 16.0).powi(3)
    });
    let mut e = 0.0;
    for (poly, l) in fixtures::light_grid_polygons(&lights) {
        e += polygon_irradiance(x.as_dvec3(), DVec3::Z, &poly, l).unwrap();
    }
    let mut desc = fixtures::floor_probe(0.5, x, x + Vec3::new(0.0, 0.0, 0.01));
    desc.shapes.extend(lights);
    (desc, diffuse_radiance(0.5, e))
}

fn selections() -> [EmitterSelection; 6] {
    [
        EmitterSelection::Uniform,
        EmitterSelection::Power,
        EmitterSelection::Exhaustive,
        EmitterSelection::Bvh,
        EmitterSelection::Ris(1),
        EmitterSelection::Ris(8),
    ]
}

/// Light sampling alone, multi-sample MIS (balance; power with two light samples) and
/// one-sample MIS (both heuristics), with this emitter choice.
fn strategies(selection: EmitterSelection) -> Vec<Strategy> {
    let base = Strategy {
        kind: StrategyKind::Light,
        heuristic: Heuristic::Balance,
        emitter_samples: 1,
        bsdf_samples: 1,
        selection,
        light_sampling: LightSampling::Area,
        hide_emitters: false,
    };
    vec![
        base,
        Strategy {
            kind: StrategyKind::Mis,
            ..base
        },
        Strategy {
            kind: StrategyKind::Mis,
            heuristic: Heuristic::Power,
            emitter_samples: 2,
            ..base
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            ..base
        },
        Strategy {
            kind: StrategyKind::MisOneSample,
            heuristic: Heuristic::Power,
            light_sampling: LightSampling::SolidAngle,
            ..base
        },
    ]
}

/// 256 lights, two receivers (under the grid's middle and near its corner), every emitter
/// choice under five strategies: a two-sided t-test of each one-pixel render (40k samples)
/// against the exact radiance, ALPHA Sidak-corrected over the 60 renders. Also asserts that
/// the point-dependent choices and RIS beat uniform choice's variance under light sampling
/// near the corner, where few lights matter.
#[test]
fn many_lights_match_lambert_for_every_emitter_choice() {
    use crate::stats::ttest::{one_sample, sidak};
    let receivers = [Vec3::new(0.1, -0.2, 0.0), Vec3::new(3.6, 3.3, 0.0)];
    let alpha = sidak(ALPHA, receivers.len() * selections().len() * 5);
    let n = 40_000u32;
    for (k, x) in receivers.iter().enumerate() {
        let (desc, reference) = grid_probe(*x);
        let scene = Scene::build(desc).unwrap();
        let mut light_var = Vec::new();
        for sel in selections() {
            for s in strategies(sel) {
                let out = render(&scene, s, &settings(n, 3 + k as u64));
                assert_eq!(out.non_finite_samples, 0);
                let (mean, var_of_mean) = (out.mean.data[0][0], out.variance.data[0][0]);
                let t = one_sample(mean, var_of_mean * n as f64, n as u64, reference);
                assert!(
                    t.passes(alpha),
                    "receiver {k} {}: {mean} vs {reference}: {t:?}",
                    s.label()
                );
                if s.kind == StrategyKind::Light {
                    light_var.push((sel, var_of_mean));
                }
            }
        }
        if k == 1 {
            let uniform = light_var[0].1;
            for (sel, v) in &light_var[2..] {
                if *sel != EmitterSelection::Ris(1) {
                    assert!(
                        *v < uniform,
                        "{sel}: variance {v} not below uniform's {uniform}"
                    );
                }
            }
        }
    }
}

/// `ris:1` keeps its one candidate, drawn by power: the image is bitwise power choice's,
/// for every strategy that samples lights, on the grid and the bundled Veach scene.
#[test]
fn ris_with_one_candidate_is_power_choice() {
    let veach = crate::scene::load_scene("scenes/veach-mis/veach-mis.xml".as_ref(), &[]).unwrap();
    let (grid, _) = grid_probe(Vec3::new(0.3, 0.1, 0.0));
    let scenes = [grid, veach].map(|d| Scene::build(d).unwrap());
    for scene in &scenes {
        for s in strategies(EmitterSelection::Power) {
            let ris = Strategy {
                selection: EmitterSelection::Ris(1),
                ..s
            };
            let mut st = settings(4, 9);
            if scene.camera.width > 1 {
                st.spp = 2;
            }
            let (a, b) = (render(scene, s, &st), render(scene, ris, &st));
            let bits = |o: &crate::render::RenderOutput| -> Vec<u64> {
                o.mean
                    .data
                    .iter()
                    .flat_map(|p| p.map(f64::to_bits))
                    .collect()
            };
            assert!(bits(&a) == bits(&b), "{}", s.label());
        }
    }
}
