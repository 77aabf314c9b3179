//! Placements (ISO 10303-42 geometry schema): CARTESIAN_POINT, DIRECTION and the axis
//! placements that frame every elementary curve and surface.

use glam::DVec3;

use super::{Frame, Rec, Resolver};
use crate::formats::cad::step::records::Value;
use crate::formats::error::ParseError;

impl<'e, 'a> Resolver<'e, 'a> {
    /// CARTESIAN_POINT (2D points get z = 0).
    pub fn point(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let r = self.follow(from, i, &["CARTESIAN_POINT"])?;
        self.coordinates(&r, 1, "coordinates")
    }

    pub(super) fn coordinates(&self, r: &Rec, i: usize, what: &str) -> Result<DVec3, ParseError> {
        let p = r.param(i, what)?;
        let c = r.numbers(p, what)?;
        match c[..] {
            [x, y] => Ok(DVec3::new(x, y, 0.0)),
            [x, y, z] => Ok(DVec3::new(x, y, z)),
            _ => Err(r.error_at(
                p.line,
                p.column,
                format!("expected 2 or 3 {what}, found {}", c.len()),
            )),
        }
    }

    /// DIRECTION, normalised; a zero direction is an error.
    pub fn direction(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let r = self.follow(from, i, &["DIRECTION"])?;
        let d = self.coordinates(&r, 1, "direction ratios")?;
        let n = d.normalize_or_zero();
        if n == DVec3::ZERO || !n.is_finite() {
            return Err(r.error("expected a non-zero direction"));
        }
        Ok(n)
    }

    /// AXIS2_PLACEMENT_3D (location, axis, ref_direction; the last two optional) or
    /// AXIS2_PLACEMENT_2D (location, ref_direction).
    pub fn frame(&self, from: &Rec, i: usize) -> Result<Frame, ParseError> {
        let r = self.follow(from, i, &["AXIS2_PLACEMENT_3D", "AXIS2_PLACEMENT_2D"])?;
        self.deeper(&r, || self.frame_of(&r))
    }

    pub fn frame_of(&self, r: &Rec) -> Result<Frame, ParseError> {
        let origin = self.point(r, 1)?;
        let optional_dir = |i: usize| -> Result<Option<DVec3>, ParseError> {
            match r.rec.params.get(i).map(|p| &p.value) {
                None | Some(Value::Unset) => Ok(None),
                _ => self.direction(r, i).map(Some),
            }
        };
        let (z, x_hint) = if r.rec.name == "AXIS2_PLACEMENT_2D" {
            (Some(DVec3::Z), optional_dir(2)?)
        } else {
            (optional_dir(2)?, optional_dir(3)?)
        };
        // ISO 10303-42 build_axes: a default axis is z, a default or parallel
        // ref_direction falls back to a world axis.
        Frame::new(origin, z.unwrap_or(DVec3::Z), x_hint).map_err(|e| r.error(e.to_string()))
    }
}
