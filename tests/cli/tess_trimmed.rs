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
