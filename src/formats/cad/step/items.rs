//! What each representation item is to the reader (ISO 10303-42 §5.4 topology, §4.4
//! geometry, the tessellated items of ISO 10303-42 §7): containers that hold other items
//! (solids, shells, surface models, geometric sets), the leaves that are rendered (faces,
//! surfaces standing alone, triangulated items), and wireframe that is not.
//!
//! A shape representation's items are walked down to their leaves, each leaf keeping the
//! colour of the nearest styled item above it, as OpenCASCADE's StepToTopoDS_Builder walks
//! shells, GEOMETRIC_SETs and tessellated solids.

use std::collections::{BTreeMap, HashMap};

use super::entities::Resolver;
use super::records::Instance;
use super::style::Colour;
use crate::formats::error::ParseError;

/// Deepest nesting of containers followed (a solid's void shell's oriented shell is three).
const MAX_NESTING: usize = 8;

/// Surfaces that can stand alone in a set or a surface model (ISO 10303-42 §4.4: the
/// elementary, swept, B-spline, offset and bounded surfaces). A complex B-spline instance
/// carries a `SURFACE` record of its own.
const SURFACES: [&str; 17] = [
    "SURFACE",
    "PLANE",
    "CYLINDRICAL_SURFACE",
    "CONICAL_SURFACE",
    "SPHERICAL_SURFACE",
    "TOROIDAL_SURFACE",
    "DEGENERATE_TOROIDAL_SURFACE",
    "SURFACE_OF_REVOLUTION",
    "SURFACE_OF_LINEAR_EXTRUSION",
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "BEZIER_SURFACE",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_SURFACE",
    "OFFSET_SURFACE",
    "CURVE_BOUNDED_SURFACE",
    "RECTANGULAR_TRIMMED_SURFACE",
    "RECTANGULAR_COMPOSITE_SURFACE",
];

/// The tessellated items read as triangles (ISO 10303-42 §7: tessellated_solid,
/// tessellated_shell, triangulated_face, complex_triangulated_face and the surface sets).
pub const TESSELLATED: [&str; 6] = [
    "TESSELLATED_SOLID",
    "TESSELLATED_SHELL",
    "TRIANGULATED_FACE",
    "COMPLEX_TRIANGULATED_FACE",
    "TRIANGULATED_SURFACE_SET",
    "COMPLEX_TRIANGULATED_SURFACE_SET",
];

/// What an item is to the reader.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Holds other items: its references at parameter `list` (a list) or `single`.
    Container {
        single: Option<usize>,
        list: Option<usize>,
    },
    /// ADVANCED_FACE or FACE_SURFACE.
    Face,
    /// A surface outside any face.
    Surface,
    /// Triangles.
    Tessellated,
    /// Anything else (points and curves in a set, presentation, what the reader does not
    /// know).
    Other,
}

/// The kind of `inst`.
pub fn kind(inst: &Instance) -> Kind {
    let list = |i| Kind::Container {
        single: None,
        list: Some(i),
    };
    let single = |i| Kind::Container {
        single: Some(i),
        list: None,
    };
    match inst.records[0].name {
        "ADVANCED_FACE" | "FACE_SURFACE" => return Kind::Face,
        "MANIFOLD_SOLID_BREP" => return single(1),
        // ISO 10303-42 §5.4.?: brep_with_voids(outer, voids), the voids ORIENTED_CLOSED_SHELLs.
        "BREP_WITH_VOIDS" => {
            return Kind::Container {
                single: Some(1),
                list: Some(2),
            };
        }
        "CLOSED_SHELL" | "OPEN_SHELL" | "CONNECTED_FACE_SET" => return list(1),
        // oriented_closed_shell / oriented_open_shell / oriented_face (name, the derived
        // list, element, orientation): the element's faces, whichever side is outward.
        "ORIENTED_CLOSED_SHELL" | "ORIENTED_OPEN_SHELL" | "ORIENTED_FACE" => return single(2),
        "SHELL_BASED_SURFACE_MODEL" | "FACE_BASED_SURFACE_MODEL" => return list(1),
        "GEOMETRIC_SET" | "GEOMETRIC_CURVE_SET" => return list(1),
        _ => {}
    }
    if TESSELLATED.iter().any(|t| inst.record(t).is_some()) {
        Kind::Tessellated
    } else if inst.records.iter().any(|r| SURFACES.contains(&r.name)) {
        Kind::Surface
    } else {
        Kind::Other
    }
}

/// Whether a representation item holds anything the reader renders or walks into.
pub fn is_geometry(inst: &Instance) -> bool {
    kind(inst) != Kind::Other
}

/// A leaf found under an item: its id and the colour it inherits.
pub type Leaf = (u64, Option<Colour>);

/// Collects the leaves (faces, standalone surfaces, tessellated items) under item `id`,
/// each with its own colour or the nearest styled container's. Points and curves inside
/// geometric sets are counted in `skipped` by type: they have no area to render.
pub fn leaves(
    res: &Resolver,
    id: u64,
    colours: &HashMap<u64, Colour>,
    skipped: &mut BTreeMap<String, usize>,
    out: &mut Vec<Leaf>,
) -> Result<(), ParseError> {
    walk(res, id, colours, None, skipped, out, 0)
}

fn walk(
    res: &Resolver,
    id: u64,
    colours: &HashMap<u64, Colour>,
    inherited: Option<Colour>,
    skipped: &mut BTreeMap<String, usize>,
    out: &mut Vec<Leaf>,
    depth: usize,
) -> Result<(), ParseError> {
    let Some(inst) = res.ex.get(id) else {
        return Ok(());
    };
    let colour = colours.get(&id).copied().or(inherited);
    let (single, list) = match kind(inst) {
        Kind::Face | Kind::Surface | Kind::Tessellated => {
            out.push((id, colour));
            return Ok(());
        }
        Kind::Other => {
            // Only inside a container: a representation's own non-geometry items are
            // counted where the representation is read (`assembly`).
            if depth > 0 {
                *skipped.entry(inst.type_name().into_owned()).or_default() += 1;
            }
            return Ok(());
        }
        Kind::Container { single, list } => (single, list),
    };
    let r = res.rec(inst);
    if depth > MAX_NESTING {
        return Err(r.error("items nest too deep (a reference cycle?)"));
    }
    let mut children = Vec::new();
    if let Some(i) = single {
        children.push(r.reference(i, "a shell or face")?);
    }
    if let Some(i) = list {
        children.extend(r.references(i, "items")?);
    }
    for c in children {
        walk(res, c, colours, colour, skipped, out, depth + 1)?;
    }
    Ok(())
}
