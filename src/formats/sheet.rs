//! A scene's surfaces laid out for the writers of formats that keep trims (OBJ free-form,
//! IGES): each surface as a sheet of Bézier patches (Dammertz §2.8: the NURBS surface
//! decomposed, in span order, u spans fastest) joined along their shared edges, with its
//! trim loops in the patches' own parameter space.
//!
//! A sheet is written as one piecewise Bézier surface (OBJ `cstype bezier` with `parm`
//! breakpoints; IGES 128 with every interior knot of multiplicity equal to the degree), so
//! the surface's loops, which cross its patches, are written once, in the one parameter
//! space the patches share; a reader decomposes it back into the same patches. Where
//! neighbouring patches do not share their edge exactly (a surface with a break), each
//! patch is a sheet of its own, carrying the surface's loops.

use glam::{DVec4, Vec3};

use crate::geom::BezierPatch;
use crate::geom::bezier::ParamRect;
use crate::geom::trim::clip::loops_within;
use crate::geom::trim::reparam::loops_in_nurbs_space;
use crate::geom::trim::{AxisMap, TrimLoop};
use crate::scene::model::{Geometry, Scene, SurfaceGeometry};

/// Bézier patches sharing their edges, over breakpoints in u and v, with trim loops.
#[derive(Clone, Debug, PartialEq)]
pub struct Sheet {
    /// The scene object it belongs to.
    pub object: usize,
    pub degree_u: usize,
    pub degree_v: usize,
    pub breaks_u: Vec<f64>,
    pub breaks_v: Vec<f64>,
    /// Homogeneous premultiplied control points, `(breaks_u.len() − 1) · degree_u + 1`
    /// per row, u fastest.
    pub net: Vec<DVec4>,
    /// Loops in the parameters the breakpoints are in; none: the whole domain.
    pub loops: Vec<TrimLoop>,
}

impl Sheet {
    /// Control points per row (along u) and per column (along v).
    pub fn net_size(&self) -> (usize, usize) {
        (
            (self.breaks_u.len() - 1) * self.degree_u + 1,
            (self.breaks_v.len() - 1) * self.degree_v + 1,
        )
    }

    pub fn is_rational(&self) -> bool {
        self.net.iter().any(|p| p.w != 1.0)
    }

    pub fn domain(&self) -> ParamRect {
        ParamRect {
            u0: self.breaks_u[0],
            u1: *self.breaks_u.last().unwrap_or(&self.breaks_u[0]),
            v0: self.breaks_v[0],
            v1: *self.breaks_v.last().unwrap_or(&self.breaks_v[0]),
        }
    }

    /// The sheet's patches in span order, u fastest, each with its domain.
    pub fn patches(&self) -> Vec<BezierPatch> {
        let (du, dv) = (self.degree_u, self.degree_v);
        let (cu, _) = self.net_size();
        let mut out = Vec::new();
        for j in 0..self.breaks_v.len() - 1 {
            for i in 0..self.breaks_u.len() - 1 {
                let points = (0..=dv)
                    .flat_map(|b| (0..=du).map(move |a| (j * dv + b) * cu + i * du + a))
                    .map(|k| self.net[k])
                    .collect();
                if let Ok(p) = BezierPatch::new(du, dv, points) {
                    out.push(p.with_domain(ParamRect {
                        u0: self.breaks_u[i],
                        u1: self.breaks_u[i + 1],
                        v0: self.breaks_v[j],
                        v1: self.breaks_v[j + 1],
                    }));
                }
            }
        }
        out
    }
}

/// The colour an object is written with: its material's diffuse colour, unless it has the
/// uncoloured default material CAD files get ([`crate::formats::cad::scene::assemble`]).
pub fn object_colour(scene: &Scene, object: usize) -> Option<Vec3> {
    let m = scene.materials.get(scene.objects[object].material)?;
    (m.name != "default").then_some(m.diffuse)
}

/// Every surface of the scene as sheets, in object and surface order. A triangle mesh has
/// no place in a patch format: it is an error naming the object, as is a surface that
/// cannot be decomposed or whose loops cannot be carried over.
pub fn scene_sheets(scene: &Scene) -> Result<Vec<Sheet>, String> {
    let mut out = Vec::new();
    for (k, object) in scene.objects.iter().enumerate() {
        let placed;
        let geometry = match &object.geometry {
            Geometry::Instance(i) => {
                placed = i.flattened();
                &placed
            }
            g => g,
        };
        match geometry {
            Geometry::Surfaces(surfaces) => {
                for (n, s) in surfaces.iter().enumerate() {
                    let located = |e: String| format!("object `{}`, surface {n}: {e}", object.name);
                    let patches = match &s.geometry {
                        SurfaceGeometry::Bezier(p) => vec![p.clone()],
                        SurfaceGeometry::Nurbs(nurbs) => nurbs
                            .try_to_bezier_patches()
                            .map_err(|e| located(e.to_string()))?,
                    };
                    let Some(first) = patches.first() else {
                        continue;
                    };
                    let domain = span(&patches).unwrap_or(first.domain());
                    // Loops cut to the domain first, in the parameters they are written
                    // in (where a loop closed beyond the range, around a closed surface,
                    // runs past the angles the map knows), so that the written curves lie
                    // in the surface's domain as IGES 142 and OBJ `trim` ask.
                    let Some(loops) = loops_within(&s.trims, trim_rect(&s.trim_space, domain))
                        .map_err(|e| located(e.to_string()))?
                    else {
                        continue;
                    };
                    let loops = loops_in_nurbs_space(&loops, &s.trim_space, domain)
                        .map_err(|e| located(e.to_string()))?;
                    out.extend(join(k, &patches, &loops));
                }
            }
            Geometry::Subdivision(s) => {
                out.extend(s.patches.iter().map(|p| single(k, p, Vec::new())));
            }
            Geometry::Mesh(_) => {
                return Err(format!(
                    "object `{}` is a triangle mesh, which this format stores no place for (it holds patches only)",
                    object.name
                ));
            }
            Geometry::Instance(_) => {
                return Err(format!(
                    "object `{}` is an instance of an instance, which is never built",
                    object.name
                ));
            }
        }
    }
    Ok(out)
}

