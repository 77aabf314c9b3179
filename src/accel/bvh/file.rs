//! The tree section of a BVH file: versioned, little-endian, checksummed, and validated on
//! load. A scene's BVH file is this section followed by its prepared patches
//! ([`crate::accel::mapped`]).
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | [`MAGIC`] |
//! | 8 | 4 | format version `u32` ([`FORMAT_VERSION`]) |
//! | 12 | 8 | input key `u64`: what the tree was built from (`scene::source_key`) |
//! | 20 | 8 | node count `u64` |
//! | 28 | 8 | primitive count `u64` |
//! | 36 | 32 × nodes | [`Node`]s: `min.xyz`, `max.xyz` as `f32` bits, `first`, `count`, each a `u32` |
//! | … | 4 × prims | primitive indices, `u32` |
//! | … | 8 | [`checksum`] `u64` of every byte before it |
//!
//! Every field of a node is a 4-byte word at a 4-byte offset, so on a little-endian host the
//! nodes and indices are cast from the bytes (`bytemuck`, which checks size and alignment)
//! and copied once; a big-endian host converts each word.

use std::io::{self, Read, Write};

use rayon::prelude::*;
use thiserror::Error;

use super::{Bvh, Node};

/// First bytes of every BVH file. The high first byte and the CR LF catch files mangled by
/// text-mode transfers, as in PNG's signature.
pub const MAGIC: [u8; 8] = *b"\x89PTBVH\r\n";

/// The format version this build writes and reads. Version 2 keys the file by
/// its inputs' bytes, checksums with xxh3 and appends the prepared patches; version 3
/// adds to each patch record where a subdivision surface's patch lies in its
/// quad, which `trace` reports; version 4 records the floating origin the geometry was
/// built at (`crate::scene::origin`).
pub const FORMAT_VERSION: u32 = 4;

const HEADER_LEN: usize = 36;
const NODE_WORDS: usize = size_of::<Node>() / 4;

/// Bytes per checksum chunk: chunks are hashed on all cores (a 200 MB file in a few
/// milliseconds), then their digests once more.
const CHECKSUM_CHUNK: usize = 1 << 20;

