//! AP242 tessellated geometry (ISO 10303-42 §7, the tessellated schema) as triangles:
//! TESSELLATED_SOLID and TESSELLATED_SHELL (their tessellated faces), TRIANGULATED_FACE,
//! COMPLEX_TRIANGULATED_FACE, TRIANGULATED_SURFACE_SET and COMPLEX_TRIANGULATED_SURFACE_SET,
//! over the points of a COORDINATES_LIST.
//!
//! Indices are 1-based. A non-empty `pnindex` maps the item's own point numbers
//! (1..=pnmax) to positions in the coordinates list; an empty one means the item numbers
//! the list directly. `normals` holds none, one for every point (a flat face) or one per
//! point. A triangle strip (p1, p2, p3, p4, …) is the triangles (p1, p2, p3), (p3, p2, p4),
//! … turning alternately so that all face the same way; a fan (p1, p2, p3, p4, …) is
//! (p1, p2, p3), (p1, p3, p4), …; triangles repeating a point are dropped, as
//! OpenCASCADE's StepToTopoDS_TranslateFace drops them.

use glam::DVec3;

use super::entities::{Rec, Resolver};
use super::records::{Instance, Param};
use crate::formats::error::ParseError;
use crate::scene::model::TriangleMesh;

/// Reads a tessellated item's triangles, in the file's length unit.
pub fn read(res: &Resolver, inst: &Instance) -> Result<TriangleMesh, ParseError> {
    let mut mesh = TriangleMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        indices: Vec::new(),
    };
    if let Some(r) = ["TESSELLATED_SOLID", "TESSELLATED_SHELL"]
        .iter()
        .find_map(|n| res.named(inst, n))
    {
        for id in r.references(1, "tessellated items")? {
            let item = res.instance(&r, id)?;
            // Tessellated edges and vertices (the same solid's boundaries) carry no area.
            if item.record("TESSELLATED_EDGE").is_some()
                || item.record("TESSELLATED_VERTEX").is_some()
            {
                continue;
            }
            let face = triangulated(res, item).unwrap_or_else(|| {
                Err(res.unsupported(
                    &r,
                    &format!(
                        "tessellated faces (TRIANGULATED_FACE, COMPLEX_TRIANGULATED_FACE), found #{id} {}",
                        item.type_name()
                    ),
                ))
            })?;
            append(&mut mesh, face);
        }
        return Ok(mesh);
    }
    let face = triangulated(res, inst).unwrap_or_else(|| {
        Err(res.unsupported(&res.rec(inst), "a triangulated face or surface set"))
    })?;
    append(&mut mesh, face);
    Ok(mesh)
}

/// Appends `b` to `a`, keeping normals only where every part has them.
fn append(a: &mut TriangleMesh, b: TriangleMesh) {
    let base = a.positions.len() as u32;
    let normals = (a.positions.is_empty() || a.normals.len() == a.positions.len())
        && b.normals.len() == b.positions.len();
    a.positions.extend(b.positions);
    if normals {
        a.normals.extend(b.normals);
    } else {
        a.normals.clear();
    }
    a.indices
        .extend(b.indices.iter().map(|t| t.map(|i| i + base)));
}

/// A triangulated face or surface set; `None` for other instances.
fn triangulated(res: &Resolver, inst: &Instance) -> Option<Result<TriangleMesh, ParseError>> {
    // (name, coordinates, pnmax, normals, [geometric_link,] pnindex, then triangles or
    // strips and fans): faces carry a geometric link, sets do not.
    let (r, pnindex, complex) = [
        ("TRIANGULATED_FACE", 5, false),
        ("COMPLEX_TRIANGULATED_FACE", 5, true),
        ("TRIANGULATED_SURFACE_SET", 4, false),
        ("COMPLEX_TRIANGULATED_SURFACE_SET", 4, true),
    ]
    .iter()
    .find_map(|&(n, p, c)| res.named(inst, n).map(|r| (r, p, c)))?;
    Some(res.deeper(&r, || mesh(res, &r, pnindex, complex)))
}

