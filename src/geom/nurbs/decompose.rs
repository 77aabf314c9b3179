//! Exact decomposition into Bézier pieces (Piegl & Tiller, *The NURBS Book*, A5.6
//! DecomposeCurve; A5.7 DecomposeSurface is A5.6 on every row, then on every column of
//! the resulting strips), the NURBS→Bézier conversion of Dammertz 2005, §2.8.
//!
//! A5.6 raises every interior knot to multiplicity p in one sweep over the control
//! polygon, emitting one Bézier segment per non-empty span: repeated knots form a single
//! breakpoint, so zero-length spans never produce a piece. Each new point is a convex
//! combination of old ones (as in Boehm insertion), so weights stay positive. A knot of
//! multiplicity p + 1 (a break, see `knots`) needs no insertion: the next segment is the
//! p + 1 control points after it, as for multiplicity p.

use glam::DVec4;

use super::curve::NurbsCurve;
use super::surface::NurbsSurface;
use crate::geom::MAX_DEGREE;
use crate::geom::bezier::{BezierPatch, GeomError, ParamRect};

/// One Bézier piece of a curve: `degree + 1` homogeneous points over `[t0, t1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierSegment {
    pub t0: f64,
    pub t1: f64,
    pub points: Vec<DVec4>,
}

impl NurbsCurve {
    /// The Bézier segments of the non-empty spans of the domain, in order (A5.6, after
    /// clamping unclamped ends).
    pub fn bezier_segments(&self) -> Vec<BezierSegment> {
        let c = self.clamped();
        let (p, u, pw) = (c.degree, &c.knots, &c.points);
        let m = u.len() - 1;
        let mut segments = Vec::new();
        let mut current: Vec<DVec4> = pw[..=p].to_vec();
        let mut next = vec![DVec4::ZERO; p + 1];
        let mut alphas = [0.0; MAX_DEGREE];
        let (mut a, mut b) = (p, p + 1);
        while b < m {
            let i = b;
            while b < m && u[b + 1] == u[b] {
                b += 1;
            }
            let mult = b - i + 1;
            if mult < p {
                // Insert u[b] until its multiplicity is p.
                let numer = u[b] - u[a];
                for j in (mult + 1..=p).rev() {
                    alphas[j - mult - 1] = numer / (u[a + j] - u[a]);
                }
                let r = p - mult;
                for j in 1..=r {
                    let s = mult + j;
                    for k in (s..=p).rev() {
                        let alpha = alphas[k - s];
                        current[k] = current[k] * alpha + current[k - 1] * (1.0 - alpha);
                    }
                    if b < m {
                        // The next segment's leading points, in reverse order.
                        next[r - j] = current[p];
                    }
                }
            }
            segments.push(BezierSegment {
                t0: u[a],
                t1: u[b],
                points: current.clone(),
            });
            if b < m {
                // At a break (multiplicity p + 1) the points of the next segment are the
                // p + 1 after it, exactly as at multiplicity p.
                let mult = mult.min(p);
                next[p - mult..=p].copy_from_slice(&pw[b - mult..=b]);
                std::mem::swap(&mut current, &mut next);
                a = b;
                b += 1;
            }
        }
        segments
    }
}

impl NurbsSurface {
    /// Exact decomposition into Bézier patches, in span order with u spans fastest; each
    /// patch's domain is its knot span. Zero-length spans are skipped. A surface that fails
    /// [`NurbsSurface::validate`] (possible only by editing the public fields, or by a
    /// transform that overflows) yields no patches; [`Self::try_to_bezier_patches`] says why.
    pub fn to_bezier_patches(&self) -> Vec<BezierPatch> {
        self.try_to_bezier_patches().unwrap_or_default()
    }

