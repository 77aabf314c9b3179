//! One conversion per USD prim type we read (UsdGeom `NurbsPatch`, `Mesh`, `Camera`;
//! UsdLux `DistantLight`, `SphereLight`; UsdShade `UsdPreviewSurface`), each from the
//! composed prim, in the prim's own coordinates.

use std::collections::HashMap;

use glam::{DAffine3, DVec2, DVec3, DVec4, Vec3};
use openusd::usd::Prim;

use super::values::{Attr, ValueError, count, counts, numbers, points, scalar, token, tuples};
use crate::geom::nurbs::NurbsSurface;
use crate::geom::subdiv::SubdivisionSurface;
use crate::geom::trim::{ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Camera, Geometry, Light, Material, Surface, TriangleMesh};

/// The attributes each conversion reads; any other authored attribute of the prim is
/// reported as not read. `extent` is left out of the report: it is derived from the
/// points, and the bounds are computed from the geometry itself.
pub const NURBS_READ: &[&str] = &[
    "uVertexCount",
    "vVertexCount",
    "uOrder",
    "vOrder",
    "uKnots",
    "vKnots",
    "uForm",
    "vForm",
    "uRange",
    "vRange",
    "points",
    "pointWeights",
    "orientation",
    "trimCurve:counts",
    "trimCurve:orders",
    "trimCurve:vertexCounts",
    "trimCurve:knots",
    "trimCurve:ranges",
    "trimCurve:points",
];
pub const MESH_READ: &[&str] = &[
    "points",
    "faceVertexCounts",
    "faceVertexIndices",
    "subdivisionScheme",
    "orientation",
    "holeIndices",
    // Read to say what is not honoured (see [`mesh`]).
    "interpolateBoundary",
    "creaseIndices",
    "creaseLengths",
    "creaseSharpnesses",
    "cornerIndices",
    "cornerSharpnesses",
];
pub const CAMERA_READ: &[&str] = &["focalLength", "horizontalAperture", "verticalAperture"];
pub const LIGHT_READ: &[&str] = &[
    "intensity",
    "color",
    "exposure",
    "inputs:intensity",
    "inputs:color",
    "inputs:exposure",
];
pub const SHADER_READ: &[&str] = &[
    "info:id",
    "inputs:diffuseColor",
    "inputs:metallic",
    "inputs:roughness",
    "inputs:opacity",
    "inputs:ior",
];
/// Read on every prim: transforms, visibility, purpose, and the display colour.
pub const COMMON_READ: &[&str] = &[
    "xformOpOrder",
    "visibility",
    "purpose",
    "extent",
    "primvars:displayColor",
];

fn bad(prim: &Prim, what: impl std::fmt::Display) -> ValueError {
    ValueError(format!("{}: {what}", prim.path()))
}

fn required<T>(attr: Attr, v: Option<T>) -> Result<T, ValueError> {
    v.ok_or_else(|| {
        ValueError(format!(
            "{}.{}: required, not authored",
            attr.0.path(),
            attr.1
        ))
    })
}

/// Whether the prim's `orientation` is `leftHanded` (its normals follow the left-hand
/// rule, UsdGeomGprim).
fn left_handed(prim: &Prim) -> Result<bool, ValueError> {
    Ok(token((prim, "orientation"))?.as_deref() == Some("leftHanded"))
}

