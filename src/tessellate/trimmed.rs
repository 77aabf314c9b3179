//! Trimmed surfaces: a constrained Delaunay triangulation of the surface's parameter domain
//! (Chew, "Constrained Delaunay triangulations", Algorithmica 4, 1989; here the `spade`
//! crate, which decides orientation and in-circle tests exactly with Shewchuk's adaptive
//! predicates, so slivers next to the loops cannot make it fail).
//!
//! The points are the patch grid points the trim keeps (the same grids as untrimmed patches)
//! and the samples of every loop piece; consecutive samples of a piece are constraint edges,
//! so no triangle crosses the sampled loops. A triangle is kept where its centre is inside
//! the region by the exact even–odd test ([`TrimRegion::contains`]), which sorts out outer
//! loops, holes and islands with no orientation or nesting information.
//!
//! Loops are sampled to the tessellation's own accuracy: in adaptive mode until the chord
//! height of the loop's image on the surface is within the tolerance (as for patch edges);
//! with a fixed grid, until no loop segment spans more than a grid cell in either parameter.
//! Each trimmed surface is its own piece of mesh: its boundary is sampled from its own
//! loops, so neighbouring trimmed faces leave gaps, measured by [`super::gaps`].

use std::collections::HashMap;

use glam::{DVec2, DVec3, DVec4};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::edge::{EdgeCurve, Side, segments_for_tolerance, segments_until};
use super::{Plan, TessellateError};
use crate::geom::BezierPatch;
use crate::geom::bezier::{ParamRect, de_casteljau_point, dehomogenize};
use crate::geom::trim::pieces::Piece;
use crate::geom::trim::{AxisMap, Coverage, TrimRegion};
use crate::scene::model::{Surface, TriangleMesh};

/// A trimmed surface triangulated in its (NURBS) parameters: `params[k]` is vertex k,
/// triangles run counter-clockwise in (u, v), and `boundary` lists, per loop piece, the
/// vertices its samples became, in order.
#[derive(Clone, Debug, Default)]
pub(super) struct ParamTriangulation {
    pub params: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
    pub boundary: Vec<Vec<u32>>,
}

/// A trimmed surface's mesh and its boundary polylines in space (one per loop piece).
pub(super) struct TrimmedFace {
    pub mesh: TriangleMesh,
    pub boundary: Vec<Vec<DVec3>>,
}

/// A surface's Bézier patches located by parameter: the sorted span breaks in u and v and,
/// per span cell, the patch over it.
struct Patches {
    list: Vec<(BezierPatch, Coverage)>,
    /// Each patch's grid cell in the surface's parameters.
    cells: Vec<DVec2>,
    u: Vec<f64>,
    v: Vec<f64>,
    cell: HashMap<(usize, usize), usize>,
    domain: ParamRect,
}

impl Patches {
    fn of(surface: &Surface, plan: Plan) -> Option<Patches> {
        let list = surface.trimmed_patches();
        let cells = list
            .iter()
            .map(|(patch, _)| {
                let (gu, gv) = grid(patch, plan);
                let d = patch.domain();
                DVec2::new((d.u1 - d.u0) / gu as f64, (d.v1 - d.v0) / gv as f64)
            })
            .collect();
        let breaks = |f: &dyn Fn(&ParamRect) -> [f64; 2]| {
            let mut b: Vec<f64> = list.iter().flat_map(|(p, _)| f(&p.domain())).collect();
            b.sort_by(f64::total_cmp);
            b.dedup();
            b
        };
        let u = breaks(&|d| [d.u0, d.u1]);
        let v = breaks(&|d| [d.v0, d.v1]);
        if u.len() < 2 || v.len() < 2 {
            return None;
        }
        let (u0, u1, v0, v1) = (u[0], u[u.len() - 1], v[0], v[v.len() - 1]);
        let cell = list
            .iter()
            .enumerate()
            .map(|(k, (p, _))| {
                let d = p.domain();
                ((span(&u, d.u0), span(&v, d.v0)), k)
            })
            .collect();
        Some(Patches {
            list,
            cells,
            u,
            v,
            cell,
            domain: ParamRect { u0, u1, v0, v1 },
        })
    }

    /// The patch over (u, v) (clamped to the domain) and the local parameters there.
    fn at(&self, p: DVec2) -> (&BezierPatch, f64, f64) {
        let patch = &self.list[self.index(p)].0;
        let d = patch.domain();
        let (u, v) = self.clamp(p);
        let local = |t: f64, a: f64, b: f64| ((t - a) / (b - a)).clamp(0.0, 1.0);
        (patch, local(u, d.u0, d.u1), local(v, d.v0, d.v1))
    }

