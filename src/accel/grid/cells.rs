//! Storage of the non-empty voxels only (LG90 §3.1: "storing only nonempty voxels ... using
//! a simple hashing scheme like the one described by Cleary and Wyvill"): an open-addressing
//! table from a voxel's linear index to its range in one array of primitive numbers.

/// Marks an unused slot; no voxel has this linear index (the grid has fewer voxels).
const EMPTY_KEY: u64 = u64::MAX;

/// The table is kept at most half full, so a probe for an empty voxel (the common case
/// along most rays) ends after about 1.5 slots with linear probing (Knuth, TAOCP 6.4).
const MAX_LOAD_INVERSE: usize = 2;

/// Fibonacci hashing multiplier (Knuth, TAOCP 6.4: 2^64 / golden ratio); neighbouring
/// voxel indices land far apart.
const FIB_MULTIPLIER: u64 = 0x9E37_79B9_7F4A_7C15;

#[derive(Clone, Copy, Debug)]
struct Slot {
    key: u64,
    first: u32,
    count: u32,
}

/// The voxels that hold primitives, and which primitives each holds.
#[derive(Clone, Debug)]
pub struct CellTable {
    slots: Vec<Slot>,
    /// log2 of the slot count subtracted from 64: the hash keeps the top bits.
    shift: u32,
    prims: Vec<u32>,
    cells: usize,
}

impl CellTable {
    /// Builds the table from `(voxel, primitive)` pairs, which it sorts; duplicate pairs
    /// are kept once.
    pub fn from_pairs(mut pairs: Vec<(u64, u32)>) -> CellTable {
        pairs.sort_unstable();
        pairs.dedup();
        let cells = pairs.chunk_by(|a, b| a.0 == b.0).count();
        let size = (cells * MAX_LOAD_INVERSE).next_power_of_two().max(2);
        let mut table = CellTable {
            slots: vec![
                Slot {
                    key: EMPTY_KEY,
                    first: 0,
                    count: 0,
                };
                size
            ],
            shift: 64 - size.trailing_zeros(),
            prims: pairs.iter().map(|p| p.1).collect(),
            cells,
        };
        let mut first = 0;
        for run in pairs.chunk_by(|a, b| a.0 == b.0) {
            let mut i = table.home(run[0].0);
            while table.slots[i].key != EMPTY_KEY {
                i = (i + 1) & (size - 1);
            }
            table.slots[i] = Slot {
                key: run[0].0,
                first: first as u32,
                count: run.len() as u32,
            };
            first += run.len();
        }
        table
    }

    fn home(&self, key: u64) -> usize {
        (key.wrapping_mul(FIB_MULTIPLIER) >> self.shift) as usize
    }

    /// The primitives registered in voxel `key` (empty for an empty voxel).
    #[inline]
    pub fn get(&self, key: u64) -> &[u32] {
        let mask = self.slots.len() - 1;
        let mut i = self.home(key);
        loop {
            let s = self.slots[i];
            if s.key == key {
                return &self.prims[s.first as usize..(s.first + s.count) as usize];
            }
            if s.key == EMPTY_KEY {
                return &[];
            }
            i = (i + 1) & mask;
        }
    }

    /// Number of non-empty voxels.
    pub fn cell_count(&self) -> usize {
        self.cells
    }

    /// Number of (voxel, primitive) registrations.
    pub fn registration_count(&self) -> usize {
        self.prims.len()
    }

    /// Bytes held: the slots and the primitive lists.
    pub fn memory_bytes(&self) -> usize {
        self.slots.len() * std::mem::size_of::<Slot>() + self.prims.len() * 4
    }

    /// Every non-empty voxel with its primitives, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = (u64, &[u32])> {
        self.slots.iter().filter(|s| s.key != EMPTY_KEY).map(|s| {
            (
                s.key,
                &self.prims[s.first as usize..(s.first + s.count) as usize],
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_match_a_sorted_map() {
        let mut pairs = Vec::new();
        let mut x = 12345u64;
        for _ in 0..5000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            pairs.push(((x >> 40) % 3000, (x >> 20) as u32 % 50));
        }
        let table = CellTable::from_pairs(pairs.clone());
        let mut map = std::collections::BTreeMap::<u64, Vec<u32>>::new();
        for (k, p) in pairs {
            map.entry(k).or_default().push(p);
        }
        for v in map.values_mut() {
            v.sort_unstable();
            v.dedup();
        }
        assert_eq!(table.cell_count(), map.len());
        for key in 0..3100 {
            let want = map.get(&key).map_or(&[][..], |v| v.as_slice());
            assert_eq!(table.get(key), want, "voxel {key}");
        }
        assert_eq!(table.iter().count(), map.len());
    }
}
