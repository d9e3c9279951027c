//! Kinematics as parameters: each Euler angle a finite Fourier series at one flapping
//! frequency, ramped in from rest, and the limits a design must respect.
//!
//! ```text
//! θ_i(t) = r(t) · (c_i0 + Σ_{k=1..K} a_ik cos kx + b_ik sin kx),   x = 2πf t,   i ∈ {φ, ψ, α}
//! ```
//!
//! with `r` the generator's C² ramp over `ramp_cycles / f` seconds. The parameter vector is
//! `[c_φ0, a_φ1..a_φK, b_φ1..b_φK, c_ψ0, …, b_αK]` (rad), `3(1 + 2K)` values. Every Euler
//! state is linear in it, so `∂s(t)/∂θ` is the basis `r(t)·[1, cos kx, sin kx]` and its time
//! derivatives ([`HarmonicKinematics::basis_into`]).

use std::f64::consts::PI;

use faer::linalg::solvers::Solve;
use serde::{Deserialize, Serialize};

use super::spec::ramp;
use super::{Family, FourierSeries, TrajectorySpec};
use crate::kinematics::EulerState;

/// Names of the three angles in parameter names and limits.
pub const ANGLE_NAMES: [&str; 3] = ["stroke", "deviation", "pitch"];

/// Periodic Euler angles with `K` harmonics at one frequency (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HarmonicKinematics {
    /// Flapping frequency f (Hz).
    pub frequency_hz: f64,
    /// Harmonics per angle, K ≥ 1.
    pub harmonics: usize,
    /// Ramp-in from rest (cycles).
    pub ramp_cycles: f64,
    /// `3(1 + 2K)` Fourier coefficients (rad), angle by angle `[c₀, a₁..a_K, b₁..b_K]`.
    pub coefficients_rad: Vec<f64>,
}

/// Why a parameter set is not kinematics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HarmonicError {
    /// A field is out of range.
    #[error("{field} = {value}: {reason}")]
    Invalid {
        /// The field.
        field: String,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A fit had too few samples or a singular basis.
    #[error("cannot fit {harmonics} harmonics to {samples} samples")]
    Fit {
        /// Harmonics asked for.
        harmonics: usize,
        /// Samples given.
        samples: usize,
    },
}

impl HarmonicKinematics {
    /// Number of parameters with `harmonics` harmonics per angle.
    pub fn n_params(harmonics: usize) -> usize {
        3 * (1 + 2 * harmonics)
    }

    /// Zero kinematics (the wing at rest) with `harmonics` harmonics at `frequency_hz`.
    pub fn zeros(frequency_hz: f64, harmonics: usize, ramp_cycles: f64) -> Self {
        Self {
            frequency_hz,
            harmonics,
            ramp_cycles,
            coefficients_rad: vec![0.0; Self::n_params(harmonics)],
        }
    }

    /// The name of every parameter, e.g. `stroke.sin1_rad` (the order of the vector).
    pub fn parameter_names(harmonics: usize) -> Vec<String> {
        let mut names = Vec::with_capacity(Self::n_params(harmonics));
        for a in ANGLE_NAMES {
            names.push(format!("{a}.offset_rad"));
            names.extend((1..=harmonics).map(|k| format!("{a}.cos{k}_rad")));
            names.extend((1..=harmonics).map(|k| format!("{a}.sin{k}_rad")));
        }
        names
    }

