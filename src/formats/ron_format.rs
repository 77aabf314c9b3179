//! Our RON scene format: the serde mirror of the scene model, and its conversion to and
//! from [`Scene`]. Geometry is referenced by file (relative to the scene) or given inline.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::error::{LoadError, ParseError};
use super::ron_locate::RonLocator;
use super::source_key::SourceKey;
use crate::geom::BezierPatch;
use crate::geom::bezier::ParamRect;
use crate::geom::nurbs::NurbsSurface;
use crate::geom::trim::{AxisMap, ParamCurve, TrimLoop, TrimSegment};
use crate::scene::animation::{CameraKey, CameraPath};
use crate::scene::model::*;
use xxhash_rust::xxh3::xxh3_64;

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
    /// The geometry of the earlier object named `of`, as read (before that object's own
    /// transform), placed by this object's `transform` (Dammertz §3.3). Every object that
    /// instances the same geometry shares one copy of it when rendered.
    Instance { of: String },
}

#[derive(Debug, Serialize, Deserialize)]
pub enum SurfaceDef {
    /// A Bézier patch: degrees (du, dv), `(du+1)(dv+1)` points u fastest, optional weights.
    Bezier {
        degree: (usize, usize),
        points: Vec<V3>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
        /// The rectangle `(u0, u1, v0, v1)` of its surface's parameters the patch covers,
        /// which its trim loops are written in; `[0,1]²` when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        domain: Option<(f64, f64, f64, f64)>,
        /// Trim loops, as for `Nurbs`.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        trims: Vec<TrimLoopDef>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        trim_space: Option<(AxisMapDef, AxisMapDef)>,
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
        /// Trim loops (even–odd over all loops) in the trim parameter space.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        trims: Vec<TrimLoopDef>,
        /// How (u, v) map to the trim parameters; identity when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        trim_space: Option<(AxisMapDef, AxisMapDef)>,
    },
}

/// A trim loop: the outer boundary or a hole.
#[derive(Debug, Serialize, Deserialize)]
pub struct TrimLoopDef {
    pub hole: bool,
    pub segments: Vec<TrimSegmentDef>,
}

/// A B-spline trim curve restricted to `[t0, t1]`: homogeneous points `(w u, w v, w)` and
/// `points + degree + 1` knots.
#[derive(Debug, Serialize, Deserialize)]
pub struct TrimSegmentDef {
    pub t0: f64,
    pub t1: f64,
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<V3>,
}

/// [`AxisMap`] in the file.
#[derive(Debug, Serialize, Deserialize)]
pub enum AxisMapDef {
    Identity,
    Arcs { breaks: Vec<f64>, angles: Vec<f64> },
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
    Ok(read_scene_keyed(path, false, None)?.0)
}

/// The parse of the RON scene at `path` as a BVH file keeps it: the xxh3-64 of the file's
/// bytes and its [`SceneFile`] as JSON, which `serde_json` (with exact float round trips)
/// reads about ten times faster than `ron` reads the text: 10,000 objects in 2.3 MB of RON
/// take 0.1 s to parse. `None` if the file cannot be read or parsed, or holds what JSON
/// cannot (non-finite numbers).
pub fn parsed_scene(path: &Path) -> Option<(u64, Vec<u8>)> {
    let src = super::error::read_text(path).ok()?;
    let file = parse_scene_file(path, &src).ok()?;
    let json = serde_json::to_vec(&file).ok()?;
    // A file JSON cannot give back as it was is not kept.
    let back: SceneFile = serde_json::from_slice(&json).ok()?;
    (format!("{back:?}") == format!("{file:?}")).then(|| (xxh3_64(src.as_bytes()), json))
}

