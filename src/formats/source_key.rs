//! The key a BVH file is checked against: a hash of everything in a scene's inputs that
//! decides its prepared geometry, computed without parsing any geometry file. It covers the
//! bytes of each geometry file (hashed once per load however many objects name it), how
//! each object refers to its geometry, its up axis and transform, and which objects others
//! instance; materials, lights, the camera and object names do not change the geometry and
//! are left out. The hash is xxh3-64 (Collet, xxHash 0.8): stable across runs, hosts and
//! Rust versions, which `std`'s `DefaultHasher` does not promise, and fast enough (tens of
//! GB/s) that keying a large input costs nothing next to reading it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::DAffine3;
use xxhash_rust::xxh3::{Xxh3, xxh3_64};

use super::error::LoadError;

/// Builds a source key, one field at a time.
pub struct SourceKey {
    hasher: Xxh3,
    /// The hash of each file's bytes, by path.
    files: HashMap<PathBuf, u64>,
}

impl Default for SourceKey {
    fn default() -> Self {
        Self::new()
    }
}

impl SourceKey {
    pub fn new() -> SourceKey {
        SourceKey {
            hasher: Xxh3::new(),
            files: HashMap::new(),
        }
    }

    /// A field tag or a string, length first so that fields cannot run into each other.
    pub fn text(&mut self, s: &str) {
        self.number(s.len() as u64);
        self.hasher.update(s.as_bytes());
    }

    pub fn number(&mut self, x: u64) {
        self.hasher.update(&x.to_le_bytes());
    }

    /// An affine map by the bits of its twelve `f64` entries (so `0.0` and `-0.0` differ,
    /// as they may in the placed geometry).
    pub fn transform(&mut self, m: &DAffine3) {
        for x in m.to_cols_array() {
            self.number(x.to_bits());
        }
    }

    /// The geometry file at `path`: its extension (which picks the reader) and the hash of
    /// its bytes, read once per path.
    pub fn file(&mut self, path: &Path) -> Result<(), LoadError> {
        let digest = match self.files.get(path) {
            Some(&d) => d,
            None => {
                let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
                let d = xxh3_64(&bytes);
                self.files.insert(path.to_path_buf(), d);
                d
            }
        };
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        self.text(&ext);
        self.number(digest);
        Ok(())
    }

    pub fn finish(&self) -> u64 {
        self.hasher.digest()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published xxh3-64 value of the empty input (xxHash's reference test vector), so
    /// the key uses the real algorithm and will not change with the crate's version.
    #[test]
    fn xxh3_matches_the_reference_vector() {
        assert_eq!(xxh3_64(b""), 0x2d06_8005_38d3_94c2);
    }

    #[test]
    fn fields_do_not_run_into_each_other() {
        let key = |parts: &[&str]| {
            let mut k = SourceKey::new();
            parts.iter().for_each(|p| k.text(p));
            k.finish()
        };
        assert_ne!(key(&["ab", "c"]), key(&["a", "bc"]));
        assert_eq!(key(&["ab", "c"]), key(&["ab", "c"]));
    }

    #[test]
    fn a_file_is_keyed_by_its_bytes_not_its_name() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.bpt"), dir.path().join("b.bpt"));
        std::fs::write(&a, b"1\n1 1\n0 0 0 1 0 0 0 1 0 1 1 0\n").unwrap();
        std::fs::write(&b, b"1\n1 1\n0 0 0 1 0 0 0 1 0 1 1 0\n").unwrap();
        let key = |p: &Path| {
            let mut k = SourceKey::new();
            k.file(p).unwrap();
            k.finish()
        };
        assert_eq!(key(&a), key(&b));
        // One byte changed, same size.
        std::fs::write(&b, b"1\n1 1\n0 0 0 1 0 0 0 1 0 1 1 1\n").unwrap();
        assert_ne!(key(&a), key(&b));
    }
}
