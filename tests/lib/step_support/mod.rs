//! A small STEP writer for the tests: entity instances numbered as they are added, a
//! header, and a product structure (shape representation with units) around the faces, so
//! each test writes exactly the entities it checks. Also an independent Cox–de Boor
//! evaluation and the closed forms the converted faces are checked against.

use glam::{DVec2, DVec3};

/// Reals written with 17 significant digits (exact round trip) in Part 21 form.
pub fn real(x: f64) -> String {
    format!("{x:.16E}")
}

fn list(items: &[String]) -> String {
    format!("({})", items.join(","))
}

fn refs(ids: &[u64]) -> String {
    list(&ids.iter().map(|i| format!("#{i}")).collect::<Vec<_>>())
}

fn reals(xs: &[f64]) -> String {
    list(&xs.iter().map(|&x| real(x)).collect::<Vec<_>>())
}

#[derive(Default)]
pub struct StepWriter {
    pub lines: Vec<String>,
    pub next: u64,
    pub faces: Vec<u64>,
    /// Further items of the shape representation (geometric sets, tessellated items).
    pub items: Vec<u64>,
    /// Length unit: `None` for millimetres, or a conversion-based unit (name, mm).
    pub unit: Option<(String, f64)>,
    /// Plane-angle unit in degrees instead of radians.
    pub degrees: bool,
    /// A declared length uncertainty (in the length unit), as CAD systems write their
    /// modelling tolerance.
    pub uncertainty: Option<f64>,
}

impl StepWriter {
    pub fn add(&mut self, body: impl AsRef<str>) -> u64 {
        self.next += 1;
        self.lines
            .push(format!("#{}={};", self.next, body.as_ref()));
        self.next
    }

    pub fn point(&mut self, p: DVec3) -> u64 {
        self.add(format!("CARTESIAN_POINT('',{})", reals(&[p.x, p.y, p.z])))
    }

    pub fn point2(&mut self, p: DVec2) -> u64 {
        self.add(format!("CARTESIAN_POINT('',{})", reals(&[p.x, p.y])))
    }

    pub fn dir(&mut self, d: DVec3) -> u64 {
        self.add(format!("DIRECTION('',{})", reals(&[d.x, d.y, d.z])))
    }

    pub fn dir2(&mut self, d: DVec2) -> u64 {
        self.add(format!("DIRECTION('',{})", reals(&[d.x, d.y])))
    }

    /// AXIS2_PLACEMENT_3D at `o` with axis `z` and ref_direction `x`.
    pub fn axis(&mut self, o: DVec3, z: DVec3, x: DVec3) -> u64 {
        let (p, a, r) = (self.point(o), self.dir(z), self.dir(x));
        self.add(format!("AXIS2_PLACEMENT_3D('',#{p},#{a},#{r})"))
    }

    pub fn line(&mut self, o: DVec3, d: DVec3) -> u64 {
        let p = self.point(o);
        let dir = self.dir(d.normalize());
        let v = self.add(format!("VECTOR('',#{dir},{})", real(d.length())));
        self.add(format!("LINE('',#{p},#{v})"))
    }

    pub fn line2(&mut self, o: DVec2, d: DVec2) -> u64 {
        let p = self.point2(o);
        let dir = self.dir2(d.normalize());
        let v = self.add(format!("VECTOR('',#{dir},{})", real(d.length())));
        self.add(format!("LINE('',#{p},#{v})"))
    }

    pub fn circle(&mut self, axis: u64, r: f64) -> u64 {
        self.add(format!("CIRCLE('',#{axis},{})", real(r)))
    }

    pub fn vertex(&mut self, p: DVec3) -> u64 {
        let c = self.point(p);
        self.add(format!("VERTEX_POINT('',#{c})"))
    }

    pub fn edge(&mut self, v0: u64, v1: u64, curve: u64, same_sense: bool) -> u64 {
        self.add(format!(
            "EDGE_CURVE('',#{v0},#{v1},#{curve},{})",
            if same_sense { ".T." } else { ".F." }
        ))
    }

    pub fn oriented(&mut self, edge: u64, orientation: bool) -> u64 {
        self.add(format!(
            "ORIENTED_EDGE('',*,*,#{edge},{})",
            if orientation { ".T." } else { ".F." }
        ))
    }

    /// FACE_OUTER_BOUND (or FACE_BOUND) over an EDGE_LOOP of (edge, orientation) pairs.
    pub fn bound(&mut self, edges: &[(u64, bool)], outer: bool) -> u64 {
        let oes: Vec<u64> = edges.iter().map(|&(e, o)| self.oriented(e, o)).collect();
        let l = self.add(format!("EDGE_LOOP('',{})", refs(&oes)));
        let kind = if outer {
            "FACE_OUTER_BOUND"
        } else {
            "FACE_BOUND"
        };
        self.add(format!("{kind}('',#{l},.T.)"))
    }

