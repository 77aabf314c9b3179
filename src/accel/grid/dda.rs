//! 3D DDA (Amanatides and Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing", 1987):
//! the voxels a ray passes through, in order, each with the parameter interval it spends
//! there. Crossing times are computed in `f64` from the plane positions, not accumulated,
//! so they do not drift along long rays.

use glam::DVec3;

use super::Grid;
use crate::geom::Ray;

/// One voxel along a ray: its cell and the `t` interval of the ray inside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Voxel {
    pub cell: [u32; 3],
    pub t_enter: f64,
    pub t_exit: f64,
}

/// Iterator over the voxels of a grid along a ray, nearest first, within the ray's
/// `[tmin, tmax]`.
#[derive(Clone, Debug)]
pub struct Dda {
    cell: [i64; 3],
    dims: [i64; 3],
    step: [i64; 3],
    /// Index of the next grid plane crossed on each axis.
    plane: [i64; 3],
    t_next: [f64; 3],
    t: f64,
    t_end: f64,
    origin: DVec3,
    inv_dir: DVec3,
    lo: DVec3,
    edge: f64,
    done: bool,
}

impl Dda {
    pub(super) fn new(grid: &Grid, ray: &Ray) -> Dda {
        let origin = ray.origin.as_dvec3();
        let dir = ray.dir.as_dvec3();
        let inv_dir = dir.recip();
        let dims = grid.dims.map(i64::from);
        let hi = grid.lo + DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * grid.edge;
        let bounds = crate::geom::DAabb {
            min: grid.lo,
            max: hi,
        };
        let span = bounds.intersect(origin, inv_dir, ray.tmin as f64, ray.tmax as f64);
        let (t, t_end) = span.unwrap_or((0.0, -1.0));
        let entry = origin + dir * t;
        let mut dda = Dda {
            cell: [0; 3],
            dims,
            step: [0; 3],
            plane: [0; 3],
            t_next: [f64::INFINITY; 3],
            t,
            t_end,
            origin,
            inv_dir,
            lo: grid.lo,
            edge: grid.edge,
            // A non-finite origin or direction gives NaN crossing times, which would step
            // an axis the ray does not move along forever.
            done: span.is_none()
                || grid.cells.cell_count() == 0
                || !(origin.is_finite() && dir.is_finite()),
        };
        for a in 0..3 {
            let c = ((entry[a] - grid.lo[a]) / grid.edge).floor();
            // Rounding of the entry point may land a hair outside; clamp into the grid.
            dda.cell[a] = (c as i64).clamp(0, dims[a] - 1);
            if dir[a] != 0.0 {
                dda.step[a] = if dir[a] > 0.0 { 1 } else { -1 };
                dda.plane[a] = dda.cell[a] + i64::from(dir[a] > 0.0);
                dda.t_next[a] = dda.plane_t(a);
            }
        }
        dda
    }

    fn plane_t(&self, a: usize) -> f64 {
        (self.lo[a] + self.plane[a] as f64 * self.edge - self.origin[a]) * self.inv_dir[a]
    }
}

impl Iterator for Dda {
    type Item = Voxel;

    fn next(&mut self) -> Option<Voxel> {
        if self.done {
            return None;
        }
        let t = self.t_next;
        let a = if t[0] <= t[1] && t[0] <= t[2] {
            0
        } else if t[1] <= t[2] {
            1
        } else {
            2
        };
        let voxel = Voxel {
            cell: self.cell.map(|c| c as u32),
            t_enter: self.t,
            t_exit: t[a].min(self.t_end),
        };
        if t[a] >= self.t_end {
            self.done = true;
        } else {
            self.cell[a] += self.step[a];
            self.done = !(0..self.dims[a]).contains(&self.cell[a]);
            self.t = t[a];
            self.plane[a] += self.step[a];
            self.t_next[a] = self.plane_t(a);
        }
        Some(voxel)
    }
}
