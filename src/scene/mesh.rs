//! Triangle meshes: polygonal Wavefront OBJ (via `tobj`, triangulated, one index per
//! vertex) and glTF 2.0 / GLB (via `gltf`: positions, normals and indices of every
//! triangle primitive in the default scene, with node transforms applied).

use std::path::Path;

use glam::{DAffine3, DMat4, DVec3};

use super::error::LoadError;
use super::model::TriangleMesh;

/// Reads a polygonal OBJ file as one mesh (all objects and groups merged), triangulating
/// faces. Normals are kept when every vertex has one.
pub fn read_obj_mesh(path: &Path) -> Result<TriangleMesh, LoadError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Missing or broken material libraries do not matter for geometry, so the material
    // result is dropped.
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| {
        LoadError::invalid(
            path,
            format!("OBJ mesh: {e} (the OBJ mesh reader cannot tell the line)"),
        )
    })?;
    let mut mesh = TriangleMesh::default();
    for model in &models {
        let m = &model.mesh;
        let positions = triples(&m.positions);
        let normals = triples(&m.normals);
        let part = TriangleMesh {
            normals: if normals.len() == positions.len() {
                normals
            } else {
                Vec::new()
            },
            positions,
            indices: m
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        };
        append(path, &mut mesh, part, &model.name)?;
    }
    finish(path, mesh, "faces (`f`)")
}

/// Reads a glTF (`.gltf` with embedded or external buffers) or GLB file as one mesh.
pub fn read_gltf(path: &Path) -> Result<TriangleMesh, LoadError> {
    let gltf_error = |e: gltf::Error| LoadError::invalid(path, format!("glTF: {e}"));
    let gltf = gltf::Gltf::open(path).map_err(gltf_error)?;
    let buffers = gltf::import_buffers(&gltf.document, path.parent(), gltf.blob.clone())
        .map_err(gltf_error)?;
    let mut mesh = TriangleMesh::default();
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next());
    let mut stack: Vec<(gltf::Node, DMat4)> = match &scene {
        Some(s) => s.nodes().map(|n| (n, DMat4::IDENTITY)).collect(),
        None => Vec::new(),
    };
    while let Some((node, parent)) = stack.pop() {
        let local = glam::Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let world = parent * local;
        stack.extend(node.children().map(|c| (c, world)));
        let Some(m) = node.mesh() else { continue };
        let name = m.name().unwrap_or("").to_string();
        for (k, primitive) in m.primitives().enumerate() {
            let label = format!("mesh {} (\"{name}\") primitive {k}", m.index());
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                return Err(LoadError::invalid(
                    path,
                    format!(
                        "glTF {label}: expected triangles, found mode {:?}",
                        primitive.mode()
                    ),
                ));
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<DVec3> = reader
                .read_positions()
                .ok_or_else(|| {
                    LoadError::invalid(path, format!("glTF {label}: expected POSITION"))
                })?
                .map(|p| glam::Vec3::from(p).as_dvec3())
                .collect();
            let normals: Vec<DVec3> = reader
                .read_normals()
                .map(|n| n.map(|n| glam::Vec3::from(n).as_dvec3()).collect())
                .unwrap_or_default();
            let flat: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            let mut part = TriangleMesh {
                positions,
                normals,
                indices: flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            };
            part.transform(&DAffine3::from_mat4(world));
            append(path, &mut mesh, part, &label)?;
        }
    }
    finish(path, mesh, "triangle primitives")
}

/// Appends `part` to `mesh`, checking its indices. Normals are kept only when every part
/// has them.
fn append(
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

fn finish(path: &Path, mesh: TriangleMesh, what: &str) -> Result<TriangleMesh, LoadError> {
    if mesh.indices.is_empty() {
        return Err(LoadError::invalid(
            path,
            format!("expected at least one triangle (from {what}), found none"),
        ));
    }
    Ok(mesh)
}

/// Packed `x y z` values as points.
fn triples<T: Copy + Into<f64>>(values: &[T]) -> Vec<DVec3> {
    values
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0].into(), c[1].into(), c[2].into()))
        .collect()
}
