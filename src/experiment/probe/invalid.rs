//! Degenerate and invalid input: what must be rejected (with a message naming the problem)
//! and what must be accepted with a warning, as an experiment's `[[invalid]]` entries and its
//! cases' `warning`s state.

use crate::scene::{load_scene, Scene};
use std::path::Path;

/// One documented outcome and what actually happened.
#[derive(Clone, Debug)]
pub struct Check {
    pub input: String,
    /// "error" or "warning": what the input must produce.
    pub expect: &'static str,
    /// The substring the message must contain.
    pub must_contain: String,
    /// The message actually produced (empty if none).
    pub message: String,
    pub ok: bool,
}

/// Loads and builds a scene: its error, or its warnings.
pub fn try_scene(file: &Path, defines: &[(String, String)]) -> Result<Vec<String>, String> {
    let desc = load_scene(file, defines).map_err(|e| e.to_string())?;
    Scene::build(desc)
        .map(|s| s.warnings)
        .map_err(|e| e.to_string())
}

/// Compares an outcome with the expected error or warning.
pub fn check(
    input: String,
    expect: &'static str,
    must_contain: &str,
    outcome: Result<Vec<String>, String>,
) -> Check {
    let (message, right_kind) = match (expect, outcome) {
        ("error", Err(e)) => (e, true),
        ("warning", Ok(w)) => (w.join("; "), true),
        (_, Err(e)) => (format!("unexpected error: {e}"), false),
        (_, Ok(w)) => (format!("no error (warnings: {w:?})"), false),
    };
    Check {
        input,
        expect,
        must_contain: must_contain.to_string(),
        ok: right_kind && message.contains(must_contain),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::ShapeGeometry;
    use glam::Vec3;

    fn build(desc: crate::scene::desc::SceneDesc) -> Result<Vec<String>, String> {
        Scene::build(desc)
            .map(|s| s.warnings)
            .map_err(|e| e.to_string())
    }

    /// Descriptions built in code bypass the XML reader: the build must check them itself.
    #[test]
    fn scene_descriptions_in_code_with_non_finite_input_are_rejected() {
        let mut desc = crate::scene::fixtures::furnace(0.5, false, 1);
        if let ShapeGeometry::Mesh { positions, .. } = &mut desc.shapes[0].geometry {
            positions[3] = Vec3::new(1.0, f32::INFINITY, 0.0);
        }
        let c = check(
            "infinite vertex".into(),
            "error",
            "non-finite vertex",
            build(desc),
        );
        assert!(c.ok, "{c:?}");
        let mut desc = crate::scene::fixtures::furnace(0.5, true, 1);
        desc.shapes[2].emitter.as_mut().unwrap().radiance.y = f32::NAN;
        let c = check(
            "NaN radiance".into(),
            "error",
            "emitter radiance must be finite",
            build(desc),
        );
        assert!(c.ok, "{c:?}");
    }

    #[test]
    fn the_wrong_kind_of_outcome_fails_even_with_the_right_words() {
        let c = check("x".into(), "warning", "zero", Err("zero area".into()));
        assert!(!c.ok);
        let c = check(
            "x".into(),
            "error",
            "zero",
            Ok(vec!["zero radiance".into()]),
        );
        assert!(!c.ok);
        let c = check(
            "x".into(),
            "warning",
            "zero",
            Ok(vec!["zero radiance".into()]),
        );
        assert!(c.ok);
    }
}