    /// The outer bound of a face between iso-curves: `low` and `right` forwards, `high`
    /// and `left` backwards (the edges of a parameter rectangle all running in +u or +v).
    /// A seam face passes its seam edge as both `right` and `left`.
    pub fn quad_bound(&mut self, low: u64, right: u64, high: u64, left: u64) -> u64 {
        self.bound(
            &[(low, true), (right, true), (high, false), (left, false)],
            true,
        )
    }

    /// A face over the parameter rectangle with `corners` (u0v0, u1v0, u1v1, u0v1) whose
    /// sides lie on `curves` (low v, high u, high v, low u), each running in +u or +v.
    pub fn rect_face(&mut self, surface: u64, corners: [DVec3; 4], curves: [u64; 4]) -> u64 {
        let vs: Vec<u64> = corners.iter().map(|&p| self.vertex(p)).collect();
        let e0 = self.edge(vs[0], vs[1], curves[0], true);
        let e1 = self.edge(vs[1], vs[2], curves[1], true);
        let e2 = self.edge(vs[3], vs[2], curves[2], true);
        let e3 = self.edge(vs[0], vs[3], curves[3], true);
        let b = self.quad_bound(e0, e1, e2, e3);
        self.face(&[b], surface)
    }

    pub fn face(&mut self, bounds: &[u64], surface: u64) -> u64 {
        self.face_with_sense(bounds, surface, true)
    }

    /// A face whose normal is its surface's (`same_sense` true) or the opposite.
    pub fn face_with_sense(&mut self, bounds: &[u64], surface: u64, same_sense: bool) -> u64 {
        let sense = if same_sense { ".T." } else { ".F." };
        let f = self.add(format!(
            "ADVANCED_FACE('',{},#{surface},{sense})",
            refs(bounds)
        ));
        self.faces.push(f);
        f
    }

    /// A rectangle of straight edges through the four corners, as one outer bound.
    pub fn polygon_bound(&mut self, corners: &[DVec3], outer: bool) -> u64 {
        let vs: Vec<u64> = corners.iter().map(|&c| self.vertex(c)).collect();
        let n = corners.len();
        let mut edges = Vec::new();
        for k in 0..n {
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            let l = self.line(a, b - a);
            edges.push((self.edge(vs[k], vs[(k + 1) % n], l, true), true));
        }
        self.bound(&edges, outer)
    }

