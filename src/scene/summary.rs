//! A description of a scene for `info`: counts, degrees, bounds, materials, lights.

use std::collections::BTreeMap;

use serde::Serialize;

use super::model::{Geometry, Light, Scene, SurfaceGeometry};

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

#[derive(Debug, Serialize)]
pub struct ObjectSummary {
    pub name: String,
    pub material: String,
    pub surfaces: usize,
    pub nurbs_surfaces: usize,
    pub patches: usize,
    pub trim_loops: usize,
    pub triangles: usize,
}

pub fn summarize(scene: &Scene) -> SceneSummary {
    let mut degrees = BTreeMap::new();
    let mut objects = Vec::new();
    let (mut patches, mut rational, mut nurbs, mut triangles) = (0, 0, 0, 0);
    for o in &scene.objects {
        let bez = o.bezier_patches();
        for p in &bez {
            *degrees
                .entry(format!("{}x{}", p.degree_u(), p.degree_v()))
                .or_insert(0) += 1;
            rational += p.is_rational() as usize;
        }
        let (surfaces, n, trims, tris) = match &o.geometry {
            Geometry::Surfaces(s) => (
                s.len(),
                s.iter()
                    .filter(|s| matches!(s.geometry, SurfaceGeometry::Nurbs(_)))
                    .count(),
                s.iter().map(|s| s.trims.len()).sum(),
                0,
            ),
            Geometry::Mesh(m) => (0, 0, 0, m.indices.len()),
            Geometry::Subdivision(_) => (1, 0, 0, 0),
        };
        patches += bez.len();
        nurbs += n;
        triangles += tris;
        objects.push(ObjectSummary {
            name: o.name.clone(),
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
    }
}
