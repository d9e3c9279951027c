//! Derivatives of the wing-frame angular velocity and of the 7 model inputs with respect to
//! the Euler state, for design by gradient (chain rule from kinematic parameters to inputs).
//!
//! The state vector is `s = [φ, ψ, α, φ̇, ψ̇, α̇, φ̈, ψ̈, α̈]` (rad, rad/s, rad/s²). With
//! `ω`, `ω̇` as in [`crate::kinematics`] and `v = [ω_y, −ω_x, 0]`:
//!
//! ```text
//! dAoA = (ω_x dω_y − ω_y dω_x) / (ω_x² + ω_y²)      (AoA = atan2(−ω_y, −ω_x))
//! d|v| = (ω_x dω_x + ω_y dω_y) / |v|
//! da_x = dω̇_y + ω_x dω_z + ω_z dω_x
//! da_y = −dω̇_x + ω_y dω_z + ω_z dω_y
//! da_z = −2 (ω_x dω_x + ω_y dω_y)
//! ```
//!
//! At rest (`|v| = 0`) the angle of attack is undefined; its row and that of `|v|` are zero
//! there (a one-sided choice; the design kinematics start from rest with zero sensitivity).

use crate::kinematics::EulerState;

/// Index of each Euler-state component in the state vector `s` of this module.
pub const STATE_NAMES: [&str; 9] = [
    "stroke_rad",
    "deviation_rad",
    "pitch_rad",
    "stroke_rate_rad_s",
    "deviation_rate_rad_s",
    "pitch_rate_rad_s",
    "stroke_accel_rad_s2",
    "deviation_accel_rad_s2",
    "pitch_accel_rad_s2",
];

/// `∂ω/∂s` and `∂ω̇/∂s` (each 3 × 9, wing-frame components) at `state`.
pub fn omega_jacobian(state: &EulerState) -> ([[f64; 9]; 3], [[f64; 9]; 3]) {
    let [_, psi, alpha] = state.angles_rad;
    let [pd, sd, ad] = state.rates_rad_s;
    let [pdd, sdd, _] = state.accels_rad_s2;
    let (sp, cp) = psi.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    let mut w = [[0.0; 9]; 3];
    w[0][1] = -pd * sp * sa;
    w[0][2] = pd * cp * ca + sd * sa;
    w[0][3] = cp * sa;
    w[0][4] = -ca;
    w[1][1] = -pd * sp * ca;
    w[1][2] = -pd * cp * sa + sd * ca;
    w[1][3] = cp * ca;
    w[1][4] = sa;
    w[2][1] = pd * cp;
    w[2][3] = sp;
    w[2][5] = 1.0;
    let mut wd = [[0.0; 9]; 3];
    // ω̇_x = φ̈ cψ sα − φ̇ψ̇ sψ sα + φ̇ cψ cα α̇ − ψ̈ cα + ψ̇ sα α̇
    wd[0][1] = -pdd * sp * sa - pd * sd * cp * sa - pd * sp * ca * ad;
    wd[0][2] = pdd * cp * ca - pd * sd * sp * ca - pd * cp * sa * ad + sdd * sa + sd * ca * ad;
    wd[0][3] = -sd * sp * sa + cp * ca * ad;
    wd[0][4] = -pd * sp * sa + sa * ad;
    wd[0][5] = pd * cp * ca + sd * sa;
    wd[0][6] = cp * sa;
    wd[0][7] = -ca;
    // ω̇_y = φ̈ cψ cα − φ̇ψ̇ sψ cα − φ̇ cψ sα α̇ + ψ̈ sα + ψ̇ cα α̇
    wd[1][1] = -pdd * sp * ca - pd * sd * cp * ca + pd * sp * sa * ad;
    wd[1][2] = -pdd * cp * sa + pd * sd * sp * sa - pd * cp * ca * ad + sdd * ca - sd * sa * ad;
    wd[1][3] = -sd * sp * ca - cp * sa * ad;
    wd[1][4] = -pd * sp * ca + ca * ad;
    wd[1][5] = -pd * cp * sa + sd * ca;
    wd[1][6] = cp * ca;
    wd[1][7] = sa;
    // ω̇_z = φ̈ sψ + φ̇ψ̇ cψ + α̈
    wd[2][1] = pdd * cp - pd * sd * sp;
    wd[2][3] = sd * cp;
    wd[2][4] = pd * cp;
    wd[2][6] = sp;
    wd[2][8] = 1.0;
    (w, wd)
}

