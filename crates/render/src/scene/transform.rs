//! `<transform>` elements: translate, scale, rotate, lookat and matrix, composed in document
//! order (the first listed is applied first, so M = T_n ... T_1), as in Mitsuba and Nori.

use super::error::SceneError;
use super::xml::{parse_floats, parse_vec3, Element};
use glam::{Mat3, Mat4, Vec3};

/// A `<transform>` element's matrix: its `translate`, `rotate`, `scale`, `matrix` and
/// `lookat` children, applied in document order.
pub fn parse_transform(elem: &Element) -> Result<Mat4, SceneError> {
    elem.check_attrs(&["name"])?;
    let mut m = Mat4::IDENTITY;
    for op in &elem.children {
        m = parse_op(op)? * m;
    }
    Ok(m)
}

fn parse_op(op: &Element) -> Result<Mat4, SceneError> {
    match op.tag.as_str() {
        "translate" => {
            op.check_attrs(&["x", "y", "z", "value"])?;
            Ok(Mat4::from_translation(Vec3::from(op.vec3_attrs(0.0)?)))
        }
        "scale" => {
            op.check_attrs(&["x", "y", "z", "value"])?;
            Ok(Mat4::from_scale(Vec3::from(op.vec3_attrs(1.0)?)))
        }
        "rotate" => {
            op.check_attrs(&["x", "y", "z", "axis", "angle"])?;
            let axis = match op.attr("axis") {
                Some(a) if ["x", "y", "z"].iter().any(|k| op.attr(k).is_some()) => {
                    return Err(op.err(format!(
                        "give the axis either as axis=\"{a}\" or as x/y/z attributes"
                    )))
                }
                Some(a) => Vec3::from(parse_vec3(a).map_err(|m| op.err(m))?),
                None => Vec3::from(op.vec3_attrs(0.0)?),
            };
            if axis.length_squared() == 0.0 {
                return Err(op.err("expected a non-zero rotation axis"));
            }
            let angle = op
                .float_attr("angle")?
                .ok_or_else(|| op.err("expected an 'angle' attribute (degrees)"))?;
            Ok(Mat4::from_axis_angle(axis.normalize(), angle.to_radians()))
        }
        "lookat" | "look_at" => {
            op.check_attrs(&["origin", "target", "up"])?;
            let get = |name: &str| -> Result<Option<Vec3>, SceneError> {
                op.attr(name)
                    .map(|v| parse_vec3(v).map(Vec3::from).map_err(|m| op.err(m)))
                    .transpose()
            };
            let origin = get("origin")?.ok_or_else(|| op.err("expected an 'origin' attribute"))?;
            let target = get("target")?.ok_or_else(|| op.err("expected a 'target' attribute"))?;
            look_at(origin, target, get("up")?).map_err(|m| op.err(m))
        }
        "matrix" => {
            op.check_attrs(&["value"])?;
            let v = parse_floats(op.required_attr("value")?).map_err(|m| op.err(m))?;
            match v.len() {
                // Row-major in the file; glam wants columns.
                16 => Ok(Mat4::from_cols_slice(&v).transpose()),
                9 => Ok(Mat4::from_mat3(Mat3::from_cols_slice(&v).transpose())),
                n => Err(op.err(format!("expected 16 (or 9) numbers, found {n}"))),
            }
        }
        other => Err(op.err(format!(
            "unknown transform operation <{other}>; expected translate, scale, rotate, lookat \
             or matrix"
        ))),
    }
}

