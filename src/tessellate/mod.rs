//! Triangle tessellation of Bézier patches: the baseline that the direct ray tracer is
//! compared against (Dammertz 2005, §3.4 and Tables 2.1–2.4, which tessellate every patch
//! into 512, 4608 and 131072 triangles).
//!
//! Every vertex is a point of the exact surface evaluated in `f64` (de Casteljau), with
//! the normal from the exact derivatives ([`BezierPatch::normal`], which also handles the
//! collapsed edges of the teapot's lid and bottom). The mesh is crack-free across patch
//! borders: boundary curves are shared objects ([`edge`]), sampled once from a canonical
//! direction, and vertices are welded by their exact `f64` position. Where a patch's grid
//! is finer than one of its boundary curves (adaptive mode), the ring of triangles next to
//! that boundary is stitched by merging the two vertex loops by parameter ([`stitch`]).
//!
//! A trimmed surface is triangulated in its parameter domain instead, constrained to its
//! sampled loops ([`trimmed`]). Neighbouring trimmed faces are joined along the edges they
//! share: a boundary sample of one face that lies on the other's trim curve is sampled on
//! both and placed at one position ([`shared`]), so a closed solid's mesh is closed. What
//! gaps remain (free edges, edges farther apart than the file's tolerance) are measured
//! and reported ([`gaps`]), and so is the largest distance of the surface from the mesh.

mod cubes;
mod edge;
pub mod gaps;
mod shared;
mod stitch;
mod subdivision;
mod trimmed;
pub mod write;

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use thiserror::Error;

use crate::geom::BezierPatch;
use crate::scene::model::{Geometry, Object, Scene, Surface, SurfaceGeometry, TriangleMesh};

pub use edge::MAX_ADAPTIVE_SEGMENTS;
use edge::{EdgeCurve, EdgeKey, Side, segments_for_tolerance};
pub use gaps::TrimGaps;
pub use write::{MeshFormat, write_mesh_scene};

/// How finely each patch is cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TessellationMode {
    /// A `grid_u` × `grid_v` grid of quads per patch, each split into two triangles.
    Uniform { grid_u: u32, grid_v: u32 },
    /// `n` triangles per patch: the grid `g_u × g_v` with `2 g_u g_v = n` that is closest
    /// to square (`g_u ≥ g_v`, `g_v` the largest divisor of n/2 not above √(n/2)), so
    /// n = 2k² gives the k × k grid of Dammertz's tables (512 → 16², 4608 → 48²,
    /// 131072 → 256²). Odd n has no such grid and is rejected.
    TrianglesPerPatch(u32),
    /// Chord height at most `tolerance` (scene units) along every boundary curve and along
    /// the mid-parameter curves of each patch.
    Adaptive { tolerance: f64 },
}

/// Why a scene could not be tessellated.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TessellateError {
    #[error(
        "{0} triangles per patch is not 2·g_u·g_v for whole grid sizes g_u, g_v ≥ 1; use an even count such as 512 (16×16), 4608 (48×48) or 131072 (256×256)"
    )]
    TriangleCount(u32),
    #[error("grid {0}×{1}: both grid sizes must be at least 1")]
    Grid(u32, u32),
    #[error("tolerance {0} must be a positive finite number")]
    Tolerance(f64),
    #[error("the mesh would have more than 2^32 - 1 vertices")]
    TooManyVertices,
    #[error("a trimmed surface's parameter point cannot be triangulated: {0}")]
    Parameter(String),
    #[error(
        "the tessellation would reach {triangles} triangles by patch {patch} of object {object:?}, above the budget of {budget} (2^24 triangles, about 1 GB with their vertices); use a coarser --grid or --triangles-per-patch, or a larger --tolerance"
    )]
    Budget {
        object: String,
        patch: u32,
        triangles: u64,
        budget: u64,
    },
    #[error(
        "trimmed face {face} of object {object:?} would need about {triangles:.1e} triangles to lie within the tolerance (estimated from its control points before any work), above the budget of {budget} (2^24 triangles, about 1 GB with their vertices); its control points may be damaged, or use a larger --tolerance"
    )]
    Estimate {
        object: String,
        face: u32,
        triangles: f64,
        budget: u64,
    },
}

