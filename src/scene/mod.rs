//! The scene model and one reader/writer per format: our RON scene, `.bpt` Bézier patch
//! files, Wavefront OBJ free-form surfaces, pbrt-v3 `Shape "nurbs"`, and triangle meshes
//! (polygonal OBJ, glTF and GLB), and IGES 5.3 CAD files (trimmed NURBS, exactly). Every reader
//! reports errors as `file:line:col: what was
//! expected`; every writer writes to a temporary name and renames.

pub mod animation;
pub mod bare_shell;
pub mod bpt;
pub mod cage;
pub mod convert;
pub mod error;
pub mod generate;
pub mod gltf_mesh;
pub mod iges;
pub mod load;
pub mod mesh;
pub mod model;
pub mod obj;
pub mod pbrt;
pub mod rays;
pub mod ron_format;
pub mod ron_locate;
pub mod source_key;
pub mod step;
pub mod summary;
pub mod text;
pub mod write;

pub use error::{LoadError, ParseError};
pub use load::{
    LoadOptions, load_geometry, load_scene, load_scene_keyed, load_scene_with, load_subdivision,
};
pub use model::*;
