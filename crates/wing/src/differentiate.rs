//! Zero-phase smoothing differentiator for measured, sampled, quantised angles.
//!
//! Savitzky–Golay: around each sample a polynomial of degree `order` is fitted by least squares
//! to the 2m + 1 samples of a window (m = `half_window`) and its value, first and second
//! derivative are taken at the sample. In the interior the window is centred, so the filter is
//! symmetric and has zero phase lag. Within m samples of either end the window is the first
//! (last) 2m + 1 samples and the polynomial is evaluated off-centre ("interp" edge mode; these
//! edge values are noisier).
//!
//! With local coordinate z = (j − m)/m ∈ [−1, 1] and Vandermonde V_{jq} = z_j^q, the fitted
//! coefficients are c = (VᵀV)⁻¹Vᵀ y, so every derivative at every window position is a fixed
//! weight vector; the weights are computed once in [`SavitzkyGolay::new`].

use crate::kinematics::EulerState;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use thiserror::Error;

/// Errors of the differentiator.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum DifferentiateError {
    /// The polynomial order is not below the window length, or is below 2.
    #[error("Savitzky-Golay order {order} needs 2 <= order < window length {window}")]
    InvalidOrder {
        /// Polynomial order.
        order: usize,
        /// Window length 2m + 1.
        window: usize,
    },
    /// Fewer samples than one window.
    #[error("signal has {n_samples} samples, shorter than the window of {window}")]
    TooShort {
        /// Number of samples.
        n_samples: usize,
        /// Window length.
        window: usize,
    },
    /// Output length differs from the input length.
    #[error("output has {got} rows, input has {expected}")]
    LengthMismatch {
        /// Input length.
        expected: usize,
        /// Output length.
        got: usize,
    },
    /// Non-positive or non-finite sampling period.
    #[error("invalid sampling period dt_s = {dt_s}")]
    InvalidPeriod {
        /// The period.
        dt_s: f64,
    },
}

/// Savitzky–Golay settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SavitzkyGolayConfig {
    /// m: the window has 2m + 1 samples.
    pub half_window: usize,
    /// Polynomial degree.
    pub order: usize,
}

impl Default for SavitzkyGolayConfig {
    /// Window 121 samples (0.48 s at 250 Hz), degree 6 (see docs/kinematics.md for the
    /// accuracy this gives on 4096-count encoder data).
    fn default() -> Self {
        Self {
            half_window: 60,
            order: 6,
        }
    }
}

impl SavitzkyGolayConfig {
    /// The window of the default's time span (0.48 s) at a sampling period `dt_s`, degree 6:
    /// `m = max(round(0.24 s / dt_s), 4)` (at 250 Hz the default itself; at the paper's
    /// 25 Hz, `m = 6`, 13 samples).
    pub fn spanning_default(dt_s: f64) -> Self {
        let d = Self::default();
        let span_s = d.half_window as f64 / 250.0;
        let m = if dt_s > 0.0 && dt_s.is_finite() {
            (span_s / dt_s).round().clamp(4.0, 1e6) as usize
        } else {
            d.half_window
        };
        Self {
            half_window: m,
            order: d.order,
        }
    }
}

/// The wing-frame inputs ([`crate::dataset::INPUT_NAMES`] order: AoA rad, |v| m/s, a_x a_y a_z
/// m/s², α̇ rad/s, α̈ rad/s²) of measured Euler angle rows [φ, ψ, α] (rad) sampled every
/// `dt_s`: angles, rates and accelerations by the Savitzky–Golay differentiator `cfg`, then
/// [`crate::kinematics::WingKinematics::from_euler`].
///
/// # Errors
/// [`DifferentiateError`] for a bad window or period, or fewer samples than one window.
pub fn measured_inputs(
    angles_rad: &[[f64; 3]],
    dt_s: f64,
    cfg: SavitzkyGolayConfig,
) -> Result<Vec<[f64; 7]>, DifferentiateError> {
    let sg = SavitzkyGolay::new(cfg)?;
    let mut states = vec![EulerState::default(); angles_rad.len()];
    let mut column = vec![0.0; angles_rad.len()];
    sg.euler_states(angles_rad, dt_s, &mut states, &mut column)?;
    Ok(states
        .iter()
        .map(|s| crate::kinematics::WingKinematics::from_euler(s).inputs())
        .collect())
}

