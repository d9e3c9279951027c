//! The published hovering case's figure: C_L and C_D against t/T of several sources.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, padded_range, render};
use crate::error::{AnalysisError, Result};

/// One source's histories.
#[derive(Debug, Clone, Copy)]
pub struct HoverSeries<'a> {
    /// Legend label.
    pub label: &'a str,
    /// t/T of each sample.
    pub t: &'a [f64],
    /// C_L.
    pub lift: &'a [f64],
    /// C_D.
    pub drag: &'a [f64],
    /// A published source: drawn in black or grey, thin; otherwise in the palette, thick.
    pub published: bool,
}

/// Draws C_L (top) and C_D (bottom) of every series over t/T ∈ `[from, to]` into `path`
/// (`.png`/`.svg`, 1200 × 800 px).
///
/// # Errors
/// [`AnalysisError::Empty`] / [`AnalysisError::Shape`] naming the series, plot/IO errors.
pub fn lift_drag<'a>(
    path: &Path,
    title: &str,
    series: &[HoverSeries<'a>],
    from: f64,
    to: f64,
) -> Result<()> {
    if series.is_empty() {
        return Err(AnalysisError::Empty {
            what: "hovering series".into(),
        });
    }
    for s in series {
        if s.t.len() < 2 || s.lift.len() != s.t.len() || s.drag.len() != s.t.len() {
            return Err(AnalysisError::Shape {
                what: format!("series `{}`", s.label),
                expected: "t, C_L and C_D of one length ≥ 2".into(),
                found: format!("{}, {}, {}", s.t.len(), s.lift.len(), s.drag.len()),
            });
        }
    }
    let pick =
        |s: &HoverSeries<'a>, r: usize| -> &'a [f64] { if r == 0 { s.lift } else { s.drag } };
    let greys = [BLACK, RGBColor(110, 110, 110), RGBColor(170, 170, 170)];
    render!(path, (1200, 800), |root| {
        let area = root.titled(title, bold(18.0))?;
        let rows = area.split_evenly((2, 1));
        for (r, (row, name)) in rows.iter().zip(["C_L", "C_D"]).enumerate() {
            let inside = |s: &HoverSeries<'a>| {
                s.t.iter()
                    .zip(pick(s, r))
                    .filter(|(t, _)| (from..=to).contains(*t))
                    .map(|(_, y)| *y)
                    .collect::<Vec<f64>>()
            };
            let all: Vec<f64> = series.iter().flat_map(inside).collect();
            let (y0, y1) = padded_range(all.iter(), 0.05);
            let mut ch = ChartBuilder::on(row)
                .margin(10)
                .x_label_area_size(34)
                .y_label_area_size(50)
                .build_cartesian_2d(from..to, y0..y1)?;
            ch.configure_mesh()
                .max_light_lines(1)
                .x_desc("t/T")
                .y_desc(name)
                .label_style(font(13.0))
                .draw()?;
            let (mut grey, mut colour) = (0, 0);
            for s in series {
                let style = if s.published {
                    grey += 1;
                    greys[(grey - 1) % greys.len()].stroke_width(1)
                } else {
                    colour += 1;
                    PALETTE[(colour - 1) % PALETTE.len()].stroke_width(2)
                };
                let points =
                    s.t.iter()
                        .zip(pick(s, r))
                        .filter(|(t, _)| (from..=to).contains(*t))
                        .map(|(t, y)| (*t, *y));
                ch.draw_series(LineSeries::new(points, style))?
                    .label(s.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            }
            if r == 0 {
                draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 12.0)?;
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_and_refuses_mismatched_series() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..100).map(|i| i as f64 / 25.0).collect();
        let y: Vec<f64> = t.iter().map(|x| x.sin()).collect();
        let s = HoverSeries {
            label: "a",
            t: &t,
            lift: &y,
            drag: &y,
            published: true,
        };
        let path = dir.path().join("h.svg");
        lift_drag(
            &path,
            "t",
            &[
                s,
                HoverSeries {
                    published: false,
                    ..s
                },
            ],
            0.0,
            4.0,
        )
        .unwrap();
        assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
        let bad = HoverSeries {
            lift: &y[..10],
            ..s
        };
        assert!(lift_drag(&path, "t", &[bad], 0.0, 4.0).is_err());
    }
}
