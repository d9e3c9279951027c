//! Fig. 5: control-authority figures from an [`AuthoritySummary`] and a [`PeakTable`].

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{PALETTE, bold, font, render};
use crate::authority::{AuthoritySummary, PeakTable};
use crate::error::{AnalysisError, Result};
use crate::kde::DensityGrid;

/// Horizontal runs `(x_lo, x_hi, y_lo, y_hi)` of grid cells with density ≥ `level` (a filled
/// region as few rectangles).
fn region_runs(g: &DensityGrid, level: f64) -> Vec<(f64, f64, f64, f64)> {
    let half = |axis: &[f64], i: usize| -> (f64, f64) {
        let lo = if i > 0 {
            0.5 * (axis[i - 1] + axis[i])
        } else {
            axis[i]
        };
        let hi = if i + 1 < axis.len() {
            0.5 * (axis[i] + axis[i + 1])
        } else {
            axis[i]
        };
        (lo, hi)
    };
    let mut runs = Vec::new();
    for b in 0..g.ys.len() {
        let (y0, y1) = half(&g.ys, b);
        let mut a = 0;
        while a < g.xs.len() {
            if g.at(a, b) >= level {
                let start = a;
                while a < g.xs.len() && g.at(a, b) >= level {
                    a += 1;
                }
                runs.push((half(&g.xs, start).0, half(&g.xs, a - 1).1, y0, y1));
            } else {
                a += 1;
            }
        }
    }
    runs
}

/// Fig. 5Ai: one panel per latent state (4 per row); for each input its highest-density region
/// (light fill and outline) and its mode (+), on (lag in cycles, max |r|).
///
/// # Errors
/// [`AnalysisError::Empty`] if the summary has no densities (e.g. deserialized), plot/IO errors.
pub fn hdr_contours(path: &Path, s: &AuthoritySummary) -> Result<()> {
    let (ns, ni) = (s.state_names.len(), s.input_names.len());
    if s.densities.len() != ns * ni || ns == 0 {
        return Err(AnalysisError::Empty {
            what: "density grids of the authority summary".into(),
        });
    }
    let ncol = ns.min(4);
    let nrow = ns.div_ceil(ncol);
    let xmax = s.config.max_lag_cycles;
    render!(
        path,
        (300 * ncol as u32 + 150, 290 * nrow as u32 + 40),
        |root| {
            let root = root.titled(
                &format!(
                    "{:.0} % highest-density regions (+ = mode) of max |r| vs lag",
                    100.0 * s.config.hdr_mass
                ),
                bold(20.0),
            )?;
            let (plots, legend) = root.split_horizontally(300 * ncol as u32);
            let areas = plots.split_evenly((nrow, ncol));
            for (j, area) in areas.iter().enumerate().take(ns) {
                let mut ch = ChartBuilder::on(area)
                    .caption(&s.state_names[j], bold(16.0))
                    .margin(6)
                    .x_label_area_size(32)
                    .y_label_area_size(40)
                    .build_cartesian_2d(0.0..xmax, 0.0..1.0)?;
                ch.configure_mesh()
                    .disable_x_mesh()
                    .disable_y_mesh()
                    .x_labels(5)
                    .y_labels(5)
                    .x_desc("lag (cycles)")
                    .y_desc("max |r|")
                    .label_style(font(11.0))
                    .draw()?;
                for k in 0..ni {
                    let col = PALETTE[k % PALETTE.len()];
                    let g = &s.densities[j * ni + k];
                    let p = s.pair(j, k);
                    ch.draw_series(region_runs(g, p.hdr_threshold).into_iter().map(
                        |(x0, x1, y0, y1)| {
                            Rectangle::new([(x0, y0), (x1, y1)], col.mix(0.16).filled())
                        },
                    ))?;
                    for seg in g.contour_segments(p.hdr_threshold) {
                        ch.draw_series(LineSeries::new(
                            [(seg[0][0], seg[0][1]), (seg[1][0], seg[1][1])],
                            col.stroke_width(2),
                        ))?;
                    }
                }
                for k in 0..ni {
                    let col = PALETTE[k % PALETTE.len()];
                    let p = s.pair(j, k);
                    ch.draw_series(std::iter::once(Cross::new(
                        (p.mode_lag_cycles, p.mode_abs_r),
                        6,
                        col.stroke_width(3),
                    )))?;
                }
            }
            // Legend column.
            for (k, name) in s.input_names.iter().enumerate() {
                let col = PALETTE[k % PALETTE.len()];
                let y = 60 + 28 * k as i32;
                legend.draw(&Rectangle::new(
                    [(14, y - 8), (34, y + 8)],
                    col.mix(0.4).filled(),
                ))?;
                legend.draw(&Rectangle::new(
                    [(14, y - 8), (34, y + 8)],
                    col.stroke_width(2),
                ))?;
                legend.draw(&Text::new(
                    name.clone(),
                    (42, y),
                    font(15.0).pos(Pos::new(HPos::Left, VPos::Center)),
                ))?;
            }
            Ok::<(), Box<dyn std::error::Error>>(())
        }
    )
}

