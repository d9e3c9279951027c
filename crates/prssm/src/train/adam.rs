//! Adam (Kingma & Ba 2015) with bias correction.
//!
//! For gradient `g_t` at step `t = 1, 2, …` and learning rate `η_t`:
//!
//! ```text
//! m_t = β₁ m_{t−1} + (1 − β₁) g_t          v_t = β₂ v_{t−1} + (1 − β₂) g_t²
//! m̂_t = m_t / (1 − β₁ᵗ)                    v̂_t = v_t / (1 − β₂ᵗ)
//! θ_t = θ_{t−1} − η_t m̂_t / (√v̂_t + ε)
//! ```
//!
//! The state (`m`, `v`, `t`) is plain data so that checkpoints restore it exactly.

use serde::{Deserialize, Serialize};

/// Adam hyper-parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AdamParams {
    /// First-moment decay β₁ in [0, 1).
    pub beta1: f64,
    /// Second-moment decay β₂ in [0, 1).
    pub beta2: f64,
    /// Denominator offset ε > 0.
    pub eps: f64,
}

impl Default for AdamParams {
    /// β₁ = 0.9, β₂ = 0.999, ε = 1e-8 (the TensorFlow and PyTorch defaults).
    fn default() -> Self {
        Self {
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
        }
    }
}

/// Adam optimizer state for `n` parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Adam {
    /// Hyper-parameters.
    pub params: AdamParams,
    /// First moments `m` (length n).
    pub m: Vec<f64>,
    /// Second moments `v` (length n).
    pub v: Vec<f64>,
    /// Number of steps taken `t`.
    pub t: u64,
}

impl Adam {
    /// Fresh state (`m = v = 0`, `t = 0`) for `n` parameters.
    pub fn new(n: usize, params: AdamParams) -> Self {
        Self {
            params,
            m: vec![0.0; n],
            v: vec![0.0; n],
            t: 0,
        }
    }

    /// Applies one step in place: `theta ← theta − lr · m̂ / (√v̂ + ε)`. Allocates nothing.
    ///
    /// `theta` and `grad` must have the state's length (checked by the trainer once).
    pub fn step(&mut self, theta: &mut [f64], grad: &[f64], lr: f64) {
        debug_assert_eq!(theta.len(), self.m.len());
        debug_assert_eq!(grad.len(), self.m.len());
        let AdamParams { beta1, beta2, eps } = self.params;
        self.t += 1;
        let t = self.t as i32;
        let c1 = 1.0 - beta1.powi(t);
        let c2 = 1.0 - beta2.powi(t);
        for (((th, &g), m), v) in theta
            .iter_mut()
            .zip(grad)
            .zip(self.m.iter_mut())
            .zip(self.v.iter_mut())
        {
            *m = beta1 * *m + (1.0 - beta1) * g;
            *v = beta2 * *v + (1.0 - beta2) * g * g;
            *th -= lr * (*m / c1) / ((*v / c2).sqrt() + eps);
        }
    }

    /// Copies another state of the same size into `self` without allocating.
    pub fn copy_from(&mut self, other: &Adam) {
        self.params = other.params;
        self.m.copy_from_slice(&other.m);
        self.v.copy_from_slice(&other.v);
        self.t = other.t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_step_moves_by_lr_times_sign() {
        // m̂₁ = g, v̂₁ = g² ⇒ Δθ = −η g / (|g| + ε).
        let mut adam = Adam::new(3, AdamParams::default());
        let mut theta = [1.0, -2.0, 0.5];
        adam.step(&mut theta, &[3.0, -0.25, 1e-3], 0.1);
        let g = [3.0, -0.25, 1e-3];
        let expect: Vec<f64> = [1.0, -2.0, 0.5]
            .iter()
            .zip(g)
            .map(|(t, g): (&f64, f64)| t - 0.1 * g / (g.abs() + 1e-8))
            .collect();
        for (a, b) in theta.iter().zip(expect) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
    }

    #[test]
    fn two_steps_match_hand_computation() {
        let p = AdamParams {
            beta1: 0.5,
            beta2: 0.75,
            eps: 0.0,
        };
        let mut adam = Adam::new(1, p);
        let mut theta = [0.0];
        adam.step(&mut theta, &[2.0], 1.0);
        adam.step(&mut theta, &[-1.0], 1.0);
        // t=2: m = 0.5·(0.5·2) + 0.5·(−1) = 0, so the second step does not move θ.
        assert!((theta[0] + 1.0).abs() < 1e-15);
        // v = 0.75·0.25·4 + 0.25·1 = 1.0 ⇒ v̂ = 1/(1−0.5625).
        assert!((adam.v[0] - 1.0).abs() < 1e-15);
        assert_eq!(adam.t, 2);
    }

    #[test]
    fn minimizes_an_ill_conditioned_quadratic() {
        // f(θ) = ½ Σ a_i (θ_i − c_i)², minimum at c.
        let a = [1.0, 100.0, 0.01];
        let c = [1.0, -2.0, 3.0];
        let mut adam = Adam::new(3, AdamParams::default());
        let mut theta = [0.0; 3];
        let mut g = [0.0; 3];
        for t in 0..5000 {
            for i in 0..3 {
                g[i] = a[i] * (theta[i] - c[i]);
            }
            let lr = 0.05 * 0.999f64.powi(t);
            adam.step(&mut theta, &g, lr);
        }
        for i in 0..3 {
            assert!((theta[i] - c[i]).abs() < 1e-3, "θ{i} = {}", theta[i]);
        }
    }
}
