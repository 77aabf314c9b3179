//! Choosing a reader by file type, and turning bare geometry into a scene.

use std::path::Path;

use super::cad::{iges, scene, step};
use super::error::LoadError;
use super::{bpt, cage, gltf_mesh, mesh, obj, pbrt, ron_format};
use crate::geom::bbox::DAabb;
use crate::scene::model::{Axis, Geometry, Object, Scene, Surface};

/// The kinds of input file we read, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    Ron,
    Bpt,
    Obj,
    Pbrt,
    Gltf,
    Stl,
    Iges,
    Step,
    Usd,
}

impl InputKind {
    pub fn of(path: &Path) -> Option<InputKind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "ron" => InputKind::Ron,
            "bpt" => InputKind::Bpt,
            "obj" => InputKind::Obj,
            "pbrt" => InputKind::Pbrt,
            "gltf" | "glb" => InputKind::Gltf,
            "stl" => InputKind::Stl,
            "igs" | "iges" => InputKind::Iges,
            "step" | "stp" => InputKind::Step,
            "usda" | "usdc" | "usdz" | "usd" => InputKind::Usd,
            _ => return None,
        })
    }
}

fn unknown_kind(path: &Path) -> LoadError {
    LoadError::invalid(
        path,
        "unknown file type: expected .ron (scene), .usda, .usdc, .usdz, .usd, .bpt, .obj, .pbrt, .gltf, .glb, .stl, .igs, .iges, .step or .stp",
    )
}

/// Reads a geometry file: free-form surfaces or a triangle mesh
/// ([`load_geometry_noted`] also gives the warnings).
pub fn load_geometry(path: &Path) -> Result<Geometry, LoadError> {
    Ok(load_geometry_noted(path)?.0)
}

/// [`load_geometry`] and the warning lines reading the file gave, for the command line to
/// print.
pub fn load_geometry_noted(path: &Path) -> Result<(Geometry, Vec<String>), LoadError> {
    let geometry = match InputKind::of(path).ok_or_else(|| unknown_kind(path))? {
        InputKind::Bpt => Ok(Geometry::Surfaces(
            bpt::read_bpt(path)?
                .into_iter()
                .map(Surface::bezier)
                .collect(),
        )),
        InputKind::Obj => {
            let src = super::error::read_text(path)?;
            if obj::is_freeform(&src) {
                Ok(Geometry::Surfaces(obj::parse_obj_freeform(path, &src)?))
            } else {
                Ok(Geometry::Mesh(mesh::read_obj_mesh(path)?))
            }
        }
        InputKind::Pbrt => {
            let src = super::error::read_text(path)?;
            Ok(Geometry::Surfaces(pbrt::parse_pbrt(path, &src)?))
        }
        InputKind::Gltf => Ok(Geometry::Mesh(gltf_mesh::read_gltf(path)?)),
        InputKind::Stl => Ok(Geometry::Mesh(super::stl::read_stl(path)?)),
        InputKind::Iges => return scene::build_geometry(path, iges::read_cad(path)?),
        InputKind::Step => return scene::build_geometry(path, step::read_step(path)?),
        InputKind::Ron | InputKind::Usd => Err(LoadError::invalid(
            path,
            "a scene cannot be used as geometry; reference its geometry files instead",
        )),
    }?;
    Ok((geometry, Vec::new()))
}

/// The up axis a format's convention gives bare geometry: y for glTF (glTF 2.0 §3.4, "glTF
/// uses a right-handed coordinate system ... +Y is up"), z for everything else (CAD
/// formats, and ours).
pub fn default_up(kind: InputKind) -> Axis {
    match kind {
        InputKind::Gltf => Axis::Y,
        _ => Axis::Z,
    }
}

/// Frames bare geometry read from `path` again after `--width`/`--height` (the fit depends
/// on the aspect ratio) with `up` pointing up, or its format's default. A RON scene has its
/// own camera: it is left alone, and `--up` is refused there.
pub fn reframe(path: &Path, scene: &mut Scene, up: Option<Axis>) -> Result<(), LoadError> {
    let kind = InputKind::of(path).ok_or_else(|| unknown_kind(path))?;
    if kind == InputKind::Ron || scene.own_camera {
        return match up {
            Some(_) => Err(LoadError::invalid(
                path,
                "--up frames bare geometry; in a scene, set the camera, or give an object `up: Y` (a USD stage's camera and upAxis stand)",
            )),
            None => Ok(()),
        };
    }
    scene.frame_bare(up.unwrap_or(default_up(kind)));
    Ok(())
}

