//! Rendered images as pieces of a whole: where the pixels sit in the camera's image and
//! what made them, stored in the file so `merge` can check that pieces belong together.
//!
//! - EXR: the data window is the piece's window and the display window the whole image
//!   (OpenEXR, *Technical Introduction*, "Data Window and Display Window"); the render's
//!   provenance is one text attribute, `patchtrace`.
//! - PNG: the pixels are the window's; tEXt chunks (PNG 1.2 §11.3.4.3) hold the
//!   provenance (`patchtrace`) and the window (`patchtrace:window`, `X0,X1,Y0,Y1 of WxH`).
//!
//! A whole-image render carries the same records, so a merged image is byte for byte the
//! image rendered in one piece. Files are written to a temporary name and renamed.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Blocks, Compression, Encoding, FlatSamples, Image,
    ImageAttributes, IntegerBounds, Layer, LayerAttributes, LineOrder, ReadChannels, ReadLayers,
    Text, Vec2, WritableImage, read,
};

use super::window::Window;
use crate::scene::LoadError;
use crate::scene::write::{temporary_name, write_atomic};

/// EXR attribute and PNG keyword of the provenance.
pub const PROVENANCE_KEY: &str = "patchtrace";
/// PNG keyword of the window.
pub const WINDOW_KEY: &str = "patchtrace:window";

/// Where a piece sits in its image and what made it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PieceInfo {
    /// The whole image's size.
    pub width: u32,
    pub height: u32,
    pub window: Window,
    /// The scene and settings that made it (see `cli::render`); pieces merge only when
    /// these agree exactly.
    pub provenance: String,
}

/// One piece as read back: its placement, and its pixels as EXR channels (linear, any
/// AOV layers) or as 8-bit sRGB RGBA.
pub struct Piece {
    pub info: PieceInfo,
    pub pixels: PiecePixels,
}

pub enum PiecePixels {
    Exr(Vec<AnyChannel<FlatSamples>>),
    Png(Vec<u8>),
}

/// The one encoding of every EXR we write: ZIP over 16-line blocks written in increasing
/// order, so the bytes are the same on every run (tiles in unspecified order would be
/// written as the compressing threads finish).
const ENCODING: Encoding = Encoding {
    compression: Compression::ZIP16,
    blocks: Blocks::ScanLines,
    line_order: LineOrder::Increasing,
};

/// Writes `channels` (each over `info.window`, row-major) as one EXR layer.
pub fn write_exr(
    path: &Path,
    info: &PieceInfo,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Result<(), LoadError> {
    let w = info.window;
    let mut attributes = LayerAttributes {
        layer_position: Vec2(w.x0 as i32, w.y0 as i32),
        ..LayerAttributes::default()
    };
    attributes.other.insert(
        Text::from(PROVENANCE_KEY),
        AttributeValue::Text(Text::from(info.provenance.as_str())),
    );
    let layer = Layer::new(
        (w.width() as usize, w.height() as usize),
        attributes,
        ENCODING,
        AnyChannels::sort(channels.into()),
    );
    let display = IntegerBounds::from_dimensions((info.width as usize, info.height as usize));
    let image = Image::empty(ImageAttributes::new(display)).with_layer(layer);
    let tmp = temporary_name(path);
    image.write().to_file(&tmp).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        LoadError::invalid(path, format!("writing EXR: {e}"))
    })?;
    std::fs::rename(&tmp, path).map_err(|e| LoadError::io(path, e))
}

/// Writes 8-bit sRGB RGBA pixels of `info.window` as PNG with the piece's text chunks.
pub fn write_png(path: &Path, info: &PieceInfo, rgba8: &[u8]) -> Result<(), LoadError> {
    let w = info.window;
    write_atomic(path, |out| {
        let mut enc = png::Encoder::new(out, w.width(), w.height());
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        // fdeflate's PNG-tuned compressor: the default zlib level took 4 % of the teapot
        // render's CPU time, this 0.3 %, for files 1.44 times as large (106 KB against
        // 74 KB at 512², BENCHMARKS.md, scenes at scale).
        enc.set_compression(png::Compression::Fast);
        let text = |e: png::EncodingError| std::io::Error::other(e);
        enc.add_text_chunk(PROVENANCE_KEY.into(), info.provenance.clone())
            .map_err(text)?;
        enc.add_text_chunk(
            WINDOW_KEY.into(),
            format!("{w} of {}x{}", info.width, info.height),
        )
        .map_err(text)?;
        let mut writer = enc.write_header().map_err(text)?;
        writer.write_image_data(rgba8).map_err(text)?;
        writer.finish().map_err(text)
    })
}

