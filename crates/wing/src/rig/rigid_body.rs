//! The loads of a rig that are not aerodynamic, and the sensor's frame.
//!
//! Loads here are wrenches [F_x, F_y, F_z (N), M_x, M_y, M_z (N·m)], wing axes, moments about the
//! wing root on the pitch axis P = (0, 0, r₀) unless named otherwise (module [`super`]). The
//! origin O of the wing frame, where the pitch axis meets the stroke axis, is fixed. For a body
//! of mass m, volume V, centre of mass c and of buoyancy b (from P), inertia I_c about c, in a
//! fluid of density ρ, with g_w = R_0wᵀ(0, −g, 0) the gravity in wing axes:
//!
//! - weight: F = m g_w, M = c × F;
//! - buoyancy: F = −ρV g_w, M = b × F;
//! - inertia (d'Alembert): with a_c = ω̇ × c_O + ω × (ω × c_O), c_O = c + P,
//!   F = −m a_c, M = c × F − (I_c ω̇ + ω × I_c ω).
//!
//! All three are linear in the parameters (m, m·c, ρV, ρV·b, I_P about P): [`static_regressor`]
//! and [`inertial_regressor`] are those linear maps, used both for the loads of known mass
//! properties and to identify them from a reference run ([`super::identify`]).
//!
//! The sensor at offset d from P with axes R_ws reports (F_s, M_s) about its origin; in wing
//! axes about P: F = R_ws F_s, M = R_ws M_s + d × F.

use super::description::{MassProperties, SensorPose, Subtract};
use crate::kinematics::{
    EulerState, Mat3, WingKinematics, mat_mul, mat_vec, rot_x, rot_y, rot_z,
    rotation_global_from_wing, skew, transpose,
};
use crate::vec3::{add, cross, sub};
use crate::virtual_wing::GRAVITY_M_S2;

/// A wrench [F (N); M (N·m)].
pub type Wrench = [f64; 6];

/// The sensor's axes and origin on the wing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorFrame {
    /// R_ws: sensor components to wing components.
    wing_from_sensor: Mat3,
    /// d: the sensor origin from P (m).
    offset_m: [f64; 3],
}

impl SensorFrame {
    /// The frame of a sensor pose.
    pub fn new(pose: &SensorPose) -> Self {
        let [rx, ry, rz] = pose.rotation_deg.map(f64::to_radians);
        Self {
            wing_from_sensor: mat_mul(&mat_mul(&rot_x(rx), &rot_y(ry)), &rot_z(rz)),
            offset_m: pose.offset_m,
        }
    }

    /// A wrench reported by the sensor (its axes, about its origin) in wing axes about P.
    pub fn to_wing(&self, w: &Wrench) -> Wrench {
        let f = mat_vec(&self.wing_from_sensor, [w[0], w[1], w[2]]);
        let m = add(
            mat_vec(&self.wing_from_sensor, [w[3], w[4], w[5]]),
            cross(self.offset_m, f),
        );
        [f[0], f[1], f[2], m[0], m[1], m[2]]
    }

    /// A wrench in wing axes about P as the sensor reports it.
    pub fn to_sensor(&self, w: &Wrench) -> Wrench {
        let rt = transpose(&self.wing_from_sensor);
        let f = [w[0], w[1], w[2]];
        let about_sensor = sub([w[3], w[4], w[5]], cross(self.offset_m, f));
        let fs = mat_vec(&rt, f);
        let ms = mat_vec(&rt, about_sensor);
        [fs[0], fs[1], fs[2], ms[0], ms[1], ms[2]]
    }
}

/// A static load F = k·g_w, M = s × g_w: the weight (k = m, s = m·c) or the buoyancy
/// (k = −ρV, s = −ρV·b), or both at once as identified in the fluid.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct StaticParameters {
    /// k (kg).
    pub mass_kg: f64,
    /// s, about P (kg·m).
    pub first_moment_kg_m: [f64; 3],
}

/// The inertial parameters about P: mass m, first moment h = m·c (kg·m) and the inertia tensor
/// about P, [I_xx, I_yy, I_zz, I_xy, I_xz, I_yz] (kg·m²).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct InertialParameters {
    /// m (kg).
    pub mass_kg: f64,
    /// h = m·c (kg·m).
    pub first_moment_kg_m: [f64; 3],
    /// I_P (kg·m²).
    pub inertia_p_kg_m2: [f64; 6],
}

