//! The induced inflow of the whole wing (momentum theory of an actuator surface): the fluid the
//! hovering wing pushes down, which carries the prescribed wake.
//!
//! The wing sweeps, per half-stroke, the annular sector A = ½Φ(R² − r0²) (Φ the stroke angle
//! swept in the last half-stroke, rad; R the tip and r0 the root radius). Pushing the fluid
//! through it down at w takes the momentum flux 2ρAw² (ideal actuator, far wake at 2w), which
//! balances the recent mean vertical force L̄:
//!
//! w = √(max(L̄, 0) / (2ρA))   (m/s),
//!
//! L̄ = Σ e^{−s/(s_U c)} L Δs / (s_U c), the vertical force averaged over the last s_U chords of
//! travel of the reference point (a full window from the start, so w builds up from rest). As
//! for the strips (`vortex::inflow`), w ∝ U under time scaling and w = 0 at rest.
//!
//! The slipstream below the wing speeds up from w at the stroke plane to 2w far below (the
//! momentum balance): on the axis of the vortex-cylinder model of an actuator disk of radius R,
//! the fluid at depth d below the disk moves down at
//!
//! v(d) = w·(1 + d/√(d² + R²))   (→ 0 far above, 2w far below),
//!
//! which [`slipstream_speed`] gives and which carries the prescribed wake: a wake sinking at w
//! everywhere would pile up twice the far wake's vorticity under the wing.

use crate::vortex::Inflow;

/// Downward speed (m/s) of the fluid at depth `depth_m` below the stroke plane (negative above
/// it) in the slipstream of a disk of radius `radius_m` whose induced velocity is `w_m_s`.
pub(crate) fn slipstream_speed(w_m_s: f64, depth_m: f64, radius_m: f64) -> f64 {
    w_m_s * (1.0 + depth_m / depth_m.hypot(radius_m))
}

/// Reversals closer together than this (chords of travel of the reference point) are not
/// half-strokes.
const MIN_HALF_STROKE_CHORDS: f64 = 0.5;

#[derive(Debug, Clone, Copy)]
pub(crate) struct WingInflow {
    model: Inflow,
    /// s_U·c (m).
    window_m: f64,
    /// 2ρ·½(R² − r0²) (kg/m): A·2ρ per radian of stroke.
    two_rho_area_per_rad: f64,
    /// The smallest half-stroke (rad).
    min_half_stroke_rad: f64,
    /// Σ e^{−s/(s_U c)}·L·Δs (N·m).
    recent_lift_n_m: f64,
    /// Σ e^{−s/(s_U c)}·Δs and ·Δt: the recent mean speed of the reference point is their ratio.
    recent_travel_m: f64,
    recent_time_s: f64,
    /// Stroke angle at the last reversal (rad), the last half-stroke's sweep (rad), and the sign
    /// of the stroke rate (0 before any motion).
    reversal_angle_rad: Option<f64>,
    half_stroke_rad: f64,
    direction: f64,
}

impl WingInflow {
    pub fn new(
        model: Inflow,
        window_m: f64,
        density: f64,
        root_m: f64,
        tip_m: f64,
        chord_m: f64,
    ) -> Self {
        Self {
            model,
            window_m,
            two_rho_area_per_rad: density * (tip_m * tip_m - root_m * root_m),
            min_half_stroke_rad: MIN_HALF_STROKE_CHORDS * chord_m / tip_m,
            recent_lift_n_m: 0.0,
            recent_travel_m: 0.0,
            recent_time_s: 0.0,
            reversal_angle_rad: None,
            half_stroke_rad: 0.0,
            direction: 0.0,
        }
    }

    pub fn reset(&mut self) {
        self.recent_lift_n_m = 0.0;
        self.recent_travel_m = 0.0;
        self.recent_time_s = 0.0;
        self.reversal_angle_rad = None;
        self.half_stroke_rad = 0.0;
        self.direction = 0.0;
    }

    /// Records a step of travel `ds_m` over `dt_s` with vertical force `lift_n` (N), at stroke
    /// angle `stroke_rad` moving at `stroke_rate_rad_s`.
    pub fn advance(
        &mut self,
        ds_m: f64,
        dt_s: f64,
        lift_n: f64,
        stroke_rad: f64,
        stroke_rate_rad_s: f64,
    ) {
        let keep = (-ds_m / self.window_m).exp();
        self.recent_lift_n_m = keep * self.recent_lift_n_m + lift_n * ds_m;
        self.recent_travel_m = keep * self.recent_travel_m + ds_m;
        self.recent_time_s = keep * self.recent_time_s + dt_s;
        let start = *self.reversal_angle_rad.get_or_insert(stroke_rad);
        let sign = if stroke_rate_rad_s != 0.0 {
            stroke_rate_rad_s.signum()
        } else {
            self.direction
        };
        let arc = (stroke_rad - start).abs();
        if self.direction == 0.0 {
            self.direction = sign;
        } else if sign != self.direction && arc >= self.min_half_stroke_rad {
            self.half_stroke_rad = arc;
            self.reversal_angle_rad = Some(stroke_rad);
            self.direction = sign;
        }
    }

    /// The downward velocity of the fluid w (m/s) at stroke angle `stroke_rad`.
    pub fn velocity_m_s(&self, stroke_rad: f64) -> f64 {
        match self.model {
            Inflow::Still => 0.0,
            Inflow::Uniform { ratio } => {
                if self.recent_time_s > 0.0 {
                    ratio * self.recent_travel_m / self.recent_time_s
                } else {
                    0.0
                }
            }
            Inflow::Momentum => {
                let current = self
                    .reversal_angle_rad
                    .map_or(0.0, |a| (stroke_rad - a).abs());
                let sweep = self
                    .half_stroke_rad
                    .max(current)
                    .max(self.min_half_stroke_rad);
                let lift = self.recent_lift_n_m / self.window_m;
                (lift.max(0.0) / (self.two_rho_area_per_rad * sweep)).sqrt()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slipstream moves at w in the stroke plane, 2w far below, nothing far above, and
    /// speeds up monotonically on the way down.
    #[test]
    fn slipstream_doubles_below_the_wing() {
        let (w, r) = (0.05, 0.235);
        assert_eq!(slipstream_speed(w, 0.0, r), w);
        assert!((slipstream_speed(w, 1e3, r) - 2.0 * w).abs() < 1e-7);
        assert!(slipstream_speed(w, -1e3, r) < 1e-8);
        let depths = [-0.5, -0.1, 0.0, 0.1, 0.5, 2.0];
        let speeds: Vec<f64> = depths.iter().map(|&d| slipstream_speed(w, d, r)).collect();
        assert!(speeds.windows(2).all(|v| v[1] > v[0]), "{speeds:?}");
    }
}
