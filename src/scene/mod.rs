//! Scene loading: XML readers for Mitsuba 3, Mitsuba 0.6 and Nori, producing a `SceneDesc`.

pub mod desc;
pub mod error;
pub mod mesh;
pub mod props;
pub mod transform;
pub mod xml;

pub use error::SceneError;
