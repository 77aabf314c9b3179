//! Our RON scene format: the serde mirror of the scene model, and its conversion to and
//! from [`Scene`]. Geometry is referenced by file (relative to the scene) or given inline.

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DAffine3, DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::animation::{CameraKey, CameraPath};
use super::error::{LoadError, ParseError};
use super::model::*;
use crate::geom::BezierPatch;
use crate::geom::nurbs::NurbsSurface;

type V3 = (f64, f64, f64);
type C3 = (f32, f32, f32);

#[derive(Debug, Serialize, Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct SceneFile {
    pub camera: CameraDef,
    #[serde(default = "default_background")]
    pub background: C3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<u32>,
    /// Samples per pixel (`render --spp` overrides it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<u32>,
    #[serde(default)]
    pub lights: Vec<LightDef>,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDef>,
    pub objects: Vec<ObjectDef>,
}

fn default_background() -> C3 {
    (0.05, 0.05, 0.08)
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub eye: V3,
    pub look_at: V3,
    pub up: V3,
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
    /// A turntable: `orbit: (frames: 24, degrees: 360)` turns the eye about `look_at`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit: Option<OrbitDef>,
    /// Keyframes: `keyframes: [(frame: 0, eye: (…)), (frame: 24, eye: (…), fov_y: 30)]`;
    /// fields a key leaves out are the camera's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keyframes: Vec<KeyDef>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitDef {
    pub frames: u32,
    #[serde(default = "full_turn")]
    pub degrees: f64,
}

fn full_turn() -> f64 {
    360.0
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyDef {
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eye: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look_at: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_y: Option<f64>,
}

#[derive(Debug, Serialize, Deserialize)]
pub enum LightDef {
    Point {
        position: V3,
        #[serde(default = "white")]
        intensity: C3,
    },
    Directional {
        direction: V3,
        #[serde(default = "white")]
        intensity: C3,
    },
}

fn white() -> C3 {
    (1.0, 1.0, 1.0)
}

#[derive(Debug, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<C3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shininess: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflect: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmit: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub highlight: Option<Highlight>,
}

#[derive(Debug, Serialize, Deserialize, Clone, Copy, PartialEq)]
pub enum Highlight {
    Phong,
    Blinn,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDef {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub geometry: GeometryDef,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// The axis that is up in the object's geometry (`X`, `Y` or `Z`, default `Z`): a
    /// y-up model is turned to stand in the z-up scene before its transforms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Axis>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub transform: Vec<TransformDef>,
}

#[derive(Debug, Serialize, Deserialize)]
pub enum GeometryDef {
    /// A geometry file (`.bpt`, `.obj`, `.pbrt`, `.gltf`, `.glb`), relative to the scene.
    File(String),
    /// Inline free-form surfaces.
    Surfaces(Vec<SurfaceDef>),
    /// A Catmull–Clark surface: `Subdivision(File("cage.obj"))`, a polygon mesh (OBJ or
    /// glTF) as the control cage, with sharp (`EDGE_ONLY`) boundaries.
    Subdivision(Box<GeometryDef>),
}

#[derive(Debug, Serialize, Deserialize)]
pub enum SurfaceDef {
    /// A Bézier patch: degrees (du, dv), `(du+1)(dv+1)` points u fastest, optional weights.
    Bezier {
        degree: (usize, usize),
        points: Vec<V3>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
    },
    /// A NURBS surface: degrees, knot vectors, control net size (nu, nv), points u fastest.
    Nurbs {
        degree: (usize, usize),
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        count: (usize, usize),
        points: Vec<V3>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
    },
}

/// Transforms, applied in the order listed.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub enum TransformDef {
    Translate(f64, f64, f64),
    Scale(f64),
    ScaleXyz(f64, f64, f64),
    /// Degrees about the x, y or z axis (right-handed).
    RotateX(f64),
    RotateY(f64),
    RotateZ(f64),
    /// Degrees about an arbitrary axis.
    Rotate(V3, f64),
}

impl TransformDef {
    fn to_affine(self) -> DAffine3 {
        match self {
            TransformDef::Translate(x, y, z) => DAffine3::from_translation(DVec3::new(x, y, z)),
            TransformDef::Scale(s) => DAffine3::from_scale(DVec3::splat(s)),
            TransformDef::ScaleXyz(x, y, z) => DAffine3::from_scale(DVec3::new(x, y, z)),
            TransformDef::RotateX(d) => DAffine3::from_rotation_x(d.to_radians()),
            TransformDef::RotateY(d) => DAffine3::from_rotation_y(d.to_radians()),
            TransformDef::RotateZ(d) => DAffine3::from_rotation_z(d.to_radians()),
            TransformDef::Rotate(a, d) => {
                DAffine3::from_axis_angle(DVec3::from(a).normalize_or(DVec3::Z), d.to_radians())
            }
        }
    }
}

