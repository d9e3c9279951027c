//! The design figures: panels of curves (kinematics, loads with a predicted band, convergence,
//! a closed loop's cycles), each curve with an optional shaded band.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};

/// One curve.
#[derive(Debug, Clone, Copy)]
pub struct Curve<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// A band `(lower, upper)` shaded in the curve's colour.
    pub band: Option<(&'a [f64], &'a [f64])>,
    /// Colour index in the palette; `None`: black (a target or a reference).
    pub colour: Option<usize>,
    /// Draw markers at the points.
    pub markers: bool,
}

/// One panel.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    /// Label of the x axis.
    pub x_label: &'a str,
    /// Label of the y axis.
    pub y_label: &'a str,
    /// Its curves.
    pub curves: Vec<Curve<'a>>,
}

/// Draws `panels` in a grid of `columns` into `path` (`.png`/`.svg`, 560 × 380 px a panel).
///
/// # Errors
/// [`AnalysisError::Empty`] without panels or for a panel without curves;
/// [`AnalysisError::Shape`] naming a curve whose arrays differ in length; plot/IO errors.
pub fn panels(path: &Path, title: &str, panels: &[Panel<'_>], columns: usize) -> Result<()> {
    let columns = columns.max(1);
    if panels.is_empty() || panels.iter().any(|p| p.curves.is_empty()) {
        return Err(AnalysisError::Empty {
            what: "design figure panels".into(),
        });
    }
    for c in panels.iter().flat_map(|p| &p.curves) {
        let band_ok = c
            .band
            .is_none_or(|(lo, hi)| lo.len() == c.x.len() && hi.len() == c.x.len());
        if c.x.len() != c.y.len() || c.x.is_empty() || !band_ok {
            return Err(AnalysisError::Shape {
                what: format!("curve `{}`", c.label),
                expected: "x, y (and the band) of one length ≥ 1".into(),
                found: format!("{} x, {} y", c.x.len(), c.y.len()),
            });
        }
    }
    let rows = panels.len().div_ceil(columns);
    let size = (560 * columns as u32, 380 * rows as u32 + 40);
    render!(path, size, |root| {
        let area = root.titled(title, bold(18.0))?;
        let cells = area.split_evenly((rows, columns));
        for (cell, p) in cells.iter().zip(panels) {
            let xs = p.curves.iter().flat_map(|c| c.x.iter());
            let (x0, x1) = padded_range(xs, 0.0);
            let ys = p.curves.iter().flat_map(|c| {
                let band = c
                    .band
                    .map(|(lo, hi)| lo.iter().chain(hi))
                    .into_iter()
                    .flatten();
                c.y.iter().chain(band)
            });
            let (y0, y1) = padded_range(ys, 0.06);
            let mut ch = ChartBuilder::on(cell)
                .margin(12)
                .x_label_area_size(36)
                .y_label_area_size(62)
                .build_cartesian_2d(x0..x1, y0..y1)?;
            ch.configure_mesh()
                .max_light_lines(1)
                .x_desc(p.x_label)
                .y_desc(p.y_label)
                .label_style(font(13.0))
                .draw()?;
            for c in &p.curves {
                let colour = c.colour.map_or(BLACK, |i| PALETTE[i % PALETTE.len()]);
                if let Some((lo, hi)) = c.band {
                    let poly: Vec<(f64, f64)> =
                        c.x.iter()
                            .zip(lo)
                            .map(|(x, y)| (*x, *y))
                            .chain(c.x.iter().zip(hi).rev().map(|(x, y)| (*x, *y)))
                            .collect();
                    ch.draw_series(std::iter::once(Polygon::new(poly, colour.mix(0.18))))?;
                }
                let style = colour.stroke_width(if c.colour.is_some() { 2 } else { 1 });
                let pts: Vec<(f64, f64)> = c.x.iter().zip(c.y).map(|(x, y)| (*x, *y)).collect();
                ch.draw_series(LineSeries::new(pts.clone(), style))?
                    .label(c.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
                if c.markers {
                    ch.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
                }
            }
            draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 11.0)?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_bands_and_refuses_mismatched_curves() {
        let dir = tempfile::tempdir().unwrap();
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|v| v.sin()).collect();
        let lo: Vec<f64> = y.iter().map(|v| v - 0.2).collect();
        let hi: Vec<f64> = y.iter().map(|v| v + 0.2).collect();
        let c = Curve {
            label: "a",
            x: &x,
            y: &y,
            band: Some((&lo, &hi)),
            colour: Some(0),
            markers: true,
        };
        let p = Panel {
            x_label: "t",
            y_label: "y",
            curves: vec![
                c,
                Curve {
                    band: None,
                    colour: None,
                    ..c
                },
            ],
        };
        let path = dir.path().join("d.svg");
        panels(&path, "design", &[p.clone(), p.clone(), p], 2).unwrap();
        assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
        let bad = Panel {
            x_label: "t",
            y_label: "y",
            curves: vec![Curve { y: &y[..3], ..c }],
        };
        assert!(panels(&path, "design", &[bad], 1).is_err());
        assert!(panels(&path, "design", &[], 1).is_err());
    }
}
