//! Triangle meshes from OBJ (tobj) and glTF (gltf). PLACEHOLDER: filled in by the formats
//! work.

use std::path::Path;

use super::error::LoadError;
use super::model::TriangleMesh;

pub fn read_obj_mesh(path: &Path) -> Result<TriangleMesh, LoadError> {
    Err(LoadError::invalid(
        path,
        "OBJ meshes are not implemented yet",
    ))
}

pub fn read_gltf(path: &Path) -> Result<TriangleMesh, LoadError> {
    Err(LoadError::invalid(path, "glTF is not implemented yet"))
}
