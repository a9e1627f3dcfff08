//! Loader tests of Nori's dialect: its element names, defaults and integrator settings.

use super::bsdf_tests::{dielectric, diffuse, nori, one};
use super::tests::{load, mesh, TempDir};
use super::*;
use crate::bsdf::{BsdfKind, Mirror};
use crate::scene::transform;

#[test]
fn nori_scene() {
    let dir = TempDir::new("nori");
    dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let xml = r#"<?xml version="1.0"?>
<scene>
    <integrator type="direct"><string name="sampling" value="light"/></integrator>
    <sampler type="independent"><integer name="sampleCount" value="32"/></sampler>
    <camera type="perspective">
        <float name="fov" value="30"/>
        <integer name="width" value="100"/>
        <integer name="height" value="50"/>
        <float name="nearClip" value="0.1"/>
        <transform name="toWorld">
            <scale value="-1,1,1"/>
            <lookat target="0,0,0" origin="0,0,5" up="0,1,0"/>
        </transform>
    </camera>
    <mesh type="obj">
        <string name="filename" value="tri.obj"/>
        <transform name="toWorld"><translate value="0,0,1"/></transform>
        <bsdf type="diffuse"><color name="albedo" value="0.2 0.3 0.4"/></bsdf>
        <emitter type="area"><color name="radiance" value="1,1,1"/></emitter>
    </mesh>
    <mesh type="obj"><string name="filename" value="tri.obj"/></mesh>
    <mesh type="obj"><string name="filename" value="tri.obj"/><bsdf type="mirror"/></mesh>
    <mesh type="obj"><string name="filename" value="tri.obj"/>
        <bsdf type="dielectric"><float name="intIOR" value="1.7"/></bsdf></mesh>
    <mesh type="obj"><string name="filename" value="tri.obj"/><bsdf type="microfacet"/></mesh>
    <mesh type="obj"><string name="filename" value="tri.obj"/>
        <bsdf type="microfacet"><float name="alpha" value="0.3"/><float name="intIOR" value="1.3"/>
        <float name="extIOR" value="1.1"/><color name="kd" value="0.1, 0.2, 0.3"/></bsdf></mesh>
    <emitter type="point"><point name="position" value="1,2,3"/><color name="power" value="12.566370614"/></emitter>
    <emitter type="pointlight"><point name="position" value="0,1,0"/><color name="radiance" value="2,2,2"/></emitter>
</scene>"#;
    let path = dir.write("scene.xml", xml);
    let s = load_scene(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.integrator.strategy, StrategyKind::Light);
    assert_eq!(s.sampler.sample_count, 32);
    assert_eq!((s.film.width, s.film.height), (100, 50));
    assert_eq!(
        s.film.filter,
        FilterDesc::Gaussian {
            stddev: 0.5,
            radius: 2.0
        }
    );
    assert_eq!(
        (s.camera.fov_degrees, s.camera.near_clip, s.camera.far_clip),
        (30.0, 0.1, 10000.0)
    );
    let expected = transform::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Some(Vec3::Y)).unwrap()
        * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    assert!(s.camera.to_world.abs_diff_eq(expected, 1e-6));
    let (p, n, _) = mesh(&s.shapes[0]);
    assert_eq!(p[1], Vec3::new(1.0, 0.0, 1.0));
    assert!(n.is_none());
    assert_eq!(s.shapes[0].bsdf, diffuse(Vec3::new(0.2, 0.3, 0.4)));
    assert_eq!(
        s.shapes[0].emitter,
        Some(AreaEmitterDesc {
            radiance: Vec3::ONE
        })
    );
    assert_eq!(s.shapes[1].bsdf, diffuse(Vec3::splat(0.5)));
    assert_eq!(s.shapes[2].bsdf, one(BsdfKind::Mirror(Mirror)));
    assert_eq!(s.shapes[3].bsdf, dielectric(1.7, 1.000277));
    assert_eq!(
        s.shapes[4].bsdf,
        nori(0.1, 1.5046, 1.000277, Vec3::splat(0.5))
    );
    assert_eq!(
        s.shapes[5].bsdf,
        nori(0.3, 1.3, 1.1, Vec3::new(0.1, 0.2, 0.3))
    );
    assert_eq!(s.point_lights[0].position, Vec3::new(1.0, 2.0, 3.0));
    assert!(s.point_lights[0].intensity.abs_diff_eq(Vec3::ONE, 1e-6));
    assert_eq!(s.point_lights[1].intensity, Vec3::splat(2.0));
}

