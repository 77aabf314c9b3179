//! Rendering an image: 16×16 tiles traced in parallel with rayon. Each pixel depends only
//! on its own rays, so the image is the same, byte for byte, for any number of threads.

use glam::Vec4;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::camera::CameraRays;
use super::film::Film;
use super::integrator::Integrator;
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

/// A traced tile: its corner, (colour, splits) per pixel row-major, and its statistics.
type TileResult = (u32, u32, Vec<(Vec4, u32)>, RayTally);

/// Traces every pixel of the scene camera. `progress` is advanced per tile.
pub fn render_image(integrator: &Integrator, progress: &ProgressBar) -> Rendered {
    let cam = &integrator.scene.camera;
    let (width, height) = (cam.width, cam.height);
    let rays = CameraRays::new(cam);
    let tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    progress.set_length(tiles.len() as u64);
    let results: Vec<TileResult> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let mut tally = RayTally::default();
            let (x1, y1) = ((x0 + TILE).min(width), (y0 + TILE).min(height));
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for y in y0..y1 {
                for x in x0..x1 {
                    let before = tally.splits();
                    let color = integrator.primary(&rays.ray(x, y), &mut tally);
                    px.push((color, (tally.splits() - before).min(u32::MAX as u64) as u32));
                }
            }
            progress.inc(1);
            (x0, y0, px, tally)
        })
        .collect();
    let mut film = Film {
        width,
        height,
        pixels: vec![Vec4::ZERO; (width * height) as usize],
    };
    let mut effort = vec![0; (width * height) as usize];
    let mut total = RayTally::default();
    for (x0, y0, px, tally) in results {
        let w = (x0 + TILE).min(width) - x0;
        for (k, (color, splits)) in px.into_iter().enumerate() {
            let (x, y) = (x0 + k as u32 % w, y0 + k as u32 / w);
            let i = (y * width + x) as usize;
            film.pixels[i] = color;
            effort[i] = splits;
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
