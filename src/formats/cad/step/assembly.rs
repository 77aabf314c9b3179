//! Product structure (AP214/AP242 assemblies, ISO 10303-44 §4.?): which shape
//! representations hold geometry, and where each component sits. A component's
//! representation is tied to its assembly's by a REPRESENTATION_RELATIONSHIP_WITH_
//! TRANSFORMATION whose ITEM_DEFINED_TRANSFORMATION maps placement `item_1` (in the
//! component, `rep_1`) onto `item_2` (in the assembly, `rep_2`); the
//! CONTEXT_DEPENDENT_SHAPE_REPRESENTATION naming the NEXT_ASSEMBLY_USAGE_OCCURRENCE ties it
//! to the product tree but adds no geometry. Plain SHAPE_REPRESENTATION_RELATIONSHIPs join a
//! part's representations (its placements and its B-rep).
//!
//! The scene model has no instances yet, so every occurrence is flattened into a
//! transformed copy of the component's geometry; the reader says how many.

use std::collections::HashMap;

use glam::DAffine3;

use super::entities::{Rec, Resolver};
use super::records::Value;
use crate::formats::error::ParseError;

/// Deepest assembly nesting followed; deeper (or cyclic) structure is refused.
const MAX_NESTING: usize = 32;
/// Most occurrences flattened: nesting multiplies them, and a file of a few kilobytes can
/// otherwise ask for billions of copies.
const MAX_OCCURRENCES: usize = 100_000;

/// One placed copy of a representation's geometry items.
#[derive(Clone, Debug)]
pub struct Occurrence {
    /// The representation whose items are placed.
    pub representation: u64,
    /// Its items that hold geometry (solids, shells, faces, surface models).
    pub items: Vec<u64>,
    /// Component coordinates to world coordinates, in the component's own length unit.
    pub transform: DAffine3,
    /// The context holding the representation's units.
    pub context: Option<u64>,
}

/// Geometry items the reader converts.
pub const GEOMETRY_ITEMS: [&str; 7] = [
    "MANIFOLD_SOLID_BREP",
    "BREP_WITH_VOIDS",
    "SHELL_BASED_SURFACE_MODEL",
    "CLOSED_SHELL",
    "OPEN_SHELL",
    "ADVANCED_FACE",
    "FACE_SURFACE",
];

/// Items that carry no geometry of their own (placements, presentation).
const NON_GEOMETRY_ITEMS: [&str; 4] = [
    "AXIS2_PLACEMENT_3D",
    "STYLED_ITEM",
    "CARTESIAN_POINT",
    "DIRECTION",
];

struct Link {
    child: u64,
    parent: u64,
    transform: Option<DAffine3>,
}

