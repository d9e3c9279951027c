//! The rig check's figure: for each of a few trajectories (a column), the five standardized
//! loads (rows) of a dataset over the reference's mean and its 95 % band.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};
use crate::rig::CHANNELS;

/// One column: a trajectory's standardized loads and the reference's, `n × 5` row-major.
#[derive(Debug, Clone, Copy)]
pub struct RigPanel<'a> {
    /// Column title (e.g. "test #26").
    pub title: &'a str,
    /// Time of each sample (s).
    pub t_s: &'a [f64],
    /// The dataset's loads, standardized.
    pub loads_z: &'a [f64],
    /// The reference's mean, standardized.
    pub reference_mean_z: &'a [f64],
    /// The reference's variance, standardized.
    pub reference_var_z: &'a [f64],
}

/// Draws the panels into `path` (`.png`/`.svg`; 320 × 1000 px per column): the reference's
/// mean (orange) with its 95 % band, the dataset's loads (black), labelled `dataset_label`.
///
/// # Errors
/// [`AnalysisError::Empty`] / [`AnalysisError::Shape`] naming the panel, plot/IO errors.
pub fn rig_overlay(
    path: &Path,
    title: &str,
    dataset_label: &str,
    panels: &[RigPanel<'_>],
) -> Result<()> {
    if panels.is_empty() {
        return Err(AnalysisError::Empty {
            what: "trajectories of the rig figure".into(),
        });
    }
    for p in panels {
        let n = p.t_s.len();
        let lens = [
            p.loads_z.len(),
            p.reference_mean_z.len(),
            p.reference_var_z.len(),
        ];
        if n < 2 || lens.iter().any(|&l| l != 5 * n) {
            return Err(AnalysisError::Shape {
                what: format!("series of `{}`", p.title),
                expected: format!("5 × {n} values each (5 channels at each time, n ≥ 2)"),
                found: format!("{lens:?}"),
            });
        }
    }
    let cols = panels.len();
    render!(path, (320 * cols as u32, 1000), |root| {
        let area = root.titled(title, bold(18.0))?;
        let columns = area.split_evenly((1, cols));
        let reference = PALETTE[1];
        for (c, (column, p)) in columns.iter().zip(panels).enumerate() {
            let column = column.titled(p.title, bold(14.0))?;
            let rows = column.split_evenly((5, 1));
            let (t0, t1) = padded_range(p.t_s.iter(), 0.0);
            for (k, row) in rows.iter().enumerate() {
                let pick =
                    |v: &[f64]| -> Vec<f64> { v.iter().skip(k).step_by(5).copied().collect() };
                let (y, m, var) = (
                    pick(p.loads_z),
                    pick(p.reference_mean_z),
                    pick(p.reference_var_z),
                );
                let half: Vec<f64> = var.iter().map(|v| 1.96 * v.max(0.0).sqrt()).collect();
                let lo: Vec<f64> = m.iter().zip(&half).map(|(m, h)| m - h).collect();
                let hi: Vec<f64> = m.iter().zip(&half).map(|(m, h)| m + h).collect();
                let (y0, y1) = padded_range(y.iter().chain(&lo).chain(&hi), 0.05);
                let mut ch = ChartBuilder::on(row)
                    .margin(6)
                    .x_label_area_size(if k == 4 { 30 } else { 14 })
                    .y_label_area_size(46)
                    .build_cartesian_2d(t0..t1, y0..y1)?;
                let y_desc = if c == 0 {
                    format!("{} (σ)", CHANNELS[k])
                } else {
                    String::new()
                };
                ch.configure_mesh()
                    .max_light_lines(1)
                    .x_desc(if k == 4 { "t (s)" } else { "" })
                    .y_desc(y_desc)
                    .label_style(font(11.0))
                    .draw()?;
                let band: Vec<(f64, f64)> = p
                    .t_s
                    .iter()
                    .zip(&hi)
                    .map(|(&t, &v)| (t, v))
                    .chain(p.t_s.iter().zip(&lo).rev().map(|(&t, &v)| (t, v)))
                    .collect();
                ch.draw_series(std::iter::once(Polygon::new(
                    band,
                    reference.mix(0.2).filled(),
                )))?;
                ch.draw_series(LineSeries::new(
                    p.t_s.iter().zip(&m).map(|(&t, &v)| (t, v)),
                    reference.stroke_width(2),
                ))?
                .label("rig stand-in (published model, 95 % band)")
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], reference.stroke_width(3))
                });
                ch.draw_series(LineSeries::new(
                    p.t_s.iter().zip(&y).map(|(&t, &v)| (t, v)),
                    BLACK.stroke_width(1),
                ))?
                .label(dataset_label)
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(3))
                });
                if c == 0 && k == 0 {
                    draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 11.0)?;
                }
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_and_refuses_misshaped_panels() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.04).collect();
        let y: Vec<f64> = (0..250).map(|i| (i as f64 * 0.05).sin()).collect();
        let v = vec![0.01; 250];
        let panel = RigPanel {
            title: "test #26",
            t_s: &t,
            loads_z: &y,
            reference_mean_z: &y,
            reference_var_z: &v,
        };
        let path = dir.path().join("rig.png");
        rig_overlay(&path, "rig", "L0", &[panel, panel]).unwrap();
        assert_eq!(&std::fs::read(&path).unwrap()[..4], b"\x89PNG");
        let short = RigPanel {
            loads_z: &y[..245],
            ..panel
        };
        let e = rig_overlay(&path, "rig", "L0", &[short]).unwrap_err();
        assert!(e.to_string().contains("test #26"), "{e}");
    }
}
