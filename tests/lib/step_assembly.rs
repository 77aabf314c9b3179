//! STEP assembly placements through the real binary. A unit square face in a component is
//! placed in its assembly by an ITEM_DEFINED_TRANSFORMATION, written both ways CAD systems
//! write it: the component as `rep_1` (most writers), the assembly as `rep_1` with the
//! NEXT_ASSEMBLY_USAGE_OCCURRENCE naming the component (SolidWorks; CATIA V4 also, but
//! with the component's frame as `transform_item_1`), and as a MAPPED_ITEM.
//! Each must put the square where the frame puts it, computed here in closed form.

use crate::common;
use crate::step_support;

use glam::DVec3;
use step_support::StepWriter;

/// The component's frame in the assembly: origin (10, 20, 30), z along +x, x along +y, so
/// y = z × x = +z.
const ORIGIN: DVec3 = DVec3::new(10.0, 20.0, 30.0);
const Z: DVec3 = DVec3::X;
const X: DVec3 = DVec3::Y;

/// A writer holding the square [0,1]² at z = 0; returns (writer, the square's surface
/// model, a context).
fn square() -> (StepWriter, u64, u64) {
    let mut w = StepWriter::default();
    let model = w.unit_square_model();
    let ctx = w.add("(GEOMETRIC_REPRESENTATION_CONTEXT(3) REPRESENTATION_CONTEXT('',''))");
    (w, model, ctx)
}

/// The square in a component representation; returns (writer, component rep, its origin
/// placement, context, the square's model).
fn component() -> (StepWriter, u64, u64, u64, u64) {
    let (mut w, model, ctx) = square();
    let origin = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let rep = w.add(format!(
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',(#{origin},#{model}),#{ctx})"
    ));
    (w, rep, origin, ctx, model)
}

/// The hit of a ray along -x through the component point (0.5, 0.5, 0), placed.
fn check(w: &StepWriter, name: &str) {
    // Component (0.5, 0.5, 0) → ORIGIN + 0.5 x + 0.5 (z × x).
    let want = ORIGIN + 0.5 * X + 0.5 * Z.cross(X);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, w.text()).unwrap();
    let rays = [(want + DVec3::new(100.0, 0.0, 0.0), -DVec3::X)];
    let hits = common::trace_hits(&path, &rays);
    let (p, _) = hits[0].unwrap_or_else(|| panic!("{name}: the ray missed"));
    assert!(
        (p - want).length() < 1e-9,
        "{name}: hit {p}, expected {want}"
    );
}

/// A product definition whose shape is `rep`; returns it and its PRODUCT_DEFINITION_SHAPE.
fn product(w: &mut StepWriter, rep: u64, pd_name: &str) -> (u64, u64) {
    let pd = w.add(format!("PRODUCT_DEFINITION('{pd_name}','',$,$)"));
    let pds = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    w.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    (pd, pds)
}

/// How a writer lays out a placement's REPRESENTATION_RELATIONSHIP and its
/// ITEM_DEFINED_TRANSFORMATION.
#[derive(Clone, Copy, Debug)]
enum Writing {
    /// The component as `rep_1`, `transform_item_1` its frame (most writers).
    ComponentRep1,
    /// The assembly as `rep_1`, `transform_item_1` the assembly's frame (SolidWorks).
    AssemblyRep1,
    /// The assembly as `rep_1`, but `transform_item_1` still the component's frame
    /// (CATIA V4).
    AssemblyRep1ComponentItem1,
}

/// `child` (whose frame is `child_origin`) placed at ORIGIN in an assembly, written as
/// `writing` says; returns the component's PRODUCT_DEFINITION_SHAPE.
fn assemble(w: &mut StepWriter, child: u64, child_origin: u64, ctx: u64, writing: Writing) -> u64 {
    let place = w.axis(ORIGIN, Z, X);
    let parent = w.add(format!("SHAPE_REPRESENTATION('',(#{place}),#{ctx})"));
    let (assembly, _) = product(w, parent, "assembly");
    let (part, part_shape) = product(w, child, "part");
    let nauo = w.add(format!(
        "NEXT_ASSEMBLY_USAGE_OCCURRENCE('1','','',#{assembly},#{part},$)"
    ));
    let nauo_shape = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{nauo})"));
    let (rep_1, rep_2, item_1, item_2) = match writing {
        Writing::ComponentRep1 => (child, parent, child_origin, place),
        Writing::AssemblyRep1 => (parent, child, place, child_origin),
        Writing::AssemblyRep1ComponentItem1 => (parent, child, child_origin, place),
    };
    let idt = w.add(format!(
        "ITEM_DEFINED_TRANSFORMATION('','',#{item_1},#{item_2})"
    ));
    let rel = w.add(format!(
        "(REPRESENTATION_RELATIONSHIP('','',#{rep_1},#{rep_2}) REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#{idt}) SHAPE_REPRESENTATION_RELATIONSHIP())"
    ));
    w.add(format!(
        "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION(#{rel},#{nauo_shape})"
    ));
    part_shape
}

