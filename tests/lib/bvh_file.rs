//! The BVH file: a round trip gives the same arrays and the same traversals, and each kind of
//! bad file is refused with its own error, never a panic (property test over byte flips and
//! truncations).

use crate::bvh_support;

use bvh_support::{Rng, random_boxes, random_ray};
use patchtrace::accel::bvh::{Bvh, BvhFileError, FORMAT_VERSION, MAGIC, checksum};
use proptest::prelude::*;

const HASH: u64 = 0x0123_4567_89ab_cdef;
const HEADER_LEN: usize = 36;
const NODE_LEN: usize = 32;

fn sample() -> (Vec<patchtrace::geom::Aabb>, Bvh, Vec<u8>) {
    let boxes = random_boxes(&mut Rng::new(20), 60);
    let bvh = Bvh::build(&boxes);
    let mut bytes = Vec::new();
    bvh.write(&mut bytes, HASH).unwrap();
    (boxes, bvh, bytes)
}

fn read(bytes: &[u8]) -> Result<Bvh, BvhFileError> {
    Bvh::read(&mut &bytes[..], HASH)
}

/// Replaces the trailing checksum so that a deliberate edit is seen by the structural checks.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 8;
    let sum = checksum(&bytes[..n]);
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
}

#[test]
fn round_trip_is_identical() {
    let (_, bvh, bytes) = sample();
    // Layout from the module docs: header, 32-byte nodes, 4-byte indices, checksum.
    assert_eq!(
        bytes.len(),
        HEADER_LEN + NODE_LEN * bvh.node_count() + 4 * bvh.prim_count() + 8
    );
    assert_eq!(bytes[..8], MAGIC);
    let back = read(&bytes).unwrap();
    assert_eq!(back.nodes(), bvh.nodes());
    assert_eq!(back.prim_indices(), bvh.prim_indices());
    let mut rng = Rng::new(21);
    for _ in 0..200 {
        let ray = random_ray(&mut rng);
        let trace = |b: &Bvh| {
            let mut calls = Vec::new();
            let stats = b.traverse(&ray, |p, tmax| {
                calls.push((p, tmax));
                (p % 3 == 0).then_some(tmax * 0.9)
            });
            (calls, stats)
        };
        assert_eq!(trace(&bvh), trace(&back));
    }
}

#[test]
fn empty_tree_round_trips() {
    let bvh = Bvh::build(&[]);
    let mut bytes = Vec::new();
    bvh.write(&mut bytes, HASH).unwrap();
    assert_eq!(read(&bytes).unwrap(), bvh);
}

#[test]
fn stale_hash_is_refused_with_rebuild_advice() {
    let (_, _, bytes) = sample();
    let err = Bvh::read(&mut &bytes[..], HASH ^ 1).unwrap_err();
    assert!(
        matches!(err, BvhFileError::Stale { found: HASH, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("rebuild with `patchtrace bvh`"));
}

#[test]
fn wrong_magic_is_not_a_bvh_file() {
    let (_, _, mut bytes) = sample();
    bytes[1] = b'X';
    assert!(matches!(read(&bytes), Err(BvhFileError::NotBvh)));
    assert!(matches!(read(b"P3\n4 4\n255\n"), Err(BvhFileError::NotBvh)));
    assert!(matches!(read(b""), Err(BvhFileError::NotBvh)));
}

#[test]
fn wrong_version_names_both_versions() {
    let (_, _, mut bytes) = sample();
    bytes[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let err = read(&bytes).unwrap_err();
    assert!(
        matches!(err, BvhFileError::UnsupportedVersion { found, supported }
            if found == FORMAT_VERSION + 1 && supported == FORMAT_VERSION),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains(&(FORMAT_VERSION + 1).to_string())
            && msg.contains(&FORMAT_VERSION.to_string())
    );
}

#[test]
fn every_truncation_is_refused() {
    let (_, _, bytes) = sample();
    for len in 0..bytes.len() {
        let err = read(&bytes[..len]).unwrap_err();
        let expected = if len == 0 {
            matches!(err, BvhFileError::NotBvh)
        } else {
            // The error names the byte where the file ends.
            matches!(err, BvhFileError::Truncated { at, .. } if at == len)
                && err.to_string().starts_with(&format!("byte {len}: "))
        };
        assert!(expected, "length {len}: {err:?}");
    }
}

#[test]
fn corrupt_payload_fails_the_checksum() {
    let (_, _, mut bytes) = sample();
    bytes[HEADER_LEN + 5] ^= 0x10;
    assert!(matches!(read(&bytes), Err(BvhFileError::Corrupt(_))));
}

#[test]
fn bad_child_index_is_refused_even_with_a_valid_checksum() {
    let (_, bvh, bytes) = sample();
    let inner = bvh.nodes().iter().position(|n| !n.is_leaf()).unwrap();
    let first_field = HEADER_LEN + NODE_LEN * inner + 24;
    // Out of range, pointing at itself (a cycle), and pointing back at the root.
    for bad in [bvh.node_count() as u32, inner as u32, 0] {
        let mut edited = bytes.clone();
        edited[first_field..first_field + 4].copy_from_slice(&bad.to_le_bytes());
        reseal(&mut edited);
        let err = read(&edited).unwrap_err();
        assert!(
            matches!(err, BvhFileError::Invalid(_)),
            "child {bad}: {err:?}"
        );
    }
}

#[test]
fn bad_primitive_index_is_refused() {
    let (_, bvh, bytes) = sample();
    let at = HEADER_LEN + NODE_LEN * bvh.node_count();
    for bad in [bvh.prim_count() as u32, bvh.prim_indices()[1]] {
        let mut edited = bytes.clone();
        edited[at..at + 4].copy_from_slice(&bad.to_le_bytes());
        reseal(&mut edited);
        assert!(
            matches!(read(&edited), Err(BvhFileError::Invalid(_))),
            "index {bad}"
        );
    }
}

#[test]
fn absurd_counts_are_refused_before_reading() {
    let (_, _, mut bytes) = sample();
    bytes[20..28].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(read(&bytes), Err(BvhFileError::Corrupt(_))));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// A single changed byte changes the 64-bit xxh3 checksum (all but certainly: a
    /// collision has probability 2^-64), so every such file must be refused, and none may
    /// panic.
    #[test]
    fn byte_flips_are_refused_without_panic(pos in any::<prop::sample::Index>(), flip in 1u8..=255) {
        let (_, _, mut bytes) = sample();
        let i = pos.index(bytes.len());
        bytes[i] ^= flip;
        prop_assert!(read(&bytes).is_err());
    }

    /// Many flips, resealed so the checksum passes, then truncated: reading must not panic,
    /// and any tree it accepts must traverse without panicking.
    #[test]
    fn resealed_garbage_never_panics(
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..20),
        cut in any::<prop::sample::Index>(),
        reseal_it in any::<bool>(),
    ) {
        let (_, _, mut bytes) = sample();
        for (pos, b) in flips {
            let i = HEADER_LEN + pos.index(bytes.len() - HEADER_LEN - 8);
            bytes[i] = b;
        }
        if reseal_it {
            reseal(&mut bytes);
        }
        let len = cut.index(bytes.len() + 1);
        if let Ok(bvh) = read(&bytes[..len]) {
            let mut rng = Rng::new(22);
            for _ in 0..20 {
                bvh.traverse(&random_ray(&mut rng), |_, t| Some(t * 0.5));
            }
        }
    }
}
