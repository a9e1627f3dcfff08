//! The scenes shipped in `scenes/` load, and the two Cornell boxes agree.

use super::desc::*;
use super::load_scene;
use glam::Vec3;
use std::path::PathBuf;

fn scene_path(rel: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes")
        .join(rel)
}

pub(crate) fn load(rel: &str) -> SceneDesc {
    load_scene(&scene_path(rel), &[]).unwrap_or_else(|e| panic!("{e}"))
}

/// World-space triangles of a mesh shape.
fn triangles(s: &ShapeDesc) -> Vec<[Vec3; 3]> {
    match &s.geometry {
        ShapeGeometry::Mesh {
            positions, indices, ..
        } => indices
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect(),
        other => panic!("expected a mesh, got {other:?}"),
    }
}

fn normal_and_area(t: &[Vec3; 3]) -> (Vec3, f32) {
    let c = (t[1] - t[0]).cross(t[2] - t[0]);
    (c.normalize(), 0.5 * c.length())
}

#[test]
fn cornell_boxes_in_both_dialects_agree() {
    let m = load("cbox/cbox.xml");
    let n = load("cbox/cbox-nori.xml");
    assert_eq!(m.camera, n.camera);
    assert_eq!(m.film, n.film);
    assert_eq!(m.sampler, n.sampler);
    assert_eq!(m.point_lights, n.point_lights);
    assert_eq!(m.shapes.len(), 8);
    assert_eq!(m.shapes.len(), n.shapes.len());
    for (a, b) in m.shapes.iter().zip(&n.shapes) {
        assert_eq!(a.geometry, b.geometry, "{} vs {}", a.origin, b.origin);
        assert_eq!(a.bsdf, b.bsdf, "{} vs {}", a.origin, b.origin);
        assert_eq!(a.emitter, b.emitter, "{} vs {}", a.origin, b.origin);
    }
    assert_eq!(m.integrator.strategy, StrategyKind::Mis);
    assert_eq!(n.integrator.strategy, StrategyKind::Mis);
    assert_eq!(m.integrator.heuristic, Heuristic::Power);
    assert_eq!(n.integrator.heuristic, Heuristic::Balance);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    assert!(n.warnings.is_empty(), "{:?}", n.warnings);
}

#[test]
fn cornell_box_is_the_published_one() {
    let s = load("cbox/cbox.xml");
    assert_eq!((s.film.width, s.film.height), (256, 256));
    assert_eq!(s.film.filter, FilterDesc::Box);
    assert!((s.camera.fov_degrees - 39.3077).abs() < 1e-4);
    let origin = s.camera.to_world.transform_point3(Vec3::ZERO);
    assert!(origin.abs_diff_eq(Vec3::new(0.278, 0.273, -0.8), 1e-6));
    assert!(s
        .camera
        .to_world
        .transform_vector3(Vec3::Z)
        .abs_diff_eq(Vec3::Z, 1e-6));

    // Document order: floor, ceiling, back, left (red), right (green), short and tall block,
    // light.
    let centre = Vec3::new(0.278, 0.2744, 0.2796);
    let mut emitters = 0;
    for (i, shape) in s.shapes.iter().enumerate() {
        let tris = triangles(shape);
        let mean = tris.iter().flatten().sum::<Vec3>() / (3 * tris.len()) as f32;
        for t in &tris {
            let (n, area) = normal_and_area(t);
            assert!(area > 0.0);
            let centroid = (t[0] + t[1] + t[2]) / 3.0;
            match i {
                // Walls face the inside of the box.
                0..=4 => assert!(n.dot(centre - centroid) > 0.0, "{}", shape.origin),
                // Block sides face away from the block's vertical axis; tops face up.
                5 | 6 => {
                    let out = (centroid - mean) * Vec3::new(1.0, 0.0, 1.0);
                    assert!(n.y > 0.99 || n.dot(out) > 0.0, "{}", shape.origin);
                }
                _ => assert!(n.abs_diff_eq(-Vec3::Y, 1e-6), "light must face down"),
            }
        }
        if (5..=6).contains(&i) {
            assert_eq!(tris.len(), 10, "blocks have 5 quads");
        }
        if let Some(e) = &shape.emitter {
            emitters += 1;
            assert_eq!(i, 7);
            assert_eq!(e.radiance, Vec3::new(17.0, 12.0, 4.0));
            let area: f32 = tris.iter().map(|t| normal_and_area(t).1).sum();
            assert!((area - 0.13 * 0.105).abs() < 1e-6, "{area}");
        }
    }
    assert_eq!(emitters, 1);
    let white =
        crate::scene::fixtures::one_sided(crate::bsdf::BsdfKind::Diffuse(crate::bsdf::Diffuse {
            reflectance: Vec3::new(0.725, 0.71, 0.68),
        }));
    let red =
        crate::scene::fixtures::one_sided(crate::bsdf::BsdfKind::Diffuse(crate::bsdf::Diffuse {
            reflectance: Vec3::new(0.63, 0.065, 0.05),
        }));
    let green =
        crate::scene::fixtures::one_sided(crate::bsdf::BsdfKind::Diffuse(crate::bsdf::Diffuse {
            reflectance: Vec3::new(0.14, 0.45, 0.091),
        }));
    let bsdfs: Vec<&crate::bsdf::Material> = s.shapes.iter().map(|s| &s.bsdf).collect();
    assert_eq!(
        bsdfs,
        vec![&white, &white, &white, &red, &green, &white, &white, &white]
    );
    // Red wall on the image's left: camera +x is image-left and the red wall is at x = 0.55.
    let red_x = triangles(&s.shapes[3])[0][0].x;
    assert!(red_x > 0.5);
}

