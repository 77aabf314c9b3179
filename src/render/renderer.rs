//! Rendering an image or a window of it: runs of 16×16 pixels traced in parallel with
//! rayon, each pixel the mean of its samples (`sampler`). Each pixel depends only on its
//! own rays, so the image is the same, byte for byte, for any number of threads, any
//! sampling order and any split into tiles.

use glam::Vec4;
use indicatif::ProgressBar;
use rayon::prelude::*;

use super::camera::CameraRays;
use super::film::{Film, linear_to_srgb};
use super::integrator::Integrator;
use super::order::SampleOrder;
use super::sampler::{ADAPTIVE_FIRST, Filter, SampleCount, pixel_sample};
use super::stats::RayTally;
use super::window::Window;
use crate::accel::scene::{QueryStats, SceneHit};

/// Edge of a square tile in pixels: small enough to balance two cores on a 512² image,
/// large enough that scheduling costs nothing.
const TILE: u32 = 16;

/// What to render: the pixel order, the samples per pixel and their filter, the window of
/// the camera's image, and whether to record the centre ray's hit per pixel for the AOVs.
#[derive(Clone, Copy, Debug)]
pub struct RenderJob {
    pub order: SampleOrder,
    pub samples: SampleCount,
    pub filter: Filter,
    pub window: Window,
    pub hits: bool,
}

impl RenderJob {
    /// One sample at each pixel centre of the whole image, in `order`.
    pub fn whole(camera: &crate::scene::Camera, order: SampleOrder) -> RenderJob {
        RenderJob {
            order,
            samples: SampleCount::Fixed(1),
            filter: Filter::Box,
            window: Window::full(camera.width, camera.height),
            hits: false,
        }
    }
}

/// A rendered window: its image, the ray statistics, and per pixel (row-major over the
/// window) the effort, de Casteljau splits of all rays the pixel started (Dammertz Fig.
/// 2.9), the samples taken, and with [`RenderJob::hits`] the centre ray's hit.
pub struct Rendered {
    pub film: Film,
    pub tally: RayTally,
    pub effort: Vec<u32>,
    pub samples: Vec<u32>,
    pub hits: Vec<Option<CentreHit>>,
}

/// The nearest hit of a pixel's centre ray (the DESIGN.md camera ray with offset 0.5,
/// 0.5), for the geometric AOVs: the same ray `trace` would be given for the pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CentreHit {
    pub hit: SceneHit,
    /// The hit point, origin + t · direction of the `f32` ray as traced.
    pub point: glam::DVec3,
}

/// One traced pixel. The centre hit, asked for only by the geometric AOVs, is boxed: a
/// [`SceneHit`] is some 170 bytes, which per pixel of every render was most of the memory
/// of a 512² render (52 of 64 MB resident).
struct PixelResult {
    color: Vec4,
    splits: u32,
    samples: u32,
    hit: Option<Box<CentreHit>>,
}

/// Traces every pixel of the scene camera in the default order. `progress` is advanced
/// per tile.
pub fn render_image(integrator: &Integrator, progress: &ProgressBar) -> Rendered {
    render_image_in_order(integrator, SampleOrder::default(), progress)
}

/// Traces every pixel of the scene camera in `order`, one sample per pixel.
pub fn render_image_in_order(
    integrator: &Integrator,
    order: SampleOrder,
    progress: &ProgressBar,
) -> Rendered {
    render(
        integrator,
        &RenderJob::whole(&integrator.scene.camera, order),
        progress,
    )
}

/// Traces the pixels of `job.window` in `job.order` (LG90 §5): the order's sequence over
/// the whole image, less the pixels outside the window, is cut into runs of one tile's
/// worth of pixels, which rayon hands out to the workers as contiguous shares, so each
/// worker traces its pixels in the order's sequence. A pixel depends only on its own
/// samples, so the image does not depend on the order, the threads or the window.
pub fn render(integrator: &Integrator, job: &RenderJob, progress: &ProgressBar) -> Rendered {
    let cam = &integrator.scene.camera;
    let (width, height) = (cam.width, cam.height);
    let win = job.window;
    let rays = CameraRays::new(cam);
    let mut sequence = job
        .order
        .pixels(integrator.scene, &rays, width, height, TILE);
    if win != Window::full(width, height) {
        sequence.retain(|&i| win.contains(i % width, i / width));
    }
    let run = (TILE * TILE) as usize;
    progress.set_length(sequence.len().div_ceil(run) as u64);
    let results: Vec<(&[u32], Vec<PixelResult>, RayTally)> = sequence
        .par_chunks(run)
        .map(|chunk| {
            let mut tally = RayTally::default();
            let px = chunk
                .iter()
                .map(|&i| trace_pixel(integrator, &rays, job, i % width, i / width, &mut tally))
                .collect();
            progress.inc(1);
            (chunk, px, tally)
        })
        .collect();
    let n = (win.width() * win.height()) as usize;
    let mut film = Film {
        width: win.width(),
        height: win.height(),
        pixels: vec![Vec4::ZERO; n],
    };
    let mut effort = vec![0; n];
    let mut samples = vec![0; n];
    let mut hits = vec![None; if job.hits { n } else { 0 }];
    let mut total = RayTally::default();
    for (indices, px, tally) in results {
        for (&i, p) in indices.iter().zip(px) {
            let k = ((i / width - win.y0) * win.width() + (i % width - win.x0)) as usize;
            film.pixels[k] = p.color;
            effort[k] = p.splits;
            samples[k] = p.samples;
            if job.hits {
                hits[k] = p.hit.map(|h| *h);
            }
        }
        total = total.merge(tally);
    }
    progress.finish_and_clear();
    Rendered {
        film,
        tally: total,
        effort,
        samples,
        hits,
    }
}

