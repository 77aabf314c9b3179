//! Reading a RON scene: parsing the text (or a kept parse of it), checking what it asks
//! for, and building the [`Scene`] with the geometry files it references.

use std::path::Path;
use std::sync::Arc;

use glam::DAffine3;
use xxhash_rust::xxh3::xxh3_64;

use super::schema::*;
use super::surfaces::surface_from_def;
use crate::formats::error::{LoadError, ParseError};
use crate::formats::ron_locate::RonLocator;
use crate::formats::source_key::SourceKey;
use crate::scene::animation::{CameraKey, CameraPath};
use crate::scene::model::*;

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
    let src = crate::formats::error::read_text(path).ok()?;
    let file = parse_scene_file(path, &src).ok()?;
    let json = serde_json::to_vec(&file).ok()?;
    // A file JSON cannot give back as it was is not kept.
    let back: SceneFile = serde_json::from_slice(&json).ok()?;
    (format!("{back:?}") == format!("{file:?}")).then(|| (xxh3_64(src.as_bytes()), json))
}

/// [`read_scene`] with its [`SourceKey`](crate::formats::source_key) digest. With `defer`, geometry
/// files are hashed but not parsed: the objects they feed get no geometry (the caller has
/// it prepared already, in a BVH file with this key). `parsed` is a [`parsed_scene`] kept
/// from an earlier read: used in place of parsing the text when the text is unchanged.
pub fn read_scene_keyed(
    path: &Path,
    defer: bool,
    parsed: Option<(u64, &[u8])>,
) -> Result<(Scene, u64), LoadError> {
    let src = crate::formats::error::read_text(path)?;
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
                        let (g, noted) = crate::formats::load::load_geometry_noted(&path)
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
                        crate::formats::load::load_subdivision(&path)
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
        own_camera: true,
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