/// A 64-bit FNV-1a hash of a value's `Debug` text: stable across runs and machines (unlike
/// std's randomly keyed hasher), so pieces rendered anywhere can be compared.
pub fn fingerprint(value: &impl std::fmt::Debug) -> u64 {
    struct Fnv(u64);
    impl std::fmt::Write for Fnv {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            for b in s.bytes() {
                self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
            }
            Ok(())
        }
    }
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let _ = std::fmt::write(&mut h, format_args!("{value:?}"));
    h.0
}

/// Reads a piece written by [`write_exr`] or [`write_png`].
pub fn read_piece(path: &Path) -> Result<Piece, LoadError> {
    match super::film::ImageFormat::of(path) {
        Some(super::film::ImageFormat::Exr) => read_exr(path),
        Some(super::film::ImageFormat::Png) => read_png(path),
        None => Err(LoadError::invalid(
            path,
            "unsupported image type: expected .png or .exr",
        )),
    }
}

fn not_a_piece(path: &Path, what: &str) -> LoadError {
    LoadError::invalid(
        path,
        format!("{what}: not a piece written by `patchtrace render`"),
    )
}

fn read_exr(path: &Path) -> Result<Piece, LoadError> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| LoadError::invalid(path, format!("reading EXR: {e}")))?;
    let layer = image.layer_data;
    let provenance = match layer.attributes.other.get(&Text::from(PROVENANCE_KEY)) {
        Some(AttributeValue::Text(t)) => t.to_string(),
        _ => return Err(not_a_piece(path, "no `patchtrace` attribute")),
    };
    let display = image.attributes.display_window;
    let pos = layer.attributes.layer_position;
    let whole = Window::full(display.size.0 as u32, display.size.1 as u32);
    if display.position != Vec2(0, 0) || pos.0 < 0 || pos.1 < 0 {
        return Err(not_a_piece(
            path,
            "the display window does not start at 0,0",
        ));
    }
    let window = Window {
        x0: pos.0 as u32,
        x1: pos.0 as u32 + layer.size.0 as u32,
        y0: pos.1 as u32,
        y1: pos.1 as u32 + layer.size.1 as u32,
    };
    window
        .check(whole.x1, whole.y1)
        .map_err(|e| not_a_piece(path, &e))?;
    Ok(Piece {
        info: PieceInfo {
            width: whole.x1,
            height: whole.y1,
            window,
            provenance,
        },
        pixels: PiecePixels::Exr(layer.channel_data.list.into_vec()),
    })
}

fn read_png(path: &Path) -> Result<Piece, LoadError> {
    let file = std::fs::File::open(path).map_err(|e| LoadError::io(path, e))?;
    let bad = |e: png::DecodingError| LoadError::invalid(path, format!("reading PNG: {e}"));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(bad)?;
    let text = |key: &str| {
        reader
            .info()
            .uncompressed_latin1_text
            .iter()
            .find(|c| c.keyword == key)
            .map(|c| c.text.clone())
    };
    let provenance =
        text(PROVENANCE_KEY).ok_or_else(|| not_a_piece(path, "no `patchtrace` text"))?;
    let placement = text(WINDOW_KEY).ok_or_else(|| not_a_piece(path, "no window text"))?;
    let (window, size) = placement
        .split_once(" of ")
        .ok_or_else(|| not_a_piece(path, "bad window text"))?;
    let window: Window = window.parse().map_err(|e: String| not_a_piece(path, &e))?;
    let (width, height) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
        .ok_or_else(|| not_a_piece(path, "bad image size"))?;
    window
        .check(width, height)
        .map_err(|e| not_a_piece(path, &e))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Rgba
        || info.bit_depth != png::BitDepth::Eight
        || (info.width, info.height) != (window.width(), window.height())
    {
        return Err(not_a_piece(path, "not 8-bit RGBA of the window's size"));
    }
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let frame = reader.next_frame(&mut buf).map_err(bad)?;
    buf.truncate(frame.buffer_size());
    Ok(Piece {
        info: PieceInfo {
            width,
            height,
            window,
            provenance,
        },
        pixels: PiecePixels::Png(buf),
    })
}