    /// The index of the patch over (u, v), clamped to the domain.
    fn index(&self, p: DVec2) -> usize {
        let (u, v) = self.clamp(p);
        // A NURBS surface's patches tile its grid of non-empty spans, so every cell has
        // one; the first patch stands in should that ever not hold.
        self.cell
            .get(&(span(&self.u, u), span(&self.v, v)))
            .copied()
            .unwrap_or(0)
    }

    fn clamp(&self, p: DVec2) -> (f64, f64) {
        let d = &self.domain;
        (p.x.clamp(d.u0, d.u1), p.y.clamp(d.v0, d.v1))
    }

    fn eval(&self, p: DVec2) -> DVec3 {
        let (patch, s, t) = self.at(p);
        patch.eval(s, t)
    }
}

/// The span of sorted breaks `b` (at least two) that holds `t`, the end spans beyond them.
fn span(b: &[f64], t: f64) -> usize {
    b.partition_point(|&x| x <= t).clamp(1, b.len() - 1) - 1
}

/// A patch's grid size under `plan`, as for an untrimmed patch.
fn grid(patch: &BezierPatch, plan: Plan) -> (usize, usize) {
    let curves = Side::ALL.map(|s| EdgeCurve::of(patch, s));
    let (gu, gv, _) = plan.grid(patch, &curves);
    (gu, gv)
}

/// The point of a loop piece at `t`; the ends are the end points themselves, so pieces
/// that meet share their sample bit for bit.
fn piece_point(piece: &Piece, t: f64) -> DVec2 {
    if t == 0.0 {
        return piece.start();
    }
    if t == 1.0 {
        return piece.end();
    }
    let h: Vec<DVec4> = piece
        .points
        .iter()
        .map(|q| DVec4::new(q.x, q.y, 0.0, q.z))
        .collect();
    dehomogenize(de_casteljau_point(&h, t)).truncate()
}

/// A trim-space point in the surface's own parameters.
fn to_surface(maps: &[AxisMap; 2], p: DVec2) -> DVec2 {
    DVec2::new(maps[0].invert(p.x), maps[1].invert(p.y))
}

/// Triangulates the surface of `patches`, whose loops make `region`, in its parameter
/// domain.
fn triangulate_patches(
    patches: &Patches,
    region: &TrimRegion,
    plan: Plan,
) -> Result<ParamTriangulation, TessellateError> {
    let mut points = Points::default();
    for (patch, coverage) in &patches.list {
        if *coverage == Coverage::Outside {
            continue;
        }
        let (gu, gv) = grid(patch, plan);
        let d = patch.domain();
        for j in 0..=gv {
            for i in 0..=gu {
                let (s, t) = (i as f64 / gu as f64, j as f64 / gv as f64);
                let keep = match coverage {
                    Coverage::Partial(trim) => trim.keeps(s, t),
                    _ => true,
                };
                if keep {
                    let (u, v) = d.to_parent(s, t);
                    points.add(DVec2::new(u, v));
                }
            }
        }
    }
    let maps = region.maps();
    let mut boundary = Vec::with_capacity(region.pieces().len());
    for piece in region.pieces() {
        let at = |t: f64| to_surface(maps, piece_point(piece, t));
        let degree = piece.points.len() - 1;
        let n = match plan {
            Plan::Adaptive { tolerance } => {
                segments_for_tolerance(&|t| patches.eval(at(t)), degree, tolerance)
            }
            // No segment longer than the grid cell of the patch where it starts.
            Plan::Uniform { .. } => segments_until(degree, &|t0, t1| {
                let (a, b) = (at(t0), at(t1));
                let cell = patches.cells[patches.index(a)];
                let d = (b - a).abs();
                d.x <= cell.x && d.y <= cell.y
            }),
        };
        let samples: Vec<u32> = (0..=n)
            .map(|k| points.add(at(k as f64 / n as f64)))
            .collect();
        boundary.push(samples);
    }
    let triangles = constrained_delaunay(&points.list, &boundary, region)?;
    Ok(ParamTriangulation {
        params: points.list,
        triangles,
        boundary,
    })
}

/// The points of a triangulation, each made once (by its exact bits).
#[derive(Default)]
struct Points {
    list: Vec<DVec2>,
    index: HashMap<[u64; 2], u32>,
}

impl Points {
    fn add(&mut self, p: DVec2) -> u32 {
        // spade refuses coordinates below 2^-142 in magnitude (its exact predicates would
        // underflow); such a parameter is zero for any purpose here.
        let p = DVec2::from(p.to_array().map(|x| {
            if x.abs() < spade::MIN_ALLOWED_VALUE {
                0.0
            } else {
                x
            }
        }));
        let next = self.list.len() as u32;
        *self
            .index
            .entry(p.to_array().map(f64::to_bits))
            .or_insert_with(|| {
                self.list.push(p);
                next
            })
    }
}