/// Most triangles one tessellation may make: 2^24 (16.7 M), 12 bytes of indices each plus
/// about half a vertex each (24 bytes, and the welding map's entry), about 1 GB in all.
/// Dammertz's finest table row (131072 per patch) on the 32-patch teapot is 4.2 M;
/// `--grid 100000,100000` asked for 40 GB.
pub const MAX_TRIANGLES: u64 = 1 << 24;

/// Size of a tessellation. `bytes` is the memory the triangle path renders from: `f32`
/// positions and normals (24 bytes per vertex) and `u32` indices (12 bytes per triangle).
/// `trim_gaps` are the gaps between the trimmed faces of the tessellated object or scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TessellationReport {
    pub triangles: u64,
    pub vertices: u64,
    pub bytes: u64,
    pub trim_gaps: TrimGaps,
    /// The largest distance from a trimmed face's exact surface to its triangles, probed at
    /// thirteen points of every triangle in the face's parameters (scene units).
    pub surface_distance: f64,
    /// The largest distance of a vertex on an edge two trimmed faces share from a face's
    /// own surface point there (scene units): the vertex is one face's exact point, so this
    /// is how far apart the file's two faces are along their edges.
    pub edge_offset: f64,
    /// The distance within which boundary samples of trimmed faces are taken as one point
    /// ([`shared::EDGE_FRACTION`] of the model).
    pub edge_tolerance: f64,
}

/// Bytes per vertex of the rendered mesh: three `f32` position and three `f32` normal
/// coordinates.
const BYTES_PER_VERTEX: u64 = 24;
/// Bytes per triangle: three `u32` indices.
const BYTES_PER_TRIANGLE: u64 = 12;

impl TessellationReport {
    pub fn of(mesh: &TriangleMesh) -> Self {
        let (triangles, vertices) = (mesh.indices.len() as u64, mesh.positions.len() as u64);
        TessellationReport {
            triangles,
            vertices,
            bytes: vertices * BYTES_PER_VERTEX + triangles * BYTES_PER_TRIANGLE,
            ..TessellationReport::default()
        }
    }

    /// Adds the sizes and takes the larger distances; gaps are a property of the faces
    /// measured together, so they are left to the caller that has them all
    /// ([`tessellate_scene`]).
    pub fn add(&mut self, other: &TessellationReport) {
        self.triangles += other.triangles;
        self.vertices += other.vertices;
        self.bytes += other.bytes;
        self.surface_distance = self.surface_distance.max(other.surface_distance);
        self.edge_offset = self.edge_offset.max(other.edge_offset);
    }
}

/// Where a vertex came from: the patch (index into the slice given to
/// [`tessellate_patches`]) and the parameters in that patch's own [0,1]². A vertex shared
/// by several patches records the first one that made it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexParam {
    pub patch: u32,
    pub u: f64,
    pub v: f64,
}

/// A tessellated set of patches with the parameters of each vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PatchMesh {
    pub mesh: TriangleMesh,
    pub params: Vec<VertexParam>,
}

/// Replaces every surface object of `scene` by its tessellation; meshes are kept as they
/// are. Camera, lights and materials are unchanged, so the result renders comparably.
pub fn tessellate_scene(
    scene: &Scene,
    mode: TessellationMode,
) -> Result<(Scene, TessellationReport), TessellateError> {
    tessellate_scene_with(scene, mode, &mut || {})
}

/// [`tessellate_scene`], calling `patch_done()` after each patch, for a progress bar. The
/// scene's triangles stay within [`MAX_TRIANGLES`] in all.
pub fn tessellate_scene_with(
    scene: &Scene,
    mode: TessellationMode,
    patch_done: &mut dyn FnMut(),
) -> Result<(Scene, TessellationReport), TessellateError> {
    let mut report = TessellationReport::default();
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut boundaries = Vec::new();
    let (mut splits, edge_tolerance) = split_and_join(&scene.objects, mode)?;
    for (object, split) in scene.objects.iter().zip(&mut splits) {
        let budget = Budget {
            object: &object.name,
            triangles: MAX_TRIANGLES.saturating_sub(report.triangles),
        };
        let (o, r, b) = object_within(object, split.take(), mode, budget, patch_done)?;
        report.add(&r);
        objects.push(o);
        boundaries.extend(b);
    }
    report.trim_gaps = gaps::measure(&boundaries);
    report.edge_tolerance = edge_tolerance;
    Ok((
        Scene {
            objects,
            ..scene.clone()
        },
        report,
    ))
}

