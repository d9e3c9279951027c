//! Sweep figures: accuracy against a swept setting (latent dimension, training-set size), one
//! panel per setting, the mean over seeds as a line and each run as a dot.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::Result;

/// One run of a sweep: the swept value and its overall RMSEs (σ units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    /// The swept value (e.g. D_x or the number of training trajectories).
    pub value: usize,
    /// Overall RMSE on the trajectories trained on.
    pub train: f64,
    /// Overall RMSE on the test set, if there is one.
    pub test: Option<f64>,
}

/// One panel: a swept setting and its runs (sorted by value).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPanel<'a> {
    /// Panel title.
    pub title: &'a str,
    /// X-axis label.
    pub x_label: &'a str,
    /// The runs, sorted by `value`.
    pub points: &'a [SweepPoint],
}

/// Draws one panel per entry of `panels` (560 px wide each, 440 px high) into `path`
/// (`.png`/`.svg`): training and test RMSE against the swept value, the mean over runs of
/// equal value as a line, every run as a dot.
///
/// # Errors
/// Plot and I/O errors naming the file.
pub fn accuracy_vs_setting(path: &Path, panels: &[SweepPanel<'_>]) -> Result<()> {
    let n = panels.len().max(1);
    render!(path, (560 * n as u32, 440), |root| {
        let areas = root.split_evenly((1, n));
        for (area, panel) in areas.iter().zip(panels) {
            let rows = panel.points;
            let xs = rows.iter().map(|r| r.value as f64).collect::<Vec<_>>();
            let ys = rows
                .iter()
                .flat_map(|r| std::iter::once(r.train).chain(r.test))
                .collect::<Vec<_>>();
            let (x0, x1) = padded_range(xs.iter(), 0.08);
            let (_, y1) = padded_range(ys.iter(), 0.1);
            let mut ch = ChartBuilder::on(area)
                .caption(panel.title, bold(18.0))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, 0.0..y1)?;
            ch.configure_mesh()
                .x_desc(panel.x_label)
                .y_desc("overall RMSE (σ units)")
                .label_style(font(14.0))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()?;
            let mut values: Vec<usize> = rows.iter().map(|r| r.value).collect();
            values.dedup();
            for (c, (label, get)) in [
                (
                    "training",
                    (|r: &SweepPoint| Some(r.train)) as fn(&SweepPoint) -> Option<f64>,
                ),
                ("test", |r: &SweepPoint| r.test),
            ]
            .into_iter()
            .enumerate()
            {
                let col = PALETTE[c];
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter_map(|r| get(r).map(|v| (r.value as f64, v)))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let means: Vec<(f64, f64)> = values
                    .iter()
                    .filter_map(|&v| {
                        let s: Vec<f64> = rows
                            .iter()
                            .filter(|r| r.value == v)
                            .filter_map(get)
                            .collect();
                        (!s.is_empty()).then(|| (v as f64, s.iter().sum::<f64>() / s.len() as f64))
                    })
                    .collect();
                ch.draw_series(LineSeries::new(means, col.stroke_width(2)))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 22, y)], col.stroke_width(3))
                    });
                ch.draw_series(
                    pts.iter()
                        .map(|&(x, y)| Circle::new((x, y), 4, col.filled())),
                )?;
            }
            draw_legend(&mut ch, SeriesLabelPosition::MiddleRight, 14.0)?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
