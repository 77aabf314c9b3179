//! A floating origin for scenes far from the world origin.
//!
//! The kernels work in `f32` (DESIGN.md conventions), whose ulp grows with the coordinate,
//! not with the model: a 100 mm part placed 14,000 mm from the origin (vehicle coordinates,
//! plant layouts, a CAD assembly's placement) keeps about 2^-10 mm of its 2^-17 mm at home,
//! and hit points move by hundreds of ulps of the model's own size. Rendering and tracing
//! therefore move the whole scene (geometry, camera, lights) by `-origin` in `f64`, before
//! anything is rounded to `f32`, and add `origin` back to every world position they report
//! (the `trace` hit points, the position AOV). Rays, hit boxes and secondary-ray origins
//! live in the moved frame, where each `f32` coordinate is as fine as the model allows;
//! directions, `t` and normals are the same in both frames.
//!
//! A scene whose geometry sits around the world origin is not moved at all (its origin is
//! zero), so its arithmetic, and its image, stay exactly what they were.

use glam::{DAffine3, DVec3};

use super::{Light, Scene};
use crate::scene::animation::CameraPath;

/// How far, in multiples of the geometry's largest extent, its centre may lie from the
/// world origin before the scene is moved. At 1 the coordinates' ulps are at most twice
/// the model's own, so moving changes only the last bit; beyond it every doubling of the
/// distance loses one more bit of the model.
pub const FAR_FACTOR: f64 = 1.0;

impl Scene {
    /// The origin rendering and tracing move this scene to: the centre of its geometry's
    /// bounds when that centre lies more than [`FAR_FACTOR`] extents from the world origin,
    /// else zero. The centre is rounded to `f32` so that it is itself a coordinate the
    /// renderer could hold.
    pub fn floating_origin(&self) -> DVec3 {
        let b = self.bounds();
        if b.is_empty() {
            return DVec3::ZERO;
        }
        let centre = b.center();
        let extent = b.extent().max_element();
        if centre.abs().max_element() > FAR_FACTOR * extent {
            centre.as_vec3().as_dvec3()
        } else {
            DVec3::ZERO
        }
    }

    /// Moves everything in the scene by `offset`: geometry, camera (and its animation),
    /// lights, and the bounds of geometry not read.
    pub fn translate(&mut self, offset: DVec3) {
        if offset == DVec3::ZERO {
            return;
        }
        let m = DAffine3::from_translation(offset);
        for object in &mut self.objects {
            object.geometry.transform(&m);
        }
        self.camera.eye += offset;
        self.camera.look_at += offset;
        if let Some(CameraPath::Keys(keys)) = &mut self.animation {
            for key in keys {
                key.eye += offset;
                key.look_at += offset;
            }
        }
        for light in &mut self.lights {
            if let Light::Point { position, .. } = light {
                *position += offset;
            }
        }
        if let Some(b) = &mut self.unread_bounds {
            b.min += offset;
            b.max += offset;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierPatch;
    use crate::scene::{Geometry, Object, Surface};

    fn patch_at(offset: DVec3, size: f64) -> Scene {
        let points = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                (offset + DVec3::new(i, j, (i * j) % 2.0) * size / 3.0).extend(1.0)
            })
            .collect();
        let patch = BezierPatch::new(3, 3, points).unwrap();
        let object = Object {
            name: "p".into(),
            material: 0,
            geometry: Geometry::Surfaces(vec![Surface::bezier(patch)]),
        };
        Scene::framing(vec![object])
    }

    #[test]
    fn scenes_near_the_origin_stay_and_far_ones_move_to_their_centre() {
        assert_eq!(
            patch_at(DVec3::new(-0.5, -0.5, 0.0), 1.0).floating_origin(),
            DVec3::ZERO
        );
        // A unit patch one extent away is still near; ten extents away it moves.
        assert_eq!(
            patch_at(DVec3::new(0.4, 0.0, 0.0), 1.0).floating_origin(),
            DVec3::ZERO
        );
        let far = patch_at(DVec3::new(14_000.0, -3_000.0, 250.0), 100.0);
        let origin = far.floating_origin();
        let centre = far.bounds().center();
        assert!((origin - centre).abs().max_element() <= 1e-3);
        assert_eq!(origin.as_vec3().as_dvec3(), origin);
    }

    #[test]
    fn translation_moves_geometry_camera_and_lights_together() {
        let scene = patch_at(DVec3::new(14_000.0, -3_000.0, 250.0), 100.0);
        let mut moved = scene.clone();
        let offset = -scene.floating_origin();
        moved.translate(offset);
        let (a, b) = (scene.bounds(), moved.bounds());
        assert!((b.min - (a.min + offset)).abs().max_element() < 1e-9);
        assert!((b.center()).abs().max_element() < 1e-3);
        assert_eq!(moved.camera.eye, scene.camera.eye + offset);
        assert_eq!(moved.camera.look_at, scene.camera.look_at + offset);
        for (l, m) in scene.lights.iter().zip(&moved.lights) {
            match (l, m) {
                (Light::Point { position: p, .. }, Light::Point { position: q, .. }) => {
                    assert_eq!(*q, *p + offset)
                }
                (l, m) => assert_eq!(l, m),
            }
        }
    }
}
