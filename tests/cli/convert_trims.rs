//! `convert` to OBJ free-form and IGES keeps trims: a made rational surface with an outer
//! loop and a circular hole, and a real CAD part, written, read back by our readers and
//! traced, against closed-form answers and the original's hits.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use crate::common;
use common::{run, stderr, testdata, trace_rows};
use patchtrace::formats::load_geometry;
use patchtrace::geom::trim::TrimRegion;
use patchtrace::scene::{Geometry, SurfaceGeometry};

/// Outer loop: the square [LO, HI]²; hole: the circle about HOLE_CENTRE of HOLE_RADIUS,
/// crossing the surface's interior knots (0.5) so that it cuts all four patches.
const LO: f64 = 0.1;
const HI: f64 = 0.9;
const HOLE_CENTRE: DVec2 = DVec2::new(0.5, 0.45);
const HOLE_RADIUS: f64 = 0.2;

/// A rational biquadratic B-spline surface with knots 0 0 0 .5 1 1 1 both ways (2 × 2
/// patches), weights other than 1, trimmed by a square (degree-1 `curv2`) and a circular
/// hole (the exact rational quadratic circle, Piegl & Tiller §7.5).
fn made_obj() -> String {
    let mut s = String::new();
    for j in 0..4 {
        for i in 0..4 {
            let (x, y) = (i as f64 / 3.0, j as f64 / 3.0);
            let z = 0.2 * (2.0 * x).sin() * (1.0 + y);
            let w = 1.0 + 0.2 * ((i + j) % 2) as f64;
            s += &format!("v {x} {y} {z} {w}\n");
        }
    }
    for (u, v) in [(LO, LO), (HI, LO), (HI, HI), (LO, HI), (LO, LO)] {
        s += &format!("vp {u} {v}\n");
    }
    s += "cstype bspline\ndeg 1\ncurv2 1 2 3 4 5\nparm u 0 0 0.25 0.5 0.75 1 1\nend\n";
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let circle = [
        (1.0, 0.0, 1.0),
        (1.0, 1.0, h),
        (0.0, 1.0, 1.0),
        (-1.0, 1.0, h),
        (-1.0, 0.0, 1.0),
        (-1.0, -1.0, h),
        (0.0, -1.0, 1.0),
        (1.0, -1.0, h),
        (1.0, 0.0, 1.0),
    ];
    for (x, y, w) in circle {
        let p = HOLE_CENTRE + HOLE_RADIUS * DVec2::new(x, y);
        s += &format!("vp {} {} {w}\n", p.x, p.y);
    }
    s += "cstype rat bspline\ndeg 2\ncurv2 6 7 8 9 10 11 12 13 14\n";
    s += "parm u 0 0 0 0.25 0.25 0.5 0.5 0.75 0.75 1 1 1\nend\n";
    s += "cstype rat bspline\ndeg 2 2\nsurf 0 1 0 1";
    for k in 1..=16 {
        s += &format!(" {k}");
    }
    s += "\nparm u 0 0 0 0.5 1 1 1\nparm v 0 0 0 0.5 1 1 1\ntrim 0 1 1\nhole 0 1 2\nend\n";
    s
}