/// One object's tessellation (a mesh object is returned unchanged). Its untrimmed surfaces
/// become one welded, crack-free mesh as by [`tessellate_patches`]; each trimmed surface
/// is appended as its own piece ([`trimmed`]).
pub fn tessellate_object(
    object: &Object,
    mode: TessellationMode,
) -> Result<(Object, TessellationReport), TessellateError> {
    let budget = Budget {
        object: &object.name,
        triangles: MAX_TRIANGLES,
    };
    let (mut splits, edge_tolerance) = split_and_join(std::slice::from_ref(object), mode)?;
    let (object, mut report, boundaries) =
        object_within(object, splits[0].take(), mode, budget, &mut || {})?;
    report.trim_gaps = gaps::measure(&boundaries);
    report.edge_tolerance = edge_tolerance;
    Ok((object, report))
}

/// One trimmed surface's share of a tessellation, with each vertex's parameters in the
/// surface's own domain.
#[derive(Clone, Debug)]
pub struct TrimmedMesh {
    /// The surface's index in the slice given to [`tessellate_trimmed`].
    pub surface: usize,
    pub mesh: TriangleMesh,
    pub params: Vec<DVec2>,
}

/// The trimmed surfaces among `surfaces` tessellated as [`tessellate_scene`] does them
/// (joined along the edges they share), each with its vertices' parameters, so that the
/// mesh can be checked against the exact surfaces; the report has the distances, not the
/// gaps.
pub fn tessellate_trimmed(
    surfaces: &[Surface],
    mode: TessellationMode,
) -> Result<(Vec<TrimmedMesh>, TessellationReport), TessellateError> {
    let plan = Plan::new(mode)?;
    let (mut index, mut faces) = (Vec::new(), Vec::new());
    for (k, s) in surfaces.iter().enumerate() {
        if let Some(region) = s.trim_region().ok().flatten()
            && let Some(face) = trimmed::Face::new(s, region, plan)
                .map_err(|triangles| estimate_error("", faces.len(), triangles))?
        {
            index.push(k);
            faces.push(face);
        }
    }
    let mut report = TessellationReport {
        edge_tolerance: shared::join(&mut faces),
        ..TessellationReport::default()
    };
    let mut out = Vec::with_capacity(faces.len());
    for (n, (face, surface)) in faces.iter().zip(index).enumerate() {
        let budget = Budget {
            object: "",
            triangles: MAX_TRIANGLES.saturating_sub(report.triangles),
        };
        let face = face.tessellate(plan, budget, n as u32)?;
        report.add(&TessellationReport {
            surface_distance: face.deviation,
            edge_offset: face.offset,
            ..TessellationReport::of(&face.mesh)
        });
        out.push(TrimmedMesh {
            surface,
            mesh: face.mesh,
            params: face.params,
        });
    }
    Ok((out, report))
}

/// An object's free-form surfaces: the Bézier patches of its untrimmed ones and its
/// trimmed faces, ready to be triangulated.
struct Split {
    plain: Vec<BezierPatch>,
    faces: Vec<trimmed::Face>,
}

