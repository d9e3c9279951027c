//! Euler-angle kinematics of a rigid wing and the 7 wing-frame model inputs.
//!
//! # Frames and angles
//!
//! ```text
//!            y_0 (up, stroke axis)                 wing frame w (at φ = ψ = α = 0)
//!             ^                                      y_w: chordwise, towards the leading edge (up)
//!             |   tip path (ψ > 0 lifts the tip)     z_w: span, root -> tip (along z_0)
//!             |     .-~~~-.                          x_w = y_w × z_w: plate normal (along x_0)
//!             |   /         \
//!             o------------------> z_0 (span at φ = 0)      LE  ^ y_w
//!            /  stroke axis                                  |  |
//!           v x_0                                  pitch axis o--+--> x_w   (plate seen from the tip,
//!                                                               |           α rotates it about z_w)
//!                                                           TE  |
//! ```
//!
//! The rotation from the wing frame to the global frame 0 is
//!
//! R_0w = R_y(φ) · R_x(−ψ) · R_z(α)
//!
//! with stroke frame s = R_y(φ) (stroke φ about the vertical y_0), deviation frame
//! d = s · R_x(−ψ) (positive deviation ψ lifts the tip) and wing frame w = d · R_z(α) (pitch α about
//! the span). At φ = ψ = α = 0 the plate is vertical, leading edge up, span along z_0; the tip
//! direction is R_0w e_z = [cos ψ sin φ, sin ψ, cos ψ cos φ].
//!
//! # Angular velocity and the pitch-axis point at unit span
//!
//! Wing-frame angular velocity ω = R_0wᵀ ω_0 (rad/s):
//!
//! ```text
//! ω_x = φ̇ cos ψ sin α − ψ̇ cos α
//! ω_y = φ̇ cos ψ cos α + ψ̇ sin α
//! ω_z = φ̇ sin ψ + α̇
//! ```
//!
//! The pitch axis passes through the stroke axis, so the point at unit distance along the span
//! on the pitch axis is e_z. Its velocity and acceleration in wing-frame components are
//! (per metre of span, i.e. 1/s and 1/s²):
//!
//! v = ω × e_z = [ω_y, −ω_x, 0],
//! a = ω̇ × e_z + ω × (ω × e_z) = [ω̇_y + ω_z ω_x, −ω̇_x + ω_z ω_y, −(ω_x² + ω_y²)].
//!
//! The angle of attack is AoA = atan2(−v_x, v_y) (measured from the chord axis y_w, so that
//! pol2cart(AoA + π/2, |v|) = (v_x, v_y)). It is signed: in normal hovering it alternates sign
//! between half-strokes (for ψ = 0 it has the sign of −φ̇ when the leading edge leads), and
//! |AoA| is the usual geometric angle of attack. With ψ = 0 the mid-stroke |AoA| is 90° − |α|.

/// Euler angles [stroke φ, deviation ψ, pitch α] and their first and second time derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EulerState {
    /// [φ, ψ, α] (rad).
    pub angles_rad: [f64; 3],
    /// [φ̇, ψ̇, α̇] (rad/s).
    pub rates_rad_s: [f64; 3],
    /// [φ̈, ψ̈, α̈] (rad/s²).
    pub accels_rad_s2: [f64; 3],
}

/// Wing-frame kinematics at unit distance along the span on the pitch axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WingKinematics {
    /// Angular velocity ω of the wing, wing-frame components (rad/s).
    pub omega_rad_s: [f64; 3],
    /// dω/dt, wing-frame components (rad/s²).
    pub omega_dot_rad_s2: [f64; 3],
    /// Signed geometric angle of attack AoA = atan2(−v_x, v_y) (rad), in (−π, π].
    pub aoa_rad: f64,
    /// |v| of the unit-span point (1/s, i.e. m/s per m of span).
    pub speed: f64,
    /// Normal velocity component v_x = ω_y (1/s).
    pub v_x: f64,
    /// Chordwise velocity component v_y = −ω_x (1/s).
    pub v_y: f64,
    /// [a_x, a_y, a_z] = ω̇ × e_z + ω × (ω × e_z) (1/s²): normal, chordwise, spanwise.
    pub a: [f64; 3],
    /// Pitch rate α̇ (rad/s), the Euler rate.
    pub pitch_rate_rad_s: f64,
    /// Pitch acceleration α̈ (rad/s²), the Euler acceleration.
    pub pitch_acc_rad_s2: f64,
    /// The global vertical y_0 (up, the stroke axis) in wing-frame components (a unit vector);
    /// `None` where the orientation is not known ([`Self::from_omega`], [`Self::from_rotation`]).
    pub up_wing: Option<[f64; 3]>,
}