/// Camera-style frame: columns left = up x dir, up' = dir x left, dir, origin. Camera space
/// then looks along +z with +x to the image's left, matching Mitsuba and Nori.
pub fn look_at(origin: Vec3, target: Vec3, up: Option<Vec3>) -> Result<Mat4, String> {
    let dir = target - origin;
    if dir.length_squared() == 0.0 {
        return Err("lookat origin and target coincide".into());
    }
    let dir = dir.normalize();
    // Mitsuba picks an arbitrary perpendicular up when none is given.
    let up = up.unwrap_or_else(|| dir.any_orthonormal_vector());
    let left = up.cross(dir);
    if left.length_squared() < 1e-12 * up.length_squared() {
        return Err("lookat 'up' is parallel to the viewing direction".into());
    }
    let left = left.normalize();
    let new_up = dir.cross(left);
    Ok(Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::xml::parse_document;
    use std::path::Path;

    fn transform(body: &str) -> Result<Mat4, SceneError> {
        let xml = format!("<scene><transform name=\"to_world\">{body}</transform></scene>");
        let root = parse_document(&xml, Path::new("t.xml"), &[]).unwrap();
        parse_transform(&root.children[0])
    }

    fn close(a: Mat4, b: Mat4) -> bool {
        a.abs_diff_eq(b, 1e-5)
    }

    #[test]
    fn ops_compose_in_document_order() {
        // scale first, then translate: p -> 2p + (1,0,0)
        let m = transform(r#"<scale value="2"/><translate x="1"/>"#).unwrap();
        assert!(m
            .transform_point3(Vec3::new(1.0, 1.0, 1.0))
            .abs_diff_eq(Vec3::new(3.0, 2.0, 2.0), 1e-6));
        let expected = Mat4::from_translation(Vec3::X) * Mat4::from_scale(Vec3::splat(2.0));
        assert!(close(m, expected));
        // the other order differs
        let m2 = transform(r#"<translate x="1"/><scale value="2"/>"#).unwrap();
        assert!(m2
            .transform_point3(Vec3::ZERO)
            .abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-6));
    }

    #[test]
    fn rotate_scale_translate_matrix() {
        let m = transform(
            r#"<rotate y="1" angle="90"/><scale x="1" y="2" z="3"/>
               <translate value="1, 2, 3"/><rotate axis="0,0,1" angle="180"/>"#,
        )
        .unwrap();
        let expected = Mat4::from_rotation_z(std::f32::consts::PI)
            * Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_scale(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2);
        assert!(close(m, expected), "{m:?}");
        // rotation about +y by 90 deg takes +z to +x (right-handed)
        let r = transform(r#"<rotate y="1" angle="90"/>"#).unwrap();
        assert!(r.transform_vector3(Vec3::Z).abs_diff_eq(Vec3::X, 1e-6));
        let s = transform(r#"<scale value="-1,1,1"/>"#).unwrap();
        assert!(close(s, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))));
    }

    #[test]
    fn matrix_is_row_major() {
        let m = transform(r#"<matrix value="1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1"/>"#).unwrap();
        assert!(close(m, Mat4::from_translation(Vec3::new(5.0, 6.0, 7.0))));
        let e = transform(r#"<matrix value="1 2 3"/>"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected 16"), "{e}");
        let e = transform(r#"<matrix value="1 0 0 nan 0 1 0 0 0 0 1 0 0 0 0 1"/>"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.xml:1: <matrix") && e.contains("finite"),
            "{e}"
        );
    }

    #[test]
    fn lookat_frame() {
        let m =
            transform(r#"<lookat origin="278, 273, -800" target="278, 273, -799" up="0, 1, 0"/>"#)
                .unwrap();
        assert!(m.col(0).truncate().abs_diff_eq(Vec3::X, 1e-6)); // left
        assert!(m.col(1).truncate().abs_diff_eq(Vec3::Y, 1e-6));
        assert!(m.col(2).truncate().abs_diff_eq(Vec3::Z, 1e-6));
        assert!(m
            .col(3)
            .abs_diff_eq(glam::Vec4::new(278.0, 273.0, -800.0, 1.0), 1e-4));
        // looking down -z: left is -x
        let m = transform(r#"<lookat origin="0,0,0" target="0,0,-1" up="0,1,0"/>"#).unwrap();
        assert!(m.col(0).truncate().abs_diff_eq(-Vec3::X, 1e-6));
        let e = transform(r#"<lookat origin="0,0,0" target="0,1,0" up="0,1,0"/>"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("parallel"), "{e}");
    }

    #[test]
    fn bad_ops_are_errors() {
        let e = transform(r#"<shear value="1"/>"#).unwrap_err().to_string();
        assert!(
            e.contains("<shear") && e.contains("unknown transform"),
            "{e}"
        );
        let e = transform(r#"<rotate y="1"/>"#).unwrap_err().to_string();
        assert!(e.contains("angle"), "{e}");
        let e = transform(r#"<translate x="abc"/>"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected a number, found \"abc\""), "{e}");
        let e = transform(r#"<translate q="1"/>"#).unwrap_err().to_string();
        assert!(e.contains("unexpected attribute 'q'"), "{e}");
    }
}
