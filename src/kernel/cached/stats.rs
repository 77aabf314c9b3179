//! Cache counters of the cached kernel: the "cache misses" and "cache hit ratio" rows of
//! Lischinski & Gonczarowski's Tables 2–6 (§7.1), and the work of the surface trees.

/// Counters summed over kernel calls.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CachedStats {
    /// Ray–patch tests that found the patch's tree in the cache.
    pub hits: u64,
    /// Ray–patch tests that had to start a new tree.
    pub misses: u64,
    /// Trees released from the cache to stay within its budget (§4.3).
    pub evictions: u64,
    /// Tree nodes created (four per split of a leaf).
    pub nodes_created: u64,
    /// Ray–box tests against tree nodes' boxes.
    pub tree_box_tests: u64,
    /// Regular subdivisions of undecided boxes (§4.2 step 8), cached or not.
    pub subdivisions: u64,
    /// Subdivisions below the depth limit, which are not cached.
    pub uncached_subdivisions: u64,
}

impl CachedStats {
    pub fn add(&mut self, o: &CachedStats) {
        self.hits += o.hits;
        self.misses += o.misses;
        self.evictions += o.evictions;
        self.nodes_created += o.nodes_created;
        self.tree_box_tests += o.tree_box_tests;
        self.subdivisions += o.subdivisions;
        self.uncached_subdivisions += o.uncached_subdivisions;
    }

    /// Share of ray–patch tests that used a cached tree ("cache hit ratio", as a fraction).
    pub fn hit_ratio(&self) -> f64 {
        let n = self.hits + self.misses;
        if n == 0 {
            0.0
        } else {
            self.hits as f64 / n as f64
        }
    }
}