/// [`read_scene`] with its [`SourceKey`](super::source_key) digest. With `defer`, geometry
/// files are hashed but not parsed: the objects they feed get no geometry (the caller has
/// it prepared already, in a BVH file with this key). `parsed` is a [`parsed_scene`] kept
/// from an earlier read: used in place of parsing the text when the text is unchanged.
pub fn read_scene_keyed(
    path: &Path,
    defer: bool,
    parsed: Option<(u64, &[u8])>,
) -> Result<(Scene, u64), LoadError> {
    let src = super::error::read_text(path)?;
    let unchanged = parsed.filter(|(hash, _)| *hash == xxh3_64(src.as_bytes()));
    let file = match unchanged.and_then(|(_, json)| serde_json::from_slice(json).ok()) {
        Some(file) => file,
        None => parse_scene_file(path, &src)?,
    };
    let mut key = SourceKey::new();
    key.text("ron scene");
    let scene = build_scene(path, &RonLocator::new(path, &src), file, (defer, &mut key))?;
    Ok((scene, key.finish()))
}

/// The deepest `max_depth` a scene may ask for. Each level can double the ray tree (a
/// material that both reflects and transmits), and the integrator recurses once per level,
/// so an unbounded value overflowed the stack (`max_depth: 100000`). 64 bounces
/// is far beyond what an 8-bit or half-float pixel can show: with the adaptive cut-off a
/// ray's weight falls below 1/255 long before, unless every surface is a perfect mirror.
pub const MAX_TRACE_DEPTH: u32 = 64;

