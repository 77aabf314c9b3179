//! The CAD front door: every CAD reader (STEP, IGES) hands over what it read as a
//! [`CadModel`] — parts, their placed occurrences, colours, the declared length unit, what
//! was left out and why — and this module alone turns it into a [`Scene`]:
//!
//! - one millimetre convention: the declared unit's size is applied to every placement;
//! - colours become materials once, named `rgb(r,g,b)`, index 0 the uncoloured default;
//! - a part placed once is a transformed copy, a part placed more than once is shared
//!   geometry with one [`Instance`] per placement (Dammertz §3.3), prepared once;
//! - what could not be read is returned as warning lines for the command line to print
//!   (the library prints nothing) and as notes for `info`;
//! - a file that yields nothing renderable is an error that says what the file held and
//!   why each entity failed, never an empty scene.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};

use crate::formats::error::LoadError;
use crate::scene::model::{Geometry, Instance, Material, Object, Scene, Surface, TriangleMesh};

/// A length unit as the file declared it: its name and its size in millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct DeclaredUnit {
    pub name: String,
    pub millimetres: f64,
}

impl DeclaredUnit {
    /// The unit of a scene read from a `format` file in this unit, in words: millimetres,
    /// and what the file declared.
    pub fn in_words(&self, format: &str) -> String {
        format!(
            "lengths in millimetres (the {format} file declares {}, {} mm)",
            self.name, self.millimetres
        )
    }
}

/// One renderable piece of a part: an exact surface or a triangle mesh the file gives as
/// triangles (AP242 tessellated geometry).
#[derive(Clone, Debug)]
pub enum Shape {
    Surface(Surface),
    Triangles(TriangleMesh),
}

/// A shape and the colour the file gives it (`None`: uncoloured).
#[derive(Clone, Debug)]
pub struct Piece {
    pub shape: Shape,
    pub colour: Option<Vec3>,
}

/// A part: geometry in its own coordinates, in the file's declared unit.
#[derive(Clone, Debug, Default)]
pub struct Part {
    /// How the file names the part (`#12` for a STEP representation), used in object names.
    pub name: String,
    pub pieces: Vec<Piece>,
}

/// One placement of a part: part coordinates to model coordinates, both in the file's
/// declared unit.
#[derive(Clone, Debug)]
pub struct Occurrence {
    pub part: usize,
    pub transform: DAffine3,
}

/// An entity the reader could not convert: how the file names it (`#12`, `D 45`) and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub entity: String,
    pub why: String,
}

/// What a CAD reader hands over.
#[derive(Clone, Debug)]
pub struct CadModel {
    /// The format's name, for messages: `STEP`, `IGES`.
    pub format: &'static str,
    /// What the converted entities are called in messages: `face`, `surface`.
    pub noun: &'static str,
    pub unit: DeclaredUnit,
    pub parts: Vec<Part>,
    pub occurrences: Vec<Occurrence>,
    /// Entities that could not be converted.
    pub failures: Vec<Failure>,
    /// Valid entities the reader does not read, counted by type.
    pub skipped: BTreeMap<String, usize>,
    /// What the file held, in a few words (for the error when nothing is renderable).
    pub held: String,
    /// Facts for `info`, one line each (schema, units, counts).
    pub notes: Vec<String>,
    /// Warnings of the reader's own (tolerated syntax, healing), one line each, without
    /// the file name.
    pub warnings: Vec<String>,
}

impl CadModel {
    /// An empty model of `format` in `unit`.
    pub fn new(format: &'static str, noun: &'static str, unit: DeclaredUnit) -> CadModel {
        CadModel {
            format,
            noun,
            unit,
            parts: Vec::new(),
            occurrences: Vec::new(),
            failures: Vec::new(),
            skipped: BTreeMap::new(),
            held: String::new(),
            notes: Vec::new(),
            warnings: Vec::new(),
        }
    }