/// All occurrences of geometry in the file, and the item types left unread (counted by
/// type). Errors are located at the relationship or transformation at fault.
pub fn occurrences(
    res: &Resolver,
    unsupported: &mut std::collections::BTreeMap<String, usize>,
) -> Result<Vec<Occurrence>, ParseError> {
    // Representations with their items and contexts.
    let mut reps: HashMap<u64, (Vec<u64>, Option<u64>)> = HashMap::new();
    for inst in &res.ex.instances {
        let Some(r) = inst
            .records
            .iter()
            .find(|r| r.name.ends_with("SHAPE_REPRESENTATION") && r.params.len() >= 3)
        else {
            continue;
        };
        let rec = Rec {
            path: res.path,
            inst,
            rec: r,
        };
        let mut items = Vec::new();
        for id in rec.references(1, "representation items")? {
            let Some(item) = res.ex.get(id) else {
                return Err(rec.error(format!(
                    "references #{id}, which is not defined in the file"
                )));
            };
            let name = item.records[0].name;
            if GEOMETRY_ITEMS.contains(&name) {
                items.push(id);
            } else if !NON_GEOMETRY_ITEMS.contains(&name) {
                *unsupported
                    .entry(item.type_name().into_owned())
                    .or_default() += 1;
            }
        }
        let context = match r.params[2].value {
            Value::Ref(c) => Some(c),
            _ => None,
        };
        reps.insert(inst.id, (items, context));
    }
    // Links between representations.
    let mut links = Vec::new();
    for inst in &res.ex.instances {
        let Some(r) = inst
            .record("REPRESENTATION_RELATIONSHIP")
            .or(inst.record("SHAPE_REPRESENTATION_RELATIONSHIP"))
        else {
            continue;
        };
        if r.params.len() < 4 {
            continue;
        }
        let rec = Rec {
            path: res.path,
            inst,
            rec: r,
        };
        let child = rec.reference(2, "rep_1")?;
        let parent = rec.reference(3, "rep_2")?;
        let transform = match inst.record("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
            Some(t) => {
                let trec = Rec {
                    path: res.path,
                    inst,
                    rec: t,
                };
                let idt_id = trec.reference(0, "an ITEM_DEFINED_TRANSFORMATION")?;
                let idt = res.instance(&trec, idt_id)?;
                let Some(ir) = res.named(idt, "ITEM_DEFINED_TRANSFORMATION") else {
                    *unsupported.entry(idt.type_name().into_owned()).or_default() += 1;
                    continue;
                };
                let from = res.frame(&ir, 2)?.to_affine();
                let to = res.frame(&ir, 3)?.to_affine();
                Some(to * from.inverse())
            }
            None => None,
        };
        links.push(Link {
            child,
            parent,
            transform,
        });
    }
    // Representations joined without a transformation are one part.
    let mut part: HashMap<u64, u64> = reps.keys().map(|&k| (k, k)).collect();
    fn find(part: &mut HashMap<u64, u64>, mut k: u64) -> u64 {
        while let Some(&p) = part.get(&k) {
            if p == k {
                break;
            }
            k = p;
        }
        k
    }
    for l in links.iter().filter(|l| l.transform.is_none()) {
        let (a, b) = (find(&mut part, l.child), find(&mut part, l.parent));
        if a != b && part.contains_key(&a) && part.contains_key(&b) {
            part.insert(a, b);
        }
    }
    let mut members: HashMap<u64, Vec<u64>> = HashMap::new();
    let mut ids: Vec<u64> = reps.keys().copied().collect();
    ids.sort_unstable();
    for id in ids {
        let root = find(&mut part, id);
        members.entry(root).or_default().push(id);
    }
    let mut children: HashMap<u64, Vec<(u64, DAffine3)>> = HashMap::new();
    let mut is_child: std::collections::HashSet<u64> = Default::default();
    for l in &links {
        if let Some(t) = l.transform {
            let (c, p) = (find(&mut part, l.child), find(&mut part, l.parent));
            children.entry(p).or_default().push((c, t));
            is_child.insert(c);
        }
    }
    let mut roots: Vec<u64> = members
        .keys()
        .copied()
        .filter(|k| !is_child.contains(k))
        .collect();
    roots.sort_unstable();
    let mut out = Vec::new();
    let mut stack: Vec<(u64, DAffine3, usize)> = roots
        .into_iter()
        .rev()
        .map(|r| (r, DAffine3::IDENTITY, 0))
        .collect();
    while let Some((p, t, depth)) = stack.pop() {
        if depth > MAX_NESTING {
            return Err(ParseError::new(
                res.path,
                1,
                1,
                format!(
                    "assembly structure nests deeper than {MAX_NESTING} (a cycle through #{p}?)"
                ),
            ));
        }
        if out.len() > MAX_OCCURRENCES {
            return Err(ParseError::new(
                res.path,
                1,
                1,
                format!("the assembly flattens into more than {MAX_OCCURRENCES} occurrences"),
            ));
        }
        // A link may name a product with no shape (a mutated or partial file): it then
        // places nothing.
        for rep in members.get(&p).into_iter().flatten() {
            let Some((items, context)) = reps.get(rep) else {
                continue;
            };
            if !items.is_empty() {
                out.push(Occurrence {
                    representation: *rep,
                    items: items.clone(),
                    transform: t,
                    context: *context,
                });
            }
        }
        for (c, ct) in children.get(&p).into_iter().flatten().rev() {
            stack.push((*c, t * *ct, depth + 1));
        }
    }
    Ok(out)
}