/// A `NurbsPatch` as a trimmed NURBS surface (UsdGeomNurbsPatch). `points` are not
/// pre-weighted: a point with weight w becomes `(w x, w y, w z, w)`. A periodic form
/// changes nothing: USD writes a periodic patch with its wrapped points and unclamped
/// knots, which is the B-spline over the domain its knots give. Trim curves are loops of
/// curves in (u, v) with homogeneous points `(w u, w v, w)` (RenderMan's `RiTrimCurve`
/// convention that UsdGeom follows); a loop is a hole when it runs clockwise (the
/// region to the left of a loop is kept, as in GLU's trimming), so the even–odd region
/// of `geom::trim` keeps what USD keeps.
pub fn nurbs_patch(prim: &Prim) -> Result<(Surface, Vec<String>), ValueError> {
    let mut notes = Vec::new();
    let get_count = |name: &'static str| -> Result<usize, ValueError> {
        required((prim, name), count((prim, name))?)
    };
    let (nu, nv) = (get_count("uVertexCount")?, get_count("vVertexCount")?);
    let (ou, ov) = (get_count("uOrder")?, get_count("vOrder")?);
    if ou < 2 || ov < 2 {
        return Err(bad(
            prim,
            format!("orders {ou} x {ov}: each must be at least 2"),
        ));
    }
    let knots_u = required((prim, "uKnots"), numbers((prim, "uKnots"))?)?;
    let knots_v = required((prim, "vKnots"), numbers((prim, "vKnots"))?)?;
    let pts = required((prim, "points"), points((prim, "points"))?)?;
    if pts.len() != nu * nv {
        return Err(bad(
            prim,
            format!("{} points for a {nu} x {nv} control net", pts.len()),
        ));
    }
    let weights = numbers((prim, "pointWeights"))?.unwrap_or_else(|| vec![1.0; pts.len()]);
    if weights.len() != pts.len() {
        return Err(bad(
            prim,
            format!("{} pointWeights for {} points", weights.len(), pts.len()),
        ));
    }
    let homogeneous: Vec<DVec4> = pts
        .iter()
        .zip(&weights)
        .map(|(p, &w)| (*p * w).extend(w))
        .collect();
    let surface = NurbsSurface::new(ou - 1, ov - 1, knots_u, knots_v, nu, nv, homogeneous)
        .map_err(|e| bad(prim, e))?;
    let surface = ranged(prim, surface, &mut notes)?;
    let mut s = Surface {
        geometry: crate::scene::model::SurfaceGeometry::Nurbs(surface),
        trims: trim_loops(prim)?,
        trim_space: Default::default(),
    };
    if left_handed(prim)? {
        s.flip_sides();
    }
    Ok((s, notes))
}

/// The surface restricted to its `uRange` and `vRange` (UsdGeomNurbsPatch: the
/// parameters "over which the surface is actually defined", within the knots' domain),
/// exactly: each range end is inserted as a knot to full multiplicity and what lies
/// beyond it is dropped ([`NurbsSurface::restricted`]). The parameters do not change, so
/// trim loops stay where they were. A range reaching beyond the knots' domain is clipped
/// to it, with a note; one that misses the domain is an error.
fn ranged(
    prim: &Prim,
    surface: NurbsSurface,
    notes: &mut Vec<String>,
) -> Result<NurbsSurface, ValueError> {
    let domain = surface.domain();
    let mut range = domain;
    for (name, lo, hi) in [
        ("uRange", &mut range.u0, &mut range.u1),
        ("vRange", &mut range.v0, &mut range.v1),
    ] {
        let Some(r) = tuples((prim, name), 2)? else {
            continue;
        };
        let (a, b) = (r[0], r[1]);
        let (from, to) = (a.max(*lo), b.min(*hi));
        // Written so that a NaN end is refused too.
        let overlaps = from < to;
        if !overlaps {
            return Err(bad(
                prim,
                format!("{name} ({a}, {b}) does not overlap the knots' domain ({lo}, {hi})"),
            ));
        }
        if (from, to) != (a, b) {
            notes.push(format!(
                "{}: {name} ({a}, {b}) reaches beyond the knots' domain ({lo}, {hi}); clipped to it",
                prim.path()
            ));
        }
        (*lo, *hi) = (from, to);
    }
    Ok(if range == domain {
        surface
    } else {
        surface.restricted(range)
    })
}

