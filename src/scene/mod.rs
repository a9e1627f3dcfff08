//! Scene loading: XML readers for Mitsuba 3, Mitsuba 0.6 and Nori, producing a `SceneDesc`.

mod bsdf;
pub mod desc;
pub mod error;
pub mod loader;
pub mod mesh;
pub mod props;
pub mod transform;
pub mod xml;

pub use error::SceneError;
pub use loader::{load_scene, load_scene_str, Dialect};

#[cfg(test)]
mod bundled_tests;
