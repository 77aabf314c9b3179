//! IGES 5.3 (`.igs`, `.iges`), the exchange format CAD systems write, read exactly: no
//! tessellation; analytic geometry becomes rational NURBS through
//! `geom::nurbs::analytic`. Layered as OpenCASCADE's IGES reader: `records` (the file's
//! syntax, `IGESData`), `directory` (Directory Entries), `entities` (typed entities,
//! `IGESGeom`), then translation by kind (`IGESToBRep`): `curves`, `surfaces`, `trimmed`
//! (144 over any surface, 142 curves on surfaces).
//!
//! Drawn are the visible entities that are not physically part of others (§2.3.1 status):
//! trimmed surfaces (144), bounded surfaces (143), the faces of manifold solids (186, its
//! 514 shells, 510 faces, 508 loops and 504 edge lists), bare surfaces (128, 114, 108,
//! 118, 120, 122, and the closed analytic 196, 198), and subfigure instances (408 of a
//! 308), flattened into transformed copies of their members. What is not read is counted
//! by type in [`Report`]; a surface that cannot be converted is named by its
//! directory sequence number; neither is dropped silently.

pub mod curves;
pub mod directory;
pub mod elementary;
pub mod entities;
mod projection;
pub mod records;
pub mod surfaces;
pub mod trimmed;
pub mod units;

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DAffine3, DVec3};

use self::directory::DirEntry;
use self::entities::{Entity, Params};
use self::records::{Tolerated, Value};
use self::units::LengthUnit;
use super::scene::{CadModel, DeclaredUnit, Failure, Occurrence, Part, Piece, Shape};
use crate::formats::error::ParseError;
use crate::scene::model::Surface;

/// The file's entities, addressed by directory pointer.
pub struct Model {
    pub entries: Vec<DirEntry>,
    pub entities: Vec<Entity>,
    /// The parameter-space curves on 192–198 follow OpenCASCADE's parameterisations:
    /// files written by it, whose IGES writer and reader
    /// (`IGESToBRep_TopoSurface::ParamSurface`) scale the angles of cylinders, cones (u),
    /// spheres and tori by 180/π, measure a cone's v along its side and exchange a torus's
    /// u and v; the 5.3 text read here gives radians and the height along the axis.
    pub angles_in_degrees: bool,
}

/// Nesting limit of transforms referring to transforms, against cycles.
const MAX_TRANSFORM_CHAIN: usize = 32;

impl Model {
    /// The entry and entity a directory pointer (odd sequence number) names.
    pub fn get(&self, pointer: usize) -> Result<(&DirEntry, &Entity), String> {
        let i = pointer.wrapping_sub(1) / 2;
        if pointer.is_multiple_of(2) || i >= self.entries.len() {
            return Err(format!("D {pointer} is not a directory entry of this file"));
        }
        Ok((&self.entries[i], &self.entities[i]))
    }

    /// The transform a directory entry's transform pointer names, chained through the
    /// transforms' own pointers (§4.21: the 124's matrix is itself in the space of the
    /// one it points to); identity for 0.
    pub fn transform(&self, mut pointer: usize) -> Result<DAffine3, String> {
        let mut m = DAffine3::IDENTITY;
        for _ in 0..MAX_TRANSFORM_CHAIN {
            if pointer == 0 {
                return Ok(m);
            }
            let (entry, entity) = self.get(pointer)?;
            let Entity::Transform(t) = entity else {
                return Err(format!(
                    "the transform pointer D {pointer} names entity {}, not 124",
                    entry.entity_type
                ));
            };
            m = *t * m;
            pointer = entry.transform;
        }
        Err(format!(
            "transforms chain deeper than {MAX_TRANSFORM_CHAIN} (a cycle?)"
        ))
    }