/// The `trimCurve:*` attributes as loops (see [`nurbs_patch`]).
fn trim_loops(prim: &Prim) -> Result<Vec<TrimLoop>, ValueError> {
    let Some(loop_counts) = counts((prim, "trimCurve:counts"))? else {
        return Ok(Vec::new());
    };
    let need = |name: &'static str| required((prim, name), counts((prim, name))?);
    let orders = need("trimCurve:orders")?;
    let vertex_counts = need("trimCurve:vertexCounts")?;
    let knots = required(
        (prim, "trimCurve:knots"),
        numbers((prim, "trimCurve:knots"))?,
    )?;
    let ranges = required(
        (prim, "trimCurve:ranges"),
        tuples((prim, "trimCurve:ranges"), 2)?,
    )?;
    let pts = required(
        (prim, "trimCurve:points"),
        tuples((prim, "trimCurve:points"), 3)?,
    )?;
    let curves: usize = loop_counts.iter().sum();
    if orders.len() != curves || vertex_counts.len() != curves || ranges.len() != 2 * curves {
        return Err(bad(
            prim,
            format!(
                "trimCurve: counts give {curves} curves, but there are {} orders, {} vertexCounts and {} ranges",
                orders.len(),
                vertex_counts.len(),
                ranges.len() / 2
            ),
        ));
    }
    let (mut k0, mut p0, mut c) = (0, 0, 0);
    let mut loops = Vec::new();
    for &n_curves in &loop_counts {
        let mut segments = Vec::new();
        for _ in 0..n_curves {
            let (order, n) = (orders[c], vertex_counts[c]);
            if order < 2 || n < order {
                return Err(bad(
                    prim,
                    format!("trim curve {c}: order {order} with {n} points"),
                ));
            }
            let (k1, p1) = (k0 + n + order, p0 + n);
            if k1 > knots.len() || 3 * p1 > pts.len() {
                return Err(bad(
                    prim,
                    format!("trim curve {c}: more knots or points than trimCurve holds"),
                ));
            }
            segments.push(TrimSegment {
                t0: ranges[2 * c],
                t1: ranges[2 * c + 1],
                curve: ParamCurve {
                    degree: order - 1,
                    knots: knots[k0..k1].to_vec(),
                    points: pts[3 * p0..3 * p1]
                        .chunks(3)
                        .map(DVec3::from_slice)
                        .collect(),
                },
            });
            (k0, p0, c) = (k1, p1, c + 1);
        }
        let hole = signed_area(&segments) < 0.0;
        loops.push(TrimLoop { hole, segments });
    }
    Ok(loops)
}

/// Samples per trim segment for the loop's orientation: the sign of the area only needs
/// a polygon of the loop's shape, not its exact area.
const ORIENTATION_SAMPLES: usize = 32;

/// The area a loop encloses, positive when it runs counter-clockwise (the shoelace sum
/// over points sampled along its segments).
fn signed_area(segments: &[TrimSegment]) -> f64 {
    let pts: Vec<DVec2> = segments
        .iter()
        .flat_map(|s| {
            (0..ORIENTATION_SAMPLES).map(move |k| {
                let t = s.t0 + (s.t1 - s.t0) * k as f64 / ORIENTATION_SAMPLES as f64;
                s.curve.point(t)
            })
        })
        .collect();
    let n = pts.len();
    (0..n)
        .map(|i| pts[i].perp_dot(pts[(i + 1) % n]))
        .sum::<f64>()
        * 0.5
}

/// A `Mesh`: its faces and how it is to be read.
pub struct MeshRead {
    /// `None` when every face is a hole.
    pub geometry: Option<Geometry>,
    /// What the reading could not honour, one line each.
    pub notes: Vec<String>,
}

