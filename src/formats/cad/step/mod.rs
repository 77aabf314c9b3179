//! STEP (ISO 10303-21 exchange structure, AP203/AP214/AP242 B-rep models), layered like
//! OpenCASCADE's reader (StepData / StepGeom / StepToGeom):
//!
//! - `lexer`, `records`: Part 21 syntax, every token with its line and column.
//! - `entities`: typed, validated ISO 10303-42 geometry and topology.
//! - `geometry`: curves and surfaces evaluated by their definitions, converted to exact
//!   rational NURBS through the shared `geom::nurbs::analytic`.
//! - `topology`: faces and their bounds to trim loops in each surface's parameter domain.
//! - `assembly`, `units`, `style`: placements of parts, length units, colours.
//!
//! Malformed files (syntax, wrong parameter kinds, dangling references) are errors located
//! at `file.step:LINE:COL: #id ENTITY: …`. Entities that are valid but that the reader does
//! not convert are counted by type, and faces that cannot be converted are named by `#id`,
//! in the [`Report`] that `info` prints and in one warning line on stderr.

pub mod assembly;
pub mod entities;
pub mod geometry;
pub mod lexer;
pub mod records;
pub mod style;
pub mod topology;
pub mod units;

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DVec3};
use rayon::prelude::*;

use self::entities::Resolver;
use self::style::Colour;
use self::units::Units;
use crate::formats::error::{LoadError, ParseError};
use crate::scene::model::{Geometry, Instance, Material, Object, Surface};

/// What reading a STEP file found beyond the geometry.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub schemas: Vec<String>,
    pub units: Units,
    pub faces: usize,
    /// Faces that could not be converted: `(#id, why)`.
    pub failed_faces: Vec<(u64, String)>,
    /// Entities left unread, by type.
    pub unsupported: BTreeMap<String, usize>,
    /// Edges projected into their face's domain (no usable pcurve) and the largest
    /// distance between such an edge and its trim, in millimetres.
    pub projected_edges: usize,
    pub max_projection_error: f64,
    /// Shape occurrences flattened into transformed copies (the scene model has no
    /// instances yet); 1 for a single part.
    pub occurrences: usize,
    pub colours: usize,
}

impl Report {
    /// One line per fact, for `info`.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![
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
                "faces: {} converted, {} failed; {} shape occurrence(s){}; {} colour(s)",
                self.faces,
                self.failed_faces.len(),
                self.occurrences,
                if self.occurrences > 1 {
                    " flattened into transformed copies"
                } else {
                    ""
                },
                self.colours
            ),
            format!(
                "projected edges: {}, largest projection error {:.3e} mm",
                self.projected_edges, self.max_projection_error
            ),
        ];
        if !self.unsupported.is_empty() {
            out.push(format!("unsupported entities: {}", self.unsupported_list()));
        }
        for (id, why) in &self.failed_faces {
            out.push(format!("face #{id} not converted: {why}"));
        }
        out
    }

    fn unsupported_list(&self) -> String {
        self.unsupported
            .iter()
            .map(|(t, n)| format!("{t} x{n}"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The one warning line for stderr, if anything was left out.
    pub fn warning(&self, path: &Path) -> Option<String> {
        if self.unsupported.is_empty() && self.failed_faces.is_empty() {
            return None;
        }
        let mut parts = Vec::new();
        if !self.failed_faces.is_empty() {
            let ids: Vec<String> = self
                .failed_faces
                .iter()
                .map(|(id, _)| format!("#{id}"))
                .collect();
            parts.push(format!(
                "{} face(s) not converted ({})",
                ids.len(),
                ids.join(" ")
            ));
        }
        if !self.unsupported.is_empty() {
            parts.push(format!("unsupported entities: {}", self.unsupported_list()));
        }
        Some(format!("warning: {}: {}", path.display(), parts.join("; ")))
    }
}

/// A STEP file read: objects (one per shape occurrence and colour), their materials
/// (index 0 is the default), and the report.
pub struct StepModel {
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub report: Report,
}

fn located(path: &Path, e: lexer::LexError) -> ParseError {
    ParseError::new(path, e.line as usize, e.column as usize, e.message)
}

/// The faces of a geometry item with the colour each inherits (its own, else the
/// nearest styled container's).
fn item_faces(
    res: &Resolver,
    id: u64,
    colours: &HashMap<u64, Colour>,
    inherited: Option<Colour>,
    out: &mut Vec<(u64, Option<Colour>)>,
    depth: usize,
) -> Result<(), ParseError> {
    let Some(inst) = res.ex.get(id) else {
        return Ok(());
    };
    let colour = colours.get(&id).copied().or(inherited);
    let r = res.rec(inst);
    let children: Vec<u64> = match r.rec.name {
        "ADVANCED_FACE" | "FACE_SURFACE" => {
            out.push((id, colour));
            return Ok(());
        }
        "MANIFOLD_SOLID_BREP" => vec![r.reference(1, "the outer CLOSED_SHELL")?],
        "BREP_WITH_VOIDS" => {
            let mut v = vec![r.reference(1, "the outer CLOSED_SHELL")?];
            v.extend(r.references(2, "void shells")?);
            v
        }
        "CLOSED_SHELL" | "OPEN_SHELL" => r.references(1, "faces")?,
        "SHELL_BASED_SURFACE_MODEL" => r.references(1, "shells")?,
        _ => return Ok(()),
    };
    if depth > 8 {
        return Err(r.error("shells nest too deep (a reference cycle?)"));
    }
    for c in children {
        item_faces(res, c, colours, colour, out, depth + 1)?;
    }
    Ok(())
}

/// Reads a STEP file into objects, materials and a report.
pub fn read_step(path: &Path) -> Result<StepModel, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    // Part 21 text is ISO 8859-1 outside strings' escapes; bytes above 127 (seen in
    // comments and names) are taken as Latin-1 rather than refused.
    let src = match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    };
    Ok(read_step_str(path, &src)?)
}

