//! Fig. 2C: 3-D sketches of wing motions — the chord at one span station drawn at intervals
//! along the path, the leading edge marked with a dot.
//!
//! Frames: global `0` with `y₀` up; wing frame `w` with span `z_w`, chord towards the leading
//! edge `y_w`, normal `x_w`; `R_0w = R_y(φ) R_x(−ψ) R_z(α)` for Euler angles [φ, ψ, α] (rad).
//! A chord point `y_w` (m, from the pitch axis, positive towards the LE) at span station `r`
//! (m from the stroke axis) is at `p₀ = R_0w (0, y_w, r)ᵀ`.

use std::path::Path;

use plotters::prelude::*;

use super::{PALETTE, bold, font, render};
use crate::error::{AnalysisError, Result};

/// Rotation about x, y or z by `a` (rad), row-major.
fn rot(axis: usize, a: f64) -> [[f64; 3]; 3] {
    let (s, c) = a.sin_cos();
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// `R_0w = R_y(φ) R_x(−ψ) R_z(α)` (wing → global) for `euler_rad = [φ, ψ, α]`.
pub fn rotation_global_from_wing(euler_rad: [f64; 3]) -> [[f64; 3]; 3] {
    let [phi, psi, alpha] = euler_rad;
    mul(&mul(&rot(1, phi), &rot(0, -psi)), &rot(2, alpha))
}

/// Global positions (m) of the leading and trailing edges `(LE, TE)` of the chord at span
/// station `r_m`, for chord `chord_m` with the pitch axis `pitch_axis_frac` chords behind the LE.
pub fn chord_endpoints(
    euler_rad: [f64; 3],
    r_m: f64,
    chord_m: f64,
    pitch_axis_frac: f64,
) -> ([f64; 3], [f64; 3]) {
    let r = rotation_global_from_wing(euler_rad);
    let at = |y: f64| -> [f64; 3] { [0, 1, 2].map(|i| r[i][1] * y + r[i][2] * r_m) };
    (
        at(pitch_axis_frac * chord_m),
        at(-(1.0 - pitch_axis_frac) * chord_m),
    )
}

/// One trajectory to sketch.
#[derive(Debug, Clone, Copy)]
pub struct WingPath<'a> {
    /// Panel title.
    pub label: &'a str,
    /// Euler angles [φ, ψ, α] (rad) per sample.
    pub euler_rad: &'a [[f64; 3]],
}

/// Geometry of the drawn chord.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WingSketchGeometry {
    /// Span station of the drawn chord from the stroke axis (m; published U_ref radius 0.235).
    pub r_m: f64,
    /// Chord length (m; published 0.06).
    pub chord_m: f64,
    /// Pitch axis behind the LE, fraction of the chord (published 0.15).
    pub pitch_axis_frac: f64,
    /// Draw a chord every this many samples.
    pub every: usize,
}

impl Default for WingSketchGeometry {
    fn default() -> Self {
        Self {
            r_m: 0.235,
            chord_m: 0.06,
            pitch_axis_frac: 0.15,
            every: 2,
        }
    }
}

/// Draws one 3-D panel per path (3 per row, 420 × 400 px each) into `path`.
///
/// # Errors
/// [`AnalysisError::Empty`] for no paths or an empty path; plot/IO errors.
pub fn wing_motion_3d(
    path: &Path,
    paths: &[WingPath<'_>],
    geom: &WingSketchGeometry,
) -> Result<()> {
    if paths.is_empty() || paths.iter().any(|p| p.euler_rad.is_empty()) {
        return Err(AnalysisError::Empty {
            what: "wing paths".into(),
        });
    }
    let n = paths.len();
    let ncol = n.min(3);
    let nrow = n.div_ceil(ncol);
    let lim = geom.r_m + geom.chord_m;
    render!(path, (420 * ncol as u32, 400 * nrow as u32), |root| {
        let areas = root.split_evenly((nrow, ncol));
        for (i, (area, wp)) in areas.iter().zip(paths).enumerate() {
            let col = PALETTE[i % PALETTE.len()];
            let mut ch = ChartBuilder::on(area)
                .caption(wp.label, bold(16.0))
                .margin(6)
                .build_cartesian_3d(-lim..lim, -lim..lim, -lim..lim)?;
            ch.with_projection(|mut pb| {
                pb.yaw = 0.55;
                pb.pitch = 0.35;
                pb.scale = 0.95;
                pb.into_matrix()
            });
            ch.configure_axes()
                .light_grid_style(RGBColor(240, 240, 240))
                .max_light_lines(2)
                .label_style(font(11.0))
                .x_labels(3)
                .y_labels(3)
                .z_labels(3)
                .draw()?;
            // Pitch-axis path.
            let axis_pt = |e: &[f64; 3]| {
                let (le, te) = chord_endpoints(*e, geom.r_m, geom.chord_m, geom.pitch_axis_frac);
                let f = geom.pitch_axis_frac;
                [0, 1, 2].map(|k| le[k] * (1.0 - f) + te[k] * f)
            };
            ch.draw_series(LineSeries::new(
                wp.euler_rad.iter().map(|e| {
                    let p = axis_pt(e);
                    (p[0], p[1], p[2])
                }),
                RGBColor(160, 160, 160).stroke_width(1),
            ))?;
            for e in wp.euler_rad.iter().step_by(geom.every.max(1)) {
                let (le, te) = chord_endpoints(*e, geom.r_m, geom.chord_m, geom.pitch_axis_frac);
                ch.draw_series(LineSeries::new(
                    [(te[0], te[1], te[2]), (le[0], le[1], le[2])],
                    col.stroke_width(2),
                ))?;
                ch.draw_series(std::iter::once(Circle::new(
                    (le[0], le[1], le[2]),
                    2,
                    BLACK.filled(),
                )))?;
            }
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn chord_endpoints_follow_the_frame_convention() {
        let (r, c, f) = (0.2, 0.1, 0.25);
        // Zero angles: span along z₀, LE straight up (+y₀).
        let (le, te) = chord_endpoints([0.0; 3], r, c, f);
        assert!(close(le, [0.0, 0.025, 0.2]) && close(te, [0.0, -0.075, 0.2]));
        // φ = 90°: R_y turns the span from z₀ to x₀.
        let (le, _) = chord_endpoints([FRAC_PI_2, 0.0, 0.0], r, c, f);
        assert!(close(le, [0.2, 0.025, 0.0]));
        // α = −90° (the home pitch): the chord lies along +x₀ (LE towards +x₀).
        let (le, te) = chord_endpoints([0.0, 0.0, -FRAC_PI_2], r, c, f);
        assert!(close(le, [0.025, 0.0, 0.2]) && close(te, [-0.075, 0.0, 0.2]));
        // ψ = 90°: R_x(−90°) lifts the span to +y₀ (deviation up).
        let (le, _) = chord_endpoints([0.0, FRAC_PI_2, 0.0], r, c, f);
        assert!(close(le, [0.0, 0.2, -0.025]));
    }
}
