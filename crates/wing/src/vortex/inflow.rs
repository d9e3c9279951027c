//! The induced inflow of a strip: the fluid that a hovering wing pushes down, in which the strip
//! works (see [`super::strip`], "Induced inflow").
//!
//! Blade-element momentum theory: the strip at radius r sweeps, per half-stroke, an arc of
//! horizontal length a = Φr (Φ the stroke amplitude, rad). Pushing the fluid through that arc
//! down at w takes the momentum flux 2ρ·a·w² per unit span (ideal actuator, far wake at 2w), which
//! balances the mean vertical force per span L̄′:
//!
//! w = √(max(L̄′, 0) / (2ρ·a))   (m/s).
//!
//! L̄′ is the strip's own vertical force averaged over its recent travel (the weights of the
//! LESP reference speed, e^{−s/(s_U c)}), so w follows the lift with a lag of about s_U chords of
//! travel, as the dynamic-inflow models of rotors do; a is the horizontal travel of the last
//! half-stroke (at least that of the current one), so the inflow needs no knowledge of the
//! trajectory ahead. Both scale with the motion: w ∝ U under time scaling, and w = 0 at rest.

use serde::{Deserialize, Serialize};

/// How the fluid around a strip moves vertically.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Inflow {
    /// The fluid is at rest far away (the LDVM as published).
    #[default]
    Still,
    /// The fluid moves down at w = `ratio`·U_ref, U_ref the strip's reference speed.
    Uniform {
        /// w / U_ref (dimensionless, ≥ 0).
        ratio: f64,
    },
    /// Blade-element momentum theory (module docs): w = √(L̄′/(2ρ·a)).
    Momentum,
}

impl std::str::FromStr for Inflow {
    type Err = super::VortexError;
    /// `still`, `momentum` or `uniform:K` (w = K·U_ref, K ≥ 0).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.to_ascii_lowercase();
        let ratio = lower
            .strip_prefix("uniform:")
            .and_then(|k| k.parse::<f64>().ok())
            .filter(|k| k.is_finite() && *k >= 0.0);
        match (lower.as_str(), ratio) {
            ("still", _) => Ok(Self::Still),
            ("momentum", _) => Ok(Self::Momentum),
            (_, Some(ratio)) => Ok(Self::Uniform { ratio }),
            _ => Err(super::VortexError::UnknownChoice {
                setting: "inflow",
                name: s.into(),
                expected: "still, momentum or uniform:K with K >= 0",
            }),
        }
    }
}

/// The name [`std::str::FromStr`] reads: `still`, `momentum` or `uniform:K`.
impl std::fmt::Display for Inflow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Still => f.write_str("still"),
            Self::Momentum => f.write_str("momentum"),
            Self::Uniform { ratio } => write!(f, "uniform:{ratio}"),
        }
    }
}

/// Reversals closer together than this (chords of horizontal travel) are not half-strokes.
const MIN_HALF_STROKE_CHORDS: f64 = 0.5;

/// The state of one strip's induced inflow.
#[derive(Debug, Clone, Copy)]
pub(crate) struct InflowState {
    model: Inflow,
    /// 2ρ (kg/m³).
    two_rho: f64,
    /// MIN_HALF_STROKE_CHORDS·c (m).
    min_half_stroke_m: f64,
    /// Σ e^{−s/(s_U c)}·L′·dt (N·s/m): the recent vertical force per span, times time.
    recent_lift_n_s_m: f64,
    /// Horizontal travel since the last reversal (m).
    arc_m: f64,
    /// Horizontal travel of the last half-stroke (m); 0 before the first reversal.
    half_stroke_m: f64,
    /// Sign of the horizontal velocity in the current half-stroke (0 before any motion).
    direction: f64,
}

impl InflowState {
    pub fn new(model: Inflow, density_kg_m3: f64, chord_m: f64) -> Self {
        Self {
            model,
            two_rho: 2.0 * density_kg_m3,
            min_half_stroke_m: MIN_HALF_STROKE_CHORDS * chord_m,
            recent_lift_n_s_m: 0.0,
            arc_m: 0.0,
            half_stroke_m: 0.0,
            direction: 0.0,
        }
    }

    pub fn reset(&mut self) {
        *self = Self {
            recent_lift_n_s_m: 0.0,
            arc_m: 0.0,
            half_stroke_m: 0.0,
            direction: 0.0,
            ..*self
        };
    }

    pub fn is_still(&self) -> bool {
        self.model == Inflow::Still
    }

