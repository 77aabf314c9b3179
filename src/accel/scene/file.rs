//! A scene's geometry to and from its BVH file ([`super::mapped`]).

use super::build::{Split, collect_patches, place};
use super::triangles::{Triangles, collect_triangles};
use super::{Accel, SceneGeometry};
use crate::accel::bvh::Bvh;
use crate::accel::mapped;
use crate::accel::patches::PatchStore;
use crate::geom::subdiv::Piece;
use crate::scene::Scene;

/// A scene's geometry from its BVH file ([`mapped`]).
pub enum FromFile {
    /// The file holds the prepared patches: the geometry, mapped, and the scene's trim loop
    /// count (the scene itself was read without its geometry).
    Mapped(Box<SceneGeometry>, usize),
    /// The file holds the tree only (triangles, instances, trimmed or general patches): the
    /// geometry must be built from the scene, read with its geometry, with
    /// [`SceneGeometry::with_tree`].
    TreeOnly(Bvh),
}

impl SceneGeometry {
    /// The geometry of a BVH file accepted for the scene ([`mapped::Opened::check`]).
    pub fn from_file(file: mapped::BvhFile) -> FromFile {
        match file.patches {
            Some(patches) => {
                let accel = Accel::bvh(file.bvh, patches.len(), &Triangles::default());
                let geometry = SceneGeometry {
                    patches: PatchStore::Mapped(patches),
                    triangles: Triangles::default(),
                    accel,
                    instances: Vec::new(),
                    prototypes: Vec::new(),
                };
                FromFile::Mapped(Box::new(geometry), file.trim_loops)
            }
            None => FromFile::TreeOnly(file.bvh),
        }
    }

    /// Where the mapped patches of subdivision surfaces lie in their quads, by object and
    /// patch number (empty for other objects): what `trace` reports for a scene read from
    /// a BVH file without its geometry files ([`crate::scene::Object::trace_patch`]).
    pub fn mapped_pieces(&self, objects: usize) -> Vec<Vec<Piece>> {
        let mut by_object: Vec<Vec<Option<Piece>>> = vec![Vec::new(); objects];
        if let PatchStore::Mapped(m) = &self.patches {
            for i in 0..m.len() {
                let (object, patch) = m.id(i);
                if let (Some(piece), Some(list)) = (m.piece(i), by_object.get_mut(object as usize))
                {
                    if list.len() <= patch as usize {
                        list.resize(patch as usize + 1, None);
                    }
                    list[patch as usize] = Some(piece);
                }
            }
        }
        by_object
            .into_iter()
            .map(|list| {
                let patches = 0..list.len() as u32;
                list.into_iter()
                    .zip(patches)
                    .map(|(piece, p)| piece.unwrap_or(Piece::whole(p)))
                    .collect()
            })
            .collect()
    }

    /// Prepares `scene` with a tree from its BVH file ([`FromFile::TreeOnly`]); `path`
    /// names the file in the error when the tree indexes a different number of primitives.
    pub fn with_tree(
        scene: &Scene,
        bvh: Bvh,
        path: &std::path::Path,
    ) -> Result<SceneGeometry, crate::formats::LoadError> {
        let split = Split::of(scene);
        let prototypes = split.prepare_prototypes();
        let patches = collect_patches(&split.own);
        let triangles = collect_triangles(&split.own);
        let instances = place(&split.instances, &prototypes, patches.originals.len());
        if bvh.prim_count() != patches.originals.len() + triangles.corners.len() + instances.len() {
            return Err(crate::formats::LoadError::invalid(
                path,
                "the BVH indexes a different number of patches than the scene; rebuild it with `patchtrace bvh`",
            ));
        }
        let accel = Accel::bvh(bvh, patches.originals.len(), &triangles);
        Ok(Self::with_accel(
            patches, triangles, accel, instances, prototypes,
        ))
    }

    /// Writes the BVH file for inputs with key `key`, atomically: the tree, and the
    /// prepared patches when the geometry is only patches the file can hold, with the
    /// scene's `trim_loops` and the floating `origin` it was moved by (minus it) before it
    /// was built, and the scene file's `parsed` form (`ron_format::parsed_scene`)
    /// when there is one; whether it holds the patches. Refused for a grid.
    pub fn save_bvh(
        &self,
        path: &std::path::Path,
        key: u64,
        (trim_loops, origin): (usize, glam::DVec3),
        parsed: Option<(u64, &[u8])>,
        piece_of: &(dyn Fn(u32, u32) -> Option<Piece> + Sync),
    ) -> Result<bool, crate::io::OutputError> {
        let Accel::Bvh(bvh, _) = &self.accel else {
            return Err(crate::io::OutputError::invalid(
                path,
                "the geometry was prepared with a grid, which has no BVH to write",
            ));
        };
        let records = match &self.patches {
            PatchStore::Owned(p)
                if self.triangles.corners.is_empty() && self.instances.is_empty() =>
            {
                mapped::records(p, piece_of)
            }
            _ => None,
        };
        crate::io::write_atomic(path, |w| {
            mapped::write(
                w,
                bvh,
                key,
                (records.as_deref(), trim_loops),
                origin,
                parsed,
            )
        })?;
        Ok(records.is_some())
    }
}