fn indices(r: &Rec, p: &Param, what: &str) -> Result<Vec<i64>, ParseError> {
    r.list_of(p, what)?
        .iter()
        .map(|q| r.integer(q, what))
        .collect()
}

fn mesh(
    res: &Resolver,
    r: &Rec,
    pnindex_at: usize,
    complex: bool,
) -> Result<TriangleMesh, ParseError> {
    let list = res.follow(r, 1, &["COORDINATES_LIST"])?;
    let coords: Vec<DVec3> = list
        .list(2, "position coordinates")?
        .iter()
        .map(|p| {
            let c = list.numbers(p, "coordinates")?;
            match c[..] {
                [x, y, z] => Ok(DVec3::new(x, y, z)),
                _ => Err(list.error_at(
                    p.line,
                    p.column,
                    format!("expected 3 coordinates, found {}", c.len()),
                )),
            }
        })
        .collect::<Result<_, _>>()?;
    let pnindex = indices(r, r.param(pnindex_at, "pnindex")?, "point indices")?;
    let positions: Vec<DVec3> = if pnindex.is_empty() {
        coords
    } else {
        pnindex
            .iter()
            .map(|&k| {
                usize::try_from(k - 1)
                    .ok()
                    .and_then(|k| coords.get(k).copied())
                    .ok_or_else(|| {
                        r.error(format!(
                            "pnindex {k} is outside the coordinates list's 1..={}",
                            coords.len()
                        ))
                    })
            })
            .collect::<Result<_, _>>()?
    };
    let normals_p = r.param(3, "normals")?;
    let given: Vec<DVec3> = r
        .list_of(normals_p, "normals")?
        .iter()
        .map(|p| {
            let n = r.numbers(p, "a normal")?;
            match n[..] {
                [x, y, z] => Ok(DVec3::new(x, y, z).normalize_or_zero()),
                _ => Err(r.error_at(p.line, p.column, "expected a normal of 3 numbers")),
            }
        })
        .collect::<Result<_, _>>()?;
    let normals = match given.len() {
        0 => Vec::new(),
        1 => vec![given[0]; positions.len()],
        n if n == positions.len() => given,
        n => {
            return Err(r.error_at(
                normals_p.line,
                normals_p.column,
                format!(
                    "expected no normal, one, or one per point ({}), found {n}",
                    positions.len()
                ),
            ));
        }
    };
    let point = |k: i64| -> Result<u32, ParseError> {
        if k >= 1 && (k as usize) <= positions.len() {
            Ok((k - 1) as u32)
        } else {
            Err(r.error(format!(
                "point index {k} is outside the item's 1..={}",
                positions.len()
            )))
        }
    };
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut push = |t: [i64; 3]| -> Result<(), ParseError> {
        let t = [point(t[0])?, point(t[1])?, point(t[2])?];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            triangles.push(t);
        }
        Ok(())
    };
    if complex {
        for p in r.list(pnindex_at + 1, "triangle strips")? {
            let s = indices(r, p, "a triangle strip")?;
            for k in 2..s.len() {
                // Every other triangle turns back so that the strip keeps one side.
                push(if k % 2 == 0 {
                    [s[k - 2], s[k - 1], s[k]]
                } else {
                    [s[k - 1], s[k - 2], s[k]]
                })?;
            }
        }
        for p in r.list(pnindex_at + 2, "triangle fans")? {
            let f = indices(r, p, "a triangle fan")?;
            for k in 2..f.len() {
                push([f[0], f[k - 1], f[k]])?;
            }
        }
    } else {
        for p in r.list(pnindex_at + 1, "triangles")? {
            match indices(r, p, "a triangle")?[..] {
                [a, b, c] => push([a, b, c])?,
                _ => return Err(r.error_at(p.line, p.column, "expected a triangle of 3 indices")),
            }
        }
    }
    Ok(TriangleMesh {
        positions,
        normals,
        indices: triangles,
    })
}