    /// As [`Self::to_bezier_patches`], reporting an invalid surface as an error.
    pub fn try_to_bezier_patches(&self) -> Result<Vec<BezierPatch>, GeomError> {
        self.validate()?;
        let (pu, pv) = (self.degree_u, self.degree_v);
        // A5.7 step 1: every row in u; rows[j][a] is segment a of row j.
        let rows: Vec<Vec<BezierSegment>> = (0..self.count_v)
            .map(|j| self.row_u(j).bezier_segments())
            .collect();
        // Step 2: every column i of every u strip a, in v; columns[a][i][b].
        let columns: Vec<Vec<Vec<BezierSegment>>> = (0..rows[0].len())
            .map(|a| {
                (0..=pu)
                    .map(|i| {
                        NurbsCurve {
                            degree: pv,
                            knots: self.knots_v.clone(),
                            points: rows.iter().map(|row| row[a].points[i]).collect(),
                        }
                        .bezier_segments()
                    })
                    .collect()
            })
            .collect();
        let mut patches = Vec::with_capacity(rows[0].len() * columns[0][0].len());
        for b in 0..columns[0][0].len() {
            for (a, strip) in columns.iter().enumerate() {
                let points = (0..=pv)
                    .flat_map(|j| strip.iter().map(move |column| column[b].points[j]))
                    .collect();
                let domain = ParamRect {
                    u0: rows[0][a].t0,
                    u1: rows[0][a].t1,
                    v0: strip[0][b].t0,
                    v1: strip[0][b].t1,
                };
                patches.push(BezierPatch::new(pu, pv, points)?.with_domain(domain));
            }
        }
        Ok(patches)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::knots;
    use crate::geom::nurbs::testutil::{breakpoints, knot_vector, surface};
    use proptest::prelude::*;

    /// The patch whose domain holds (u, v), and the local parameters there; on a shared
    /// edge the later patch, as evaluation takes the span to the right of a knot (A2.1),
    /// which matters at a break.
    fn locate(patches: &[BezierPatch], u: f64, v: f64) -> Option<(&BezierPatch, f64, f64)> {
        patches.iter().rev().find_map(|p| {
            let d = p.domain();
            (d.u0 <= u && u <= d.u1 && d.v0 <= v && v <= d.v1)
                .then(|| (p, (u - d.u0) / (d.u1 - d.u0), (v - d.v0) / (d.v1 - d.v0)))
        })
    }

    proptest! {
        #[test]
        fn decomposition_is_exact(
            s in surface(),
            params in prop::collection::vec((0.0..=1.0f64, 0.0..=1.0f64), 16),
        ) {
            let patches = s.to_bezier_patches();
            let spans_u = breakpoints(s.degree_u, &s.knots_u).len() - 1;
            let spans_v = breakpoints(s.degree_v, &s.knots_v).len() - 1;
            prop_assert_eq!(patches.len(), spans_u * spans_v);
            // Span order, u fastest.
            for (k, p) in patches.iter().enumerate() {
                let (a, b) = (k % spans_u, k / spans_u);
                let d = p.domain();
                prop_assert_eq!((d.u0, d.v0), (breakpoints(s.degree_u, &s.knots_u)[a],
                    breakpoints(s.degree_v, &s.knots_v)[b]));
                prop_assert_eq!((p.degree_u(), p.degree_v()), (s.degree_u, s.degree_v));
            }
            let tolerance = 1e-12 * s.net_diagonal();
            for (u, v) in params {
                let (patch, lu, lv) = locate(&patches, u, v).expect("patches cover the domain");
                let dev = (patch.eval(lu, lv) - s.eval(u, v)).length();
                prop_assert!(dev <= tolerance, "deviation {} at ({}, {})", dev, u, v);
            }
        }

        /// A5.6 gives the same control points as inserting every interior knot up to
        /// multiplicity p with A5.1 and taking each span's p + 1 points.
        #[test]
        fn segments_match_repeated_insertion(
            (p, knots, points) in (1usize..=5, any::<bool>())
                .prop_flat_map(|(p, c)| (Just(p), knot_vector(p, c)))
                .prop_flat_map(|(p, k)| {
                    let n = k.len() - p - 1;
                    (Just(p), Just(k), prop::collection::vec(
                        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, 0.1..=10.0f64)
                            .prop_map(|(x, y, z, w)| DVec4::new(x * w, y * w, z * w, w)), n))
                }),
        ) {
            let curve = NurbsCurve { degree: p, knots, points };
            let mut inserted = curve.clamped();
            let breaks = breakpoints(p, &curve.knots);
            for &t in &breaks[1..breaks.len() - 1] {
                let s = knots::multiplicity(&inserted.knots, t);
                if s < p {
                    inserted = inserted.insert_knot(t, p - s).unwrap();
                }
            }
            let segments = curve.bezier_segments();
            prop_assert_eq!(segments.len(), breaks.len() - 1);
            let scale = curve.points.iter().map(|q| q.abs().max_element()).fold(0.0, f64::max);
            for (k, seg) in segments.iter().enumerate() {
                prop_assert_eq!((seg.t0, seg.t1), (breaks[k], breaks[k + 1]));
                // Every interior knot now has multiplicity p or p + 1: the span starting
                // at t0 (last knot index i with knots[i] <= t0) has the p + 1 points
                // i - p ..= i (The NURBS Book P2.2).
                let i = inserted.knots.partition_point(|&x| x <= seg.t0) - 1;
                for (a, b) in seg.points.iter().zip(&inserted.points[i - p..=i]) {
                    prop_assert!((*a - *b).abs().max_element() <= 1e-13 * scale, "{} vs {}", a, b);
                }
            }
        }
    }

    #[test]
    fn invalid_surface_gives_no_patches() {
        let mut s = crate::geom::nurbs::shapes::torus(2.0, 0.5).unwrap();
        s.points[3].w = -1.0;
        assert!(s.to_bezier_patches().is_empty());
        assert_eq!(
            s.try_to_bezier_patches().unwrap_err(),
            GeomError::Weight {
                index: 3,
                weight: -1.0
            }
        );
    }
}