/// A 3×3 matrix, rows first.
pub type Mat3 = [[f64; 3]; 3];

impl WingKinematics {
    /// Analytic wing kinematics from Euler angles, rates and accelerations (see module docs).
    pub fn from_euler(state: &EulerState) -> Self {
        let [_, psi, alpha] = state.angles_rad;
        let [phi_d, psi_d, alpha_d] = state.rates_rad_s;
        let [phi_dd, psi_dd, alpha_dd] = state.accels_rad_s2;
        let (s_psi, c_psi) = psi.sin_cos();
        let (s_al, c_al) = alpha.sin_cos();
        let omega = [
            phi_d * c_psi * s_al - psi_d * c_al,
            phi_d * c_psi * c_al + psi_d * s_al,
            phi_d * s_psi + alpha_d,
        ];
        let omega_dot = [
            phi_dd * c_psi * s_al - phi_d * psi_d * s_psi * s_al + phi_d * c_psi * c_al * alpha_d
                - psi_dd * c_al
                + psi_d * s_al * alpha_d,
            phi_dd * c_psi * c_al - phi_d * psi_d * s_psi * c_al - phi_d * c_psi * s_al * alpha_d
                + psi_dd * s_al
                + psi_d * c_al * alpha_d,
            phi_dd * s_psi + phi_d * psi_d * c_psi + alpha_dd,
        ];
        let r = rotation_global_from_wing(&state.angles_rad);
        Self {
            up_wing: Some(r[1]),
            ..Self::from_omega(omega, omega_dot, alpha_d, alpha_dd)
        }
    }

    /// Wing kinematics from the wing-frame angular velocity ω and its derivative ω̇, plus the
    /// pitch Euler rate α̇ and acceleration α̈ (which ω alone does not determine).
    pub fn from_omega(
        omega_rad_s: [f64; 3],
        omega_dot_rad_s2: [f64; 3],
        pitch_rate_rad_s: f64,
        pitch_acc_rad_s2: f64,
    ) -> Self {
        let [wx, wy, wz] = omega_rad_s;
        let [wdx, wdy, _] = omega_dot_rad_s2;
        let v_x = wy;
        let v_y = -wx;
        let a = [wdy + wz * wx, -wdx + wz * wy, -(wx * wx + wy * wy)];
        Self {
            omega_rad_s,
            omega_dot_rad_s2,
            aoa_rad: (-v_x).atan2(v_y),
            speed: v_x.hypot(v_y),
            v_x,
            v_y,
            a,
            pitch_rate_rad_s,
            pitch_acc_rad_s2,
            up_wing: None,
        }
    }

    /// Wing kinematics from the rotation matrix R_0w(t) (wing → global, any global frame) and
    /// its first and second time derivatives:
    ///
    /// `[ω]× = Rᵀ Ṙ`, `[ω̇]× = Rᵀ R̈ − [ω]×²`.
    ///
    /// The skew parts are extracted by antisymmetrisation, so small errors in numerically
    /// differentiated matrices do not bias ω. A constant global rotation Q (R → Q R) leaves the
    /// result unchanged.
    pub fn from_rotation(
        r: &Mat3,
        r_dot: &Mat3,
        r_ddot: &Mat3,
        pitch_rate_rad_s: f64,
        pitch_acc_rad_s2: f64,
    ) -> Self {
        let w_skew = mat_mul(&transpose(r), r_dot);
        let omega = vee(&w_skew);
        let rt_rdd = mat_mul(&transpose(r), r_ddot);
        let w2 = mat_mul(&skew(omega), &skew(omega));
        let mut wd_skew = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                wd_skew[i][j] = rt_rdd[i][j] - w2[i][j];
            }
        }
        Self::from_omega(omega, vee(&wd_skew), pitch_rate_rad_s, pitch_acc_rad_s2)
    }

    /// The 7 model inputs in the published order [AoA, |v|, a_x, a_y, a_z, α̇, α̈]
    /// (rad, 1/s, 1/s², 1/s², 1/s², rad/s, rad/s²).
    pub fn inputs(&self) -> [f64; 7] {
        [
            self.aoa_rad,
            self.speed,
            self.a[0],
            self.a[1],
            self.a[2],
            self.pitch_rate_rad_s,
            self.pitch_acc_rad_s2,
        ]
    }
}

