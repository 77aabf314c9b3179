//! STAND-IN until the real BVH lands: a flat list with the final API.
use std::io::{Read, Write};

use crate::geom::{Aabb, Ray};

pub struct Bvh {
    boxes: Vec<Aabb>,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct TraversalStats {
    pub nodes_visited: u64,
    pub box_tests: u64,
}

#[derive(Debug, thiserror::Error)]
#[error("bvh file error")]
pub struct BvhFileError;

pub struct GeometryHasher(u64);
impl Default for GeometryHasher {
    fn default() -> Self {
        Self::new()
    }
}
impl GeometryHasher {
    pub fn new() -> Self {
        GeometryHasher(0xcbf29ce484222325)
    }
    pub fn write_bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x100000001b3);
        }
    }
    pub fn write_f64(&mut self, x: f64) {
        self.write_bytes(&x.to_le_bytes())
    }
    pub fn write_u64(&mut self, x: u64) {
        self.write_bytes(&x.to_le_bytes())
    }
    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl Bvh {
    pub fn build(boxes: &[Aabb]) -> Bvh {
        Bvh {
            boxes: boxes.to_vec(),
        }
    }
    pub fn bounds(&self) -> Aabb {
        self.boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b))
    }
    pub fn prim_count(&self) -> usize {
        self.boxes.len()
    }
    pub fn node_count(&self) -> usize {
        1
    }
    pub fn traverse<F: FnMut(u32, f32) -> Option<f32>>(
        &self,
        ray: &Ray,
        mut hit: F,
    ) -> TraversalStats {
        let inv = ray.dir.recip();
        let mut tmax = ray.tmax;
        for (i, b) in self.boxes.iter().enumerate() {
            if b.intersect(ray.origin, inv, ray.tmin, tmax).is_some() {
                if let Some(t) = hit(i as u32, tmax) {
                    tmax = t;
                }
            }
        }
        TraversalStats {
            nodes_visited: 1,
            box_tests: self.boxes.len() as u64,
        }
    }
    pub fn traverse_any<F: FnMut(u32) -> bool>(
        &self,
        ray: &Ray,
        mut hit: F,
    ) -> (bool, TraversalStats) {
        let inv = ray.dir.recip();
        let st = TraversalStats {
            nodes_visited: 1,
            box_tests: self.boxes.len() as u64,
        };
        for (i, b) in self.boxes.iter().enumerate() {
            if b.intersect(ray.origin, inv, ray.tmin, ray.tmax).is_some() && hit(i as u32) {
                return (true, st);
            }
        }
        (false, st)
    }
    pub fn write(&self, w: &mut dyn Write, h: u64) -> std::io::Result<()> {
        w.write_all(&h.to_le_bytes())
    }
    pub fn read(_r: &mut dyn Read, _h: u64) -> Result<Bvh, BvhFileError> {
        Err(BvhFileError)
    }
}