    fn skipped_list(&self) -> String {
        self.skipped
            .iter()
            .map(|(t, n)| format!("{t} x{n}"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The lines `info` prints: the reader's notes, what was skipped, each failure.
    pub fn info_lines(&self) -> Vec<String> {
        let mut out = self.notes.clone();
        if !self.skipped.is_empty() {
            out.push(format!("unsupported entities: {}", self.skipped_list()));
        }
        for f in &self.failures {
            out.push(format!(
                "{} {} not converted: {}",
                self.noun, f.entity, f.why
            ));
        }
        out
    }

    /// The warning lines for the command line, each naming `path`: the reader's own, then
    /// one line for what was left out.
    pub fn warning_lines(&self, path: &Path) -> Vec<String> {
        let mut out: Vec<String> = self
            .warnings
            .iter()
            .map(|w| format!("warning: {}: {w}", path.display()))
            .collect();
        let mut parts = Vec::new();
        if !self.failures.is_empty() {
            let ids: Vec<&str> = self.failures.iter().map(|f| f.entity.as_str()).collect();
            parts.push(format!(
                "{} {}(s) not converted ({})",
                ids.len(),
                self.noun,
                ids.join(" ")
            ));
        }
        if !self.skipped.is_empty() {
            parts.push(format!("unsupported entities: {}", self.skipped_list()));
        }
        if !parts.is_empty() {
            out.push(format!("warning: {}: {}", path.display(), parts.join("; ")));
        }
        out
    }
}

/// A model's objects (in millimetres) and their materials (index 0 the default), before
/// framing.
pub struct Assembled {
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    /// Distinct colours among the materials.
    pub colours: usize,
}

/// The material name of a colour: the one naming scheme of every CAD format.
pub fn colour_name(c: Vec3) -> String {
    format!("rgb({:.3},{:.3},{:.3})", c.x, c.y, c.z)
}

/// Which kind of geometry a group holds: a scene [`Geometry`] is surfaces or a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Kind {
    Surfaces,
    Triangles,
}

/// Objects of `model`: one per occurrence, material and kind of geometry, placed in
/// millimetres; `stem` names them.
pub fn assemble(model: &CadModel, stem: &str) -> Assembled {
    let mut palette: Vec<Vec3> = Vec::new();
    let mut material_of = |c: Option<Vec3>| match c {
        Some(c) => {
            1 + palette.iter().position(|p| *p == c).unwrap_or_else(|| {
                palette.push(c);
                palette.len() - 1
            })
        }
        None => 0,
    };
    // Each part's pieces grouped by material and kind, once per part.
    let groups: Vec<BTreeMap<(usize, Kind), Geometry>> = model
        .parts
        .iter()
        .map(|part| {
            let mut g: BTreeMap<(usize, Kind), Geometry> = BTreeMap::new();
            for piece in &part.pieces {
                let m = material_of(piece.colour);
                match &piece.shape {
                    Shape::Surface(s) => {
                        if let Geometry::Surfaces(v) = g
                            .entry((m, Kind::Surfaces))
                            .or_insert_with(|| Geometry::Surfaces(Vec::new()))
                        {
                            v.push(s.clone());
                        }
                    }
                    Shape::Triangles(t) => {
                        if let Geometry::Mesh(mesh) = g
                            .entry((m, Kind::Triangles))
                            .or_insert_with(|| Geometry::Mesh(TriangleMesh::default()))
                        {
                            append_mesh(mesh, t);
                        }
                    }
                }
            }
            g
        })
        .collect();
    let mut materials = vec![Material::default_named("default")];
    for c in &palette {
        let mut m = Material::default_named(&colour_name(*c));
        m.diffuse = *c;
        materials.push(m);
    }
    let mut uses = vec![0usize; model.parts.len()];
    for o in &model.occurrences {
        uses[o.part] += 1;
    }
    let scale = DAffine3::from_scale(DVec3::splat(model.unit.millimetres));
    let mut shared: HashMap<(usize, usize, Kind), Arc<Geometry>> = HashMap::new();
    let mut placed = Vec::new();
    for (k, occ) in model.occurrences.iter().enumerate() {
        for (&(material, kind), geometry) in &groups[occ.part] {
            placed.push((k, material, kind, occ, geometry));
        }
    }
    let many = placed.len() > 1;
    let objects = placed
        .into_iter()
        .map(|(k, material, kind, occ, geometry)| {
            let placement = scale * occ.transform;
            let geometry = if uses[occ.part] > 1 {
                let part = shared
                    .entry((occ.part, material, kind))
                    .or_insert_with(|| Arc::new(geometry.clone()));
                Geometry::Instance(Instance::new(part.clone(), placement))
            } else {
                let mut g = geometry.clone();
                g.transform(&placement);
                g
            };
            Object {
                name: if many {
                    format!(
                        "{stem} {} occurrence {} {}",
                        model.parts[occ.part].name,
                        k + 1,
                        materials[material].name
                    )
                } else {
                    stem.to_string()
                },
                material,
                geometry,
            }
        })
        .collect();
    Assembled {
        objects,
        materials,
        colours: palette.len(),
    }
}

fn append_mesh(into: &mut TriangleMesh, t: &TriangleMesh) {
    let base = into.positions.len() as u32;
    // Normals are kept only when every piece has them, one per position.
    let with_normals =
        into.normals.len() == into.positions.len() && t.normals.len() == t.positions.len();
    into.positions.extend_from_slice(&t.positions);
    if with_normals {
        into.normals.extend_from_slice(&t.normals);
    } else {
        into.normals.clear();
    }
    into.indices.extend(
        t.indices
            .iter()
            .map(|i| [i[0] + base, i[1] + base, i[2] + base]),
    );
}

/// A CAD file read: its scene (framed, its warnings in [`Scene::warnings`]) and the lines
/// `info` prints.
pub struct CadScene {
    pub scene: Scene,
    pub notes: Vec<String>,
}

/// Most failures listed one by one in the nothing-renderable error; the rest are counted.
const LISTED_FAILURES: usize = 20;

/// The scene of `model`, read from `path`; an error when nothing in it can be rendered.
pub fn build_scene(path: &Path, model: CadModel) -> Result<CadScene, LoadError> {
    let stem = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let assembled = assemble(&model, &stem);
    if !assembled.objects.iter().any(renderable) {
        return Err(nothing_renderable(path, &model));
    }
    let mut scene = Scene::framing(assembled.objects);
    scene.materials = assembled.materials;
    scene.warnings = model.warning_lines(path);
    scene.unit = Some(crate::scene::model::SceneUnit {
        millimetres: 1.0,
        words: model.unit.in_words(model.format),
    });
    Ok(CadScene {
        notes: model.info_lines(),
        scene,
    })
}

/// The surfaces (or, when it has only triangles, the mesh) of a CAD file as one geometry,
/// for a scene's `File("part.step")`, and its warning lines.
pub fn build_geometry(path: &Path, model: CadModel) -> Result<(Geometry, Vec<String>), LoadError> {
    let CadScene { scene, .. } = build_scene(path, model)?;
    let mut warnings = scene.warnings;
    let mut surfaces = Vec::new();
    let mut mesh = TriangleMesh::default();
    for o in scene.objects {
        match o.geometry.resolved().into_owned() {
            Geometry::Surfaces(s) => surfaces.extend(s),
            Geometry::Mesh(m) => append_mesh(&mut mesh, &m),
            _ => {}
        }
    }
    if surfaces.is_empty() {
        return Ok((Geometry::Mesh(mesh), warnings));
    }
    if !mesh.indices.is_empty() {
        warnings.push(format!(
            "warning: {}: {} triangle(s) left out: a scene's File geometry is surfaces or a mesh, and this file has both; read the file on its own to see both",
            path.display(),
            mesh.indices.len()
        ));
    }
    Ok((Geometry::Surfaces(surfaces), warnings))
}

fn renderable(o: &Object) -> bool {
    match &o.geometry {
        Geometry::Surfaces(s) => !s.is_empty(),
        Geometry::Mesh(m) => !m.indices.is_empty(),
        Geometry::Instance(i) => match i.geometry.as_ref() {
            Geometry::Surfaces(s) => !s.is_empty(),
            Geometry::Mesh(m) => !m.indices.is_empty(),
            _ => true,
        },
        Geometry::Subdivision(_) => true,
    }
}

/// The error for a file with nothing renderable: what it held, what was skipped, and why
/// each entity that was tried failed.
fn nothing_renderable(path: &Path, model: &CadModel) -> LoadError {
    let mut msg = format!(
        "nothing to render: the {} file holds {}",
        model.format,
        if model.held.is_empty() {
            "no geometry"
        } else {
            model.held.as_str()
        }
    );
    if !model.skipped.is_empty() {
        msg.push_str(&format!(
            "; not read (unsupported): {}",
            model.skipped_list()
        ));
    }
    if !model.failures.is_empty() {
        msg.push_str(&format!(
            "; {} {}(s) could not be converted:",
            model.failures.len(),
            model.noun
        ));
        for f in model.failures.iter().take(LISTED_FAILURES) {
            msg.push_str(&format!("\n  {} {}: {}", model.noun, f.entity, f.why));
        }
        if model.failures.len() > LISTED_FAILURES {
            msg.push_str(&format!(
                "\n  and {} more",
                model.failures.len() - LISTED_FAILURES
            ));
        }
    }
    LoadError::invalid(path, msg)
}