/// A `Mesh` as a Catmull–Clark cage (UsdGeomMesh's default `subdivisionScheme`), or as
/// triangles (fans of its faces) for `none`. `bilinear` and `loop` are read as triangles,
/// said in a note: the kernel has neither scheme. The faces in `holeIndices` are not
/// rendered: a cage keeps them, so they still shape their neighbours (OpenSubdiv's
/// holes), and triangles drop them. Creases and corners are said in a note, not
/// honoured: the Catmull–Clark kernel has smooth interior edges and `edgeOnly`
/// boundaries. So is USD's default `interpolateBoundary = "edgeAndCorner"` where it
/// differs, at a boundary vertex of one face (OpenSubdiv's `VTX_BOUNDARY_EDGE_AND_CORNER`
/// makes it a sharp corner; `edgeOnly` keeps it smooth), and `none` on a mesh with a
/// boundary.
pub fn mesh(prim: &Prim) -> Result<MeshRead, ValueError> {
    let pts = required((prim, "points"), points((prim, "points"))?)?;
    let face_counts = required(
        (prim, "faceVertexCounts"),
        counts((prim, "faceVertexCounts"))?,
    )?;
    let indices = required(
        (prim, "faceVertexIndices"),
        counts((prim, "faceVertexIndices"))?,
    )?;
    if face_counts.iter().sum::<usize>() != indices.len() {
        return Err(bad(
            prim,
            format!(
                "faceVertexCounts add up to {}, but there are {} faceVertexIndices",
                face_counts.iter().sum::<usize>(),
                indices.len()
            ),
        ));
    }
    if let Some(&i) = indices.iter().find(|&&i| i >= pts.len()) {
        return Err(bad(
            prim,
            format!(
                "faceVertexIndices: index {i} beyond the {} points",
                pts.len()
            ),
        ));
    }
    let flip = left_handed(prim)?;
    let mut faces = Vec::with_capacity(face_counts.len());
    let mut at = 0;
    for &n in &face_counts {
        if n < 3 {
            return Err(bad(prim, format!("a face of {n} vertices")));
        }
        let mut f: Vec<u32> = indices[at..at + n].iter().map(|&i| i as u32).collect();
        if flip {
            f.reverse();
        }
        faces.push(f);
        at += n;
    }
    let holes = counts((prim, "holeIndices"))?.unwrap_or_default();
    if let Some(&h) = holes.iter().find(|&&h| h >= faces.len()) {
        return Err(bad(
            prim,
            format!("holeIndices: face {h} beyond the {} faces", faces.len()),
        ));
    }
    let scheme = token((prim, "subdivisionScheme"))?.unwrap_or_else(|| "catmullClark".into());
    let mut notes = Vec::new();
    let path = prim.path();
    let mut is_hole = vec![false; faces.len()];
    for &h in &holes {
        is_hole[h] = true;
    }
    if is_hole.iter().all(|&h| h) {
        notes.push(format!(
            "{path}: every face is in holeIndices; nothing to render"
        ));
        return Ok(MeshRead {
            geometry: None,
            notes,
        });
    }
    if scheme == "catmullClark" {
        let mut sharp = Vec::new();
        for name in ["creaseIndices", "cornerIndices"] {
            if numbers((prim, name))?.is_some_and(|v| !v.is_empty()) {
                sharp.push(name);
            }
        }
        if !sharp.is_empty() {
            notes.push(format!(
                "{path}: {} not honoured (the Catmull–Clark kernel has smooth interior edges and edgeOnly boundaries)",
                sharp.join(" and ")
            ));
        }
        notes.extend(boundary_note(prim, &faces, pts.len())?);
        let holes = holes.iter().map(|&h| h as u32).collect();
        let cage = SubdivisionSurface::with_holes(pts, faces, holes).map_err(|e| bad(prim, e))?;
        return Ok(MeshRead {
            geometry: Some(Geometry::Subdivision(cage)),
            notes,
        });
    }
    if scheme != "none" {
        notes.push(format!(
            "{path}: subdivisionScheme \"{scheme}\" read as flat triangles (the kernel has Catmull–Clark only)"
        ));
    }
    let triangles = faces
        .iter()
        .zip(&is_hole)
        .filter(|(_, hole)| !**hole)
        .flat_map(|(f, _)| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
        .collect();
    Ok(MeshRead {
        geometry: Some(Geometry::Mesh(TriangleMesh {
            positions: pts,
            normals: Vec::new(),
            indices: triangles,
        })),
        notes,
    })
}

/// What `interpolateBoundary` asks of the cage's boundary that the kernel's `edgeOnly`
/// rule does not give, if anything: sharp corners at the boundary vertices of one face
/// under `edgeAndCorner` (the fallback), no boundary faces under `none`.
fn boundary_note(
    prim: &Prim,
    faces: &[Vec<u32>],
    points: usize,
) -> Result<Option<String>, ValueError> {
    let rule = token((prim, "interpolateBoundary"))?.unwrap_or_else(|| "edgeAndCorner".into());
    let path = prim.path();
    Ok(match rule.as_str() {
        "edgeAndCorner" => {
            let mut faces_at = vec![0usize; points];
            for &v in faces.iter().flatten() {
                faces_at[v as usize] += 1;
            }
            let corners = faces_at.iter().filter(|&&n| n == 1).count();
            (corners > 0).then(|| {
                format!(
                    "{path}: interpolateBoundary \"edgeAndCorner\" not honoured at {corners} boundary corner vertices (read as edgeOnly: smooth, not sharp, corners)"
                )
            })
        }
        "none" => {
            let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
            for f in faces {
                for (k, &v) in f.iter().enumerate() {
                    let w = f[(k + 1) % f.len()];
                    *edges.entry((v.min(w), v.max(w))).or_default() += 1;
                }
            }
            edges.values().any(|&n| n == 1).then(|| {
                format!(
                    "{path}: interpolateBoundary \"none\" not honoured (read as edgeOnly: the boundary faces are rendered)"
                )
            })
        }
        _ => None,
    })
}

/// UsdGeomCamera's fallbacks, in tenths of a scene unit (its "aperture in
/// millimetres" convention): a 50 mm lens on a 35 mm academy aperture.
const FOCAL_LENGTH: f64 = 50.0;
const HORIZONTAL_APERTURE: f64 = 20.955;
const VERTICAL_APERTURE: f64 = 15.2908;
/// The image width a USD camera gets; its height follows the aperture's aspect ratio.
const CAMERA_WIDTH: u32 = 512;

/// A `Camera` placed by `world`: it looks down its local -z with +y up (UsdGeomCamera);
/// the vertical field of view is `2 atan(verticalAperture / (2 focalLength))`, and the
/// image is [`CAMERA_WIDTH`] wide with the apertures' aspect ratio.
pub fn camera(prim: &Prim, world: &DAffine3) -> Result<Camera, ValueError> {
    let get = |name: &'static str, fallback: f64| -> Result<f64, ValueError> {
        Ok(scalar((prim, name))?.unwrap_or(fallback))
    };
    let focal = get("focalLength", FOCAL_LENGTH)?;
    let (h, v) = (
        get("horizontalAperture", HORIZONTAL_APERTURE)?,
        get("verticalAperture", VERTICAL_APERTURE)?,
    );
    if !(focal > 0.0 && h > 0.0 && v > 0.0) {
        return Err(bad(
            prim,
            format!("focalLength {focal} and apertures {h} x {v} must be positive"),
        ));
    }
    let eye = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(-DVec3::Z).normalize();
    let height =
        ((f64::from(CAMERA_WIDTH) * v / h).round() as u32).clamp(1, crate::scene::MAX_IMAGE_EDGE);
    Ok(Camera {
        eye,
        look_at: eye + forward,
        up: world.transform_vector3(DVec3::Y).normalize(),
        fov_y: 2.0 * (v / (2.0 * focal)).atan().to_degrees(),
        width: CAMERA_WIDTH,
        height,
    })
}