fn v3(t: V3) -> DVec3 {
    DVec3::new(t.0, t.1, t.2)
}

fn c3(t: C3) -> Vec3 {
    Vec3::new(t.0, t.1, t.2)
}

/// Parses RON scene text into the serde mirror; syntax errors carry line and column.
pub fn parse_scene_file(path: &Path, src: &str) -> Result<SceneFile, ParseError> {
    // Implicit `Some` lets users write `material: "pink"` instead of `Some("pink")`.
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .from_str::<SceneFile>(src)
        .map_err(|e| {
            ParseError::new(
                path,
                e.span.start.line,
                e.span.start.col,
                e.code.to_string(),
            )
        })
}

/// Reads a RON scene and everything it references.
pub fn read_scene(path: &Path) -> Result<Scene, LoadError> {
    let src = super::error::read_text(path)?;
    let file = parse_scene_file(path, &src)?;
    build_scene(path, file)
}

fn build_scene(path: &Path, file: SceneFile) -> Result<Scene, LoadError> {
    let c = &file.camera;
    let camera = Camera {
        eye: v3(c.eye),
        look_at: v3(c.look_at),
        up: v3(c.up),
        fov_y: c.fov_y,
        width: c.width,
        height: c.height,
    };
    validate_camera(path, &camera)?;
    let animation = camera_path(path, c, &camera)?;
    let max_spp = crate::render::sampler::MAX_SPP;
    if let Some(n) = file.samples
        && !(1..=max_spp).contains(&n)
    {
        return Err(LoadError::invalid(
            path,
            format!("samples: expected a count from 1 to {max_spp}, found {n}"),
        ));
    }
    let mut materials: Vec<Material> = file
        .materials
        .iter()
        .map(|(name, m)| material_from_def(name, m))
        .collect();
    for m in &materials {
        validate_material(path, m)?;
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut objects = Vec::with_capacity(file.objects.len());
    for (index, o) in file.objects.iter().enumerate() {
        let material = match &o.material {
            Some(name) => materials.iter().position(|m| &m.name == name).ok_or_else(|| {
                LoadError::invalid(path, format!("object {index} uses material \"{name}\", which is not defined in `materials`"))
            })?,
            None => {
                if !materials.iter().any(|m| m.name == "default") {
                    materials.push(Material::default_named("default"));
                }
                materials.iter().position(|m| m.name == "default").unwrap_or(0)
            }
        };
        let mut geometry = match &o.geometry {
            GeometryDef::File(f) => super::load::load_geometry(&base.join(f))?,
            GeometryDef::Subdivision(inner) => match inner.as_ref() {
                GeometryDef::File(f) => super::load::load_subdivision(&base.join(f))?,
                _ => {
                    return Err(LoadError::invalid(
                        path,
                        format!(
                            "object {index}: expected Subdivision(File(\"cage.obj\")): a cage is read from a mesh file"
                        ),
                    ));
                }
            },
            GeometryDef::Surfaces(defs) => Geometry::Surfaces(
                defs.iter()
                    .enumerate()
                    .map(|(k, d)| {
                        surface_from_def(d).map_err(|e| {
                            LoadError::invalid(path, format!("object {index}, surface {k}: {e}"))
                        })
                    })
                    .collect::<Result<_, _>>()?,
            ),
        };
        let stand = DAffine3::from_mat3(o.up.unwrap_or(Axis::Z).to_z_up());
        let m = o.transform.iter().fold(stand, |acc, t| t.to_affine() * acc);
        if m != DAffine3::IDENTITY {
            geometry.transform(&m);
        }
        let name = o.name.clone().unwrap_or_else(|| match &o.geometry {
            GeometryDef::File(f) => f.clone(),
            GeometryDef::Subdivision(inner) => match inner.as_ref() {
                GeometryDef::File(f) => f.clone(),
                _ => format!("object{index}"),
            },
            GeometryDef::Surfaces(_) => format!("object{index}"),
        });
        objects.push(Object {
            name,
            material,
            geometry,
        });
    }
    let lights = file
        .lights
        .iter()
        .map(|l| match *l {
            LightDef::Point {
                position,
                intensity,
            } => Light::Point {
                position: v3(position),
                intensity: c3(intensity),
            },
            LightDef::Directional {
                direction,
                intensity,
            } => Light::Directional {
                direction: v3(direction),
                intensity: c3(intensity),
            },
        })
        .collect();
    Ok(Scene {
        camera,
        background: c3(file.background),
        ambient: file.ambient.unwrap_or(DEFAULT_AMBIENT),
        max_depth: file.max_depth.unwrap_or(DEFAULT_MAX_DEPTH),
        samples: file.samples,
        animation,
        lights,
        materials,
        objects,
    })
}

/// The camera's animation, checked: an orbit has at least one frame and a finite angle;
/// keyframes are in increasing frame order and each is a valid camera.
fn camera_path(
    path: &Path,
    def: &CameraDef,
    camera: &Camera,
) -> Result<Option<CameraPath>, LoadError> {
    match (&def.orbit, def.keyframes.is_empty()) {
        (Some(_), false) => Err(LoadError::invalid(
            path,
            "camera: give either orbit or keyframes, not both",
        )),
        (Some(o), true) => {
            if o.frames == 0 || !o.degrees.is_finite() {
                return Err(LoadError::invalid(
                    path,
                    "camera: orbit needs frames >= 1 and a finite number of degrees",
                ));
            }
            Ok(Some(CameraPath::Orbit {
                frames: o.frames,
                degrees: o.degrees,
            }))
        }
        (None, true) => Ok(None),
        (None, false) => {
            let mut keys = Vec::with_capacity(def.keyframes.len());
            for (i, k) in def.keyframes.iter().enumerate() {
                if let Some(prev) = keys.last().map(|p: &CameraKey| p.frame)
                    && k.frame <= prev
                {
                    return Err(LoadError::invalid(
                        path,
                        format!(
                            "camera: keyframe {i} (frame {}) does not come after frame {prev}",
                            k.frame
                        ),
                    ));
                }
                let key = CameraKey {
                    frame: k.frame,
                    eye: k.eye.map_or(camera.eye, v3),
                    look_at: k.look_at.map_or(camera.look_at, v3),
                    up: k.up.map_or(camera.up, v3),
                    fov_y: k.fov_y.unwrap_or(camera.fov_y),
                };
                let posed = Camera {
                    eye: key.eye,
                    look_at: key.look_at,
                    up: key.up,
                    fov_y: key.fov_y,
                    ..camera.clone()
                };
                if let Err(LoadError::Invalid { message, .. }) = validate_camera(path, &posed) {
                    return Err(LoadError::invalid(path, format!("keyframe {i}: {message}")));
                }
                keys.push(key);
            }
            Ok(Some(CameraPath::Keys(keys)))
        }
    }
}

fn validate_camera(path: &Path, c: &Camera) -> Result<(), LoadError> {
    let f = c.look_at - c.eye;
    if !(c.eye.is_finite() && c.look_at.is_finite() && c.up.is_finite()) {
        return Err(LoadError::invalid(
            path,
            "camera: eye, look_at and up must be finite",
        ));
    }
    if f.length_squared() == 0.0 || f.cross(c.up).length_squared() == 0.0 {
        return Err(LoadError::invalid(
            path,
            "camera: look_at must differ from eye, and up must not be parallel to the view direction",
        ));
    }
    if !(c.fov_y > 0.0 && c.fov_y < 180.0) {
        return Err(LoadError::invalid(
            path,
            format!(
                "camera: fov_y must be between 0 and 180 degrees, found {}",
                c.fov_y
            ),
        ));
    }
    if c.width == 0 || c.height == 0 || c.width > 1 << 15 || c.height > 1 << 15 {
        return Err(LoadError::invalid(
            path,
            format!(
                "camera: width and height must be 1 to 32768, found {}x{}",
                c.width, c.height
            ),
        ));
    }
    Ok(())
}

fn validate_material(path: &Path, m: &Material) -> Result<(), LoadError> {
    let values = [
        m.specular,
        m.shininess,
        m.reflect,
        m.transmit,
        m.ior,
        m.diffuse.x,
        m.diffuse.y,
        m.diffuse.z,
    ];
    if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
        return Err(LoadError::invalid(
            path,
            format!(
                "material \"{}\": values must be finite and non-negative",
                m.name
            ),
        ));
    }
    if m.ior <= 0.0 {
        return Err(LoadError::invalid(
            path,
            format!("material \"{}\": ior must be positive", m.name),
        ));
    }
    Ok(())
}

