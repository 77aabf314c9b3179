//! The pinhole camera of the DESIGN.md contract. Rays are computed in `f64` and rounded
//! once to `f32`.

use glam::{DVec3, Vec3};

use crate::geom::Ray;
use crate::kernel::subdivision::ScreenFootprint;
use crate::scene::Camera;

/// The camera's orthonormal frame and image-plane scale, precomputed.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    scale: f64,
    width: f64,
    height: f64,
}

impl CameraRays {
    pub fn new(c: &Camera) -> Self {
        let forward = (c.look_at - c.eye).normalize();
        let right = forward.cross(c.up).normalize();
        let up = right.cross(forward);
        CameraRays {
            eye: c.eye,
            forward,
            right,
            up,
            scale: (c.fov_y.to_radians() * 0.5).tan(),
            width: c.width as f64,
            height: c.height as f64,
        }
    }

    /// Origin and unit direction in `f64` for pixel (x, y) and sample offset (sx, sy).
    pub fn ray_f64(&self, x: u32, y: u32, sx: f64, sy: f64) -> (DVec3, DVec3) {
        let a = (2.0 * (x as f64 + sx) / self.width - 1.0) * self.scale * self.width / self.height;
        let b = (1.0 - 2.0 * (y as f64 + sy) / self.height) * self.scale;
        (
            self.eye,
            (self.forward + a * self.right + b * self.up).normalize(),
        )
    }

    /// The ray through the centre of pixel (x, y), rounded once to `f32`.
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        self.ray_at(x, y, 0.5, 0.5)
    }

    /// The ray through offset (sx, sy) of pixel (x, y), rounded once to `f32`.
    pub fn ray_at(&self, x: u32, y: u32, sx: f64, sy: f64) -> Ray {
        let (o, d) = self.ray_f64(x, y, sx, sy);
        Ray::new(o.as_vec3(), d.as_vec3())
    }

    /// The continuous pixel coordinates (x from the left, y from the top) and the depth
    /// along the view direction of a point in front of the eye: the inverse of
    /// [`CameraRays::ray_f64`]. `None` for a point on or behind the eye's plane.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64, f64)> {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        if depth.is_nan() || depth <= 0.0 {
            return None;
        }
        let a = d.dot(self.right) / depth;
        let b = d.dot(self.up) / depth;
        let x = (a * self.height / (self.scale * self.width) + 1.0) * self.width / 2.0;
        let y = (1.0 - b / self.scale) * self.height / 2.0;
        Some((x, y, depth))
    }

    pub fn eye(&self) -> Vec3 {
        self.eye.as_vec3()
    }

    /// What adaptive termination (Dammertz §2.5.3) needs: the view direction and half a
    /// pixel's edge on the image plane at distance 1 (pixels are square: `2 s / height`
    /// wide and high).
    pub fn footprint(&self) -> ScreenFootprint {
        ScreenFootprint {
            forward: self.forward.as_vec3().to_array(),
            half_pixel: (self.scale / self.height) as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, -8.0, 4.5),
            look_at: DVec3::new(0.0, 0.0, 1.2),
            up: DVec3::Z,
            fov_y: 40.0,
            width: 640,
            height: 480,
        }
    }

    #[test]
    fn centre_ray_looks_at_the_target() {
        let mut c = camera();
        c.width = 2;
        c.height = 2;
        let cam = CameraRays::new(&c);
        // With 2x2 pixels, the four centre rays are symmetric about the view direction.
        let f = (c.look_at - c.eye).normalize();
        let sum: DVec3 = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .map(|&(x, y)| cam.ray_f64(x, y, 0.5, 0.5).1)
            .sum();
        assert!((sum.normalize() - f).length() < 1e-12);
    }

    #[test]
    fn projection_inverts_the_pixel_ray() {
        let c = camera();
        let cam = CameraRays::new(&c);
        for &(x, y, sx, sy) in &[
            (0, 0, 0.25, 0.75),
            (639, 479, 0.5, 0.5),
            (100, 300, 0.9, 0.1),
        ] {
            let (o, d) = cam.ray_f64(x, y, sx, sy);
            let (px, py, depth) = cam.project(o + 7.0 * d).expect("in front");
            assert!((px - (x as f64 + sx)).abs() < 1e-9, "{px} vs {x}+{sx}");
            assert!((py - (y as f64 + sy)).abs() < 1e-9, "{py} vs {y}+{sy}");
            // The depth along the view direction is the distance times the cosine.
            let f = (c.look_at - c.eye).normalize();
            assert!((depth - 7.0 * d.dot(f)).abs() < 1e-9);
        }
        assert!(cam.project(c.eye - (c.look_at - c.eye)).is_none());
    }

    #[test]
    fn corner_ray_follows_the_contract_formula() {
        let c = camera();
        let cam = CameraRays::new(&c);
        let (_, d) = cam.ray_f64(0, 0, 0.0, 0.0);
        // Top-left corner: a = -s * aspect, b = s; the angle to the vertical centre line of
        // the image is half the vertical field of view.
        let f = (c.look_at - c.eye).normalize();
        let r = f.cross(c.up).normalize();
        let u = r.cross(f);
        let s = 20f64.to_radians().tan();
        let expect = (f - s * 640.0 / 480.0 * r + s * u).normalize();
        assert!((d - expect).length() < 1e-15);
        assert!(d.dot(u) > 0.0 && d.dot(r) < 0.0);
    }
}