/// A light's colour times `intensity · 2^exposure` (UsdLuxLightAPI), read from the
/// `inputs:` names or the older unprefixed ones.
fn light_power(prim: &Prim) -> Result<Vec3, ValueError> {
    let either = |name: &'static str| -> Result<Option<Vec<f64>>, ValueError> {
        match numbers((prim, name))? {
            Some(v) => Ok(Some(v)),
            None => numbers((prim, &format!("inputs:{name}"))),
        }
    };
    let intensity = either("intensity")?
        .and_then(|v| v.first().copied())
        .unwrap_or(1.0);
    let exposure = either("exposure")?
        .and_then(|v| v.first().copied())
        .unwrap_or(0.0);
    let colour = either("color")?
        .filter(|c| c.len() >= 3)
        .map_or(DVec3::ONE, |c| DVec3::from_slice(&c));
    Ok((colour * intensity * exposure.exp2()).as_vec3())
}

/// A `DistantLight` (shining down its local -z) or a `SphereLight` (a point light at its
/// centre; its radius is not read), placed by `world`.
pub fn light(prim: &Prim, kind: &str, world: &DAffine3) -> Result<Light, ValueError> {
    let intensity = light_power(prim)?;
    Ok(if kind == "DistantLight" {
        Light::Directional {
            direction: world.transform_vector3(-DVec3::Z).normalize(),
            intensity,
        }
    } else {
        Light::Point {
            position: world.transform_point3(DVec3::ZERO),
            intensity,
        }
    })
}