    /// The colour of an entry (RGB in [0, 1]): a 314 it points to, or one of the eight
    /// predefined colours (§2.3.1 field 13).
    pub fn colour(&self, entry: &DirEntry) -> Option<DVec3> {
        match entry.colour {
            c if c < 0 => match self.get(c.unsigned_abs() as usize).ok()?.1 {
                Entity::Colour(rgb) => Some((*rgb / 100.0).clamp(DVec3::ZERO, DVec3::ONE)),
                _ => None,
            },
            1 => Some(DVec3::ZERO),
            2 => Some(DVec3::X),
            3 => Some(DVec3::Y),
            4 => Some(DVec3::Z),
            5 => Some(DVec3::new(1.0, 1.0, 0.0)),
            6 => Some(DVec3::new(1.0, 0.0, 1.0)),
            7 => Some(DVec3::new(0.0, 1.0, 1.0)),
            8 => Some(DVec3::ONE),
            _ => None,
        }
    }
}

/// What reading found besides the surfaces: units, and what was not drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The declared length unit (Global parameters 14 and 15).
    pub unit: LengthUnit,
    /// Global parameter 13, model space scale (reported, not applied: see `units`).
    pub scale: f64,
    /// What was tolerated or guessed, one line each, for the command line to print.
    pub warnings: Vec<String>,
    /// Drawn entities of types that are not read, by type.
    pub ignored: BTreeMap<i32, usize>,
    /// Surfaces that could not be converted, named by directory sequence number (`D 45`).
    pub failed: Vec<Failure>,
    /// Trim curves projected from model space; the largest distance between such a
    /// curve's trim and its projection onto the surface (this reader's approximation); and
    /// the largest distance of the curve itself from the surface (the file's own gap).
    pub projected: usize,
    pub max_trim_error: f64,
    pub max_curve_gap: f64,
    /// Surfaces (directory sequence numbers) whose parameter-space trim curves lay far
    /// from their model-space curves, which were drawn instead, and the largest distance.
    pub strayed: Vec<usize>,
    pub max_stray: f64,
    /// Model-space curves (directory sequence numbers) lying far from the surface they
    /// bound while their parameter-space curves disagree with them: the parameter-space
    /// curves were drawn.
    pub off_surface: Vec<usize>,
    /// Blanked entities (status 01, §2.2.4.4.9) drawn, as OpenCASCADE draws them.
    pub blanked: usize,
}

impl Report {
    /// The lines `info` prints about the file (what was skipped and failed is added by
    /// the [CAD front door](crate::formats::cad::scene)).
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![format!(
            "IGES units: {} ({} mm), read in millimetres (model scale {}{})",
            self.unit.name,
            self.unit.millimetres,
            self.scale,
            if self.scale == 1.0 {
                ""
            } else {
                ", not applied, as OpenCASCADE reads it"
            }
        )];
        if self.projected > 0 {
            out.push(format!(
                "IGES trim curves projected from model space: {}; their trims within {:.3e} mm of the projected curves, which lie up to {:.3e} mm from their surfaces",
                self.projected,
                self.max_trim_error * self.unit.millimetres,
                self.max_curve_gap * self.unit.millimetres
            ));
        }
        if self.blanked > 0 {
            out.push(format!(
                "IGES blanked entities drawn (as OpenCASCADE reads them): {}",
                self.blanked
            ));
        }
        if let Some(first) = self.off_surface.first() {
            out.push(format!(
                "IGES model-space trim curves lying off their surfaces, their parameter-space curves drawn: {} (first D {first})",
                self.off_surface.len()
            ));
        }
        if let Some(first) = self.strayed.first() {
            out.push(format!(
                "IGES trim curves drawn from model space because their parameter-space curves lie up to {:e} mm from them: on {} surface(s) (first D {first})",
                self.max_stray * self.unit.millimetres,
                self.strayed.len()
            ));
        }
        out
    }

    /// The entity types not read, each named, for the front door's count by type.
    pub fn skipped(&self) -> BTreeMap<String, usize> {
        self.ignored
            .iter()
            .map(|(t, n)| (format!("{t} ({})", entity_name(*t)), *n))
            .collect()
    }
}

