//! The fitted curves and the data as an SVG plot.

use super::{Fit, Point};
use std::path::Path;

/// Draws the data and every fitted curve (strain against force) as SVG.
pub fn plot(path: &Path, data: &[Point], fits: &[Fit], title: &str) -> Result<(), String> {
    use plotters::prelude::*;
    let f_max = data.iter().map(|p| p.1).fold(0.0, f64::max) * 1.05;
    let e_max = data.iter().map(|p| p.0).fold(0.0, f64::max) * 1.15;
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..f_max, 0.0..e_max)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("force (N)")
        .y_desc("strain (displacement variation ratio)")
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(
            data.iter()
                .map(|&(e, f)| Circle::new((f, e), 3, BLACK.filled())),
        )
        .map_err(|e| e.to_string())?
        .label("data")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
    let colours = [RED, BLUE, GREEN];
    for (fit, colour) in fits.iter().zip(colours) {
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|i| f_max * i as f64 / 200.0)
            .map(|f| (f, fit.model.strain_at(f)))
            .filter(|(_, e)| e.is_finite())
            .collect();
        let m = fit.metrics;
        chart
            .draw_series(LineSeries::new(curve, colour.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(format!(
                "{} (mean {:.4}, max {:.4})",
                fit.model.kind().name().to_uppercase(),
                m.mean_abs,
                m.max_abs
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
