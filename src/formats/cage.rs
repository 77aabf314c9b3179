//! Catmull–Clark control cages: the polygons of a Wavefront OBJ file (`v` and `f`
//! statements, faces kept as written, not triangulated) or the triangles of a glTF mesh,
//! turned into a [`SubdivisionSurface`]. Cages that are not manifold polygon meshes with
//! consistent winding are refused with the reason ([`CageError`]).

use std::path::Path;

use glam::DVec3;

use super::error::{LoadError, ParseError, read_text};
use super::text::{Words, logical_lines};
use crate::geom::subdiv::SubdivisionSurface;
use crate::scene::model::TriangleMesh;

/// Reads an OBJ file's polygons as a cage. Statements other than `v` and `f` (normals,
/// texture coordinates, groups, materials, smoothing) do not shape the surface and are
/// skipped; `f` accepts `v`, `v/vt`, `v//vn` and `v/vt/vn` corners and negative
/// (relative) indices.
pub fn read_obj_cage(path: &Path) -> Result<SubdivisionSurface, LoadError> {
    let src = read_text(path)?;
    let (points, faces) = parse_obj_polygons(path, &src)?;
    surface(path, points, faces)
}

/// The cage of a triangle mesh (glTF): positions that are bitwise equal are one vertex,
/// so seams that glTF splits for normals or texture coordinates stay closed.
pub fn mesh_cage(path: &Path, mesh: &TriangleMesh) -> Result<SubdivisionSurface, LoadError> {
    let mut index = std::collections::HashMap::new();
    let mut points = Vec::new();
    let mut remap = Vec::with_capacity(mesh.positions.len());
    for p in &mesh.positions {
        let key = p.to_array().map(f64::to_bits);
        let i = *index.entry(key).or_insert_with(|| {
            points.push(*p);
            points.len() as u32 - 1
        });
        remap.push(i);
    }
    let faces = mesh
        .indices
        .iter()
        .map(|t| t.iter().map(|&i| remap[i as usize]).collect())
        .collect();
    surface(path, points, faces)
}

fn surface(
    path: &Path,
    points: Vec<DVec3>,
    faces: Vec<Vec<u32>>,
) -> Result<SubdivisionSurface, LoadError> {
    SubdivisionSurface::new(points, faces)
        .map_err(|e| LoadError::invalid(path, format!("Catmull–Clark cage: {e}")))
}

/// The vertices and polygons of an OBJ text.
pub fn parse_obj_polygons(
    path: &Path,
    src: &str,
) -> Result<(Vec<DVec3>, Vec<Vec<u32>>), ParseError> {
    let (lines, eof) = logical_lines(src);
    let mut points = Vec::new();
    let mut faces = Vec::new();
    for line in &lines {
        let mut words = Words::new(path, line);
        let Some(keyword) = words.next_opt() else {
            continue;
        };
        match keyword.text {
            "v" => {
                let x = words.finite("x coordinate")?;
                let y = words.finite("y coordinate")?;
                let z = words.finite("z coordinate")?;
                // An optional weight is allowed by OBJ and meaningless for a cage.
                words.finite_opt("vertex weight")?;
                words.expect_end()?;
                points.push(DVec3::new(x, y, z));
            }
            "f" => {
                let mut face = Vec::new();
                for tok in words.rest() {
                    let first = tok.text.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        words.error_at(
                            tok,
                            format!("expected a vertex index, found `{}`", tok.text),
                        )
                    })?;
                    let count = points.len() as i64;
                    let resolved = if index < 0 { count + index } else { index - 1 };
                    if index == 0 || resolved < 0 || resolved >= count {
                        return Err(words.error_at(
                            tok,
                            format!(
                                "expected a vertex index in 1..={count} (or -1..=-{count}), found {index}"
                            ),
                        ));
                    }
                    face.push(resolved as u32);
                }
                if face.len() < 3 {
                    return Err(words.error_at_end(format!(
                        "expected a face of at least 3 vertices, found {}",
                        face.len()
                    )));
                }
                faces.push(face);
            }
            _ => {}
        }
    }
    if faces.is_empty() {
        return Err(ParseError::new(
            path,
            eof.0,
            eof.1,
            "expected at least one face (`f`) for a Catmull–Clark cage, found none",
        ));
    }
    Ok((points, faces))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_keep_their_corners_and_resolve_relative_indices() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2//1 3 -1\n";
        let (points, faces) = parse_obj_polygons(Path::new("c.obj"), src).unwrap();
        assert_eq!(points.len(), 4);
        assert_eq!(faces, vec![vec![0, 1, 2, 3]]);
    }

    #[test]
    fn bad_index_names_line_and_column() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 7\n";
        let e = parse_obj_polygons(Path::new("c.obj"), src).unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("c.obj:4:7:"), "{msg}");
        assert!(msg.contains("expected a vertex index in 1..=3"), "{msg}");
    }
}
