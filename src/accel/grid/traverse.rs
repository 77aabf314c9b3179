//! Space tracing through the grid (LG90 §3.1, the scheme at the end of the section): walk
//! the voxels along the ray with the DDA; in each, test every registered primitive not yet
//! seen by this ray (the mailbox) against its tight box, try the survivors nearest box
//! first, and stop after the voxel that holds the closest hit so far (the hit lies before
//! the voxel's exit, so no later voxel can hold a nearer one).

use std::cell::RefCell;

use super::Grid;
use crate::geom::Ray;

/// Work done by one grid traversal, for `--stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GridStats {
    /// Voxels the DDA stepped through, empty ones included.
    pub voxels_visited: u64,
    /// Ray–box tests against tight primitive boxes (once per primitive per ray).
    pub box_tests: u64,
}

/// LG90's mailboxes, one set per thread (rays on different rayon workers must not see each
/// other's numbers): `stamps[prim]` is the number of the last ray tested against `prim`.
#[derive(Default)]
struct Mailbox {
    grid: u64,
    ray: u32,
    stamps: Vec<u32>,
    /// Primitives of the current voxel that passed their box test: (entry t, primitive).
    candidates: Vec<(f32, u32)>,
}

impl Mailbox {
    /// Starts a new ray on `grid`: a fresh ray number, and cleared stamps when the grid
    /// changed or the numbers wrapped around.
    fn next_ray(&mut self, grid: &Grid) -> u32 {
        if self.grid != grid.id || self.stamps.len() != grid.boxes.len() {
            self.grid = grid.id;
            self.stamps.clear();
            self.stamps.resize(grid.boxes.len(), 0);
            self.ray = 0;
        }
        self.ray = self.ray.wrapping_add(1);
        if self.ray == 0 {
            self.stamps.fill(0);
            self.ray = 1;
        }
        self.ray
    }
}

thread_local! {
    static MAILBOX: RefCell<Mailbox> = RefCell::new(Mailbox::default());
}

/// Runs `f` with this thread's mailbox, or with a fresh one if a caller's `hit` closure
/// queries a grid from inside a traversal (then the outer one holds the thread's).
fn with_mailbox<R>(f: impl FnOnce(&mut Mailbox) -> R) -> R {
    MAILBOX.with(|m| match m.try_borrow_mut() {
        Ok(mut m) => f(&mut m),
        Err(_) => f(&mut Mailbox::default()),
    })
}

impl Grid {
    /// Nearest-hit traversal: calls `hit(prim, tmax)` at most once per primitive whose
    /// tight box the ray enters before the current `tmax` (starting at `ray.tmax`); a
    /// returned `t` shortens `tmax`. Within a voxel primitives are tried in order of box
    /// entry; the walk ends after the voxel whose exit lies at or beyond `tmax`.
    pub fn traverse<F: FnMut(u32, f32) -> Option<f32>>(&self, ray: &Ray, mut hit: F) -> GridStats {
        let mut stats = GridStats::default();
        let inv_dir = ray.dir.recip();
        let mut tmax = ray.tmax;
        with_mailbox(|mb| {
            let id = mb.next_ray(self);
            for voxel in self.voxels(ray) {
                stats.voxels_visited += 1;
                mb.candidates.clear();
                for &prim in self.cells.get(self.key(voxel.cell)) {
                    let stamp = &mut mb.stamps[prim as usize];
                    if *stamp == id {
                        continue;
                    }
                    *stamp = id;
                    stats.box_tests += 1;
                    let b = &self.boxes[prim as usize];
                    if let Some((t, _)) = b.intersect(ray.origin, inv_dir, ray.tmin, tmax) {
                        mb.candidates.push((t, prim));
                    }
                }
                mb.candidates.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                for &(t_enter, prim) in &mb.candidates {
                    if t_enter > tmax {
                        break;
                    }
                    if let Some(t) = hit(prim, tmax) {
                        tmax = tmax.min(t);
                    }
                }
                if f64::from(tmax) <= voxel.t_exit {
                    break;
                }
            }
        });
        stats
    }

    /// Any-hit traversal for shadow rays: calls `hit(prim)` at most once per primitive
    /// whose tight box the ray meets within `[ray.tmin, ray.tmax]`, and stops at the first
    /// that returns `true`.
    pub fn traverse_any<F: FnMut(u32) -> bool>(&self, ray: &Ray, mut hit: F) -> (bool, GridStats) {
        let mut stats = GridStats::default();
        let inv_dir = ray.dir.recip();
        let found = with_mailbox(|mb| {
            let id = mb.next_ray(self);
            for voxel in self.voxels(ray) {
                stats.voxels_visited += 1;
                for &prim in self.cells.get(self.key(voxel.cell)) {
                    let stamp = &mut mb.stamps[prim as usize];
                    if *stamp == id {
                        continue;
                    }
                    *stamp = id;
                    stats.box_tests += 1;
                    let b = &self.boxes[prim as usize];
                    if b.intersect(ray.origin, inv_dir, ray.tmin, ray.tmax)
                        .is_some()
                        && hit(prim)
                    {
                        return true;
                    }
                }
            }
            false
        });
        (found, stats)
    }
}
