//! USD scenes (`.usda` text, `.usdc` crate, `.usdz` package) read as our scene. The
//! file's syntax and composition — sublayers, references and payloads to local files,
//! `over`s, variant selections at their defaults, `instanceable` prims and their
//! prototypes — are the `openusd` crate's (a pure-Rust implementation of Pixar's Sdf, Pcp
//! and Usd); this module walks the composed stage and converts what it finds
//! ([`prims`]: one conversion per prim type):
//!
//! - the `Xform` stack (`xformOp:*` in `xformOpOrder`, `!resetXformStack!`,
//!   [`values::local_transform`]) and the stage's `upAxis` (a y-up stage is turned to
//!   our z up); coordinates stay in the stage's units, and `metersPerUnit` (UsdGeom's
//!   fallback 0.01 when unauthored) is the scene's unit ([`stage_unit`]);
//! - an instanceable prim is one shared copy of its prototype's geometry per gprim and
//!   one [`Instance`] per placement (Dammertz §3.3), as is each point of a
//!   `PointInstancer`;
//! - `material:binding` (on the prim or its nearest ancestor) to a `UsdPreviewSurface`,
//!   else `primvars:displayColor`, gives the material;
//! - prims of other types and attributes not read are counted by type for `info` and one
//!   warning line; invisible prims and the `proxy` and `guide` purposes are not rendered
//!   (UsdGeomImageable: a renderer draws `default` and `render`).

pub mod prims;
pub mod values;

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DQuat, DVec3};
use openusd::sdf;
use openusd::usd::{Prim, Stage};

use super::error::{LoadError, ParseError};
use crate::scene::model::{
    Axis, Camera, Geometry, Instance, Light, Material, Object, Scene, SceneUnit,
};
use values::ValueError;

/// What reading a USD stage gives: the scene, and facts for `info`, one line each.
pub struct UsdRead {
    pub scene: Scene,
    pub notes: Vec<String>,
}

/// A gprim as the walk found it: geometry in the walk root's coordinates (placed by
/// `transform`), shared when it is an instance prototype's.
struct Piece {
    name: String,
    material: usize,
    geometry: Arc<Geometry>,
    transform: DAffine3,
}

/// The walk's state over the whole stage.
struct Reader<'a> {
    stage: &'a Stage,
    materials: Vec<Material>,
    material_index: HashMap<String, usize>,
    /// Prototype path → its pieces in prototype coordinates, converted once.
    prototypes: HashMap<String, Arc<Vec<Piece>>>,
    cameras: Vec<(String, Camera)>,
    lights: Vec<Light>,
    /// Prim types not read, and attributes of read prims not read, with counts.
    unread: BTreeMap<String, usize>,
    /// What could not be honoured, one line each.
    notes: Vec<String>,
    gprims: usize,
    instances: usize,
}

fn value_error(path: &Path, e: ValueError) -> LoadError {
    LoadError::invalid(path, e.0)
}