/// [`read_step`] on text already in memory; `path` names the file in errors.
pub fn read_step_str(path: &Path, src: &str) -> Result<StepModel, ParseError> {
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
    let scale = DAffine3::from_scale(DVec3::splat(report.units.length.factor));
    // The model's size, for tolerances: the bounding box of every Cartesian point.
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
    let size = if lo.x <= hi.x {
        (hi - lo).length().max(f64::MIN_POSITIVE)
    } else {
        1.0
    };
    // Faces resolved once, in file order (the resolver's caches are not shared), then
    // converted on every core (each face on its own), then placed per occurrence.
    let mut placed: Vec<Vec<(u64, Option<Colour>)>> = Vec::with_capacity(occurrences.len());
    let mut resolved: Vec<(u64, entities::Face)> = Vec::new();
    let mut seen: HashSet<u64> = HashSet::new();
    for occ in &occurrences {
        let mut faces = Vec::new();
        for &item in &occ.items {
            item_faces(&res, item, &colours, None, &mut faces, 0)?;
        }
        for &(fid, _) in &faces {
            if seen.insert(fid)
                && let Some(face) = resolve_face(&res, fid, &mut report, &mut unsupported)?
            {
                resolved.push((fid, face));
            }
        }
        placed.push(faces);
    }
    // Tolerances follow the faces' own extent where they have edges: files hold points
    // far from their faces (CATIA's k1 key: a wireframe kilometres wide).
    let size = topology::faces_extent(resolved.iter().map(|(_, f)| f)).unwrap_or(size);
    let outcomes: Vec<(u64, Result<topology::FaceOutcome, String>)> = resolved
        .par_iter()
        .map(|(fid, face)| (*fid, topology::convert_face(face, size)))
        .collect();
    let mut converted: HashMap<u64, Surface> = HashMap::new();
    for (fid, outcome) in outcomes {
        match outcome {
            Ok(out) => {
                report.projected_edges += out.projected_edges;
                report.max_projection_error = report.max_projection_error.max(out.projection_error);
                converted.insert(fid, out.surface);
            }
            Err(why) => report.failed_faces.push((fid, why)),
        }
    }
    let mut palette: Vec<Colour> = Vec::new();
    // Per occurrence and material, the surfaces in their representation's own frame.
    let mut groups: BTreeMap<(usize, usize), Vec<Surface>> = BTreeMap::new();
    for (k, faces) in placed.into_iter().enumerate() {
        for (fid, colour) in faces {
            let Some(surface) = converted.get(&fid) else {
                continue;
            };
            let material = match colour {
                Some(c) => {
                    1 + palette.iter().position(|p| *p == c).unwrap_or_else(|| {
                        palette.push(c);
                        palette.len() - 1
                    })
                }
                None => 0,
            };
            groups
                .entry((k, material))
                .or_default()
                .push(surface.clone());
        }
    }
    let geometries = placed_geometries(&occurrences, groups, scale);
    report.faces = converted.len();
    report.failed_faces.sort_by_key(|(id, _)| *id);
    report.max_projection_error *= report.units.length.factor;
    report.unsupported = unsupported;
    report.colours = palette.len();
    let mut materials = vec![Material::default_named("default")];
    for c in &palette {
        let mut m =
            Material::default_named(&format!("rgb({:.3},{:.3},{:.3})", c.0.x, c.0.y, c.0.z));
        m.diffuse = c.0;
        materials.push(m);
    }
    let stem = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let objects = geometries
        .into_iter()
        .map(|((k, material), geometry)| {
            let occ = &occurrences[k];
            Object {
                name: if occurrences.len() > 1 || material > 0 {
                    format!(
                        "{stem} #{} occurrence {} {}",
                        occ.representation,
                        k + 1,
                        materials[material].name
                    )
                } else {
                    stem.clone()
                },
                material,
                geometry,
            }
        })
        .collect();
    Ok(StepModel {
        objects,
        materials,
        report,
    })
}

