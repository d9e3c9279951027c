//! System-identification figure: measured test outputs and the open-loop prediction (mean and
//! ±2σ band, `σ² = v` the predictive variance incl. `σ_y²`), one row per output channel,
//! against the test-sample index.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};

/// Draws the test-part prediction into `path` (`.png`/`.svg`, 1000 × 320 px per output).
/// `measured`, `mean`, `var` are row-major `T × D_y` with `D_y = names.len()`, raw units.
///
/// # Errors
/// [`AnalysisError::Empty`]/[`AnalysisError::Shape`] for empty or mismatched series,
/// plot/IO errors.
pub fn plot_test_prediction(
    path: &Path,
    title: &str,
    names: &[String],
    measured: &[f64],
    mean: &[f64],
    var: &[f64],
) -> Result<()> {
    let dy = names.len();
    if dy == 0 || measured.is_empty() {
        return Err(AnalysisError::Empty {
            what: "test outputs".into(),
        });
    }
    if measured.len() % dy != 0 || mean.len() != measured.len() || var.len() != measured.len() {
        return Err(AnalysisError::Shape {
            what: "measured / mean / variance".into(),
            expected: format!("equal lengths, a multiple of {dy} outputs"),
            found: format!("{} / {} / {}", measured.len(), mean.len(), var.len()),
        });
    }
    let n = measured.len() / dy;
    let height = 60 + 320 * dy as u32;
    render!(path, (1000, height), |root| {
        let area = root.titled(title, bold(18.0))?;
        let rows = area.split_evenly((dy, 1));
        for (j, (row, name)) in rows.iter().zip(names).enumerate() {
            let col = |s: &[f64]| -> Vec<f64> { s.iter().skip(j).step_by(dy).copied().collect() };
            let (y, m, v) = (col(measured), col(mean), col(var));
            let sd: Vec<f64> = v.iter().map(|v| v.max(0.0).sqrt()).collect();
            let lo: Vec<f64> = m.iter().zip(&sd).map(|(m, s)| m - 2.0 * s).collect();
            let hi: Vec<f64> = m.iter().zip(&sd).map(|(m, s)| m + 2.0 * s).collect();
            let (y0, y1) = padded_range(y.iter().chain(&lo).chain(&hi), 0.05);
            let mut ch = ChartBuilder::on(row)
                .margin(8)
                .x_label_area_size(34)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..(n - 1).max(1) as f64, y0..y1)?;
            ch.configure_mesh()
                .light_line_style(RGBColor(238, 238, 238))
                .x_desc("test sample")
                .y_desc(name.as_str())
                .label_style(font(13.0))
                .draw()?;
            let c = PALETTE[0];
            let band: Vec<(f64, f64)> = hi
                .iter()
                .enumerate()
                .map(|(t, &v)| (t as f64, v))
                .chain(lo.iter().enumerate().rev().map(|(t, &v)| (t as f64, v)))
                .collect();
            ch.draw_series(std::iter::once(Polygon::new(band, c.mix(0.2).filled())))?
                .label("±2σ")
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 18, y + 5)], c.mix(0.3).filled())
                });
            ch.draw_series(LineSeries::new(
                m.iter().enumerate().map(|(t, &v)| (t as f64, v)),
                c.stroke_width(2),
            ))?
            .label("PR-SSM mean (open loop)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(3)));
            ch.draw_series(LineSeries::new(
                y.iter().enumerate().map(|(t, &v)| (t as f64, v)),
                BLACK.stroke_width(1),
            ))?
            .label("measured")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(3)));
            draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 13.0)?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_png_and_rejects_mismatched_series() {
        let dir = tempfile::tempdir().unwrap();
        let names = vec!["p".to_string(), "q".to_string()];
        let y: Vec<f64> = (0..40).map(|i| (i as f64 * 0.3).sin()).collect();
        let var = vec![0.04; 40];
        let path = dir.path().join("fig.png");
        plot_test_prediction(&path, "t", &names, &y, &y, &var).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let e = plot_test_prediction(&path, "t", &names, &y, &y[..38], &var[..38]).unwrap_err();
        assert!(matches!(e, AnalysisError::Shape { .. }), "{e}");
        let e = plot_test_prediction(&path, "t", &names, &y[..39], &y[..39], &var[..39]);
        assert!(e.is_err());
    }
}