/// A Savitzky–Golay differentiator with precomputed weights.
#[derive(Debug, Clone)]
pub struct SavitzkyGolay {
    half_window: usize,
    /// weights[e · L + j] = [w₀, w₁, w₂] for evaluation position e and tap j (L = 2m + 1), in
    /// sample units (w₁ per sample, w₂ per sample²).
    weights: Vec<[f64; 3]>,
}

impl SavitzkyGolay {
    /// Builds the weights for all 2m + 1 evaluation positions. Cost O(m²·order).
    pub fn new(cfg: SavitzkyGolayConfig) -> Result<Self, DifferentiateError> {
        let m = cfg.half_window;
        let len = 2 * m + 1;
        let p = cfg.order;
        if p < 2 || p >= len {
            return Err(DifferentiateError::InvalidOrder {
                order: p,
                window: len,
            });
        }
        let z: Vec<f64> = (0..len).map(|j| (j as f64 - m as f64) / m as f64).collect();
        // Gram matrix G = VᵀV, (p+1)×(p+1); solve G C = Vᵀ for C = (VᵀV)⁻¹Vᵀ, (p+1)×len.
        let n = p + 1;
        let mut g = vec![0.0; n * n];
        let mut c = vec![0.0; n * len];
        for (j, &zj) in z.iter().enumerate() {
            let mut pw = 1.0;
            for q in 0..n {
                c[q * len + j] = pw;
                pw *= zj;
            }
        }
        for a in 0..n {
            for b in 0..n {
                g[a * n + b] = (0..len).map(|j| c[a * len + j] * c[b * len + j]).sum();
            }
        }
        solve_in_place(&mut g, &mut c, n, len);
        let mut weights = vec![[0.0; 3]; len * len];
        for (e, &z0) in z.iter().enumerate() {
            for j in 0..len {
                let mut w = [0.0; 3];
                let mut pw = 1.0; // z0^q
                let mut pw1 = 0.0; // z0^(q-1)
                let mut pw2 = 0.0; // z0^(q-2)
                for q in 0..n {
                    let cq = c[q * len + j];
                    let qf = q as f64;
                    w[0] += cq * pw;
                    w[1] += cq * qf * pw1;
                    w[2] += cq * qf * (qf - 1.0) * pw2;
                    pw2 = pw1;
                    pw1 = pw;
                    pw *= z0;
                }
                let mf = m as f64;
                weights[e * len + j] = [w[0], w[1] / mf, w[2] / (mf * mf)];
            }
        }
        Ok(Self {
            half_window: m,
            weights,
        })
    }

    /// Window length 2m + 1.
    pub fn window(&self) -> usize {
        2 * self.half_window + 1
    }

    /// Smoothed value, rate and acceleration of sample `i` of `x` (sampled every `dt_s`).
    fn eval(&self, x: &[f64], i: usize, dt_s: f64) -> [f64; 3] {
        let len = self.window();
        let m = self.half_window;
        let start = i.saturating_sub(m).min(x.len() - len);
        let e = i - start;
        let w = &self.weights[e * len..(e + 1) * len];
        let mut out = [0.0; 3];
        for (wj, xj) in w.iter().zip(&x[start..start + len]) {
            out[0] += wj[0] * xj;
            out[1] += wj[1] * xj;
            out[2] += wj[2] * xj;
        }
        [out[0], out[1] / dt_s, out[2] / (dt_s * dt_s)]
    }

    fn check(&self, n: usize, n_out: usize, dt_s: f64) -> Result<(), DifferentiateError> {
        if !(dt_s > 0.0 && dt_s.is_finite()) {
            return Err(DifferentiateError::InvalidPeriod { dt_s });
        }
        if n < self.window() {
            return Err(DifferentiateError::TooShort {
                n_samples: n,
                window: self.window(),
            });
        }
        if n_out != n {
            return Err(DifferentiateError::LengthMismatch {
                expected: n,
                got: n_out,
            });
        }
        Ok(())
    }

    /// Smoothed values, first and second derivatives of `x` sampled every `dt_s`; each output
    /// has `x.len()` entries. Allocates nothing. Cost O(n·(2m + 1)).
    pub fn apply(
        &self,
        x: &[f64],
        dt_s: f64,
        value: &mut [f64],
        rate: &mut [f64],
        accel: &mut [f64],
    ) -> Result<(), DifferentiateError> {
        for n_out in [value.len(), rate.len(), accel.len()] {
            self.check(x.len(), n_out, dt_s)?;
        }
        for i in 0..x.len() {
            [value[i], rate[i], accel[i]] = self.eval(x, i, dt_s);
        }
        Ok(())
    }

