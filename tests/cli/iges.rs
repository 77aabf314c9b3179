//! IGES through the real binary: the hammer renders the same from `.iges` as
//! from its OBJ conversion, `info` prints units and what was ignored, `import` writes a
//! RON scene, and errors are located with exit status 2.

use crate::common;

use std::path::{Path, PathBuf};

use common::{render, run, stderr, stdout, testdata};

fn gismo(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/gismo")
        .join(name)
}

#[test]
fn hammer_renders_the_same_from_iges_as_from_obj() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("iges.png"), dir.path().join("obj.png"));
    for (scene, out) in [
        (gismo("hammer.iges"), &a),
        (gismo("hammer.from_iges.obj"), &b),
    ] {
        let o = render(&scene, out, (96, 96), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let o = run(&["diff", a.to_str().unwrap(), b.to_str().unwrap(), "--json"]);
    let report: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["above_count"], 0, "{report}");
    // The OBJ conversion writes numbers to 10 significant digits and gives a 128's
    // parameter range as a `surf` range (the surface restricted) where the IGES reader
    // makes it an outer trim loop: a silhouette pixel may flip between hit and miss.
    assert!(
        report["coverage_mismatch"].as_u64().unwrap() <= 2,
        "{report}"
    );
}

#[test]
fn info_prints_units_and_ignored_entities() {
    let o = run(&["info", gismo("hammer.iges").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("patches: 162"), "{out}");
    assert!(
        out.contains("IGES units: MM (1 mm), read in millimetres (model scale 1)"),
        "{out}"
    );
    assert!(
        out.contains("unsupported entities: 402 (associativity) x1"),
        "{out}"
    );
    assert!(
        stderr(&o).contains("hammer.iges: unsupported entities: 402 (associativity) x1"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn import_states_the_unit_of_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    // The hammer has trim loops, which only RON keeps; Rhino's one surface has none.
    for (input, name, comment) in [
        (gismo("hammer.iges"), "hammer.ron", "//"),
        (testdata("cad/pyocc_testfile.igs"), "rhino.obj", "#"),
    ] {
        let out = dir.path().join(name);
        let o = run(&[
            "import",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            text.lines().next().unwrap(),
            format!("{comment} lengths in millimetres (the IGES file declares MM, 1 mm)"),
        );
    }
}

#[test]
fn broken_iges_is_a_located_error_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.igs");
    let text = std::fs::read_to_string(testdata("trimmed_patch.igs")).unwrap();
    // The 128's first parameter (K1 = 3) becomes a letter, same width.
    let broken = text.replacen("128,3,1,", "128,x,1,", 1);
    assert_ne!(broken, text);
    std::fs::write(&bad, broken).unwrap();
    let o = run(&["info", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let line = 1 + text.lines().position(|l| l.starts_with("128,")).unwrap();
    assert!(
        stderr(&o).contains(&format!("bad.igs:{line}:5: expected a number")),
        "{}",
        stderr(&o)
    );
}

#[test]
fn import_to_ron_keeps_trims_and_trim_spaces() {
    let dir = tempfile::tempdir().unwrap();
    for input in [gismo("hammer.iges"), testdata("trimmed_patch.igs")] {
        let out = dir.path().join("scene.ron");
        let o = run(&[
            "import",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let a = patchtrace::formats::load_scene(&input).unwrap();
        let b = patchtrace::formats::load_scene(&out).unwrap();
        let surfaces = |s: &patchtrace::scene::Scene| -> Vec<patchtrace::scene::Surface> {
            s.objects
                .iter()
                .flat_map(|o| match &o.geometry {
                    patchtrace::scene::Geometry::Surfaces(s) => s.clone(),
                    _ => Vec::new(),
                })
                .collect()
        };
        let (sa, sb) = (surfaces(&a), surfaces(&b));
        assert!(
            sa.iter().any(|s| !s.trims.is_empty()),
            "{}",
            input.display()
        );
        // RON writes f64 so that it reads back exactly.
        assert_eq!(sa, sb, "{}", input.display());
    }
    // The fuzz sample holds a surface of revolution: its angle map must survive too.
    let a = patchtrace::formats::load_scene(&testdata("trimmed_patch.igs")).unwrap();
    let arcs = a.objects.iter().any(|o| match &o.geometry {
        patchtrace::scene::Geometry::Surfaces(s) => s
            .iter()
            .any(|s| s.trim_space != <[patchtrace::geom::trim::AxisMap; 2]>::default()),
        _ => false,
    });
    assert!(arcs);
}

/// An IGES file with no surface (one line entity) is an error that says so and what the
/// file held, not an empty scene: exit status 2 for `info` and `render`, no image.
#[test]
fn an_iges_file_without_surfaces_is_refused_saying_what_it_held() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(testdata("trimmed_patch.igs")).unwrap();
    let card = |data: &str, section: char, seq: usize| format!("{data:<72}{section}{seq:>7}\n");
    let mut igs = card("one line entity, no surface", 'S', 1);
    // The Global section of a valid file, as it is.
    for g in text.lines().filter(|l| l.chars().nth(72) == Some('G')) {
        igs.push_str(g);
        igs.push('\n');
    }
    igs.push_str(&card(
        "     110       1       0       0       0       0       0       000010000",
        'D',
        1,
    ));
    igs.push_str(&card(
        "     110       0       0       1       0                               0",
        'D',
        2,
    ));
    igs.push_str(&card(
        &format!("{:<64} {:>7}", "110,0.,0.,0.,1.,0.,0.;", 1),
        'P',
        1,
    ));
    let globals = text
        .lines()
        .filter(|l| l.chars().nth(72) == Some('G'))
        .count();
    igs.push_str(&card(
        &format!("S      1G{globals:>7}D      2P      1"),
        'T',
        1,
    ));
    let path = dir.path().join("line.igs");
    std::fs::write(&path, igs).unwrap();
    let out = dir.path().join("x.png");
    for args in [
        vec!["info", path.to_str().unwrap()],
        vec![
            "render",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ],
    ] {
        let o = run(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("nothing to render"), "{err}");
        assert!(
            err.contains("the IGES file holds 1 entities (by type: 110 x1)"),
            "{err}"
        );
    }
    assert!(!out.exists());
}