/// `∂u/∂s` (7 × 9) of the inputs `u = [AoA, |v|, a_x, a_y, a_z, α̇, α̈]`
/// ([`crate::kinematics::WingKinematics::inputs`]) at `state` (module docs).
pub fn input_jacobian(state: &EulerState) -> [[f64; 9]; 7] {
    let k = crate::kinematics::WingKinematics::from_euler(state);
    let [ox, oy, oz] = k.omega_rad_s;
    let (dw, dwd) = omega_jacobian(state);
    let mut j = [[0.0; 9]; 7];
    let speed2 = ox * ox + oy * oy;
    for c in 0..9 {
        if speed2 > 1e-300 {
            j[0][c] = (ox * dw[1][c] - oy * dw[0][c]) / speed2;
            j[1][c] = (ox * dw[0][c] + oy * dw[1][c]) / speed2.sqrt();
        }
        j[2][c] = dwd[1][c] + ox * dw[2][c] + oz * dw[0][c];
        j[3][c] = -dwd[0][c] + oy * dw[2][c] + oz * dw[1][c];
        j[4][c] = -2.0 * (ox * dw[0][c] + oy * dw[1][c]);
    }
    j[5][5] = 1.0;
    j[6][8] = 1.0;
    j
}

/// The state vector `s` of an Euler state.
pub fn state_vector(state: &EulerState) -> [f64; 9] {
    let mut s = [0.0; 9];
    s[..3].copy_from_slice(&state.angles_rad);
    s[3..6].copy_from_slice(&state.rates_rad_s);
    s[6..].copy_from_slice(&state.accels_rad_s2);
    s
}

/// The Euler state of a state vector `s`.
pub fn state_of_vector(s: &[f64; 9]) -> EulerState {
    EulerState {
        angles_rad: [s[0], s[1], s[2]],
        rates_rad_s: [s[3], s[4], s[5]],
        accels_rad_s2: [s[6], s[7], s[8]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::WingKinematics;

    /// Central differences of `f` at `s` (9 columns).
    pub(crate) fn central<const N: usize>(
        s: &[f64; 9],
        f: impl Fn(&EulerState) -> [f64; N],
    ) -> [[f64; 9]; N] {
        let mut j = [[0.0; 9]; N];
        for c in 0..9 {
            let h = 1e-6 * (1.0 + s[c].abs());
            let (mut up, mut dn) = (*s, *s);
            up[c] += h;
            dn[c] -= h;
            let (fu, fd) = (f(&state_of_vector(&up)), f(&state_of_vector(&dn)));
            for r in 0..N {
                j[r][c] = (fu[r] - fd[r]) / (2.0 * h);
            }
        }
        j
    }

    fn states() -> Vec<[f64; 9]> {
        vec![
            [0.4, 0.2, -0.7, 1.3, -0.4, 0.9, -2.0, 0.7, 3.1],
            [-1.1, -0.35, 0.5, -0.8, 0.6, -2.2, 1.5, -1.2, -0.4],
            [0.0, 0.0, 0.3, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
        ]
    }

    #[test]
    fn omega_jacobian_matches_central_differences() {
        for s in states() {
            let (w, wd) = omega_jacobian(&state_of_vector(&s));
            let fw = central(&s, |st| WingKinematics::from_euler(st).omega_rad_s);
            let fwd = central(&s, |st| WingKinematics::from_euler(st).omega_dot_rad_s2);
            for r in 0..3 {
                for c in 0..9 {
                    assert!((w[r][c] - fw[r][c]).abs() < 1e-7, "ω {r} {c}");
                    assert!((wd[r][c] - fwd[r][c]).abs() < 1e-7, "ω̇ {r} {c}");
                }
            }
        }
    }

    #[test]
    fn input_jacobian_matches_central_differences() {
        for s in states() {
            let j = input_jacobian(&state_of_vector(&s));
            let f = central(&s, |st| WingKinematics::from_euler(st).inputs());
            for r in 0..7 {
                for c in 0..9 {
                    let tol = 1e-6 * (1.0 + f[r][c].abs());
                    assert!(
                        (j[r][c] - f[r][c]).abs() < tol,
                        "u{r} s{c}: {} vs {}",
                        j[r][c],
                        f[r][c]
                    );
                }
            }
        }
        // At rest the angle of attack has no derivative (and no NaN).
        let j = input_jacobian(&EulerState::default());
        assert!(j.iter().flatten().all(|v| v.is_finite()));
    }
}