/// Names of entity types (IGES 5.3 chapter 4) for the report.
fn entity_name(t: i32) -> &'static str {
    match t {
        100 => "circular arc, not drawn",
        102 => "composite curve, not drawn",
        104 => "conic arc, not drawn",
        106 => "copious data, not drawn",
        110 => "line, not drawn",
        112 => "parametric spline curve, not drawn",
        126 => "rational B-spline curve, not drawn",
        142 => "curve on a surface, not drawn",
        114 => "parametric spline surface",
        116 => "point",
        123 => "direction",
        125 => "flash",
        130 => "offset curve",
        140 => "offset surface",
        141 => "boundary",
        143 => "bounded surface",
        186 => "manifold solid B-rep",
        190 => "plane surface",
        192 => "right circular cylindrical surface",
        194 => "right circular conical surface",
        196 => "spherical surface",
        198 => "toroidal surface",
        212 | 213 => "text",
        308 => "subfigure definition",
        402 => "associativity",
        406 => "property",
        408 => "singular subfigure instance",
        502 => "vertex list",
        504 => "edge list",
        508 => "loop",
        510 => "face",
        514 => "shell",
        _ => "not supported",
    }
}

/// A converted surface and the colour of its entity.
pub struct Drawn {
    pub surface: Surface,
    pub colour: Option<DVec3>,
}

/// The drawn surfaces of a file, and the report.
pub struct Iges {
    pub surfaces: Vec<Drawn>,
    pub report: Report,
    /// What the file holds, by entity type, for the error when nothing is renderable.
    pub held: String,
}

/// The entity types of a file's directory and their counts, in a few words.
fn held(entries: &[DirEntry]) -> String {
    let mut types: BTreeMap<i32, usize> = BTreeMap::new();
    for e in entries {
        *types.entry(e.entity_type).or_default() += 1;
    }
    let listed: Vec<String> = types.iter().map(|(t, n)| format!("{t} x{n}")).collect();
    format!(
        "{} entities (by type: {})",
        entries.len(),
        if listed.is_empty() {
            "none".to_string()
        } else {
            listed.join(", ")
        }
    )
}

impl Iges {
    /// The front door's model of the file: one part, placed once, in the file's unit
    /// (the front door scales it to millimetres, as OpenCASCADE reads IGES).
    pub fn into_model(self) -> CadModel {
        let r = self.report;
        let mut model = CadModel::new(
            "IGES",
            "surface",
            DeclaredUnit {
                name: r.unit.name.clone(),
                millimetres: r.unit.millimetres,
            },
        );
        model.parts.push(Part {
            name: "IGES".into(),
            pieces: self
                .surfaces
                .into_iter()
                .map(|d| Piece {
                    shape: Shape::Surface(d.surface),
                    colour: d.colour.map(|c| c.as_vec3()),
                })
                .collect(),
        });
        model.occurrences.push(Occurrence {
            part: 0,
            transform: DAffine3::IDENTITY,
        });
        model.notes = r.lines();
        model.skipped = r.skipped();
        model.held = self.held;
        model.warnings = r.warnings;
        model.failures = r.failed;
        model
    }
}

/// One warning for the Hollerith strings read with a corrected count.
fn tolerated_warning(t: &[Tolerated]) -> Option<String> {
    let first = t.first()?;
    Some(format!(
        "{} Hollerith string(s) whose character count does not end at a delimiter, read up to the delimiter that follows (first at line {}, column {}: {} characters announced, {} before the delimiter)",
        t.len(),
        first.line,
        first.column,
        first.announced,
        first.read
    ))
}

/// The number of parameter records of `entry`: those from its first that point back to it
/// (columns 65–72, which every record of the entity carries, §2.2.4.5), where they do;
/// writers miscount the directory's parameter line count (Rhino 98 writes 20 for a 128
/// on 7 records), and OpenCASCADE reads an entity to its record delimiter whatever the
/// count says. A count that disagrees is noted in `miscounted` (directory sequence
/// number, announced, read). Without back pointers the directory's count stands.
fn parameter_lines(
    sections: &records::Sections,
    entry: &directory::DirEntry,
    miscounted: &mut Vec<(usize, usize, usize)>,
) -> usize {
    let first = entry.param_start.wrapping_sub(1);
    let owned = sections
        .owners
        .get(first..)
        .unwrap_or(&[])
        .iter()
        .take_while(|&&o| o == Some(entry.sequence))
        .count();
    if owned == 0 {
        return entry.param_count.max(1);
    }
    if owned != entry.param_count {
        miscounted.push((entry.sequence, entry.param_count, owned));
    }
    owned
}

