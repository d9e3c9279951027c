//! Fig. 3: per selected trajectory, a chord sketch in the (stroke, deviation) plane, the Euler
//! angles, and measured vs predicted C_Fx and C_Fy (two or more models, ±2σ bands).
//!
//! Chord sketch: the pitch-axis point is drawn at (φ, ψ) in degrees; with the frame convention
//! `R_0w = R_y(φ) R_x(−ψ) R_z(α)` the chord direction towards the leading edge, `y_w`, has
//! components `(−sin α, cos α)` along the directions of increasing φ and ψ, so the chord runs
//! from `TE = p − (1 − x̂₀) ĉ d` to `LE = p + x̂₀ ĉ d` (`ĉ` = chord/radius in degrees, `x̂₀` the
//! pitch-axis chord fraction); the LE end is marked with a dot.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, draw_legend, font, model_colour, padded_range, render};
use crate::error::{AnalysisError, Result};

/// Coefficient curves of one source (measurement or model).
#[derive(Debug, Clone, Copy)]
pub struct CoefficientCurves<'a> {
    /// Legend label.
    pub label: &'a str,
    /// C_Fx per sample.
    pub cfx: &'a [f64],
    /// C_Fy per sample.
    pub cfy: &'a [f64],
    /// Predictive standard deviation of C_Fx (draws a ±2σ band), if any.
    pub cfx_std: Option<&'a [f64]>,
    /// Predictive standard deviation of C_Fy, if any.
    pub cfy_std: Option<&'a [f64]>,
}

/// One column of the figure.
#[derive(Debug, Clone, Copy)]
pub struct TrajectoryPanel<'a> {
    /// Column title (e.g. "test #26 — RMSE C_Fx 0.11/0.33").
    pub title: &'a str,
    /// Time axis per sample (e.g. t̂ in cycles).
    pub t: &'a [f64],
    /// Euler angles [φ, ψ, α] (rad) per sample.
    pub euler_rad: &'a [[f64; 3]],
    /// Measured coefficients.
    pub measured: CoefficientCurves<'a>,
    /// Model predictions (drawn in palette order).
    pub models: &'a [CoefficientCurves<'a>],
}

/// Chord-sketch geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChordSketch {
    /// Drawn chord length in degrees of arc (chord / radius, published 0.06/0.235 rad ≈ 14.6°).
    pub chord_deg: f64,
    /// Pitch axis behind the LE as a fraction of the chord (published 0.15).
    pub pitch_axis_frac: f64,
    /// Draw a chord every this many samples.
    pub every: usize,
}

impl Default for ChordSketch {
    fn default() -> Self {
        Self {
            chord_deg: (0.06f64 / 0.235).to_degrees(),
            pitch_axis_frac: 0.15,
            every: 3,
        }
    }
}

/// (values, std) of C_Fx (`comp` 0) or C_Fy (1).
fn component<'b>(cc: &CoefficientCurves<'b>, comp: usize) -> (&'b [f64], Option<&'b [f64]>) {
    if comp == 0 {
        (cc.cfx, cc.cfx_std)
    } else {
        (cc.cfy, cc.cfy_std)
    }
}

fn check(p: &TrajectoryPanel<'_>) -> Result<()> {
    let n = p.t.len();
    if n < 2 {
        return Err(AnalysisError::Empty {
            what: format!("time axis of `{}`", p.title),
        });
    }
    let curves = std::iter::once(&p.measured).chain(p.models.iter());
    for c in curves {
        let lens = [
            Some(c.cfx.len()),
            Some(c.cfy.len()),
            c.cfx_std.map(<[f64]>::len),
            c.cfy_std.map(<[f64]>::len),
        ];
        if p.euler_rad.len() != n || lens.iter().flatten().any(|&l| l != n) {
            return Err(AnalysisError::Shape {
                what: format!("series of `{}` / `{}`", p.title, c.label),
                expected: format!("{n} samples each (as t)"),
                found: format!("euler {}, curves {:?}", p.euler_rad.len(), lens),
            });
        }
    }
    Ok(())
}