impl InertialParameters {
    /// The parameters as the regressor's column order [m, h, I_P].
    pub fn as_vector(&self) -> [f64; 10] {
        let h = self.first_moment_kg_m;
        let i = self.inertia_p_kg_m2;
        [
            self.mass_kg,
            h[0],
            h[1],
            h[2],
            i[0],
            i[1],
            i[2],
            i[3],
            i[4],
            i[5],
        ]
    }
}

/// The rigid-body loads of what a rig's sensor carries, linear in its parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// The weight.
    pub weight: StaticParameters,
    /// The buoyancy.
    pub buoyancy: StaticParameters,
    /// The inertia.
    pub inertia: InertialParameters,
    /// r₀: P is (0, 0, r₀) from the wing frame's fixed origin.
    pub root_offset_m: f64,
}

impl RigidBody {
    /// The body of `mass` in a fluid of `density_kg_m3`, on a wing whose root is
    /// `root_offset_m` from the stroke axis: I_P = I_c + m(|c|²E − c cᵀ).
    pub fn new(mass: &MassProperties, density_kg_m3: f64, root_offset_m: f64) -> Self {
        let m = mass.mass_kg;
        let c = mass.center_of_mass_m;
        let b = mass.center_of_buoyancy_m.unwrap_or(c);
        let displaced = density_kg_m3 * mass.volume_m3;
        let [ixx, iyy, izz, ixy, ixz, iyz] = mass.inertia_kg_m2;
        Self {
            weight: StaticParameters {
                mass_kg: m,
                first_moment_kg_m: c.map(|x| m * x),
            },
            buoyancy: StaticParameters {
                mass_kg: -displaced,
                first_moment_kg_m: b.map(|x| -displaced * x),
            },
            inertia: InertialParameters {
                mass_kg: m,
                first_moment_kg_m: c.map(|x| m * x),
                inertia_p_kg_m2: [
                    ixx + m * (c[1] * c[1] + c[2] * c[2]),
                    iyy + m * (c[0] * c[0] + c[2] * c[2]),
                    izz + m * (c[0] * c[0] + c[1] * c[1]),
                    ixy - m * c[0] * c[1],
                    ixz - m * c[0] * c[2],
                    iyz - m * c[1] * c[2],
                ],
            },
            root_offset_m,
        }
    }

    /// Weight and buoyancy at the orientation `angles_rad` [φ, ψ, α], each as `which` asks.
    pub fn static_loads(&self, angles_rad: &[f64; 3], which: &Subtract) -> Wrench {
        let y = static_regressor(gravity_in_wing(angles_rad));
        let mut out = [0.0; 6];
        for (on, p) in [
            (which.gravity, &self.weight),
            (which.buoyancy, &self.buoyancy),
        ] {
            if on {
                let theta = [
                    p.mass_kg,
                    p.first_moment_kg_m[0],
                    p.first_moment_kg_m[1],
                    p.first_moment_kg_m[2],
                ];
                add_product(&mut out, &y, &theta);
            }
        }
        out
    }

    /// The d'Alembert loads −(m a_c; I_P ω̇ + ω × I_P ω + h × a_P) of the body in the motion
    /// `state` ([`inertial_regressor`]).
    pub fn inertial_loads(&self, state: &EulerState) -> Wrench {
        let y = inertial_regressor(state, self.root_offset_m);
        let mut out = [0.0; 6];
        add_product(&mut out, &y, &self.inertia.as_vector());
        out
    }

    /// The loads `which` names in the motion `state`.
    pub fn loads(&self, state: &EulerState, which: &Subtract) -> Wrench {
        let mut w = self.static_loads(&state.angles_rad, which);
        if which.inertia {
            let i = self.inertial_loads(state);
            w.iter_mut().zip(i).for_each(|(a, b)| *a += b);
        }
        w
    }
}

/// g_w = R_0wᵀ (0, −g, 0), the gravity in wing axes (m/s²): minus g times the second row of R_0w.
pub fn gravity_in_wing(angles_rad: &[f64; 3]) -> [f64; 3] {
    let r = rotation_global_from_wing(angles_rad);
    [
        -GRAVITY_M_S2 * r[1][0],
        -GRAVITY_M_S2 * r[1][1],
        -GRAVITY_M_S2 * r[1][2],
    ]
}

/// Y_s(g) with F = k g, M = s × g equal to Y_s·[k, s_x, s_y, s_z].
pub fn static_regressor(g: [f64; 3]) -> [[f64; 4]; 6] {
    let mut y = [[0.0; 4]; 6];
    for i in 0..3 {
        y[i][0] = g[i];
    }
    // s × g = −[g]ₓ s.
    y[3][2] = g[2];
    y[3][3] = -g[1];
    y[4][1] = -g[2];
    y[4][3] = g[0];
    y[5][1] = g[1];
    y[5][2] = -g[0];
    y
}