/// A SHAPE_ASPECT of the product shape `pds` whose representation is `rep`, as Creo and
/// Pro/E write one per part for its validation properties ("solid data associated with").
fn aspect(w: &mut StepWriter, pds: u64, rep: u64) {
    let sa = w.add(format!(
        "SHAPE_ASPECT('','solid data associated with part',#{pds},.F.)"
    ));
    let def = w.add(format!(
        "PROPERTY_DEFINITION('','shape for solid data',#{sa})"
    ));
    w.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{def},#{rep})"));
}

#[test]
fn item_defined_transformations_place_the_component_every_way_round() {
    for writing in [
        Writing::ComponentRep1,
        Writing::AssemblyRep1,
        Writing::AssemblyRep1ComponentItem1,
    ] {
        let (mut w, child, child_origin, ctx, _) = component();
        assemble(&mut w, child, child_origin, ctx, writing);
        check(&w, &format!("{writing:?}.step"));
    }
}

/// The square's own place, unplaced: a ray along -z through component (0.5, 0.5, 0).
fn unplaced_hit(w: &StepWriter) -> Option<DVec3> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("unplaced.step");
    std::fs::write(&path, w.text()).unwrap();
    let rays = [(DVec3::new(0.5, 0.5, 100.0), -DVec3::Z)];
    common::trace_hits(&path, &rays)[0].map(|(p, _)| p)
}

#[test]
fn a_shape_aspect_repeating_the_placed_solid_draws_nothing_more() {
    // The aspect's representation holds the component's own model: it names that solid
    // (for its validation properties), so the square is drawn once, where the assembly
    // places it, and not again at the assembly's origin. OpenCASCADE 8.0 reads this file
    // as one face in the box [10, 20, 30]..[10, 21, 31] (STEPControl_Reader, TransferRoots,
    // TopExp::MapShapes FACE count and BRepBndLib box, run by bench/occ/python.sh).
    let (mut w, child, child_origin, ctx, model) = component();
    let pds = assemble(&mut w, child, child_origin, ctx, Writing::ComponentRep1);
    let aspect_rep = w.add(format!("SHAPE_REPRESENTATION('',(#{model}),#{ctx})"));
    aspect(&mut w, pds, aspect_rep);
    check(&w, "aspect_repeats.step");
    assert_eq!(
        unplaced_hit(&w),
        None,
        "the aspect drew a second, unplaced square"
    );
}

#[test]
fn a_shape_aspect_holding_geometry_of_its_own_is_part_of_the_product() {
    // An AP203 hybrid model: the product's representation holds only its frame, the
    // aspect's the square, which then goes where the product goes. OpenCASCADE 8.0: one
    // face in the box [10, 20, 30]..[10, 21, 31] (as above).
    let (mut w, model, ctx) = square();
    let origin = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let main = w.add(format!("SHAPE_REPRESENTATION('',(#{origin}),#{ctx})"));
    let pds = assemble(&mut w, main, origin, ctx, Writing::ComponentRep1);
    let aspect_rep = w.add(format!("SHAPE_REPRESENTATION('',(#{model}),#{ctx})"));
    aspect(&mut w, pds, aspect_rep);
    check(&w, "aspect_hybrid.step");
    assert_eq!(
        unplaced_hit(&w),
        None,
        "the aspect's square was left unplaced"
    );
}

#[test]
fn a_mapped_item_places_its_representation_origin_on_its_target() {
    let (mut w, child, _, ctx, _) = component();
    // The map's origin is not the component's own origin: (1, 0, 0) of the component
    // lands on the target, so the component moves by -1 along the target's x as well.
    let origin = w.axis(DVec3::X, DVec3::Z, DVec3::X);
    let map = w.add(format!("REPRESENTATION_MAP(#{origin},#{child})"));
    let target = w.axis(ORIGIN + X, Z, X);
    let item = w.add(format!("MAPPED_ITEM('',#{map},#{target})"));
    w.add(format!("SHAPE_REPRESENTATION('',(#{item}),#{ctx})"));
    check(&w, "mapped.step");
}
