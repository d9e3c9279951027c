//! Measured Euler angles as a trajectory of the virtual wing: samples at the dataset rate
//! (the paper's robot logged 25 Hz) become raw-rate states (250 Hz) for the aerodynamics and
//! the sensor chain.
//!
//! At the samples, angles, rates and accelerations come from the Savitzky–Golay differentiator
//! ([`SavitzkyGolayConfig::spanning_default`]: 13 samples at 25 Hz, degree 6). Between samples
//! `t_i` and `t_{i+1}` (`h = t_{i+1} − t_i`, `s = (t − t_i)/h`) each angle is the quintic Hermite
//! polynomial matching value, rate and acceleration at both ends,
//! `p(s) = H₀p₀ + H₁hv₀ + H₂h²a₀ + H₃h²a₁ + H₄hv₁ + H₅p₁`, so that the raw states are C²:
//! their rates and accelerations are the polynomial's derivatives (`dp/dt = p′/h`,
//! `d²p/dt² = p″/h²`). After the last sample the state is continued by its Taylor polynomial
//! (the raw tail of one dataset period that the decimation does not keep).
//!
//! **Start from rest.** The measured logs begin in motion (the first samples lie anywhere on
//! the stroke). A virtual wing started impulsively at that speed loads the sensor with a
//! start-up transient the rig never saw (measured on the 548, L2: F_x up to 20 N, a residual of
//! 1.18 N rms over the first 47 samples against 0.11 N after). So the drive ramps in from rest at
//! the first measured pose `p₀` over [`MEASURED_RAMP_S`]: `θ(t) = p₀ + r(t)(p(t) − p₀)` with the
//! C² ramp r of the generator (`θ̇ = ṙ(p − p₀) + rṗ`, `θ̈ = r̈(p − p₀) + 2ṙṗ + rp̈`). It ends
//! well inside the 93 samples (3.72 s) the published analyses skip; from then on the drive is
//! the measured motion.

use crate::differentiate::{DifferentiateError, SavitzkyGolay, SavitzkyGolayConfig};
use crate::kinematics::EulerState;

use super::SamplingConfig;
use super::spec::ramp;

/// Duration of the ramp-in from rest of a measured drive (s): 50 samples at 25 Hz.
pub const MEASURED_RAMP_S: f64 = 2.0;

/// Quintic Hermite basis at `s` and its first two derivatives (in `s`), in the order
/// `[p₀, v₀, a₀, a₁, v₁, p₁]`.
fn hermite(s: f64) -> [[f64; 6]; 3] {
    let (s2, s3, s4, s5) = (s * s, s * s * s, s.powi(4), s.powi(5));
    [
        [
            1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
            s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
            0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
            0.5 * s3 - s4 + 0.5 * s5,
            -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
            10.0 * s3 - 15.0 * s4 + 6.0 * s5,
        ],
        [
            -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
            1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
            s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
            1.5 * s2 - 4.0 * s3 + 2.5 * s4,
            -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
            30.0 * s2 - 60.0 * s3 + 30.0 * s4,
        ],
        [
            -60.0 * s + 180.0 * s2 - 120.0 * s3,
            -36.0 * s + 96.0 * s2 - 60.0 * s3,
            1.0 - 9.0 * s + 18.0 * s2 - 10.0 * s3,
            3.0 * s - 12.0 * s2 + 10.0 * s3,
            -24.0 * s + 84.0 * s2 - 60.0 * s3,
            60.0 * s - 180.0 * s2 + 120.0 * s3,
        ],
    ]
}

