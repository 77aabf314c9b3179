//! Segments hashed into cubes, for the near-neighbour queries between trimmed faces'
//! boundaries (the gap measure and the shared-edge join): each segment goes into the cubes
//! of points along it at most half a `step` apart, so that a point within half a cube of
//! the segment (when `step` is at most the cube) lies in a cube next to one of them.

use std::collections::HashMap;

use glam::DVec3;

pub(super) struct Cubes<T> {
    cube: f64,
    origin: DVec3,
    cells: HashMap<[i64; 3], Vec<T>>,
}

impl<T: Copy> Cubes<T> {
    pub(super) fn new(cube: f64, origin: DVec3) -> Self {
        Cubes {
            cube,
            origin,
            cells: HashMap::new(),
        }
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        ((p - self.origin) / self.cube)
            .floor()
            .to_array()
            .map(|x| x as i64)
    }

    /// Files `item` under the cubes of points from `a` to `b` at most `step` apart.
    pub(super) fn insert_segment(&mut self, a: DVec3, b: DVec3, step: f64, item: T) {
        let steps = ((b - a).length() / step).ceil().max(1.0) as usize;
        let mut last = None;
        for i in 0..=steps {
            let key = self.key(a.lerp(b, i as f64 / steps as f64));
            if last != Some(key) {
                self.cells.entry(key).or_default().push(item);
                last = Some(key);
            }
        }
    }

    /// Calls `visit` on the items filed in `p`'s cube and its 26 neighbours, an item once
    /// per cube it is filed in: a caller that must see each item once filters the
    /// candidates first and deduplicates the few left, rather than sorting them all.
    pub(super) fn visit_near(&self, p: DVec3, mut visit: impl FnMut(T)) {
        let c = self.key(p);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        list.iter().for_each(|&item| visit(item));
                    }
                }
            }
        }
    }
}
