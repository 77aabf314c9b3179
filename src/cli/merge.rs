//! `patchtrace merge PIECES... -o OUT.exr|png`: the whole image from pieces rendered with
//! `render --tile K/N` or `--crop` (pbrt-v4's `imgtool assemble`). The pieces must share
//! one provenance (scene, settings, image size) and cover the image exactly once; the
//! result is written by the same code as a render in one piece, so it is the same file.

use std::path::Path;
use std::process::ExitCode;

use exr::prelude::{AnyChannel, FlatSamples};

use crate::cli::args::MergeArgs;
use crate::formats::LoadError;
use crate::render::film::{Film, ImageFormat};
use crate::render::piece::{Piece, PieceInfo, PiecePixels, read_piece, write_exr, write_png};
use crate::render::window::{Window, check_cover};

pub fn run(args: MergeArgs) -> anyhow::Result<ExitCode> {
    let format = ImageFormat::of(&args.output).ok_or_else(|| {
        LoadError::invalid(
            &args.output,
            "unsupported image type: expected .png or .exr",
        )
    })?;
    let pieces: Vec<Piece> = args
        .pieces
        .iter()
        .map(|p| read_piece(p))
        .collect::<Result<_, _>>()?;
    let first = &pieces[0].info;
    for (piece, path) in pieces.iter().zip(&args.pieces).skip(1) {
        let i = &piece.info;
        ensure_arg!(
            (i.width, i.height, &i.provenance) == (first.width, first.height, &first.provenance),
            "{} does not come from the same render as {}:\n  {}\n  {}",
            path.display(),
            args.pieces[0].display(),
            i.provenance,
            first.provenance
        );
    }
    let windows: Vec<Window> = pieces.iter().map(|p| p.info.window).collect();
    check_cover(&windows, first.width, first.height).map_err(|e| {
        crate::cli::BadArgument(format!("the pieces do not cover the image once: {e}"))
    })?;
    let info = PieceInfo {
        window: Window::full(first.width, first.height),
        ..first.clone()
    };
    match (&pieces[0].pixels, format) {
        (PiecePixels::Png(_), ImageFormat::Exr) => {
            return Err(crate::cli::BadArgument(
                "PNG pieces hold 8-bit pixels, which cannot make the EXR a render writes; merge EXR pieces, or write a .png".into(),
            )
            .into());
        }
        (PiecePixels::Png(_), ImageFormat::Png) => {
            write_png(&args.output, &info, &join_png(&pieces, &args.pieces)?)?
        }
        (PiecePixels::Exr(_), _) => {
            let channels = join_exr(&pieces, &args.pieces)?;
            match format {
                ImageFormat::Exr => write_exr(&args.output, &info, channels)?,
                ImageFormat::Png => {
                    let film = Film::from_rgba_channels(info.width, info.height, &channels)
                        .ok_or_else(|| {
                            crate::cli::BadArgument("the pieces have no R, G, B, A channels".into())
                        })?;
                    write_png(&args.output, &info, &film.to_srgb8())?
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn mixed(path: &Path) -> anyhow::Error {
    crate::cli::BadArgument(format!(
        "{}: the pieces mix EXR and PNG files or hold different channels",
        path.display()
    ))
    .into()
}

/// Copies each piece's rows into the whole image, `bytes` per pixel.
fn place<T: Copy + Default>(info: &PieceInfo, into: &mut [T], from: &[T], per_pixel: usize) {
    let w = info.window;
    let row = w.width() as usize * per_pixel;
    for (r, y) in (w.y0..w.y1).enumerate() {
        let at = (y as usize * info.width as usize + w.x0 as usize) * per_pixel;
        into[at..at + row].copy_from_slice(&from[r * row..(r + 1) * row]);
    }
}

fn join_png(pieces: &[Piece], paths: &[std::path::PathBuf]) -> anyhow::Result<Vec<u8>> {
    let first = &pieces[0].info;
    let mut whole = vec![0u8; first.width as usize * first.height as usize * 4];
    for (piece, path) in pieces.iter().zip(paths) {
        let PiecePixels::Png(bytes) = &piece.pixels else {
            return Err(mixed(path));
        };
        place(&piece.info, &mut whole, bytes, 4);
    }
    Ok(whole)
}

/// The whole image's channels, named and typed as the first piece's.
fn join_exr(
    pieces: &[Piece],
    paths: &[std::path::PathBuf],
) -> anyhow::Result<Vec<AnyChannel<FlatSamples>>> {
    let PiecePixels::Exr(template) = &pieces[0].pixels else {
        return Err(mixed(&paths[0]));
    };
    let first = &pieces[0].info;
    let n = first.width as usize * first.height as usize;
    let mut whole: Vec<AnyChannel<FlatSamples>> = template
        .iter()
        .map(|c| {
            let data = match &c.sample_data {
                FlatSamples::F16(_) => FlatSamples::F16(vec![Default::default(); n]),
                FlatSamples::F32(_) => FlatSamples::F32(vec![0.0; n]),
                FlatSamples::U32(_) => FlatSamples::U32(vec![0; n]),
            };
            AnyChannel {
                sample_data: data,
                ..c.clone()
            }
        })
        .collect();
    for (piece, path) in pieces.iter().zip(paths) {
        let PiecePixels::Exr(channels) = &piece.pixels else {
            return Err(mixed(path));
        };
        if channels.len() != whole.len() {
            return Err(mixed(path));
        }
        for (into, from) in whole.iter_mut().zip(channels) {
            if into.name != from.name {
                return Err(mixed(path));
            }
            match (&mut into.sample_data, &from.sample_data) {
                (FlatSamples::F16(a), FlatSamples::F16(b)) => place(&piece.info, a, b, 1),
                (FlatSamples::F32(a), FlatSamples::F32(b)) => place(&piece.info, a, b, 1),
                (FlatSamples::U32(a), FlatSamples::U32(b)) => place(&piece.info, a, b, 1),
                _ => return Err(mixed(path)),
            }
        }
    }
    Ok(whole)
}