/// The raw-rate states (`n_samples · decimation` of them, every `raw_dt_s`) of measured angle
/// rows [φ, ψ, α] (rad), `n_samples` of them at the dataset rate of `sampling` (see the
/// module docs). The states at raw index `i · decimation` are the smoothed samples.
///
/// # Errors
/// [`DifferentiateError::LengthMismatch`] when there are not `n_samples` rows; the
/// differentiator's errors (too few samples).
pub fn raw_states(
    angles_rad: &[[f64; 3]],
    sampling: &SamplingConfig,
) -> Result<Vec<EulerState>, DifferentiateError> {
    let n = sampling.n_samples;
    if angles_rad.len() != n {
        return Err(DifferentiateError::LengthMismatch {
            expected: n,
            got: angles_rad.len(),
        });
    }
    let h = sampling.dataset_dt_s();
    let sg = SavitzkyGolay::new(SavitzkyGolayConfig::spanning_default(h))?;
    let mut knots = vec![EulerState::default(); n];
    let mut column = vec![0.0; n];
    sg.euler_states(angles_rad, h, &mut knots, &mut column)?;
    let dec = sampling.decimation.max(1);
    let mut out = vec![EulerState::default(); n * dec];
    for (k, st) in out.iter_mut().enumerate() {
        let (i, j) = (k / dec, k % dec);
        if i + 1 < n {
            let [b, db, ddb] = hermite(j as f64 / dec as f64);
            let (k0, k1) = (&knots[i], &knots[i + 1]);
            for a in 0..3 {
                let c = [
                    k0.angles_rad[a],
                    h * k0.rates_rad_s[a],
                    h * h * k0.accels_rad_s2[a],
                    h * h * k1.accels_rad_s2[a],
                    h * k1.rates_rad_s[a],
                    k1.angles_rad[a],
                ];
                let dot = |w: &[f64; 6]| w.iter().zip(&c).map(|(w, c)| w * c).sum::<f64>();
                st.angles_rad[a] = dot(&b);
                st.rates_rad_s[a] = dot(&db) / h;
                st.accels_rad_s2[a] = dot(&ddb) / (h * h);
            }
        } else {
            let last = &knots[n - 1];
            let tau = j as f64 * sampling.raw_dt_s();
            for a in 0..3 {
                let (p, v, acc) = (
                    last.angles_rad[a],
                    last.rates_rad_s[a],
                    last.accels_rad_s2[a],
                );
                st.angles_rad[a] = p + v * tau + 0.5 * acc * tau * tau;
                st.rates_rad_s[a] = v + acc * tau;
                st.accels_rad_s2[a] = acc;
            }
        }
    }
    let start = knots[0].angles_rad;
    let dt = sampling.raw_dt_s();
    for (k, st) in out.iter_mut().enumerate() {
        let (r, r_d, r_dd) = ramp(k as f64 * dt, MEASURED_RAMP_S);
        if r == 1.0 && r_d == 0.0 {
            break;
        }
        for (a, p0) in start.iter().enumerate() {
            let (p, v, acc) = (
                st.angles_rad[a] - p0,
                st.rates_rad_s[a],
                st.accels_rad_s2[a],
            );
            st.angles_rad[a] = p0 + r * p;
            st.rates_rad_s[a] = r_d * p + r * v;
            st.accels_rad_s2[a] = r_dd * p + 2.0 * r_d * v + r * acc;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_basis_interpolates_values_rates_and_accelerations() {
        let (at0, at1) = (hermite(0.0), hermite(1.0));
        // Value, rate, acceleration at s = 0 pick p₀, v₀, a₀; at s = 1, p₁, v₁, a₁.
        let unit = |m: &[[f64; 6]; 3], order: usize, k: usize| {
            (0..6).all(|j| (m[order][j] - if j == k { 1.0 } else { 0.0 }).abs() < 1e-12)
        };
        assert!(unit(&at0, 0, 0) && unit(&at0, 1, 1) && unit(&at0, 2, 2));
        assert!(unit(&at1, 0, 5) && unit(&at1, 1, 4) && unit(&at1, 2, 3));
    }

    /// Harmonic angles sampled at 25 Hz: the raw states at 250 Hz match the analytic ones
    /// (angles to 1e-5 rad, rates and accelerations to 1e-3 of their amplitude) past the ramp-in
    /// and away from the end; the drive starts at rest at the first sample's pose.
    #[test]
    fn raw_states_of_harmonic_samples_match_the_analytic_motion() {
        use std::f64::consts::TAU;
        let sampling = SamplingConfig::default();
        let w = TAU * 0.16;
        let f = |t: f64| {
            [
                1.1 * (w * t).sin(),
                0.2 * (2.0 * w * t).sin(),
                0.6 * (w * t).cos(),
            ]
        };
        let rows: Vec<[f64; 3]> = (0..470)
            .map(|i| f(i as f64 * sampling.dataset_dt_s()))
            .collect();
        let raw = raw_states(&rows, &sampling).unwrap();
        assert_eq!(raw.len(), 4700);
        let dt = sampling.raw_dt_s();
        let (mut ea, mut er) = (0.0f64, 0.0f64);
        for (k, st) in raw.iter().enumerate().skip(600).take(3800) {
            let t = k as f64 * dt;
            let exact = f(t);
            let rate0 = 1.1 * w * (w * t).cos();
            for (got, want) in st.angles_rad.iter().zip(exact) {
                ea = ea.max((got - want).abs());
            }
            er = er.max((st.rates_rad_s[0] - rate0).abs() / (1.1 * w));
        }
        assert!(ea < 1e-5, "angle error {ea:e} rad");
        assert_eq!(raw[0].rates_rad_s, [0.0; 3]);
        assert_eq!(raw[0].accels_rad_s2, [0.0; 3]);
        assert!((raw[0].angles_rad[0] - rows[0][0]).abs() < 1e-3);
        assert!(er < 1e-3, "rate error {er:e}");
        assert!(matches!(
            raw_states(&rows[..469], &sampling),
            Err(DifferentiateError::LengthMismatch { .. })
        ));
    }
}
