//! How the plate and the force sensor sit on the pitch shaft: two rig angles.
//!
//! The Euler angles (and so the inputs) are the encoders' readings; the wing frame they define
//! (x_w normal, y_w chordwise towards the LE, z_w along the span) is the frame the dataset's
//! loads are meant to be in. On a real rig neither the plate nor the sensor need sit at the
//! encoder's pitch zero. With both angles measured about the pitch (span) axis in the sense of
//! α:
//!
//! - the plate at θ_p flies at the pitch α + θ_p, so it sees the angle of attack AoA − θ_p for
//!   the encoders' AoA (R_0p = R_0w R_z(θ_p));
//! - the sensor at θ_s reports the loads in its own axes, R_0s = R_0w R_z(θ_s): a load L_p in
//!   the plate's axes reads L_s = R_z(θ_p − θ_s) L_p (forces and moments alike; M_z and the
//!   spanwise components unchanged, the pitch axis being the axis of the rotation).
//!
//! A plate clamped on the shaft at an angle θ to the sensor and the encoder zero is
//! θ_p = θ, θ_s = 0: the normal force then leaks into the chordwise channels as
//! F_y,s ≈ F_y + sin θ·F_x and M_x,s ≈ M_x − sin θ·M_y (docs/rig-agreement.md).

use crate::kinematics::EulerState;
use serde::{Deserialize, Serialize};

/// Largest angle either may have (deg): an assembly error, not a different rig.
pub const MAX_MOUNT_DEG: f64 = 45.0;

/// The plate's and the sensor's angles on the pitch shaft (deg, about the pitch axis in the
/// sense of α, from the pitch encoder's zero; both 0: everything aligned).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Mount {
    /// Angle θ_p of the plate's chord from the encoder's pitch zero (deg).
    pub plate_pitch_deg: f64,
    /// Angle θ_s of the sensor's axes from the encoder's pitch zero (deg): the frame the loads
    /// are reported in.
    pub sensor_pitch_deg: f64,
}

impl Mount {
    /// The first angle that is not finite or beyond ±[`MAX_MOUNT_DEG`], named.
    pub fn out_of_range(&self) -> Option<(&'static str, f64)> {
        [
            ("mount.plate_pitch_deg", self.plate_pitch_deg),
            ("mount.sensor_pitch_deg", self.sensor_pitch_deg),
        ]
        .into_iter()
        .find(|(_, v)| !(v.is_finite() && v.abs() <= MAX_MOUNT_DEG))
    }

    /// Whether the plate flies at the encoders' pitch.
    pub fn plate_aligned(&self) -> bool {
        self.plate_pitch_deg == 0.0
    }

    /// The plate's Euler state for the encoders' `state`: pitch α + θ_p, the rates unchanged.
    pub fn plate_state(&self, state: &EulerState) -> EulerState {
        let mut plate = *state;
        plate.angles_rad[2] += self.plate_pitch_deg.to_radians();
        plate
    }

    /// Re-expresses loads [F_x, F_y, M_x, M_y, M_z] from the plate's axes in the sensor's:
    /// (x, y) of the force and of the moment rotated by R_z(θ_p − θ_s).
    pub fn plate_to_sensor(&self, loads: &mut [f64; 5]) {
        let angle = (self.plate_pitch_deg - self.sensor_pitch_deg).to_radians();
        if angle == 0.0 {
            return;
        }
        let (s, c) = angle.sin_cos();
        let rotate = |x: f64, y: f64| (c * x - s * y, s * x + c * y);
        (loads[0], loads[1]) = rotate(loads[0], loads[1]);
        (loads[2], loads[3]) = rotate(loads[2], loads[3]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{WingKinematics, mat_mul, rot_z, rotation_global_from_wing};

    fn state() -> EulerState {
        EulerState {
            angles_rad: [0.3, -0.2, 0.4],
            rates_rad_s: [1.1, 0.3, -0.7],
            accels_rad_s2: [0.2, -0.5, 0.9],
        }
    }

    /// The plate's frame is the encoders' frame turned by θ_p about the span (R_0p = R_0w R_z(θ_p))
    /// and its angle of attack is the encoders' less θ_p.
    #[test]
    fn the_plate_flies_at_the_encoder_pitch_plus_its_angle() {
        let mount = Mount {
            plate_pitch_deg: 12.0,
            sensor_pitch_deg: 0.0,
        };
        let st = state();
        let plate = mount.plate_state(&st);
        let expected = mat_mul(
            &rotation_global_from_wing(&st.angles_rad),
            &rot_z(12f64.to_radians()),
        );
        let got = rotation_global_from_wing(&plate.angles_rad);
        for (a, b) in got.iter().flatten().zip(expected.iter().flatten()) {
            assert!((a - b).abs() < 1e-14);
        }
        let aoa = |s: &EulerState| WingKinematics::from_euler(s).inputs()[0];
        let d = aoa(&st) - aoa(&plate) - 12f64.to_radians();
        assert!(d.abs() < 1e-12, "AoA shift off by {d} rad");
    }

    /// A pure normal force on a plate mounted at θ reads F_x = N cos θ, F_y = N sin θ in the
    /// sensor's axes, and its flap moment M_y = a·N reads M_x = −a N sin θ; the rotation keeps
    /// the magnitudes and M_z, and a sensor turned with the plate reads the plate's loads.
    #[test]
    fn loads_turn_into_the_sensor_axes() {
        let theta = 20f64.to_radians();
        let mount = Mount {
            plate_pitch_deg: 20.0,
            sensor_pitch_deg: 0.0,
        };
        let mut loads = [2.0, 0.0, 0.0, 300.0, 7.0];
        mount.plate_to_sensor(&mut loads);
        let expected = [
            2.0 * theta.cos(),
            2.0 * theta.sin(),
            -300.0 * theta.sin(),
            300.0 * theta.cos(),
            7.0,
        ];
        for (a, b) in loads.iter().zip(expected) {
            assert!((a - b).abs() < 1e-12, "{loads:?}");
        }
        let together = Mount {
            plate_pitch_deg: 20.0,
            sensor_pitch_deg: 20.0,
        };
        let mut same = [1.0, 2.0, 3.0, 4.0, 5.0];
        together.plate_to_sensor(&mut same);
        assert_eq!(same, [1.0, 2.0, 3.0, 4.0, 5.0]);
    }

    #[test]
    fn angles_beyond_the_range_are_named() {
        assert_eq!(Mount::default().out_of_range(), None);
        let bad = Mount {
            plate_pitch_deg: 10.0,
            sensor_pitch_deg: f64::NAN,
        };
        assert_eq!(bad.out_of_range().unwrap().0, "mount.sensor_pitch_deg");
        let far = Mount {
            plate_pitch_deg: -50.0,
            sensor_pitch_deg: 0.0,
        };
        assert_eq!(far.out_of_range(), Some(("mount.plate_pitch_deg", -50.0)));
    }
}
