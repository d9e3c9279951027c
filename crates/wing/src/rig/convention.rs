//! A rig's Euler-angle convention and its conversion to flapssm's.
//!
//! flapssm's wing orientation is R_0w = R_y(φ)·R_x(−ψ)·R_z(α) ([`crate::kinematics`]): stroke φ
//! about the vertical, deviation ψ about −x (positive lifts the tip), pitch α about the span.
//! A rig records three angles θ_k in its own units, signs and zeros and may nest its gimbal in
//! another order. With the rig's angle k read as flapssm's angle of the same name,
//!
//! θ_k (rad) = sign_k · (recorded_k − zero_k) · unit,
//!
//! the rig's orientation is the product of the three rotations in the rig's `order` (outermost
//! first), each about flapssm's axis of that angle. Another order is converted through the
//! rotation matrix: R = Π R_k(θ_k), then the flapssm angles of R.
//!
//! # Decomposing a rotation
//!
//! For R = R_{e1}(a)·R_{e2}(b)·R_{e3}(c) about signed orthogonal unit axes e1, e2, e3 with
//! s = e1·(e2 × e3) = ±1:
//!
//! - b = asin(s · e1ᵀ R e3),
//! - a = atan2((e1 × e3)·(R e3), e3·(R e3)),
//! - c = atan2(−(e3 × e1)·(Rᵀ e1), e1·(Rᵀ e1)),
//!
//! and (a + π, π − b, c + π) is the same rotation: the one nearer the previous sample's angles
//! is kept, so that a time series stays continuous.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use super::RigError;
use crate::kinematics::{Mat3, mat_mul, mat_vec, rot_x, rot_y, rot_z, transpose};
use crate::vec3::{cross, dot};

/// One of the three Euler angles, named as in flapssm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EulerAngle {
    /// Stroke φ, about the vertical y_0.
    Stroke,
    /// Deviation ψ, about −x (lifts the tip).
    Deviation,
    /// Pitch α, about the span z_w.
    Pitch,
}

impl EulerAngle {
    /// flapssm's order of the angles (and of every `[_; 3]` of angles).
    pub const FLAPSSM_ORDER: [EulerAngle; 3] =
        [EulerAngle::Stroke, EulerAngle::Deviation, EulerAngle::Pitch];

    /// Index of the angle in `[φ, ψ, α]`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The signed unit axis of the angle's rotation.
    fn axis(self) -> [f64; 3] {
        match self {
            EulerAngle::Stroke => [0.0, 1.0, 0.0],
            EulerAngle::Deviation => [-1.0, 0.0, 0.0],
            EulerAngle::Pitch => [0.0, 0.0, 1.0],
        }
    }

    /// The rotation by `angle_rad` about the angle's axis.
    fn rotation(self, angle_rad: f64) -> Mat3 {
        match self {
            EulerAngle::Stroke => rot_y(angle_rad),
            EulerAngle::Deviation => rot_x(-angle_rad),
            EulerAngle::Pitch => rot_z(angle_rad),
        }
    }
}

/// Unit of recorded angles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    /// Degrees.
    Deg,
    /// Radians.
    Rad,
}

impl AngleUnit {
    /// Radians per unit.
    pub fn to_rad(self) -> f64 {
        match self {
            AngleUnit::Deg => PI / 180.0,
            AngleUnit::Rad => 1.0,
        }
    }
}

/// How a rig records its Euler angles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleConvention {
    /// The recording's columns of stroke, deviation and pitch, in that order.
    pub columns: [String; 3],
    /// Unit of the recorded angles.
    pub unit: AngleUnit,
    /// The gimbal's order of rotations, outermost first (flapssm's: stroke, deviation, pitch).
    #[serde(default = "flapssm_order")]
    pub order: [EulerAngle; 3],
    /// Sign of each recorded angle against flapssm's (+1 or −1), stroke, deviation, pitch.
    #[serde(default = "unit_signs")]
    pub sign: [f64; 3],
    /// The recorded value (recording's unit) at flapssm's zero of each angle.
    #[serde(default)]
    pub zero: [f64; 3],
}

fn flapssm_order() -> [EulerAngle; 3] {
    EulerAngle::FLAPSSM_ORDER
}

fn unit_signs() -> [f64; 3] {
    [1.0; 3]
}

impl AngleConvention {
    /// flapssm's own convention in `unit`, with the given column names.
    pub fn flapssm(columns: [String; 3], unit: AngleUnit) -> Self {
        Self {
            columns,
            unit,
            order: flapssm_order(),
            sign: unit_signs(),
            zero: [0.0; 3],
        }
    }

