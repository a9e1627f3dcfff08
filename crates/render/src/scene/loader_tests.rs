//! Loader tests: each dialect's features, defaults and error messages.

use super::bsdf_tests::dielectric;
use super::*;
use crate::bsdf::{BsdfKind, Material};
use crate::named::Named;

pub(super) const SENSOR: &str =
    r#"<sensor type="perspective"><float name="fov" value="45"/></sensor>"#;
pub(super) const LIGHT: &str =
    r#"<emitter type="point"><point name="position" value="0,5,0"/></emitter>"#;

pub(super) fn load(xml: &str) -> Result<SceneDesc, SceneError> {
    load_scene_str(xml, Path::new("dir/test.xml"), &[])
}

/// A Mitsuba 3 scene with a sensor and a point light around `body`.
pub(super) fn m3(body: &str) -> SceneDesc {
    let xml = format!("<scene version=\"3.0.0\">{SENSOR}{LIGHT}{body}</scene>");
    load(&xml).unwrap_or_else(|e| panic!("{e}"))
}

pub(super) fn m3_err(body: &str) -> String {
    let xml = format!("<scene version=\"3.0.0\">{SENSOR}{LIGHT}\n{body}\n</scene>");
    load(&xml).unwrap_err().to_string()
}

pub(super) fn shape_bsdf(s: &SceneDesc) -> &Material {
    &s.shapes[0].bsdf
}

pub(super) fn mesh(s: &ShapeDesc) -> (&Vec<Vec3>, &Option<Vec<Vec3>>, &Vec<[u32; 3]>) {
    match &s.geometry {
        ShapeGeometry::Mesh {
            positions,
            normals,
            indices,
        } => (positions, normals, indices),
        other => panic!("expected a mesh, got {other:?}"),
    }
}

fn area_and_normal(s: &ShapeDesc) -> (f32, Vec3) {
    let (p, _, idx) = mesh(s);
    let mut area = 0.0;
    let mut n = Vec3::ZERO;
    for t in idx {
        let [a, b, c] = t.map(|i| p[i as usize]);
        let cr = (b - a).cross(c - a);
        area += 0.5 * cr.length();
        n += cr;
    }
    (area, n.normalize_or_zero())
}

pub(super) struct TempDir(PathBuf);
impl TempDir {
    pub(super) fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!("directlab-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
    }
    pub(super) fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }
}
impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

#[test]
fn mitsuba3_defaults() {
    let s = m3("");
    assert_eq!(s.film.width, 768);
    assert_eq!(s.film.height, 576);
    assert_eq!(
        s.film.filter,
        FilterDesc::Gaussian {
            stddev: 0.5,
            radius: 2.0
        }
    );
    assert_eq!(
        s.sampler,
        SamplerDesc {
            sample_count: 4,
            seed: 0,
            kind: crate::sampler::SamplerKind::Independent,
        }
    );
    assert_eq!(
        s.integrator,
        IntegratorDesc {
            strategy: StrategyKind::Mis,
            heuristic: Heuristic::Power,
            emitter_samples: 1,
            bsdf_samples: 1,
            hide_emitters: false,
            direct_part_of: None,
        }
    );
    assert_eq!(s.camera.fov_axis, FovAxis::X);
    assert_eq!((s.camera.near_clip, s.camera.far_clip), (0.01, 10000.0));
    assert_eq!(s.camera.to_world, Mat4::IDENTITY);
    assert_eq!(s.source, Path::new("dir/test.xml"));
}

