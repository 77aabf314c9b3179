//! A scene's BVH file: the tree section ([`crate::accel::bvh`]) followed by the patch
//! section, the scene's patches prepared for the kernels as fixed-size records that
//! `render --bvh` maps (`memmap2`) and casts (`bytemuck`) in place: no parse, no per-patch
//! allocation, and pages read only where rays go.
//!
//! Patch section layout, from the first multiple of 8 after the tree section's checksum
//! (zero bytes before it), all little-endian:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | 1 if the records follow, 0 if the scene has geometry they cannot hold |
//! | 8 | 8 | record count `u64` (the tree's primitive count when there are records) |
//! | 16 | 8 | trim loops in the scene `u64` (for the effect line; none cuts a mapped patch) |
//! | 24 | 8 | record size `u64` ([`PatchRecord`], 680) |
//! | 32 | 24 | floating origin, three `f64` ([`crate::scene::origin`]) |
//! | 56 | 680 × records | [`PatchRecord`]s, in primitive order |
//! | … | 8 | [`checksum`] of the section before it |
//!
//! Then the scene section, the scene file's parse for `render --bvh` to skip the RON parse
//! when the text is unchanged: the xxh3-64 of the scene file's bytes (`u64`; for a bare
//! geometry file the key of its inputs), the length `u64` of the JSON that follows
//! (`formats::ron_format::SceneFile`, or for a bare geometry file its scene without geometry,
//! `scene::bare_shell::BareShell`), the JSON, and the [`checksum`] of the section.
//!
//! The tree and the records are built in the scene moved by minus the floating origin
//! (format version 4); the scene section keeps the scene where it was.
//!
//! Records hold what the render reads of a patch: the `f32` net of the bicubic or bilinear
//! fast path, its box, its (object, patch) number, and the `f64` control points and domain
//! for normals and the `f64` and LG90 kernels, and for a patch of a Catmull–Clark surface
//! where it lies in its quad after the first step (its [`Piece`], which `trace` reports,
//! format version 3). A scene with triangles, instances, patches
//! its trim loops cut, or patches of the general (rational or other-degree) path has no
//! records; its file holds the tree only, and the geometry is built from the scene.

use std::fs::File;
use std::io::{self, Write};
use std::path::Path;

use glam::DVec3;
use memmap2::Mmap;
use rayon::prelude::*;

use crate::accel::bvh::{Bvh, BvhFileError, checksum};
use crate::formats::LoadError;
use crate::geom::subdiv::Piece;
use crate::geom::{Aabb, BezierPatch};
use crate::kernel::subdivision::PreparedPatch;
use record::PatchRecord;

mod record;

pub use record::RECORD_BYTES;
pub(super) use record::records;

/// The key a scene's BVH file records: its inputs' key (`scene::source_key`) with what else
/// decides the prepared patches: `--ignore-trims`, and whether this host prepares bilinear
/// patches as bicubics (the AVX-512 path does), so that a file is never used with nets
/// another host's kernel would not have made.
pub fn key(source: u64, ignore_trims: bool) -> u64 {
    #[cfg(target_arch = "x86_64")]
    let elevated = crate::kernel::subdivision::avx512::available();
    #[cfg(not(target_arch = "x86_64"))]
    let elevated = false;
    let mut bytes = source.to_le_bytes().to_vec();
    bytes.extend([u8::from(ignore_trims), u8::from(elevated)]);
    xxhash_rust::xxh3::xxh3_64(&bytes)
}

const SECTION_HEADER: usize = 56;

