//! Readers and writers of every file format, apart from the scene model they produce
//! ([`crate::scene`]): our RON scene, `.bpt` Bézier patch files, Wavefront OBJ (free-form
//! surfaces with trims, and polygon meshes or Catmull–Clark cages), pbrt-v3
//! `Shape "nurbs"`, glTF and GLB meshes, STL meshes (ASCII and binary), `trace` ray files, and the CAD exchange formats
//! IGES and STEP ([`cad`]), and USD stages ([`usd`]). Every reader reports errors as `file:line:col: what was
//! expected` (or the byte offset, record or entity of a binary or CAD file); every writer
//! writes to a temporary name and renames ([`crate::io`]).
//!
//! - [`load`]: choosing a reader by file type, bare geometry as a framed scene, and the
//!   checks every loaded scene passes (coordinates within `f32`, trim loops usable).
//! - [`error`]: located parse errors and load errors.
//! - [`text`]: the tokenizer the line-based text formats share.
//! - [`source_key`]: the digest of a scene's input files that a BVH file is checked against.
//! - [`ron_locate`]: where keys and variants are in a RON scene's text, for errors found
//!   after deserialising.
//! - [`write`](mod@write): writing a scene by the output's extension.
//! - [`sheet`]: a scene's surfaces as sheets of Bézier patches with their trims in the
//!   patches' parameters, which the OBJ free-form and IGES ([`iges_writer`]) writers write.

pub mod bpt;
pub mod cad;
pub mod cage;
pub mod error;
pub mod gltf_mesh;
pub mod iges_writer;
pub mod load;
pub mod mesh;
pub mod obj;
pub mod pbrt;
pub mod rays;
pub mod ron_format;
pub mod ron_locate;
pub mod sheet;
pub mod source_key;
pub mod stl;
pub mod text;
pub mod usd;
pub mod write;

pub use error::{LoadError, ParseError};
pub use load::{
    LoadOptions, load_geometry, load_scene, load_scene_keyed, load_scene_with, load_subdivision,
};