/// Fig. 5Aii/iii: for one latent state, one panel per input with every trajectory's
/// (lag, max |r|), shaded by the KDE density at the point (darker = denser), plus the mode.
///
/// # Errors
/// [`AnalysisError::Parameter`]-like shape errors for a bad state index, plot/IO errors.
pub fn pair_scatter(
    path: &Path,
    table: &PeakTable,
    s: &AuthoritySummary,
    state: usize,
) -> Result<()> {
    let ni = s.input_names.len();
    if state >= s.state_names.len() || table.n_state != s.state_names.len() || table.n_input != ni {
        return Err(AnalysisError::Shape {
            what: "pair scatter state / table".into(),
            expected: format!("state < {} and a matching table", s.state_names.len()),
            found: format!("state {state}, table {} × {}", table.n_state, table.n_input),
        });
    }
    let xmax = s.config.max_lag_cycles;
    render!(path, (250 * ni as u32, 300), |root| {
        let root = root.titled(
            &format!("{}: max |r| vs lag per trajectory", s.state_names[state]),
            bold(18.0),
        )?;
        let areas = root.split_evenly((1, ni));
        for (k, area) in areas.iter().enumerate() {
            let col = PALETTE[k % PALETTE.len()];
            let pts = table.points(state, k);
            let g = s.densities.get(state * ni + k);
            let dens = |p: &[f64; 2]| -> f64 {
                g.map(|g| {
                    let a = ((p[0] / xmax) * (g.xs.len() - 1) as f64).round() as usize;
                    let b = (p[1] * (g.ys.len() - 1) as f64).round() as usize;
                    g.at(a.min(g.xs.len() - 1), b.min(g.ys.len() - 1))
                })
                .unwrap_or(1.0)
            };
            let dmax = pts.iter().map(dens).fold(1e-12, f64::max);
            let mut ch = ChartBuilder::on(area)
                .caption(&s.input_names[k], bold(15.0))
                .margin(6)
                .x_label_area_size(30)
                .y_label_area_size(if k == 0 { 40 } else { 28 })
                .build_cartesian_2d(0.0..xmax, 0.0..1.0)?;
            ch.configure_mesh()
                .disable_x_mesh()
                .disable_y_mesh()
                .x_labels(3)
                .y_labels(5)
                .x_desc("lag (cycles)")
                .y_desc(if k == 0 { "max |r|" } else { "" })
                .label_style(font(11.0))
                .draw()?;
            ch.draw_series(pts.iter().map(|p| {
                let w = 0.15 + 0.85 * dens(p) / dmax;
                Circle::new((p[0], p[1]), 3, col.mix(w).filled())
            }))?;
            let p = s.pair(state, k);
            ch.draw_series(std::iter::once(Cross::new(
                (p.mode_lag_cycles, p.mode_abs_r),
                6,
                BLACK.stroke_width(2),
            )))?;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

/// Fig. 5B: the summary as a circle grid — columns = states, rows = inputs; circle radius ∝
/// median max |r|; fill lightness ∝ lag IQR (dark = clustered, light = IQR ≥ 0.3 cycles);
/// the median lag (cycles) is printed where median |r| > `strong_median_r`.
///
/// # Errors
/// Plot/IO errors.
pub fn summary_grid(path: &Path, s: &AuthoritySummary) -> Result<()> {
    let (ns, ni) = (s.state_names.len(), s.input_names.len());
    let (cell, left, top) = (70i32, 120i32, 80i32);
    let w = (left + cell * ns as i32 + 30) as u32;
    let h = (top + cell * ni as i32 + 70) as u32;
    let dark = PALETTE[4];
    let shade = |iqr: f64| -> RGBColor {
        let t = (iqr / 0.3).clamp(0.0, 1.0) * 0.85;
        let m = |c: u8| (c as f64 + (255.0 - c as f64) * t).round() as u8;
        RGBColor(m(dark.0), m(dark.1), m(dark.2))
    };
    render!(path, (w, h), |root| {
        root.draw(&Text::new(
            "median max |r| (radius), lag IQR (lightness), median lag in cycles where median |r| > 0.5",
            (left, 24),
            bold(16.0),
        ))?;
        for (j, name) in s.state_names.iter().enumerate() {
            let x = left + cell * j as i32 + cell / 2;
            root.draw(&Text::new(
                name.clone(),
                (x, top - 18),
                bold(15.0).pos(Pos::new(HPos::Center, VPos::Center)),
            ))?;
        }
        for (k, name) in s.input_names.iter().enumerate() {
            let y = top + cell * k as i32 + cell / 2;
            root.draw(&Text::new(
                name.clone(),
                (left - 12, y),
                bold(15.0).pos(Pos::new(HPos::Right, VPos::Center)),
            ))?;
            for j in 0..ns {
                let x = left + cell * j as i32 + cell / 2;
                let p = s.pair(j, k);
                root.draw(&Rectangle::new(
                    [(x - cell / 2, y - cell / 2), (x + cell / 2, y + cell / 2)],
                    RGBColor(235, 235, 235).stroke_width(1),
                ))?;
                let r = (p.median_abs_r.clamp(0.0, 1.0) * (cell as f64 * 0.46)).round() as i32;
                root.draw(&Circle::new(
                    (x, y),
                    r.max(1),
                    shade(p.lag_iqr_cycles).filled(),
                ))?;
                root.draw(&Circle::new((x, y), r.max(1), dark.stroke_width(1)))?;
                if p.strong {
                    let light = p.lag_iqr_cycles > 0.15;
                    let tc = if light { BLACK } else { WHITE };
                    root.draw(&Text::new(
                        format!("{:.2}", p.median_lag_cycles),
                        (x, y),
                        bold(13.0)
                            .color(&tc)
                            .pos(Pos::new(HPos::Center, VPos::Center)),
                    ))?;
                }
            }
        }
        // Legend: radius and lightness.
        let ly = top + cell * ni as i32 + 36;
        let mut x = left;
        for r in [0.25, 0.5, 0.8] {
            let rad = (r * cell as f64 * 0.46).round() as i32;
            root.draw(&Circle::new((x + rad, ly), rad, shade(0.15).filled()))?;
            root.draw(&Text::new(
                format!("|r| {r}"),
                (x + 2 * rad + 6, ly),
                font(13.0).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
            x += 2 * rad + 70;
        }
        for iqr in [0.0, 0.15, 0.3] {
            root.draw(&Circle::new((x + 14, ly), 14, shade(iqr).filled()))?;
            root.draw(&Circle::new((x + 14, ly), 14, dark.stroke_width(1)))?;
            root.draw(&Text::new(
                format!("IQR {iqr}"),
                (x + 34, ly),
                font(13.0).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
            x += 100;
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
