//! STEP (ISO 10303-21 exchange structure, AP203/AP214/AP242 B-rep models), layered like
//! OpenCASCADE's reader (StepData / StepGeom / StepToGeom):
//!
//! - `lexer`, `records`: Part 21 syntax, every token with its line and column.
//! - `entities`: typed, validated ISO 10303-42 geometry and topology.
//! - `geometry`: curves and surfaces evaluated by their definitions, converted to exact
//!   rational NURBS through the shared `geom::nurbs::analytic`.
//! - `topology`: faces and their bounds to trim loops in each surface's parameter domain.
//! - `items`: what a representation holds (solids, shells, surface models, geometric sets)
//!   down to what is rendered: faces, `surfaces` standing alone (curve-bounded,
//!   rectangular-trimmed, bare), and `tessellated` items as triangles.
//! - `assembly`, `units`, `style`: placements of parts, length units, colours.
//!
//! As in OpenCASCADE's reader, damage costs only what it touches: an instance that does
//! not parse is skipped (one warning), and a face (or standalone surface, tessellated
//! item) that is malformed (wrong parameter kinds, dangling references, zero directions)
//! or uses what the reader does not convert is named by `#id` with its reason, located at
//! `LINE:COL: #id ENTITY: …`; entities the reader does not convert are counted by type.
//! A file whose structure is broken (header, sections, a string left open) is an error
//! located the same way;
//! the [CAD front door](crate::formats::cad::scene) turns what was read into the scene, the
//! lines `info` prints and one warning line.

pub mod assembly;
pub mod entities;
pub mod geometry;
pub mod items;
pub mod lexer;
mod loop_piece;
pub mod records;
pub mod style;
pub mod surfaces;
pub mod tessellated;
pub mod topology;
pub mod units;

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;

use glam::{DAffine3, DVec3};
use rayon::prelude::*;

use self::entities::Resolver;
use self::style::Colour;
use self::units::Units;
use super::POINT_TOLERANCE;
use super::scene::{self, CadModel, DeclaredUnit, Failure, Part, Piece, Shape};
use crate::formats::error::{LoadError, ParseError};
use crate::scene::model::{Material, Object, TriangleMesh};

/// What reading a STEP file found beyond the geometry.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub schemas: Vec<String>,
    pub units: Units,
    pub faces: usize,
    /// Surfaces converted outside faces (in geometric sets and surface models).
    pub surfaces: usize,
    /// Tessellated items read and their triangles.
    pub tessellated: usize,
    pub triangles: usize,
    /// Faces (and standalone surfaces, tessellated items) that could not be converted:
    /// `(#id, why)`.
    pub failed_faces: Vec<(u64, String)>,
    /// Entities left unread, by type.
    pub unsupported: BTreeMap<String, usize>,
    /// Edges projected into their face's domain (no usable pcurve).
    pub projected_edges: usize,
    /// The largest distance between a projected edge's trim and the edge's projection onto
    /// the surface (this reader's approximation), in millimetres, and the size of the
    /// faces' extent, which it is relative to.
    pub max_trim_error: f64,
    pub model_size: f64,
    /// Projected edges farther from a face's surface than [`Report::edge_tolerance`]:
    /// `(edge #id, face #id, distance in millimetres)`, the farthest first. Their trims
    /// follow the edge's projection onto the surface, as OpenCASCADE's healing does.
    pub far_edges: Vec<(u64, u64, f64)>,
    /// The distance within which an edge counts as on its face, in millimetres: the
    /// file's declared uncertainty, or [`POINT_TOLERANCE`] of the model where it declares
    /// none.
    pub edge_tolerance: f64,
    /// Faces kept with a projected edge farther from their surface than a pcurve may stray
    /// from its edge (the edge is not on the surface, or its projection failed), and that
    /// distance, in millimetres: `(#id, distance)`.
    pub stray_projections: Vec<(u64, f64)>,
    /// Placed occurrences of shape representations; 1 for a single part.
    pub occurrences: usize,
    pub colours: usize,
}