/// Reads a polygon mesh file (OBJ polygons, glTF triangles) as a Catmull–Clark cage.
pub fn load_subdivision(path: &Path) -> Result<Geometry, LoadError> {
    let refuse = |what: &str| {
        LoadError::invalid(
            path,
            format!(
                "{what} is not a polygon mesh, so it cannot be a Catmull–Clark cage; expected an OBJ file of `f` faces, glTF or STL"
            ),
        )
    };
    match InputKind::of(path).ok_or_else(|| unknown_kind(path))? {
        InputKind::Obj => {
            let src = super::error::read_text(path)?;
            if obj::is_freeform(&src) {
                return Err(refuse("an OBJ file of free-form surfaces"));
            }
            Ok(Geometry::Subdivision(cage::read_obj_cage(path)?))
        }
        InputKind::Gltf => Ok(Geometry::Subdivision(cage::mesh_cage(
            path,
            &gltf_mesh::read_gltf(path)?,
        )?)),
        InputKind::Stl => Ok(Geometry::Subdivision(cage::mesh_cage(
            path,
            &super::stl::read_stl(path)?,
        )?)),
        InputKind::Bpt => Err(refuse("a .bpt file of Bézier patches")),
        InputKind::Pbrt => Err(refuse("a pbrt file")),
        InputKind::Ron => Err(refuse("a RON scene")),
        InputKind::Usd => Err(refuse(
            "a USD stage (its meshes are Catmull–Clark cages already)",
        )),
        InputKind::Iges => Err(refuse("an IGES file")),
        InputKind::Step => Err(refuse("a STEP file")),
    }
}

/// How bare geometry files and USD stages are read.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Read a bare mesh file as a Catmull–Clark cage (`--subdivide catmull-clark`).
    pub subdivide: bool,
    /// The path of the USD `Camera` prim to look through (`--camera`).
    pub camera: Option<String>,
}

/// Reads a scene: a RON scene file, or bare geometry framed by a default camera and light.
/// Scenes whose coordinates do not fit `f32` after transforms are refused.
pub fn load_scene(path: &Path) -> Result<Scene, LoadError> {
    load_scene_with(path, LoadOptions::default())
}

/// [`load_scene`] with options for bare geometry.
pub fn load_scene_with(path: &Path, options: LoadOptions) -> Result<Scene, LoadError> {
    Ok(load_scene_noted(path, options)?.0)
}

/// [`load_scene_with`] and the scene's [`SourceKey`](super::source_key::SourceKey) digest,
/// the key its BVH file is checked against. With `defer`, a RON scene's geometry files are
/// hashed but not parsed, and the objects they feed get no geometry: for a caller that
/// finds it prepared in a BVH file with this key. Bare geometry is keyed by its bytes and
/// `options`, and read unless `defer` and `parsed` holds the shell of its scene for the
/// same key ([`BareShell`](crate::scene::bare_shell::BareShell)): its default camera frames the
/// geometry, so only a kept shell stands in for it. `parsed` is what a BVH file keeps: a RON scene's
/// [`ron_format::parsed_scene`] or a bare file's shell.
pub fn load_scene_keyed(
    path: &Path,
    options: LoadOptions,
    defer: bool,
    parsed: Option<(u64, &[u8])>,
) -> Result<(Scene, u64), LoadError> {
    if InputKind::of(path) == Some(InputKind::Ron) && !options.subdivide {
        let (scene, key) = ron_format::read_scene_keyed(path, defer, parsed)?;
        check_f32_range(path, &scene)?;
        check_trims(path, &scene)?;
        return Ok((scene, key));
    }
    let mut key = super::source_key::SourceKey::new();
    key.text("bare geometry");
    key.number(u64::from(options.subdivide));
    key.text(options.camera.as_deref().unwrap_or(""));
    key.file(path)?;
    // With `defer`, the shell the BVH file keeps for these very inputs (its hash is their
    // key) stands in for the file's scene; its geometry comes from the BVH file.
    let key = key.finish();
    let kept = parsed
        .filter(|(hash, _)| defer && *hash == key)
        .and_then(|(_, json)| crate::scene::bare_shell::BareShell::scene_of(json));
    let scene = match kept {
        Some(scene) => scene,
        None => load_scene_with(path, options.clone())?,
    };
    Ok((scene, key))
}

/// [`load_scene_with`], with what the reader noted about the file beyond the scene (a
/// CAD file's units, unsupported entities, faces left out), one line each, for `info`.
pub fn load_scene_noted(
    path: &Path,
    options: LoadOptions,
) -> Result<(Scene, Vec<String>), LoadError> {
    let (scene, notes) = if options.subdivide {
        if InputKind::of(path) == Some(InputKind::Ron) {
            return Err(LoadError::invalid(
                path,
                "--subdivide applies to bare mesh files; in a RON scene write `geometry: Subdivision(File(\"cage.obj\"))`",
            ));
        }
        (bare_scene(path, load_subdivision(path)?), Vec::new())
    } else if InputKind::of(path) == Some(InputKind::Usd) {
        let read = super::usd::read_usd(path, options.camera.as_deref())?;
        (read.scene, read.notes)
    } else if let Some(model) = read_cad(path)? {
        let read = scene::build_scene(path, model)?;
        (read.scene, read.notes)
    } else {
        (read_any_scene(path)?, Vec::new())
    };
    check_f32_range(path, &scene)?;
    check_trims(path, &scene)?;
    Ok((scene, notes))
}

