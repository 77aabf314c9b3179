//! Real CAD files written by OpenCASCADE 8.0 (`testdata/occ/PROVENANCE.txt`): a block with
//! two through holes, a boss, a hemispherical dome and filleted edges, as STEP (AP214) and
//! IGES faces. Rays aimed at each kind of face hit it where the part's dimensions put the
//! point (closed forms, independent of the readers), rays down the holes pass, and in STEP
//! every face's normal points out of the solid (`same_sense` applied).

use crate::common;

use std::f64::consts::FRAC_1_SQRT_2;

use common::{testdata, trace_hits};
use glam::{DAffine3, DVec3};

struct Aim {
    name: &'static str,
    origin: DVec3,
    dir: DVec3,
    /// Where the ray meets the part, and the outward normal there.
    hit: Option<(DVec3, DVec3)>,
}

fn aims() -> Vec<Aim> {
    let (x, z) = (DVec3::X, DVec3::Z);
    let dome = DVec3::new(12.0, -7.0, 10.0);
    // Where the plane z = 12 through the dome's centre line meets the sphere, both sides.
    let side = DVec3::new(12.0 - 12f64.sqrt(), -7.0, 12.0);
    let far_side = DVec3::new(12.0 + 12f64.sqrt(), -7.0, 12.0);
    let diag = DVec3::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0);
    let fillet = DVec3::new(17.0, 12.0, 5.0) + 3.0 * diag;
    let aim = |name, origin, dir, hit| Aim {
        name,
        origin,
        dir,
        hit,
    };
    vec![
        aim(
            "top plane",
            DVec3::new(5.0, -10.0, 30.0),
            -z,
            Some((DVec3::new(5.0, -10.0, 10.0), z)),
        ),
        aim(
            "bottom plane",
            DVec3::new(5.0, -10.0, -30.0),
            z,
            Some((DVec3::new(5.0, -10.0, 0.0), -z)),
        ),
        aim(
            "dome top",
            DVec3::new(12.0, -7.0, 30.0),
            -z,
            Some((dome + 4.0 * z, z)),
        ),
        aim(
            "dome side, from -x",
            side - 50.0 * x,
            x,
            Some((side, (side - dome) / 4.0)),
        ),
        aim(
            "dome side, from +x",
            far_side + 50.0 * x,
            -x,
            Some((far_side, (far_side - dome) / 4.0)),
        ),
        aim(
            "boss top",
            DVec3::new(-12.0, 0.0, 30.0),
            -z,
            Some((DVec3::new(-12.0, 0.0, 16.0), z)),
        ),
        aim(
            "boss side",
            DVec3::new(-40.0, 0.0, 13.0),
            x,
            Some((DVec3::new(-16.0, 0.0, 13.0), -x)),
        ),
        aim(
            "hole wall",
            DVec3::new(0.0, 0.0, 5.0),
            x,
            Some((DVec3::new(6.0, 0.0, 5.0), -x)),
        ),
        aim(
            "hole wall, diagonal",
            DVec3::new(0.0, 0.0, 5.0),
            -diag,
            Some((-6.0 * diag + 5.0 * z, diag)),
        ),
        aim("fillet", fillet + 20.0 * diag, -diag, Some((fillet, diag))),
        aim("through the hole", DVec3::new(0.0, 0.0, 30.0), -z, None),
        aim(
            "through the hole, off axis",
            DVec3::new(3.0, -2.0, 30.0),
            -z,
            None,
        ),
        aim(
            "through the small hole",
            DVec3::new(13.0, 8.0, -30.0),
            z,
            None,
        ),
        aim(
            "through the small hole, off axis",
            DVec3::new(14.5, 8.5, 30.0),
            -z,
            None,
        ),
    ]
}

fn check(file: &str, normals: bool) {
    check_placed(file, normals, aims(), &[DAffine3::IDENTITY]);
}

/// [`check`] for the part placed by each of `placements`, with the aims placed alike.
fn check_placed(file: &str, normals: bool, aims: Vec<Aim>, placements: &[DAffine3]) {
    let aims: Vec<Aim> = placements
        .iter()
        .flat_map(|m| {
            aims.iter().map(|a| Aim {
                name: a.name,
                origin: m.transform_point3(a.origin),
                dir: m.transform_vector3(a.dir),
                hit: a
                    .hit
                    .map(|(p, n)| (m.transform_point3(p), m.transform_vector3(n))),
            })
        })
        .collect();
    let rays: Vec<(DVec3, DVec3)> = aims.iter().map(|a| (a.origin, a.dir)).collect();
    let hits = trace_hits(&testdata(file), &rays);
    for (a, got) in aims.iter().zip(&hits) {
        match (a.hit, got) {
            (None, None) => {}
            (None, Some((p, _))) => panic!("{file}: {}: should pass, hit {p}", a.name),
            (Some(_), None) => panic!("{file}: {}: missed", a.name),
            (Some((want, n)), Some((p, got_n))) => {
                // f32 precision on a part 40 mm across: a few ulps of 40.
                assert!(
                    p.distance(want) < 1e-4,
                    "{file}: {}: hit {p}, expected {want}",
                    a.name
                );
                if normals {
                    let g = got_n.normalize();
                    assert!(
                        g.dot(n) > 0.9999,
                        "{file}: {}: normal {g}, outward {n}",
                        a.name
                    );
                }
            }
        }
    }
}

#[test]
fn occ_step_part_hits_every_face_kind_passes_its_holes_and_faces_outward() {
    check("occ/bracket_occ.step", true);
}

