//! Polygonal OBJ (Wavefront *Advanced Visualizer* manual, Appendix B1 "Object Files":
//! `v`, `vt`, `vn`, `f`) read as one triangle mesh: faces triangulated as fans from their
//! first corner, one vertex per distinct (position, normal) pair, normals kept when every
//! corner has one. Our own reader instead of `tobj` so that every error says where it is
//! ("the OBJ mesh reader cannot tell the line"): each reference is checked
//! against the vertices defined before it (relative indices count back from there).
//! Statements without geometry (`o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, …) are
//! skipped.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::super::error::ParseError;
use super::super::model::TriangleMesh;
use super::super::text::{LogicalLine, Token, Words, logical_lines};

/// Parses a polygonal OBJ text with at least one face.
pub fn parse_obj_mesh(path: &Path, src: &str) -> Result<TriangleMesh, ParseError> {
    let (lines, eof) = logical_lines(src);
    let mut positions: Vec<DVec3> = Vec::new();
    let mut normals: Vec<DVec3> = Vec::new();
    let mut texcoords = 0usize;
    let mut mesh = TriangleMesh::default();
    let mut mesh_normals: Vec<DVec3> = Vec::new();
    let mut all_have_normals = true;
    let mut corners: HashMap<(u32, Option<u32>), u32> = HashMap::new();
    for line in &lines {
        let mut w = Words::new(path, line);
        let Some(keyword) = w.next_opt() else {
            continue;
        };
        match keyword.text {
            "v" => {
                let p = point(&mut w)?;
                // An optional weight (rational vertices of free-form geometry) is ignored.
                w.finite_opt("w")?;
                w.expect_end()?;
                positions.push(p);
            }
            "vn" => {
                let n = point(&mut w)?;
                w.expect_end()?;
                normals.push(n);
            }
            "vt" => {
                w.rest();
                texcoords += 1;
            }
            "f" | "fo" => {
                let refs = face(
                    path,
                    line,
                    &mut w,
                    (positions.len(), texcoords, normals.len()),
                )?;
                let mut ids = Vec::with_capacity(refs.len());
                for (v, n) in refs {
                    all_have_normals &= n.is_some();
                    let next = u32::try_from(mesh.positions.len()).map_err(|_| {
                        ParseError::new(
                            path,
                            keyword.line,
                            keyword.column,
                            "expected at most 2^32 vertices",
                        )
                    })?;
                    let id = *corners.entry((v, n)).or_insert_with(|| {
                        mesh.positions.push(positions[v as usize]);
                        mesh_normals.push(n.map_or(DVec3::ZERO, |n| normals[n as usize]));
                        next
                    });
                    ids.push(id);
                }
                for k in 1..ids.len() - 1 {
                    mesh.indices.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            _ => {
                w.rest();
            }
        }
    }
    if mesh.indices.is_empty() {
        return Err(ParseError::new(
            path,
            eof.0,
            eof.1,
            "expected at least one face (`f`), found none",
        ));
    }
    if all_have_normals {
        mesh.normals = mesh_normals;
    }
    Ok(mesh)
}

fn point(w: &mut Words) -> Result<DVec3, ParseError> {
    Ok(DVec3::new(w.finite("x")?, w.finite("y")?, w.finite("z")?))
}

/// The corners of a face as (position, normal) indices from 0, checked against the counts
/// of positions, texture coordinates and normals defined so far.
fn face(
    path: &Path,
    line: &LogicalLine,
    w: &mut Words,
    (nv, nt, nn): (usize, usize, usize),
) -> Result<Vec<(u32, Option<u32>)>, ParseError> {
    let corners = w.rest();
    if corners.len() < 3 {
        return Err(ParseError::new(
            path,
            line.end.0,
            line.end.1,
            format!(
                "expected a face of at least 3 corners `v`, `v/vt`, `v//vn` or `v/vt/vn`, found {}",
                corners.len()
            ),
        ));
    }
    corners
        .iter()
        .map(|tok| {
            let mut parts = tok.text.split('/');
            let v = reference(path, tok, parts.next(), nv, "vertex")?.ok_or_else(|| {
                ParseError::new(path, tok.line, tok.column, "expected a vertex index")
            })?;
            reference(path, tok, parts.next(), nt, "texture vertex")?;
            let n = reference(path, tok, parts.next(), nn, "normal")?;
            if parts.next().is_some() {
                return Err(ParseError::new(
                    path,
                    tok.line,
                    tok.column,
                    format!("expected `v/vt/vn` at most, found `{}`", tok.text),
                ));
            }
            Ok((v, n))
        })
        .collect()
}

/// One index of a corner (absent or empty: `None`), from 1, or negative counting back
/// from the last of the `count` defined so far; returned from 0.
fn reference(
    path: &Path,
    tok: &Token,
    text: Option<&str>,
    count: usize,
    what: &str,
) -> Result<Option<u32>, ParseError> {
    let Some(text) = text.filter(|t| !t.is_empty()) else {
        return Ok(None);
    };
    let err = |m: String| ParseError::new(path, tok.line, tok.column, m);
    let i: i64 = text
        .parse()
        .map_err(|_| err(format!("expected a {what} index, found `{text}`")))?;
    let resolved = if i > 0 { i - 1 } else { count as i64 + i };
    if i == 0 || resolved < 0 || resolved >= count as i64 {
        return Err(err(format!(
            "{what} index {i} is out of range: {count} defined so far"
        )));
    }
    Ok(Some(resolved as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_become_fans_and_corners_are_shared() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\nf -4//1 -2//1 -1//1\n";
        let m = parse_obj_mesh(Path::new("q.obj"), src).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.normals, vec![DVec3::Z; 4]);
        // A corner without a normal drops all normals.
        let m = parse_obj_mesh(
            Path::new("q.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2 3\n",
        )
        .unwrap();
        assert!(m.normals.is_empty());
    }

    #[test]
    fn bad_faces_are_located() {
        let p = Path::new("b.obj");
        let cases = [
            (
                "v 0 0 0\nf 1 2 3\n",
                (2, 5),
                "vertex index 2 is out of range: 1 defined so far",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
                (4, 7),
                "vertex index 0 is out of range",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                (4, 7),
                "vertex index -4 is out of range",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1\n",
                (4, 7),
                "texture vertex index 1 is out of range",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
                (4, 7),
                "expected a vertex index, found `x`",
            ),
            (
                "v 0 0 0\nf 1 1\n",
                (2, 6),
                "expected a face of at least 3 corners",
            ),
            ("v 0 nan 0\n", (1, 5), "expected y as a finite number"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3///\n",
                (4, 7),
                "expected `v/vt/vn` at most",
            ),
        ];
        for (src, place, message) in cases {
            let e = parse_obj_mesh(p, src).unwrap_err();
            assert_eq!((e.line, e.column), place, "{src:?}: {e}");
            assert!(e.message.starts_with(message), "{src:?}: {e}");
        }
    }
}