fn build_scene(
    path: &Path,
    at: &RonLocator,
    file: SceneFile,
    (defer, key): (bool, &mut SourceKey),
) -> Result<Scene, LoadError> {
    if let Some(d) = file.max_depth
        && !(1..=MAX_TRACE_DEPTH).contains(&d)
    {
        return Err(at
            .at_key(
                "max_depth",
                format!("expected max_depth from 1 to {MAX_TRACE_DEPTH}, found {d}"),
            )
            .into());
    }
    let c = &file.camera;
    let camera = Camera {
        eye: v3(c.eye),
        look_at: v3(c.look_at),
        up: v3(c.up),
        fov_y: c.fov_y,
        width: c.width,
        height: c.height,
    };
    validate_camera(&camera).map_err(|m| at.at_key("camera", m))?;
    let animation = camera_path(at, c, &camera)?;
    let max_spp = MAX_SAMPLES;
    if let Some(n) = file.samples
        && !(1..=max_spp).contains(&n)
    {
        return Err(at
            .at_key(
                "samples",
                format!("samples: expected a count from 1 to {max_spp}, found {n}"),
            )
            .into());
    }
    let mut materials: Vec<Material> = file
        .materials
        .iter()
        .map(|(name, m)| material_from_def(name, m))
        .collect();
    for m in &materials {
        validate_material(m).map_err(|e| at.at_key(&m.name, e))?;
    }
    let base = path.parent().unwrap_or(Path::new("."));
    // Names that instances refer to: those objects keep their geometry shared and unplaced.
    let referenced_names: std::collections::HashSet<&str> = file
        .objects
        .iter()
        .filter_map(|o| match &o.geometry {
            GeometryDef::Instance { of } => Some(of.as_str()),
            _ => None,
        })
        .collect();
    let mut objects: Vec<Object> = Vec::with_capacity(file.objects.len());
    // Each geometry file is read once per load however many objects name it (a scene of
    // 10,000 copies of one teapot read and parsed it 10,000 times).
    let mut files: std::collections::HashMap<std::path::PathBuf, Geometry> =
        std::collections::HashMap::new();
    let mut warnings = Vec::new();
    for (index, o) in file.objects.iter().enumerate() {
        let material = match &o.material {
            Some(name) => materials.iter().position(|m| &m.name == name).ok_or_else(|| {
                at.at_object(index, format!("object {index} uses material \"{name}\", which is not defined in `materials`"))
            })?,
            None => {
                if !materials.iter().any(|m| m.name == "default") {
                    materials.push(Material::default_named("default"));
                }
                materials.iter().position(|m| m.name == "default").unwrap_or(0)
            }
        };
        let mut geometry = match &o.geometry {
            GeometryDef::Instance { of } => {
                let Some(Geometry::Instance(shared)) = objects
                    .iter()
                    .find(|earlier| &earlier.name == of)
                    .map(|earlier| &earlier.geometry)
                else {
                    return Err(at
                        .at_object(
                            index,
                            format!("object {index}: expected Instance(of: NAME) with the name of an earlier object, found \"{of}\""),
                        )
                        .into());
                };
                key.text("instance");
                key.text(of);
                Geometry::Instance(Instance::new(shared.geometry.clone(), DAffine3::IDENTITY))
            }
            GeometryDef::File(f) if defer => {
                key.text("file");
                key.file(&base.join(file_name(at, index, f)?))
                    .map_err(|e| referenced(at, index, f, e))?;
                Geometry::Surfaces(Vec::new())
            }
            GeometryDef::File(f) => {
                let path = base.join(file_name(at, index, f)?);
                key.text("file");
                key.file(&path).map_err(|e| referenced(at, index, f, e))?;
                match files.get(&path) {
                    Some(g) => g.clone(),
                    None => {
                        let (g, noted) = super::load::load_geometry_noted(&path)
                            .map_err(|e| referenced(at, index, f, e))?;
                        warnings.extend(noted);
                        files.insert(path, g.clone());
                        g
                    }
                }
            }
            GeometryDef::Subdivision(inner) => match inner.as_ref() {
                GeometryDef::File(f) => {
                    let path = base.join(file_name(at, index, f)?);
                    key.text("subdivision");
                    key.file(&path).map_err(|e| referenced(at, index, f, e))?;
                    if defer {
                        Geometry::Surfaces(Vec::new())
                    } else {
                        super::load::load_subdivision(&path)
                            .map_err(|e| referenced(at, index, f, e))?
                    }
                }
                _ => {
                    return Err(at
                        .at_object(
                            index,
                            format!(
                                "object {index}: expected Subdivision(File(\"cage.obj\")): a cage is read from a mesh file"
                            ),
                        )
                        .into());
                }
            },
            GeometryDef::Surfaces(defs) => {
                // Inline surfaces are part of the scene text: their definitions are the key.
                key.text("surfaces");
                key.text(&format!("{defs:?}"));
                Geometry::Surfaces(
                    defs.iter()
                        .enumerate()
                        .map(|(k, d)| {
                            surface_from_def(d).map_err(|e| {
                                at.at_surface(index, k, format!("object {index}, surface {k}: {e}"))
                            })
                        })
                        .collect::<Result<_, _>>()?,
                )
            }
        };
        let stand = DAffine3::from_mat3(o.up.unwrap_or(Axis::Z).to_z_up());
        let m = o.transform.iter().fold(stand, |acc, t| t.to_affine() * acc);
        let name = o.name.clone().unwrap_or_else(|| match &o.geometry {
            GeometryDef::Instance { of } => of.clone(),
            GeometryDef::File(f) => f.clone(),
            GeometryDef::Subdivision(inner) => match inner.as_ref() {
                GeometryDef::File(f) => f.clone(),
                _ => format!("object{index}"),
            },
            GeometryDef::Surfaces(_) => format!("object{index}"),
        });
        // Geometry an instance refers to is kept unplaced and shared, this object being
        // its first instance; any other is placed in world space now.
        let shared = referenced_names.contains(name.as_str());
        if shared && !matches!(geometry, Geometry::Instance(_)) {
            geometry = Geometry::Instance(Instance::new(Arc::new(geometry), DAffine3::IDENTITY));
        }
        key.number(u64::from(shared));
        key.transform(&m);
        if m != DAffine3::IDENTITY {
            geometry.transform(&m);
        }
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
        unread_bounds: None,
        warnings,
        unit: None,
    })
}

/// The file name of a `File(...)`, refused when empty (joined to the scene's directory it
/// would name the directory itself).
fn file_name<'a>(at: &RonLocator, index: usize, f: &'a str) -> Result<&'a str, LoadError> {
    if f.trim().is_empty() {
        return Err(at
            .at_object(
                index,
                format!("object {index}: expected a geometry file name in File(\"...\"), found an empty string"),
            )
            .into());
    }
    Ok(f)
}

