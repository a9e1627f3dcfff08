//! Error-message tests: every bad input must name the file, the line and the element.

use super::tests::TempDir;
use super::*;

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="45"/></sensor>"#;
const LIGHT: &str = r#"<emitter type="point"><point name="position" value="0,5,0"/></emitter>"#;

fn load(xml: &str) -> Result<SceneDesc, SceneError> {
    load_scene_str(xml, Path::new("dir/test.xml"), &[])
}

fn m3_err(body: &str) -> String {
    let xml = format!("<scene version=\"3.0.0\">{SENSOR}{LIGHT}\n{body}\n</scene>");
    load(&xml).unwrap_err().to_string()
}

#[test]
fn missing_mesh_file() {
    let xml = "<scene version=\"3.0.0\">\n<shape type=\"obj\">\n  <string name=\"filename\" value=\"meshes/none.obj\"/>\n</shape>\n</scene>";
    let e = load(xml).unwrap_err().to_string();
    assert!(
        e.starts_with("dir/test.xml:3: <string name=\"filename\" value=\"meshes/none.obj\">: cannot open mesh file 'dir/meshes/none.obj'"),
        "{e}"
    );
}

#[test]
fn nan_vertex_in_obj() {
    let dir = TempDir::new("nanobj");
    dir.write("bad.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    let path = dir.write(
        "s.xml",
        &format!("<scene version=\"3.0.0\">{SENSOR}\n<shape type=\"obj\"><string name=\"filename\" value=\"bad.obj\"/></shape></scene>"),
    );
    let e = load_scene(&path, &[]).unwrap_err().to_string();
    assert!(
        e.contains("s.xml:2: <string name=\"filename\" value=\"bad.obj\">"),
        "{e}"
    );
    assert!(
        e.contains("bad.obj': vertex 2") && e.contains("not finite"),
        "{e}"
    );
}

#[test]
fn malformed_number() {
    let e = load(
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n<float name=\"fov\" value=\"abc\"/>\n</sensor>\n</scene>",
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "dir/test.xml:3: <float name=\"fov\" value=\"abc\">: expected a number, found \"abc\""
    );
}

#[test]
fn nan_parameter() {
    let e = m3_err(
        r#"<shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.5, NaN, 0.5"/></bsdf></shape>"#,
    );
    assert!(e.starts_with("dir/test.xml:2: <rgb name=\"reflectance\" value=\"0.5, NaN, 0.5\">: expected a finite number"), "{e}");
    let e = m3_err(r#"<shape type="sphere"><float name="radius" value="inf"/></shape>"#);
    assert!(
        e.starts_with("dir/test.xml:2: <float name=\"radius\" value=\"inf\">"),
        "{e}"
    );
    let e = m3_err(r#"<shape type="sphere"><point name="center" x="nan"/></shape>"#);
    assert!(
        e.contains("test.xml:2: <point name=\"center\" x=\"nan\">") && e.contains("finite"),
        "{e}"
    );
}

#[test]
fn unknown_plugin_and_parameter() {
    let e = m3_err(r#"<shape type="teapot"/>"#);
    assert!(
        e.starts_with("dir/test.xml:2: <shape type=\"teapot\">: unknown shape type 'teapot'"),
        "{e}"
    );
    let e = m3_err(
        r#"<shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectence" value="0.5"/></bsdf></shape>"#,
    );
    assert!(
        e.starts_with("dir/test.xml:2: <rgb name=\"reflectence\" value=\"0.5\">: unknown parameter 'reflectence' for bsdf 'diffuse'"),
        "{e}"
    );
    let e = m3_err(r#"<shape type="ply"/>"#);
    assert!(e.contains("shape 'ply' is not supported yet"), "{e}");
    let e = m3_err(r#"<gizmo/>"#);
    assert!(
        e.starts_with("dir/test.xml:2: <gizmo>: unknown element <gizmo>"),
        "{e}"
    );
    let e = m3_err(r#"<shape type="rectangle" colour="red"/>"#);
    assert!(e.contains("unexpected attribute 'colour'"), "{e}");
    let e = m3_err(r#"<integrator type="path"/>"#);
    assert!(e.starts_with("dir/test.xml:2: <integrator type=\"path\">: integrator 'path' renders global illumination"), "{e}");
    let e = m3_err(r#"<integrator type="bdpt"/>"#);
    assert!(e.starts_with("dir/test.xml:2: <integrator type=\"bdpt\">: only direct illumination is supported; found integrator 'bdpt'"), "{e}");
}

#[test]
fn undefined_variable() {
    let e = m3_err(r#"<shape type="sphere"><float name="radius" value="$r"/></shape>"#);
    assert!(
        e.starts_with("dir/test.xml:2: <float name=\"radius\" value=\"$r\">: '$r' is not defined"),
        "{e}"
    );
}

#[test]
fn no_emitters() {
    let e = load(&format!(
        "<scene version=\"3.0.0\">\n{SENSOR}<shape type=\"cube\"/></scene>"
    ))
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "dir/test.xml:1: <scene version=\"3.0.0\">: scene has no emitters; directlab renders direct illumination only"
    );
}

#[test]
fn no_sensor_and_malformed_xml() {
    let e = load(&format!("<scene version=\"3.0.0\">{LIGHT}</scene>"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dir/test.xml:1: <scene") && e.contains("no <sensor>"),
        "{e}"
    );
    let e = load("<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("dir/test.xml:3: malformed XML") && e.contains("shape"),
        "{e}"
    );
    let e = load("<scene version=\"1.0\"/>").unwrap_err().to_string();
    assert!(e.contains("unsupported scene version"), "{e}");
}

/// Emitters that emit nothing (an area light of zero radiance, a point light of zero
/// intensity) are warnings that name the element and say which emitter choices never pick
/// them; the scene still renders.
#[test]
fn emitters_that_emit_nothing_are_named() {
    let xml = format!(
        "<scene version=\"3.0.0\">{SENSOR}\n{}\n<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"0\"/></emitter></shape>\n{LIGHT}\n</scene>",
        r#"<emitter type="point"><point name="position" value="0,1,0"/><rgb name="intensity" value="0"/></emitter>"#
    );
    let scene = crate::scene::Scene::build(load(&xml).unwrap()).unwrap();
    for (line, what) in [
        (2, "point light has zero intensity"),
        (3, "emitter has zero radiance"),
    ] {
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains(&format!("test.xml:{line}"))
                    && w.contains(what)
                    && w.contains("never pick it")),
            "{what}: {:?}",
            scene.warnings
        );
    }
}