/// Rotation about x by θ (rad).
pub fn rot_x(theta_rad: f64) -> Mat3 {
    let (s, c) = theta_rad.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

/// Rotation about y by θ (rad).
pub fn rot_y(theta_rad: f64) -> Mat3 {
    let (s, c) = theta_rad.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

/// Rotation about z by θ (rad).
pub fn rot_z(theta_rad: f64) -> Mat3 {
    let (s, c) = theta_rad.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// Rotation matrix R_0w = R_y(φ) · R_x(−ψ) · R_z(α) (wing → global), rows = global axes;
/// `angles_rad` = [φ, ψ, α].
pub fn rotation_global_from_wing(angles_rad: &[f64; 3]) -> Mat3 {
    let [phi, psi, alpha] = *angles_rad;
    mat_mul(&mat_mul(&rot_y(phi), &rot_x(-psi)), &rot_z(alpha))
}

/// Matrix product A·B.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, cij) in row.iter_mut().enumerate() {
            *cij = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// Transpose.
pub fn transpose(a: &Mat3) -> Mat3 {
    let mut t = [[0.0; 3]; 3];
    for (i, row) in a.iter().enumerate() {
        for (j, &aij) in row.iter().enumerate() {
            t[j][i] = aij;
        }
    }
    t
}

/// m·v.
pub fn mat_vec(m: &Mat3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Skew-symmetric cross-product matrix `[w]×`, with `[w]× u = w × u`.
pub fn skew(w: [f64; 3]) -> Mat3 {
    [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
}

/// Inverse of [`skew`] applied to the antisymmetric part of `m`.
pub fn vee(m: &Mat3) -> [f64; 3] {
    [
        0.5 * (m[2][1] - m[1][2]),
        0.5 * (m[0][2] - m[2][0]),
        0.5 * (m[1][0] - m[0][1]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tip_direction_matches_convention() {
        let (phi, psi) = (0.7_f64, 0.3_f64);
        let r = rotation_global_from_wing(&[phi, psi, 1.1]);
        let tip = [r[0][2], r[1][2], r[2][2]];
        let expect = [psi.cos() * phi.sin(), psi.sin(), psi.cos() * phi.cos()];
        for (a, b) in tip.iter().zip(expect) {
            assert!((a - b).abs() < 1e-15);
        }
        // At zero angles the leading edge (y_w) points up.
        let r0 = rotation_global_from_wing(&[0.0; 3]);
        assert_eq!([r0[0][1], r0[1][1], r0[2][1]], [0.0, 1.0, 0.0]);
    }

    #[test]
    fn hovering_aoa_alternates_sign() {
        // Forward stroke φ̇ > 0 with α = −45°: leading edge leads, AoA = −45°.
        let fwd = WingKinematics::from_euler(&EulerState {
            angles_rad: [0.0, 0.0, -std::f64::consts::FRAC_PI_4],
            rates_rad_s: [1.0, 0.0, 0.0],
            accels_rad_s2: [0.0; 3],
        });
        assert!((fwd.aoa_rad + std::f64::consts::FRAC_PI_4).abs() < 1e-14);
        assert!(fwd.v_y > 0.0);
        let back = WingKinematics::from_euler(&EulerState {
            angles_rad: [0.0, 0.0, std::f64::consts::FRAC_PI_4],
            rates_rad_s: [-1.0, 0.0, 0.0],
            accels_rad_s2: [0.0; 3],
        });
        assert!((back.aoa_rad - std::f64::consts::FRAC_PI_4).abs() < 1e-14);
    }
}