/// The camera's animation, checked: an orbit has at least one frame and a finite angle;
/// keyframes are in increasing frame order and each is a valid camera.
fn camera_path(
    at: &RonLocator,
    def: &CameraDef,
    camera: &Camera,
) -> Result<Option<CameraPath>, ParseError> {
    match (&def.orbit, def.keyframes.is_empty()) {
        (Some(_), false) => {
            Err(at.at_key("orbit", "camera: give either orbit or keyframes, not both"))
        }
        (Some(o), true) => {
            if o.frames == 0 || !o.degrees.is_finite() {
                return Err(at.at_key(
                    "orbit",
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
                    return Err(at.at_key(
                        "keyframes",
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
                if let Err(message) = validate_camera(&posed) {
                    return Err(at.at_key("keyframes", format!("keyframe {i}: {message}")));
                }
                keys.push(key);
            }
            Ok(Some(CameraPath::Keys(keys)))
        }
    }
}

/// An error loading the geometry file `file` of object `index`: the file's own parse
/// errors already say where they are; anything else (a missing file, content the reader
/// refuses without a place) is reported at the object that refers to the file.
fn referenced(at: &RonLocator, index: usize, file: &str, e: LoadError) -> LoadError {
    match e {
        LoadError::Parse(p) => LoadError::Parse(p),
        other => at
            .at_object(
                index,
                format!("object {index} refers to geometry file \"{file}\": {other}"),
            )
            .into(),
    }
}

fn validate_camera(c: &Camera) -> Result<(), String> {
    let f = c.look_at - c.eye;
    if !(c.eye.is_finite() && c.look_at.is_finite() && c.up.is_finite()) {
        return Err("camera: eye, look_at and up must be finite".into());
    }
    if f.length_squared() == 0.0 || f.cross(c.up).length_squared() == 0.0 {
        return Err("camera: look_at must differ from eye, and up must not be parallel to the view direction".into());
    }
    if !(c.fov_y > 0.0 && c.fov_y < 180.0) {
        return Err(format!(
            "camera: fov_y must be between 0 and 180 degrees, found {}",
            c.fov_y
        ));
    }
    c.check_size().map_err(|e| format!("camera: {e}"))
}

fn validate_material(m: &Material) -> Result<(), String> {
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
        return Err(format!(
            "material \"{}\": values must be finite and non-negative",
            m.name
        ));
    }
    if m.ior <= 0.0 {
        return Err(format!("material \"{}\": ior must be positive", m.name));
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
            domain,
            trims,
            trim_space,
        } => {
            let patch = BezierPatch::new(degree.0, degree.1, homogeneous(points, weights)?)?;
            let patch = match domain {
                &Some((u0, u1, v0, v1)) => patch.with_domain(ParamRect { u0, u1, v0, v1 }),
                None => patch,
            };
            Surface {
                geometry: SurfaceGeometry::Bezier(patch),
                trims: trims_from_defs(trims)?,
                trim_space: trim_space_from_def(trim_space)?,
            }
        }
        SurfaceDef::Nurbs {
            degree,
            knots_u,
            knots_v,
            count,
            points,
            weights,
            trims,
            trim_space,
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
            trims: trims_from_defs(trims)?,
            trim_space: trim_space_from_def(trim_space)?,
        },
    })
}

fn trims_from_defs(defs: &[TrimLoopDef]) -> Result<Vec<TrimLoop>, crate::geom::GeomError> {
    defs.iter()
        .enumerate()
        .map(|(i, l)| trim_loop_from_def(i, l))
        .collect()
}

fn trim_space_from_def(
    d: &Option<(AxisMapDef, AxisMapDef)>,
) -> Result<[AxisMap; 2], crate::geom::GeomError> {
    Ok(match d {
        None => Default::default(),
        Some((u, v)) => [axis_map_from_def(u)?, axis_map_from_def(v)?],
    })
}

/// A trim loop, validated as the kernels expect: degrees 1..=15, valid knot vectors, finite
/// points with positive weights, finite non-empty ranges.
fn trim_loop_from_def(i: usize, l: &TrimLoopDef) -> Result<TrimLoop, crate::geom::GeomError> {
    let bad = |j: usize, what: String| {
        crate::geom::GeomError::Knots(format!("trim loop {i}, segment {j}: {what}"))
    };
    let segments = l
        .segments
        .iter()
        .enumerate()
        .map(|(j, s)| {
            if !(1..=crate::geom::MAX_DEGREE).contains(&s.degree) {
                return Err(bad(j, format!("degree {} is outside 1..=15", s.degree)));
            }
            crate::geom::nurbs::knots::validate(s.degree, &s.knots, s.points.len())
                .map_err(|e| bad(j, e.to_string()))?;
            if s.points
                .iter()
                .any(|p| !(p.0.is_finite() && p.1.is_finite() && p.2 > 0.0 && p.2.is_finite()))
            {
                return Err(bad(j, "points must be finite with positive weights".into()));
            }
            if !(s.t0.is_finite() && s.t1.is_finite() && s.t0 < s.t1) {
                return Err(bad(
                    j,
                    format!("the range [{}, {}] is empty or not finite", s.t0, s.t1),
                ));
            }
            Ok(TrimSegment {
                t0: s.t0,
                t1: s.t1,
                curve: ParamCurve {
                    degree: s.degree,
                    knots: s.knots.clone(),
                    points: s.points.iter().map(|&p| v3(p)).collect(),
                },
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(TrimLoop {
        hole: l.hole,
        segments,
    })
}

fn axis_map_from_def(d: &AxisMapDef) -> Result<AxisMap, crate::geom::GeomError> {
    Ok(match d {
        AxisMapDef::Identity => AxisMap::Identity,
        AxisMapDef::Arcs { breaks, angles } => {
            let increasing =
                |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
            if breaks.len() != angles.len()
                || breaks.len() < 2
                || !increasing(breaks)
                || !increasing(angles)
            {
                return Err(crate::geom::GeomError::Knots(
                    "trim_space: Arcs needs as many breaks as angles (at least 2), both increasing"
                        .into(),
                ));
            }
            AxisMap::Arcs {
                breaks: breaks.clone(),
                angles: angles.clone(),
            }
        }
    })
}

fn axis_map_def(m: &AxisMap) -> AxisMapDef {
    match m {
        AxisMap::Identity => AxisMapDef::Identity,
        AxisMap::Arcs { breaks, angles } => AxisMapDef::Arcs {
            breaks: breaks.clone(),
            angles: angles.clone(),
        },
    }
}

/// The RON form of a surface's trim loops.
fn trim_defs(s: &Surface) -> Vec<TrimLoopDef> {
    s.trims
        .iter()
        .map(|l| TrimLoopDef {
            hole: l.hole,
            segments: l
                .segments
                .iter()
                .map(|g| TrimSegmentDef {
                    t0: g.t0,
                    t1: g.t1,
                    degree: g.curve.degree,
                    knots: g.curve.knots.clone(),
                    points: g.curve.points.iter().map(|p| (p.x, p.y, p.z)).collect(),
                })
                .collect(),
        })
        .collect()
}

/// The RON form of a surface's trim space, `None` for the identity.
fn trim_space_def(s: &Surface) -> Option<(AxisMapDef, AxisMapDef)> {
    (s.trim_space != <[AxisMap; 2]>::default()).then(|| {
        (
            axis_map_def(&s.trim_space[0]),
            axis_map_def(&s.trim_space[1]),
        )
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
        // An instance is written as its placed copy.
        let geometry = o.geometry.resolved();
        let surfaces = match geometry.as_ref() {
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
        let defs = surfaces
            .iter()
            .map(|s| match &s.geometry {
                SurfaceGeometry::Bezier(p) => {
                    let (points, weights) = split_homogeneous(p.homogeneous_points());
                    let d = p.domain();
                    SurfaceDef::Bezier {
                        degree: (p.degree_u(), p.degree_v()),
                        points,
                        weights,
                        domain: (d != ParamRect::UNIT).then_some((d.u0, d.u1, d.v0, d.v1)),
                        trims: trim_defs(s),
                        trim_space: trim_space_def(s),
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
                        trims: trim_defs(s),
                        trim_space: trim_space_def(s),
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