/// Each occurrence's surfaces placed in the model by `scale` after the occurrence's
/// transform. A part that occurs once is a placed copy; the occurrences of a part used more
/// than once are instances of one geometry in the part's frame (Dammertz §3.3), so it is
/// prepared, and its BVH built, once however often the assembly uses it.
fn placed_geometries(
    occurrences: &[assembly::Occurrence],
    groups: BTreeMap<(usize, usize), Vec<Surface>>,
    scale: DAffine3,
) -> BTreeMap<(usize, usize), Geometry> {
    let mut uses: HashMap<u64, usize> = HashMap::new();
    for occ in occurrences {
        *uses.entry(occ.representation).or_default() += 1;
    }
    let mut shared: HashMap<(u64, usize), Arc<Geometry>> = HashMap::new();
    groups
        .into_iter()
        .map(|((k, material), surfaces)| {
            let occ = &occurrences[k];
            let placement = scale * occ.transform;
            let geometry = if uses[&occ.representation] > 1 {
                let part = shared
                    .entry((occ.representation, material))
                    .or_insert_with(|| Arc::new(Geometry::Surfaces(surfaces)));
                Geometry::Instance(Instance::new(part.clone(), placement))
            } else {
                let mut g = Geometry::Surfaces(surfaces);
                g.transform(&placement);
                g
            };
            ((k, material), geometry)
        })
        .collect()
}

/// The entities of face `fid`; a face that is valid STEP but uses what the reader does not
/// convert is recorded in the report and gives `None`, a malformed one is an error.
fn resolve_face(
    res: &Resolver,
    fid: u64,
    report: &mut Report,
    unsupported: &mut BTreeMap<String, usize>,
) -> Result<Option<entities::Face>, ParseError> {
    let Some(inst) = res.ex.get(fid) else {
        return Ok(None);
    };
    res.take_unsupported();
    match res.face(inst) {
        Ok(f) => Ok(Some(f)),
        Err(e) => match res.take_unsupported() {
            Some(kind) => {
                *unsupported.entry(kind.clone()).or_default() += 1;
                report
                    .failed_faces
                    .push((fid, format!("uses {kind}, which is not supported")));
                Ok(None)
            }
            None => Err(e),
        },
    }
}

/// The surfaces of a STEP file as one geometry (for a scene's `File("part.step")`).
pub fn load_geometry(path: &Path) -> Result<Geometry, LoadError> {
    let model = read_step(path)?;
    if let Some(w) = model.report.warning(path) {
        eprintln!("{w}");
    }
    let surfaces = model
        .objects
        .into_iter()
        .flat_map(|o| match o.geometry.resolved().into_owned() {
            Geometry::Surfaces(s) => s,
            _ => Vec::new(),
        })
        .collect();
    Ok(Geometry::Surfaces(surfaces))
}