/// Writes the file: `bvh`'s tree section with `key`, then the patch section with `records`
/// (or none), the scene's `trim_loops` and the floating `origin` it was built at, then the
/// scene section with `parsed` (the scene's text hash and its parse as JSON, or nothing).
pub(super) fn write(
    w: &mut dyn Write,
    bvh: &Bvh,
    key: u64,
    (records, trim_loops): (Option<&[PatchRecord]>, usize),
    origin: DVec3,
    parsed: Option<(u64, &[u8])>,
) -> io::Result<()> {
    let tree = bvh.section(key);
    w.write_all(&tree)?;
    w.write_all(&vec![0u8; tree.len().next_multiple_of(8) - tree.len()])?;
    let has_records = records.is_some();
    let records = records.unwrap_or_default();
    let body: &[u8] = bytemuck::cast_slice(records);
    let mut section = Vec::with_capacity(SECTION_HEADER + body.len());
    for field in [
        u64::from(has_records),
        records.len() as u64,
        trim_loops as u64,
        size_of::<PatchRecord>() as u64,
        origin.x.to_bits(),
        origin.y.to_bits(),
        origin.z.to_bits(),
    ] {
        section.extend_from_slice(&field.to_le_bytes());
    }
    section.extend_from_slice(body);
    let sum = checksum(&section);
    w.write_all(&section)?;
    w.write_all(&sum.to_le_bytes())?;
    let (text_hash, json) = parsed.unwrap_or_default();
    let mut scene = Vec::with_capacity(16 + json.len());
    scene.extend_from_slice(&text_hash.to_le_bytes());
    scene.extend_from_slice(&(json.len() as u64).to_le_bytes());
    scene.extend_from_slice(json);
    let sum = checksum(&scene);
    w.write_all(&scene)?;
    w.write_all(&sum.to_le_bytes())
}

/// The patches of a mapped file.
pub struct MappedPatches {
    map: Mmap,
    /// Byte offset of the first record.
    start: usize,
    count: usize,
}

impl MappedPatches {
    fn records(&self) -> &[PatchRecord] {
        // Size and alignment were checked by `open` on this same mapping.
        bytemuck::cast_slice(
            &self.map[self.start..self.start + self.count * size_of::<PatchRecord>()],
        )
    }

    pub(super) fn len(&self) -> usize {
        self.count
    }

    pub(super) fn prepared(&self, i: usize) -> PreparedPatch {
        self.records()[i].prepared()
    }

    pub(super) fn bounds(&self, i: usize) -> Aabb {
        self.records()[i].bounds()
    }

    pub(super) fn original(&self, i: usize) -> BezierPatch {
        self.records()[i].original()
    }

    pub(super) fn id(&self, i: usize) -> (u32, u32) {
        let r = &self.records()[i];
        (r.object, r.patch)
    }

    pub(super) fn piece(&self, i: usize) -> Option<Piece> {
        self.records()[i].piece()
    }
}

/// An opened BVH file: the tree, the mapped patches when the file has them (and the host
/// is little-endian, the byte order of the records), and the scene's trim loop count.
pub struct BvhFile {
    pub bvh: Bvh,
    pub patches: Option<MappedPatches>,
    pub trim_loops: usize,
    /// The floating origin the geometry was moved by (minus it) before it was built.
    pub origin: DVec3,
}

/// A mapped BVH file whose every section passed its structural and checksum checks, not
/// yet checked against the scene ([`Opened::check`]).
pub struct Opened {
    map: Mmap,
    bvh: Bvh,
    key: u64,
    /// First record and record count, when the file has records.
    records: Option<(usize, usize)>,
    trim_loops: usize,
    origin: DVec3,
    /// The scene's parse: the hash of its text and the range of its JSON.
    scene: (u64, std::ops::Range<usize>),
}

