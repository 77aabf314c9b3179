//! A closed surface repeated over whole periods of its parameter, for trim loops that a
//! writer draws across the seam of a closed surface (a loop over u in [−π/2, π/2] on a
//! torus whose knots run over [0, 2π]). OpenCASCADE makes such surfaces periodic on
//! reading (`IGESToBRep_BasicSurface::TransferBSplineSurface`, "force periodicity on any
//! closed surface"); here the periods the loops reach are laid side by side as one
//! surface: copies of the clamped control net with their knots shifted by the period,
//! joined by knots of multiplicity degree + 1 (breaks, see `knots`). The geometry is the
//! surface's own, exactly.

use super::curve::NurbsCurve;
use super::surface::NurbsSurface;
use crate::geom::bezier::dehomogenize;

impl NurbsSurface {
    /// Whether the surface closes on itself in u: on its clamped net, the first and last
    /// control points of every row coincide within `tolerance` (a length).
    pub fn is_closed_u(&self, tolerance: f64) -> bool {
        let c = self.clamped();
        (0..c.count_v).all(|j| {
            let row = &c.points[j * c.count_u..(j + 1) * c.count_u];
            (dehomogenize(row[0]) - dehomogenize(row[c.count_u - 1])).length() <= tolerance
        })
    }

    /// The surface over `before` periods before its u domain, the domain, and `after`
    /// periods after it (the period is the domain's length).
    pub fn repeated_u(&self, before: usize, after: usize) -> NurbsSurface {
        let c = self.clamped();
        let p = c.degree_u;
        let (a, b) = super::knots::domain(p, &c.knots_u);
        let period = b - a;
        let copies = before + 1 + after;
        let shift = |k: usize| (k as f64 - before as f64) * period;
        // The first copy's knots whole, then each next copy's without its first p + 1
        // (the previous copy's last p + 1 stand for them: a break).
        let mut knots: Vec<f64> = c.knots_u.iter().map(|t| t + shift(0)).collect();
        for k in 1..copies {
            knots.extend(c.knots_u[p + 1..].iter().map(|t| t + shift(k)));
        }
        c.map_rows_u(|row: &NurbsCurve| NurbsCurve {
            degree: p,
            knots: knots.clone(),
            points: (0..copies)
                .flat_map(|_| row.points.iter().copied())
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::geom::nurbs::shapes::torus;

    #[test]
    fn a_torus_repeated_is_the_torus_shifted_by_its_period() {
        let t = torus(2.0, 0.5).unwrap();
        assert!(t.is_closed_u(1e-12));
        let d = t.domain();
        let r = t.repeated_u(1, 1);
        assert!(r.validate().is_ok());
        let e = r.domain();
        let period = d.u1 - d.u0;
        assert_eq!((e.u0, e.u1), (d.u0 - period, d.u1 + period));
        for k in 0..=20 {
            let u = d.u0 + period * k as f64 / 20.0;
            let v = d.v0 + (d.v1 - d.v0) * ((k * 7) % 20) as f64 / 20.0;
            for s in [-period, 0.0, period] {
                let x = (r.eval(u + s, v) - t.eval(u, v)).length();
                assert!(x < 1e-12, "{x} at ({u}, {v}) shifted {s}");
            }
        }
        // Not closed: a bilinear sheet.
        let sheet = crate::geom::nurbs::NurbsSurface::new(
            1,
            1,
            vec![0., 0., 1., 1.],
            vec![0., 0., 1., 1.],
            2,
            2,
            vec![
                glam::DVec4::new(0., 0., 0., 1.),
                glam::DVec4::new(1., 0., 0., 1.),
                glam::DVec4::new(0., 1., 0., 1.),
                glam::DVec4::new(1., 1., 0., 1.),
            ],
        )
        .unwrap();
        assert!(!sheet.is_closed_u(1e-9));
    }
}