#[test]
fn cornell_box_defaults_can_be_overridden() {
    let d = vec![
        ("res".to_string(), "32".to_string()),
        ("spp".to_string(), "4".to_string()),
    ];
    let s = load_scene(&scene_path("cbox/cbox.xml"), &d).unwrap();
    assert_eq!(
        (s.film.width, s.film.height, s.sampler.sample_count),
        (32, 32, 4)
    );
}

/// Irradiance at `x` (normal `n`) from a unit-radiance polygon, by the Lambert formula.
fn polygon_irradiance(x: Vec3, n: Vec3, poly: &[Vec3]) -> f32 {
    let mut sum = 0.0;
    for k in 0..poly.len() {
        let a = (poly[k] - x).normalize();
        let b = (poly[(k + 1) % poly.len()] - x).normalize();
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * a.cross(b).normalize().dot(n);
    }
    0.5 * sum.abs()
}

#[test]
fn triangle_light_scene_matches_its_documentation() {
    let s = load("triangle-light/triangle-light.xml");
    assert_eq!(s.shapes.len(), 2);
    let floor = triangles(&s.shapes[0]);
    let floor_area: f32 = floor.iter().map(|t| normal_and_area(t).1).sum();
    assert!((floor_area - 100.0).abs() < 1e-3);
    for t in &floor {
        assert!(normal_and_area(t).0.abs_diff_eq(Vec3::Y, 1e-6));
        assert!(t
            .iter()
            .all(|p| p.y.abs() < 1e-6 && p.x.abs() <= 5.0 + 1e-5));
    }
    assert_eq!(s.shapes[0].bsdf, crate::scene::fixtures::diffuse(0.5));
    let light = &s.shapes[1];
    assert_eq!(
        light.emitter,
        Some(AreaEmitterDesc {
            radiance: Vec3::ONE
        })
    );
    let tri = triangles(light);
    assert_eq!(tri.len(), 1);
    assert_eq!(
        tri[0],
        [
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(0.5, 1.0, -0.5),
            Vec3::new(0.0, 1.0, 0.5)
        ]
    );
    let (n, area) = normal_and_area(&tri[0]);
    assert!(n.abs_diff_eq(-Vec3::Y, 1e-6) && (area - 0.5).abs() < 1e-6);
    // The reference values quoted in the XML comment.
    for (x, e) in [
        (Vec3::ZERO, 0.404357),
        (Vec3::X, 0.123597),
        (-Vec3::Z, 0.177238),
    ] {
        let got = polygon_irradiance(x, Vec3::Y, &tri[0]);
        assert!((got - e).abs() < 1e-5, "{x}: {got} vs {e}");
    }
}