    /// Checks signs, zeros and order, naming the field (prefixed `angles.`).
    pub fn check(&self) -> Result<(), RigError> {
        if let Some(s) = self.sign.iter().find(|s| s.abs() != 1.0) {
            return Err(RigError::field(
                "angles.sign",
                s,
                "each sign must be 1 or -1",
            ));
        }
        if let Some(z) = self.zero.iter().find(|z| !z.is_finite()) {
            return Err(RigError::field("angles.zero", z, "must be finite"));
        }
        for (k, a) in self.order.iter().enumerate() {
            if self.order[..k].contains(a) {
                return Err(RigError::field(
                    "angles.order",
                    format!("{:?}", self.order),
                    "must name stroke, deviation and pitch once each",
                ));
            }
        }
        Ok(())
    }

    fn is_flapssm_order(&self) -> bool {
        self.order == EulerAngle::FLAPSSM_ORDER
    }

    /// The rig's angles θ (rad, flapssm's signs and zeros, `[stroke, deviation, pitch]`) of one
    /// recorded row.
    fn rig_rad(&self, recorded: [f64; 3]) -> [f64; 3] {
        let u = self.unit.to_rad();
        std::array::from_fn(|k| self.sign[k] * (recorded[k] - self.zero[k]) * u)
    }

    /// flapssm's angles [φ, ψ, α] (rad) of one recorded row (not unwrapped: see
    /// [`Self::to_flapssm_series`]).
    pub fn to_flapssm(&self, recorded: [f64; 3]) -> [f64; 3] {
        let theta = self.rig_rad(recorded);
        if self.is_flapssm_order() {
            return theta;
        }
        let r = rotation(&self.order, theta);
        decompose(&EulerAngle::FLAPSSM_ORDER, &r, None)
    }

    /// flapssm's angles of a time series of recorded rows, each angle unwrapped to be
    /// continuous.
    pub fn to_flapssm_series(&self, recorded: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut out: Vec<[f64; 3]> = recorded.iter().map(|r| self.to_flapssm(*r)).collect();
        unwrap(&mut out);
        out
    }

    /// The recorded row (the rig's unit, signs, zeros and order) of flapssm's angles
    /// [φ, ψ, α] (rad); `previous` is the previous sample's result, for continuity.
    pub fn from_flapssm(&self, angles_rad: [f64; 3], previous: Option<[f64; 3]>) -> [f64; 3] {
        let u = self.unit.to_rad();
        let theta = if self.is_flapssm_order() {
            angles_rad
        } else {
            let r = rotation(&EulerAngle::FLAPSSM_ORDER, angles_rad);
            let prev = previous.map(|p| self.rig_rad(p));
            decompose(&self.order, &r, prev)
        };
        std::array::from_fn(|k| theta[k] / (self.sign[k] * u) + self.zero[k])
    }
}

/// R = Π R_k(θ_k) over `order` (outermost first); `angles` indexed `[stroke, deviation, pitch]`.
pub fn rotation(order: &[EulerAngle; 3], angles: [f64; 3]) -> Mat3 {
    order.iter().fold(
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        |r, a| mat_mul(&r, &a.rotation(angles[a.index()])),
    )
}

/// The angles (`[stroke, deviation, pitch]`, rad) of `r` in `order` (module docs): of the two
/// solutions, the one nearer `previous` (by wrapped distance), else the one with the middle
/// angle in [−π/2, π/2].
pub fn decompose(order: &[EulerAngle; 3], r: &Mat3, previous: Option<[f64; 3]>) -> [f64; 3] {
    let [e1, e2, e3] = order.map(EulerAngle::axis);
    let s = dot(e1, cross(e2, e3));
    let r_e3 = mat_vec(r, e3);
    let rt_e1 = mat_vec(&transpose(r), e1);
    let b = (s * dot(e1, r_e3)).clamp(-1.0, 1.0).asin();
    let a = dot(cross(e1, e3), r_e3).atan2(dot(e3, r_e3));
    let c = (-dot(cross(e3, e1), rt_e1)).atan2(dot(e1, rt_e1));
    let place = |[a, b, c]: [f64; 3]| {
        let mut out = [0.0; 3];
        out[order[0].index()] = a;
        out[order[1].index()] = b;
        out[order[2].index()] = c;
        out
    };
    let first = place([a, b, c]);
    let Some(prev) = previous else {
        return first;
    };
    let second = place([a + PI, PI - b, c + PI]);
    let nearest =
        |x: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| prev[k] + wrap(x[k] - prev[k])) };
    let (first, second) = (nearest(first), nearest(second));
    let dist = |x: [f64; 3]| (0..3).map(|k| (x[k] - prev[k]).abs()).sum::<f64>();
    if dist(second) < dist(first) {
        second
    } else {
        first
    }
}

