//! Rendering an image: 16×16 tiles traced in parallel with rayon. Each pixel depends only
//! on its own rays, so the image is the same, byte for byte, for any number of threads and
//! any sampling order.

use glam::Vec4;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::camera::CameraRays;
use super::film::Film;
use super::integrator::Integrator;
use super::order::SampleOrder;
use super::stats::RayTally;

/// Edge of a square tile in pixels: small enough to balance two cores on a 512² image,
/// large enough that scheduling costs nothing.
const TILE: u32 = 16;

/// A rendered image, the ray statistics, and the effort per pixel: de Casteljau splits of
/// all rays the pixel started (Dammertz Fig. 2.9), row-major.
pub struct Rendered {
    pub film: Film,
    pub tally: RayTally,
    pub effort: Vec<u32>,
}

/// A traced run of pixels: their indices, (colour, splits) per pixel in the same order,
/// and their statistics.
type ChunkResult = (Vec<u32>, Vec<(Vec4, u32)>, RayTally);

/// Traces every pixel of the scene camera in the default order. `progress` is advanced
/// per tile.
pub fn render_image(integrator: &Integrator, progress: &ProgressBar) -> Rendered {
    render_image_in_order(integrator, SampleOrder::default(), progress)
}

/// Traces every pixel of the scene camera in `order` (LG90 §5): the sequence is cut into
/// runs of one tile's worth of pixels, which rayon hands out to the workers as contiguous
/// shares, so each worker traces its pixels in the order's sequence. The image does not
/// depend on the order.
pub fn render_image_in_order(
    integrator: &Integrator,
    order: SampleOrder,
    progress: &ProgressBar,
) -> Rendered {
    let cam = &integrator.scene.camera;
    let (width, height) = (cam.width, cam.height);
    let rays = CameraRays::new(cam);
    let sequence = order.pixels(integrator.scene, &rays, width, height, TILE);
    let run = (TILE * TILE) as usize;
    progress.set_length(sequence.len().div_ceil(run) as u64);
    let results: Vec<ChunkResult> = sequence
        .par_chunks(run)
        .map(|chunk| {
            let mut tally = RayTally::default();
            let mut px = Vec::with_capacity(chunk.len());
            for &i in chunk {
                let before = tally.splits();
                let color = integrator.primary(&rays.ray(i % width, i / width), &mut tally);
                px.push((color, (tally.splits() - before).min(u32::MAX as u64) as u32));
            }
            progress.inc(1);
            (chunk.to_vec(), px, tally)
        })
        .collect();
    let mut film = Film {
        width,
        height,
        pixels: vec![Vec4::ZERO; (width * height) as usize],
    };
    let mut effort = vec![0; (width * height) as usize];
    let mut total = RayTally::default();
    for (indices, px, tally) in results {
        for (i, (color, splits)) in indices.into_iter().zip(px) {
            film.pixels[i as usize] = color;
            effort[i as usize] = splits;
        }
        total = total.merge(tally);
    }
    progress.finish_and_clear();
    Rendered {
        film,
        tally: total,
        effort,
    }
}

/// A progress bar on stderr, hidden when `quiet` or when stderr is not a terminal.
pub fn progress_bar(quiet: bool, message: &str) -> ProgressBar {
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(0);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_string());
    bar
}
