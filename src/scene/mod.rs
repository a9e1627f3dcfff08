//! Scene loading: XML readers for Mitsuba 3, Mitsuba 0.6 and Nori produce a `SceneDesc`;
//! `Scene::build` turns it into what the renderer uses.

pub mod build;
pub mod desc;
pub mod fixtures;

pub use build::{BuildError, Scene};
