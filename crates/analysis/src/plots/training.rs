//! Training curves: one line per run (e.g. the negative ELBO per epoch).

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};

/// One training curve.
#[derive(Debug, Clone, Copy)]
pub struct TrainingCurve<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Epoch (or iteration) numbers, increasing.
    pub epochs: &'a [f64],
    /// Objective value per epoch (same length).
    pub values: &'a [f64],
}

/// Draws training curves into `path` (`.png`/`.svg`), 900 × 500 px. With `log_y` the values
/// must be positive and are plotted on a logarithmic axis.
///
/// # Errors
/// [`AnalysisError::Shape`] for mismatched lengths, [`AnalysisError::Empty`], plot/IO errors.
pub fn training_curves(
    path: &Path,
    title: &str,
    y_label: &str,
    curves: &[TrainingCurve<'_>],
    log_y: bool,
) -> Result<()> {
    if curves.is_empty() || curves.iter().any(|c| c.epochs.is_empty()) {
        return Err(AnalysisError::Empty {
            what: "training curves".into(),
        });
    }
    if let Some(c) = curves.iter().find(|c| c.epochs.len() != c.values.len()) {
        return Err(AnalysisError::Shape {
            what: format!("training curve `{}` values", c.label),
            expected: format!("{} (as epochs)", c.epochs.len()),
            found: c.values.len().to_string(),
        });
    }
    let (x0, x1) = padded_range(curves.iter().flat_map(|c| c.epochs.iter()), 0.0);
    let (y0, y1) = padded_range(curves.iter().flat_map(|c| c.values.iter()), 0.05);
    render!(path, (900, 500), |root| {
        let mut b = ChartBuilder::on(&root);
        b.caption(title, bold(22.0))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(80);
        if log_y {
            let lo = curves
                .iter()
                .flat_map(|c| c.values.iter())
                .copied()
                .filter(|v| *v > 0.0)
                .fold(f64::INFINITY, f64::min);
            let hi = y1.max(lo * 10.0);
            let mut ch = b.build_cartesian_2d(x0..x1, (lo * 0.8..hi * 1.2).log_scale())?;
            draw_curves(&mut ch, y_label, curves)?;
        } else {
            let mut ch = b.build_cartesian_2d(x0..x1, y0..y1)?;
            draw_curves(&mut ch, y_label, curves)?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

/// Mesh, one line per curve and the legend, on a linear or logarithmic y axis.
fn draw_curves<'a, DB, Y>(
    ch: &mut ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, Y>>,
    y_label: &str,
    curves: &[TrainingCurve<'_>],
) -> std::result::Result<(), Box<dyn std::error::Error>>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    Y: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    ch.configure_mesh()
        .x_desc("epoch")
        .y_desc(y_label)
        .label_style(font(15.0))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for (i, c) in curves.iter().enumerate() {
        let col = PALETTE[i % PALETTE.len()];
        let line = LineSeries::new(
            c.epochs.iter().copied().zip(c.values.iter().copied()),
            col.stroke_width(2),
        );
        ch.draw_series(line)?
            .label(c.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], col.stroke_width(3)));
    }
    draw_legend(ch, SeriesLabelPosition::MiddleRight, 15.0)?;
    Ok(())
}