/// Reads the USD stage at `path`; `camera` picks a `Camera` prim by path (default: the
/// first in namespace order; without one, a camera framing the stage).
pub fn read_usd(path: &Path, camera: Option<&str>) -> Result<UsdRead, LoadError> {
    if !path.is_file() {
        return Err(LoadError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        ));
    }
    let stage = Stage::open(&path.to_string_lossy()).map_err(|e| open_error(path, &e))?;
    // A layer that is there but cannot be read is an error; an arc to a missing one (a
    // payload not shipped, say) is a warning, as usdview treats it.
    let mut warnings = Vec::new();
    for e in stage.composition_errors() {
        if matches!(e, openusd::pcp::Error::MalformedLayer { .. }) {
            return Err(LoadError::invalid(path, format!("composition: {e}")));
        }
        warnings.push(format!("composition: {e}"));
    }
    let up = match stage.stage_metadata("upAxis").ok().flatten() {
        Some(sdf::Value::Token(t)) if t.as_str() == "Y" => Axis::Y,
        _ => Axis::Z,
    };
    let meters = match stage.stage_metadata("metersPerUnit").ok().flatten() {
        Some(v) => values::flatten(&v).and_then(|v| v.first().copied()),
        None => None,
    };
    let unit = stage_unit(path, meters)?;
    let root = DAffine3::from_mat3(up.to_z_up());
    let mut reader = Reader {
        stage: &stage,
        materials: vec![Material::default_named("default")],
        material_index: HashMap::new(),
        prototypes: HashMap::new(),
        cameras: Vec::new(),
        lights: Vec::new(),
        unread: BTreeMap::new(),
        notes: Vec::new(),
        gprims: 0,
        instances: 0,
    };
    let mut pieces = Vec::new();
    let top = stage.prim(sdf::Path::abs_root());
    for child in top.children().map_err(|e| stage_error(path, &e))? {
        reader
            .walk(&child, &root, None, &mut pieces)
            .map_err(|e| value_error(path, e))?;
    }
    let objects: Vec<Object> = pieces
        .into_iter()
        .map(|p| Object {
            name: p.name,
            material: p.material,
            geometry: Geometry::Instance(Instance::new(p.geometry, p.transform)),
        })
        .map(|mut o| {
            // A piece placed once is its own geometry, transformed; shared ones stay
            // instances.
            if let Geometry::Instance(i) = &o.geometry
                && Arc::strong_count(&i.geometry) == 1
            {
                o.geometry = i.flattened();
            }
            o
        })
        .collect();
    if objects.is_empty() {
        return Err(LoadError::invalid(
            path,
            format!(
                "the stage has nothing to render (no NurbsPatch or Mesh prims{})",
                unread_list(&reader.unread)
                    .map(|l| format!("; not read: {l}"))
                    .unwrap_or_default()
            ),
        ));
    }
    let chosen = match camera {
        Some(want) => Some(
            reader
                .cameras
                .iter()
                .find(|(p, _)| p == want)
                .map(|(_, c)| c.clone())
                .ok_or_else(|| {
                    let have: Vec<&str> = reader.cameras.iter().map(|(p, _)| p.as_str()).collect();
                    LoadError::invalid(
                        path,
                        format!(
                            "--camera {want}: no Camera prim at that path (the stage has {})",
                            if have.is_empty() {
                                "none".to_string()
                            } else {
                                have.join(", ")
                            }
                        ),
                    )
                })?,
        ),
        None => reader.cameras.first().map(|(_, c)| c.clone()),
    };
    let mut scene = Scene::framing(objects);
    if let Some(c) = chosen {
        scene.camera = c;
        scene.own_camera = true;
    }
    if !reader.lights.is_empty() {
        scene.lights = std::mem::take(&mut reader.lights);
    }
    scene.materials = reader.materials;
    scene.unit = Some(unit);
    let mut notes = vec![format!(
        "USD stage: {} gprims, {} instances of {} prototypes, {} cameras, {} lights, up axis {}",
        reader.gprims,
        reader.instances,
        reader.prototypes.len(),
        reader.cameras.len(),
        scene.lights.len(),
        if up == Axis::Y {
            "y (turned to z)"
        } else {
            "z"
        }
    )];
    if let Some(l) = unread_list(&reader.unread) {
        notes.push(format!("not read: {l}"));
        warnings.push(format!("not read: {l}"));
    }
    notes.extend(reader.notes.iter().cloned());
    warnings.extend(reader.notes);
    scene.warnings = warnings
        .into_iter()
        .map(|w| format!("warning: {}: {w}", path.display()))
        .collect();
    Ok(UsdRead { scene, notes })
}

/// UsdGeom's fallback `metersPerUnit` for a stage that does not author one
/// (UsdGeomLinearUnits::centimeters).
const FALLBACK_METERS_PER_UNIT: f64 = 0.01;

/// The stage's length unit: coordinates stay in stage units (rays, cameras and
/// `trace`'s hit points are the stage's own), and the unit records how long one is, for
/// lengths given in millimetres (`compare --tolerance 0.1mm`) and for `info`.
fn stage_unit(path: &Path, meters: Option<f64>) -> Result<SceneUnit, LoadError> {
    let m = meters.unwrap_or(FALLBACK_METERS_PER_UNIT);
    if !(m.is_finite() && m > 0.0) {
        return Err(LoadError::invalid(
            path,
            format!("metersPerUnit {m}: expected a positive length"),
        ));
    }
    let millimetres = 1000.0 * m;
    let declared = match meters {
        Some(_) => format!("metersPerUnit {m}"),
        None => format!("no metersPerUnit, UsdGeom's fallback {m}"),
    };
    Ok(SceneUnit {
        millimetres,
        words: format!(
            "lengths in stage units of {millimetres} mm (the USD stage declares {declared})"
        ),
    })
}

