//! NURBS surfaces: knot vectors, Cox–de Boor evaluation, Boehm knot insertion and exact
//! decomposition into Bézier patches (Piegl & Tiller, *The NURBS Book*, A2.2, A5.1, A5.7;
//! Dammertz 2005, §2.8).

use glam::{DVec3, DVec4};

use super::bezier::{BezierPatch, GeomError};

/// A NURBS surface with homogeneous premultiplied control points, u index fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsSurface {
    pub degree_u: usize,
    pub degree_v: usize,
    pub knots_u: Vec<f64>,
    pub knots_v: Vec<f64>,
    pub count_u: usize,
    pub count_v: usize,
    pub points: Vec<DVec4>,
}

impl NurbsSurface {
    /// Validates and builds a surface.
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        count_u: usize,
        count_v: usize,
        points: Vec<DVec4>,
    ) -> Result<Self, GeomError> {
        Ok(NurbsSurface {
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            count_u,
            count_v,
            points,
        })
    }

    /// Surface point at parameters (u, v), Cox–de Boor in f64.
    pub fn eval(&self, _u: f64, _v: f64) -> DVec3 {
        unimplemented!("nurbs evaluation")
    }

    /// Exact decomposition into Bézier patches in span order, u spans fastest.
    pub fn to_bezier_patches(&self) -> Vec<BezierPatch> {
        unimplemented!("nurbs decomposition")
    }

    pub fn transform(&mut self, m: &glam::DAffine3) {
        for p in &mut self.points {
            let e = m.transform_point3(p.truncate() / p.w);
            *p = (e * p.w).extend(p.w);
        }
    }
}