    /// The unit square [0, 1]² at z = 0 as one planar face of an open shell, in a
    /// SHELL_BASED_SURFACE_MODEL (whose id is returned): the smallest part a placement test
    /// can aim at.
    pub fn unit_square_model(&mut self) -> u64 {
        let ax = self.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let plane = self.add(format!("PLANE('',#{ax})"));
        let sq = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let b = self.polygon_bound(&sq, true);
        let face = self.face(&[b], plane);
        let shell = self.add(format!("OPEN_SHELL('',(#{face}))"));
        self.add(format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"))
    }

    /// A full circle as one closed edge (one vertex at angle 0), as a bound.
    pub fn circle_bound(&mut self, centre: DVec3, z: DVec3, x: DVec3, r: f64, outer: bool) -> u64 {
        let ax = self.axis(centre, z, x);
        let c = self.circle(ax, r);
        let v = self.vertex(centre + r * x.normalize());
        let e = self.edge(v, v, c, true);
        self.bound(&[(e, true)], outer)
    }

    /// B_SPLINE_SURFACE_WITH_KNOTS (rational complex form when `weights` is given):
    /// `points[i][j]`, i along u.
    pub fn bspline_surface(
        &mut self,
        degrees: (usize, usize),
        points: &[Vec<DVec3>],
        knots_u: (&[usize], &[f64]),
        knots_v: (&[usize], &[f64]),
        weights: Option<&[Vec<f64>]>,
    ) -> u64 {
        let rows: Vec<String> = points
            .iter()
            .map(|row| {
                let ids: Vec<u64> = row.iter().map(|&p| self.point(p)).collect();
                refs(&ids)
            })
            .collect();
        let ints = |m: &[usize]| list(&m.iter().map(|k| k.to_string()).collect::<Vec<_>>());
        match weights {
            None => self.add(format!(
                "B_SPLINE_SURFACE_WITH_KNOTS('',{},{},{},.UNSPECIFIED.,.F.,.F.,.F.,{},{},{},{},.UNSPECIFIED.)",
                degrees.0,
                degrees.1,
                list(&rows),
                ints(knots_u.0),
                ints(knots_v.0),
                reals(knots_u.1),
                reals(knots_v.1)
            )),
            Some(w) => {
                let wl: Vec<String> = w.iter().map(|r| reals(r)).collect();
                self.add(format!(
                    "(BOUNDED_SURFACE() B_SPLINE_SURFACE({},{},{},.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS({},{},{},{},.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE({}) REPRESENTATION_ITEM('') SURFACE())",
                    degrees.0,
                    degrees.1,
                    list(&rows),
                    ints(knots_u.0),
                    ints(knots_v.0),
                    reals(knots_u.1),
                    reals(knots_v.1),
                    list(&wl)
                ))
            }
        }
    }

    /// The file: header, the entities, and a product structure whose shape
    /// representation holds one shell of all faces.
    pub fn finish(mut self) -> String {
        let shell = self.add(format!("OPEN_SHELL('',{})", refs(&self.faces.clone())));
        let model = self.add(format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"));
        let mm = self.add("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))");
        let length = match self.unit.clone() {
            None => mm,
            Some((name, size)) => {
                let m = self.add(format!(
                    "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{mm})",
                    real(size)
                ));
                let dim = self.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)");
                self.add(format!(
                    "(CONVERSION_BASED_UNIT('{name}',#{m}) LENGTH_UNIT() NAMED_UNIT(#{dim}))"
                ))
            }
        };
        let rad = self.add("(NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.))");
        let angle = if self.degrees {
            let m = self.add(format!(
                "PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE({}),#{rad})",
                real(std::f64::consts::PI / 180.0)
            ));
            let dim = self.add("DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.)");
            self.add(format!(
                "(CONVERSION_BASED_UNIT('DEGREE',#{m}) NAMED_UNIT(#{dim}) PLANE_ANGLE_UNIT())"
            ))
        } else {
            rad
        };
        let sr = self.add("(NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT())");
        let uncertainty = match self.uncertainty {
            None => String::new(),
            Some(u) => {
                let m = self.add(format!(
                    "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{length},'DISTANCE_ACCURACY_VALUE','')",
                    real(u)
                ));
                format!(" GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{m}))")
            }
        };
        let ctx = self.add(format!(
            "(GEOMETRIC_REPRESENTATION_CONTEXT(3){uncertainty} GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{sr})) REPRESENTATION_CONTEXT('',''))"
        ));
        let origin = self.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let mut items = vec![origin, model];
        items.extend(&self.items);
        self.add(format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',{},#{ctx})",
            refs(&items)
        ));
        self.text()
    }

    /// The file with the entities as they are (no product structure added).
    pub fn text(&self) -> String {
        format!(
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('patchtrace test'),'2;1');\n\
FILE_NAME('test.step','2026-12-01T00:00:00',(''),(''),'','','');\n\
FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n{}\nENDSEC;\nEND-ISO-10303-21;\n",
            self.lines.join("\n")
        )
    }
}

/// B-spline basis function N_{i,p}(t) by the Cox–de Boor recursion (The NURBS Book eq.
/// 2.5), written out independently of the library's A2.2; the last span is closed at the
/// right end.
pub fn basis(i: usize, p: usize, knots: &[f64], t: f64) -> f64 {
    if p == 0 {
        let last = knots[knots.len() - 1];
        let inside = knots[i] <= t && t < knots[i + 1];
        let at_end = t == last && knots[i] < knots[i + 1] && knots[i + 1] == last;
        return if inside || at_end { 1.0 } else { 0.0 };
    }
    let mut out = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        out += (t - knots[i]) / d1 * basis(i, p - 1, knots, t);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        out += (knots[i + p + 1] - t) / d2 * basis(i + 1, p - 1, knots, t);
    }
    out
}

/// Expands (multiplicities, knots) the way STEP writes them.
pub fn expand(m: &[usize], k: &[f64]) -> Vec<f64> {
    m.iter()
        .zip(k)
        .flat_map(|(&n, &t)| std::iter::repeat_n(t, n))
        .collect()
}

/// Dimensions of [`bracket`].
pub const PLATE: f64 = 2.0;
pub const HOLE: f64 = 0.5;
pub const FILLET: f64 = 0.2;

/// A plate `[-2, 2]² × [0, 1]` with a hole of radius 0.5 through it along z, its top edge
/// rounded by a fillet of radius 0.2: a planar top with a circular hole (edges projected),
/// a toroidal fillet bounded by two circles and a seam (projected), a cylindrical hole wall
/// whose seam is a SEAM_CURVE with two pcurves, a bicubic B-spline bottom with the hole
/// (edges projected by point inversion), and four planar sides. `copies` repeats the
/// whole part shifted along x (for the reading benchmark).
pub fn bracket(copies: usize) -> String {
    let mut w = StepWriter::default();
    for k in 0..copies {
        bracket_faces(&mut w, DVec3::new(5.0 * k as f64, 0.0, 0.0));
    }
    w.finish()
}

