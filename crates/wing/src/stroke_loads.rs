//! The loads a designer asks for: the wing-frame loads of the model's outputs turned into the
//! stroke frame, about the stroke axis, and the aerodynamic power.
//!
//! Stroke frame 0 (the global frame of [`crate::kinematics`]): `y₀` up along the stroke axis,
//! `x₀` the direction the `φ̇ > 0` half-stroke sweeps at mid-stroke (the body's forward axis
//! for a wing on the right of a body whose stroke plane is horizontal), `z₀` the span at
//! `φ = ψ = 0` (out to the right). The outputs `y = [F_x, F_y, M_x, M_y, M_z]` (N, N·mm) are
//! wing-frame loads at the sensor, on the pitch axis at `r_s` from the stroke axis; the plate
//! carries no spanwise force (`F_z = 0`). Then, with `R = R_0w(φ, ψ, α)`:
//!
//! ```text
//! F₀ = R [F_x, F_y, 0]                                   thrust F₀x, lift F₀y, side F₀z (N)
//! M_o = 10⁻³ [M_x, M_y, M_z] + r_s e_z × [F_x, F_y, 0]    about the stroke axis (N·m)
//! M₀ = 10³ R M_o                                         roll M₀x, yaw M₀y, pitch M₀z (N·mm)
//! P  = −M_o · ω                                          aerodynamic power (W)
//! ```
//!
//! `P` is the rate at which the wing does work on the fluid (what an actuator supplies beyond
//! the plate's own inertia); a wing pair mirrored about the body's sagittal plane doubles lift,
//! thrust, pitch moment and power and cancels side force, roll and yaw moments.

use crate::input_jacobian::omega_jacobian;
use crate::kinematics::{
    EulerState, Mat3, WingKinematics, mat_mul, rot_x, rot_y, rot_z, rotation_global_from_wing, skew,
};

/// Names (with units) of the 7 stroke-frame quantities, in the order of
/// [`stroke_frame_loads`].
pub const QUANTITY_NAMES: [&str; 7] = [
    "thrust_n",
    "lift_n",
    "side_force_n",
    "roll_moment_n_mm",
    "yaw_moment_n_mm",
    "pitch_moment_n_mm",
    "power_w",
];

/// Index of each quantity in [`QUANTITY_NAMES`].
pub mod quantity {
    /// Thrust `F₀x` (N).
    pub const THRUST: usize = 0;
    /// Lift `F₀y` (N).
    pub const LIFT: usize = 1;
    /// Side force `F₀z` (N).
    pub const SIDE: usize = 2;
    /// Roll moment `M₀x` (N·mm).
    pub const ROLL: usize = 3;
    /// Yaw moment `M₀y` (N·mm).
    pub const YAW: usize = 4;
    /// Pitch moment `M₀z` (N·mm).
    pub const PITCH: usize = 5;
    /// Aerodynamic power (W).
    pub const POWER: usize = 6;
}

/// The moment about the stroke axis in the wing frame, `M_o` (N·m).
fn moment_at_axis(y: &[f64; 5], r_s: f64) -> [f64; 3] {
    [
        1e-3 * y[2] - r_s * y[1],
        1e-3 * y[3] + r_s * y[0],
        1e-3 * y[4],
    ]
}