fn unread_list(unread: &BTreeMap<String, usize>) -> Option<String> {
    (!unread.is_empty()).then(|| {
        unread
            .iter()
            .map(|(t, n)| format!("{t} x{n}"))
            .collect::<Vec<_>>()
            .join(", ")
    })
}

/// An error opening the stage. The stage reader does not say where in a text layer
/// parsing stopped, so a `.usda` root layer is parsed again by openusd's own parser,
/// which does: the error is then at its line and column. Otherwise the message and its
/// causes.
fn open_error(path: &Path, e: &anyhow::Error) -> LoadError {
    let text = format!("{e:#}");
    let is_text = path
        .extension()
        .is_some_and(|x| x.eq_ignore_ascii_case("usda"));
    if is_text && let Ok(src) = std::fs::read_to_string(path) {
        let mut parser = openusd::usda::parser::Parser::new(&src);
        if let Err(why) = parser.parse()
            && let Some(h) = parser.last_error_highlight()
        {
            return ParseError::new(path, h.line, h.column, format!("{why:#}")).into();
        }
    }
    LoadError::invalid(path, text)
}

fn stage_error(path: &Path, e: &anyhow::Error) -> LoadError {
    LoadError::invalid(path, format!("{e:#}"))
}

fn anyhow_value(prim: &Prim, e: anyhow::Error) -> ValueError {
    ValueError(format!("{}: {e:#}", prim.path()))
}

