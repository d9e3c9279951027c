//! Fig. 4: standardized-error histograms with central intervals (A) and half-stroke cycle
//! averages, error vs observation, with intervals (B).

use std::path::Path;

use plotters::prelude::*;

use super::{bold, draw_legend, font, model_colour, padded_range, render};
use crate::error::{AnalysisError, Result};
use crate::metrics::Histogram;
use crate::stats::central_interval;

/// One model's errors, one vector per output (e.g. [`crate::metrics::PooledErrors::errors`]).
#[derive(Debug, Clone, Copy)]
pub struct ModelErrors<'a> {
    /// Legend label, e.g. "PR-SSM test".
    pub label: &'a str,
    /// `errors[j]`: errors of output `j`.
    pub errors: &'a [Vec<f64>],
}

fn check_outputs(names: &[&str], models: &[ModelErrors<'_>]) -> Result<()> {
    if names.is_empty() || models.is_empty() {
        return Err(AnalysisError::Empty {
            what: "outputs or models to plot".into(),
        });
    }
    for m in models {
        if m.errors.len() != names.len() {
            return Err(AnalysisError::Shape {
                what: format!("errors of `{}`", m.label),
                expected: format!("{} outputs", names.len()),
                found: m.errors.len().to_string(),
            });
        }
    }
    Ok(())
}

/// Fig. 4A: per output, the `'probability'` histograms of every model's errors over `edges`
/// (published `-1.1:0.01:1.1`) and each model's central `level`-% interval as vertical lines
/// labelled with their values. One panel per output, side by side, 360 × 340 px each.
///
/// # Errors
/// Shape/empty errors, interval errors, plot/IO errors.
pub fn error_histograms(
    path: &Path,
    output_names: &[&str],
    models: &[ModelErrors<'_>],
    edges: &[f64],
    level: f64,
) -> Result<()> {
    check_outputs(output_names, models)?;
    let mut hists = Vec::new();
    let mut cis = Vec::new();
    for m in models {
        let mut hm = Vec::new();
        let mut cm = Vec::new();
        for e in m.errors {
            hm.push(Histogram::new(e, edges.to_vec())?);
            cm.push(central_interval(e, level)?);
        }
        hists.push(hm);
        cis.push(cm);
    }
    let n = output_names.len();
    let (x0, x1) = (edges[0], edges[edges.len() - 1]);
    render!(path, (360 * n as u32, 360), |root| {
        let panels = root.split_evenly((1, n));
        for (j, area) in panels.iter().enumerate() {
            let ymax = hists
                .iter()
                .flat_map(|h| h[j].probability.iter())
                .fold(0.0f64, |a, &b| a.max(b))
                * 1.35;
            let mut ch = ChartBuilder::on(area)
                .caption(format!("e / σ  ({})", output_names[j]), bold(18.0))
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(if j == 0 { 62 } else { 40 })
                .build_cartesian_2d(x0..x1, 0.0..ymax.max(1e-6))?;
            ch.configure_mesh()
                .disable_x_mesh()
                .disable_y_mesh()
                .x_labels(5)
                .y_labels(5)
                .y_desc(if j == 0 { "probability" } else { "" })
                .x_desc("standardized error")
                .label_style(font(13.0))
                .draw()?;
            for (m, model) in models.iter().enumerate() {
                let col = model_colour(m);
                let h = &hists[m][j];
                ch.draw_series(h.probability.iter().enumerate().map(|(k, &p)| {
                    Rectangle::new(
                        [(h.edges[k], 0.0), (h.edges[k + 1], p)],
                        col.mix(0.45).filled(),
                    )
                }))?
                .label(model.label)
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 16, y + 5)], col.mix(0.6).filled())
                });
                let ci = cis[m][j];
                for (v, row) in [(ci.lo, 0), (ci.hi, 0)] {
                    let y_top = ymax * (0.97 - 0.09 * m as f64) - row as f64;
                    ch.draw_series(DashedLineSeries::new(
                        [(v, 0.0), (v, y_top)],
                        5,
                        4,
                        col.stroke_width(2),
                    ))?;
                    ch.draw_series(std::iter::once(Text::new(
                        format!("{v:.2}"),
                        (v, y_top),
                        font(13.0)
                            .color(&col)
                            .pos(plotters::style::text_anchor::Pos::new(
                                plotters::style::text_anchor::HPos::Center,
                                plotters::style::text_anchor::VPos::Bottom,
                            )),
                    )))?;
                }
            }
            if j == 0 {
                draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 12.0)?;
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

/// One model's half-stroke averages (e.g. [`crate::cycles_avg::CycleAverageErrors`]).
#[derive(Debug, Clone, Copy)]
pub struct ModelCycleAverages<'a> {
    /// Legend label.
    pub label: &'a str,
    /// `observed[j]`: measured half-stroke means of output `j`.
    pub observed: &'a [Vec<f64>],
    /// `error[j]`: measured − predicted, aligned with `observed`.
    pub error: &'a [Vec<f64>],
}