fn miscounted_warning(m: &[(usize, usize, usize)]) -> Option<String> {
    let (sequence, announced, read) = m.first()?;
    Some(format!(
        "{} entities whose directory parameter line count disagrees with the records that point back to them, read to their own records (first D {sequence}: {announced} announced, {read} read)",
        m.len()
    ))
}

/// Parses an IGES file. Syntax errors are located parse errors; surfaces that cannot be
/// converted are reported, not fatal.
pub fn parse_iges(path: &Path, src: &str) -> Result<Iges, ParseError> {
    let sections = records::sections(path, src)?;
    let mut tolerated = Vec::new();
    let (delims, global) = records::global(path, &sections.global, &mut tolerated)?;
    let text = |i: usize| match global.get(i - 1).map(|t| &t.value) {
        Some(Value::Text(s)) => Some(s.clone()),
        _ => None,
    };
    let number = |i: usize| match global.get(i - 1).map(|t| &t.value) {
        Some(Value::Number { value, .. }) => Some(*value),
        _ => None,
    };
    let (unit, unit_warning) =
        units::length_unit(number(14).map(|f| f as i64), text(15).as_deref());
    let mut report = Report {
        unit,
        scale: number(13).unwrap_or(1.0),
        warnings: unit_warning.into_iter().collect(),
        ignored: BTreeMap::new(),
        failed: Vec::new(),
        projected: 0,
        max_trim_error: 0.0,
        max_curve_gap: 0.0,
        strayed: Vec::new(),
        max_stray: 0.0,
        off_surface: Vec::new(),
        blanked: 0,
    };
    let entries = directory::entries(path, &sections.directory)?;
    let mut entities = Vec::with_capacity(entries.len());
    let mut miscounted = Vec::new();
    for entry in &entries {
        if !entities::is_supported(entry.entity_type) {
            entities.push(Entity::Unsupported);
            continue;
        }
        let first = entry.param_start.wrapping_sub(1);
        let count = parameter_lines(&sections, entry, &mut miscounted);
        let records = sections
            .parameters
            .get(first..first.saturating_add(count))
            .ok_or_else(|| {
                ParseError::new(
                    path,
                    entry.line,
                    9,
                    format!(
                        "entity {} (D {}): expected its parameter data at P {} ({} records), past the Parameter Data section's {} records",
                        entry.entity_type,
                        entry.sequence,
                        entry.param_start,
                        entry.param_count,
                        sections.parameters.len()
                    ),
                )
            })?;
        let tokens = records::parameters(path, records, delims, &mut tolerated)?;
        let p = Params {
            path,
            entry,
            tokens,
        };
        if !matches!(p.tokens.first().map(|t| &t.value), Some(Value::Number { value, .. }) if *value == f64::from(entry.entity_type))
        {
            let t = &p.tokens[0];
            return Err(ParseError::new(
                path,
                t.line,
                t.column,
                format!(
                    "entity {} (D {}): expected its parameter data to start with its type {}, found `{}`",
                    entry.entity_type, entry.sequence, entry.entity_type, t.written
                ),
            ));
        }
        entities.push(entities::read(&p)?);
    }
    // Global parameters 3, 5 and 6 name the sending product, system and preprocessor.
    let angles_in_degrees = [3, 5, 6].iter().any(|&i| {
        text(i).is_some_and(|t| {
            let t = t.to_ascii_lowercase();
            t.contains("open cascade") || t.contains("opencascade")
        })
    });
    report.warnings.extend(tolerated_warning(&tolerated));
    report.warnings.extend(miscounted_warning(&miscounted));
    let model = Model {
        entries,
        entities,
        angles_in_degrees,
    };
    // Some writers leave the surface under a 144 marked independent; it is drawn through
    // the 144 only (drawn again, its untrimmed whole would cover the trims). Members of
    // subfigure definitions are drawn through their instances only.
    let mut through_others = std::collections::HashSet::new();
    for e in &model.entities {
        match e {
            Entity::Trimmed { surface, .. }
            | Entity::Bounded { surface, .. }
            | Entity::Face { surface, .. } => {
                through_others.insert(*surface);
            }
            Entity::Subfigure(members) => through_others.extend(members.iter().copied()),
            // Faces and shells of a solid (or shell) are drawn through it, whatever
            // their status says.
            Entity::Shell(faces) => through_others.extend(faces.iter().copied()),
            Entity::Brep { shells } => through_others.extend(shells.iter().copied()),
            _ => {}
        }
    }
    let mut surfaces = Vec::new();
    for entry in &model.entries {
        if through_others.contains(&entry.sequence) {
            continue;
        }
        // A face, shell, solid or trimmed surface marked as part of another entity that no
        // shell, solid or subfigure holds is drawn on its own, as OpenCASCADE draws every
        // entity nothing references (OpenCASCADE writes a lone 510 face so).
        let orphan = matches!(entry.subordinate, directory::Subordinate::Physical)
            && matches!(entry.entity_type, 143 | 144 | 186 | 510 | 514);
        if !entry.is_drawn() && !orphan {
            continue;
        }
        let before = surfaces.len();
        draw(
            &model,
            entry.sequence,
            &DAffine3::IDENTITY,
            &mut Instancing::default(),
            &mut report,
            &mut surfaces,
        );
        if entry.blank && surfaces.len() > before {
            report.blanked += 1;
        }
    }
    Ok(Iges {
        surfaces,
        report,
        held: held(&model.entries),
    })
}

