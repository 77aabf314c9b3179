//! Triangle meshes: polygonal Wavefront OBJ (read by [`super::obj::parse_obj_mesh`]),
//! and the checks every mesh reader applies to its parts (indices in range,
//! finite positions). glTF and GLB are read by [`super::gltf_mesh`].

use std::path::Path;

use super::error::LoadError;
use crate::scene::model::TriangleMesh;

/// Reads a polygonal OBJ file as one mesh (all objects and groups merged), triangulating
/// faces ([`super::obj::parse_obj_mesh`]). Normals are kept when every vertex has one.
pub fn read_obj_mesh(path: &Path) -> Result<TriangleMesh, LoadError> {
    let src = super::error::read_text(path)?;
    let part = super::obj::parse_obj_mesh(path, &src)?;
    let mut mesh = TriangleMesh::default();
    append(path, &mut mesh, part, "OBJ mesh")?;
    finish(path, mesh, "faces (`f`)")
}

/// Appends `part` to `mesh`, checking its indices. Normals are kept only when every part
/// has them.
pub(super) fn append(
    path: &Path,
    mesh: &mut TriangleMesh,
    mut part: TriangleMesh,
    label: &str,
) -> Result<(), LoadError> {
    let count = part.positions.len();
    if let Some(bad) = part
        .indices
        .iter()
        .flatten()
        .find(|&&i| i as usize >= count)
    {
        return Err(LoadError::invalid(
            path,
            format!("{label}: vertex index {bad} is out of range ({count} vertices)"),
        ));
    }
    if part.positions.iter().any(|p| !p.is_finite()) {
        return Err(LoadError::invalid(
            path,
            format!("{label}: expected finite vertex positions"),
        ));
    }
    let base = u32::try_from(mesh.positions.len())
        .map_err(|_| LoadError::invalid(path, "mesh has more than 2^32 vertices"))?;
    let had_normals = mesh.normals.len() == mesh.positions.len();
    let keep_normals = had_normals && part.normals.len() == count;
    mesh.positions.append(&mut part.positions);
    if keep_normals {
        mesh.normals.append(&mut part.normals);
    } else {
        mesh.normals.clear();
    }
    mesh.indices
        .extend(part.indices.iter().map(|t| t.map(|i| i + base)));
    Ok(())
}

pub(super) fn finish(
    path: &Path,
    mesh: TriangleMesh,
    what: &str,
) -> Result<TriangleMesh, LoadError> {
    if mesh.indices.is_empty() {
        return Err(LoadError::invalid(
            path,
            format!("expected at least one triangle (from {what}), found none"),
        ));
    }
    Ok(mesh)
}
