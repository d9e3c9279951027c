//! Fixtures shared by the wing's integration tests.
#![allow(dead_code)]

use flapssm_wing::aero::blade_element::BladeGeometry;
use flapssm_wing::kinematics::{EulerState, rotation_global_from_wing};
use std::f64::consts::{FRAC_PI_4, PI};

/// The dataset plate: 0.18 × 0.06 m, r0 = 0.055 m, pitch axis 15 %, oil, sensor at the root.
pub fn blade() -> BladeGeometry {
    BladeGeometry {
        span_m: 0.18,
        chord_m: 0.06,
        root_offset_m: 0.055,
        pitch_axis_frac: 0.15,
        density_kg_m3: 800.0,
        sensor_radius_m: 0.055,
    }
}

/// Lift (N): the vertical (global y₀, up) component of the wing-frame force [F_x, F_y] of the
/// loads `y` at `state`.
pub fn lift_n(state: &EulerState, y: &[f64; 5]) -> f64 {
    let r = rotation_global_from_wing(&state.angles_rad);
    r[1][0] * y[0] + r[1][1] * y[1]
}

/// Robofly-like hovering at `f` Hz: φ = 80° sin(2πft), ψ = 0, α = ∓45° at mid-stroke with a
/// tanh-shaped rotation of sharpness k = 3 (AoA = 45° at mid-stroke); analytic rates and
/// accelerations.
pub fn robofly_hover_state(t: f64, f: f64) -> EulerState {
    let (amp, a_pitch, k) = (80f64.to_radians(), FRAC_PI_4, 3.0);
    let w = 2.0 * PI * f;
    let x = w * t;
    let u = k * x.cos();
    let (u1, u2) = (-k * x.sin() * w, -k * x.cos() * w * w);
    let g = u.tanh();
    let g1 = (1.0 - g * g) * u1;
    let g2 = (1.0 - g * g) * u2 - 2.0 * g * (1.0 - g * g) * u1 * u1;
    let s = -a_pitch / k.tanh();
    EulerState {
        angles_rad: [amp * x.sin(), 0.0, s * g],
        rates_rad_s: [amp * w * x.cos(), 0.0, s * g1],
        accels_rad_s2: [-amp * w * w * x.sin(), 0.0, s * g2],
    }
}

/// Hovering figure-of-eight at `f` Hz: the Robofly stroke φ = 80° sin x (x = 2πft) with the
/// deviation ψ = −Ψ sin 2x (`deviation_amp_rad` = Ψ; the tip falls through mid-stroke and rises
/// through both reversals, as the generator's figure-eight family), and the tanh-shaped pitch
/// of [`robofly_hover_state`] with its plateau deepened by atan(2Ψ/Φ), so that the mid-stroke
/// AoA is 45° again despite the descent. Analytic rates and accelerations.
pub fn figure_eight_hover_state(t: f64, f: f64, deviation_amp_rad: f64) -> EulerState {
    let amp = 80f64.to_radians();
    let w = 2.0 * PI * f;
    let x = w * t;
    let dev = deviation_amp_rad;
    let robofly = robofly_hover_state(t, f);
    let pitch_scale = (FRAC_PI_4 + (2.0 * dev / amp).atan()) / FRAC_PI_4;
    EulerState {
        angles_rad: [
            amp * x.sin(),
            -dev * (2.0 * x).sin(),
            pitch_scale * robofly.angles_rad[2],
        ],
        rates_rad_s: [
            amp * w * x.cos(),
            -2.0 * dev * w * (2.0 * x).cos(),
            pitch_scale * robofly.rates_rad_s[2],
        ],
        accels_rad_s2: [
            -amp * w * w * x.sin(),
            4.0 * dev * w * w * (2.0 * x).sin(),
            pitch_scale * robofly.accels_rad_s2[2],
        ],
    }
}

/// (φ, ψ, α) → (−φ, ψ, −α): the kinematics mirrored in the wing frame's x_w (F_x, M_y, M_z
/// change sign, F_y and M_x do not).
pub fn mirrored(states: &[EulerState]) -> Vec<EulerState> {
    let m = |v: [f64; 3]| [-v[0], v[1], -v[2]];
    states
        .iter()
        .map(|s| EulerState {
            angles_rad: m(s.angles_rad),
            rates_rad_s: m(s.rates_rad_s),
            accels_rad_s2: m(s.accels_rad_s2),
        })
        .collect()
}

/// Asserts that a study's figures `got` lie within `tol` of the values it printed when its
/// output was recorded (docs/lab/wing-studies.md), naming the figure.
pub fn assert_recorded(what: &str, got: &[f64], recorded: &[f64], tol: f64) {
    assert_eq!(got.len(), recorded.len(), "{what}: {got:?}");
    for (k, (g, r)) in got.iter().zip(recorded).enumerate() {
        assert!(
            (g - r).abs() <= tol,
            "{what}[{k}]: {g:.4}, recorded {r} (tolerance {tol}); all: {got:.4?}"
        );
    }
}