#[test]
fn mitsuba3_sensor_film_sampler_integrator() {
    let xml = r#"<scene version="3.0.0">
        <integrator type="direct">
            <integer name="shading_samples" value="2"/>
            <integer name="bsdf_samples" value="3"/>
            <boolean name="hide_emitters" value="true"/>
        </integrator>
        <sensor type="perspective">
            <float name="fov" value="39.3"/>
            <string name="fov_axis" value="smaller"/>
            <float name="near_clip" value="0.5"/>
            <float name="far_clip" value="50"/>
            <transform name="to_world"><translate x="1"/></transform>
            <sampler type="independent">
                <integer name="sample_count" value="16"/>
                <integer name="seed" value="3"/>
            </sampler>
            <film type="hdrfilm">
                <integer name="width" value="64"/>
                <integer name="height" value="32"/>
                <string name="pixel_format" value="rgb"/>
                <rfilter type="tent"/>
            </film>
        </sensor>
        <emitter type="point"><rgb name="intensity" value="1, 2, 3"/></emitter>
    </scene>"#;
    let s = load(xml).unwrap();
    assert_eq!(
        s.integrator,
        IntegratorDesc {
            strategy: StrategyKind::Mis,
            heuristic: Heuristic::Power,
            emitter_samples: 2,
            bsdf_samples: 3,
            hide_emitters: true,
            direct_part_of: None,
        }
    );
    assert_eq!(s.camera.fov_degrees, 39.3);
    assert_eq!(s.camera.fov_axis, FovAxis::Smaller);
    assert_eq!((s.camera.near_clip, s.camera.far_clip), (0.5, 50.0));
    assert_eq!(s.camera.to_world, Mat4::from_translation(Vec3::X));
    assert_eq!(
        s.sampler,
        SamplerDesc {
            sample_count: 16,
            seed: 3,
            kind: crate::sampler::SamplerKind::Independent,
        }
    );
    assert_eq!((s.film.width, s.film.height), (64, 32));
    assert_eq!(s.film.filter, FilterDesc::Tent { radius: 1.0 });
    assert_eq!(s.point_lights[0].intensity, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.point_lights[0].position, Vec3::ZERO);
    assert!(
        s.warnings.iter().any(|w| w.contains("pixel_format")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn gaussian_filter_radius_follows_stddev_in_mitsuba() {
    let xml = r#"<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="45"/>
        <film type="hdrfilm"><rfilter type="gaussian"><float name="stddev" value="0.25"/></rfilter></film>
        </sensor><emitter type="point"/></scene>"#;
    let s = load(xml).unwrap();
    assert_eq!(
        s.film.filter,
        FilterDesc::Gaussian {
            stddev: 0.25,
            radius: 1.0
        }
    );
}

#[test]
fn defaults_and_defines() {
    let xml = r#"<scene version="3.0.0">
        <default name="res" value="32"/>
        <default name="spp" value="8"/>
        <sensor type="perspective"><float name="fov" value="45"/>
            <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
            <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/>
            <rfilter type="box"/></film>
        </sensor>
        <emitter type="point"/>
    </scene>"#;
    let s = load(xml).unwrap();
    assert_eq!(
        (s.film.width, s.film.height, s.sampler.sample_count),
        (32, 32, 8)
    );
    assert_eq!(s.film.filter, FilterDesc::Box);
    let d = vec![("res".to_string(), "16".to_string())];
    let s = load_scene_str(xml, Path::new("t.xml"), &d).unwrap();
    assert_eq!(
        (s.film.width, s.film.height, s.sampler.sample_count),
        (16, 16, 8)
    );
}

#[test]
fn rectangle_cube_sphere() {
    let s = m3(r#"
        <shape type="rectangle">
            <transform name="to_world"><scale value="2"/><translate value="0, 0, 3"/></transform>
        </shape>
        <shape type="rectangle"><boolean name="flip_normals" value="true"/></shape>
        <shape type="rectangle"><boolean name="face_normals" value="true"/></shape>
        <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform></shape>
        <shape type="sphere">
            <point name="center" x="1" y="0" z="0"/><float name="radius" value="2"/>
            <transform name="to_world"><scale value="3"/><rotate z="1" angle="90"/><translate y="1"/></transform>
        </shape>
        <shape type="sphere"><boolean name="flip_normals" value="true"/></shape>"#);
    let (area, n) = area_and_normal(&s.shapes[0]);
    assert!((area - 16.0).abs() < 1e-4 && n.abs_diff_eq(Vec3::Z, 1e-6));
    let (pos, normals, _) = mesh(&s.shapes[0]);
    assert!(pos.iter().all(|p| p.z == 3.0 && p.x.abs() == 2.0));
    assert!(normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));

    let (_, n) = area_and_normal(&s.shapes[1]);
    assert!(n.abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(mesh(&s.shapes[1])
        .1
        .as_ref()
        .unwrap()
        .iter()
        .all(|n| *n == -Vec3::Z));

    assert!(mesh(&s.shapes[2]).1.is_none());

    let (area, _) = area_and_normal(&s.shapes[3]);
    assert!((area - 6.0).abs() < 1e-5);
    assert_eq!(mesh(&s.shapes[3]).2.len(), 12);

    match &s.shapes[4].geometry {
        ShapeGeometry::Sphere {
            center,
            radius,
            flip_normals,
        } => {
            // (1,0,0) -> scale 3 -> (3,0,0) -> rotate 90 about z -> (0,3,0) -> +y -> (0,4,0)
            assert!(
                center.abs_diff_eq(Vec3::new(0.0, 4.0, 0.0), 1e-5),
                "{center}"
            );
            assert!((radius - 6.0).abs() < 1e-5);
            assert!(!flip_normals);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        s.shapes[5].geometry,
        ShapeGeometry::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            flip_normals: true
        }
    );
    assert!(
        s.shapes[0]
            .origin
            .starts_with("dir/test.xml:2 <shape type=\"rectangle\">"),
        "{}",
        s.shapes[0].origin
    );

    let e = m3_err(
        r#"<shape type="sphere"><transform name="to_world"><scale x="1" y="2" z="1"/></transform></shape>"#,
    );
    assert!(
        e.contains("test.xml:2: <shape type=\"sphere\">: non-uniform scale"),
        "{e}"
    );
}

#[test]
fn area_emitters_and_point_lights() {
    let s = m3(r#"
        <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="17, 12, 4"/></emitter></shape>
        <emitter type="point">
            <transform name="to_world"><translate value="1, 2, 3"/></transform>
            <spectrum name="intensity" value="5"/>
        </emitter>"#);
    assert_eq!(
        s.shapes[0].emitter,
        Some(AreaEmitterDesc {
            radiance: Vec3::new(17.0, 12.0, 4.0)
        })
    );
    assert_eq!(s.point_lights.len(), 2);
    assert_eq!(s.point_lights[0].position, Vec3::new(0.0, 5.0, 0.0));
    assert_eq!(s.point_lights[1].position, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.point_lights[1].intensity, Vec3::splat(5.0));

    let s = m3(r#"<shape type="rectangle"><emitter type="area"/></shape>"#);
    assert_eq!(
        s.shapes[0].emitter,
        Some(AreaEmitterDesc {
            radiance: Vec3::ONE
        })
    );
    let e = load("<scene><camera type=\"perspective\"/>\n<mesh type=\"cube\"><emitter type=\"area\"/></mesh></scene>")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("test.xml:2: <emitter type=\"area\">: expected a 'radiance'"),
        "{e}"
    );
    let e = m3_err(r#"<emitter type="area"><rgb name="radiance" value="1"/></emitter>"#);
    assert!(e.contains("must be nested in the shape"), "{e}");
    let e = m3_err(r#"<emitter type="envmap"><string name="filename" value="sky.exr"/></emitter>"#);
    assert!(
        e.contains("test.xml:2: <emitter type=\"envmap\">: emitter 'envmap' is not supported yet"),
        "{e}"
    );
    let e = m3_err(r#"<emitter type="constant"/>"#);
    assert!(e.contains("not supported yet"), "{e}");
}

#[test]
fn mitsuba06_camel_case() {
    let xml = r##"<scene version="0.6.0">
        <integrator type="direct">
            <integer name="emitterSamples" value="2"/><integer name="bsdfSamples" value="0"/>
            <boolean name="hideEmitters" value="true"/>
        </integrator>
        <sensor type="perspective">
            <float name="fov" value="40"/><string name="fovAxis" value="y"/>
            <float name="nearClip" value="1"/><float name="farClip" value="100"/>
            <transform name="toWorld"><translate x="2"/></transform>
            <sampler type="independent"><integer name="sampleCount" value="9"/></sampler>
            <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="10"/>
                <rfilter type="gaussian"/></film>
        </sensor>
        <shape type="sphere">
            <bsdf type="roughconductor"><float name="alphaU" value="0.2"/><float name="alphaV" value="0.4"/>
                <srgb name="specularReflectance" value="#808080"/></bsdf>
            <emitter type="area"><spectrum name="radiance" value="3"/></emitter>
        </shape>
        <shape type="rectangle"><boolean name="flipNormals" value="true"/><boolean name="faceNormals" value="true"/>
            <bsdf type="dielectric"><float name="intIOR" value="1.4"/><string name="extIOR" value="air"/></bsdf></shape>
    </scene>"##;
    let s = load(xml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (s.integrator.emitter_samples, s.integrator.bsdf_samples),
        (2, 0)
    );
    assert!(s.integrator.hide_emitters);
    assert_eq!(s.integrator.heuristic, Heuristic::Power);
    assert_eq!(s.camera.fov_axis, FovAxis::Y);
    assert_eq!((s.camera.near_clip, s.camera.far_clip), (1.0, 100.0));
    assert_eq!(
        s.camera.to_world,
        Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0))
    );
    assert_eq!(s.sampler.sample_count, 9);
    assert_eq!((s.film.width, s.film.height), (20, 10));
    match shape_bsdf(&s) {
        Material {
            kind: BsdfKind::RoughConductor(rc),
            ..
        } => {
            let specular_reflectance = rc.specular_reflectance;
            let (au, av) = (rc.mf.alpha_u, rc.mf.alpha_v);
            assert_eq!((au, av, rc.sample_visible), (0.2, 0.4, true));
            // sRGB 128/255 is 0.2158 in linear
            assert!(
                (specular_reflectance.x - 0.21586).abs() < 1e-4,
                "{specular_reflectance}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        s.shapes[0].emitter,
        Some(AreaEmitterDesc {
            radiance: Vec3::splat(3.0)
        })
    );
    assert_eq!(s.shapes[1].bsdf, dielectric(1.4, 1.000277));
    let (_, n) = area_and_normal(&s.shapes[1]);
    assert!(n.abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(mesh(&s.shapes[1]).1.is_none());
}

#[test]
fn camera_may_mirror_but_not_scale() {
    let cam = |t: &str| {
        format!(
            "<scene version=\"3.0.0\">{LIGHT}\n<sensor type=\"perspective\"><float name=\"fov\" value=\"45\"/>\
             <transform name=\"to_world\">{t}</transform></sensor></scene>"
        )
    };
    assert!(load(&cam(
        r#"<scale value="-1,1,1"/><rotate y="1" angle="30"/><translate x="4"/>"#
    ))
    .is_ok());
    let e = load(&cam(r#"<scale value="2"/>"#)).unwrap_err().to_string();
    assert!(
        e.starts_with("dir/test.xml:2: <sensor type=\"perspective\">") && e.contains("no scale"),
        "{e}"
    );
}

#[test]
fn mirrored_mesh_warns_and_ldrfilm_is_accepted() {
    let s = m3(
        r#"<shape type="rectangle"><transform name="to_world"><scale x="-1"/></transform></shape>"#,
    );
    assert!(
        s.warnings.iter().any(|w| w.contains("mirrors the shape")),
        "{:?}",
        s.warnings
    );
    let xml = r#"<scene version="0.6.0"><sensor type="perspective"><float name="fov" value="45"/>
        <film type="ldrfilm"><float name="gamma" value="2.2"/><integer name="width" value="8"/></film>
        </sensor><emitter type="point"/></scene>"#;
    let s = load(xml).unwrap();
    assert_eq!(s.film.width, 8);
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
}

#[test]
fn doctype_is_accepted_and_rotate_axis_conflict_is_reported() {
    let xml = format!("<?xml version=\"1.0\"?>\n<!DOCTYPE scene>\n<scene version=\"0.6.0\">{SENSOR}{LIGHT}</scene>");
    assert!(load(&xml).is_ok());
    let e = m3_err(
        r#"<shape type="cube"><transform name="to_world"><rotate axis="0,0,1" z="1" angle="3"/></transform></shape>"#,
    );
    assert!(e.contains("test.xml:2: <rotate"), "{e}");
}

#[test]
fn focal_length_gives_a_diagonal_fov_like_mitsuba() {
    let cam = |params: &str| {
        load(&format!(
            "<scene version=\"3.0.0\">{LIGHT}<sensor type=\"perspective\">{params}</sensor></scene>"
        ))
    };
    // Mitsuba 3.9 reports x_fov 38.1848 for the default 768x576 film: the 50 mm default lens
    // on the 43.27 mm diagonal of 36x24 mm film.
    let c = cam("").unwrap().camera;
    assert_eq!(c.fov_axis, FovAxis::Diagonal);
    assert!((c.fov_degrees - 46.7930).abs() < 1e-3, "{}", c.fov_degrees);
    let c = cam(r#"<string name="focal_length" value="35mm"/>"#)
        .unwrap()
        .camera;
    assert!((c.fov_degrees - 2.0 * (43.26662f32 / 70.0).atan().to_degrees()).abs() < 1e-4);
    let e = cam(r#"<float name="fov" value="40"/><string name="focal_length" value="35mm"/>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not both"), "{e}");
}

/// Scene samplers map to directlab's: its own names as they are, Mitsuba's others to the
/// nearest one with a warning that names both; an unknown type is an error that lists them.
#[test]
fn sampler_types_map_to_the_nearest_directlab_sampler() {
    use crate::sampler::SamplerKind::*;
    for (ty, kind, warned) in [
        ("independent", Independent, false),
        ("stratified", Stratified, false),
        ("sobol", Sobol, false),
        ("sobol-xor", SobolXor, false),
        ("multijitter", Stratified, true),
        ("orthogonal", Stratified, true),
        ("ldsampler", Sobol, true),
    ] {
        let xml = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="45"/>
            <sampler type="{ty}"><integer name="sample_count" value="16"/>
            <boolean name="jitter" value="true"/></sampler></sensor>{LIGHT}</scene>"#
        );
        let s = load(&xml).unwrap_or_else(|e| panic!("{ty}: {e}"));
        assert_eq!(s.sampler.kind, kind, "{ty}");
        assert_eq!(s.sampler.sample_count, 16);
        let nearest = s.warnings.iter().any(|w| {
            w.contains(&format!(
                "sampler '{ty}' is rendered by directlab's '{}'",
                kind.name()
            )) && w.contains("nearest")
        });
        assert_eq!(nearest, warned, "{ty}: {:?}", s.warnings);
        assert!(
            s.warnings.iter().any(|w| w.contains("jitter")),
            "{ty}: {:?}",
            s.warnings
        );
    }
    let xml = format!(r#"<scene version="3.0.0">{SENSOR}<sampler type="pmj"/>{LIGHT}</scene>"#);
    let e = load(&xml).unwrap_err().to_string();
    assert!(
        e.contains("pmj") && e.contains("sobol-xor") && e.contains("test.xml"),
        "{e}"
    );
}
