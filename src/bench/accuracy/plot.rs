//! The accuracy–time plot: mean hit error against time per ray, both axes logarithmic,
//! with the Pareto front (the methods no other method beats in both) drawn as a line.

use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::MethodResult;

/// Vertical offset of a point's label on the log error axis, as a factor.
const LABEL_LIFT: f64 = 1.35;

/// Indices of the Pareto-optimal results: no other result is at least as fast and at
/// least as accurate, and strictly better in one.
pub fn pareto_front(results: &[MethodResult]) -> Vec<usize> {
    let key = |r: &MethodResult| (r.nanoseconds_per_ray, r.hit_error.mean);
    let mut front: Vec<usize> = (0..results.len())
        .filter(|&i| {
            let (t, e) = key(&results[i]);
            !results.iter().any(|o| {
                let (to, eo) = key(o);
                to <= t && eo <= e && (to < t || eo < e)
            })
        })
        .collect();
    front.sort_by(|&a, &b| {
        results[a]
            .nanoseconds_per_ray
            .total_cmp(&results[b].nanoseconds_per_ray)
    });
    front
}

/// Size of the plot in pixels (SVG user units).
const SIZE: (u32, u32) = (900, 600);

/// The font every label is drawn in, embedded so that the plot needs no system fonts: a
/// subset of DejaVu Sans (printable ASCII and a few symbols, 11 kB, Bitstream Vera licence,
/// see `assets/fonts/LICENSE-DejaVu.txt`). plotters' `ab_glyph` text path measures and
/// rasterises with it; without a font there is no text in a bitmap.
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");

/// The family name the plot asks plotters for; [`FONT`] is registered under it.
const FAMILY: &str = "sans-serif";

fn register_font() -> Result<(), String> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    ok.then_some(())
        .ok_or_else(|| "the embedded plot font is unreadable".to_string())
}

/// SVG text of the plot. Errors of exactly 0 cannot sit on a log axis; they are drawn at
/// the bottom edge (a tenth of the smallest positive error).
pub fn svg(results: &[MethodResult], title: &str) -> Result<String, String> {
    let mut out = String::new();
    draw(
        SVGBackend::with_string(&mut out, SIZE).into_drawing_area(),
        results,
        title,
    )?;
    Ok(out)
}

/// The same plot as a PNG file's bytes (8-bit RGB).
pub fn png(results: &[MethodResult], title: &str) -> Result<Vec<u8>, String> {
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area(),
        results,
        title,
    )?;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&rgb, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// Draws the plot on any plotters backend.
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    results: &[MethodResult],
    title: &str,
) -> Result<(), String> {
    register_font()?;
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let positive: Vec<f64> = results
        .iter()
        .map(|r| r.hit_error.mean)
        .filter(|e| *e > 0.0)
        .collect();
    let floor = positive
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .min(1.0)
        / 10.0;
    let floor = if floor.is_finite() { floor } else { 1e-12 };
    let point = |r: &MethodResult| (r.nanoseconds_per_ray.max(1e-3), r.hit_error.mean.max(floor));
    let xs: Vec<f64> = results.iter().map(|r| point(r).0).collect();
    let ys: Vec<f64> = results.iter().map(|r| point(r).1).collect();
    let span = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        (lo / 2.0, hi * 2.0)
    };
    let (x0, x1) = span(&xs);
    let (y0, y1) = span(&ys);
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FAMILY, 20))
        .margin(20)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("time per ray (ns)")
        .y_desc("mean hit-point error (L1, scene units)")
        .label_style((FAMILY, 14))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(e)?;
    let front: Vec<(f64, f64)> = pareto_front(results)
        .iter()
        .map(|&i| point(&results[i]))
        .collect();
    chart
        .draw_series(LineSeries::new(front, RED.stroke_width(2)))
        .map_err(e)?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    chart
        .draw_series(
            results
                .iter()
                .map(|r| Circle::new(point(r), 5, BLUE.filled())),
        )
        .map_err(e)?;
    // Labels alternate above and below their points (a constant factor on the log axis)
    // so that neighbours do not overprint.
    chart
        .draw_series(results.iter().enumerate().map(|(i, r)| {
            let (x, y) = point(r);
            let lift = if i % 2 == 0 {
                LABEL_LIFT
            } else {
                1.0 / LABEL_LIFT
            };
            Text::new(format!("  {}", r.method), (x, y * lift), (FAMILY, 14))
        }))
        .map_err(e)?;
    chart
        .configure_series_labels()
        .label_font((FAMILY, 14))
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::accuracy::ErrorStats;

    fn result(ns: f64, err: f64) -> MethodResult {
        MethodResult {
            method: format!("{ns}/{err}"),
            hit_error: ErrorStats {
                mean: err,
                ..ErrorStats::default()
            },
            hit_error_relative: ErrorStats::default(),
            normal_error: ErrorStats::default(),
            holes: 0,
            false_hits: 0,
            rays: 1,
            nanoseconds_per_ray: ns,
            memory_bytes: 0,
        }
    }

    #[test]
    fn the_front_keeps_exactly_the_undominated_points() {
        // (time, error): b is dominated by a (slower and less accurate); d by c.
        let r = vec![
            result(10.0, 1e-3),
            result(20.0, 2e-3),
            result(100.0, 1e-6),
            result(200.0, 1e-6),
            result(5.0, 1e-1),
        ];
        assert_eq!(pareto_front(&r), vec![4, 0, 2]);
    }

    #[test]
    fn the_svg_names_every_method() {
        let r = vec![result(10.0, 1e-3), result(100.0, 0.0)];
        let svg = svg(&r, "test").unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("10/0.001") && svg.contains("100/0") && svg.contains("Pareto front"));
    }

    #[test]
    fn the_png_decodes_and_has_text_pixels() {
        let r = vec![result(10.0, 1e-3), result(100.0, 1e-6)];
        let png = png(&r, "test").unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // The caption sits in the top margin, where nothing else is drawn: dark pixels
        // there are glyphs of the embedded font.
        let dark = (0..img.width())
            .flat_map(|x| (0..40).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 128))
            .count();
        assert!(dark > 20, "no caption text drawn ({dark} dark pixels)");
    }
}
