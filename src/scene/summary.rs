//! A description of a scene for `info`: counts, degrees, bounds, materials, lights.

use std::collections::BTreeMap;

use serde::Serialize;

use super::model::{Geometry, Light, Scene, Surface, SurfaceGeometry};
use crate::geom::trim::Coverage;

#[derive(Debug, Serialize)]
pub struct SceneSummary {
    pub camera: CameraSummary,
    pub objects: Vec<ObjectSummary>,
    pub patches: usize,
    pub rational_patches: usize,
    pub nurbs_surfaces: usize,
    pub triangles: usize,
    /// "du x dv" → number of Bézier patches of that degree (after NURBS conversion).
    pub degrees: BTreeMap<String, usize>,
    pub bounds_min: [f64; 3],
    pub bounds_max: [f64; 3],
    pub materials: Vec<String>,
    pub lights: Vec<String>,
    pub max_depth: u32,
    /// The declared length unit in words, when the file declared one.
    pub unit: Option<String>,
    /// Millimetres per coordinate unit, when the file declared its unit.
    pub millimetres_per_unit: Option<f64>,
}

#[derive(Debug, Serialize)]
pub struct CameraSummary {
    pub eye: [f64; 3],
    pub look_at: [f64; 3],
    pub up: [f64; 3],
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
}

/// A Catmull–Clark surface's construction (see [`crate::geom::subdiv::Stats`]).
#[derive(Debug, Serialize)]
pub struct SubdivisionSummary {
    pub cage_vertices: usize,
    pub cage_faces: usize,
    /// Cage faces that are holes (no limit patch).
    pub holes: usize,
    /// Quads after the first Catmull–Clark step (the `trace` patch numbers).
    pub quads: usize,
    pub regular_patches: usize,
    /// Final children at extraordinary vertices.
    pub extraordinary_ends: usize,
    pub t_junctions: usize,
    /// Deepest refinement level (1: every quad regular).
    pub levels: u32,
}

#[derive(Debug, Serialize)]
pub struct ObjectSummary {
    pub name: String,
    /// For an instance, the first object (by index) placing the same shared geometry: the
    /// geometry is held and prepared once for all of them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shares_geometry_of: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivision: Option<SubdivisionSummary>,
    pub material: String,
    pub surfaces: usize,
    pub nurbs_surfaces: usize,
    pub patches: usize,
    pub trim_loops: usize,
    pub triangles: usize,
    /// One entry per surface with trim loops.
    pub trimmed_surfaces: Vec<TrimSummary>,
}

/// What a surface's trim loops are made of and what they leave of its patches.
#[derive(Debug, Serialize)]
pub struct TrimSummary {
    /// The surface's number in its object, in file order.
    pub surface: usize,
    pub loops: usize,
    pub holes: usize,
    /// Loop segments (OBJ `curv2` pieces, IGES/STEP curves).
    pub curves: usize,
    /// Bézier pieces the curves became (after the monotone split).
    pub pieces: usize,
    /// Patches the loops cut, keep whole, and cut away (culled at load).
    pub patches_cut: usize,
    pub patches_whole: usize,
    pub patches_culled: usize,
}

fn trim_summary(k: usize, s: &Surface) -> Option<TrimSummary> {
    if s.trims.is_empty() {
        return None;
    }
    let mut t = TrimSummary {
        surface: k,
        loops: s.trims.len(),
        holes: s.trims.iter().filter(|l| l.hole).count(),
        curves: s.trims.iter().map(|l| l.segments.len()).sum(),
        pieces: s
            .trim_region()
            .ok()
            .flatten()
            .map_or(0, |r| r.piece_count()),
        patches_cut: 0,
        patches_whole: 0,
        patches_culled: 0,
    };
    for (_, coverage) in s.trimmed_patches() {
        match coverage {
            Coverage::Partial(_) => t.patches_cut += 1,
            Coverage::Inside => t.patches_whole += 1,
            Coverage::Outside => t.patches_culled += 1,
        }
    }
    Some(t)
}