/// The rectangle of trim parameters the NURBS domain `d` maps onto.
fn trim_rect(maps: &[AxisMap; 2], d: ParamRect) -> ParamRect {
    let ends = |m: &AxisMap, a: f64, b: f64| {
        let (x, y) = (m.apply(a), m.apply(b));
        (x.min(y), x.max(y))
    };
    let (u0, u1) = ends(&maps[0], d.u0, d.u1);
    let (v0, v1) = ends(&maps[1], d.v0, d.v1);
    ParamRect { u0, u1, v0, v1 }
}

/// The rectangle the patches cover.
fn span(patches: &[BezierPatch]) -> Option<ParamRect> {
    let (first, last) = (patches.first()?.domain(), patches.last()?.domain());
    Some(ParamRect {
        u0: first.u0,
        u1: last.u1,
        v0: first.v0,
        v1: last.v1,
    })
}

/// A patch as a sheet of its own.
fn single(object: usize, p: &BezierPatch, loops: Vec<TrimLoop>) -> Sheet {
    let d = p.domain();
    Sheet {
        object,
        degree_u: p.degree_u(),
        degree_v: p.degree_v(),
        breaks_u: vec![d.u0, d.u1],
        breaks_v: vec![d.v0, d.v1],
        net: p.homogeneous_points().to_vec(),
        loops,
    }
}

/// The patches of one surface (span order, u fastest) as one sheet when they tile a grid
/// of breakpoints and share their edges exactly; else one sheet per patch.
fn join(object: usize, patches: &[BezierPatch], loops: &[TrimLoop]) -> Vec<Sheet> {
    joined(object, patches, loops).map_or_else(
        || {
            patches
                .iter()
                .map(|p| single(object, p, loops.to_vec()))
                .collect()
        },
        |s| vec![s],
    )
}

fn joined(object: usize, patches: &[BezierPatch], loops: &[TrimLoop]) -> Option<Sheet> {
    let first = patches.first()?;
    let (du, dv) = (first.degree_u(), first.degree_v());
    let su = patches
        .iter()
        .take_while(|p| p.domain().v0 == first.domain().v0)
        .count();
    if !patches.len().is_multiple_of(su) {
        return None;
    }
    let sv = patches.len() / su;
    let mut breaks_u: Vec<f64> = patches[..su].iter().map(|p| p.domain().u0).collect();
    breaks_u.push(patches[su - 1].domain().u1);
    let mut breaks_v: Vec<f64> = patches.iter().step_by(su).map(|p| p.domain().v0).collect();
    breaks_v.push(patches[patches.len() - 1].domain().v1);
    let (cu, cv) = (su * du + 1, sv * dv + 1);
    let mut net: Vec<Option<DVec4>> = vec![None; cu * cv];
    for (n, p) in patches.iter().enumerate() {
        let (i, j) = (n % su, n / su);
        let d = p.domain();
        let expected = ParamRect {
            u0: breaks_u[i],
            u1: breaks_u[i + 1],
            v0: breaks_v[j],
            v1: breaks_v[j + 1],
        };
        if (p.degree_u(), p.degree_v()) != (du, dv) || d != expected {
            return None;
        }
        for b in 0..=dv {
            for a in 0..=du {
                let slot = &mut net[(j * dv + b) * cu + i * du + a];
                let q = p.homogeneous(a, b);
                match slot {
                    Some(old) if *old != q => return None,
                    _ => *slot = Some(q),
                }
            }
        }
    }
    Some(Sheet {
        object,
        degree_u: du,
        degree_v: dv,
        breaks_u,
        breaks_v,
        net: net.into_iter().collect::<Option<Vec<_>>>()?,
        loops: loops.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::NurbsSurface;
    use glam::DVec3;

    #[test]
    fn a_decomposed_surface_joins_into_one_sheet_with_the_same_patches() {
        // Degree 2 × 1, knots with interior 0.5 (u) and 0.25, 0.75 (v): 2 × 3 patches.
        let (cu, cv) = (4, 4);
        let points: Vec<DVec4> = (0..cu * cv)
            .map(|k| {
                let (i, j) = ((k % cu) as f64, (k / cu) as f64);
                DVec3::new(i, j, (i * j).sin()).extend(1.0 + 0.1 * i)
            })
            .map(|h| (h.truncate() * h.w).extend(h.w))
            .collect();
        let n = NurbsSurface::new(
            2,
            1,
            vec![0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.25, 0.75, 1.0, 1.0],
            cu,
            cv,
            points,
        )
        .unwrap();
        let patches = n.to_bezier_patches();
        let sheets = join(0, &patches, &[]);
        assert_eq!(sheets.len(), 1);
        assert_eq!(sheets[0].breaks_u, vec![0.0, 0.5, 1.0]);
        assert_eq!(sheets[0].breaks_v, vec![0.0, 0.25, 0.75, 1.0]);
        assert_eq!(sheets[0].patches(), patches);
    }
}