/// The mean of a pixel's samples, its splits, its sample count, and the centre hit.
fn trace_pixel(
    integrator: &Integrator,
    rays: &CameraRays,
    job: &RenderJob,
    x: u32,
    y: u32,
    tally: &mut RayTally,
) -> PixelResult {
    let before = tally.splits();
    let mut shade = |i: u32, count: u32| {
        // One sample is the pixel centre of the camera contract; more follow the pixel's
        // stratified sequence, warped by the filter.
        let (sx, sy) = if count == 1 {
            (0.5, 0.5)
        } else {
            job.filter.offset(pixel_sample(x, y, i))
        };
        integrator.primary(&rays.ray_at(x, y, sx, sy), tally)
    };
    // Fixed counts are summed as they come (no vector per pixel); adaptive sampling keeps
    // its first samples to compare them. Either sum runs in sample order from zero.
    let (sum, count) = match job.samples {
        SampleCount::Fixed(n) => ((0..n).map(|i| shade(i, n)).sum::<Vec4>(), n),
        SampleCount::Adaptive { max } => {
            let first = ADAPTIVE_FIRST.min(max);
            let mut taken: Vec<Vec4> = (0..first).map(|i| shade(i, max)).collect();
            if disagree(&taken) {
                taken.extend((first..max).map(|i| shade(i, max)));
            }
            (taken.iter().copied().sum(), taken.len() as u32)
        }
    };
    let hit = job
        .hits
        .then(|| centre_hit(integrator, rays, x, y))
        .flatten()
        .map(Box::new);
    PixelResult {
        color: sum / count as f32,
        splits: (tally.splits() - before).min(u32::MAX as u64) as u32,
        samples: count,
        hit,
    }
}

/// Largest difference between two samples of a pixel, per sRGB-encoded channel, below
/// which adaptive sampling leaves the pixel with its first samples: 2/255, two steps of
/// an 8-bit image. The error of the mean of the first samples is under half their spread,
/// so pixels left alone are within one 8-bit step of their refined value, and smooth
/// shading (well under a step across a pixel) never triggers refinement.
pub const ADAPTIVE_SPREAD: f32 = 2.0 / 255.0;

/// Whether a pixel's first samples disagree: coverage differs (a silhouette) or a colour
/// channel spreads by more than [`ADAPTIVE_SPREAD`] after sRGB encoding, the space the
/// eye and the 8-bit output judge differences in (shadow edges, reflected edges,
/// highlights).
fn disagree(samples: &[Vec4]) -> bool {
    let enc = |p: &Vec4| {
        [
            linear_to_srgb(p.x),
            linear_to_srgb(p.y),
            linear_to_srgb(p.z),
            p.w,
        ]
    };
    let first = enc(&samples[0]);
    let (mut lo, mut hi) = (first, first);
    for p in &samples[1..] {
        for (c, v) in enc(p).into_iter().enumerate() {
            lo[c] = lo[c].min(v);
            hi[c] = hi[c].max(v);
        }
    }
    hi[3] != lo[3] || (0..3).any(|c| hi[c] - lo[c] > ADAPTIVE_SPREAD)
}

/// The nearest hit of pixel (x, y)'s centre ray, by the render's kernel.
fn centre_hit(integrator: &Integrator, rays: &CameraRays, x: u32, y: u32) -> Option<CentreHit> {
    let ray = rays.ray(x, y);
    let mut q = QueryStats::default();
    let hit = integrator
        .geometry
        .intersect(&ray, &integrator.settings.precision, &mut q)?;
    Some(CentreHit {
        hit,
        point: ray.origin.as_dvec3() + ray.dir.as_dvec3() * hit.t,
    })
}
