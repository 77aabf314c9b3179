//! Sampling orders (LG90 §5): the order in which the pixels of an image are traced. The
//! image does not depend on it; a kernel that caches per-surface work between rays (the
//! surface trees of LG90 §4.3) does, because consecutive rays through the same surface
//! reuse what the previous ones built.
//!
//! - `tiles`: 16×16 tiles in row-major order, rows within a tile (the default).
//! - `scanline`: whole image rows, top to bottom.
//! - `hilbert`: the pixels along a Hilbert curve over the image (LG90 §5.2's Peano curve
//!   order: each quadrant is finished before the next, recursively).
//! - `itembuffer`: the approximate item buffer of LG90 §5.1: a 64×64 buffer over the image
//!   whose cells keep the closest patch among those whose projected bounding box overlaps
//!   the cell; pixels are then traced surface by surface, grouped by their cell's patch.

use glam::DVec3;

use super::camera::CameraRays;
use crate::geom::DAabb;
use crate::scene::Scene;

/// Edge of the approximate item buffer in cells (LG90 §5.1: "a low resolution (e.g.,
/// 64×64) buffer").
pub const ITEM_BUFFER_CELLS: u32 = 64;

/// The order in which pixels are traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum SampleOrder {
    /// 16×16 tiles row by row, each tile row by row.
    #[default]
    Tiles,
    /// Image rows top to bottom (LG90's SCAN).
    Scanline,
    /// Along a Hilbert curve over the image (LG90 §5.2, the PEANO column).
    Hilbert,
    /// Surface by surface from an approximate 64×64 item buffer (LG90 §5.1, ITBUF).
    Itembuffer,
}

impl SampleOrder {
    /// Every pixel index `y · width + x` of a `width`×`height` image exactly once, in this
    /// order. `tile` is the tile edge of [`SampleOrder::Tiles`]; the item buffer projects the
    /// scene's patches through `camera`.
    pub fn pixels(
        self,
        scene: &Scene,
        camera: &CameraRays,
        width: u32,
        height: u32,
        tile: u32,
    ) -> Vec<u32> {
        match self {
            SampleOrder::Tiles => tiles(width, height, tile),
            SampleOrder::Scanline => (0..width * height).collect(),
            SampleOrder::Hilbert => hilbert(width, height),
            SampleOrder::Itembuffer => {
                let boxes = scene
                    .objects
                    .iter()
                    .flat_map(|o| o.bezier_patches())
                    .map(|p| p.control_box());
                ItemBuffer::build(camera, boxes, width, height).order()
            }
        }
    }
}

fn tiles(width: u32, height: u32, tile: u32) -> Vec<u32> {
    let mut out = Vec::with_capacity((width * height) as usize);
    for y0 in (0..height).step_by(tile as usize) {
        for x0 in (0..width).step_by(tile as usize) {
            for y in y0..(y0 + tile).min(height) {
                out.extend((x0..(x0 + tile).min(width)).map(|x| y * width + x));
            }
        }
    }
    out
}

/// Pixels along the Hilbert curve of the smallest power-of-two square covering the image,
/// skipping the points outside it.
fn hilbert(width: u32, height: u32) -> Vec<u32> {
    let n = width.max(height).next_power_of_two() as u64;
    let mut out = Vec::with_capacity((width * height) as usize);
    for d in 0..n * n {
        let (x, y) = hilbert_point(n, d);
        if x < width as u64 && y < height as u64 {
            out.push((y * width as u64 + x) as u32);
        }
    }
    out
}

/// Point `d` of the Hilbert curve over an `n`×`n` grid, `n` a power of two (the classic
/// iterative conversion: one quadrant choice and rotation per level).
fn hilbert_point(n: u64, d: u64) -> (u64, u64) {
    let (mut x, mut y, mut t) = (0u64, 0u64, d);
    let mut s = 1;
    while s < n {
        let rx = 1 & (t / 2);
        let ry = 1 & (t ^ rx);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - x;
                y = s - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        x += s * rx;
        y += s * ry;
        t /= 4;
        s *= 2;
    }
    (x, y)
}

/// The approximate item buffer of LG90 §5.1: per cell, the patch whose projected bounding
/// box overlaps it and is nearest to the eye.
pub struct ItemBuffer {
    width: u32,
    height: u32,
    /// Patch number per cell, row-major, `None` where no box projects.
    cells: Vec<Option<u32>>,
}