/// Maps the BVH file at `path` and checks its structure: no file makes this or a later
/// query panic or read out of bounds, as every size, offset and alignment is checked
/// before the bytes are cast; errors name the byte offset of the fault.
pub fn map(path: &Path) -> Result<Opened, LoadError> {
    let invalid = |e: BvhFileError| LoadError::invalid(path, e.to_string());
    let file = File::open(path).map_err(|e| LoadError::io(path, e))?;
    // SAFETY: the mapping is read-only and private to this process; as for every reader of
    // mapped files (ripgrep, the linker), another process truncating or rewriting the file
    // while it is mapped is outside what we guard against. `patchtrace bvh` itself never
    // rewrites a file in place: it writes a temporary file and renames it.
    let map = unsafe { Mmap::map(&file) }.map_err(|e| LoadError::io(path, e))?;
    let (bvh, key, tree_end) = Bvh::parse(&map).map_err(invalid)?;
    let at = tree_end.next_multiple_of(8);
    let truncated = |what| {
        invalid(BvhFileError::Truncated {
            what,
            at: map.len(),
        })
    };
    let corrupt = |offset: usize, what: String| {
        invalid(BvhFileError::Corrupt(format!("byte {offset}: {what}")))
    };
    if map.len() < at + SECTION_HEADER {
        return Err(truncated("patch section header"));
    }
    let word = |offset: usize| u64::from_le_bytes(super::bvh::field(&map, offset));
    let (has_records, count, trim_loops, record_size) =
        (word(at), word(at + 8), word(at + 16), word(at + 24));
    if has_records > 1 {
        return Err(corrupt(at, format!("patch section flag {has_records}")));
    }
    let origin = DVec3::from_array([32, 40, 48].map(|k| f64::from_bits(word(at + k))));
    if !origin.is_finite() {
        return Err(corrupt(at + 32, format!("floating origin {origin}")));
    }
    if record_size != RECORD_BYTES as u64 {
        return Err(corrupt(
            at + 24,
            format!("patch records of {record_size} bytes, expected {RECORD_BYTES}"),
        ));
    }
    let expected = if has_records == 1 {
        bvh.prim_count() as u64
    } else {
        0
    };
    if count != expected {
        return Err(corrupt(
            at + 8,
            format!(
                "{count} patch records for a tree of {} primitives",
                bvh.prim_count()
            ),
        ));
    }
    let start = at + SECTION_HEADER;
    let end = start + count as usize * RECORD_BYTES;
    if map.len() < end {
        return Err(truncated("patch records"));
    }
    if map.len() < end + 8 {
        return Err(truncated("patch section checksum"));
    }
    if word(end) != checksum(&map[at..end]) {
        return Err(corrupt(end, "patch section checksum mismatch".into()));
    }
    let scene = end + 8;
    if map.len() < scene + 16 {
        return Err(truncated("scene section header"));
    }
    let json_len = word(scene + 8);
    if json_len > (map.len() - scene - 16) as u64 {
        return Err(truncated("scene section"));
    }
    let json_end = scene + 16 + json_len as usize;
    if map.len() < json_end + 8 {
        return Err(truncated("scene section checksum"));
    }
    if word(json_end) != checksum(&map[scene..json_end]) {
        return Err(corrupt(json_end, "scene section checksum mismatch".into()));
    }
    if map.len() > json_end + 8 {
        return Err(corrupt(
            json_end + 8,
            "extra bytes after the scene section".into(),
        ));
    }
    let records =
        (has_records == 1 && cfg!(target_endian = "little")).then_some((start, count as usize));
    if let Some((start, _)) = records
        && bytemuck::try_cast_slice::<u8, PatchRecord>(&map[start..end]).is_err()
    {
        return Err(corrupt(
            start,
            "patch records cannot be read in place".into(),
        ));
    }
    Ok(Opened {
        scene: (word(scene), scene + 16..json_end),
        map,
        bvh,
        key,
        records,
        trim_loops: usize::try_from(trim_loops).unwrap_or(usize::MAX),
        origin,
    })
}

impl Opened {
    /// The scene's parse the file keeps: the xxh3-64 of the scene file's bytes and the
    /// JSON of its serde mirror (`formats::ron_format::SceneFile`), or for a bare geometry
    /// file the key of its inputs and its scene's `scene::bare_shell::BareShell`; empty
    /// when none.
    pub fn cached_scene(&self) -> (u64, &[u8]) {
        (self.scene.0, &self.map[self.scene.1.clone()])
    }

    /// Whether the file holds the prepared patches (not the tree alone).
    pub fn has_patches(&self) -> bool {
        self.records.is_some()
    }

    /// Accepts the file for a scene with input key `key` and `objects` objects: refused
    /// when built from other inputs, or when a record names an object the scene lacks or
    /// has degrees or a net kind no record can have (the byte offset of the record).
    pub fn check(self, path: &Path, key: u64, objects: usize) -> Result<BvhFile, LoadError> {
        let invalid = |e: BvhFileError| LoadError::invalid(path, e.to_string());
        super::bvh::check_key(self.key, key).map_err(invalid)?;
        let Some((start, count)) = self.records else {
            return Ok(BvhFile {
                bvh: self.bvh,
                patches: None,
                trim_loops: self.trim_loops,
                origin: self.origin,
            });
        };
        let patches = MappedPatches {
            map: self.map,
            start,
            count,
        };
        let fault = patches
            .records()
            .par_iter()
            .enumerate()
            .find_map_first(|(i, r)| r.fault(objects).map(|f| (i, f)));
        if let Some((i, f)) = fault {
            let at = start + i * RECORD_BYTES;
            return Err(invalid(BvhFileError::Corrupt(format!(
                "byte {at}: patch record {i}: {f}"
            ))));
        }
        Ok(BvhFile {
            bvh: self.bvh,
            patches: Some(patches),
            trim_loops: self.trim_loops,
            origin: self.origin,
        })
    }
}
