//! Catmull–Clark subdivision surfaces as Bézier patches (Dammertz §2.9; Catmull & Clark
//! 1978), so the float-precision kernel ray traces their exact limit surface.
//!
//! - [`topology`]: the polygon cage (checked manifold, consistently wound) and adjacency.
//! - [`refine`]: one Catmull–Clark step with OpenSubdiv's `EDGE_ONLY` boundaries.
//! - [`net`], [`stencil`]: a quad's 4×4 B-spline net and its exact Bézier form, summed so
//!   that neighbours agree bit for bit.
//! - [`limit`]: limit positions and normals at vertices.
//! - [`adaptive`]: regular faces as Bézier patches, faces with an extraordinary vertex
//!   refined into regular children down to the kernel's precision.
//!
//! Holes (OpenSubdiv's hole tags, USD's `holeIndices`): a cage face marked as a hole has
//! no limit patch, but its points still shape its neighbours' limit surface, which is
//! the same as without the hole.
//!
//! Parameterisation (the `trace` contract's `patch`, `u`, `v`): after the first step every
//! face of the cage with n corners has become n quads; they are numbered in cage face
//! order, corner by corner (face f's quad at its corner i is number `Σ_{g<f} n_g + i`).
//! Quad `[vertex point of corner i, edge point towards corner i + 1, face point, edge point
//! towards corner i - 1]` has u along its first edge and v along its last, each in [0, 1].

pub mod adaptive;
pub mod limit;
pub mod net;
pub mod refine;
pub mod stencil;
pub mod topology;

use glam::DVec3;

pub use topology::{CageError, Mesh};

use crate::geom::BezierPatch;

/// Where a Bézier patch lies in its quad after the first step: quad-local `(u, v)` is
/// `origin + size · R(rot) (u, v)`, R the rotation by `rot` quarter turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    pub face: u32,
    pub rot: u8,
    pub origin: (f64, f64),
    pub size: f64,
}

fn rotate(rot: u8, (x, y): (f64, f64)) -> (f64, f64) {
    match rot % 4 {
        0 => (x, y),
        1 => (-y, x),
        2 => (-x, -y),
        _ => (y, -x),
    }
}

impl Piece {
    pub fn whole(face: u32) -> Piece {
        Piece {
            face,
            rot: 0,
            origin: (0.0, 0.0),
            size: 1.0,
        }
    }

    /// The child at corner `i` after one more step (children turn by `i` quarter turns:
    /// their u runs from corner i towards corner i + 1).
    pub fn child(&self, i: usize) -> Piece {
        let corner = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][i];
        let (dx, dy) = rotate(self.rot, corner);
        Piece {
            face: self.face,
            rot: (self.rot + i as u8) % 4,
            origin: (
                self.origin.0 + self.size * dx,
                self.origin.1 + self.size * dy,
            ),
            size: self.size * 0.5,
        }
    }

    /// The patch's `(u, v)` at quad-local `(u, v)`: the inverse of [`Piece::to_face`],
    /// unclamped (outside [0, 1]² for a point the piece does not cover).
    pub fn from_face(&self, u: f64, v: f64) -> (f64, f64) {
        let d = (
            (u - self.origin.0) / self.size,
            (v - self.origin.1) / self.size,
        );
        rotate(4 - self.rot % 4, d)
    }

    /// The quad-local parameters of the patch's `(u, v)`.
    pub fn to_face(&self, u: f64, v: f64) -> (f64, f64) {
        let (dx, dy) = rotate(self.rot, (u, v));
        let clamp = |x: f64| x.clamp(0.0, 1.0);
        (
            clamp(self.origin.0 + self.size * dx),
            clamp(self.origin.1 + self.size * dy),
        )
    }
}

/// Counts of one surface's construction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    pub cage_faces: usize,
    /// Cage faces that are holes.
    pub holes: usize,
    /// Quads after the first step.
    pub faces: usize,
    /// Regular Bézier patches (whole quads and regular children).
    pub regular: usize,
    /// Final children at extraordinary vertices.
    pub extraordinary_ends: usize,
    /// Regular patch edges pushed over a T-junction.
    pub t_junctions: usize,
    /// Deepest level reached (1 when every quad is regular).
    pub levels: u32,
}

/// A Catmull–Clark surface: its cage and the Bézier patches of its limit surface.
#[derive(Clone, Debug, PartialEq)]
pub struct SubdivisionSurface {
    pub cage: Mesh,
    /// Cage faces without a limit patch, ascending.
    pub holes: Vec<u32>,
    pub patches: Vec<BezierPatch>,
    pub pieces: Vec<Piece>,
    pub stats: Stats,
}

impl SubdivisionSurface {
    pub fn new(points: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Result<Self, CageError> {
        Self::with_holes(points, faces, Vec::new())
    }

    /// The surface without the limit patches of the cage faces `holes` (indices into
    /// `faces`, in any order, repeats allowed).
    pub fn with_holes(
        points: Vec<DVec3>,
        faces: Vec<Vec<u32>>,
        mut holes: Vec<u32>,
    ) -> Result<Self, CageError> {
        let count = faces.len();
        if let Some(&face) = holes.iter().find(|&&f| f as usize >= count) {
            return Err(CageError::BadHole {
                face: face as usize,
                count,
            });
        }
        holes.sort_unstable();
        holes.dedup();
        Ok(Self::from_cage(Mesh::cage(points, faces)?, holes))
    }

    fn from_cage(cage: Mesh, holes: Vec<u32>) -> Self {
        let (patches, pieces, mut stats) = adaptive::build(&cage, &holes);
        stats.levels = stats.levels.max(1);
        SubdivisionSurface {
            cage,
            holes,
            patches,
            pieces,
            stats,
        }
    }

    /// A surface known only by where its patches lie in their quads: a scene read from a
    /// BVH file, whose patches come from the file, keeps this for `trace`'s report.
    pub fn reporting(pieces: Vec<Piece>) -> Self {
        SubdivisionSurface {
            cage: Mesh {
                points: Vec::new(),
                faces: Vec::new(),
                boundary: Default::default(),
            },
            holes: Vec::new(),
            patches: Vec::new(),
            pieces,
            stats: Stats::default(),
        }
    }

    /// Subdivision commutes with affine maps: transforms the cage and rebuilds.
    pub fn transform(&mut self, m: &glam::DAffine3) {
        let mut cage = self.cage.clone();
        for p in &mut cage.points {
            *p = m.transform_point3(*p);
        }
        *self = Self::from_cage(cage, std::mem::take(&mut self.holes));
    }

    /// The quad (after the first step) and its `(u, v)` for a hit at `(u, v)` on `patch`.
    pub fn face_uv(&self, patch: usize, u: f64, v: f64) -> Option<(u32, f64, f64)> {
        let piece = self.pieces.get(patch)?;
        let (fu, fv) = piece.to_face(u, v);
        Some((piece.face, fu, fv))
    }
}

#[cfg(test)]
mod tests;