/// Entities drawn through the instances of one top-level 408 at most: definitions that
/// instance each other several times multiply, and a hostile file must not turn a few
/// lines into billions of surfaces.
const MAX_INSTANCE_COPIES: usize = 1 << 16;

/// The subfigure definitions being expanded (a definition inside itself is a cycle) and
/// the copies still allowed.
struct Instancing {
    definitions: Vec<usize>,
    copies_left: usize,
}

impl Default for Instancing {
    fn default() -> Self {
        Instancing {
            definitions: Vec::new(),
            copies_left: MAX_INSTANCE_COPIES,
        }
    }
}

/// Converts the drawn entity at `pointer` into `out`, every surface mapped by `m` (the
/// transforms of the instances it is drawn through). Failures are reported by entity.
fn draw(
    model: &Model,
    pointer: usize,
    m: &DAffine3,
    instancing: &mut Instancing,
    report: &mut Report,
    out: &mut Vec<Drawn>,
) {
    let Ok((entry, entity)) = model.get(pointer) else {
        report.failed.push(Failure {
            entity: format!("D {pointer}"),
            why: "not a directory entry of this file".into(),
        });
        return;
    };
    let colour = model.colour(entry);
    let fail = |report: &mut Report, why: String| {
        report
            .failed
            .push(failure(entry.entity_type, entry.sequence, why))
    };
    let converted = match entity {
        Entity::Trimmed { .. } => trimmed::trimmed(model, pointer, report),
        Entity::Bounded { .. } => trimmed::bounded(model, pointer, report),
        Entity::BSplineSurface(_)
        | Entity::SplineSurface(_)
        | Entity::Elementary { .. }
        | Entity::Plane { .. }
        | Entity::Ruled { .. }
        | Entity::Revolution { .. }
        | Entity::Offset { .. }
        | Entity::Tabulated { .. } => trimmed::untrimmed(model, pointer, report),
        // A face (510) drawn on its own: a file of faces without a solid.
        Entity::Face { .. } => trimmed::face(model, pointer, report),
        Entity::Brep { shells } => {
            // §4.2 (186): every face of the outer and void shells, each its own trimmed
            // surface, in the solid's colour unless the face has its own.
            let solid = match model.transform(entry.transform) {
                Ok(t) => *m * t,
                Err(why) => return fail(report, why),
            };
            for &shell in shells {
                match model.get(shell) {
                    Ok((_, Entity::Shell(faces))) => {
                        draw_faces(model, faces, &solid, colour, report, out);
                    }
                    Ok(_) => {
                        return fail(report, format!("the shell D {shell} is not a shell (514)"));
                    }
                    Err(why) => return fail(report, why),
                }
            }
            return;
        }
        // A shell (514) drawn on its own, its faces in its colour.
        Entity::Shell(faces) => {
            match model.transform(entry.transform) {
                Ok(t) => draw_faces(model, faces, &(*m * t), colour, report, out),
                Err(why) => fail(report, why),
            }
            return;
        }
        Entity::Instance {
            definition,
            translation,
            scale,
        } => {
            // §4.137 (408): the definition scaled by S, translated by (X, Y, Z), then
            // mapped by the instance's own transform. Each instance becomes transformed
            // copies of the members (a STEP part used more than once is shared instead).
            if instancing.definitions.contains(definition) {
                return fail(
                    report,
                    format!("the definition D {definition} contains an instance of itself"),
                );
            }
            let own = match model.transform(entry.transform) {
                Ok(t) => t,
                Err(why) => return fail(report, why),
            };
            let placed = *m
                * own
                * DAffine3::from_translation(*translation)
                * DAffine3::from_scale(DVec3::splat(*scale));
            match model.get(*definition) {
                Ok((_, Entity::Subfigure(members))) => {
                    instancing.definitions.push(*definition);
                    for &member in members {
                        if instancing.copies_left == 0 {
                            fail(
                                report,
                                format!(
                                    "more than {MAX_INSTANCE_COPIES} entities drawn through instances"
                                ),
                            );
                            break;
                        }
                        instancing.copies_left -= 1;
                        draw(model, member, &placed, instancing, report, out);
                    }
                    instancing.definitions.pop();
                }
                Ok(_) => fail(
                    report,
                    format!("the definition D {definition} is not a subfigure definition (308)"),
                ),
                Err(why) => fail(report, why),
            }
            return;
        }
        // Definitions are drawn through their instances; these are not drawn.
        Entity::Subfigure(_) | Entity::Transform(_) | Entity::Colour(_) => return,
        _ => {
            *report.ignored.entry(entry.entity_type).or_default() += 1;
            return;
        }
    };
    match converted {
        Ok(mut surface) => {
            if *m != DAffine3::IDENTITY {
                surface.transform(m);
            }
            out.push(Drawn { surface, colour });
        }
        Err(why) => fail(report, why),
    }
}