/// Each object's surfaces split (`None` for other geometry), with the trimmed faces of all
/// objects joined along the edges they share ([`shared`]), and the joining distance.
fn split_and_join(
    objects: &[Object],
    mode: TessellationMode,
) -> Result<(Vec<Option<Split>>, f64), TessellateError> {
    let mut splits = Vec::with_capacity(objects.len());
    for object in objects {
        // An instance is tessellated as its placed copy.
        let geometry = object.geometry.resolved();
        let Geometry::Surfaces(surfaces) = geometry.as_ref() else {
            splits.push(None);
            continue;
        };
        let plan = Plan::new(mode)?;
        let mut split = Split {
            plain: Vec::new(),
            faces: Vec::new(),
        };
        for s in surfaces {
            // Loops that fail to convert were refused at load; were one to get here, the
            // surface is drawn untrimmed, as the renderer does.
            match s.trim_region().ok().flatten() {
                Some(region) => split
                    .faces
                    .extend(trimmed::Face::new(s, region, plan).map_err(|triangles| {
                        estimate_error(&object.name, split.faces.len(), triangles)
                    })?),
                None => match &s.geometry {
                    SurfaceGeometry::Bezier(p) => split.plain.push(p.clone()),
                    SurfaceGeometry::Nurbs(n) => split.plain.extend(n.to_bezier_patches()),
                },
            }
        }
        splits.push(Some(split));
    }
    // The faces of all objects are joined together (a part's faces may be split over
    // objects by colour), then handed back to their objects.
    let mut faces: Vec<trimmed::Face> = Vec::new();
    let mut counts = Vec::with_capacity(splits.len());
    for split in splits.iter_mut().flatten() {
        counts.push(split.faces.len());
        faces.append(&mut split.faces);
    }
    let tolerance = shared::join(&mut faces);
    let mut faces = faces.into_iter();
    for (split, n) in splits.iter_mut().flatten().zip(counts) {
        split.faces = faces.by_ref().take(n).collect();
    }
    Ok((splits, tolerance))
}

/// A trimmed face's boundary polylines in space.
type FaceBoundary = Vec<Vec<DVec3>>;

/// How many more triangles a tessellation may make, and the object named when it would
/// make more.
#[derive(Clone, Copy)]
struct Budget<'a> {
    object: &'a str,
    triangles: u64,
}

/// The error for trimmed face `face` of `object`, estimated to need `triangles`.
fn estimate_error(object: &str, face: usize, triangles: f64) -> TessellateError {
    TessellateError::Estimate {
        object: object.to_string(),
        face: face as u32,
        triangles,
        budget: MAX_TRIANGLES,
    }
}

/// [`tessellate_object`] within `budget`, without the gap measure, with the boundaries of
/// its trimmed faces; `split` is the object's surfaces, split by [`split_and_join`].
fn object_within(
    object: &Object,
    split: Option<Split>,
    mode: TessellationMode,
    budget: Budget,
    patch_done: &mut dyn FnMut(),
) -> Result<(Object, TessellationReport, Vec<FaceBoundary>), TessellateError> {
    let mut boundaries = Vec::new();
    let (mut surface_distance, mut edge_offset) = (0.0f64, 0.0f64);
    // An instance is tessellated as its placed copy.
    let geometry = object.geometry.resolved();
    let mesh = match (split, geometry.as_ref()) {
        (Some(split), _) => {
            let plan = Plan::new(mode)?;
            let mut mesh = patches_within(&split.plain, mode, budget, patch_done)?.mesh;
            for (k, face) in split.faces.iter().enumerate() {
                let budget = Budget {
                    triangles: budget.triangles.saturating_sub(mesh.indices.len() as u64),
                    ..budget
                };
                let face = face.tessellate(plan, budget, k as u32)?;
                append(&mut mesh, face.mesh)?;
                boundaries.push(face.boundary);
                surface_distance = surface_distance.max(face.deviation);
                edge_offset = edge_offset.max(face.offset);
                patch_done();
            }
            mesh
        }
        (None, Geometry::Subdivision(surface)) => {
            subdivision::tessellate_surface(surface, Plan::new(mode)?, budget, patch_done)?
        }
        (None, Geometry::Mesh(m)) => m.clone(),
        (None, _) => tessellate_patches(&geometry.bezier_patches(), mode)?.mesh,
    };
    let report = TessellationReport {
        surface_distance,
        edge_offset,
        ..TessellationReport::of(&mesh)
    };
    Ok((
        Object {
            geometry: Geometry::Mesh(mesh),
            ..object.clone()
        },
        report,
        boundaries,
    ))
}

/// Appends `part` to `mesh`, renumbering its vertices.
fn append(mesh: &mut TriangleMesh, part: TriangleMesh) -> Result<(), TessellateError> {
    if mesh.positions.len() + part.positions.len() >= u32::MAX as usize {
        return Err(TessellateError::TooManyVertices);
    }
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(part.positions);
    mesh.normals.extend(part.normals);
    mesh.indices
        .extend(part.indices.into_iter().map(|t| t.map(|i| i + base)));
    Ok(())
}

