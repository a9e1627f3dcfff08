//! Degenerate and invalid input: what must be rejected (with a message naming the problem)
//! and what must be accepted with a warning. The XML files live in `scenes/extreme/invalid`.

use crate::scene::desc::ShapeGeometry;
use crate::scene::{load_scene, Scene};
use glam::Vec3;
use std::path::Path;

pub struct Outcome {
    pub input: String,
    /// "error" or "warning": what the input must produce.
    pub expect: &'static str,
    /// The substring the message must contain.
    pub must_contain: &'static str,
    /// The message actually produced (empty if none).
    pub message: String,
    pub ok: bool,
}

/// Loads and builds `file`; returns (error, warnings).
fn try_scene(file: &Path) -> (Option<String>, Vec<String>) {
    match load_scene(file, &[]) {
        Err(e) => (Some(e.to_string()), vec![]),
        Ok(desc) => match Scene::build(desc) {
            Err(e) => (Some(e.to_string()), vec![]),
            Ok(s) => (None, s.warnings),
        },
    }
}

fn outcome(
    input: String,
    expect: &'static str,
    must_contain: &'static str,
    r: (Option<String>, Vec<String>),
) -> Outcome {
    let message = match (expect, r) {
        ("error", (Some(e), _)) => e,
        ("warning", (None, w)) => w.join("; "),
        (_, (Some(e), _)) => format!("unexpected error: {e}"),
        (_, (None, w)) => format!("no error (warnings: {w:?})"),
    };
    let ok = message.contains(must_contain) && !message.starts_with("unexpected");
    Outcome {
        input,
        expect,
        must_contain,
        message,
        ok,
    }
}

/// Every invalid-input check; `scenes` is `scenes/extreme`.
pub fn check_all(scenes: &Path) -> Vec<Outcome> {
    let files: [(&str, &'static str, &'static str); 6] = [
        ("invalid/nan-vertex.xml", "error", "is not finite"),
        (
            "invalid/inf-radiance.xml",
            "error",
            "expected a finite number",
        ),
        (
            "invalid/nan-sphere-centre.xml",
            "error",
            "expected a finite number",
        ),
        (
            "invalid/nan-roughness.xml",
            "error",
            "expected a finite number",
        ),
        (
            "invalid/all-degenerate-emitter.xml",
            "error",
            "zero total area",
        ),
        (
            "degenerate-emitter.xml",
            "warning",
            "2 zero-area triangle(s)",
        ),
    ];
    let mut v: Vec<Outcome> = files
        .iter()
        .map(|(f, expect, s)| outcome(f.to_string(), expect, s, try_scene(&scenes.join(f))))
        .collect();
    // Descriptions built in code bypass the XML reader: the build must check them itself.
    let mut desc = crate::scene::fixtures::furnace(0.5, false, 1);
    if let ShapeGeometry::Mesh { positions, .. } = &mut desc.shapes[0].geometry {
        positions[3] = Vec3::new(1.0, f32::INFINITY, 0.0);
    }
    let r = Scene::build(desc)
        .map(|s| s.warnings)
        .map_err(|e| e.to_string());
    v.push(outcome(
        "SceneDesc in code: infinite vertex".into(),
        "error",
        "non-finite vertex",
        (r.as_ref().err().cloned(), r.unwrap_or_default()),
    ));
    let mut desc = crate::scene::fixtures::furnace(0.5, true, 1);
    desc.shapes[2].emitter.as_mut().unwrap().radiance.y = f32::NAN;
    let r = Scene::build(desc)
        .map(|s| s.warnings)
        .map_err(|e| e.to_string());
    v.push(outcome(
        "SceneDesc in code: NaN radiance".into(),
        "error",
        "emitter radiance must be finite",
        (r.as_ref().err().cloned(), r.unwrap_or_default()),
    ));
    v
}