fn material_from_def(name: &str, d: &MaterialDef) -> Material {
    let base = Material::default_named(name);
    Material {
        name: name.to_string(),
        diffuse: d.diffuse.map(c3).unwrap_or(base.diffuse),
        specular: d.specular.unwrap_or(base.specular),
        shininess: d.shininess.unwrap_or(base.shininess),
        reflect: d.reflect.unwrap_or(base.reflect),
        transmit: d.transmit.unwrap_or(base.transmit),
        ior: d.ior.unwrap_or(base.ior),
        blinn: d.highlight == Some(Highlight::Blinn),
    }
}

fn homogeneous(
    points: &[V3],
    weights: &Option<Vec<f64>>,
) -> Result<Vec<glam::DVec4>, crate::geom::GeomError> {
    match weights {
        None => Ok(points.iter().map(|&p| v3(p).extend(1.0)).collect()),
        Some(w) if w.len() != points.len() => Err(crate::geom::GeomError::PointCount {
            expected: points.len(),
            found: w.len(),
        }),
        Some(w) => Ok(points
            .iter()
            .zip(w)
            .map(|(&p, &w)| (v3(p) * w).extend(w))
            .collect()),
    }
}

fn surface_from_def(d: &SurfaceDef) -> Result<Surface, crate::geom::GeomError> {
    Ok(match d {
        SurfaceDef::Bezier {
            degree,
            points,
            weights,
        } => Surface::bezier(BezierPatch::new(
            degree.0,
            degree.1,
            homogeneous(points, weights)?,
        )?),
        SurfaceDef::Nurbs {
            degree,
            knots_u,
            knots_v,
            count,
            points,
            weights,
        } => Surface {
            geometry: SurfaceGeometry::Nurbs(NurbsSurface::new(
                degree.0,
                degree.1,
                knots_u.clone(),
                knots_v.clone(),
                count.0,
                count.1,
                homogeneous(points, weights)?,
            )?),
            trims: Vec::new(),
            trim_space: Default::default(),
        },
    })
}