impl Report {
    /// One line per fact, for `info` (what was skipped and failed is added by the
    /// [CAD front door](crate::formats::cad::scene)).
    pub fn lines(&self) -> Vec<String> {
        let mut lines = vec![
            format!(
                "STEP schema: {}",
                if self.schemas.is_empty() {
                    "-".to_string()
                } else {
                    self.schemas.join(", ")
                }
            ),
            format!(
                "length unit: {} ({} mm), scaled to mm; plane angle unit: {} ({} rad)",
                self.units.length.name,
                self.units.length.factor,
                self.units.angle.name,
                self.units.angle.factor
            ),
            format!(
                "faces: {} converted, {} failed; {} shape occurrence(s); {} colour(s)",
                self.faces,
                self.failed_faces.len(),
                self.occurrences,
                self.colours
            ),
            format!(
                "projected edges (no usable pcurve): {}; their trims within {:.3e} mm of the projected edges ({:.2e} of the model's size)",
                self.projected_edges,
                self.max_trim_error,
                self.max_trim_error / self.model_size
            ),
        ];
        if let Some(&(edge, face, d)) = self.far_edges.first() {
            lines.push(format!(
                "edges farther from their face than the file's tolerance ({:.3e} mm{}): {}, up to {d:.3e} mm (edge #{edge} on face #{face}); trimmed along their projection",
                self.edge_tolerance,
                if self.units.uncertainty.is_some() {
                    ", declared"
                } else {
                    ", none declared: 1e-5 of the model"
                },
                self.far_edges.len()
            ));
        }
        if self.surfaces > 0 {
            lines.push(format!(
                "surfaces outside faces: {} converted (geometric sets, surface models)",
                self.surfaces
            ));
        }
        if self.tessellated > 0 {
            lines.push(format!(
                "tessellated items: {}, {} triangles",
                self.tessellated, self.triangles
            ));
        }
        lines
    }
}

/// A STEP file read and assembled: objects (one per shape occurrence and colour) in
/// millimetres, their materials (index 0 is the default), and the report.
pub struct StepModel {
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub report: Report,
}

fn located(path: &Path, e: lexer::LexError) -> ParseError {
    ParseError::new(path, e.line as usize, e.column as usize, e.message)
}

/// Reads a STEP file for the [CAD front door](crate::formats::cad::scene).
pub fn read_step(path: &Path) -> Result<CadModel, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    // Part 21 text is ISO 8859-1 outside strings' escapes; bytes above 127 (seen in
    // comments and names) are taken as Latin-1 rather than refused.
    let src = match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    };
    Ok(read_model(path, &src)?.0)
}

/// [`read_step`] on text already in memory, assembled as the front door assembles it;
/// `path` names the file in errors.
pub fn read_step_str(path: &Path, src: &str) -> Result<StepModel, ParseError> {
    let (model, report) = read_model(path, src)?;
    let stem = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let a = scene::assemble(&model, &stem);
    Ok(StepModel {
        objects: a.objects,
        materials: a.materials,
        report,
    })
}

