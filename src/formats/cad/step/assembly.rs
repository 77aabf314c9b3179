//! Product structure (AP214/AP242 assemblies, ISO 10303-44 §4.?): which shape
//! representations hold geometry, and where each component sits.
//!
//! A component's representation is tied to its assembly's by a REPRESENTATION_RELATIONSHIP_
//! WITH_TRANSFORMATION whose ITEM_DEFINED_TRANSFORMATION places `transform_item_1` (an item
//! of `rep_1`) onto `transform_item_2` (an item of `rep_2`) (ISO 10303-43 §4.4.?): the map
//! from `rep_1`'s coordinates to `rep_2`'s is frame(item_2) · frame(item_1)⁻¹. Which side is
//! the component is not fixed by the relationship: the CONTEXT_DEPENDENT_SHAPE_REPRESENTATION
//! naming it names the NEXT_ASSEMBLY_USAGE_OCCURRENCE (through its PRODUCT_DEFINITION_SHAPE),
//! whose `related_product_definition` is the component; its SHAPE_DEFINITION_REPRESENTATION
//! gives the component's representation. Most writers put the component in `rep_1`;
//! SolidWorks puts the assembly there, and the map is then taken the other way (as
//! OpenCASCADE's `STEPConstruct_Assembly::CheckSRRReversesNAUO` does).
//!
//! A MAPPED_ITEM places its REPRESENTATION_MAP's `mapped_representation` so that the map's
//! `mapping_origin` lands on the item's `mapping_target` (ISO 10303-43 §4.4.?): a child
//! placed by frame(target) · frame(origin)⁻¹ in the representation holding the item.
//! Plain SHAPE_REPRESENTATION_RELATIONSHIPs join a part's representations (its placements
//! and its B-rep) into one part.

use std::collections::{HashMap, HashSet};

use glam::DAffine3;

use super::entities::{Rec, Resolver};
use super::items;
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