/// Tessellates patches into one welded, crack-free mesh, keeping each vertex's (u, v).
pub fn tessellate_patches(
    patches: &[BezierPatch],
    mode: TessellationMode,
) -> Result<PatchMesh, TessellateError> {
    let budget = Budget {
        object: "",
        triangles: MAX_TRIANGLES,
    };
    patches_within(patches, mode, budget, &mut || {})
}

fn patches_within(
    patches: &[BezierPatch],
    mode: TessellationMode,
    budget: Budget,
    patch_done: &mut dyn FnMut(),
) -> Result<PatchMesh, TessellateError> {
    let plan = Plan::new(mode)?;
    let mut t = Tessellator::default();
    for (index, patch) in patches.iter().enumerate() {
        t.patch(index as u32, patch, plan, budget)?;
        patch_done();
    }
    Ok(t.out)
}

/// A validated mode.
#[derive(Clone, Copy)]
enum Plan {
    Uniform { grid_u: usize, grid_v: usize },
    Adaptive { tolerance: f64 },
}

impl Plan {
    fn new(mode: TessellationMode) -> Result<Plan, TessellateError> {
        match mode {
            TessellationMode::Uniform { grid_u, grid_v } => {
                if grid_u == 0 || grid_v == 0 {
                    return Err(TessellateError::Grid(grid_u, grid_v));
                }
                Ok(Plan::Uniform {
                    grid_u: grid_u as usize,
                    grid_v: grid_v as usize,
                })
            }
            TessellationMode::TrianglesPerPatch(n) => {
                let (grid_u, grid_v) = grid_for_triangles(n)?;
                Ok(Plan::Uniform {
                    grid_u: grid_u as usize,
                    grid_v: grid_v as usize,
                })
            }
            TessellationMode::Adaptive { tolerance } => {
                if !(tolerance.is_finite() && tolerance > 0.0) {
                    return Err(TessellateError::Tolerance(tolerance));
                }
                Ok(Plan::Adaptive { tolerance })
            }
        }
    }
}

impl Plan {
    /// The grid `(g_u, g_v)` of a patch and the segments wanted on each side (in
    /// [`Side::ALL`] order): the plan's grid, or in adaptive mode each side's own count and
    /// the grid fine enough for the opposite sides and the mid-parameter curves.
    fn grid(self, patch: &BezierPatch, curves: &[EdgeCurve; 4]) -> (usize, usize, [usize; 4]) {
        match self {
            Plan::Uniform { grid_u, grid_v } => (grid_u, grid_v, [grid_u, grid_v, grid_u, grid_v]),
            Plan::Adaptive { tolerance } => {
                let wanted = curves.each_ref().map(|c| c.adaptive_segments(tolerance));
                let mid_u =
                    segments_for_tolerance(&|t| patch.eval(t, 0.5), patch.degree_u(), tolerance);
                let mid_v =
                    segments_for_tolerance(&|t| patch.eval(0.5, t), patch.degree_v(), tolerance);
                (
                    wanted[0].max(wanted[2]).max(mid_u),
                    wanted[1].max(wanted[3]).max(mid_v),
                    wanted,
                )
            }
        }
    }
}

/// The grid `(g_u, g_v)` for `n` triangles per patch; see
/// [`TessellationMode::TrianglesPerPatch`].
pub fn grid_for_triangles(n: u32) -> Result<(u32, u32), TessellateError> {
    if n == 0 || !n.is_multiple_of(2) {
        return Err(TessellateError::TriangleCount(n));
    }
    let cells = n / 2;
    let grid_v = (1..=cells)
        .take_while(|g| g * g <= cells)
        .filter(|g| cells.is_multiple_of(*g))
        .last()
        .unwrap_or(1);
    Ok((cells / grid_v, grid_v))
}

#[derive(Default)]
struct Tessellator {
    out: PatchMesh,
    /// Exact position bits → vertex index.
    weld: HashMap<[u64; 3], u32>,
    /// Shared boundary curves → their vertices in canonical order, both ends included.
    edges: HashMap<EdgeKey, Vec<u32>>,
}