/// Draws Fig. 3 into `path` (`.png`/`.svg`): one column per panel, rows = chord sketch,
/// Euler angles (deg), C_Fx, C_Fy. 380 px per column, 1000 px high.
///
/// # Errors
/// Shape/empty errors, plot/IO errors.
pub fn time_histories<'a>(
    path: &Path,
    t_label: &str,
    panels: &[TrajectoryPanel<'a>],
    sketch: &ChordSketch,
) -> Result<()> {
    if panels.is_empty() {
        return Err(AnalysisError::Empty {
            what: "trajectory panels".into(),
        });
    }
    panels.iter().try_for_each(check)?;
    let n = panels.len();
    let (col_w, height) = (380u32, 1000u32);
    render!(path, (col_w * n as u32, height), |root| {
        let cols = root.split_evenly((1, n));
        for (c, (area, p)) in cols.iter().zip(panels).enumerate() {
            let area = area.titled(p.title, bold(16.0))?;
            let rows = area.split_by_breakpoints::<i32, i32, _, _>([], [220, 430, 630]);
            let (t0, t1) = padded_range(p.t.iter(), 0.0);
            let ylab = |s: &'static str| if c == 0 { s } else { "" };
            // Row 0: chord sketch, equal aspect in degrees.
            {
                let phi: Vec<f64> = p.euler_rad.iter().map(|e| e[0].to_degrees()).collect();
                let psi: Vec<f64> = p.euler_rad.iter().map(|e| e[1].to_degrees()).collect();
                let (mut x0, mut x1) = padded_range(phi.iter(), 0.0);
                let (mut y0, mut y1) = padded_range(psi.iter(), 0.0);
                let pad = sketch.chord_deg * 1.1;
                (x0, x1, y0, y1) = (x0 - pad, x1 + pad, y0 - pad, y1 + pad);
                // Plot area ≈ (col_w − 70) × (220 − 40) px: widen the short side to equal aspect.
                let (pw, ph) = (col_w as f64 - 70.0, 180.0);
                let scale = ((x1 - x0) / pw).max((y1 - y0) / ph);
                let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
                let (hx, hy) = (0.5 * scale * pw, 0.5 * scale * ph);
                let mut ch = ChartBuilder::on(&rows[0])
                    .margin(6)
                    .x_label_area_size(30)
                    .y_label_area_size(40)
                    .build_cartesian_2d(cx - hx..cx + hx, cy - hy..cy + hy)?;
                ch.configure_mesh()
                    .disable_x_mesh()
                    .disable_y_mesh()
                    .x_desc("stroke φ (deg)")
                    .y_desc("ψ (deg)")
                    .x_labels(5)
                    .y_labels(4)
                    .label_style(font(12.0))
                    .draw()?;
                ch.draw_series(LineSeries::new(
                    phi.iter().copied().zip(psi.iter().copied()),
                    RGBColor(170, 170, 170).stroke_width(1),
                ))?;
                let x0f = sketch.pitch_axis_frac;
                for k in (0..phi.len()).step_by(sketch.every.max(1)) {
                    let a = p.euler_rad[k][2];
                    let (dx, dy) = (-a.sin() * sketch.chord_deg, a.cos() * sketch.chord_deg);
                    let le = (phi[k] + x0f * dx, psi[k] + x0f * dy);
                    let te = (phi[k] - (1.0 - x0f) * dx, psi[k] - (1.0 - x0f) * dy);
                    ch.draw_series(LineSeries::new([te, le], BLACK.stroke_width(1)))?;
                    ch.draw_series(std::iter::once(Circle::new(le, 2, BLACK.filled())))?;
                }
            }
            // Row 1: Euler angles; at least the published ±110° range.
            {
                let (lo, hi) = padded_range(p.euler_rad.iter().flatten(), 0.0);
                let (a0, a1) = (
                    (lo.to_degrees() - 5.0).min(-110.0),
                    (hi.to_degrees() + 5.0).max(110.0),
                );
                let mut ch = ChartBuilder::on(&rows[1])
                    .margin(6)
                    .x_label_area_size(30)
                    .y_label_area_size(40)
                    .build_cartesian_2d(t0..t1, a0..a1)?;
                ch.configure_mesh()
                    .light_line_style(RGBColor(238, 238, 238))
                    .y_desc(ylab("angle (deg)"))
                    .x_labels(5)
                    .y_labels(5)
                    .label_style(font(12.0))
                    .draw()?;
                for (i, name) in ["φ", "ψ", "α"].iter().enumerate() {
                    let col = PALETTE[i + 2];
                    ch.draw_series(LineSeries::new(
                        p.t.iter()
                            .zip(p.euler_rad)
                            .map(|(&t, e)| (t, e[i].to_degrees())),
                        col.stroke_width(2),
                    ))?
                    .label(*name)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(3))
                    });
                }
                draw_legend(&mut ch, SeriesLabelPosition::UpperRight, 12.0)?;
            }
            // Rows 2, 3: C_Fx, C_Fy.
            for (row, comp) in [(2usize, 0usize), (3, 1)] {
                let pick = |cc: &CoefficientCurves<'a>| component(cc, comp);
                let mut vals: Vec<f64> = pick(&p.measured).0.to_vec();
                for m in p.models {
                    let (mu, sd) = pick(m);
                    vals.extend(
                        mu.iter()
                            .zip(sd.unwrap_or(mu))
                            .map(|(a, s)| if sd.is_some() { a + 2.0 * s } else { *a }),
                    );
                    vals.extend(
                        mu.iter()
                            .zip(sd.unwrap_or(mu))
                            .map(|(a, s)| if sd.is_some() { a - 2.0 * s } else { *a }),
                    );
                }
                let (y0, y1) = padded_range(vals.iter(), 0.06);
                let mut ch = ChartBuilder::on(&rows[row])
                    .margin(6)
                    .x_label_area_size(34)
                    .y_label_area_size(40)
                    .build_cartesian_2d(t0..t1, y0..y1)?;
                ch.configure_mesh()
                    .light_line_style(RGBColor(238, 238, 238))
                    .x_desc(if row == 3 { t_label } else { "" })
                    .y_desc(if comp == 0 {
                        ylab("C_Fx")
                    } else {
                        ylab("C_Fy")
                    })
                    .x_labels(5)
                    .y_labels(5)
                    .label_style(font(12.0))
                    .draw()?;
                for (mi, m) in p.models.iter().enumerate() {
                    let col = model_colour(mi);
                    let (mu, sd) = pick(m);
                    if let Some(sd) = sd {
                        let upper =
                            p.t.iter()
                                .zip(mu.iter().zip(sd))
                                .map(|(&t, (a, s))| (t, a + 2.0 * s));
                        let lower: Vec<(f64, f64)> =
                            p.t.iter()
                                .zip(mu.iter().zip(sd))
                                .map(|(&t, (a, s))| (t, a - 2.0 * s))
                                .collect();
                        let poly: Vec<(f64, f64)> = upper.chain(lower.into_iter().rev()).collect();
                        ch.draw_series(std::iter::once(Polygon::new(
                            poly,
                            col.mix(0.18).filled(),
                        )))?;
                    }
                    ch.draw_series(LineSeries::new(
                        p.t.iter().copied().zip(mu.iter().copied()),
                        col.stroke_width(2),
                    ))?
                    .label(m.label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(3))
                    });
                }
                let (mu, _) = pick(&p.measured);
                ch.draw_series(LineSeries::new(
                    p.t.iter().copied().zip(mu.iter().copied()),
                    BLACK.stroke_width(2),
                ))?
                .label(p.measured.label)
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(3))
                });
                if c == 0 && row == 2 {
                    draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 12.0)?;
                }
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