impl ItemBuffer {
    /// Projects each box (patch `i` is the `i`-th) and keeps the nearest per cell, nearness
    /// being the smallest depth of the box's corners. A box reaching behind the eye
    /// covers the whole image at depth 0: it surrounds the eye, and the buffer only orders
    /// samples, so a coarse answer does no harm (§5.1).
    pub fn build(
        camera: &CameraRays,
        boxes: impl Iterator<Item = DAabb>,
        width: u32,
        height: u32,
    ) -> ItemBuffer {
        let n = ITEM_BUFFER_CELLS as usize;
        let mut cells: Vec<Option<u32>> = vec![None; n * n];
        let mut depth = vec![f64::INFINITY; n * n];
        let (cw, ch) = (
            width as f64 / ITEM_BUFFER_CELLS as f64,
            height as f64 / ITEM_BUFFER_CELLS as f64,
        );
        for (i, b) in boxes.enumerate() {
            let Some((x0, y0, x1, y1, near)) = project_box(camera, &b, width, height) else {
                continue;
            };
            let cell = |v: f64, size: f64| ((v / size).floor().max(0.0) as usize).min(n - 1);
            let (cx0, cx1) = (cell(x0, cw), cell(x1, cw));
            let (cy0, cy1) = (cell(y0, ch), cell(y1, ch));
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    let k = cy * n + cx;
                    if near < depth[k] {
                        depth[k] = near;
                        cells[k] = Some(i as u32);
                    }
                }
            }
        }
        ItemBuffer {
            width,
            height,
            cells,
        }
    }

    /// The patch of the cell holding pixel (x, y).
    pub fn patch_at(&self, x: u32, y: u32) -> Option<u32> {
        let n = ITEM_BUFFER_CELLS as u64;
        let cx = (x as u64 * n / self.width as u64) as usize;
        let cy = (y as u64 * n / self.height as u64) as usize;
        self.cells[cy * n as usize + cx]
    }

    /// All pixels, surface by surface in patch order, each surface's pixels row by row;
    /// pixels whose cell holds no patch come last.
    pub fn order(&self) -> Vec<u32> {
        let mut keyed: Vec<(u32, u32)> = (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .map(|(x, y)| (self.patch_at(x, y).unwrap_or(u32::MAX), y * self.width + x))
            .collect();
        keyed.sort_unstable();
        keyed.into_iter().map(|(_, p)| p).collect()
    }
}

/// The pixel rectangle (x0, y0, x1, y1) covered by a box's projection, clipped to the
/// image, and its nearest depth; `None` when it falls outside the image.
fn project_box(
    camera: &CameraRays,
    b: &DAabb,
    width: u32,
    height: u32,
) -> Option<(f64, f64, f64, f64, f64)> {
    let (w, h) = (width as f64, height as f64);
    let (mut x0, mut y0, mut x1, mut y1) =
        (f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY);
    let mut near = f64::INFINITY;
    for k in 0..8 {
        let corner = DVec3::new(
            if k & 1 == 0 { b.min.x } else { b.max.x },
            if k & 2 == 0 { b.min.y } else { b.max.y },
            if k & 4 == 0 { b.min.z } else { b.max.z },
        );
        let Some((x, y, d)) = camera.project(corner) else {
            return Some((0.0, 0.0, w, h, 0.0));
        };
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
        near = near.min(d);
    }
    (x1 >= 0.0 && y1 >= 0.0 && x0 < w && y0 < h).then_some((x0, y0, x1, y1, near))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Camera;

    fn camera(width: u32, height: u32) -> (Camera, CameraRays) {
        let c = Camera {
            eye: DVec3::new(0.0, -10.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::Z,
            fov_y: 40.0,
            width,
            height,
        };
        let rays = CameraRays::new(&c);
        (c, rays)
    }

    fn is_permutation(order: &[u32], n: u32) -> bool {
        let mut seen = vec![false; n as usize];
        order.len() == n as usize
            && order
                .iter()
                .all(|&p| p < n && !std::mem::replace(&mut seen[p as usize], true))
    }

    #[test]
    fn every_order_visits_every_pixel_once() {
        let scene = Scene::framing(Vec::new());
        let (_, cam) = camera(37, 21);
        for order in [
            SampleOrder::Tiles,
            SampleOrder::Scanline,
            SampleOrder::Hilbert,
            SampleOrder::Itembuffer,
        ] {
            let p = order.pixels(&scene, &cam, 37, 21, 16);
            assert!(is_permutation(&p, 37 * 21), "{order:?}");
        }
    }

    #[test]
    fn hilbert_steps_to_a_neighbour_and_finishes_each_quadrant_first() {
        let p = hilbert(32, 32);
        for w in p.windows(2) {
            let (a, b) = ((w[0] % 32, w[0] / 32), (w[1] % 32, w[1] / 32));
            assert_eq!(a.0.abs_diff(b.0) + a.1.abs_diff(b.1), 1, "{a:?} -> {b:?}");
        }
        // The first quarter of the sequence is one 16×16 quadrant.
        let quadrant = |i: u32| ((i % 32) / 16, (i / 32) / 16);
        assert!(p[..256].iter().all(|&i| quadrant(i) == quadrant(p[0])));
    }

    #[test]
    fn item_buffer_keeps_the_nearest_box_per_cell() {
        let (_, cam) = camera(64, 64);
        // A small box in front of a large one: the centre cells go to the small box, the
        // rim of the large one (seen around it) to the large box.
        let near = DAabb {
            min: DVec3::new(-0.2, -4.0, -0.2),
            max: DVec3::new(0.2, -3.8, 0.2),
        };
        let far = DAabb {
            min: DVec3::new(-2.0, 0.0, -2.0),
            max: DVec3::new(2.0, 0.5, 2.0),
        };
        let ib = ItemBuffer::build(&cam, [far, near].into_iter(), 64, 64);
        assert_eq!(ib.patch_at(32, 32), Some(1));
        let (x, y, _) = cam.project(DVec3::new(1.8, 0.0, 0.0)).unwrap();
        assert_eq!(ib.patch_at(x as u32, y as u32), Some(0));
        assert_eq!(ib.patch_at(0, 0), None);
        // Pixels are grouped: all of patch 0's, then patch 1's, then the empty cells'.
        let keys: Vec<u32> = ib
            .order()
            .iter()
            .map(|&i| ib.patch_at(i % 64, i / 64).unwrap_or(u32::MAX))
            .collect();
        assert!(keys.windows(2).all(|w| w[0] <= w[1]));
    }
}