/// Y_i with the d'Alembert wrench of a body in the motion `state` equal to Y_i·[m, h, I_P]:
/// a_P = ω̇ × p + ω × (ω × p) with p = (0, 0, r₀),
/// F = −m a_P − ([ω̇]ₓ + [ω]ₓ²) h, M = [a_P]ₓ h − (L(ω̇) + [ω]ₓ L(ω)) I_P, where L(v) I_P = I_P v.
pub fn inertial_regressor(state: &EulerState, root_offset_m: f64) -> [[f64; 10]; 6] {
    let kin = WingKinematics::from_euler(state);
    let (om, omd) = (kin.omega_rad_s, kin.omega_dot_rad_s2);
    let p = [0.0, 0.0, root_offset_m];
    let a_p = add(cross(omd, p), cross(om, cross(om, p)));
    let l = |v: [f64; 3]| {
        [
            [v[0], 0.0, 0.0, v[1], v[2], 0.0],
            [0.0, v[1], 0.0, v[0], 0.0, v[2]],
            [0.0, 0.0, v[2], 0.0, v[0], v[1]],
        ]
    };
    let (s_omd, s_om, s_a) = (skew(omd), skew(om), skew(a_p));
    let (l_omd, l_om) = (l(omd), l(om));
    let mut y = [[0.0; 10]; 6];
    for i in 0..3 {
        y[i][0] = -a_p[i];
        for j in 0..3 {
            let om2: f64 = (0..3).map(|k| s_om[i][k] * s_om[k][j]).sum();
            y[i][1 + j] = -(s_omd[i][j] + om2);
            y[3 + i][1 + j] = s_a[i][j];
        }
        for j in 0..6 {
            let gyro: f64 = (0..3).map(|k| s_om[i][k] * l_om[k][j]).sum();
            y[3 + i][4 + j] = -(l_omd[i][j] + gyro);
        }
    }
    y
}

/// out += Y·θ.
fn add_product<const K: usize>(out: &mut Wrench, y: &[[f64; K]; 6], theta: &[f64; K]) {
    for (o, row) in out.iter_mut().zip(y) {
        *o += row.iter().zip(theta).map(|(a, b)| a * b).sum::<f64>();
    }
}

/// The dataset's five channels [F_x, F_y (N), M_x, M_y, M_z (N·mm)] of a wrench.
pub fn dataset_channels(w: &Wrench) -> [f64; 5] {
    [w[0], w[1], 1e3 * w[3], 1e3 * w[4], 1e3 * w[5]]
}

