//! The cache of surface trees with least-recently-used replacement (Lischinski &
//! Gonczarowski 1990, §4.3): "each time a surface is tested against a ray, its tree is
//! inserted at the end of the queue ... trees are released from the head of the queue."
//! The queue is a map from a use stamp to the key (ordered, so its head is the least
//! recently used tree); the budget is in bytes, as the paper's cache size (Table 1).

use std::collections::{BTreeMap, HashMap};

/// Something whose memory the cache accounts for.
pub trait Weigh {
    /// Bytes the value holds, its heap buffers included.
    fn bytes(&self) -> usize;
}

struct Entry<T> {
    value: T,
    stamp: u64,
    bytes: usize,
}

/// Values keyed by `usize` under a byte budget, released least recently used first.
pub struct Lru<T> {
    budget: usize,
    used: usize,
    clock: u64,
    entries: HashMap<usize, Entry<T>>,
    queue: BTreeMap<u64, usize>,
}

impl<T: Weigh> Lru<T> {
    pub fn new(budget: usize) -> Self {
        Lru {
            budget,
            used: 0,
            clock: 0,
            entries: HashMap::new(),
            queue: BTreeMap::new(),
        }
    }

    /// Removes and returns the value of `key`; the caller puts it back after use, which
    /// makes it the most recently used.
    pub fn take(&mut self, key: usize) -> Option<T> {
        let e = self.entries.remove(&key)?;
        self.queue.remove(&e.stamp);
        self.used -= e.bytes;
        Some(e.value)
    }

    /// Inserts `value` as the most recently used and releases trees from the head of the
    /// queue until the cache fits its budget (the new value last: one larger than the
    /// whole budget is not kept). Returns how many values were released; an old value of
    /// `key` is replaced, not counted.
    pub fn put(&mut self, key: usize, value: T) -> u64 {
        self.take(key);
        let mut released = 0;
        let bytes = value.bytes();
        self.clock += 1;
        self.queue.insert(self.clock, key);
        self.entries.insert(
            key,
            Entry {
                value,
                stamp: self.clock,
                bytes,
            },
        );
        self.used += bytes;
        while self.used > self.budget {
            let Some((_, oldest)) = self.queue.pop_first() else {
                break;
            };
            if let Some(e) = self.entries.remove(&oldest) {
                self.used -= e.bytes;
                released += 1;
            }
        }
        released
    }

    /// Whether `key` is cached, without touching its place in the queue.
    pub fn contains(&self, key: usize) -> bool {
        self.entries.contains_key(&key)
    }

    /// Bytes held by the cached values.
    pub fn used(&self) -> usize {
        self.used
    }

    /// Releases everything and sets a new budget.
    pub fn reset(&mut self, budget: usize) {
        self.entries.clear();
        self.queue.clear();
        self.used = 0;
        self.budget = budget;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Blob(usize);
    impl Weigh for Blob {
        fn bytes(&self) -> usize {
            self.0
        }
    }

    #[test]
    fn a_tiny_budget_releases_the_least_recently_used_first() {
        let mut c = Lru::new(300);
        for k in 0..3 {
            assert_eq!(c.put(k, Blob(100)), 0);
        }
        // Use 0 again: 1 is now the least recently used.
        let b = c.take(0).unwrap();
        c.put(0, b);
        assert_eq!(c.put(3, Blob(100)), 1);
        assert!(!c.contains(1), "1 was the least recently used");
        assert!(c.contains(0) && c.contains(2) && c.contains(3));
        // A large value releases the two oldest (2, then 0) to fit.
        assert_eq!(c.put(4, Blob(150)), 2);
        assert!(!c.contains(2) && !c.contains(0));
        assert!(c.contains(3) && c.contains(4));
        assert_eq!(c.used(), 250);
    }

    #[test]
    fn a_value_larger_than_the_budget_is_not_kept() {
        let mut c = Lru::new(100);
        c.put(1, Blob(50));
        assert_eq!(c.put(2, Blob(500)), 2);
        assert_eq!(c.used(), 0);
        assert!(!c.contains(1) && !c.contains(2));
    }

    #[test]
    fn putting_a_key_back_replaces_its_value() {
        let mut c = Lru::new(1000);
        c.put(7, Blob(10));
        assert_eq!(c.put(7, Blob(30)), 0);
        assert_eq!(c.used(), 30);
        assert_eq!(c.take(7).map(|b| b.0), Some(30));
        assert_eq!(c.used(), 0);
    }
}
