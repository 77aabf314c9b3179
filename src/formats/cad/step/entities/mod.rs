//! Typed, validated STEP entities (ISO 10303-42 geometry and topology, the AP203/AP214/
//! AP242 subset a B-rep needs), read from the exchange structure by following references
//! (OpenCASCADE's StepGeom/StepShape layer). Every accessor checks the parameter's kind and
//! count and names the instance in its error (`#12 CIRCLE: expected a positive radius`);
//! reference chains are bounded so a cyclic file cannot recurse forever.
//!
//! - `record`: one record's parameters, each accessor checking its kind.
//! - `placement`: points, directions and axis placements.
//! - `bspline`: what B-spline curves and surfaces share (knots listed or implied,
//!   weights).
//! - `curves`, `surfaces`: the geometry a face is made of, by entity.
//! - `faces`: topology, faces to their bounds, edges and vertices.

mod bspline;
mod curves;
mod faces;
mod placement;
mod record;
mod surfaces;

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::records::{Exchange, Instance, Record};
use crate::formats::error::ParseError;
pub use crate::geom::nurbs::analytic::Frame;

pub use self::curves::{Curve, PCurve};
pub use self::faces::{Bound, Edge, Face, OrientedEdge};
pub use self::surfaces::SurfaceDef;

/// Longest chain of references followed while resolving one entity. Real B-reps are about
/// ten deep (face → loop → edge → curve → placement → direction); a cycle in a damaged
/// file reaches the bound and is reported instead of overflowing the stack.
const MAX_DEPTH: usize = 200;

/// Reads typed entities from an exchange structure, caching shared ones.
pub struct Resolver<'e, 'a> {
    pub ex: &'e Exchange<'a>,
    pub path: &'e Path,
    /// Radians per unit of plane angle in the file (1, or π/180 for degrees).
    pub angle_unit: f64,
    depth: Cell<usize>,
    curves: RefCell<HashMap<u64, Arc<Curve>>>,
    surfaces: RefCell<HashMap<u64, Arc<SurfaceDef>>>,
    edges: RefCell<HashMap<u64, Arc<Edge>>>,
    /// The type of the last valid but unsupported entity met (an OFFSET_SURFACE under a
    /// face), which makes its face skipped rather than the file refused.
    unsupported: RefCell<Option<String>>,
}

/// One record of one instance, with accessors that check kinds and locate errors.
#[derive(Clone, Copy)]
pub struct Rec<'r, 'a> {
    pub path: &'r Path,
    pub inst: &'r Instance<'a>,
    pub rec: &'r Record<'a>,
}

impl<'e, 'a> Resolver<'e, 'a> {
    pub fn new(ex: &'e Exchange<'a>, path: &'e Path) -> Self {
        Resolver {
            ex,
            path,
            angle_unit: 1.0,
            depth: Cell::new(0),
            curves: RefCell::default(),
            surfaces: RefCell::default(),
            edges: RefCell::default(),
            unsupported: RefCell::default(),
        }
    }

    /// Takes the type of the unsupported entity met since the last call, if any.
    pub fn take_unsupported(&self) -> Option<String> {
        self.unsupported.borrow_mut().take()
    }

    pub(super) fn unsupported(&self, r: &Rec, what: &str) -> ParseError {
        *self.unsupported.borrow_mut() = Some(r.inst.type_name().into_owned());
        r.error(format!("expected {what}"))
    }

    /// The instance `id`, referenced from parameter `p` of `from`.
    pub fn instance(&self, from: &Rec, id: u64) -> Result<&'e Instance<'a>, ParseError> {
        self.ex.get(id).ok_or_else(|| {
            from.error(format!(
                "references #{id}, which is not defined in the file"
            ))
        })
    }

    /// The record `name` of `inst` (its only record for a simple instance).
    pub fn rec<'r>(&'r self, inst: &'r Instance<'a>) -> Rec<'r, 'a> {
        Rec {
            path: self.path,
            inst,
            rec: &inst.records[0],
        }
    }

    pub fn named<'r>(&'r self, inst: &'r Instance<'a>, name: &str) -> Option<Rec<'r, 'a>> {
        inst.record(name).map(|rec| Rec {
            path: self.path,
            inst,
            rec,
        })
    }

    /// Runs `f` one reference level deeper, failing past [`MAX_DEPTH`].
    pub(super) fn deeper<T>(
        &self,
        from: &Rec,
        f: impl FnOnce() -> Result<T, ParseError>,
    ) -> Result<T, ParseError> {
        let d = self.depth.get();
        if d >= MAX_DEPTH {
            return Err(from.error(format!(
                "references nest deeper than {MAX_DEPTH} (a reference cycle?)"
            )));
        }
        self.depth.set(d + 1);
        let out = f();
        self.depth.set(d);
        out
    }

    /// Follows parameter `i` of `from` to an instance that must be one of `types`.
    pub(super) fn follow<'r>(
        &'r self,
        from: &Rec,
        i: usize,
        types: &[&str],
    ) -> Result<Rec<'r, 'a>, ParseError> {
        let what = types.join(" or ");
        let id = from.reference(i, &what)?;
        self.expect_type(from, id, types, i)
    }

    pub(super) fn expect_type<'r>(
        &'r self,
        from: &Rec,
        id: u64,
        types: &[&str],
        i: usize,
    ) -> Result<Rec<'r, 'a>, ParseError> {
        let inst = self.instance(from, id)?;
        for t in types {
            if let Some(r) = self.named(inst, t) {
                return Ok(r);
            }
        }
        let p = &from.rec.params[i.min(from.rec.params.len().saturating_sub(1))];
        Err(from.error_at(
            p.line,
            p.column,
            format!(
                "expected a reference to {}, found #{id} {}",
                types.join(" or "),
                inst.type_name()
            ),
        ))
    }

    /// Entity `id` from `cache`, or read by `read` one level deeper and kept.
    fn cached<T>(
        &self,
        cache: &RefCell<HashMap<u64, Arc<T>>>,
        from: &Rec,
        id: u64,
        read: impl FnOnce(&'e Instance<'a>) -> Result<T, ParseError>,
    ) -> Result<Arc<T>, ParseError> {
        if let Some(c) = cache.borrow().get(&id) {
            return Ok(c.clone());
        }
        let inst = self.instance(from, id)?;
        let c = Arc::new(self.deeper(from, || read(inst))?);
        cache.borrow_mut().insert(id, c.clone());
        Ok(c)
    }
}
