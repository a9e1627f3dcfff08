//! Scene loading: XML readers for Mitsuba 3, Mitsuba 0.6 and Nori produce a `SceneDesc`;
//! `Scene::build` turns it into what the renderer uses (materials, emitters, sampling tables,
//! BVH).
//!
//! One reader serves the three dialects: `<scene version="3.x">` is Mitsuba 3 (2.x is read the
//! same way), `version="0.x"` is Mitsuba 0.6 and no version is Nori. Parameter names are
//! compared after camelCase -> snake_case normalisation, so `toWorld`/`to_world`,
//! `intIOR`/`int_ior` and `sampleCount`/`sample_count` are interchangeable, and Nori's element
//! names (`camera`, `mesh`, `color`) are accepted beside Mitsuba's (`sensor`, `shape`, `rgb`).
//! Only defaults differ by dialect (Nori: 1280x720 film, 1 spp, fov 30, near clip 1e-4,
//! balance heuristic; Mitsuba: 768x576, 4 spp, near clip 0.01, power heuristic).
//!
//! Supported plugins: integrator `direct` (+ Nori's `sampling` string, `direct_ems`,
//! `direct_mats`, `direct_mis`, and the direct part of path tracers under `--integrator
//! direct`); sensor `perspective` (fov, or Mitsuba's focal_length with its 50 mm default,
//! which is a diagonal fov); film `hdrfilm` (`ldrfilm` read as hdrfilm); rfilter `box`,
//! `tent`, `gaussian`; sampler: every registered [`crate::sampler::SamplerKind`] by its name,
//! Mitsuba's other samplers mapped to the nearest with a warning; bsdf: every registered BSDF
//! ([`crate::bsdf::REGISTERED`]) and `twosided`; shape `obj`, `rectangle`, `cube`, `sphere`;
//! emitter `area` (nested in a shape), `point`, `pointlight`.
//!
//! Everything else is an error naming the file, line and element: unknown types and
//! parameters, known-but-unsupported plugins ("not supported yet"), malformed or non-finite
//! numbers, undefined `$name`s, missing meshes. Harmless parameters (film output formats,
//! shutter times, sampling weights, ...) are ignored with a message in `SceneDesc::warnings`.
//!
//! Differences from Mitsuba 3 worth knowing: OBJ files without normals keep `normals: None`
//! (flat shading) where Mitsuba 3 would compute smooth vertex normals; conductor `material`
//! names cover Ag, Al, Au, Cr, Cu, W and none only; spectra must be constant.

mod bsdf;
pub mod build;
pub mod desc;
pub mod error;
pub mod fixtures;
pub mod loader;
pub mod mesh;
pub mod props;
pub mod scaling;
mod sensor;
pub mod transform;
pub mod xml;

pub use build::{BuildError, Scene};
pub use error::SceneError;
pub use loader::{load_scene, load_scene_str, Dialect};

#[cfg(test)]
mod bsdf_furnace_tests;
#[cfg(test)]
mod bsdf_ray_tests;
#[cfg(test)]
pub(crate) mod bundled_tests;
#[cfg(test)]
pub(crate) mod random;

/// Loads and builds a scene, printing its warnings to stderr. A film too large for this
/// machine's memory is refused here, before any render starts.
pub fn open(path: &std::path::Path, defines: &[(String, String)]) -> Result<Scene, String> {
    open_with(path, defines, None)
}

/// [`open`] with the integrator read as `mode` says; says so when a global-illumination
/// integrator was read as its direct part.
pub fn open_with(
    path: &std::path::Path,
    defines: &[(String, String)],
    mode: Option<loader::IntegratorMode>,
) -> Result<Scene, String> {
    let desc = loader::load_scene_with(path, defines, mode).map_err(|e| e.to_string())?;
    if let Some(t) = &desc.integrator.direct_part_of {
        eprintln!(
            "note: {}: integrator '{t}' read as its direct illumination (--integrator direct): \
             the image is the direct part only",
            path.display()
        );
    }
    let scene = Scene::build(desc).map_err(|e| e.to_string())?;
    crate::film::check_film_memory(scene.camera.width, scene.camera.height)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}