fn convert(input: &Path, output: &Path) {
    let o = run(&[
        "convert",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(output.exists());
}

/// `trace --precision f64` of the rays: per ray `None` or `(t, point)`.
fn hits(scene: &Path, rays: &[(DVec3, DVec3)]) -> Vec<Option<(f64, DVec3)>> {
    let text: String = rays
        .iter()
        .map(|(o, d)| format!("{} {} {} {} {} {}\n", o.x, o.y, o.z, d.x, d.y, d.z))
        .collect();
    trace_rows(scene, &text, &["--precision", "f64"])
        .iter()
        .map(|f| {
            let x = |k: usize| f[k].parse::<f64>().unwrap();
            (f[1] == "1").then(|| (x(2), DVec3::new(x(7), x(8), x(9))))
        })
        .collect()
}

fn surfaces(path: &Path) -> Vec<patchtrace::scene::Surface> {
    match load_geometry(path).unwrap() {
        Geometry::Surfaces(s) => s,
        other => panic!("expected surfaces, found {other:?}"),
    }
}

#[test]
fn a_trimmed_rational_surface_with_a_hole_survives_obj_and_iges() {
    let dir = tempfile::tempdir().unwrap();
    let original = dir.path().join("made.obj");
    std::fs::write(&original, made_obj()).unwrap();
    let nurbs = match &surfaces(&original)[0].geometry {
        SurfaceGeometry::Nurbs(n) => n.clone(),
        other => panic!("expected a NURBS surface, found {other:?}"),
    };
    let written: Vec<PathBuf> = ["out.obj", "out.igs"]
        .iter()
        .map(|name| {
            let out = dir.path().join(name);
            convert(&original, &out);
            out
        })
        .collect();

    // Read back: the same four patches (within an ulp: OBJ and IGES store x y z and w) and
    // the same trimmed region, checked at (u, v) samples against the closed form.
    let reference = nurbs.to_bezier_patches();
    for out in &written {
        let back = surfaces(out);
        let patches: Vec<_> = back
            .iter()
            .flat_map(|s| match &s.geometry {
                SurfaceGeometry::Bezier(p) => vec![p.clone()],
                SurfaceGeometry::Nurbs(n) => n.to_bezier_patches(),
            })
            .collect();
        assert_eq!(patches.len(), 4, "{}", out.display());
        for (a, b) in reference.iter().zip(&patches) {
            assert_eq!(a.domain(), b.domain());
            for (p, q) in a.homogeneous_points().iter().zip(b.homogeneous_points()) {
                assert!(
                    (*p - *q).abs().max_element() <= 4.0 * f64::EPSILON,
                    "{p} vs {q}"
                );
            }
        }
        let region = TrimRegion::new(&back[0].trims, &back[0].trim_space)
            .unwrap()
            .unwrap();
        for i in 0..=40 {
            for j in 0..=40 {
                let uv = DVec2::new(i as f64 / 40.0 + 0.003, j as f64 / 40.0 + 0.007);
                assert_eq!(
                    region.contains(uv.x, uv.y),
                    kept(uv),
                    "{} at {uv}",
                    out.display()
                );
            }
        }
    }

    // Rays straight down onto points of the surface, evaluated in f64 by de Boor's
    // algorithm on the original NURBS surface, away from the loops: each hits where the
    // closed form says, at that point, in the original and in both written files.
    let mut rays = Vec::new();
    let mut expected = Vec::new();
    for i in 0..24 {
        for j in 0..24 {
            let uv = DVec2::new((i as f64 + 0.37) / 24.0, (j as f64 + 0.61) / 24.0);
            let near_square = [uv.x - LO, HI - uv.x, uv.y - LO, HI - uv.y]
                .iter()
                .any(|d| d.abs() < 0.01);
            if near_square || ((uv - HOLE_CENTRE).length() - HOLE_RADIUS).abs() < 0.01 {
                continue;
            }
            let p = nurbs.eval(uv.x, uv.y);
            rays.push((p + DVec3::Z * 5.0, -DVec3::Z));
            expected.push(kept(uv).then_some(p));
        }
    }
    assert!(expected.iter().filter(|e| e.is_some()).count() > 100);
    assert!(expected.iter().filter(|e| e.is_none()).count() > 100);
    for scene in std::iter::once(&original).chain(&written) {
        for (k, (hit, want)) in hits(scene, &rays).iter().zip(&expected).enumerate() {
            match (hit, want) {
                (None, None) => {}
                (Some((t, p)), Some(q)) => {
                    assert!(
                        (t - 5.0).abs() < 1e-9,
                        "{}: ray {k}: t {t}",
                        scene.display()
                    );
                    assert!((*p - *q).length() < 1e-9, "{}: ray {k}", scene.display());
                }
                _ => panic!("{}: ray {k}: {hit:?}, expected {want:?}", scene.display()),
            }
        }
    }
}

/// The closed form of the trimmed region: inside the square, outside the hole.
fn kept(uv: DVec2) -> bool {
    let in_square = (LO..=HI).contains(&uv.x) && (LO..=HI).contains(&uv.y);
    in_square && (uv - HOLE_CENTRE).length() > HOLE_RADIUS
}

/// A fixed pseudo-random sequence in [0, 1) (64-bit LCG, Knuth's MMIX constants).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn a_real_part_traces_the_same_after_obj_and_iges() {
    // CATIA V5's CAx-IF k1 part: 58 faces, many on cylinders and cones, whose trims are
    // written in angles and moved to the NURBS parameters on the way out.
    let original = testdata("cad/occt_trj5_k1-ct-214.stp");
    let dir = tempfile::tempdir().unwrap();
    // About the part's box as `info` prints it.
    let (lo, hi) = (DVec3::new(-2.0, -26.0, -7.0), DVec3::new(127.0, 23.0, 7.0));
    let size = (hi - lo).length();
    let mut rng = Lcg(29);
    let rays: Vec<(DVec3, DVec3)> = (0..600)
        .map(|_| {
            let mut r = || rng.next();
            let target = lo + (hi - lo) * DVec3::new(r(), r(), r());
            let dir = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            (target - dir * size, dir)
        })
        .collect();
    let before = hits(&original, &rays);
    let hit_count = before.iter().filter(|h| h.is_some()).count();
    assert!(hit_count > 100, "{hit_count} hits");
    for name in ["k1.obj", "k1.igs"] {
        let out = dir.path().join(name);
        convert(&original, &out);
        let after = hits(&out, &rays);
        for (k, (a, b)) in before.iter().zip(&after).enumerate() {
            match (a, b) {
                (None, None) => {}
                (Some((ta, pa)), Some((tb, pb))) => {
                    assert!(
                        (ta - tb).abs() <= 1e-9 * size && (*pa - *pb).length() <= 1e-9 * size,
                        "{name}: ray {k}: t {ta} vs {tb}"
                    );
                }
                _ => panic!("{name}: ray {k}: {a:?} before, {b:?} after"),
            }
        }
    }
}

#[test]
fn written_iges_keeps_units_and_colours_and_its_layout() {
    // The BGA's two colours (STEP COLOUR_RGB) come back as 314 entities, and every record
    // is 80 columns with its section letter and sequence number (IGES 5.3 §2.1).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bga.igs");
    convert(&testdata("cad/sfe_BGA_10x10mm_blankhdr.step"), &out);
    let text = std::fs::read_to_string(&out).unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for line in text.lines() {
        assert_eq!(line.len(), 80, "{line:?}");
        let section = line.as_bytes()[72] as char;
        let n = counts.entry(section).or_insert(0usize);
        *n += 1;
        assert_eq!(line[73..].trim().parse::<usize>().unwrap(), *n, "{line:?}");
    }
    let global: String = text
        .lines()
        .filter(|l| l.as_bytes()[72] == b'G')
        .map(|l| &l[..72])
        .collect();
    assert!(global.contains(",1.0,2,2HMM,"), "{global}");
    // The STEP file's COLOUR_RGB values, as `info` on it names its materials.
    let scene = patchtrace::formats::load_scene(&out).unwrap();
    for grey in [0.725f32, 0.588] {
        assert!(
            scene
                .materials
                .iter()
                .any(|m| (m.diffuse - glam::Vec3::splat(grey)).abs().max_element() < 1e-3),
            "{:?}",
            scene.materials
        );
    }
}

#[test]
fn a_mesh_is_refused_and_no_file_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("tri.obj");
    std::fs::write(&mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for name in ["out.igs", "out.obj"] {
        let out = dir.path().join(name);
        let o = run(&[
            "convert",
            mesh.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("triangle mesh"), "{}", stderr(&o));
        assert!(!out.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