#[test]
fn occ_iges_faces_part_hits_every_face_kind_and_passes_its_holes() {
    check("occ/bracket_occ_faces.igs", false);
}

#[test]
fn occ_iges_brep_part_hits_every_face_kind_and_passes_its_holes() {
    // A 186 solid whose cylinders and dome (192, 196) carry parameter-space curves in
    // degrees, OpenCASCADE's convention.
    check("occ/bracket_occ_brep.igs", false);
}

#[test]
fn occ_inch_step_and_iges_come_out_where_the_millimetre_part_is() {
    // The same part written in inches: read in millimetres, both hit the closed-form
    // points of the part's millimetre dimensions, so they render to the same size and
    // place as each other and as the millimetre files.
    check("occ/bracket_occ_inch.step", true);
    check("occ/bracket_occ_inch.igs", false);
}

/// OpenCASCADE's assembly of the bracket used three times (XCAF components, turned by 0°,
/// 90° and 180° about z and moved): three instances of one shared part, and the vertical
/// aims (which cannot reach another copy) hit each placed copy where the placement puts
/// them, and pass its placed holes.
#[test]
fn occ_step_assembly_places_three_instances_of_one_part() {
    let o = common::run(&["info", testdata("occ/brackets3_occ.step").to_str().unwrap()]);
    let out = common::stdout(&o);
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert_eq!(
        out.matches("an instance of object 0's geometry").count(),
        2,
        "{out}"
    );
    let placements: Vec<DAffine3> = [(0.0, 0.0, 0.0), (60.0, 0.0, 90.0), (0.0, 50.0, 180.0)]
        .iter()
        .map(|&(dx, dy, degrees): &(f64, f64, f64)| {
            DAffine3::from_translation(DVec3::new(dx, dy, 0.0))
                * DAffine3::from_rotation_z(degrees.to_radians())
        })
        .collect();
    let vertical = aims()
        .into_iter()
        .filter(|a| a.dir.x == 0.0 && a.dir.y == 0.0)
        .collect::<Vec<_>>();
    assert_eq!(vertical.len(), 8);
    check_placed("occ/brackets3_occ.step", true, vertical, &placements);
}

/// Rays along the outward normal at (u, v) of the torus (R 10, r 3, axis z) and the cone
/// frustum (base r 6 at (30, 0, 0), top r 2 at height 8) of `torus_cone_occ_brep.igs`,
/// with the points in closed form; two rays just above the frustum's top pass beside or
/// hit the top plane, where a cone running on past it (its height read as the length
/// along its side) would be hit first.
fn torus_cone_aims() -> Vec<Aim> {
    let aim = |name, origin, dir, hit| Aim {
        name,
        origin,
        dir,
        hit,
    };
    let mut aims = Vec::new();
    for (u, v) in [(0.3, 0.2), (2.0, -1.1), (4.0, 1.3), (5.5, 0.0)] {
        let (cu, su) = (f64::cos(u), f64::sin(u));
        let (cv, sv) = (f64::cos(v), f64::sin(v));
        let p = DVec3::new((10.0 + 3.0 * cv) * cu, (10.0 + 3.0 * cv) * su, 3.0 * sv);
        let n = DVec3::new(cv * cu, cv * su, sv);
        aims.push(aim("torus", p + 25.0 * n, -n, Some((p, n))));
    }
    for (u, h) in [(0.5, 1.0), (2.5, 4.0), (4.5, 7.5)] {
        let r = 6.0 - 0.5 * h;
        let (cu, su) = (f64::cos(u), f64::sin(u));
        let p = DVec3::new(30.0 + r * cu, r * su, h);
        let n = DVec3::new(cu, su, 0.5).normalize();
        aims.push(aim("cone", p + 25.0 * n, -n, Some((p, n))));
    }
    let top = DVec3::new(31.8, 0.0, 8.0);
    aims.push(aim(
        "cone's top",
        top + 20.0 * DVec3::Z,
        -DVec3::Z,
        Some((top, DVec3::Z)),
    ));
    aims.push(aim(
        "above the cone's top",
        DVec3::new(60.0, 0.0, 8.3),
        -DVec3::X,
        None,
    ));
    aims
}

#[test]
fn occ_iges_brep_torus_and_cone_take_its_parameter_conventions() {
    // OpenCASCADE writes a 198 torus's parameter-space curves in degrees with u and v
    // exchanged and turned, and a 194 cone's v along its side; read as IGES 5.3 says, the
    // torus was refused and the cone ran past its top.
    check_placed(
        "occ/torus_cone_occ_brep.igs",
        false,
        torus_cone_aims(),
        &[DAffine3::IDENTITY],
    );
}

/// Found by the mutation run (`benches/mutation_run.rs`): OpenCASCADE's two-solid file with
/// one part's shape representation deleted made the assembly walk look up a product that
/// had none, and panic. That part now places nothing; the other part's 3 faces still load.
#[test]
fn a_part_without_its_shape_representation_places_nothing() {
    let text = std::fs::read_to_string(testdata("occ/torus_cone_occ.step")).unwrap();
    let cut: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("#36 = ADVANCED_BREP_SHAPE_REPRESENTATION"))
        .collect();
    assert_eq!(cut.len() + 1, text.lines().count(), "the line to delete");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.step");
    std::fs::write(&path, cut.join("\n")).unwrap();
    let o = common::run(&["info", path.to_str().unwrap()]);
    let (out, err) = (common::stdout(&o), common::stderr(&o));
    assert!(o.status.success(), "{err}");
    assert!(out.contains("faces: 3 converted, 0 failed"), "{out}");
}
