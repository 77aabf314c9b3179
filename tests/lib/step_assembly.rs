//! STEP assembly placements through the real binary. A unit square face in a component is
//! placed in its assembly by an ITEM_DEFINED_TRANSFORMATION, written both ways CAD systems
//! write it: the component as `rep_1` (most writers) and the assembly as `rep_1` with the
//! NEXT_ASSEMBLY_USAGE_OCCURRENCE naming the component (SolidWorks), and as a MAPPED_ITEM.
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

/// The square [0,1]² at z = 0 in a component representation; returns (writer, component
/// rep, its origin placement, context).
fn component() -> (StepWriter, u64, u64, u64) {
    let mut w = StepWriter::default();
    let model = w.unit_square_model();
    let ctx = w.add("(GEOMETRIC_REPRESENTATION_CONTEXT(3) REPRESENTATION_CONTEXT('',''))");
    let origin = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let rep = w.add(format!(
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',(#{origin},#{model}),#{ctx})"
    ));
    (w, rep, origin, ctx)
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

fn product(w: &mut StepWriter, rep: u64, pd_name: &str) -> u64 {
    let pd = w.add(format!("PRODUCT_DEFINITION('{pd_name}','',$,$)"));
    let pds = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    w.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    pd
}

#[test]
fn item_defined_transformations_place_the_component_either_way_round() {
    for reversed in [false, true] {
        let (mut w, child, child_origin, ctx) = component();
        let place = w.axis(ORIGIN, Z, X);
        let parent = w.add(format!("SHAPE_REPRESENTATION('',(#{place}),#{ctx})"));
        let assembly = product(&mut w, parent, "assembly");
        let part = product(&mut w, child, "part");
        let nauo = w.add(format!(
            "NEXT_ASSEMBLY_USAGE_OCCURRENCE('1','','',#{assembly},#{part},$)"
        ));
        let nauo_shape = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{nauo})"));
        // transform_item_1 is an item of rep_1, transform_item_2 of rep_2 (ISO 10303-43).
        let (rep_1, rep_2, item_1, item_2) = if reversed {
            (parent, child, place, child_origin)
        } else {
            (child, parent, child_origin, place)
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
        check(&w, &format!("reversed_{reversed}.step"));
    }
}

#[test]
fn a_mapped_item_places_its_representation_origin_on_its_target() {
    let (mut w, child, _, ctx) = component();
    // The map's origin is not the component's own origin: (1, 0, 0) of the component
    // lands on the target, so the component moves by -1 along the target's x as well.
    let origin = w.axis(DVec3::X, DVec3::Z, DVec3::X);
    let map = w.add(format!("REPRESENTATION_MAP(#{origin},#{child})"));
    let target = w.axis(ORIGIN + X, Z, X);
    let item = w.add(format!("MAPPED_ITEM('',#{map},#{target})"));
    w.add(format!("SHAPE_REPRESENTATION('',(#{item}),#{ctx})"));
    check(&w, "mapped.step");
}
