//! The CAD front door (`formats::cad::scene`): what a reader hands over becomes one scene
//! with one material per colour, warnings go to the command line (stderr) and not into the
//! scene's objects, and a file that yields nothing renderable is an error (exit 2) that says
//! what the file held and why each entity failed.

use crate::common;
use crate::step_support;

use common::{run, stderr};
use glam::{DAffine3, DVec3, Vec3};
use patchtrace::formats::cad::scene::{
    CadModel, DeclaredUnit, Occurrence, Part, Piece, Shape, assemble, build_scene,
};
use patchtrace::scene::model::{Geometry, TriangleMesh};

fn triangle(colour: Option<Vec3>) -> Piece {
    Piece {
        shape: Shape::Triangles(TriangleMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: Vec::new(),
            indices: vec![[0, 1, 2]],
        }),
        colour,
    }
}

fn inch_model() -> CadModel {
    let mut m = CadModel::new(
        "STEP",
        "face",
        DeclaredUnit {
            name: "inch".into(),
            millimetres: 25.4,
        },
    );
    let red = Some(Vec3::new(1.0, 0.0, 0.0));
    m.parts.push(Part {
        name: "#1".into(),
        pieces: vec![triangle(red), triangle(None), triangle(red)],
    });
    m.parts.push(Part {
        name: "#2".into(),
        pieces: vec![triangle(red)],
    });
    // Part 0 twice (shared), part 1 once (a placed copy).
    for (part, x) in [(0, 0.0), (0, 10.0), (1, 20.0)] {
        m.occurrences.push(Occurrence {
            part,
            transform: DAffine3::from_translation(DVec3::new(x, 0.0, 0.0)),
        });
    }
    m
}

#[test]
fn one_material_per_colour_and_placements_in_millimetres() {
    let a = assemble(&inch_model(), "m.step");
    // Default plus one red, however many pieces and parts are red.
    assert_eq!(a.materials.len(), 2);
    assert_eq!(a.materials[1].diffuse, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(a.materials[1].name, "rgb(1.000,0.000,0.000)");
    // Occurrence × material: 2 + 2 + 1.
    assert_eq!(a.objects.len(), 5);
    // The third occurrence's vertex (1,0,0) sits at (20 + 1) inches = 533.4 mm.
    let last = a.objects.last().unwrap();
    let Geometry::Mesh(mesh) = &last.geometry else {
        panic!("a part placed once is a placed copy: {:?}", last.geometry);
    };
    assert!((mesh.positions[1] - DVec3::new(21.0 * 25.4, 0.0, 0.0)).length() < 1e-12);
    // The part placed twice is shared: both of its red objects hold one Arc.
    let shared: Vec<_> = a
        .objects
        .iter()
        .filter_map(|o| match &o.geometry {
            Geometry::Instance(i) if o.material == 1 => Some(i.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(shared.len(), 2);
    assert!(std::sync::Arc::ptr_eq(
        &shared[0].geometry,
        &shared[1].geometry
    ));
    let p = shared[1].transform.transform_point3(DVec3::X);
    assert!((p - DVec3::new(11.0 * 25.4, 0.0, 0.0)).length() < 1e-12);
}

#[test]
fn warnings_are_returned_not_printed() {
    let mut m = inch_model();
    m.warnings.push("tolerated something".into());
    m.skipped.insert("CURVE_THING".into(), 3);
    let path = std::path::Path::new("m.step");
    let read = build_scene(path, m).unwrap();
    assert_eq!(
        read.scene.warnings,
        vec![
            "warning: m.step: tolerated something".to_string(),
            "warning: m.step: unsupported entities: CURVE_THING x3".to_string()
        ]
    );
    assert!(
        read.notes
            .contains(&"unsupported entities: CURVE_THING x3".to_string())
    );
}

#[test]
fn a_model_with_nothing_renderable_is_an_error_naming_what_it_held() {
    let mut m = CadModel::new(
        "STEP",
        "face",
        DeclaredUnit {
            name: "millimetre".into(),
            millimetres: 1.0,
        },
    );
    m.held = "2 face(s)".into();
    m.parts.push(Part::default());
    m.occurrences.push(Occurrence {
        part: 0,
        transform: DAffine3::IDENTITY,
    });
    for (id, why) in [("#7", "first reason"), ("#9", "second reason")] {
        m.failures.push(patchtrace::formats::cad::scene::Failure {
            entity: id.into(),
            why: why.into(),
        });
    }
    let Err(e) = build_scene(std::path::Path::new("e.step"), m) else {
        panic!("an empty scene was built");
    };
    let e = e.to_string();
    assert!(e.contains("nothing to render"), "{e}");
    assert!(e.contains("2 face(s)"), "{e}");
    assert!(e.contains("face #7: first reason"), "{e}");
    assert!(e.contains("face #9: second reason"), "{e}");
}

/// A STEP file whose only face lies on a SURFACE_REPLICA (ISO 10303-42 §4.4.?, a
/// transformed copy of another surface, which the reader does not convert), beside a
/// GEOMETRIC_CURVE_SET: nothing to render, exit 2, and the message names both.
#[test]
fn a_step_file_with_nothing_renderable_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = step_support::StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let origin = w.point(DVec3::ZERO);
    let op = w.add(format!(
        "CARTESIAN_TRANSFORMATION_OPERATOR_3D('','',$,$,#{origin},$,$)"
    ));
    let replica = w.add(format!("SURFACE_REPLICA('',#{plane},#{op})"));
    let sq = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    let b = w.polygon_bound(&sq, true);
    let bad = w.face(&[b], replica);
    let path = dir.path().join("replica.step");
    std::fs::write(&path, w.finish()).unwrap();
    let out = dir.path().join("r.png");
    let (p, o) = (path.to_str().unwrap(), out.to_str().unwrap());
    for args in [&["info", p][..], &["render", p, "-o", o][..]] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("nothing to render"), "{err}");
        assert!(err.contains("1 face(s)"), "{err}");
        assert!(
            err.contains(&format!("face #{bad}: uses SURFACE_REPLICA")),
            "{err}"
        );
        assert!(!out.exists());
    }
}

/// A Windows path with single backslashes in FILE_NAME (MSC.Patran writes one): `\T` and
/// `\t` begin no control directive of ISO 10303-21 §6.4.3, so they are kept as text with
/// one warning, as OpenCASCADE reads the file, and the part is read whole.
#[test]
fn backslashes_that_begin_no_escape_are_text_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    let text = step_support::bracket(1).replacen(
        "FILE_NAME('test.step'",
        "FILE_NAME('C:\\TEMP\\test.step'",
        1,
    );
    let line = text.lines().position(|l| l.contains("C:\\TEMP")).unwrap() + 1;
    let path = dir.path().join("windows.step");
    std::fs::write(&path, text).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(common::stdout(&o).contains("faces: 8 converted, 0 failed"));
    let err = stderr(&o);
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains(&format!("windows.step: {line}:11: 2 backslash(es)")),
        "{err}"
    );
    assert!(warnings[0].contains("first `\\TE`"), "{err}");
}