impl Tessellator {
    fn patch(
        &mut self,
        index: u32,
        patch: &BezierPatch,
        plan: Plan,
        budget: Budget,
    ) -> Result<(), TessellateError> {
        let curves = Side::ALL.map(|s| EdgeCurve::of(patch, s));
        let (mut grid_u, mut grid_v, wanted) = plan.grid(patch, &curves);
        let mut sides: [Vec<u32>; 4] = Default::default();
        for (k, side) in Side::ALL.into_iter().enumerate() {
            sides[k] = self.side_vertices(index, patch, side, &curves[k], wanted[k])?;
        }
        if !stitch::sides_match(grid_u, grid_v, &sides) {
            // The ring stitch needs at least one interior grid point.
            grid_u = grid_u.max(2);
            grid_v = grid_v.max(2);
        }
        // Checked before the grid is made: the interior grid alone is (g_u + 1)(g_v + 1)
        // vertices, so an absurd grid must be refused before its allocation.
        let triangles = self.out.mesh.indices.len() as u64 + 2 * grid_u as u64 * grid_v as u64;
        if triangles > budget.triangles {
            return Err(TessellateError::Budget {
                object: budget.object.to_string(),
                patch: index,
                triangles: triangles + (MAX_TRIANGLES - budget.triangles),
                budget: MAX_TRIANGLES,
            });
        }
        let mut interior = vec![0u32; (grid_u + 1) * (grid_v + 1)];
        for j in 1..grid_v {
            for i in 1..grid_u {
                let (u, v) = (i as f64 / grid_u as f64, j as f64 / grid_v as f64);
                interior[j * (grid_u + 1) + i] =
                    self.vertex(patch.eval(u, v), index, patch, u, v)?;
            }
        }
        let grid = stitch::Grid {
            nu: grid_u,
            nv: grid_v,
            interior: &interior,
            sides: &sides,
        };
        let indices = &mut self.out.mesh.indices;
        grid.triangulate(&mut |tri| {
            if tri[0] != tri[1] && tri[1] != tri[2] && tri[2] != tri[0] {
                indices.push(tri);
            }
        });
        Ok(())
    }

    /// The side's vertices in counter-clockwise order, both corners included, made on
    /// first use of the curve with `segments` segments and reused by every later patch.
    fn side_vertices(
        &mut self,
        index: u32,
        patch: &BezierPatch,
        side: Side,
        curve: &EdgeCurve,
        segments: usize,
    ) -> Result<Vec<u32>, TessellateError> {
        let mut verts = match self.edges.get(&curve.key) {
            Some(v) => v.clone(),
            None => {
                let mut v = Vec::with_capacity(segments + 1);
                for k in 0..=segments {
                    let t = k as f64 / segments as f64;
                    let (u, w) = side.param(if curve.reversed { 1.0 - t } else { t });
                    v.push(self.vertex(curve.sample(k, segments), index, patch, u, w)?);
                }
                self.edges.insert(curve.key.clone(), v.clone());
                v
            }
        };
        if curve.reversed {
            verts.reverse();
        }
        Ok(verts)
    }

    /// The welded vertex at `p`, made (with the exact normal at (u, v)) if new.
    fn vertex(
        &mut self,
        p: DVec3,
        index: u32,
        patch: &BezierPatch,
        u: f64,
        v: f64,
    ) -> Result<u32, TessellateError> {
        let p = p + DVec3::ZERO; // fold -0.0 into +0.0 so the key is unique
        let key = p.to_array().map(f64::to_bits);
        if let Some(&i) = self.weld.get(&key) {
            return Ok(i);
        }
        let i = u32::try_from(self.out.mesh.positions.len())
            .ok()
            .filter(|&i| i != u32::MAX)
            .ok_or(TessellateError::TooManyVertices)?;
        self.out.mesh.positions.push(p);
        self.out.mesh.normals.push(patch.normal(u, v));
        self.out.params.push(VertexParam { patch: index, u, v });
        self.weld.insert(key, i);
        Ok(i)
    }
}
