//! IGES files as CAD systems write them (`testdata/cad/PROVENANCE.tsv`, `testdata/gismo/`),
//! read in millimetres and traced; the expected hits are OpenCASCADE 8.0's, printed by
//! `bench/occ/run.sh FILE --rays 300` (its `occ.csv`, rays from its `rays.txt`, seed 1),
//! which reads the same files with `IGESControl_Reader` in millimetres.

use crate::common;

use std::path::{Path, PathBuf};

use common::{run, stderr, stdout, testdata};
use glam::DVec3;

fn gismo(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/gismo")
        .join(name)
}

/// Each ray `[ox, oy, oz, dx, dy, dz]` hits within `tolerance` (mm) of OpenCASCADE's point.
fn hits_as_occ(scene: &Path, rays: &[([f64; 6], [f64; 3])], tolerance: f64) {
    hits_as_occ_with(scene, rays, tolerance, &[]);
}

fn hits_as_occ_with(scene: &Path, rays: &[([f64; 6], [f64; 3])], tolerance: f64, extra: &[&str]) {
    let text: String = rays
        .iter()
        .map(|(r, _)| format!("{} {} {} {} {} {}\n", r[0], r[1], r[2], r[3], r[4], r[5]))
        .collect();
    let rows = common::trace_rows(scene, &text, extra);
    for ((_, occ), row) in rays.iter().zip(&rows) {
        assert_eq!(
            row[1],
            "1",
            "{}: a miss where OpenCASCADE hits",
            scene.display()
        );
        let p = DVec3::new(
            row[7].parse().unwrap(),
            row[8].parse().unwrap(),
            row[9].parse().unwrap(),
        );
        let e = (p - DVec3::from_array(*occ)).length();
        assert!(
            e <= tolerance,
            "{}: {p} vs {occ:?} ({e:e} mm)",
            scene.display()
        );
    }
}

/// Tolerance of the comparisons: the f32 kernels on models tens of millimetres across.
const MM: f64 = 1e-3;

#[test]
fn centimetre_file_is_traced_in_millimetres() {
    // Autodesk DirectConnect, unit flag 10 (CM); rays 0 and 1 of
    // `bench/occ/run.sh testdata/gismo/torus.igs --rays 300`.
    let torus = gismo("torus.igs");
    hits_as_occ(
        &torus,
        &[
            (
                [
                    15.73474989478636,
                    25.24346000244904,
                    -80.70145149223583,
                    -0.01693837657591235,
                    -0.3427038241553823,
                    0.9392907858103632,
                ],
                [14.380368576011845, -2.158909712762892, -5.59638534276236],
            ),
            (
                [
                    26.599334997993427,
                    62.38531712026208,
                    -54.06938840456796,
                    -0.3544276468417252,
                    -0.6319860829988856,
                    0.6891840349645102,
                ],
                [-5.5865235547127305, 4.994154619430077, 8.515965937320352],
            ),
        ],
        MM,
    );
    let o = run(&["info", torus.to_str().unwrap()]);
    assert!(
        stdout(&o).contains("IGES units: CM (10 mm), read in millimetres"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn catia_v4_surface_with_break_knots_is_read() {
    // One 144 over a 128 whose u knots repeat degree + 1 times; rays 0 and 1 of
    // `bench/occ/run.sh testdata/cad/occt_CTS17806-38038.igs --rays 300`.
    hits_as_occ(
        &testdata("cad/occt_CTS17806-38038.igs"),
        &[
            (
                [
                    2030.0300316810676,
                    -807.2733876401487,
                    42.89419451074,
                    -0.0818053632491954,
                    -0.9059851355322105,
                    -0.4153297686638286,
                ],
                [2028.7294012724788, -821.6777221507507, 36.29083129272169],
            ),
            (
                [
                    2039.6383720256688,
                    -811.3896691009359,
                    38.48167368762081,
                    -0.7007446876846276,
                    -0.7121788219202251,
                    0.04193099438475338,
                ],
                [2029.625339391296, -821.566085577183, 39.080831159015304],
            ),
        ],
        MM,
    );
}

#[test]
fn miscounted_hollerith_in_the_global_section_is_read_with_one_warning() {
    // Rhino 7 announces `38H` before its 32-character file name, then `,` and blanks.
    let file = testdata("cad/pyocc_testfile.igs");
    let o = run(&["info", file.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.matches("Hollerith").count(), 1, "{err}");
    assert!(
        err.contains("line 3, column 1: 38 characters announced, 32 before the delimiter"),
        "{err}"
    );
    // The parameters after it are in place: MM (parameter 15), and the bilinear 128's
    // box is that of its four control points as written in the file.
    let out = stdout(&o);
    assert!(out.contains("IGES units: MM (1 mm)"), "{out}");
    assert!(
        out.contains(
            "bounds: [-17.4713751196072, -1.511404777835494, 0.0] .. [22.26938756285151, 39.01970722272699, 0.0]"
        ),
        "{out}"
    );
}

#[test]
fn clockwise_loop_across_the_seam_of_a_torus_bounds_the_rest_of_it() {
    // HarmonyWare: one 144 over a closed 12 x 12 B-spline torus on [0, 2pi]^2, its outer
    // loop u in [-pi/2, pi/2] (across the seam), v in [2.89, 3.96], clockwise: the face is
    // the torus without that rectangle. Rays 0 and 1 of `bench/occ/run.sh
    // testdata/cad/occt_OCC26138_Torus.igs --rays 300` and ray 2 (a random one) hit it
    // far from the rectangle. Toth's kernel: the subdivision kernel does not yet
    // converge on degree 12.
    hits_as_occ_with(
        &testdata("cad/occt_OCC26138_Torus.igs"),
        &[
            (
                [
                    -450.2177609289869,
                    1460.8160326615312,
                    -921.040608107085,
                    0.3895952154419073,
                    -0.6868203580034465,
                    0.6135905507231931,
                ],
                [127.50653240383258, 442.3414974338234, -11.157341419201657],
            ),
            (
                [
                    -45.97832826417232,
                    1684.1761548325435,
                    -771.5129233409361,
                    0.18050973752375032,
                    -0.8215201552000937,
                    0.540851984612353,
                ],
                [226.92199723176412, 442.1760232547117, 46.164198517457976],
            ),
            (
                [
                    -976.9753177996565,
                    -928.9563589327954,
                    -344.95275460130244,
                    0.6825322420863397,
                    0.6611724856219728,
                    0.3114493261656806,
                ],
                [67.22264542905896, 82.56356680574117, 131.5298669918621],
            ),
        ],
        MM,
        &["--kernel", "toth"],
    );
}
