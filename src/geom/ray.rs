//! Rays in `f32` (the kernels' precision) with a parametric interval `[tmin, tmax]`.

use glam::Vec3;

/// A ray `origin + t * dir` restricted to `t` in `[tmin, tmax]`. The direction need not be
/// unit length; `t` is measured in units of it (the `trace` contract).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmin: f32,
    pub tmax: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray {
            origin,
            dir,
            tmin: 0.0,
            tmax: f32::INFINITY,
        }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}
