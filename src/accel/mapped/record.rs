//! The fixed-size patch records of a BVH file ([`super`]): what the render reads of a
//! patch, cast in place from the mapping.

use glam::{DVec3, DVec4, Vec3, Vec4};
use rayon::prelude::*;

use crate::accel::patches::OwnedPatches;
use crate::geom::bezier::ParamRect;
use crate::geom::subdiv::Piece;
use crate::geom::{Aabb, BezierPatch};
use crate::kernel::subdivision::PreparedPatch;
use crate::kernel::subdivision::affine::AffinePatch;
use crate::kernel::subdivision::bicubic::Net;
use crate::kernel::subdivision::bilinear::BilinearNet;
use crate::kernel::subdivision::prepared::Prepared;

/// Most control points a record holds: a bicubic patch's.
const POINTS: usize = 16;

/// `kind` of a bicubic net whose registers hold rows (fixed v).
const KIND_ROWS: u32 = 0;
/// `kind` of a bicubic net whose registers hold columns (fixed u).
const KIND_COLUMNS: u32 = 1;
/// `kind` of a bilinear net.
const KIND_BILINEAR: u32 = 2;
/// `kind` of an affine patch (closed form, no net: it is made from the corner points).
const KIND_AFFINE: u32 = 3;

/// `piece_face` of a patch that is not part of a subdivision surface.
const NO_PIECE: u32 = u32::MAX;

/// Bytes per patch record in the file.
pub const RECORD_BYTES: usize = size_of::<PatchRecord>();

/// One patch as the file stores it; `Pod`, so that the mapped bytes are records.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub(in crate::accel) struct PatchRecord {
    /// The kernel's net: a bicubic [`Net`]'s three blocks of four registers of four lanes,
    /// or a [`BilinearNet`]'s three registers in the first twelve; zero for an affine patch.
    pub(super) net: [f32; 48],
    /// [`PreparedPatch::bounds`]: min xyz, max xyz.
    pub(super) bounds: [f32; 6],
    pub(super) kind: u32,
    pub(super) object: u32,
    pub(super) patch: u32,
    /// Degree in u in the low 16 bits, in v in the high 16.
    pub(super) degrees: u32,
    /// For a patch of a subdivision surface its [`Piece`]: the quad, the quarter turns,
    /// and (in `piece`) the origin u, v and size; `piece_face` is [`NO_PIECE`] otherwise.
    pub(super) piece_face: u32,
    pub(super) piece_rot: u32,
    /// The patch's parameter rectangle: u0, u1, v0, v1.
    pub(super) domain: [f64; 4],
    /// Control points x y z, u fastest, the first (du + 1)(dv + 1) used (weights are 1).
    pub(super) points: [f64; 3 * POINTS],
    pub(super) piece: [f64; 3],
}

impl PatchRecord {
    /// The record of an untrimmed patch, `None` for one of the general path or rational.
    fn new(
        prepared: &PreparedPatch,
        original: &BezierPatch,
        (object, patch): (u32, u32),
        piece: Option<Piece>,
    ) -> Option<PatchRecord> {
        if original.is_rational() || original.point_count() > POINTS {
            return None;
        }
        let mut net = [0.0; 48];
        let kind = match &prepared.data {
            Prepared::Bicubic(n) => {
                let lanes = n.xyz.iter().flatten().flat_map(|r| r.to_array());
                net.iter_mut().zip(lanes).for_each(|(d, s)| *d = s);
                if n.transposed {
                    KIND_COLUMNS
                } else {
                    KIND_ROWS
                }
            }
            Prepared::Bilinear(n) => {
                let lanes = n.xyz.iter().flat_map(|r| r.to_array());
                net.iter_mut().zip(lanes).for_each(|(d, s)| *d = s);
                KIND_BILINEAR
            }
            Prepared::Affine(_) => KIND_AFFINE,
            Prepared::General { .. } => return None,
        };
        let b = prepared.bounds();
        let d = original.domain();
        let mut points = [0.0; 3 * POINTS];
        let coords = original.euclidean_points().flat_map(|p| p.to_array());
        points.iter_mut().zip(coords).for_each(|(d, s)| *d = s);
        Some(PatchRecord {
            net,
            bounds: [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z],
            kind,
            object,
            patch,
            degrees: original.degree_u() as u32 | (original.degree_v() as u32) << 16,
            piece_face: piece.map_or(NO_PIECE, |p| p.face),
            piece_rot: piece.map_or(0, |p| u32::from(p.rot)),
            domain: [d.u0, d.u1, d.v0, d.v1],
            points,
            piece: piece.map_or([0.0; 3], |p| [p.origin.0, p.origin.1, p.size]),
        })
    }

    pub(super) fn piece(&self) -> Option<Piece> {
        (self.piece_face != NO_PIECE).then(|| Piece {
            face: self.piece_face,
            rot: self.piece_rot as u8,
            origin: (self.piece[0], self.piece[1]),
            size: self.piece[2],
        })
    }

