//! The two-dimensional hovering case of Wang, Birch & Dickinson (2004): a plate translating
//! back and forth along a horizontal stroke while it flips, run through any fidelity of the
//! virtual wing.
//!
//! # Motion
//!
//! The chord's centre moves along x(t) = (A₀/2) cos(2πft) and the chord makes the angle
//! α_c(t) = π/2 + β sin(2πft + φ) with the horizontal (A₀ = 2.8c, β = π/4, φ = 0: symmetric
//! rotation, the leading edge leading in both half-strokes), pitching about its centre, at
//! Re = U_max c/ν = 75 with U_max = πfA₀.
//!
//! # Two dimensions from the wing
//!
//! Every fidelity runs on the wing it always runs on, so the check is of the code the datasets
//! come from: a plate of `span_chords` × c whose mid-span sits `radius_chords` chords from the
//! stroke axis flaps through φ(t) = φ₀ cos(2πft), φ₀ = (A₀/2)/R, with the pitch
//! α(t) = β sin(2πft + φ) in this crate's convention (α = 0: the plate vertical). At R = 100c
//! the speed varies by ±5 % along a span of 10c and the arc departs from the straight stroke by
//! 0.01c: translation. L3's lattice then has its tips 5 chords from mid-span (a finite wing of
//! aspect ratio 10; the 2-D case has none); its wake stays in still fluid, as in the
//! experiment's tank (no slipstream of a revolving wing).
//!
//! # Loads
//!
//! Lift L is the vertical force, drag D the horizontal force against the motion of the
//! mid-span point (its sign flips at each reversal, as in the published histories), per unit
//! span, as coefficients C = F / (½ρU_max²c) — the definition of Wang et al. (2004). The
//! published files (../shared/data/wang2004-hovering) are on that scale within their
//! digitization: their mid-stroke values lie near the quasi-steady C_L = 1.2 sin 2α,
//! C_D = 1.4 − cos 2α at U_max.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::dataset::{Fluid, WingGeometry};
use crate::kinematics::{EulerState, rotation_global_from_wing};
use crate::sensor::SensorConfig;
use crate::virtual_wing::{Fidelity, SimulateError, VirtualWing, VirtualWingConfig};
use crate::vortex::Inflow;

/// The motion and the emulation (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hovering2d {
    /// Stroke amplitude A₀ (peak to peak) in chords (2.8).
    pub stroke_chords: f64,
    /// Pitch amplitude β (rad; π/4).
    pub pitch_amplitude_rad: f64,
    /// Phase φ of the rotation (rad; 0, symmetric).
    pub pitch_phase_rad: f64,
    /// Re = U_max c/ν (75).
    pub reynolds: f64,
    /// Periods simulated from rest (4, as the published histories).
    pub periods: usize,
    /// Samples per period (1000).
    pub samples_per_period: usize,
    /// Span of the emulating plate, in chords (10).
    pub span_chords: f64,
    /// Radius of its mid-span, in chords (100).
    pub radius_chords: f64,
}

impl Default for Hovering2d {
    fn default() -> Self {
        Self {
            stroke_chords: 2.8,
            pitch_amplitude_rad: PI / 4.0,
            pitch_phase_rad: 0.0,
            reynolds: 75.0,
            periods: 4,
            samples_per_period: 1000,
            span_chords: 10.0,
            radius_chords: 100.0,
        }
    }
}

/// Chord (m), frequency (Hz) and density of the emulation; the coefficients do not depend on
/// them.
const CHORD_M: f64 = 0.06;
const FREQUENCY_HZ: f64 = 0.25;
const DENSITY_KG_M3: f64 = 800.0;

/// Lift and drag coefficient histories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HoveringLoads {
    /// Time in periods, t/T.
    pub t_periods: Vec<f64>,
    /// C_L.
    pub lift: Vec<f64>,
    /// C_D.
    pub drag: Vec<f64>,
}

impl Hovering2d {
    /// U_max = πfA₀ (m/s) of the emulation.
    fn max_speed_m_s(&self) -> f64 {
        PI * FREQUENCY_HZ * self.stroke_chords * CHORD_M
    }

    /// The emulating wing at `fidelity`: the plate, pitch axis at mid-chord, in a fluid of the
    /// case's Re, with the Re-dependent settings (skin friction, L2 core growth) at that Re, L3's
    /// wake in still fluid, no sensor chain.
    pub fn wing(&self, fidelity: Fidelity) -> VirtualWingConfig {
        let c = CHORD_M;
        let span = self.span_chords * c;
        let radius = self.radius_chords * c;
        let mut cfg = VirtualWingConfig {
            fidelity,
            wing: WingGeometry {
                span_m: span,
                chord_m: c,
                root_offset_m: radius - 0.5 * span,
                pitch_axis_frac: 0.5,
                u_ref_radius_m: radius,
            },
            fluid: Fluid {
                density_kg_m3: DENSITY_KG_M3,
                kinematic_viscosity_m2_s: self.max_speed_m_s() * c / self.reynolds,
            },
            sensor: SensorConfig::noise_free(),
            mount: crate::mount::Mount::default(),
            ..VirtualWingConfig::default()
        };
        cfg.sensor_radius_m = cfg.wing.root_offset_m;
        cfg.aero.quasi_steady.skin_friction =
            crate::aero::quasi_steady::blasius_skin_friction(self.reynolds);
        cfg.l2.ldvm.core_growth_reynolds = Some(self.reynolds);
        cfg.l3.inflow = Inflow::Still;
        cfg
    }

