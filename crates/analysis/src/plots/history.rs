//! The history curve: test error of a load model against the length of input history it is
//! given, one panel per dataset, one line per output and the held-out training error.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::Result;

/// One history length and its errors (σ units).
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryPoint {
    /// History given (stroke cycles).
    pub history_cycles: f64,
    /// Test RMSE per output.
    pub test_rmse: Vec<f64>,
    /// Pooled RMSE on the held-out training trajectories.
    pub validation_rmse: f64,
}

/// One panel: a dataset's curve (points sorted by history).
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryPanel<'a> {
    /// Panel title.
    pub title: &'a str,
    /// Output names, one per entry of [`HistoryPoint::test_rmse`].
    pub outputs: &'a [&'a str],
    /// The points.
    pub points: &'a [HistoryPoint],
}

/// Draws one panel per entry of `panels` (560 × 440 px each) into `path` (`.png`/`.svg`).
///
/// # Errors
/// Plot and I/O errors naming the file.
pub fn history_curve(path: &Path, panels: &[HistoryPanel<'_>]) -> Result<()> {
    let n = panels.len().max(1);
    render!(path, (560 * n as u32, 440), |root| {
        let areas = root.split_evenly((1, n));
        for (area, panel) in areas.iter().zip(panels) {
            let pts = panel.points;
            let xs: Vec<f64> = pts.iter().map(|p| p.history_cycles).collect();
            let ys: Vec<f64> = pts
                .iter()
                .flat_map(|p| p.test_rmse.iter().copied().chain([p.validation_rmse]))
                .collect();
            let (x0, x1) = padded_range(xs.iter(), 0.05);
            let (_, y1) = padded_range(ys.iter(), 0.1);
            let mut ch = ChartBuilder::on(area)
                .caption(panel.title, bold(18.0))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, 0.0..y1)?;
            ch.configure_mesh()
                .x_desc("history given (stroke cycles)")
                .y_desc("RMSE (σ units)")
                .label_style(font(14.0))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()?;
            for (j, name) in panel.outputs.iter().enumerate() {
                let col = PALETTE[j % PALETTE.len()];
                let line: Vec<(f64, f64)> = pts
                    .iter()
                    .filter_map(|p| p.test_rmse.get(j).map(|v| (p.history_cycles, *v)))
                    .collect();
                ch.draw_series(LineSeries::new(line.clone(), col.stroke_width(2)))?
                    .label(format!("{name} (test)"))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 22, y)], col.stroke_width(3))
                    });
                ch.draw_series(line.iter().map(|&p| Circle::new(p, 3, col.filled())))?;
            }
            let val: Vec<(f64, f64)> = pts
                .iter()
                .map(|p| (p.history_cycles, p.validation_rmse))
                .collect();
            ch.draw_series(DashedLineSeries::new(val, 6, 4, BLACK.stroke_width(2)))?
                .label("all outputs (held-out training)")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], BLACK.stroke_width(2))
                });
            draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 13.0)?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