/// Fig. 4B: per output, error vs observed half-stroke mean coefficient for every model, a zero
/// line, and each model's central `level`-% error interval as labelled horizontal dashed lines.
/// `error_limits[j]` fixes the error axis (published ±0.75 for forces, ±2 for moments);
/// `None` fits the data.
///
/// # Errors
/// Shape/empty errors, interval errors, plot/IO errors.
pub fn cycle_average_scatter(
    path: &Path,
    output_names: &[&str],
    models: &[ModelCycleAverages<'_>],
    error_limits: Option<&[f64]>,
    level: f64,
) -> Result<()> {
    let as_err: Vec<ModelErrors<'_>> = models
        .iter()
        .map(|m| ModelErrors {
            label: m.label,
            errors: m.error,
        })
        .collect();
    check_outputs(output_names, &as_err)?;
    for m in models {
        if m.observed.len() != output_names.len()
            || m.observed
                .iter()
                .zip(m.error)
                .any(|(o, e)| o.len() != e.len())
        {
            return Err(AnalysisError::Shape {
                what: format!("cycle averages of `{}`", m.label),
                expected: "observed and error of equal lengths per output".into(),
                found: "mismatch".into(),
            });
        }
    }
    let mut cis = Vec::new();
    for m in models {
        cis.push(
            m.error
                .iter()
                .map(|e| central_interval(e, level))
                .collect::<Result<Vec<_>>>()?,
        );
    }
    let n = output_names.len();
    render!(path, (340 * n as u32, 360), |root| {
        let panels = root.split_evenly((1, n));
        for (j, area) in panels.iter().enumerate() {
            let (ox0, ox1) = padded_range(models.iter().flat_map(|m| m.observed[j].iter()), 0.08);
            let lim = match error_limits.and_then(|l| l.get(j)) {
                Some(&l) => l,
                None => {
                    let (a, b) = padded_range(models.iter().flat_map(|m| m.error[j].iter()), 0.1);
                    a.abs().max(b.abs())
                }
            };
            let mut ch = ChartBuilder::on(area)
                .caption(format!("half-stroke mean {}", output_names[j]), bold(17.0))
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(if j == 0 { 60 } else { 44 })
                .build_cartesian_2d(ox0..ox1, -lim..lim)?;
            ch.configure_mesh()
                .disable_x_mesh()
                .disable_y_mesh()
                .x_labels(5)
                .y_labels(5)
                .x_desc("observation")
                .y_desc(if j == 0 {
                    "error (measured − predicted)"
                } else {
                    ""
                })
                .label_style(font(13.0))
                .draw()?;
            ch.draw_series(LineSeries::new(
                [(ox0, 0.0), (ox1, 0.0)],
                BLACK.stroke_width(1),
            ))?;
            for (m, model) in models.iter().enumerate() {
                let col = model_colour(m);
                ch.draw_series(
                    model.observed[j]
                        .iter()
                        .zip(&model.error[j])
                        .map(|(&o, &e)| {
                            Circle::new((o, e.clamp(-lim, lim)), 3, col.mix(0.55).filled())
                        }),
                )?
                .label(model.label)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, col.filled()));
                let ci = cis[m][j];
                for v in [ci.lo, ci.hi] {
                    ch.draw_series(DashedLineSeries::new(
                        [(ox0, v), (ox1, v)],
                        5,
                        4,
                        col.stroke_width(2),
                    ))?;
                    ch.draw_series(std::iter::once(Text::new(
                        format!("{v:.2}"),
                        // Model 0 labelled at the right edge, model 1 at the left, …
                        if m % 2 == 0 {
                            (ox1 - (ox1 - ox0) * 0.02, v)
                        } else {
                            (ox0 + (ox1 - ox0) * 0.02, v)
                        },
                        font(13.0)
                            .color(&col)
                            .pos(plotters::style::text_anchor::Pos::new(
                                if m % 2 == 0 {
                                    plotters::style::text_anchor::HPos::Right
                                } else {
                                    plotters::style::text_anchor::HPos::Left
                                },
                                plotters::style::text_anchor::VPos::Bottom,
                            )),
                    )))?;
                }
            }
            if j == 0 {
                draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 12.0)?;
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