fn bracket_faces(w: &mut StepWriter, o: DVec3) {
    let (p, a, f) = (PLATE, HOLE, FILLET);
    let big = a + f;
    let zf = 1.0 - f;
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    // Top: plane z = 1 with the fillet's outer circle as a hole.
    let ax = w.axis(o + z, z, x);
    let top = w.add(format!("PLANE('',#{ax})"));
    let corners =
        |h: f64| [(-p, -p), (p, -p), (p, p), (-p, p)].map(|(a, b)| o + DVec3::new(a, b, h));
    let outer = w.polygon_bound(&corners(1.0), true);
    let hole = w.circle_bound(o + z, z, x, big, false);
    w.face(&[outer, hole], top);
    // Fillet: torus about z, tube centre circle at height 1 − f, v from π/2 (top) to π.
    let tax = w.axis(o + zf * z, z, x);
    let torus = w.add(format!(
        "TOROIDAL_SURFACE('',#{tax},{},{})",
        real(big),
        real(f)
    ));
    let (v_top, v_in) = (
        w.vertex(o + DVec3::new(big, 0.0, 1.0)),
        w.vertex(o + DVec3::new(a, 0.0, zf)),
    );
    let c_top_ax = w.axis(o + z, z, x);
    let c_top = w.circle(c_top_ax, big);
    let c_in_ax = w.axis(o + zf * z, z, x);
    let c_in = w.circle(c_in_ax, a);
    let seam_ax = w.axis(o + DVec3::new(big, 0.0, zf), -y, x);
    let seam_c = w.circle(seam_ax, f);
    let e_top = w.edge(v_top, v_top, c_top, true);
    let e_in = w.edge(v_in, v_in, c_in, true);
    // The meridian circle's frame has axis −y and x = +x, so its y is (−y) × x = z:
    // angle π/2 is the top vertex and π the inner one.
    let e_seam = w.edge(v_top, v_in, seam_c, true);
    let b = w.quad_bound(e_top, e_seam, e_in, e_seam);
    w.face(&[b], torus);
    // Hole wall: cylinder r = a from z = 0 to 1 − f, seam at angle 0 with pcurves.
    let cax = w.axis(o, z, x);
    let cyl = w.add(format!("CYLINDRICAL_SURFACE('',#{cax},{})", real(a)));
    let v_low = w.vertex(o + DVec3::new(a, 0.0, 0.0));
    let c_low_ax = w.axis(o, z, x);
    let c_low = w.circle(c_low_ax, a);
    let e_low = w.edge(v_low, v_low, c_low, true);
    let seam3 = w.line(o + DVec3::new(a, 0.0, 0.0), z);
    let mut pcurves = Vec::new();
    for u in [0.0, std::f64::consts::TAU] {
        let l = w.line2(DVec2::new(u, 0.0), DVec2::Y);
        let rep = w.add(format!("DEFINITIONAL_REPRESENTATION('',(#{l}),#{l})"));
        pcurves.push(w.add(format!("PCURVE('',#{cyl},#{rep})")));
    }
    let seam = w.add(format!(
        "SEAM_CURVE('',#{seam3},(#{},#{}),.PCURVE_S1.)",
        pcurves[0], pcurves[1]
    ));
    let e_wall = w.edge(v_low, v_in, seam, true);
    let e_in2 = w.edge(v_in, v_in, c_in, true);
    let b = w.quad_bound(e_low, e_wall, e_in2, e_wall);
    w.face(&[b], cyl);
    // Bottom: a flat bicubic B-spline over the square, knots with an interior break.
    let n = 5;
    let pts: Vec<Vec<DVec3>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let s = |k: usize| -p + 2.0 * p * [0.0, 0.2, 0.5, 0.8, 1.0][k];
                    o + DVec3::new(s(i), s(j), 0.0)
                })
                .collect()
        })
        .collect();
    let bottom = w.bspline_surface(
        (3, 3),
        &pts,
        (&[4, 1, 4], &[0.0, 0.5, 1.0]),
        (&[4, 1, 4], &[0.0, 0.5, 1.0]),
        None,
    );
    let outer = w.polygon_bound(&corners(0.0), true);
    let hole = w.circle_bound(o, z, x, a, false);
    w.face(&[outer, hole], bottom);
    // Sides.
    for (normal, along) in [(x, y), (-x, -y), (y, -x), (-y, x)] {
        let c = o + p * normal;
        let sax = w.axis(c, normal, along);
        let side = w.add(format!("PLANE('',#{sax})"));
        let q = [
            c - p * along,
            c + p * along,
            c + p * along + z,
            c - p * along + z,
        ];
        let b = w.polygon_bound(&q, true);
        w.face(&[b], side);
    }
}
