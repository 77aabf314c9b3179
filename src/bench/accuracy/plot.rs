//! The accuracy–time plot: mean hit error against time per ray, both axes logarithmic,
//! with the Pareto front (the methods no other method beats in both) drawn as a line.

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

/// SVG text of the plot. Errors of exactly 0 cannot sit on a log axis; they are drawn at
/// the bottom edge (a tenth of the smallest positive error), which the caption states.
pub fn svg(results: &[MethodResult], title: &str) -> Result<String, String> {
    let mut out = String::new();
    {
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
        let point =
            |r: &MethodResult| (r.nanoseconds_per_ray.max(1e-3), r.hit_error.mean.max(floor));
        let xs: Vec<f64> = results.iter().map(|r| point(r).0).collect();
        let ys: Vec<f64> = results.iter().map(|r| point(r).1).collect();
        let span = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(0.0, f64::max);
            (lo / 2.0, hi * 2.0)
        };
        let (x0, x1) = span(&xs);
        let (y0, y1) = span(&ys);
        let root = SVGBackend::with_string(&mut out, (900, 600)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(20)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("time per ray (ns)")
            .y_desc("mean hit-point error (L1, scene units)")
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
        // Labels alternate above and below their points (a constant factor on the log
        // axis) so that neighbours do not overprint.
        chart
            .draw_series(results.iter().enumerate().map(|(i, r)| {
                let (x, y) = point(r);
                let lift = if i % 2 == 0 {
                    LABEL_LIFT
                } else {
                    1.0 / LABEL_LIFT
                };
                Text::new(format!("  {}", r.method), (x, y * lift), ("sans-serif", 14))
            }))
            .map_err(e)?;
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE)
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(out)
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
}