/// Items that carry no geometry of their own (placements, presentation), or that place
/// another representation (MAPPED_ITEM, followed as a link).
const NON_GEOMETRY_ITEMS: [&str; 5] = [
    "MAPPED_ITEM",
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
    // The representation holding each item (for MAPPED_ITEMs).
    let mut item_owner: HashMap<u64, u64> = HashMap::new();
    for inst in &res.ex.instances {
        let Some(r) = inst.shape_representation() else {
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
            item_owner.entry(id).or_insert(inst.id);
            let name = item.records[0].name;
            if items::is_geometry(item) {
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
    let components = Components::of(res);
    // Links between representations.
    let mut links = Vec::new();
    // A shape aspect's representation draws only what its product's own representations do
    // not already hold (OpenCASCADE's STEPControl_ActorRead: an aspect whose items are
    // already translated names a portion of the shape, e.g. the solid for validation
    // properties or a datum's face; otherwise it is an AP203 hybrid model's geometry, part
    // of the product). Drawing it as a root of its own would repeat the solid at the origin
    // of the assembly, wherever the product is placed.
    let held = held_by(res, &reps, &components.aspects);
    for (&rep, &pd) in &components.aspects {
        if let Some((items, _)) = reps.get_mut(&rep) {
            items.retain(|i| !held.contains(i));
        }
        if let Some(&main) = components.reps.get(&pd).and_then(|r| r.first()) {
            links.push(Link {
                child: rep,
                parent: main,
                transform: None,
            });
        }
    }
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
        let rep_1 = rec.reference(2, "rep_1")?;
        let rep_2 = rec.reference(3, "rep_2")?;
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
                let item_1 = res.frame(&ir, 2)?.to_affine();
                let item_2 = res.frame(&ir, 3)?.to_affine();
                let ids = (
                    ir.reference(2, "transform_item_1")?,
                    ir.reference(3, "transform_item_2")?,
                );
                Some((item_2 * item_1.inverse(), ids))
            }
            None => None,
        };
        // The component is rep_1 as written, rep_2 when the NAUO says so. The placement
        // takes the component's frame item onto the assembly's: item_2 · item_1⁻¹ when
        // item_1 is the component's (the usual writing), its inverse when the file puts
        // item_1 in the assembly (CATIA V4 writes the assembly as rep_1 and item_1 in the
        // component, which the order of the reps alone would read mirrored). Where
        // neither item is listed by either representation, the order of the reps decides.
        let (child, parent) = if components.reversed(inst.id, rep_1, rep_2) {
            (rep_2, rep_1)
        } else {
            (rep_1, rep_2)
        };
        let transform = transform.map(|(t, (id_1, id_2))| {
            let lists = |rep: u64, item: u64| lists_item(res, rep, item);
            let forward = if lists(child, id_1) || lists(parent, id_2) {
                true
            } else if lists(child, id_2) || lists(parent, id_1) {
                false
            } else {
                child == rep_1
            };
            if forward { t } else { t.inverse() }
        });
        links.push(Link {
            child,
            parent,
            transform,
        });
    }
    for inst in &res.ex.instances {
        let Some(r) = res.named(inst, "MAPPED_ITEM") else {
            continue;
        };
        let Some(&parent) = item_owner.get(&inst.id) else {
            continue;
        };
        let map = res.instance(&r, r.reference(1, "a REPRESENTATION_MAP")?)?;
        let m = res.rec(map);
        let origin = res.frame(&m, 0)?.to_affine();
        let child = m.reference(1, "the mapped representation")?;
        let target = res.frame(&r, 2)?.to_affine();
        links.push(Link {
            child,
            parent,
            transform: Some(target * origin.inverse()),
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
    let mut is_child: HashSet<u64> = HashSet::new();
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

/// Topological items that a representation outside `aspects` holds, directly or inside a
/// solid or shell it holds (ISO 10303-42 §5.4: a solid's shells, a shell's faces), and the
/// elements of the geometric sets it holds.
fn held_by(
    res: &Resolver,
    reps: &HashMap<u64, (Vec<u64>, Option<u64>)>,
    aspects: &HashMap<u64, u64>,
) -> HashSet<u64> {
    let mut held = HashSet::new();
    let mut stack: Vec<u64> = reps
        .iter()
        .filter(|(rep, _)| !aspects.contains_key(rep))
        .flat_map(|(_, (items, _))| items.iter().copied())
        .collect();
    while let Some(id) = stack.pop() {
        let Some(inst) = res.ex.get(id) else {
            continue;
        };
        let name = &inst.records[0].name;
        if SETS.contains(name) && held.insert(id) {
            // A geometric_set (ISO 10303-42)'s elements (bare surfaces, curves) are held as
            // they are; nothing below them is shared with an aspect.
            let mut elements = Vec::new();
            for r in &inst.records {
                push_references(&r.params, &mut elements);
            }
            held.extend(elements);
            continue;
        }
        if !TOPOLOGY.contains(name) || !held.insert(id) {
            continue;
        }
        for r in &inst.records {
            push_references(&r.params, &mut stack);
        }
    }
    held
}

/// Geometric sets, whose elements a shape aspect may name again (AutoCAD writes each
/// surface of a set as an aspect's representation too).
const SETS: [&str; 2] = ["GEOMETRIC_SET", "GEOMETRIC_CURVE_SET"];

/// The entities a solid or shell is made of, down to its faces.
const TOPOLOGY: [&str; 10] = [
    "MANIFOLD_SOLID_BREP",
    "BREP_WITH_VOIDS",
    "SHELL_BASED_SURFACE_MODEL",
    "CLOSED_SHELL",
    "OPEN_SHELL",
    "ORIENTED_CLOSED_SHELL",
    "ORIENTED_OPEN_SHELL",
    "CONNECTED_FACE_SET",
    "ADVANCED_FACE",
    "FACE_SURFACE",
];

/// Whether the representation `rep` lists `item` among its items.
fn lists_item(res: &Resolver, rep: u64, item: u64) -> bool {
    res.ex.get(rep).is_some_and(|i| {
        i.records
            .iter()
            .filter(|r| r.name.ends_with("REPRESENTATION"))
            .any(|r| match r.params.get(1).map(|p| &p.value) {
                Some(Value::List(items)) => items.iter().any(|p| p.value == Value::Ref(item)),
                _ => false,
            })
    })
}

fn push_references(params: &[crate::formats::cad::step::records::Param], out: &mut Vec<u64>) {
    for p in params {
        match &p.value {
            Value::Ref(id) => out.push(*id),
            Value::List(items) => push_references(items, out),
            _ => {}
        }
    }
}

/// Which representations belong to the component of each assembly relationship: the
/// relationship's CONTEXT_DEPENDENT_SHAPE_REPRESENTATION → PRODUCT_DEFINITION_SHAPE →
/// NEXT_ASSEMBLY_USAGE_OCCURRENCE (relating: the assembly, related: the component), and
/// each product definition's representations by SHAPE_DEFINITION_REPRESENTATION.
struct Components {
    /// Relationship id → (assembly, component) product definitions.
    usage: HashMap<u64, (u64, u64)>,
    /// Product definition → its shape representations.
    reps: HashMap<u64, Vec<u64>>,
    /// Representation of a shape aspect (ISO 10303-41: a portion of a product's shape, by
    /// SHAPE_DEFINITION_REPRESENTATION of a PROPERTY_DEFINITION of the aspect) → the product
    /// definition whose shape it belongs to.
    aspects: HashMap<u64, u64>,
}

impl Components {
    fn of(res: &Resolver) -> Components {
        let ex = res.ex;
        let refs = |inst: &crate::formats::cad::step::records::Instance, name: &str| {
            let r = inst.record(name)?;
            let ids: Vec<Option<u64>> = r
                .params
                .iter()
                .map(|p| match p.value {
                    Value::Ref(id) => Some(id),
                    _ => None,
                })
                .collect();
            Some(ids)
        };
        // PRODUCT_DEFINITION_SHAPE → what it defines (a product definition or a NAUO).
        let mut defines: HashMap<u64, u64> = HashMap::new();
        let mut usage = HashMap::new();
        let mut reps: HashMap<u64, Vec<u64>> = HashMap::new();
        for inst in &ex.instances {
            if let Some(p) = refs(inst, "PRODUCT_DEFINITION_SHAPE")
                && let Some(Some(d)) = p.get(2)
            {
                defines.insert(inst.id, *d);
            }
        }
        let mut aspects = HashMap::new();
        // A shape aspect (any subtype: SHAPE_ASPECT, DATUM_FEATURE, …) names its product
        // definition shape as its third attribute, `of_shape`.
        let aspect_of = |property: u64| {
            let p = ex.get(property)?.record("PROPERTY_DEFINITION")?;
            let Some(Value::Ref(aspect)) = p.params.get(2).map(|q| &q.value) else {
                return None;
            };
            let a = ex.get(*aspect)?;
            a.records.iter().find_map(|r| match r.params.get(2)?.value {
                Value::Ref(pds) => defines.get(&pds).copied(),
                _ => None,
            })
        };
        for inst in &ex.instances {
            if let Some(p) = refs(inst, "SHAPE_DEFINITION_REPRESENTATION")
                && let (Some(Some(def)), Some(Some(rep))) = (p.first(), p.get(1))
            {
                if let Some(&pd) = defines.get(def) {
                    reps.entry(pd).or_default().push(*rep);
                } else if let Some(pd) = aspect_of(*def) {
                    aspects.insert(*rep, pd);
                }
            }
            if let Some(p) = refs(inst, "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION")
                && let (Some(Some(rel)), Some(Some(pds))) = (p.first(), p.get(1))
                && let Some(nauo) = defines.get(pds).and_then(|&n| ex.get(n))
                && let Some(n) = nauo
                    .records
                    .iter()
                    .find(|r| r.name.ends_with("ASSEMBLY_USAGE_OCCURRENCE"))
                && let (Some(Value::Ref(a)), Some(Value::Ref(c))) = (
                    n.params.get(3).map(|p| &p.value),
                    n.params.get(4).map(|p| &p.value),
                )
            {
                usage.insert(*rel, (*a, *c));
            }
        }
        Components {
            usage,
            reps,
            aspects,
        }
    }

    /// Whether relationship `rel` between `rep_1` and `rep_2` has its component in `rep_2`.
    fn reversed(&self, rel: u64, rep_1: u64, rep_2: u64) -> bool {
        let Some(&(assembly, component)) = self.usage.get(&rel) else {
            return false;
        };
        let holds = |pd: u64, rep: u64| self.reps.get(&pd).is_some_and(|r| r.contains(&rep));
        !holds(component, rep_1) && (holds(component, rep_2) || holds(assembly, rep_1))
    }
}