    /// Records one step of `dt_s`: `keep` = e^{−Δs/(s_U c)} of its travel, `lift_n_m` the
    /// vertical force per span of the step before (N/m), `horizontal_m_s` the section's
    /// horizontal velocity along a fixed horizontal direction of its plane (m/s).
    pub fn advance(&mut self, keep: f64, dt_s: f64, lift_n_m: f64, horizontal_m_s: f64) {
        self.recent_lift_n_s_m = keep * self.recent_lift_n_s_m + lift_n_m * dt_s;
        let sign = if horizontal_m_s > 0.0 {
            1.0
        } else if horizontal_m_s < 0.0 {
            -1.0
        } else {
            self.direction
        };
        if self.direction == 0.0 {
            self.direction = sign;
        } else if sign != self.direction && self.arc_m >= self.min_half_stroke_m {
            self.half_stroke_m = self.arc_m;
            self.arc_m = 0.0;
            self.direction = sign;
        }
        self.arc_m += horizontal_m_s.abs() * dt_s;
    }

    /// The inflow speed w ≥ 0 (m/s, downwards) for the reference speed `u_ref_m_s` and the
    /// averaging window `window_s` (s): the time the strip takes for s_U chords at U_ref, or
    /// the weighted time since the start where that is longer. A full window in the mean's
    /// denominator makes the inflow of a strip started from rest build up as its wake forms: over
    /// the first window of a constant lift L′, L̄′ ≈ L′·a/(s_U c), so w² ≈ L′/(2ρ·s_U c) stays
    /// finite while the arc a is still short.
    pub fn speed_m_s(&self, u_ref_m_s: f64, window_s: f64) -> f64 {
        match self.model {
            Inflow::Still => 0.0,
            Inflow::Uniform { ratio } => ratio * u_ref_m_s,
            Inflow::Momentum => {
                let arc = self.half_stroke_m.max(self.arc_m);
                if window_s > 0.0 && arc > 0.0 {
                    let lift = (self.recent_lift_n_s_m / window_s).max(0.0);
                    (lift / (self.two_rho * arc)).sqrt()
                } else {
                    0.0
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady strokes of 0.3 m at 0.2 m/s with a constant lift of 2 N/m: after a few
    /// half-strokes the arc is the stroke's and w = √(L′/(2ρa)) exactly.
    #[test]
    fn momentum_inflow_of_steady_strokes() {
        let mut s = InflowState::new(Inflow::Momentum, 800.0, 0.06);
        let (dt, v, stroke) = (0.001, 0.2, 0.3);
        let mut t = 0.0;
        let mut time = 0.0;
        for _ in 0..20_000 {
            let dir = if ((t * v / stroke) as u64) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            // travel-weighted forgetting over 4 chords
            let keep = (-v * dt / 0.24f64).exp();
            time = keep * time + dt;
            s.advance(keep, dt, 2.0, dir * v);
            t += dt;
        }
        let w = s.speed_m_s(v, time);
        let exact = (2.0 / (2.0 * 800.0 * stroke)).sqrt();
        assert!((s.half_stroke_m - stroke).abs() < 2.0 * v * dt);
        assert!((w - exact).abs() < 1e-2 * exact, "{w} against {exact}");
    }

    /// No lift, no inflow; a still model never moves the fluid; a jitter shorter than half a
    /// chord is not a reversal.
    #[test]
    fn inflow_edge_cases() {
        let mut s = InflowState::new(Inflow::Momentum, 800.0, 0.06);
        s.advance(1.0, 0.01, 0.0, 0.1);
        assert_eq!(s.speed_m_s(0.1, 0.01), 0.0);
        s.advance(1.0, 0.01, 0.0, -0.1);
        assert_eq!(s.half_stroke_m, 0.0);
        let still = InflowState::new(Inflow::Still, 800.0, 0.06);
        assert_eq!(still.speed_m_s(1.0, 1.0), 0.0);
        let uniform = InflowState::new(Inflow::Uniform { ratio: 0.2 }, 800.0, 0.06);
        assert_eq!(uniform.speed_m_s(0.5, 1.0), 0.1);
        assert_eq!("Momentum".parse::<Inflow>().unwrap(), Inflow::Momentum);
        assert_eq!("still".parse::<Inflow>().unwrap(), Inflow::Still);
        assert_eq!(
            "uniform:0.1".parse::<Inflow>().unwrap(),
            Inflow::Uniform { ratio: 0.1 }
        );
        for bad in ["uniform:-1", "uniform:x", "up"] {
            let e = bad.parse::<Inflow>().unwrap_err().to_string();
            assert!(e.contains(bad) && e.contains("momentum"), "{e}");
        }
        // Display writes the name FromStr reads.
        for inflow in [
            Inflow::Still,
            Inflow::Momentum,
            Inflow::Uniform { ratio: 0.25 },
        ] {
            assert_eq!(inflow.to_string().parse::<Inflow>().unwrap(), inflow);
        }
    }
}
