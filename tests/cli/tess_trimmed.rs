//! `tessellate` on a real trimmed CAD model: the hammer of G+Smo's test data (a 1998 IGES
//! export as OBJ free-form, 45 trimmed surfaces, 3 holes).

use crate::common;

use common::{run, stderr, stdout};

#[test]
fn the_hammer_tessellates_with_its_trims_and_reports_the_gaps() {
    let hammer = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/gismo/hammer.from_iges.obj");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hammer.obj");
    let o = run(&[
        "tessellate",
        hammer.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let g = &r["trim_gaps"];
    assert_eq!(g["faces"], 45, "{r}");
    let shared = g["shared_samples"].as_u64().unwrap();
    let free = g["free_samples"].as_u64().unwrap();
    // A closed solid: nearly every boundary sample lies next to another face.
    assert!(shared > 1000 && free * 20 < shared, "{g}");
    let largest = g["largest"].as_f64().unwrap();
    assert!(largest <= g["radius"].as_f64().unwrap(), "{g}");
    // The written mesh holds what the report counts.
    let text = std::fs::read_to_string(&out).unwrap();
    let faces = text.lines().filter(|l| l.starts_with("f ")).count() as u64;
    assert_eq!(faces, r["triangles"].as_u64().unwrap());
    assert!(faces > 1000);
    // The text report names the gaps too (on a coarse grid: the wording is the check).
    let o = run(&[
        "tessellate",
        hammer.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--triangles-per-patch",
        "8",
    ]);
    assert!(stdout(&o).contains("trim gaps: largest"), "{}", stdout(&o));
}

/// A damaged file: the holed plate of `testdata/holed_plate.obj` with one control point of
/// its plate moved to 9·10¹⁸ (a bilinear patch twisted that far needs some 10²⁰ triangles
/// at 0.05). The estimate made before any work refuses the face, naming it, with exit 2
/// and no file written; before it, the refinement ran for minutes and wrote 1.3 M
/// triangles as far as 10¹⁷ from the surface.
#[test]
fn a_control_point_thrown_far_out_is_refused_before_the_work() {
    let plate = std::fs::read_to_string(common::testdata("holed_plate.obj")).unwrap();
    assert_eq!(plate.matches("\nv 4 2 0\n").count(), 1);
    let damaged = plate.replace("\nv 4 2 0\n", "\nv 4 2 9e18\n");
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("damaged.obj");
    std::fs::write(&input, damaged).unwrap();
    let out = dir.path().join("damaged.stl");
    let o = run(&[
        "tessellate",
        input.to_str().unwrap(),
        "--tolerance",
        "0.05",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("trimmed face 0 of object \"damaged.obj\"") && e.contains("e20 triangles"),
        "{e}"
    );
    assert!(!out.exists());
}