/// The wrench of the dataset's five channels, F_z = 0 (a flat plate has no spanwise
/// aerodynamic force).
pub fn wrench_of_channels(y: &[f64; 5]) -> Wrench {
    [y[0], y[1], 0.0, 1e-3 * y[2], 1e-3 * y[3], 1e-3 * y[4]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::description::{ForceUnit, MomentUnit};

    fn body() -> MassProperties {
        MassProperties {
            mass_kg: 0.02,
            volume_m3: 1.5e-5,
            center_of_mass_m: [0.001, -0.01, 0.06],
            center_of_buoyancy_m: Some([0.0, -0.012, 0.05]),
            inertia_kg_m2: [3e-5, 2e-5, 1.2e-5, 1e-7, -2e-7, 3e-7],
        }
    }

    fn close(a: &[f64], b: &[f64], tol: f64) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol, "{a:?} vs {b:?}");
        }
    }

    /// At φ = ψ = 0, α = 90° the plate is horizontal with x_w up... the gravity (0, −g, 0)
    /// global is −g along −x_w rotated: closed form for a static pose.
    #[test]
    fn weight_and_buoyancy_of_a_static_pose() {
        let rb = RigidBody::new(&body(), 900.0, 0.04);
        let only_gravity = Subtract {
            gravity: true,
            ..Subtract::default()
        };
        // At zero angles the wing frame is the global frame: g_w = (0, −g, 0).
        let w = rb.static_loads(&[0.0; 3], &only_gravity);
        let f = [0.0, -0.02 * GRAVITY_M_S2, 0.0];
        let c = body().center_of_mass_m;
        let m = [
            c[1] * f[2] - c[2] * f[1],
            c[2] * f[0] - c[0] * f[2],
            c[0] * f[1] - c[1] * f[0],
        ];
        close(&w, &[f[0], f[1], f[2], m[0], m[1], m[2]], 1e-15);
        // Pitched by 90°: the global up is −x_w (R_z(90°) maps x_w to y_0).
        let w = rb.static_loads(&[0.0, 0.0, std::f64::consts::FRAC_PI_2], &only_gravity);
        close(&w[..3], &[-0.02 * GRAVITY_M_S2, 0.0, 0.0], 1e-15);
        // Buoyancy: −ρV g_w at the centre of buoyancy.
        let only_buoyancy = Subtract {
            buoyancy: true,
            ..Subtract::default()
        };
        let w = rb.static_loads(&[0.0; 3], &only_buoyancy);
        let lift = 900.0 * 1.5e-5 * GRAVITY_M_S2;
        let b = [0.0, -0.012, 0.05];
        close(&w, &[0.0, lift, 0.0, -b[2] * lift, 0.0, b[0] * lift], 1e-15);
    }

    /// A pure stroke rotation at constant rate Ω (ψ = α = 0): ω = (0, Ω, 0), the centre of mass
    /// at c_O feels the centripetal −Ω²(c_O,x, 0, c_O,z); the d'Alembert force is m Ω² (c_x, 0,
    /// c_O,z) and the gyroscopic moment −Ω × I Ω = −Ω²(−I_yz, 0, I_xy)... in closed form.
    #[test]
    fn inertia_of_a_pure_rotation() {
        let mass = body();
        let rb = RigidBody::new(&mass, 0.0, 0.04);
        let omega = 3.0;
        let st = EulerState {
            angles_rad: [0.3, 0.0, 0.0],
            rates_rad_s: [omega, 0.0, 0.0],
            accels_rad_s2: [0.0; 3],
        };
        let w = rb.inertial_loads(&st);
        let c = mass.center_of_mass_m;
        let c_o = [c[0], c[1], c[2] + 0.04];
        let f = [
            mass.mass_kg * omega * omega * c_o[0],
            0.0,
            mass.mass_kg * omega * omega * c_o[2],
        ];
        let [_, _, _, ixy, _, iyz] = mass.inertia_kg_m2;
        // I ω = Ω (I_xy, I_yy, I_yz); ω × I ω = Ω² (I_yz, 0, −I_xy).
        let gyro = [omega * omega * iyz, 0.0, -omega * omega * ixy];
        let cf = cross(c, f);
        close(
            &w,
            &[
                f[0],
                f[1],
                f[2],
                cf[0] - gyro[0],
                cf[1] - gyro[1],
                cf[2] - gyro[2],
            ],
            1e-15,
        );
        // A pure angular acceleration about the span (pitch): F = −m ω̇ × c_O, M adds −I_c ω̇.
        let st = EulerState {
            angles_rad: [0.0; 3],
            rates_rad_s: [0.0; 3],
            accels_rad_s2: [0.0, 0.0, 5.0],
        };
        let w = rb.inertial_loads(&st);
        let f = [
            5.0 * c_o[1] * mass.mass_kg,
            -5.0 * c_o[0] * mass.mass_kg,
            0.0,
        ];
        let cf = cross(c, f);
        let [_, _, izz, _, ixz, iyz] = mass.inertia_kg_m2;
        let i_omd = [ixz * 5.0, iyz * 5.0, izz * 5.0];
        close(
            &w,
            &[
                f[0],
                f[1],
                f[2],
                cf[0] - i_omd[0],
                cf[1] - i_omd[1],
                cf[2] - i_omd[2],
            ],
            1e-15,
        );
    }

    /// The sensor frame: a force along the sensor's x rotated 90° about z is along the wing's y;
    /// an offset adds d × F; to_sensor inverts to_wing.
    #[test]
    fn the_sensor_frame_transform() {
        let pose = SensorPose {
            columns: Default::default(),
            force_unit: ForceUnit::N,
            moment_unit: MomentUnit::NM,
            offset_m: [0.0, 0.01, 0.02],
            rotation_deg: [0.0, 0.0, 90.0],
            noise_sd: [0.0; 6],
            bias_sd: [0.0; 6],
        };
        let frame = SensorFrame::new(&pose);
        let w = frame.to_wing(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        // F = (0, 1, 0); d × F = (0.01·0 − 0.02·1, 0.02·0 − 0·0, 0·1 − 0.01·0) = (−0.02, 0, 0).
        close(&w, &[0.0, 1.0, 0.0, -0.02, 0.0, 0.0], 1e-15);
        let pose = SensorPose {
            rotation_deg: [20.0, -35.0, 110.0],
            offset_m: [0.003, -0.01, 0.02],
            ..pose
        };
        let frame = SensorFrame::new(&pose);
        let x = [0.3, -1.2, 0.4, 0.01, -0.02, 0.005];
        close(&frame.to_sensor(&frame.to_wing(&x)), &x, 1e-15);
    }
}