/// Why a BVH file was refused.
#[derive(Debug, Error)]
pub enum BvhFileError {
    #[error("byte 0: not a patchtrace BVH file (wrong magic number)")]
    NotBvh,
    #[error(
        "byte 8: BVH file format version {found} is not supported (this build reads version {supported}); rebuild with `patchtrace bvh`"
    )]
    UnsupportedVersion { found: u32, supported: u32 },
    #[error(
        "the BVH file was built from different inputs (key {found:016x}, the scene's is {expected:016x}: a geometry file's bytes, a transform or an option changed); rebuild with `patchtrace bvh`"
    )]
    Stale { found: u64, expected: u64 },
    #[error("byte {at}: the BVH file is truncated: it ends inside the {what}")]
    Truncated { what: &'static str, at: usize },
    /// A count or checksum that cannot be right; the message starts with its byte offset.
    #[error("the BVH file is corrupt: {0}")]
    Corrupt(String),
    #[error("the BVH file has an invalid tree: {0}")]
    Invalid(String),
    #[error("reading the BVH file: {0}")]
    Io(#[from] io::Error),
}

/// The checksum of BVH file sections: xxh3-64 (Collet, xxHash 0.8) of the little-endian
/// xxh3-64 digests of each [`CHECKSUM_CHUNK`] bytes. Not cryptographic: it catches damage,
/// not forgery (the structural checks after it keep forged files from doing harm).
pub fn checksum(bytes: &[u8]) -> u64 {
    let digests: Vec<u8> = bytes
        .par_chunks(CHECKSUM_CHUNK)
        .flat_map_iter(|c| xxhash_rust::xxh3::xxh3_64(c).to_le_bytes())
        .collect();
    xxhash_rust::xxh3::xxh3_64(&digests)
}

impl Bvh {
    /// Writes the tree section for inputs with key `key`. Atomic replacement of a file on
    /// disk is the caller's job (`io::write_atomic`).
    pub fn write(&self, w: &mut dyn Write, key: u64) -> io::Result<()> {
        w.write_all(&self.section(key))
    }

    /// The bytes [`write`](Bvh::write) writes.
    pub(crate) fn section(&self, key: u64) -> Vec<u8> {
        let words: &[u32] = bytemuck::cast_slice(&self.nodes);
        let mut buf =
            Vec::with_capacity(HEADER_LEN + 4 * (words.len() + self.prim_indices.len()) + 8);
        buf.extend_from_slice(&MAGIC);
        buf.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        buf.extend_from_slice(&key.to_le_bytes());
        buf.extend_from_slice(&(self.nodes.len() as u64).to_le_bytes());
        buf.extend_from_slice(&(self.prim_indices.len() as u64).to_le_bytes());
        for word in words.iter().chain(&self.prim_indices) {
            buf.extend_from_slice(&word.to_le_bytes());
        }
        let checksum = checksum(&buf);
        buf.extend_from_slice(&checksum.to_le_bytes());
        buf
    }

    /// Reads a file written by [`write`](Bvh::write), refusing it unless it is a BVH tree
    /// section of this version, intact, built for inputs with key `expected_key`, a valid
    /// tree, and nothing more. No input makes this or a later traversal panic.
    pub fn read(r: &mut dyn Read, expected_key: u64) -> Result<Bvh, BvhFileError> {
        let mut bytes = Vec::new();
        r.read_to_end(&mut bytes)?;
        let (bvh, key, end) = Bvh::parse(&bytes)?;
        if end != bytes.len() {
            return Err(BvhFileError::Corrupt(format!(
                "byte {end}: extra bytes after the checksum"
            )));
        }
        check_key(key, expected_key)?;
        Ok(bvh)
    }

    /// Parses the tree section at the start of `bytes`, with the checks of
    /// [`read`](Bvh::read) but the key's ([`check_key`]), returning the tree, the key it
    /// records and the offset where the section ends.
    pub(crate) fn parse(bytes: &[u8]) -> Result<(Bvh, u64, usize), BvhFileError> {
        let magic_len = bytes.len().min(MAGIC.len());
        if magic_len == 0 || bytes[..magic_len] != MAGIC[..magic_len] {
            return Err(BvhFileError::NotBvh);
        }
        let truncated = |what, at| BvhFileError::Truncated { what, at };
        if bytes.len() < MAGIC.len() {
            return Err(truncated("magic number", bytes.len()));
        }
        if bytes.len() < HEADER_LEN {
            return Err(truncated("header", bytes.len()));
        }
        let version = u32::from_le_bytes(field(bytes, 8));
        if version != FORMAT_VERSION {
            return Err(BvhFileError::UnsupportedVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        let found_key = u64::from_le_bytes(field(bytes, 12));
        let node_count = u64::from_le_bytes(field(bytes, 20));
        let prim_count = u64::from_le_bytes(field(bytes, 28));
        // A binary tree with non-empty leaves has at most 2n - 1 nodes; checking this first
        // keeps a corrupt count from overflowing the lengths below.
        if prim_count > u64::from(u32::MAX) || node_count > (2 * prim_count).saturating_sub(1) {
            return Err(BvhFileError::Corrupt(format!(
                "byte 20: {node_count} nodes for {prim_count} primitives"
            )));
        }
        // In u64, where these bounded counts cannot overflow on any host.
        let data_end = HEADER_LEN as u64 + 4 * (NODE_WORDS as u64 * node_count + prim_count);
        if (bytes.len() as u64) < data_end {
            return Err(truncated("tree data", bytes.len()));
        }
        let (node_count, data_end) = (node_count as usize, data_end as usize);
        if bytes.len() < data_end + 8 {
            return Err(truncated("checksum", bytes.len()));
        }
        if u64::from_le_bytes(field(bytes, data_end)) != checksum(&bytes[..data_end]) {
            return Err(BvhFileError::Corrupt(format!(
                "byte {data_end}: checksum mismatch"
            )));
        }
        let nodes_end = HEADER_LEN + size_of::<Node>() * node_count;
        let nodes = words(&bytes[HEADER_LEN..nodes_end]);
        let prim_indices = words(&bytes[nodes_end..data_end]);
        Ok((
            Bvh::from_parts(nodes, prim_indices)?,
            found_key,
            data_end + 8,
        ))
    }
}

/// Refuses a file whose recorded input key `found` is not the scene's `expected` one.
pub(crate) fn check_key(found: u64, expected: u64) -> Result<(), BvhFileError> {
    if found == expected {
        Ok(())
    } else {
        Err(BvhFileError::Stale { found, expected })
    }
}

/// Little-endian 4-byte words as `T` (nodes or indices): cast and copied where the host
/// and alignment allow, converted word by word otherwise.
fn words<T: bytemuck::Pod>(bytes: &[u8]) -> Vec<T> {
    if cfg!(target_endian = "little")
        && let Ok(cast) = bytemuck::try_cast_slice::<u8, T>(bytes)
    {
        return cast.to_vec();
    }
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes(field(b, 0)))
        .collect();
    bytemuck::cast_slice(&words).to_vec()
}

/// The `N` items of `s` from `at`; callers index within lengths checked beforehand.
pub(crate) fn field<T: Copy, const N: usize>(s: &[T], at: usize) -> [T; N] {
    s[at..at + N]
        .try_into()
        .expect("length checked by the caller")
}