    /// Checks frequency, harmonics, ramp and coefficients, naming the field.
    ///
    /// # Errors
    /// [`HarmonicError::Invalid`].
    pub fn check(&self) -> Result<(), HarmonicError> {
        let bad = |field: &str, value: f64, reason| {
            Err(HarmonicError::Invalid {
                field: field.to_string(),
                value,
                reason,
            })
        };
        if !(self.frequency_hz > 0.0 && self.frequency_hz.is_finite()) {
            return bad("frequency_hz", self.frequency_hz, "must be finite and > 0");
        }
        if self.harmonics == 0 || self.harmonics > 16 {
            return bad("harmonics", self.harmonics as f64, "must be in 1..=16");
        }
        if !(self.ramp_cycles > 0.0 && self.ramp_cycles.is_finite()) {
            return bad("ramp_cycles", self.ramp_cycles, "must be finite and > 0");
        }
        let n = Self::n_params(self.harmonics);
        if self.coefficients_rad.len() != n {
            return bad(
                "coefficients_rad",
                self.coefficients_rad.len() as f64,
                "must hold 3(1 + 2K) values",
            );
        }
        let names = Self::parameter_names(self.harmonics);
        if let Some((i, v)) = self
            .coefficients_rad
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite())
        {
            return bad(&names[i], *v, "must be finite");
        }
        Ok(())
    }

    /// Ramp-in duration (s).
    pub fn ramp_s(&self) -> f64 {
        self.ramp_cycles / self.frequency_hz
    }

    /// The Fourier series of angle `i` (rad).
    fn series(&self, i: usize) -> FourierSeries {
        let k = self.harmonics;
        let c = &self.coefficients_rad[i * (1 + 2 * k)..(i + 1) * (1 + 2 * k)];
        FourierSeries {
            offset_rad: c[0],
            cos_rad: c[1..=k].to_vec(),
            sin_rad: c[1 + k..].to_vec(),
        }
    }

    /// These kinematics as a trajectory of the generator (family `harmonic`, phase 0), which
    /// the virtual wing runs.
    pub fn spec(&self) -> TrajectorySpec {
        TrajectorySpec {
            family: Family::Harmonic,
            frequency_hz: self.frequency_hz,
            ramp_s: self.ramp_s(),
            phase_rad: 0.0,
            angles: [self.series(0), self.series(1), self.series(2)],
            aoa_targets_rad: [0.0; 2],
        }
    }

    /// The Euler states at `t = k·dt_s`, `k = 0..out.len()`. Allocates nothing beyond the
    /// series (once).
    pub fn sample_into(&self, dt_s: f64, out: &mut [EulerState]) {
        self.spec().sample_into(dt_s, out);
    }

    /// The basis at `t_s`: `out[j] = [b_j, ḃ_j, b̈_j]` of `b_j = r(t)·[1, cos kx, sin kx]_j`
    /// (`1 + 2K` values), so that angle `i`'s value, rate and acceleration are
    /// `Σ_j θ_{i,j} out[j]`. Allocates nothing.
    pub fn basis_into(&self, t_s: f64, out: &mut [[f64; 3]]) {
        let k_n = self.harmonics;
        let w = 2.0 * PI * self.frequency_hz;
        let (r, rd, rdd) = ramp(t_s, self.ramp_s());
        let x = w * t_s;
        // g, ġ, g̈ of each basis function in time, then the product rule with r.
        let mut put = |j: usize, g: f64, gd: f64, gdd: f64| {
            out[j] = [r * g, rd * g + r * gd, rdd * g + 2.0 * rd * gd + r * gdd];
        };
        put(0, 1.0, 0.0, 0.0);
        for k in 1..=k_n {
            let kw = k as f64 * w;
            let (s, c) = (k as f64 * x).sin_cos();
            put(k, c, -kw * s, -kw * kw * c);
            put(k_n + k, s, kw * c, -kw * kw * s);
        }
    }

    /// Least-squares fit of `harmonics` harmonics at `frequency_hz` to angle rows
    /// `[φ, ψ, α]` (rad) sampled every `dt_s` from `t = 0`, over samples `window` (the
    /// periodic part; the ramp is not fitted).
    ///
    /// # Errors
    /// [`HarmonicError::Fit`] with fewer samples than coefficients per angle or a singular
    /// basis; [`HarmonicError::Invalid`] for a bad frequency or harmonic count.
    pub fn fit(
        angles_rad: &[[f64; 3]],
        dt_s: f64,
        frequency_hz: f64,
        harmonics: usize,
        window: std::ops::Range<usize>,
    ) -> Result<Self, HarmonicError> {
        let mut out = Self::zeros(frequency_hz, harmonics, 1.5);
        out.check()?;
        let nb = 1 + 2 * harmonics;
        let rows =
            &angles_rad[window.start.min(angles_rad.len())..window.end.min(angles_rad.len())];
        let fail = HarmonicError::Fit {
            harmonics,
            samples: rows.len(),
        };
        if rows.len() < 2 * nb {
            return Err(fail);
        }
        let w = 2.0 * PI * frequency_hz;
        let basis = faer::Mat::<f64>::from_fn(rows.len(), nb, |n, j| {
            let x = w * (window.start + n) as f64 * dt_s;
            match j {
                0 => 1.0,
                j if j <= harmonics => (j as f64 * x).cos(),
                j => ((j - harmonics) as f64 * x).sin(),
            }
        });
        let rhs = faer::Mat::<f64>::from_fn(rows.len(), 3, |n, i| rows[n][i]);
        let gram = basis.transpose() * &basis;
        let llt = gram.llt(faer::Side::Lower).map_err(|_| fail.clone())?;
        let coef = llt.solve(basis.transpose() * &rhs);
        for i in 0..3 {
            for j in 0..nb {
                out.coefficients_rad[i * nb + j] = coef[(j, i)];
            }
        }
        if out.coefficients_rad.iter().any(|v| !v.is_finite()) {
            return Err(fail);
        }
        Ok(out)
    }
}