    /// Euler states (angles, rates, accelerations) from measured angle rows [φ, ψ, α] (rad)
    /// sampled every `dt_s`. Allocates nothing.
    pub fn euler_states(
        &self,
        angles_rad: &[[f64; 3]],
        dt_s: f64,
        out: &mut [EulerState],
        column: &mut [f64],
    ) -> Result<(), DifferentiateError> {
        self.check(angles_rad.len(), out.len(), dt_s)?;
        self.check(angles_rad.len(), column.len(), dt_s)?;
        for a in 0..3 {
            for (c, row) in column.iter_mut().zip(angles_rad) {
                *c = row[a];
            }
            for (i, st) in out.iter_mut().enumerate() {
                let [v, r, acc] = self.eval(column, i, dt_s);
                st.angles_rad[a] = v;
                st.rates_rad_s[a] = r;
                st.accels_rad_s2[a] = acc;
            }
        }
        Ok(())
    }
}

/// Rounds an angle (rad) to the grid of an encoder with `counts_per_rev` counts per revolution.
pub fn quantize_to_encoder(angle_rad: f64, counts_per_rev: u32) -> f64 {
    let q = 2.0 * PI / counts_per_rev as f64;
    (angle_rad / q).round() * q
}

/// Solves G X = B in place (G: n×n row-major, B: n×k row-major, overwritten by X) by Gaussian
/// elimination with partial pivoting. G is a small, well-conditioned Gram matrix here.
fn solve_in_place(g: &mut [f64], b: &mut [f64], n: usize, k: usize) {
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&r, &s| g[r * n + col].abs().total_cmp(&g[s * n + col].abs()))
            .unwrap_or(col);
        if piv != col {
            for j in 0..n {
                g.swap(col * n + j, piv * n + j);
            }
            for j in 0..k {
                b.swap(col * k + j, piv * k + j);
            }
        }
        let d = g[col * n + col];
        for r in 0..n {
            if r == col {
                continue;
            }
            let f = g[r * n + col] / d;
            if f == 0.0 {
                continue;
            }
            for j in 0..n {
                g[r * n + j] -= f * g[col * n + j];
            }
            for j in 0..k {
                b[r * k + j] -= f * b[col * k + j];
            }
        }
    }
    for r in 0..n {
        let d = g[r * n + r];
        for j in 0..k {
            b[r * k + j] /= d;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Harmonic angles at the paper's 25 Hz and stroke frequency 0.16 Hz: the inputs from the
    /// differentiated angles equal the analytic ones to 1e-3 of each input's range (measured:
    /// 1.1e-4 at worst, a_y).
    #[test]
    fn measured_inputs_of_harmonic_angles_match_the_analytic_inputs() {
        use crate::kinematics::WingKinematics;
        use std::f64::consts::TAU;
        let (dt, w) = (0.04, TAU * 0.16);
        let state = |t: f64| EulerState {
            angles_rad: [
                1.1 * (w * t).sin(),
                0.2 * (2.0 * w * t).sin(),
                0.6 * (w * t).cos(),
            ],
            rates_rad_s: [
                1.1 * w * (w * t).cos(),
                0.4 * w * (2.0 * w * t).cos(),
                -0.6 * w * (w * t).sin(),
            ],
            accels_rad_s2: [
                -1.1 * w * w * (w * t).sin(),
                -0.8 * w * w * (2.0 * w * t).sin(),
                -0.6 * w * w * (w * t).cos(),
            ],
        };
        let states: Vec<EulerState> = (0..470).map(|i| state(i as f64 * dt)).collect();
        let angles: Vec<[f64; 3]> = states.iter().map(|s| s.angles_rad).collect();
        let cfg = SavitzkyGolayConfig::spanning_default(dt);
        assert_eq!((cfg.half_window, cfg.order), (6, 6));
        assert_eq!(
            SavitzkyGolayConfig::spanning_default(1.0 / 250.0),
            SavitzkyGolayConfig::default()
        );
        let got = measured_inputs(&angles, dt, cfg).unwrap();
        let exact: Vec<[f64; 7]> = states
            .iter()
            .map(|s| WingKinematics::from_euler(s).inputs())
            .collect();
        for k in 0..7 {
            let range = exact.iter().map(|u| u[k].abs()).fold(0.0, f64::max);
            let err = got
                .iter()
                .zip(&exact)
                .map(|(a, b)| (a[k] - b[k]).abs())
                .fold(0.0, f64::max);
            assert!(
                err <= 1e-3 * range,
                "input {k}: error {err} of range {range}"
            );
        }
        assert!(matches!(
            measured_inputs(&angles[..10], dt, cfg),
            Err(DifferentiateError::TooShort { .. })
        ));
    }

    #[test]
    fn polynomials_up_to_the_order_are_exact_everywhere() {
        // A degree-4 fit reproduces a quartic and its derivatives at every sample, edges included.
        let sg = SavitzkyGolay::new(SavitzkyGolayConfig {
            half_window: 6,
            order: 4,
        })
        .unwrap();
        let dt = 0.01;
        let f = |t: f64| 0.3 - 1.2 * t + 0.7 * t * t - 2.0 * t.powi(3) + 1.5 * t.powi(4);
        let d1 = |t: f64| -1.2 + 1.4 * t - 6.0 * t * t + 6.0 * t.powi(3);
        let d2 = |t: f64| 1.4 - 12.0 * t + 18.0 * t * t;
        let x: Vec<f64> = (0..40).map(|i| f(i as f64 * dt)).collect();
        let (mut v, mut r, mut a) = (vec![0.0; 40], vec![0.0; 40], vec![0.0; 40]);
        sg.apply(&x, dt, &mut v, &mut r, &mut a).unwrap();
        for i in 0..40 {
            let t = i as f64 * dt;
            assert!((v[i] - f(t)).abs() < 1e-12, "value {i}");
            assert!(
                (r[i] - d1(t)).abs() < 1e-9,
                "rate {i}: {} vs {}",
                r[i],
                d1(t)
            );
            assert!(
                (a[i] - d2(t)).abs() < 1e-6,
                "accel {i}: {} vs {}",
                a[i],
                d2(t)
            );
        }
    }

    #[test]
    fn interior_weights_are_symmetric_and_match_the_classic_table() {
        // Classic 5-point quadratic smoothing weights: (−3, 12, 17, 12, −3)/35.
        let sg = SavitzkyGolay::new(SavitzkyGolayConfig {
            half_window: 2,
            order: 2,
        })
        .unwrap();
        let classic = [-3.0, 12.0, 17.0, 12.0, -3.0].map(|w| w / 35.0);
        let centre = &sg.weights[2 * 5..3 * 5];
        for j in 0..5 {
            assert!((centre[j][0] - classic[j]).abs() < 1e-14);
            // Zero phase: value weights even, rate weights odd.
            assert!((centre[j][0] - centre[4 - j][0]).abs() < 1e-14);
            assert!((centre[j][1] + centre[4 - j][1]).abs() < 1e-14);
        }
        // First derivative: (−2, −1, 0, 1, 2)/10 per sample.
        for (j, w) in centre.iter().enumerate() {
            assert!((w[1] - (j as f64 - 2.0) / 10.0).abs() < 1e-14);
        }
    }

    #[test]
    fn bad_arguments_are_errors() {
        assert!(
            SavitzkyGolay::new(SavitzkyGolayConfig {
                half_window: 1,
                order: 3
            })
            .is_err()
        );
        assert!(
            SavitzkyGolay::new(SavitzkyGolayConfig {
                half_window: 5,
                order: 1
            })
            .is_err()
        );
        let sg = SavitzkyGolay::new(SavitzkyGolayConfig::default()).unwrap();
        let x = vec![0.0; 10];
        let mut o = vec![0.0; 10];
        let (mut o2, mut o3) = (o.clone(), o.clone());
        assert!(matches!(
            sg.apply(&x, 0.004, &mut o, &mut o2, &mut o3),
            Err(DifferentiateError::TooShort { .. })
        ));
        let x = vec![0.0; 300];
        assert!(matches!(
            sg.apply(&x, 0.004, &mut o, &mut o2, &mut o3),
            Err(DifferentiateError::LengthMismatch { .. })
        ));
        assert_eq!(quantize_to_encoder(0.0016, 4096), 2.0 * PI / 4096.0);
    }
}