#[test]
fn nori_defaults_and_sampling_values() {
    let scene = |integrator: &str| {
        format!(
            r#"<scene>{integrator}<camera type="perspective"/>
            <emitter type="pointlight"><point name="position" value="0,1,0"/><color name="radiance" value="1"/></emitter></scene>"#
        )
    };
    let s = load(&scene("")).unwrap();
    assert_eq!(
        (s.film.width, s.film.height, s.sampler.sample_count),
        (1280, 720, 1)
    );
    assert_eq!((s.camera.fov_degrees, s.camera.near_clip), (30.0, 1e-4));
    let cases = [
        (
            r#"<integrator type="direct"><string name="sampling" value="light"/></integrator>"#,
            StrategyKind::Light,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct"><string name="sampling" value="material"/></integrator>"#,
            StrategyKind::Bsdf,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct"><string name="sampling" value="MIS"/></integrator>"#,
            StrategyKind::Mis,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct"><string name="sampling" value="mis"/></integrator>"#,
            StrategyKind::Mis,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct_ems"/>"#,
            StrategyKind::Light,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct_mats"/>"#,
            StrategyKind::Bsdf,
            Heuristic::Balance,
        ),
        (
            r#"<integrator type="direct_mis"/>"#,
            StrategyKind::Mis,
            Heuristic::Balance,
        ),
    ];
    for (integrator, strategy, heuristic) in cases {
        let s = load(&scene(integrator)).unwrap();
        assert_eq!(
            (s.integrator.strategy, s.integrator.heuristic),
            (strategy, heuristic),
            "{integrator}"
        );
    }
    let e = load(&scene(
        r#"<integrator type="direct"><string name="sampling" value="both"/></integrator>"#,
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("expected sampling \"light\", \"material\" or \"MIS\""),
        "{e}"
    );
    let e = load(&scene(r#"<integrator type="path_mis"/>"#))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("integrator 'path_mis' renders global illumination")
            && e.contains("pass --integrator direct")
            && e.contains("integrator = \"direct\"")
            && e.starts_with("dir/test.xml:1"),
        "{e}"
    );
}

/// `--integrator direct`: every path tracer (and Whitted's) is read as its direct part with
/// the strategy its name implies, says so, and drops the path depth with a warning; other
/// integrators stay refused, and without the mode the path tracers are refused.
#[test]
fn global_illumination_integrators_read_as_their_direct_part() {
    use crate::scene::loader::{load_scene_element, IntegratorMode};
    use crate::scene::xml::parse_document;
    let scene = |integrator: &str, version: &str| {
        format!(
            r#"<scene{version}>{integrator}<sensor type="perspective"/>
            <emitter type="point"><point name="position" value="0,1,0"/><rgb name="intensity" value="1"/></emitter></scene>"#
        )
    };
    let direct = |xml: &str| {
        let root = parse_document(xml, Path::new("t.xml"), &[]).unwrap();
        load_scene_element(&root, Path::new("t.xml"), Some(IntegratorMode::Direct))
    };
    let cases = [
        ("path_mis", "", StrategyKind::Mis, Heuristic::Balance),
        ("path_ems", "", StrategyKind::Light, Heuristic::Balance),
        ("path_mats", "", StrategyKind::Bsdf, Heuristic::Balance),
        ("whitted", "", StrategyKind::Light, Heuristic::Balance),
        (
            "path",
            " version=\"3.0.0\"",
            StrategyKind::Mis,
            Heuristic::Power,
        ),
        (
            "volpath",
            " version=\"3.0.0\"",
            StrategyKind::Mis,
            Heuristic::Power,
        ),
    ];
    for (ty, version, kind, heuristic) in cases {
        let xml = scene(
            &format!(
                r#"<integrator type="{ty}"><integer name="max_depth" value="5"/></integrator>"#
            ),
            version,
        );
        let s = direct(&xml).unwrap_or_else(|e| panic!("{ty}: {e}"));
        let i = &s.integrator;
        assert_eq!((i.strategy, i.heuristic), (kind, heuristic), "{ty}");
        assert_eq!(i.direct_part_of.as_deref(), Some(ty));
        assert!(
            s.warnings.iter().any(|w| w.contains("max_depth")),
            "{ty}: {:?}",
            s.warnings
        );
        assert!(load(&xml).is_err(), "{ty} refused without the mode");
    }
    let plain = direct(&scene(r#"<integrator type="direct"/>"#, "")).unwrap();
    assert_eq!(plain.integrator.direct_part_of, None);
    let e = direct(&scene(r#"<integrator type="bdpt"/>"#, " version=\"3.0.0\""))
        .unwrap_err()
        .to_string();
    assert!(e.contains("found integrator 'bdpt'"), "{e}");
}