/// The triangles of the constrained Delaunay triangulation of `points` with the boundary
/// polylines as constraints whose centres `region` keeps. A constraint that would cross an
/// earlier one (loops that touch or cross themselves) is left out; the centre test still
/// decides which triangles stay.
fn constrained_delaunay(
    points: &[DVec2],
    boundary: &[Vec<u32>],
    region: &TrimRegion,
) -> Result<Vec<[u32; 3]>, TessellateError> {
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(points.len());
    for p in points {
        handles.push(
            cdt.insert(Point2::new(p.x, p.y))
                .map_err(|e| TessellateError::Parameter(e.to_string()))?,
        );
    }
    for polyline in boundary {
        for w in polyline.windows(2) {
            if w[0] != w[1] {
                cdt.try_add_constraint(handles[w[0] as usize], handles[w[1] as usize]);
            }
        }
    }
    // Points are distinct, so spade's handles are the points' indices in insertion order.
    Ok(cdt
        .inner_faces()
        .filter_map(|face| {
            let tri = face.vertices().map(|v| v.fix().index() as u32);
            let c = tri.iter().map(|&i| points[i as usize]).sum::<DVec2>() / 3.0;
            region.contains(c.x, c.y).then_some(tri)
        })
        .collect())
}

/// The trimmed surface's mesh (vertices on the exact surface, exact normals) and its
/// boundary in space.
pub(super) fn tessellate_trimmed(
    surface: &Surface,
    region: &TrimRegion,
    plan: Plan,
) -> Result<TrimmedFace, TessellateError> {
    let Some(patches) = Patches::of(surface, plan) else {
        return Ok(TrimmedFace {
            mesh: TriangleMesh::default(),
            boundary: Vec::new(),
        });
    };
    let tri = triangulate_patches(&patches, region, plan)?;
    let mut mesh = TriangleMesh::default();
    let mut index = vec![u32::MAX; tri.params.len()];
    for t in &tri.triangles {
        let mut out = [0u32; 3];
        for (k, &i) in t.iter().enumerate() {
            let slot = &mut index[i as usize];
            if *slot == u32::MAX {
                let (patch, s, w) = patches.at(tri.params[i as usize]);
                *slot = u32::try_from(mesh.positions.len())
                    .ok()
                    .filter(|&n| n != u32::MAX)
                    .ok_or(TessellateError::TooManyVertices)?;
                mesh.positions.push(patch.eval(s, w) + DVec3::ZERO);
                mesh.normals.push(patch.normal(s, w));
            }
            out[k] = *slot;
        }
        mesh.indices.push(out);
    }
    let boundary = tri
        .boundary
        .iter()
        .map(|line| {
            line.iter()
                .map(|&i| patches.eval(tri.params[i as usize]))
                .collect()
        })
        .collect();
    Ok(TrimmedFace { mesh, boundary })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::NurbsSurface;
    use crate::geom::trim::{ParamCurve, TrimLoop};
    use crate::scene::model::{Geometry, Object, SurfaceGeometry};
    use crate::tessellate::{TessellationMode, tessellate_object};
    use std::f64::consts::PI;

    /// The even-odd test against a polygon, independent of the trim code.
    fn in_polygon(p: DVec2, poly: &[DVec2]) -> bool {
        let mut odd = false;
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                odd = !odd;
            }
        }
        odd
    }

    fn distance_to_polygon(p: DVec2, poly: &[DVec2]) -> f64 {
        (0..poly.len())
            .map(|k| {
                let (a, b) = (poly[k].extend(0.0), poly[(k + 1) % poly.len()].extend(0.0));
                crate::geom::segment::distance_to_segment(p.extend(0.0), a, b)
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn dense_circle(c: DVec2, r: f64) -> Vec<DVec2> {
        (0..4096)
            .map(|k| c + r * DVec2::from_angle(2.0 * PI * k as f64 / 4096.0))
            .collect()
    }

    /// A curved biquadratic NURBS over [0, 2]² with 2 × 2 spans, cut by an outer square, a
    /// round hole across the middle knot lines and a clockwise square island in the hole.
    fn bent_surface() -> (Surface, Vec<Vec<DVec2>>) {
        let n = 4;
        let mut points = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64 * 2.0 / 3.0, j as f64 * 2.0 / 3.0);
                let z = 0.3 * ((i * j) % 3) as f64 - 0.2 * (i as f64 - 1.5).powi(2);
                points.push(DVec4::new(x, y, z, 1.0));
            }
        }
        let knots = vec![0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0];
        let nurbs = NurbsSurface::new(2, 2, knots.clone(), knots, n, n, points).unwrap();
        let (c, r) = (DVec2::new(1.0, 0.9), 0.5);
        let to2 =
            |q: &[(f64, f64)]| -> Vec<DVec2> { q.iter().map(|&(x, y)| DVec2::new(x, y)).collect() };
        let outer = to2(&[(0.1, 0.1), (1.9, 0.1), (1.9, 1.9), (0.1, 1.9)]);
        let island = to2(&[(0.9, 0.8), (0.9, 1.0), (1.1, 1.0), (1.1, 0.8)]);
        let surface = Surface {
            geometry: SurfaceGeometry::Nurbs(nurbs),
            trims: vec![
                TrimLoop::closed(ParamCurve::polygon(&outer), false),
                TrimLoop::closed(ParamCurve::circle(c, r), true),
                TrimLoop::closed(ParamCurve::polygon(&island), false),
            ],
            trim_space: Default::default(),
        };
        let loops = vec![outer, dense_circle(c, r), island];
        (surface, loops)
    }

    fn param_triangulation(surface: &Surface, mode: TessellationMode) -> ParamTriangulation {
        let plan = Plan::new(mode).unwrap();
        let region = surface.trim_region().unwrap().unwrap();
        triangulate_patches(&Patches::of(surface, plan).unwrap(), &region, plan).unwrap()
    }

    #[test]
    fn every_triangle_centre_lies_inside_the_loops() {
        let (surface, loops) = bent_surface();
        for mode in [
            TessellationMode::TrianglesPerPatch(128),
            TessellationMode::Adaptive { tolerance: 2e-3 },
        ] {
            let tri = param_triangulation(&surface, mode);
            // Away from the loops by more than their sampling error: the circle's chords are
            // within r (1 - cos(π/32)) = 2.4e-3 of it in the grid mode (8 segments per
            // quarter at least) and about the tolerance in the adaptive one.
            let margin = 1e-2;
            let mut checked = 0;
            let mut area = 0.0;
            for t in &tri.triangles {
                let [a, b, c] = t.map(|i| tri.params[i as usize]);
                let twice = (b - a).perp_dot(c - a);
                assert!(twice > 0.0, "{mode:?}: clockwise or flat triangle");
                area += 0.5 * twice;
                let centre = (a + b + c) / 3.0;
                if loops
                    .iter()
                    .any(|l| distance_to_polygon(centre, l) < margin)
                {
                    continue;
                }
                let parity = loops.iter().filter(|l| in_polygon(centre, l)).count();
                assert_eq!(parity % 2, 1, "{mode:?}: centre {centre} is trimmed away");
                checked += 1;
            }
            assert!(checked > 200, "{mode:?}: {checked}");
            // The kept area in the parameter plane: square, less the disc, plus the island.
            let want = 1.8 * 1.8 - PI * 0.25 + 0.2 * 0.2;
            assert!(
                (area - want).abs() < 0.01,
                "{mode:?}: area {area} vs {want}"
            );
        }
    }

    #[test]
    fn a_plate_with_a_round_hole_misses_the_holes_area() {
        // The plane z = 0 over [0, 1]² (x = u, y = v), a hole of radius r: the mesh's area is
        // 1 - π r² up to the polygon inscribed in the circle, whose area falls short of the
        // disc's by less than its perimeter times the chord height, i.e. 2π r · tolerance.
        let plate = BezierPatch::from_points(
            1,
            1,
            &[
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
            ],
        )
        .unwrap();
        let r = 0.3;
        for tolerance in [1e-2, 1e-4] {
            let surface = Surface {
                trims: vec![
                    TrimLoop::closed(
                        ParamCurve::polygon(&[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]),
                        false,
                    ),
                    TrimLoop::closed(ParamCurve::circle(DVec2::new(0.45, 0.55), r), true),
                ],
                ..Surface::bezier(plate.clone())
            };
            let object = Object {
                name: "plate".into(),
                material: 0,
                geometry: Geometry::Surfaces(vec![surface]),
            };
            let (mesh, report) =
                tessellate_object(&object, TessellationMode::Adaptive { tolerance }).unwrap();
            let Geometry::Mesh(mesh) = mesh.geometry else {
                panic!("not a mesh")
            };
            let area: f64 = mesh
                .indices
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum();
            let exact = 1.0 - PI * r * r;
            assert!(area >= exact - 1e-12, "{tolerance}: {area} < {exact}");
            assert!(
                area - exact <= 2.0 * PI * r * tolerance,
                "{tolerance}: {area} vs {exact}"
            );
            assert!(mesh.positions.iter().all(|p| p.z == 0.0));
            assert_eq!(report.trim_gaps.faces, 1);
        }
    }
}