/// Every trim loop converts to Bézier pieces (degrees, knots, weights, ranges), checked
/// once at load so that the renderer never meets loops it cannot apply; the error names
/// the object and surface.
pub fn check_trims(path: &Path, scene: &Scene) -> Result<(), LoadError> {
    for o in &scene.objects {
        for (k, s) in o.geometry.surfaces().iter().enumerate() {
            if let Err(e) = s.trim_region() {
                return Err(LoadError::invalid(
                    path,
                    format!("object \"{}\", surface {k}: trim loops: {e}", o.name),
                ));
            }
        }
    }
    Ok(())
}

/// Smallest object extent the renderer accepts: 2^-60 ≈ 8.7e-19. Shading squares
/// distances of about this size in `f32`; below 2^-63 the squares fall under
/// `f32::MIN_POSITIVE` (2^-126) into the subnormal range and normalising gives NaN.
pub const MIN_OBJECT_EXTENT: f64 = 1.0 / (1u64 << 60) as f64;

/// The renderer rounds geometry to `f32` once; a coordinate beyond its range would become
/// infinite there, and an object smaller than [`MIN_OBJECT_EXTENT`] would shade in the
/// subnormal range, so both are refused with the object's name. `path` names the scene in
/// the error.
pub fn check_f32_range(path: &Path, scene: &Scene) -> Result<(), LoadError> {
    for o in &scene.objects {
        check_box_range(path, &o.name, "", &o.bounds())?;
        // An instance's shared geometry is prepared in `f32` in its own coordinates, before
        // its transform: a file at 1e39 scaled by 1e-10 is placed in range but would
        // round to infinity there.
        if let Geometry::Instance(i) = &o.geometry {
            check_box_range(path, &o.name, " before its transform", &i.geometry.bounds())?;
        }
    }
    let c = &scene.camera;
    if !(c.eye.as_vec3().is_finite() && c.look_at.as_vec3().is_finite()) {
        return Err(LoadError::invalid(
            path,
            format!(
                "camera: eye {} or look_at {} is beyond the f32 range (±{:e}) the renderer works in",
                c.eye,
                c.look_at,
                f32::MAX
            ),
        ));
    }
    Ok(())
}

/// [`check_f32_range`] for one box of object `name`; `when` says which coordinates the box
/// is in (empty for the placed object).
fn check_box_range(path: &Path, name: &str, when: &str, b: &DAabb) -> Result<(), LoadError> {
    if b.is_empty() {
        return Ok(());
    }
    let extent = b.extent().max_element();
    if extent > 0.0 && extent < MIN_OBJECT_EXTENT {
        return Err(LoadError::invalid(
            path,
            format!(
                "object \"{name}\" is only {extent:e} across{when}, below the {MIN_OBJECT_EXTENT:e} that f32 shading resolves (distances would square into the subnormal range); scale the scene up"
            ),
        ));
    }
    let largest = b.min.abs().max(b.max.abs()).max_element();
    // Box arithmetic (slab tests, extents, the default camera's distance) works on
    // differences of coordinates, so the extent must fit as well: a patch at ±3e38
    // has finite corners but an infinite f32 width.
    if !((largest as f32).is_finite()) || !((extent as f32).is_finite()) {
        return Err(LoadError::invalid(
            path,
            format!(
                "object \"{name}\": coordinates reach {largest:e} and the box spans {extent:e}{}, beyond the f32 range (±{:e}) the renderer works in; scale the scene down",
                if when.is_empty() {
                    " after transforms"
                } else {
                    when
                },
                f32::MAX
            ),
        ));
    }
    Ok(())
}

/// The front door's model of a CAD file (STEP, IGES); `None` for other kinds.
fn read_cad(path: &Path) -> Result<Option<scene::CadModel>, LoadError> {
    Ok(match InputKind::of(path) {
        Some(InputKind::Step) => Some(step::read_step(path)?),
        Some(InputKind::Iges) => Some(iges::read_cad(path)?),
        _ => None,
    })
}

fn read_any_scene(path: &Path) -> Result<Scene, LoadError> {
    match InputKind::of(path).ok_or_else(|| unknown_kind(path))? {
        InputKind::Ron => ron_format::read_scene(path),
        _ => Ok(bare_scene(path, load_geometry(path)?)),
    }
}

fn bare_scene(path: &Path, geometry: Geometry) -> Scene {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let kind = InputKind::of(path).unwrap_or(InputKind::Bpt);
    Scene::framing_up(
        vec![Object {
            name,
            material: 0,
            geometry,
        }],
        default_up(kind),
    )
}
