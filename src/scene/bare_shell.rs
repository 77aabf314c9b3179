//! A bare geometry file's scene without its geometry: the framing camera and light, the
//! materials and the objects' names and materials. The BVH file of a bare file keeps it
//! (in the scene section, where a RON scene keeps its parse, under the key of the bare
//! file's inputs instead of the hash of a scene text), so that `render --bvh` and
//! `trace --bvh` on a bare file read no geometry: the framing cannot be made again from
//! the file's patches, as it comes from the control points' bounds, not the tight boxes
//! the records hold.

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::model::{Camera, Geometry, Light, Material, Object, Scene};
use crate::geom::bbox::DAabb;

#[derive(Serialize, Deserialize)]
pub struct BareShell {
    camera: Camera,
    background: Vec3,
    ambient: f32,
    max_depth: u32,
    samples: Option<u32>,
    lights: Vec<Light>,
    materials: Vec<Material>,
    /// Name and material index of each object, in order.
    objects: Vec<(String, usize)>,
    /// The geometry's bounds, min and max: `--width`, `--height` and `--up` frame the
    /// geometry again ([`crate::formats::load::reframe`]).
    bounds: [[f64; 3]; 2],
    /// The camera is the file's own (a USD stage's `Camera` prim), not a framing one.
    #[serde(default)]
    own_camera: bool,
}

impl BareShell {
    /// The shell of a bare file's scene as JSON; `None` for a scene with a camera path,
    /// which no bare file has.
    pub fn json_of(scene: &Scene) -> Option<Vec<u8>> {
        let bounds = scene.bounds();
        if scene.animation.is_some() || bounds.is_empty() {
            return None;
        }
        let shell = BareShell {
            camera: scene.camera.clone(),
            background: scene.background,
            ambient: scene.ambient,
            max_depth: scene.max_depth,
            samples: scene.samples,
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
            objects: scene
                .objects
                .iter()
                .map(|o| (o.name.clone(), o.material))
                .collect(),
            bounds: [bounds.min.to_array(), bounds.max.to_array()],
            own_camera: scene.own_camera,
        };
        serde_json::to_vec(&shell).ok()
    }

    /// The scene `json` describes, its objects without geometry (the BVH file holds it);
    /// `None` when the JSON is not a shell or names a material the shell lacks.
    pub fn scene_of(json: &[u8]) -> Option<Scene> {
        let shell: BareShell = serde_json::from_slice(json).ok()?;
        if shell
            .objects
            .iter()
            .any(|(_, m)| *m >= shell.materials.len())
        {
            return None;
        }
        Some(Scene {
            camera: shell.camera,
            background: shell.background,
            ambient: shell.ambient,
            max_depth: shell.max_depth,
            samples: shell.samples,
            animation: None,
            lights: shell.lights,
            materials: shell.materials,
            objects: shell
                .objects
                .into_iter()
                .map(|(name, material)| Object {
                    name,
                    material,
                    geometry: Geometry::Surfaces(Vec::new()),
                })
                .collect(),
            unread_bounds: Some(DAabb {
                min: DVec3::from_array(shell.bounds[0]),
                max: DVec3::from_array(shell.bounds[1]),
            }),
            own_camera: shell.own_camera,
            warnings: Vec::new(),
            unit: None,
        })
    }
}