impl Reader<'_> {
    /// Counts the prim's authored attributes that are not in `read` (nor in
    /// [`prims::COMMON_READ`] or an `xformOp:`).
    fn count_unread(&mut self, prim: &Prim, kind: &str, read: &[&str]) -> Result<(), ValueError> {
        for a in prim.attributes().map_err(|e| anyhow_value(prim, e))? {
            let Some((_, name)) = a.path().split_property() else {
                continue;
            };
            if read.contains(&name)
                || prims::COMMON_READ.contains(&name)
                || name.starts_with("xformOp:")
            {
                continue;
            }
            if values::raw((prim, name))?.is_some() {
                *self.unread.entry(format!("{kind}.{name}")).or_default() += 1;
            }
        }
        Ok(())
    }

    /// The material a gprim gets: its bound `UsdPreviewSurface` (`binding`, the nearest
    /// `material:binding` at or above it), else its display colour, else the default.
    fn material_of(&mut self, prim: &Prim, binding: Option<&str>) -> Result<usize, ValueError> {
        if let Some(m) = binding {
            if let Some(&k) = self.material_index.get(m) {
                return Ok(k);
            }
            if let Some(material) = self.preview_surface(m)? {
                self.materials.push(material);
                let k = self.materials.len() - 1;
                self.material_index.insert(m.to_string(), k);
                return Ok(k);
            }
        }
        let Some(c) = prims::display_colour(prim)? else {
            return Ok(0);
        };
        let name = format!("displayColor({:.3},{:.3},{:.3})", c.x, c.y, c.z);
        if let Some(&k) = self.material_index.get(&name) {
            return Ok(k);
        }
        let mut m = Material::default_named(&name);
        m.diffuse = c;
        self.materials.push(m);
        self.material_index.insert(name, self.materials.len() - 1);
        Ok(self.materials.len() - 1)
    }

    /// The `UsdPreviewSurface` shader a `Material` prim's `outputs:surface` connects to,
    /// converted; `None` (with a note) for another kind of shader.
    fn preview_surface(&mut self, material_path: &str) -> Result<Option<Material>, ValueError> {
        let path = sdf::Path::new(material_path).map_err(|e| ValueError(format!("{e}")))?;
        let material = self.stage.prim(path);
        let output = material.attribute("outputs:surface");
        let sources = output
            .connections()
            .map_err(|e| anyhow_value(&material, e))?;
        let Some(source) = sources.first() else {
            self.notes.push(format!(
                "{material_path}: no outputs:surface connection; the default material is used"
            ));
            return Ok(None);
        };
        let shader = self.stage.prim(source.prim_path());
        let id = values::token((&shader, "info:id"))?;
        if id.as_deref() != Some("UsdPreviewSurface") {
            self.notes.push(format!(
                "{material_path}: shader {} is {}, not UsdPreviewSurface; the default material is used",
                shader.path(),
                id.as_deref().unwrap_or("unidentified")
            ));
            return Ok(None);
        }
        self.count_unread(&shader, "Shader", prims::SHADER_READ)?;
        prims::preview_surface(&shader, material_path).map(Some)
    }

    /// Walks `prim` and its descendants, `parent` placing the parent's coordinates in the
    /// walk root's, adding its gprims to `out`.
    fn walk(
        &mut self,
        prim: &Prim,
        parent: &DAffine3,
        binding: Option<&str>,
        out: &mut Vec<Piece>,
    ) -> Result<(), ValueError> {
        let status = |r: anyhow::Result<bool>| r.map_err(|e| anyhow_value(prim, e));
        if !status(prim.is_active())? || !status(prim.is_defined())? || status(prim.is_abstract())?
        {
            return Ok(());
        }
        if values::token((prim, "visibility"))?.as_deref() == Some("invisible")
            || matches!(
                values::token((prim, "purpose"))?.as_deref(),
                Some("proxy" | "guide")
            )
        {
            return Ok(());
        }
        let kind = prim
            .type_name()
            .map_err(|e| anyhow_value(prim, e))?
            .map(|t| t.as_str().to_string())
            .unwrap_or_default();
        let (local, reset) = values::local_transform(prim)?;
        let world = if reset { local } else { *parent * local };
        let bound = prim
            .relationship("material:binding")
            .targets()
            .ok()
            .and_then(|t| t.first().map(|p| p.as_str().to_string()));
        let binding = bound.as_deref().or(binding);
        let name = prim.path().as_str().to_string();

        if status(prim.is_instance())? {
            let Some(prototype) = prim.prototype().map_err(|e| anyhow_value(prim, e))? else {
                return Ok(());
            };
            let pieces = self.prototype(&prototype, binding)?;
            self.instances += 1;
            for p in pieces.iter() {
                out.push(Piece {
                    name: format!("{name}{}", p.name),
                    material: p.material,
                    geometry: p.geometry.clone(),
                    transform: world * p.transform,
                });
            }
            return Ok(());
        }
        match kind.as_str() {
            "NurbsPatch" => {
                self.count_unread(prim, &kind, prims::NURBS_READ)?;
                let (surface, notes) = prims::nurbs_patch(prim)?;
                self.notes.extend(notes);
                self.gprim(prim, binding, Geometry::Surfaces(vec![surface]), world, out)?;
            }
            "Mesh" => {
                self.count_unread(prim, &kind, prims::MESH_READ)?;
                let read = prims::mesh(prim)?;
                self.notes.extend(read.notes);
                if let Some(geometry) = read.geometry {
                    self.gprim(prim, binding, geometry, world, out)?;
                }
            }
            "Camera" => {
                self.count_unread(prim, &kind, prims::CAMERA_READ)?;
                self.cameras.push((name, prims::camera(prim, &world)?));
            }
            "DistantLight" | "SphereLight" => {
                self.count_unread(prim, &kind, prims::LIGHT_READ)?;
                self.lights.push(prims::light(prim, &kind, &world)?);
            }
            "PointInstancer" => {
                self.point_instancer(prim, &world, binding, out)?;
                // Its prototypes are drawn only where it places them.
                return Ok(());
            }
            // Grouping prims, and shading prims read through bindings.
            "" | "Xform" | "Scope" => {}
            "Material" | "Shader" | "NodeGraph" => return Ok(()),
            other => *self.unread.entry(format!("prim {other}")).or_default() += 1,
        }
        for child in prim.children().map_err(|e| anyhow_value(prim, e))? {
            self.walk(&child, &world, binding, out)?;
        }
        Ok(())
    }

    fn gprim(
        &mut self,
        prim: &Prim,
        binding: Option<&str>,
        geometry: Geometry,
        world: DAffine3,
        out: &mut Vec<Piece>,
    ) -> Result<(), ValueError> {
        self.gprims += 1;
        out.push(Piece {
            name: prim.path().as_str().to_string(),
            material: self.material_of(prim, binding)?,
            geometry: Arc::new(geometry),
            transform: world,
        });
        Ok(())
    }

    /// A prototype's pieces in its own coordinates (the instance prim's transform is the
    /// instance's, not the prototype's), converted on first use; names are relative to
    /// the prototype.
    fn prototype(
        &mut self,
        prototype: &sdf::Path,
        binding: Option<&str>,
    ) -> Result<Arc<Vec<Piece>>, ValueError> {
        let key = prototype.as_str().to_string();
        if let Some(p) = self.prototypes.get(&key) {
            return Ok(p.clone());
        }
        let root = self.stage.prim(prototype.clone());
        let mut pieces = Vec::new();
        for child in root.children().map_err(|e| anyhow_value(&root, e))? {
            self.walk(&child, &DAffine3::IDENTITY, binding, &mut pieces)?;
        }
        for p in &mut pieces {
            p.name = p.name.strip_prefix(&key).unwrap_or(&p.name).to_string();
        }
        let pieces = Arc::new(pieces);
        self.prototypes.insert(key, pieces.clone());
        Ok(pieces)
    }

    /// A `PointInstancer` (UsdGeomPointInstancer): prototype `protoIndices[i]` placed at
    /// `positions[i]`, turned by `orientations[i]` and scaled by `scales[i]` (scale first,
    /// then orientation, then position), each prototype's geometry shared. The
    /// single-precision `orientationsf`, when authored, is read instead of the half
    /// `orientations` (it is there for the precision).
    fn point_instancer(
        &mut self,
        prim: &Prim,
        world: &DAffine3,
        binding: Option<&str>,
        out: &mut Vec<Piece>,
    ) -> Result<(), ValueError> {
        self.count_unread(
            prim,
            "PointInstancer",
            &[
                "protoIndices",
                "positions",
                "orientations",
                "orientationsf",
                "scales",
            ],
        )?;
        let targets = prim
            .relationship("prototypes")
            .targets()
            .map_err(|e| anyhow_value(prim, e))?;
        let indices = values::counts((prim, "protoIndices"))?.unwrap_or_default();
        let positions = values::points((prim, "positions"))?.unwrap_or_default();
        let orientations = match values::tuples((prim, "orientationsf"), 4)? {
            Some(q) => q,
            None => values::tuples((prim, "orientations"), 4)?.unwrap_or_default(),
        };
        let scales = values::points((prim, "scales"))?.unwrap_or_default();
        if positions.len() != indices.len() {
            return Err(ValueError(format!(
                "{}: {} positions for {} protoIndices",
                prim.path(),
                positions.len(),
                indices.len()
            )));
        }
        let mut shared: Vec<Option<Vec<Piece>>> = (0..targets.len()).map(|_| None).collect();
        for (i, &k) in indices.iter().enumerate() {
            let target = targets.get(k).ok_or_else(|| {
                ValueError(format!(
                    "{}: protoIndices[{i}] = {k}, but there are {} prototypes",
                    prim.path(),
                    targets.len()
                ))
            })?;
            if shared[k].is_none() {
                let mut pieces = Vec::new();
                let proto = self.stage.prim(target.clone());
                // The prototype prim's own transform is part of it (UsdGeomPointInstancer).
                self.walk(&proto, &DAffine3::IDENTITY, binding, &mut pieces)?;
                shared[k] = Some(pieces);
            }
            let q = orientations
                .get(4 * i..4 * i + 4)
                .map_or(DQuat::IDENTITY, |q| {
                    DQuat::from_xyzw(q[1], q[2], q[3], q[0]).normalize()
                });
            let s = scales.get(i).copied().unwrap_or(DVec3::ONE);
            let placed = *world * DAffine3::from_scale_rotation_translation(s, q, positions[i]);
            self.instances += 1;
            for p in shared[k].iter().flatten() {
                out.push(Piece {
                    name: format!("{}[{i}]{}", prim.path().as_str(), p.name),
                    material: p.material,
                    geometry: p.geometry.clone(),
                    transform: placed * p.transform,
                });
            }
        }
        Ok(())
    }
}