fn rotate(r: &Mat3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// `[thrust, lift, side (N), roll, yaw, pitch (N·mm), power (W)]` of wing-frame loads `y`
/// at `state`, the sensor `sensor_radius_m` from the stroke axis (module docs).
pub fn stroke_frame_loads(y: &[f64; 5], state: &EulerState, sensor_radius_m: f64) -> [f64; 7] {
    let r = rotation_global_from_wing(&state.angles_rad);
    let f = rotate(&r, [y[0], y[1], 0.0]);
    let mo = moment_at_axis(y, sensor_radius_m);
    let m = rotate(&r, mo).map(|v| 1e3 * v);
    let w = WingKinematics::from_euler(state).omega_rad_s;
    let p = -(mo[0] * w[0] + mo[1] * w[1] + mo[2] * w[2]);
    [f[0], f[1], f[2], m[0], m[1], m[2], p]
}

/// The means over the samples of the 7 quantities of [`stroke_frame_loads`] of wing-frame
/// `loads` at `states` (one state per row; the cycle means when the rows span whole cycles).
pub fn mean_stroke_frame_loads(
    loads: &[[f64; 5]],
    states: &[EulerState],
    sensor_radius_m: f64,
) -> [f64; 7] {
    let n = loads.len().max(1) as f64;
    let mut q = [0.0; 7];
    for (y, s) in loads.iter().zip(states) {
        let v = stroke_frame_loads(y, s, sensor_radius_m);
        q.iter_mut().zip(v).for_each(|(a, b)| *a += b / n);
    }
    q
}

/// `∂q/∂y` (7 × 5) and `∂q/∂s` (7 × 9, the state vector of [`crate::input_jacobian`]) of the
/// quantities `q` of [`stroke_frame_loads`].
pub fn stroke_frame_jacobian(
    y: &[f64; 5],
    state: &EulerState,
    sensor_radius_m: f64,
) -> ([[f64; 5]; 7], [[f64; 9]; 7]) {
    let [phi, psi, alpha] = state.angles_rad;
    let r = rotation_global_from_wing(&state.angles_rad);
    let w = WingKinematics::from_euler(state).omega_rad_s;
    let rs = sensor_radius_m;
    let mut dy = [[0.0; 5]; 7];
    for i in 0..3 {
        dy[i][0] = r[i][0];
        dy[i][1] = r[i][1];
        dy[3 + i][0] = 1e3 * rs * r[i][1];
        dy[3 + i][1] = -1e3 * rs * r[i][0];
        for k in 0..3 {
            dy[3 + i][2 + k] = r[i][k];
        }
    }
    dy[6] = [
        -w[1] * rs,
        w[0] * rs,
        -1e-3 * w[0],
        -1e-3 * w[1],
        -1e-3 * w[2],
    ];
    // dR/dφ = [e_y]× R, dR/dψ = −R_y(φ) R_x(−ψ) [e_x]× R_z(α), dR/dα = R [e_z]×.
    let dr = [
        mat_mul(&skew([0.0, 1.0, 0.0]), &r),
        mat_mul(
            &mat_mul(&mat_mul(&rot_y(phi), &rot_x(-psi)), &skew([-1.0, 0.0, 0.0])),
            &rot_z(alpha),
        ),
        mat_mul(&r, &skew([0.0, 0.0, 1.0])),
    ];
    let fw = [y[0], y[1], 0.0];
    let mo = moment_at_axis(y, rs);
    let mut ds = [[0.0; 9]; 7];
    for (c, d) in dr.iter().enumerate() {
        let (f, m) = (rotate(d, fw), rotate(d, mo));
        for i in 0..3 {
            ds[i][c] = f[i];
            ds[3 + i][c] = 1e3 * m[i];
        }
    }
    let (dw, _) = omega_jacobian(state);
    for c in 0..9 {
        ds[6][c] = -(mo[0] * dw[0][c] + mo[1] * dw[1][c] + mo[2] * dw[2][c]);
    }
    (dy, ds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input_jacobian::{state_of_vector, state_vector};

    #[test]
    fn hovering_stroke_lifts_and_costs_power() {
        // Mid forward stroke (φ̇ > 0), pitched back 45° (AoA −45°): the normal force of a
        // plate opposing its motion points back and up when the leading edge leads.
        let st = EulerState {
            angles_rad: [0.0, 0.0, -std::f64::consts::FRAC_PI_4],
            rates_rad_s: [1.0, 0.0, 0.0],
            accels_rad_s2: [0.0; 3],
        };
        // Drag opposes v: v in the wing frame is [ω_y, −ω_x, 0]; the normal force F_x = −c v_x.
        let k = WingKinematics::from_euler(&st);
        let y = [-0.5 * k.v_x.signum(), 0.0, 0.0, 0.0, 0.0];
        let q = stroke_frame_loads(&y, &st, 0.055);
        assert!(q[quantity::LIFT] > 0.3, "lift {}", q[quantity::LIFT]);
        assert!(q[quantity::THRUST] < -0.3, "drag {}", q[quantity::THRUST]);
        assert!(q[quantity::POWER] > 0.0, "power {}", q[quantity::POWER]);
        assert!(q[quantity::SIDE].abs() < 1e-15);
        // A normal force at the sensor works against the normal velocity there:
        // P = |F_x| · v_x · r_s = 0.5 · cos 45° · 0.055.
        let want = 0.5 * std::f64::consts::FRAC_1_SQRT_2 * 0.055;
        assert!((q[quantity::POWER] - want).abs() < 1e-12);
    }

    #[test]
    fn jacobians_match_central_differences() {
        let y = [0.31, -0.12, 4.2, -17.0, 2.5];
        let s = [0.4, 0.2, -0.7, 1.3, -0.4, 0.9, -2.0, 0.7, 3.1];
        let st = state_of_vector(&s);
        let (dy, ds) = stroke_frame_jacobian(&y, &st, 0.055);
        for c in 0..5 {
            let h = 1e-6 * (1.0 + y[c].abs());
            let (mut up, mut dn) = (y, y);
            up[c] += h;
            dn[c] -= h;
            let (qu, qd) = (
                stroke_frame_loads(&up, &st, 0.055),
                stroke_frame_loads(&dn, &st, 0.055),
            );
            for r in 0..7 {
                let fd = (qu[r] - qd[r]) / (2.0 * h);
                assert!((fd - dy[r][c]).abs() < 1e-6 * (1.0 + fd.abs()), "q{r} y{c}");
            }
        }
        for c in 0..9 {
            let h = 1e-6 * (1.0 + s[c].abs());
            let (mut up, mut dn) = (state_vector(&st), state_vector(&st));
            up[c] += h;
            dn[c] -= h;
            let qu = stroke_frame_loads(&y, &state_of_vector(&up), 0.055);
            let qd = stroke_frame_loads(&y, &state_of_vector(&dn), 0.055);
            for r in 0..7 {
                let fd = (qu[r] - qd[r]) / (2.0 * h);
                assert!((fd - ds[r][c]).abs() < 1e-6 * (1.0 + fd.abs()), "q{r} s{c}");
            }
        }
    }
}