/// Roughness below which a surface counts as a mirror in the Blinn–Phong exponent
/// (the exponent of roughness 0.01 is 2 / 0.01^4 − 2 ≈ 2 · 10^8, beyond any use).
const MIN_ROUGHNESS: f32 = 0.01;

/// A `UsdPreviewSurface` shader's inputs as our Whitted material named `name`:
///
/// - `diffuse` = `diffuseColor · (1 − metallic)` (metals have no diffuse term);
/// - `reflect` = `metallic · (1 − roughness)` (a smooth metal is a mirror);
/// - `specular` = `1 − roughness`, with the Blinn–Phong exponent `2 / α² − 2` of the
///   microfacet width `α = roughness²` (Walter et al. 2007, §5.2: the Phong exponent
///   that matches a Beckmann distribution of width α);
/// - `transmit` = `1 − opacity`, `ior` = `ior`.
///
/// Inputs connected to textures are not read: their authored fallback, or the schema's,
/// stands.
pub fn preview_surface(shader: &Prim, name: &str) -> Result<Material, ValueError> {
    let input = |n: &'static str| numbers((shader, n));
    let one = |n: &'static str, fallback: f32| -> Result<f32, ValueError> {
        Ok(input(n)?
            .and_then(|v| v.first().copied())
            .map_or(fallback, |x| x as f32))
    };
    let colour = input("inputs:diffuseColor")?
        .filter(|c| c.len() >= 3)
        .map_or(Vec3::splat(0.18), |c| DVec3::from_slice(&c).as_vec3());
    let metallic = one("inputs:metallic", 0.0)?.clamp(0.0, 1.0);
    let roughness = one("inputs:roughness", 0.5)?.clamp(0.0, 1.0);
    let opacity = one("inputs:opacity", 1.0)?.clamp(0.0, 1.0);
    let alpha = roughness.max(MIN_ROUGHNESS).powi(2);
    let mut m = Material::default_named(name);
    m.diffuse = colour * (1.0 - metallic);
    m.reflect = metallic * (1.0 - roughness);
    m.specular = 1.0 - roughness;
    m.shininess = 2.0 / (alpha * alpha) - 2.0;
    m.blinn = true;
    m.transmit = 1.0 - opacity;
    m.ior = one("inputs:ior", 1.5)?;
    Ok(m)
}

/// A gprim's `primvars:displayColor` (its first colour, a constant colour being the
/// common case), `None` when unauthored.
pub fn display_colour(prim: &Prim) -> Result<Option<Vec3>, ValueError> {
    Ok(tuples((prim, "primvars:displayColor"), 3)?
        .filter(|c| !c.is_empty())
        .map(|c| DVec3::from_slice(&c).as_vec3()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counter_clockwise_loops_have_positive_area() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let ccw = TrimSegment::polyline(&[square.as_slice(), &square[..1]].concat());
        assert!((signed_area(&[ccw]) - 1.0).abs() < 1e-12);
        let mut cw: Vec<DVec2> = square.to_vec();
        cw.reverse();
        cw.push(cw[0]);
        assert!((signed_area(&[TrimSegment::polyline(&cw)]) + 1.0).abs() < 1e-12);
    }
}