    /// The Euler states of the motion, every 1/`samples_per_period` period from t = 0, and the
    /// time step (s).
    pub fn states(&self) -> (Vec<EulerState>, f64) {
        let w = 2.0 * PI * FREQUENCY_HZ;
        let phi0 = 0.5 * self.stroke_chords / self.radius_chords;
        let (beta, phase) = (self.pitch_amplitude_rad, self.pitch_phase_rad);
        let dt = 1.0 / (FREQUENCY_HZ * self.samples_per_period as f64);
        let n = self.periods * self.samples_per_period + 1;
        let states = (0..n)
            .map(|k| {
                let t = k as f64 * dt;
                let (s, c) = (w * t).sin_cos();
                let (sp, cp) = (w * t + phase).sin_cos();
                EulerState {
                    angles_rad: [phi0 * c, 0.0, beta * sp],
                    rates_rad_s: [-phi0 * w * s, 0.0, beta * w * cp],
                    accels_rad_s2: [-phi0 * w * w * c, 0.0, -beta * w * w * sp],
                }
            })
            .collect();
        (states, dt)
    }

    /// Runs the motion through `fidelity` (module docs).
    ///
    /// # Errors
    /// The wing's configuration errors; [`SimulateError::NonFinite`] for a non-finite load.
    pub fn simulate(&self, fidelity: Fidelity) -> Result<HoveringLoads, SimulateError> {
        let cfg = self.wing(fidelity);
        let mut wing = VirtualWing::new(&cfg)?;
        let (states, dt) = self.states();
        let mut loads = vec![[0.0; 5]; states.len()];
        wing.aero_loads_into(&states, dt, &mut loads);
        if let Some(sample) = loads.iter().position(|y| y.iter().any(|v| !v.is_finite())) {
            return Err(SimulateError::NonFinite { index: 0, sample });
        }
        let u = self.max_speed_m_s();
        let scale = 0.5 * DENSITY_KG_M3 * u * u * CHORD_M * cfg.wing.span_m;
        let (mut lift, mut drag) = (Vec::new(), Vec::new());
        for (st, y) in states.iter().zip(&loads) {
            let r = rotation_global_from_wing(&st.angles_rad);
            // Global force of the wing-frame (F_x, F_y); y₀ is up. The mid-span point moves
            // along (cos φ, 0, −sin φ)·φ̇.
            let f: [f64; 3] = std::array::from_fn(|i| r[i][0] * y[0] + r[i][1] * y[1]);
            let phi = st.angles_rad[0];
            let along = f[0] * phi.cos() - f[2] * phi.sin();
            lift.push(f[1] / scale);
            drag.push(-along * st.rates_rad_s[0].signum() / scale);
        }
        let t_periods = (0..states.len())
            .map(|k| k as f64 / self.samples_per_period as f64)
            .collect();
        Ok(HoveringLoads {
            t_periods,
            lift,
            drag,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::WingKinematics;

    /// The leading edge leads at 45° mid-stroke in both half-strokes, at the speed U_max.
    #[test]
    fn the_motion_is_the_papers() {
        let case = Hovering2d::default();
        let (states, _) = case.states();
        let radius = case.radius_chords * CHORD_M;
        for quarter in [250, 750] {
            let k = WingKinematics::from_euler(&states[quarter]);
            let [aoa, speed] = [k.inputs()[0], k.inputs()[1]];
            assert!(
                (aoa.abs() - PI / 4.0).abs() < 1e-9,
                "AoA {aoa} at sample {quarter}"
            );
            assert!((speed * radius - case.max_speed_m_s()).abs() < 1e-12);
        }
        let wing = case.wing(Fidelity::L0);
        let re = case.max_speed_m_s() * CHORD_M / wing.fluid.kinematic_viscosity_m2_s;
        assert!((re - 75.0).abs() < 1e-9);
    }

    /// At L0 the mid-stroke lift and drag are the translational ones: the plate's C_N(45°)
    /// split into lift and drag (C_N* (cos, sin)) and the chordwise force, within the ±5 % speed
    /// spread of the span.
    #[test]
    fn quasi_steady_mid_stroke_forces() {
        let case = Hovering2d::default();
        let loads = case.simulate(Fidelity::L0).unwrap();
        let k = 2 * case.samples_per_period + case.samples_per_period / 4;
        let cn = crate::aero::quasi_steady::plate_normal(PI / 4.0);
        let expected = cn * (PI / 4.0).cos();
        assert!(
            (loads.lift[k] - expected).abs() < 0.06 * expected,
            "C_L {} vs {expected}",
            loads.lift[k]
        );
        assert!(
            loads.drag[k] > 0.0 && loads.drag[k] < 2.0,
            "C_D {}",
            loads.drag[k]
        );
    }
}
