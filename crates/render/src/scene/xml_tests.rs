//! Tests of the XML reader (`xml.rs`).

use super::*;

fn parse(xml: &str, defines: &[(&str, &str)]) -> Result<Element, SceneError> {
    let d: Vec<(String, String)> = defines
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    parse_document(xml, Path::new("t.xml"), &d)
}

#[test]
fn numbers() {
    assert_eq!(parse_float(" 1.5 "), Ok(1.5));
    assert!(parse_float("abc")
        .unwrap_err()
        .contains("expected a number"));
    assert!(parse_float("nan").unwrap_err().contains("finite"));
    assert!(parse_float("inf").unwrap_err().contains("finite"));
    assert_eq!(parse_floats("1, 2 3,4"), Ok(vec![1.0, 2.0, 3.0, 4.0]));
    assert_eq!(parse_vec3("2"), Ok([2.0; 3]));
    assert!(parse_vec3("1 2").is_err());
    assert_eq!(parse_bool("TRUE"), Ok(true));
    assert!(parse_bool("yes").is_err());
    assert_eq!(parse_int("12"), Ok(12));
    assert!(parse_int("1.5").is_err());
}

#[test]
fn names_normalize_to_snake_case() {
    assert_eq!(normalize_name("toWorld"), "to_world");
    assert_eq!(normalize_name("intIOR"), "int_ior");
    assert_eq!(normalize_name("sampleCount"), "sample_count");
    assert_eq!(normalize_name("alphaU"), "alpha_u");
    assert_eq!(normalize_name("fov_axis"), "fov_axis");
}

#[test]
fn declared_parameters_lists_the_root_defaults_only() {
    let xml = r#"<scene><default name="res" value="8"/><default name="spp" value="$res"/>
        <shape type="sphere"><default name="inner" value="1"/></shape></scene>"#;
    assert_eq!(declared_parameters(xml), ["res", "spp"]);
    assert!(declared_parameters("<scene>").is_empty());
}

#[test]
fn defaults_substitute_and_defines_override() {
    let xml = r#"<scene version="3.0.0">
        <default name="res" value="256"/>
        <default name="spp" value="$res"/>
        <integer name="width" value="$res"/>
        <integer name="n" value="x$spp-$res"/>
    </scene>"#;
    let root = parse(xml, &[]).unwrap();
    assert_eq!(root.children[2].attr("value"), Some("256"));
    assert_eq!(root.children[3].attr("value"), Some("x256-256"));
    let root = parse(xml, &[("res", "64")]).unwrap();
    assert_eq!(root.children[2].attr("value"), Some("64"));
    // The override is seen by defaults that depend on it.
    assert_eq!(root.children[3].attr("value"), Some("x64-64"));
}

#[test]
fn undefined_parameter_is_reported_with_position() {
    let xml = "<scene version=\"3.0.0\">\n  <float name=\"fov\" value=\"$fov\"/>\n</scene>";
    let e = parse(xml, &[]).unwrap_err().to_string();
    assert!(
        e.starts_with("t.xml:2: <float name=\"fov\" value=\"$fov\">"),
        "{e}"
    );
    assert!(e.contains("'$fov' is not defined"), "{e}");
}

#[test]
fn malformed_xml_names_position() {
    let e = parse("<scene>\n<shape type=\"obj\">\n</scene>", &[])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.xml:3:"), "{e}");
    assert!(e.contains("shape"), "{e}");
}

/// The line of an offset is 1 + the newlines before it, whether offsets come in order
/// (short and long steps forward) or not.
#[test]
fn lines_of_offsets_in_any_order() {
    let text: String = (0..500)
        .map(|i| "x".repeat(i % 7) + "\n")
        .collect::<String>()
        + "tail";
    let lines = Lines::new(&text);
    let naive = |pos: usize| text[..pos].matches('\n').count() as u32 + 1;
    let forward: Vec<usize> = (0..text.len()).step_by(3).collect();
    let mut rng = crate::rng::Rng::new(7, 0);
    let random: Vec<usize> = (0..2000)
        .map(|_| (rng.next_f32() * text.len() as f32) as usize % text.len())
        .collect();
    for pos in forward.iter().chain(&random).chain(&[0, text.len() - 1]) {
        assert_eq!(lines.of(*pos), naive(*pos), "offset {pos}");
    }
}

#[test]
fn elements_remember_lines_and_attributes() {
    let root = parse(
        "<scene>\n\n  <bsdf type=\"diffuse\" id=\"a\"/>\n</scene>",
        &[],
    )
    .unwrap();
    let b = &root.children[0];
    assert_eq!(b.line, 3);
    assert_eq!(b.display(), "<bsdf type=\"diffuse\" id=\"a\">");
    assert!(b.check_attrs(&["type", "id"]).is_ok());
    let e = b.check_attrs(&["type"]).unwrap_err().to_string();
    assert!(e.contains("unexpected attribute 'id'"), "{e}");
}
