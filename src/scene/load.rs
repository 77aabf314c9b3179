//! Choosing a reader by file type, and turning bare geometry into a scene.

use std::path::Path;

use super::error::LoadError;
use super::model::{Axis, Geometry, Object, Scene, Surface};
use super::{bpt, cage, mesh, obj, pbrt, ron_format};

/// The kinds of input file we read, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    Ron,
    Bpt,
    Obj,
    Pbrt,
    Gltf,
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
            _ => return None,
        })
    }
}

fn unknown_kind(path: &Path) -> LoadError {
    LoadError::invalid(
        path,
        "unknown file type: expected .ron (scene), .bpt, .obj, .pbrt, .gltf or .glb",
    )
}

/// Reads a geometry file: free-form surfaces or a triangle mesh.
pub fn load_geometry(path: &Path) -> Result<Geometry, LoadError> {
    match InputKind::of(path).ok_or_else(|| unknown_kind(path))? {
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
        InputKind::Gltf => Ok(Geometry::Mesh(mesh::read_gltf(path)?)),
        InputKind::Ron => Err(LoadError::invalid(
            path,
            "a scene cannot be used as geometry; reference its geometry files instead",
        )),
    }
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

/// `--up`: frames bare geometry read from `path` with `up` pointing up instead of its
/// format's default. A RON scene has its own camera, so it is refused there.
pub fn reframe(path: &Path, scene: &mut Scene, up: Option<Axis>) -> Result<(), LoadError> {
    let Some(up) = up else { return Ok(()) };
    if InputKind::of(path) == Some(InputKind::Ron) {
        return Err(LoadError::invalid(
            path,
            "--up frames bare geometry; in a scene, set the camera, or give an object `up: Y`",
        ));
    }
    scene.frame_bare(up);
    Ok(())
}

/// Reads a polygon mesh file (OBJ polygons, glTF triangles) as a Catmull–Clark cage.
pub fn load_subdivision(path: &Path) -> Result<Geometry, LoadError> {
    let refuse = |what: &str| {
        LoadError::invalid(
            path,
            format!(
                "{what} is not a polygon mesh, so it cannot be a Catmull–Clark cage; expected an OBJ file of `f` faces, or glTF"
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
            &mesh::read_gltf(path)?,
        )?)),
        InputKind::Bpt => Err(refuse("a .bpt file of Bézier patches")),
        InputKind::Pbrt => Err(refuse("a pbrt file")),
        InputKind::Ron => Err(refuse("a RON scene")),
    }
}

/// How bare geometry files are read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Read a bare mesh file as a Catmull–Clark cage (`--subdivide catmull-clark`).
    pub subdivide: bool,
}

/// Reads a scene: a RON scene file, or bare geometry framed by a default camera and light.
/// Scenes whose coordinates do not fit `f32` after transforms are refused.
pub fn load_scene(path: &Path) -> Result<Scene, LoadError> {
    load_scene_with(path, LoadOptions::default())
}

/// [`load_scene`] with options for bare geometry.
pub fn load_scene_with(path: &Path, options: LoadOptions) -> Result<Scene, LoadError> {
    let scene = if options.subdivide {
        if InputKind::of(path) == Some(InputKind::Ron) {
            return Err(LoadError::invalid(
                path,
                "--subdivide applies to bare mesh files; in a RON scene write `geometry: Subdivision(File(\"cage.obj\"))`",
            ));
        }
        bare_scene(path, load_subdivision(path)?)
    } else {
        read_any_scene(path)?
    };
    check_f32_range(path, &scene)?;
    Ok(scene)
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
        let b = o.bounds();
        if b.is_empty() {
            continue;
        }
        let extent = b.extent().max_element();
        if extent > 0.0 && extent < MIN_OBJECT_EXTENT {
            return Err(LoadError::invalid(
                path,
                format!(
                    "object \"{}\" is only {extent:e} across, below the {MIN_OBJECT_EXTENT:e} that f32 shading resolves (distances would square into the subnormal range); scale the scene up",
                    o.name
                ),
            ));
        }
        let largest = b.min.abs().max(b.max.abs()).max_element();
        if !((largest as f32).is_finite()) {
            return Err(LoadError::invalid(
                path,
                format!(
                    "object \"{}\": coordinates reach {largest:e} after transforms, beyond the f32 range (±{:e}) the renderer works in",
                    o.name,
                    f32::MAX
                ),
            ));
        }
    }
    Ok(())
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