    fn degrees(&self) -> (usize, usize) {
        (
            (self.degrees & 0xffff) as usize,
            (self.degrees >> 16) as usize,
        )
    }

    pub(super) fn bounds(&self) -> Aabb {
        let b = &self.bounds;
        Aabb {
            min: Vec3::new(b[0], b[1], b[2]),
            max: Vec3::new(b[3], b[4], b[5]),
        }
    }

    pub(super) fn prepared(&self) -> PreparedPatch {
        if let Some(affine) = self.affine() {
            return PreparedPatch::affine(affine);
        }
        let reg = |at: usize| Vec4::from_slice(&self.net[at..at + 4]);
        let data = match self.kind {
            KIND_BILINEAR => Prepared::Bilinear(BilinearNet {
                xyz: [reg(0), reg(4), reg(8)],
            }),
            kind => Prepared::Bicubic(Net {
                xyz: [0, 16, 32].map(|c| [0, 4, 8, 12].map(|r| reg(c + r))),
                transposed: kind == KIND_COLUMNS,
            }),
        };
        PreparedPatch {
            data,
            bounds: self.bounds(),
        }
    }

    /// The closed form of an affine record, from the same three corners and by the same
    /// arithmetic as the patch it was written from ([`AffinePatch::of`]), so the mapped
    /// patch gives the same hits. `None` for other kinds, and for an affine record whose
    /// corners are degenerate (only in a file forged past its checksum: [`Self::fault`]
    /// refuses it).
    fn affine(&self) -> Option<AffinePatch> {
        if self.kind != KIND_AFFINE {
            return None;
        }
        let (du, dv) = self.degrees();
        let point = |k: usize| DVec3::from_slice(&self.points[3 * k..3 * k + 3]);
        let o = point(0);
        AffinePatch::new(o, point(du) - o, point(dv * (du + 1)) - o)
    }

    /// The `f64` patch. Records are validated when the file is opened (degrees, point count);
    /// points that are not finite (only in a file forged past its checksum) give the unit
    /// square, so that no input can make this fail.
    pub(super) fn original(&self) -> BezierPatch {
        let (du, dv) = self.degrees();
        let n = (du + 1) * (dv + 1);
        let points: Vec<DVec3> = self.points[..3 * n]
            .chunks_exact(3)
            .map(DVec3::from_slice)
            .collect();
        let [u0, u1, v0, v1] = self.domain;
        BezierPatch::from_points(du, dv, &points)
            .map(|p| p.with_domain(ParamRect { u0, u1, v0, v1 }))
            .unwrap_or_else(|_| unit_square())
    }

    /// Why this record cannot be used with a scene of `objects` objects, if it cannot.
    pub(super) fn fault(&self, objects: usize) -> Option<String> {
        let (du, dv) = self.degrees();
        if !(1..=3).contains(&du) || !(1..=3).contains(&dv) {
            return Some(format!("degrees {du} × {dv} outside 1..=3"));
        }
        if self.kind > KIND_AFFINE {
            return Some(format!("unknown net kind {}", self.kind));
        }
        if self.kind == KIND_AFFINE && self.affine().is_none() {
            return Some("affine patch with degenerate corners".to_string());
        }
        if self.piece_face != NO_PIECE
            && (self.piece_rot > 3
                || !self.piece.iter().all(|x| x.is_finite())
                || self.piece[2] <= 0.0)
        {
            return Some(format!(
                "subdivision piece with {} quarter turns and origin and size {:?}",
                self.piece_rot, self.piece
            ));
        }
        if self.object as usize >= objects {
            return Some(format!(
                "object {} in a scene of {objects} objects",
                self.object
            ));
        }
        None
    }
}

fn unit_square() -> BezierPatch {
    let corners = [
        DVec4::new(0.0, 0.0, 0.0, 1.0),
        DVec4::X + DVec4::W,
        DVec4::Y + DVec4::W,
        DVec4::ONE.with_z(0.0),
    ];
    BezierPatch::new(1, 1, corners.to_vec()).expect("a valid unit square")
}

/// The patch records of `patches`, or `None` when any patch cannot be mapped (trimmed,
/// general path, rational); `piece_of(object, patch)` is where a subdivision surface's
/// patch lies in its quad.
pub(in crate::accel) fn records(
    patches: &OwnedPatches,
    piece_of: &(dyn Fn(u32, u32) -> Option<Piece> + Sync),
) -> Option<Vec<PatchRecord>> {
    if patches.trims.iter().any(Option::is_some) {
        return None;
    }
    (0..patches.prepared.len())
        .into_par_iter()
        .map(|i| {
            let id @ (object, patch) = patches.ids[i];
            let piece = piece_of(object, patch);
            PatchRecord::new(&patches.prepared[i], &patches.originals[i], id, piece)
        })
        .collect()
}