/// An angle wrapped to (−π, π].
fn wrap(x: f64) -> f64 {
    let w = x.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

/// Removes 2π jumps between consecutive samples of each angle.
fn unwrap(rows: &mut [[f64; 3]]) {
    for k in 1..rows.len() {
        let prev = rows[k - 1];
        for (a, p) in rows[k].iter_mut().zip(prev) {
            *a = p + wrap(*a - p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::rotation_global_from_wing;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const ORDERS: [[EulerAngle; 3]; 6] = {
        use EulerAngle::*;
        [
            [Stroke, Deviation, Pitch],
            [Stroke, Pitch, Deviation],
            [Deviation, Stroke, Pitch],
            [Deviation, Pitch, Stroke],
            [Pitch, Stroke, Deviation],
            [Pitch, Deviation, Stroke],
        ]
    };

    fn close(a: &Mat3, b: &Mat3) -> f64 {
        (0..9)
            .map(|i| (a[i / 3][i % 3] - b[i / 3][i % 3]).abs())
            .fold(0.0, f64::max)
    }

    /// flapssm's order is the kinematics module's rotation.
    #[test]
    fn the_flapssm_order_is_the_wing_rotation() {
        let angles = [0.7, -0.3, 1.9];
        let r = rotation(&EulerAngle::FLAPSSM_ORDER, angles);
        assert!(close(&r, &rotation_global_from_wing(&angles)) < 1e-15);
    }

    /// Every order: decompose(rotation(θ)) is θ (middle angle within ±π/2) and the rotation
    /// is the same for the second solution.
    #[test]
    fn decomposition_inverts_the_rotation_in_every_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for order in &ORDERS {
            for _ in 0..200 {
                let mut theta: [f64; 3] = std::array::from_fn(|_| rng.random_range(-3.0..3.0));
                theta[order[1].index()] = rng.random_range(-1.5..1.5);
                let r = rotation(order, theta);
                let back = decompose(order, &r, None);
                for k in 0..3 {
                    assert!(
                        wrap(back[k] - theta[k]).abs() < 1e-10,
                        "{order:?} {theta:?} {back:?}"
                    );
                }
                let other = decompose(order, &r, Some(back.map(|x| x + PI)));
                assert!(close(&rotation(order, other), &r) < 1e-12);
            }
        }
    }

    /// Recorded rows in degrees, with signs, zeros and another order, convert to flapssm's
    /// angles and back; the series stays continuous through ±180°.
    #[test]
    fn a_convention_round_trips_and_stays_continuous() {
        let conv = AngleConvention {
            columns: ["a".into(), "b".into(), "c".into()],
            unit: AngleUnit::Deg,
            order: [EulerAngle::Stroke, EulerAngle::Pitch, EulerAngle::Deviation],
            sign: [-1.0, 1.0, -1.0],
            zero: [10.0, 0.0, 90.0],
        };
        let flapssm: Vec<[f64; 3]> = (0..400)
            .map(|k| {
                let t = k as f64 * 0.01;
                [
                    1.2 * (2.0 * t).sin(),
                    0.2 * (4.0 * t).cos(),
                    1.8 * (2.0 * t).cos(),
                ]
            })
            .collect();
        let mut prev = None;
        let recorded: Vec<[f64; 3]> = flapssm
            .iter()
            .map(|a| {
                let r = conv.from_flapssm(*a, prev);
                prev = Some(r);
                r
            })
            .collect();
        for w in recorded.windows(2) {
            // Near the gimbal lock (the middle angle, pitch, through 90°) the rig angles move
            // fast; a branch flip would jump by about 180°.
            assert!(
                (0..3).all(|k| (w[1][k] - w[0][k]).abs() < 45.0),
                "jump {w:?}"
            );
        }
        let back = conv.to_flapssm_series(&recorded);
        for (b, a) in back.iter().zip(&flapssm) {
            for k in 0..3 {
                assert!((b[k] - a[k]).abs() < 1e-9, "{b:?} vs {a:?}");
            }
        }
    }

    /// A sign of 2 or a repeated angle in the order is refused, naming the field.
    #[test]
    fn bad_conventions_are_refused() {
        let mut conv =
            AngleConvention::flapssm(["a".into(), "b".into(), "c".into()], AngleUnit::Rad);
        conv.sign[1] = 2.0;
        assert!(
            matches!(conv.check(), Err(RigError::Field { field, .. }) if field == "angles.sign")
        );
        conv.sign[1] = 1.0;
        conv.order[2] = EulerAngle::Stroke;
        assert!(
            matches!(conv.check(), Err(RigError::Field { field, .. }) if field == "angles.order")
        );
    }
}
