//! A stable 64-bit hash of scene geometry, stored in BVH files to detect a file built for
//! different geometry. It must give the same value on every run, platform and Rust version,
//! which `std`'s `DefaultHasher` does not promise, so this is FNV-1a 64 (Fowler, Noll and Vo;
//! the offset basis and prime are the published FNV-1a 64 parameters), fed little-endian bytes.

/// FNV-1a 64 offset basis (published FNV parameters).
const FNV_OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
/// FNV-1a 64 prime (published FNV parameters).
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// Incremental FNV-1a 64 hasher. Numbers are hashed by their little-endian bytes, `f64` by its
/// bit pattern (so `0.0` and `-0.0` differ, as they do as stored geometry).
#[derive(Clone, Copy, Debug)]
pub struct GeometryHasher {
    state: u64,
}

impl Default for GeometryHasher {
    fn default() -> Self {
        Self::new()
    }
}

impl GeometryHasher {
    pub fn new() -> Self {
        GeometryHasher {
            state: FNV_OFFSET_BASIS,
        }
    }

    pub fn write_bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.state = (self.state ^ u64::from(b)).wrapping_mul(FNV_PRIME);
        }
    }

    pub fn write_u64(&mut self, x: u64) {
        self.write_bytes(&x.to_le_bytes());
    }

    pub fn write_f64(&mut self, x: f64) {
        self.write_u64(x.to_bits());
    }

    pub fn finish(&self) -> u64 {
        self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fnv(bytes: &[u8]) -> u64 {
        let mut h = GeometryHasher::new();
        h.write_bytes(bytes);
        h.finish()
    }

    /// Published FNV-1a 64 test vectors (the FNV reference test suite).
    #[test]
    fn matches_published_fnv1a_vectors() {
        assert_eq!(fnv(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn numbers_hash_as_little_endian_bytes() {
        let mut a = GeometryHasher::new();
        a.write_f64(1.5);
        a.write_u64(7);
        let mut bytes = 1.5f64.to_bits().to_le_bytes().to_vec();
        bytes.extend_from_slice(&7u64.to_le_bytes());
        assert_eq!(a.finish(), fnv(&bytes));
    }
}
