//! Writing a scene as RON, all geometry inline.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DVec3, Vec3};

use super::schema::*;
use super::surfaces::surface_def;
use crate::scene::animation::CameraPath;
use crate::scene::model::*;

/// The serde mirror of a scene with all geometry inline (meshes are not representable
/// inline and are refused). Shared geometry is written once, with the first object that
/// places it; the others are `Instance`s of that object, each placed by its matrix.
pub fn scene_to_file(scene: &Scene) -> Result<SceneFile, String> {
    let c = &scene.camera;
    let t = |v: DVec3| (v.x, v.y, v.z);
    let tc = |v: Vec3| (v.x, v.y, v.z);
    let mut objects = Vec::new();
    let mut written: HashMap<*const Geometry, String> = HashMap::new();
    for o in &scene.objects {
        let limit_patches: Vec<Surface>;
        let (geometry, transform) = match &o.geometry {
            Geometry::Instance(i) => {
                let key = Arc::as_ptr(&i.geometry);
                let placed = vec![TransformDef::matrix(&i.transform)];
                if let Some(of) = written.get(&key) {
                    objects.push(ObjectDef {
                        name: Some(o.name.clone()),
                        geometry: GeometryDef::Instance { of: of.clone() },
                        material: Some(scene.materials[o.material].name.clone()),
                        up: None,
                        transform: placed,
                    });
                    continue;
                }
                written.insert(key, o.name.clone());
                (i.geometry.as_ref(), placed)
            }
            g => (g, Vec::new()),
        };
        let surfaces = match geometry {
            Geometry::Surfaces(s) => s,
            // Written as its limit surface's Bézier patches.
            Geometry::Subdivision(s) => {
                limit_patches = s.patches.iter().cloned().map(Surface::bezier).collect();
                &limit_patches
            }
            Geometry::Mesh(_) | Geometry::Instance(_) => {
                return Err(format!(
                    "object \"{}\" is a triangle mesh; RON scenes reference meshes by file",
                    o.name
                ));
            }
        };
        let defs = surfaces.iter().map(surface_def).collect();
        objects.push(ObjectDef {
            name: Some(o.name.clone()),
            geometry: GeometryDef::Surfaces(defs),
            material: Some(scene.materials[o.material].name.clone()),
            up: None,
            transform,
        });
    }
    Ok(SceneFile {
        camera: CameraDef {
            eye: t(c.eye),
            look_at: t(c.look_at),
            up: t(c.up),
            fov_y: c.fov_y,
            width: c.width,
            height: c.height,
            orbit: match &scene.animation {
                Some(CameraPath::Orbit { frames, degrees }) => Some(OrbitDef {
                    frames: *frames,
                    degrees: *degrees,
                }),
                _ => None,
            },
            keyframes: match &scene.animation {
                Some(CameraPath::Keys(keys)) => keys
                    .iter()
                    .map(|k| KeyDef {
                        frame: k.frame,
                        eye: Some(t(k.eye)),
                        look_at: Some(t(k.look_at)),
                        up: Some(t(k.up)),
                        fov_y: Some(k.fov_y),
                    })
                    .collect(),
                _ => Vec::new(),
            },
        },
        background: tc(scene.background),
        ambient: Some(scene.ambient),
        max_depth: Some(scene.max_depth),
        samples: scene.samples,
        lights: scene
            .lights
            .iter()
            .map(|l| match l {
                Light::Point {
                    position,
                    intensity,
                } => LightDef::Point {
                    position: t(*position),
                    intensity: tc(*intensity),
                },
                Light::Directional {
                    direction,
                    intensity,
                } => LightDef::Directional {
                    direction: t(*direction),
                    intensity: tc(*intensity),
                },
            })
            .collect(),
        materials: scene
            .materials
            .iter()
            .map(|m| {
                (
                    m.name.clone(),
                    MaterialDef {
                        diffuse: Some(tc(m.diffuse)),
                        specular: Some(m.specular),
                        shininess: Some(m.shininess),
                        reflect: Some(m.reflect),
                        transmit: Some(m.transmit),
                        ior: Some(m.ior),
                        highlight: Some(if m.blinn {
                            Highlight::Blinn
                        } else {
                            Highlight::Phong
                        }),
                    },
                )
            })
            .collect(),
        objects,
    })
}

/// RON text for a scene, geometry inline.
pub fn scene_to_ron(scene: &Scene) -> Result<String, String> {
    let file = scene_to_file(scene)?;
    let config = ron::ser::PrettyConfig::new()
        .struct_names(true)
        .depth_limit(4)
        .extensions(ron::extensions::Extensions::IMPLICIT_SOME);
    ron::ser::to_string_pretty(&file, config).map_err(|e| e.to_string())
}
