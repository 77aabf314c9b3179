//! The BVH file: versioned, little-endian, checksummed, and validated on load.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | [`MAGIC`] |
//! | 8 | 4 | format version `u32` ([`FORMAT_VERSION`]) |
//! | 12 | 8 | geometry hash `u64` ([`GeometryHasher`](super::GeometryHasher) of the scene) |
//! | 20 | 8 | node count `u64` |
//! | 28 | 8 | primitive count `u64` |
//! | 36 | 32 × nodes | [`Node`]s: `min.xyz`, `max.xyz` as `f32` bits, `first`, `count`, each a `u32` |
//! | … | 4 × prims | primitive indices, `u32` |
//! | … | 8 | checksum `u64`: FNV-1a 64 of every byte before it |
//!
//! Every field of a node is a 4-byte word, so nodes are written as their `bytemuck` words each
//! converted with `to_le_bytes`: the same file on little- and big-endian hosts (a no-op on
//! little-endian ones, a byte swap on big-endian ones).

use std::io::{self, Read, Write};

use thiserror::Error;

use super::hash::GeometryHasher;
use super::{Bvh, Node};

/// First bytes of every BVH file. The high first byte and the CR LF catch files mangled by
/// text-mode transfers, as in PNG's signature.
pub const MAGIC: [u8; 8] = *b"\x89PTBVH\r\n";

/// The format version this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

const HEADER_LEN: usize = 36;
const NODE_WORDS: usize = size_of::<Node>() / 4;

/// Why a BVH file was refused.
#[derive(Debug, Error)]
pub enum BvhFileError {
    #[error("byte 0: not a patchtrace BVH file (wrong magic number)")]
    NotBvh,
    #[error(
        "byte 8: BVH file format version {found} is not supported (this build reads version {supported})"
    )]
    UnsupportedVersion { found: u32, supported: u32 },
    #[error(
        "the BVH file was built for different geometry (geometry hash {found:016x}, scene has {expected:016x}); rebuild with `patchtrace bvh`"
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

impl Bvh {
    /// Writes the file for geometry with hash `geometry_hash`. Atomic replacement of a file on
    /// disk is the caller's job (`scene::write::write_atomic`).
    pub fn write(&self, w: &mut dyn Write, geometry_hash: u64) -> io::Result<()> {
        let words: &[u32] = bytemuck::cast_slice(&self.nodes);
        let mut buf =
            Vec::with_capacity(HEADER_LEN + 4 * (words.len() + self.prim_indices.len()) + 8);
        buf.extend_from_slice(&MAGIC);
        buf.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        buf.extend_from_slice(&geometry_hash.to_le_bytes());
        buf.extend_from_slice(&(self.nodes.len() as u64).to_le_bytes());
        buf.extend_from_slice(&(self.prim_indices.len() as u64).to_le_bytes());
        for word in words.iter().chain(&self.prim_indices) {
            buf.extend_from_slice(&word.to_le_bytes());
        }
        let checksum = checksum(&buf);
        buf.extend_from_slice(&checksum.to_le_bytes());
        w.write_all(&buf)
    }

    /// Reads a file written by [`write`](Bvh::write), refusing it unless it is a BVH file of
    /// this version, intact, built for geometry with hash `expected_geometry_hash`, and a
    /// valid tree. No input makes this or a later traversal panic.
    pub fn read(r: &mut dyn Read, expected_geometry_hash: u64) -> Result<Bvh, BvhFileError> {
        let mut header = Vec::with_capacity(HEADER_LEN);
        r.take(MAGIC.len() as u64).read_to_end(&mut header)?;
        if !MAGIC.starts_with(&header) || header.is_empty() {
            return Err(BvhFileError::NotBvh);
        }
        if header.len() < MAGIC.len() {
            return Err(BvhFileError::Truncated {
                what: "magic number",
                at: header.len(),
            });
        }
        read_exactly(r, &mut header, HEADER_LEN - MAGIC.len(), ("header", 0))?;
        let version = u32::from_le_bytes(field(&header, 8));
        if version != FORMAT_VERSION {
            return Err(BvhFileError::UnsupportedVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        let found_hash = u64::from_le_bytes(field(&header, 12));
        let node_count = u64::from_le_bytes(field(&header, 20));
        let prim_count = u64::from_le_bytes(field(&header, 28));
        // A binary tree with non-empty leaves has at most 2n - 1 nodes; checking this first
        // keeps a corrupt count from asking for an absurd read.
        if prim_count > u64::from(u32::MAX) || node_count > (2 * prim_count).saturating_sub(1) {
            return Err(BvhFileError::Corrupt(format!(
                "byte 20: {node_count} nodes for {prim_count} primitives"
            )));
        }
        let (node_count, prim_count) = (node_count as usize, prim_count as usize);
        let mut data = header;
        read_exactly(
            r,
            &mut data,
            4 * (NODE_WORDS * node_count + prim_count),
            ("tree data", 0),
        )?;
        let mut stored = Vec::with_capacity(8);
        read_exactly(r, &mut stored, 8, ("checksum", data.len()))?;
        if u64::from_le_bytes(field(&stored, 0)) != checksum(&data) {
            return Err(BvhFileError::Corrupt(format!(
                "byte {}: checksum mismatch",
                data.len()
            )));
        }
        if r.read(&mut [0u8; 1])? != 0 {
            return Err(BvhFileError::Corrupt(format!(
                "byte {}: extra bytes after the checksum",
                data.len() + 8
            )));
        }
        if found_hash != expected_geometry_hash {
            return Err(BvhFileError::Stale {
                found: found_hash,
                expected: expected_geometry_hash,
            });
        }
        let words: Vec<u32> = data[HEADER_LEN..]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(field(b, 0)))
            .collect();
        let (node_words, prim_indices) = words.split_at(NODE_WORDS * node_count);
        let nodes = node_words
            .chunks_exact(NODE_WORDS)
            .map(|w| bytemuck::cast::<[u32; NODE_WORDS], Node>(field(w, 0)))
            .collect();
        Bvh::from_parts(nodes, prim_indices.to_vec())
    }
}

fn checksum(bytes: &[u8]) -> u64 {
    let mut h = GeometryHasher::new();
    h.write_bytes(bytes);
    h.finish()
}

/// Appends exactly `len` more bytes from `r` to `buf`, which starts at byte `base` of the
/// file (for the error's offset). Reads through `take` so that a corrupt length can only
/// make the buffer as big as the file really is.
fn read_exactly(
    r: &mut dyn Read,
    buf: &mut Vec<u8>,
    len: usize,
    (what, base): (&'static str, usize),
) -> Result<(), BvhFileError> {
    let want = buf.len() + len;
    r.take(len as u64).read_to_end(buf)?;
    if buf.len() < want {
        return Err(BvhFileError::Truncated {
            what,
            at: base + buf.len(),
        });
    }
    Ok(())
}

/// The `N` items of `s` from `at`; callers index within lengths checked beforehand.
fn field<T: Copy, const N: usize>(s: &[T], at: usize) -> [T; N] {
    s[at..at + N]
        .try_into()
        .expect("length checked by the caller")
}