/// The first object of `scene` that is an instance of the same shared geometry as object
/// `index`, if that object is an instance.
fn first_sharing(scene: &Scene, index: usize) -> Option<usize> {
    let shared = |k: usize| match &scene.objects[k].geometry {
        Geometry::Instance(i) => Some(&i.geometry),
        _ => None,
    };
    let mine = shared(index)?;
    (0..=index).find(|&k| shared(k).is_some_and(|g| std::sync::Arc::ptr_eq(g, mine)))
}

pub fn summarize(scene: &Scene) -> SceneSummary {
    let mut degrees = BTreeMap::new();
    let mut objects = Vec::new();
    let (mut patches, mut rational, mut nurbs, mut triangles) = (0, 0, 0, 0);
    for (index, o) in scene.objects.iter().enumerate() {
        let bez = o.bezier_patches();
        for p in &bez {
            *degrees
                .entry(format!("{}x{}", p.degree_u(), p.degree_v()))
                .or_insert(0) += 1;
            rational += p.is_rational() as usize;
        }
        // An instance is summarised as its placed copy.
        let geometry = o.geometry.resolved();
        let (surfaces, n, trims, tris) = match geometry.as_ref() {
            Geometry::Surfaces(s) => (
                s.len(),
                s.iter()
                    .filter(|s| matches!(s.geometry, SurfaceGeometry::Nurbs(_)))
                    .count(),
                s.iter().map(|s| s.trims.len()).sum(),
                0,
            ),
            Geometry::Mesh(m) => (0, 0, 0, m.indices.len()),
            Geometry::Subdivision(_) | Geometry::Instance(_) => (1, 0, 0, 0),
        };
        patches += bez.len();
        nurbs += n;
        triangles += tris;
        let subdivision = match geometry.as_ref() {
            Geometry::Subdivision(sd) => Some(SubdivisionSummary {
                cage_vertices: sd.cage.points.len(),
                cage_faces: sd.stats.cage_faces,
                holes: sd.stats.holes,
                quads: sd.stats.faces,
                regular_patches: sd.stats.regular,
                extraordinary_ends: sd.stats.extraordinary_ends,
                t_junctions: sd.stats.t_junctions,
                levels: sd.stats.levels,
            }),
            _ => None,
        };
        objects.push(ObjectSummary {
            name: o.name.clone(),
            shares_geometry_of: first_sharing(scene, index),
            subdivision,
            material: scene
                .materials
                .get(o.material)
                .map(|m| m.name.clone())
                .unwrap_or_default(),
            surfaces,
            nurbs_surfaces: n,
            patches: bez.len(),
            trim_loops: trims,
            triangles: tris,
            trimmed_surfaces: geometry
                .surfaces()
                .iter()
                .enumerate()
                .filter_map(|(k, s)| trim_summary(k, s))
                .collect(),
        });
    }
    let b = scene.bounds();
    let c = &scene.camera;
    SceneSummary {
        camera: CameraSummary {
            eye: c.eye.to_array(),
            look_at: c.look_at.to_array(),
            up: c.up.to_array(),
            fov_y: c.fov_y,
            width: c.width,
            height: c.height,
        },
        objects,
        patches,
        rational_patches: rational,
        nurbs_surfaces: nurbs,
        triangles,
        degrees,
        bounds_min: b.min.to_array(),
        bounds_max: b.max.to_array(),
        materials: scene.materials.iter().map(|m| m.name.clone()).collect(),
        lights: scene
            .lights
            .iter()
            .map(|l| match l {
                Light::Point { position, .. } => format!("point at {position}"),
                Light::Directional { direction, .. } => format!("directional towards {direction}"),
            })
            .collect(),
        max_depth: scene.max_depth,
        unit: scene.unit.as_ref().map(|u| u.words.clone()),
        millimetres_per_unit: scene.unit.as_ref().map(|u| u.millimetres),
    }
}
