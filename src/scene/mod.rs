//! The scene model: camera (and its animation), lights, materials, and objects whose
//! geometry is free-form surfaces (Bézier, NURBS, trimmed), Catmull–Clark cages, triangle
//! meshes or instances of shared geometry. Files are read into it and written from it by
//! [`crate::formats`].
//!
//! - [`model`]: the types, framing of bare geometry, and per-object queries.
//! - [`animation`]: turntables and camera keyframes.
//! - [`convert`]: NURBS surfaces of a scene to their Bézier patches (Dammertz §2.8).
//! - [`origin`]: the floating origin that keeps far-away scenes' `f32` coordinates fine.
//! - [`bare_shell`]: what a BVH file keeps of a bare geometry file's scene.
//! - [`summary`]: the counts, bounds and degrees `info` reports.
//! - [`generate`]: the randomly scattered teapot scenes of LG90 §7.

pub mod animation;
pub mod bare_shell;
pub mod convert;
pub mod generate;
pub mod model;
pub mod origin;
pub mod summary;

pub use model::*;