/// Limits on the angles, rates and accelerations of a design (magnitudes), angle by angle
/// `[φ, ψ, α]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KinematicLimits {
    /// Largest |angle| (rad).
    pub angle_rad: [f64; 3],
    /// Largest |rate| (rad/s).
    pub rate_rad_s: [f64; 3],
    /// Largest |acceleration| (rad/s²).
    pub accel_rad_s2: [f64; 3],
}

/// A limit a state breaks.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitViolation {
    /// The quantity, e.g. `stroke_rate_rad_s` ([`crate::input_jacobian::STATE_NAMES`]).
    pub field: &'static str,
    /// Its value.
    pub value: f64,
    /// The limit on its magnitude.
    pub limit: f64,
    /// The sample where it is largest.
    pub sample: usize,
}

impl KinematicLimits {
    /// The limits of a measured set: per angle, the largest magnitude of angle, rate and
    /// acceleration over `states` (each trajectory's states at the dataset rate, e.g. the
    /// smoothed samples of [`super::measured::raw_states`]), from sample `skip` on.
    pub fn of_states(states: &[Vec<EulerState>], skip: usize) -> Self {
        let mut l = Self {
            angle_rad: [0.0; 3],
            rate_rad_s: [0.0; 3],
            accel_rad_s2: [0.0; 3],
        };
        for st in states.iter().flat_map(|s| s.iter().skip(skip)) {
            for i in 0..3 {
                l.angle_rad[i] = l.angle_rad[i].max(st.angles_rad[i].abs());
                l.rate_rad_s[i] = l.rate_rad_s[i].max(st.rates_rad_s[i].abs());
                l.accel_rad_s2[i] = l.accel_rad_s2[i].max(st.accels_rad_s2[i].abs());
            }
        }
        l
    }

    /// The nine limits in the order of the state vector of [`crate::input_jacobian`].
    pub fn as_vector(&self) -> [f64; 9] {
        let mut v = [0.0; 9];
        v[..3].copy_from_slice(&self.angle_rad);
        v[3..6].copy_from_slice(&self.rate_rad_s);
        v[6..].copy_from_slice(&self.accel_rad_s2);
        v
    }

    /// Checks that every limit is finite and > 0, naming the field.
    ///
    /// # Errors
    /// [`HarmonicError::Invalid`].
    pub fn check(&self) -> Result<(), HarmonicError> {
        for (i, v) in self.as_vector().iter().enumerate() {
            if !(*v > 0.0 && v.is_finite()) {
                return Err(HarmonicError::Invalid {
                    field: format!("limits.{}", crate::input_jacobian::STATE_NAMES[i]),
                    value: *v,
                    reason: "must be finite and > 0",
                });
            }
        }
        Ok(())
    }