/// The faces (510) of a shell, each its own trimmed surface placed by `placement`, in its
/// own colour or else `colour` (the shell's or its solid's).
fn draw_faces(
    model: &Model,
    faces: &[usize],
    placement: &DAffine3,
    colour: Option<DVec3>,
    report: &mut Report,
    out: &mut Vec<Drawn>,
) {
    for &f in faces {
        let face_colour = model.get(f).ok().and_then(|(e, _)| model.colour(e));
        match trimmed::face(model, f, report) {
            Ok(mut surface) => {
                surface.transform(placement);
                out.push(Drawn {
                    surface,
                    colour: face_colour.or(colour),
                });
            }
            Err(why) => report.failed.push(failure(510, f, why)),
        }
    }
}

/// A surface that could not be converted: named by its directory sequence number, its
/// entity type opening the reason.
fn failure(entity_type: i32, sequence: usize, why: String) -> Failure {
    Failure {
        entity: format!("D {sequence}"),
        why: format!("entity {entity_type}: {why}"),
    }
}

/// Reads an IGES file from disk.
pub fn read_iges(path: &Path) -> Result<Iges, crate::formats::LoadError> {
    // Hollerith strings may hold any 8-bit text; the geometry is ASCII.
    let bytes = std::fs::read(path).map_err(|e| crate::formats::LoadError::io(path, e))?;
    Ok(parse_iges(path, &String::from_utf8_lossy(&bytes))?)
}

/// Reads an IGES file for the [CAD front door](crate::formats::cad::scene).
pub fn read_cad(path: &Path) -> Result<CadModel, crate::formats::LoadError> {
    Ok(read_iges(path)?.into_model())
}
