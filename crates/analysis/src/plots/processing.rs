//! The check of a rig recording's processing: per load channel (a row), the loads after the
//! tare, the rigid-body loads subtracted and the processed (aerodynamic) loads against time,
//! with the end of the tare's rest marked — at rest the processed loads must be flat at zero.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};

/// A recording's signals at the raw rate, one row `[F_x, F_y, M_x, M_y, M_z]` per sample.
#[derive(Debug, Clone, Copy)]
pub struct ProcessingPanel<'a> {
    /// Figure title (the recording).
    pub title: &'a str,
    /// Time of each sample (s).
    pub t_s: &'a [f64],
    /// After the tare, wing axes about the root.
    pub tared: &'a [[f64; 5]],
    /// The rigid-body loads subtracted.
    pub subtracted: &'a [[f64; 5]],
    /// The processed loads.
    pub processed: &'a [[f64; 5]],
    /// End of the tare's rest (s), if any.
    pub rest_end_s: Option<f64>,
    /// Channel labels with units.
    pub channels: [&'a str; 5],
}

/// Draws the panel into `path` (`.png`/`.svg`, 900 × 1000 px).
///
/// # Errors
/// [`AnalysisError::Shape`] for series of unequal lengths or fewer than two samples, plot/IO
/// errors.
pub fn processing_steps(path: &Path, p: &ProcessingPanel<'_>) -> Result<()> {
    let n = p.t_s.len();
    let lens = [p.tared.len(), p.subtracted.len(), p.processed.len()];
    if n < 2 || lens.iter().any(|&l| l != n) {
        return Err(AnalysisError::Shape {
            what: format!("processing steps of `{}`", p.title),
            expected: format!("{n} samples in each series (n ≥ 2)"),
            found: format!("{lens:?}"),
        });
    }
    let series: [(&str, &[[f64; 5]], RGBColor); 3] = [
        ("after the tare", p.tared, PALETTE[0]),
        ("rigid-body loads subtracted", p.subtracted, PALETTE[1]),
        ("processed (aerodynamic)", p.processed, RGBColor(0, 0, 0)),
    ];
    render!(path, (900, 1000), |root| {
        let area = root.titled(p.title, bold(16.0))?;
        let rows = area.split_evenly((5, 1));
        let (t0, t1) = padded_range(p.t_s.iter(), 0.0);
        for (k, row) in rows.iter().enumerate() {
            let values = series
                .iter()
                .flat_map(|(_, s, _)| s.iter().map(move |r| r[k]));
            let (y0, y1) = padded_range(values.collect::<Vec<_>>().iter(), 0.05);
            let mut ch = ChartBuilder::on(row)
                .margin(6)
                .x_label_area_size(if k == 4 { 30 } else { 14 })
                .y_label_area_size(56)
                .build_cartesian_2d(t0..t1, y0..y1)?;
            ch.configure_mesh()
                .max_light_lines(1)
                .x_desc(if k == 4 { "t (s)" } else { "" })
                .y_desc(p.channels[k])
                .label_style(font(11.0))
                .draw()?;
            for (label, s, colour) in series {
                ch.draw_series(LineSeries::new(
                    p.t_s.iter().zip(s).map(|(&t, r)| (t, r[k])),
                    colour.stroke_width(1),
                ))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            }
            if let Some(t) = p.rest_end_s {
                ch.draw_series(std::iter::once(PathElement::new(
                    vec![(t, y0), (t, y1)],
                    PALETTE[4].stroke_width(1),
                )))?;
            }
            if k == 0 {
                draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 11.0)?;
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_and_refuses_unequal_series() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        let y: Vec<[f64; 5]> = t.iter().map(|t| [t.sin(); 5]).collect();
        let panel = ProcessingPanel {
            title: "rec.csv",
            t_s: &t,
            tared: &y,
            subtracted: &y,
            processed: &y,
            rest_end_s: Some(0.3),
            channels: [
                "F_x (N)",
                "F_y (N)",
                "M_x (N·mm)",
                "M_y (N·mm)",
                "M_z (N·mm)",
            ],
        };
        let svg = dir.path().join("p.svg");
        processing_steps(&svg, &panel).unwrap();
        assert!(
            std::fs::read_to_string(&svg)
                .unwrap()
                .contains("after the tare")
        );
        let short = ProcessingPanel {
            processed: &y[..50],
            ..panel
        };
        assert!(matches!(
            processing_steps(&dir.path().join("q.svg"), &short),
            Err(AnalysisError::Shape { .. })
        ));
    }
}