    /// The largest relative excess over the limits in `states` (`None` when all are within).
    pub fn violation(&self, states: &[EulerState]) -> Option<LimitViolation> {
        let lim = self.as_vector();
        let mut worst: Option<(f64, LimitViolation)> = None;
        for (n, st) in states.iter().enumerate() {
            let s = crate::input_jacobian::state_vector(st);
            for i in 0..9 {
                let excess = s[i].abs() / lim[i];
                if excess > 1.0 && worst.as_ref().is_none_or(|(w, _)| excess > *w) {
                    worst = Some((
                        excess,
                        LimitViolation {
                            field: crate::input_jacobian::STATE_NAMES[i],
                            value: s[i],
                            limit: lim[i],
                            sample: n,
                        },
                    ));
                }
            }
        }
        worst.map(|(_, v)| v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> HarmonicKinematics {
        let mut h = HarmonicKinematics::zeros(0.2, 3, 1.5);
        let c = &mut h.coefficients_rad;
        c[4] = 1.1; // stroke sin1
        c[2] = 0.05; // stroke cos2
        c[7 + 2] = -0.2; // deviation cos2
        c[14] = 0.1; // pitch offset
        c[14 + 1] = 0.6; // pitch cos1
        c[14 + 6] = -0.1; // pitch sin3
        h
    }

    /// The basis reproduces the sampled states exactly (states are linear in θ).
    #[test]
    fn basis_is_the_states_linear_map() {
        let h = example();
        let mut st = vec![EulerState::default(); 200];
        h.sample_into(0.04, &mut st);
        let mut b = vec![[0.0; 3]; 7];
        for (n, s) in st.iter().enumerate() {
            h.basis_into(n as f64 * 0.04, &mut b);
            for i in 0..3 {
                let th = &h.coefficients_rad[i * 7..(i + 1) * 7];
                let v: [f64; 3] = std::array::from_fn(|o| (0..7).map(|j| th[j] * b[j][o]).sum());
                assert!((v[0] - s.angles_rad[i]).abs() < 1e-12);
                assert!((v[1] - s.rates_rad_s[i]).abs() < 1e-12);
                assert!((v[2] - s.accels_rad_s2[i]).abs() < 1e-12);
            }
        }
    }

    /// Fitting a harmonic trajectory after its ramp returns its coefficients.
    #[test]
    fn fit_recovers_the_coefficients() {
        let h = example();
        let mut st = vec![EulerState::default(); 470];
        h.sample_into(0.04, &mut st);
        let angles: Vec<[f64; 3]> = st.iter().map(|s| s.angles_rad).collect();
        let f = HarmonicKinematics::fit(&angles, 0.04, 0.2, 3, 200..470).unwrap();
        for (a, b) in f.coefficients_rad.iter().zip(&h.coefficients_rad) {
            assert!((a - b).abs() < 1e-10, "{a} vs {b}");
        }
        assert!(HarmonicKinematics::fit(&angles, 0.04, 0.2, 3, 460..470).is_err());
    }

    #[test]
    fn limits_name_the_worst_excess_and_bad_fields() {
        let h = example();
        let mut st = vec![EulerState::default(); 470];
        h.sample_into(0.04, &mut st);
        let lim = KinematicLimits::of_states(&[st.clone()], 0);
        assert!(lim.violation(&st).is_none());
        let mut tight = lim;
        tight.rate_rad_s[0] *= 0.5;
        let v = tight.violation(&st).unwrap();
        assert_eq!(v.field, "stroke_rate_rad_s");
        assert!(v.value.abs() > v.limit);
        let mut bad = h.clone();
        bad.coefficients_rad[9] = f64::NAN;
        let e = bad.check().unwrap_err().to_string();
        assert!(e.contains("deviation.cos2_rad"), "{e}");
        tight.accel_rad_s2[2] = 0.0;
        assert!(
            tight
                .check()
                .unwrap_err()
                .to_string()
                .contains("pitch_accel_rad_s2")
        );
    }
}