/// The model's size, for tolerances: the diagonal of the bounding box of every Cartesian
/// point (1 when there are none).
fn model_size(ex: &records::Exchange) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for inst in &ex.instances {
        let r = &inst.records[0];
        if r.name == "CARTESIAN_POINT"
            && let Some(records::Value::List(c)) = r.params.get(1).map(|p| &p.value)
        {
            let v: Vec<f64> = c
                .iter()
                .filter_map(|p| match p.value {
                    records::Value::Real(x) => Some(x),
                    records::Value::Integer(i) => Some(i as f64),
                    _ => None,
                })
                .collect();
            if v.len() == 3 {
                let p = DVec3::new(v[0], v[1], v[2]);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    if lo.x <= hi.x {
        (hi - lo).length().max(f64::MIN_POSITIVE)
    } else {
        1.0
    }
}

/// What the file's shape representations hold, by item type, for the error when nothing
/// in it is renderable.
fn held(ex: &records::Exchange, faces: usize) -> String {
    let mut items: BTreeMap<String, usize> = BTreeMap::new();
    let mut seen: HashSet<u64> = HashSet::new();
    for inst in &ex.instances {
        let Some(r) = inst.shape_representation() else {
            continue;
        };
        let Some(records::Value::List(list)) = r.params.get(1).map(|p| &p.value) else {
            continue;
        };
        for p in list {
            if let records::Value::Ref(id) = p.value
                && seen.insert(id)
                && let Some(item) = ex.get(id)
            {
                *items.entry(item.type_name().into_owned()).or_default() += 1;
            }
        }
    }
    let listed: Vec<String> = items.iter().map(|(t, n)| format!("{t} x{n}")).collect();
    format!(
        "{faces} face(s); shape representation items: {}",
        if listed.is_empty() {
            "none".to_string()
        } else {
            listed.join(", ")
        }
    )
}

/// Reads the exchange structure `src` into the front door's model and the STEP report.
pub fn read_model(path: &Path, src: &str) -> Result<(CadModel, Report), ParseError> {
    let ex = records::parse(src).map_err(|e| located(path, e))?;
    let mut res = Resolver::new(&ex, path);
    let mut report = Report {
        schemas: ex.schemas(),
        units: units::file_units(&res),
        ..Default::default()
    };
    res.angle_unit = report.units.angle.factor;
    let mut unsupported = BTreeMap::new();
    let mut occurrences = assembly::occurrences(&res, &mut unsupported)?;
    if occurrences.is_empty() {
        // No product structure: every face of the file, once.
        let items: Vec<u64> = ex
            .instances
            .iter()
            .filter(|i| matches!(i.records[0].name, "ADVANCED_FACE" | "FACE_SURFACE"))
            .map(|i| i.id)
            .collect();
        if !items.is_empty() {
            occurrences.push(assembly::Occurrence {
                representation: 0,
                items,
                transform: DAffine3::IDENTITY,
                context: None,
            });
        }
    }
    report.occurrences = occurrences.len();
    let colours = style::colours(&ex);
    let size = model_size(&ex);
    // Leaves (faces, standalone surfaces, tessellated items) resolved once, in file
    // order (the resolver's caches are not shared), then converted on every core (each on
    // its own), then placed per occurrence.
    let mut placed: Vec<Vec<items::Leaf>> = Vec::with_capacity(occurrences.len());
    let mut resolved: Vec<(u64, Source)> = Vec::new();
    let mut seen: HashSet<u64> = HashSet::new();
    for occ in &occurrences {
        let mut leaves = Vec::new();
        for &item in &occ.items {
            // A container that cannot be walked (a shell with a malformed face list) is
            // lost with what it holds; the leaves found before the error are kept.
            if let Err(e) = items::leaves(&res, item, &colours, &mut unsupported, &mut leaves)
                && !report.failed_faces.iter().any(|&(f, _)| f == item)
            {
                report.failed_faces.push((item, why(&e)));
            }
        }
        for &(id, _) in &leaves {
            if seen.insert(id)
                && let Some(source) = resolve(&res, id, &mut report, &mut unsupported)
            {
                resolved.push((id, source));
            }
        }
        placed.push(leaves);
    }
    // Tolerances follow the faces' own extent where they have edges: files hold points
    // far from their faces (CATIA's k1 key: a wireframe kilometres wide).
    let size = topology::faces_extent(resolved.iter().filter_map(|(_, s)| match s {
        Source::Face(f) | Source::Standalone(surfaces::Standalone::Face(f)) => Some(f),
        _ => None,
    }))
    .unwrap_or(size);
    let outcomes: Vec<(u64, Result<Converted, String>)> = resolved
        .into_par_iter()
        .map(|(id, source)| (id, convert(source, size)))
        .collect();
    let mut converted: HashMap<u64, Shape> = HashMap::new();
    let factor = report.units.length.factor;
    report.model_size = size * factor;
    report.edge_tolerance = report
        .units
        .uncertainty
        .unwrap_or(POINT_TOLERANCE * report.model_size);
    let mut projected: HashMap<u64, (u64, f64)> = HashMap::new();
    for (id, outcome) in outcomes {
        if let Ok(Converted::Face(out) | Converted::Surface(out)) = &outcome {
            report.max_trim_error = report.max_trim_error.max(out.trim_error * factor);
            let mut worst = out.trim_error;
            for &(edge, gap) in &out.edge_gaps {
                worst = worst.max(gap);
                let farthest = projected.entry(edge).or_insert((id, gap));
                if gap > farthest.1 {
                    *farthest = (id, gap);
                }
            }
            if worst > size * topology::PCURVE_TOLERANCE {
                report.stray_projections.push((id, worst));
            }
        }
        match outcome {
            Ok(Converted::Face(out)) => {
                report.faces += 1;
                converted.insert(id, Shape::Surface(out.surface));
            }
            Ok(Converted::Surface(out)) => {
                report.surfaces += 1;
                converted.insert(id, Shape::Surface(out.surface));
            }
            Ok(Converted::Mesh(mesh)) => {
                report.tessellated += 1;
                report.triangles += mesh.indices.len();
                converted.insert(id, Shape::Triangles(mesh));
            }
            Err(why) => report.failed_faces.push((id, why)),
        }
    }
    report.failed_faces.sort_by_key(|(id, _)| *id);
    report.projected_edges = projected.len();
    report.far_edges = projected
        .into_iter()
        .map(|(edge, (face, gap))| (edge, face, gap * factor))
        .filter(|&(_, _, d)| d > report.edge_tolerance)
        .collect();
    report
        .far_edges
        .sort_by(|a, b| b.2.total_cmp(&a.2).then(a.0.cmp(&b.0)));
    report.stray_projections.sort_by_key(|(id, _)| *id);
    for (_, d) in &mut report.stray_projections {
        *d *= report.units.length.factor;
    }
    let mut model = CadModel::new(
        "STEP",
        "face",
        DeclaredUnit {
            name: report.units.length.name.clone(),
            millimetres: report.units.length.factor,
        },
    );
    // One part per representation, however many occurrences place it.
    let mut part_of: HashMap<u64, usize> = HashMap::new();
    let mut palette: Vec<Colour> = Vec::new();
    for (occ, faces) in occurrences.iter().zip(placed) {
        let part = *part_of.entry(occ.representation).or_insert_with(|| {
            model.parts.push(Part {
                name: format!("#{}", occ.representation),
                pieces: faces
                    .iter()
                    .filter_map(|(fid, colour)| {
                        let shape = converted.get(fid)?;
                        if let Some(c) = colour
                            && !palette.contains(c)
                        {
                            palette.push(*c);
                        }
                        Some(Piece {
                            shape: shape.clone(),
                            colour: colour.map(|c| c.0),
                        })
                    })
                    .collect(),
            });
            model.parts.len() - 1
        });
        model.occurrences.push(scene::Occurrence {
            part,
            transform: occ.transform,
        });
    }
    report.colours = palette.len();
    report.unsupported = unsupported;
    model.held = held(&ex, seen.len());
    model.warnings = ex.warnings.clone();
    if !report.stray_projections.is_empty() {
        let listed: Vec<String> = report
            .stray_projections
            .iter()
            .map(|(id, d)| format!("#{id} ({d:.3e} mm)"))
            .collect();
        model.warnings.push(format!(
            "{} face(s) trimmed by edges projected more than {:e} of the model's size from their surface: {}",
            listed.len(),
            topology::PCURVE_TOLERANCE,
            listed.join(" ")
        ));
    }
    model.notes = report.lines();
    model.skipped = report.unsupported.clone();
    model.failures = report
        .failed_faces
        .iter()
        .map(|(id, why)| Failure {
            // Leaves other than faces say what they are.
            entity: match ex.get(*id) {
                Some(i) if items::kind(i) != items::Kind::Face => {
                    format!("#{id} ({})", i.type_name())
                }
                _ => format!("#{id}"),
            },
            why: why.clone(),
        })
        .collect();
    Ok((model, report))
}

/// A leaf read: a face, a surface standing alone, or triangles.
enum Source {
    Face(entities::Face),
    Standalone(surfaces::Standalone),
    Mesh(TriangleMesh),
}

/// A leaf converted: a face's or a standalone surface's trimmed surface (with what its
/// conversion measured), or triangles.
enum Converted {
    Face(topology::FaceOutcome),
    Surface(topology::FaceOutcome),
    Mesh(TriangleMesh),
}

/// Converts one leaf; the error says why it could not be (the caller names it). `size`
/// is the model's size, which the tolerances are relative to.
fn convert(source: Source, size: f64) -> Result<Converted, String> {
    Ok(match source {
        Source::Face(f) => Converted::Face(topology::convert_face(&f, size)?),
        Source::Standalone(surfaces::Standalone::Face(f)) => {
            Converted::Surface(topology::convert_face(&f, size)?)
        }
        Source::Standalone(surfaces::Standalone::Patch(p)) => {
            Converted::Surface(topology::FaceOutcome {
                surface: surfaces::convert_patch(&p)?,
                trim_error: 0.0,
                edge_gaps: Vec::new(),
            })
        }
        Source::Mesh(m) if m.indices.is_empty() => return Err("it holds no triangle".into()),
        Source::Mesh(m) => Converted::Mesh(m),
    })
}

/// Why an entity could not be read, for the failure list: the error's line and column in
/// the file and its message (which names the malformed instance).
fn why(e: &ParseError) -> String {
    format!("{}:{}: {}", e.line, e.column, e.message)
}

/// The entities of leaf `id`, or `None` with the reason recorded in the report: a leaf
/// that is valid STEP but uses what the reader does not convert, or a malformed one (a
/// dangling reference, a zero direction, a parameter missing or of the wrong kind). As
/// with OpenCASCADE, one bad face costs that face, not the file.
fn resolve(
    res: &Resolver,
    id: u64,
    report: &mut Report,
    unsupported: &mut BTreeMap<String, usize>,
) -> Option<Source> {
    let inst = res.ex.get(id)?;
    res.take_unsupported();
    let read = match items::kind(inst) {
        items::Kind::Face => res.face(inst).map(Source::Face),
        items::Kind::Surface => surfaces::read(res, inst).map(Source::Standalone),
        items::Kind::Tessellated => tessellated::read(res, inst).map(Source::Mesh),
        _ => return None,
    };
    match read {
        Ok(s) => Some(s),
        Err(e) => {
            let reason = match res.take_unsupported() {
                Some(kind) => {
                    let reason = format!("uses {kind}, which is not supported");
                    *unsupported.entry(kind).or_default() += 1;
                    reason
                }
                None => why(&e),
            };
            report.failed_faces.push((id, reason));
            None
        }
    }
}