fn split_homogeneous(points: &[glam::DVec4]) -> (Vec<V3>, Option<Vec<f64>>) {
    let xyz = points
        .iter()
        .map(|p| {
            let e = p.truncate() / p.w;
            (e.x, e.y, e.z)
        })
        .collect();
    let weights = points
        .iter()
        .any(|p| p.w != 1.0)
        .then(|| points.iter().map(|p| p.w).collect());
    (xyz, weights)
}

/// The serde mirror of a scene with all geometry inline (meshes are not representable
/// inline and are refused).
pub fn scene_to_file(scene: &Scene) -> Result<SceneFile, String> {
    let c = &scene.camera;
    let t = |v: DVec3| (v.x, v.y, v.z);
    let tc = |v: Vec3| (v.x, v.y, v.z);
    let mut objects = Vec::new();
    for o in &scene.objects {
        let limit_patches: Vec<Surface>;
        let surfaces = match &o.geometry {
            Geometry::Surfaces(s) => s,
            // Written as its limit surface's Bézier patches.
            Geometry::Subdivision(s) => {
                limit_patches = s.patches.iter().cloned().map(Surface::bezier).collect();
                &limit_patches
            }
            Geometry::Mesh(_) => {
                return Err(format!(
                    "object \"{}\" is a triangle mesh; RON scenes reference meshes by file",
                    o.name
                ));
            }
        };
        let defs = surfaces
            .iter()
            .map(|s| match &s.geometry {
                SurfaceGeometry::Bezier(p) => {
                    let (points, weights) = split_homogeneous(p.homogeneous_points());
                    SurfaceDef::Bezier {
                        degree: (p.degree_u(), p.degree_v()),
                        points,
                        weights,
                    }
                }
                SurfaceGeometry::Nurbs(n) => {
                    let (points, weights) = split_homogeneous(&n.points);
                    SurfaceDef::Nurbs {
                        degree: (n.degree_u, n.degree_v),
                        knots_u: n.knots_u.clone(),
                        knots_v: n.knots_v.clone(),
                        count: (n.count_u, n.count_v),
                        points,
                        weights,
                    }
                }
            })
            .collect();
        objects.push(ObjectDef {
            name: Some(o.name.clone()),
            geometry: GeometryDef::Surfaces(defs),
            material: Some(scene.materials[o.material].name.clone()),
            up: None,
            transform: Vec::new(),
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
