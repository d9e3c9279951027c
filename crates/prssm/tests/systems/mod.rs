//! Simulated nonlinear benchmark systems with known dynamics, for testing system
//! identification end to end (the engine's tests; not part of its API).
//!
//! [`Duffing`]: the forced Duffing oscillator
//!
//! ```text
//! ẍ + δ ẋ + α x + β x³ = γ u(t)
//! ```
//!
//! (dimensionless time and position). The input is held constant over each sample period
//! (zero-order hold) and the state integrated with classical RK4 sub-steps.

use flapssm_prssm::bench::random_input;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The forced Duffing oscillator `ẍ = γ u − δ ẋ − α x − β x³`; state `[x, ẋ]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Duffing {
    /// Linear stiffness α.
    pub alpha: f64,
    /// Cubic stiffness β (> 0: hardening).
    pub beta: f64,
    /// Damping δ.
    pub delta: f64,
    /// Input gain γ.
    pub gamma: f64,
}

impl Default for Duffing {
    /// A damped hardening oscillator: α = 1, β = 1, δ = 0.3, γ = 1.
    fn default() -> Self {
        Self {
            alpha: 1.0,
            beta: 1.0,
            delta: 0.3,
            gamma: 1.0,
        }
    }
}

impl Duffing {
    /// Time derivative `[ẋ, ẍ]` of `state = [x, ẋ]` under input `u`.
    pub fn derivative(&self, state: [f64; 2], u: f64) -> [f64; 2] {
        let [x, v] = state;
        [
            v,
            self.gamma * u - self.delta * v - self.alpha * x - self.beta * x * x * x,
        ]
    }

    /// Advances `state` by `dt` under constant input `u` with `substeps` RK4 steps.
    pub fn advance(&self, state: [f64; 2], u: f64, dt: f64, substeps: usize) -> [f64; 2] {
        let n = substeps.max(1);
        let h = dt / n as f64;
        let mut s = state;
        let add = |a: [f64; 2], k: [f64; 2], c: f64| [a[0] + c * k[0], a[1] + c * k[1]];
        for _ in 0..n {
            let k1 = self.derivative(s, u);
            let k2 = self.derivative(add(s, k1, h / 2.0), u);
            let k3 = self.derivative(add(s, k2, h / 2.0), u);
            let k4 = self.derivative(add(s, k3, h), u);
            s = [
                s[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
                s[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            ];
        }
        s
    }

    /// States at the sample times `t = 0, dt, …, (T−1) dt` from `x0` with input `u[t]` held
    /// over `[t dt, (t+1) dt)`; `T = u.len()`.
    pub fn simulate(&self, x0: [f64; 2], u: &[f64], dt: f64, substeps: usize) -> Vec<[f64; 2]> {
        let mut out = Vec::with_capacity(u.len());
        let mut s = x0;
        for &ut in u {
            out.push(s);
            s = self.advance(s, ut, dt, substeps);
        }
        out
    }
}

/// Input/output sequences of a simulated system (one input, one output per step).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedData {
    /// Inputs `u` per sequence (length T each).
    pub inputs: Vec<Vec<f64>>,
    /// Noisy observed outputs `y = x + ε`, `ε ~ N(0, noise_std²)`, per sequence.
    pub outputs: Vec<Vec<f64>>,
    /// Noise-free outputs `x` per sequence.
    pub clean: Vec<Vec<f64>>,
    /// Observation noise standard deviation.
    pub noise_std: f64,
    /// Sampling period.
    pub dt: f64,
}

/// `n_seq` sequences of `len` steps of the [`Duffing`] oscillator at `dt = 0.2` (10 RK4
/// sub-steps), each started at rest and driven by [`random_input`] (amplitude 1, hold 8);
/// the position is observed with noise `noise_std`. Everything derives from `seed`.
pub fn duffing_dataset(
    system: &Duffing,
    n_seq: usize,
    len: usize,
    noise_std: f64,
    seed: u64,
) -> SimulatedData {
    let dt = 0.2;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut data = SimulatedData {
        inputs: Vec::new(),
        outputs: Vec::new(),
        clean: Vec::new(),
        noise_std,
        dt,
    };
    for _ in 0..n_seq {
        let u = random_input(len, 1.0, 8, rng.random());
        let x: Vec<f64> = system
            .simulate([0.0, 0.0], &u, dt, 10)
            .iter()
            .map(|s| s[0])
            .collect();
        let y = x
            .iter()
            .map(|v| v + noise_std * rng.sample::<f64, _>(StandardNormal))
            .collect();
        data.inputs.push(u);
        data.outputs.push(y);
        data.clean.push(x);
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unforced_undamped_duffing_conserves_energy() {
        // H = ½ẋ² + ½αx² + ¼βx⁴ is invariant for δ = 0, u = 0.
        let sys = Duffing {
            delta: 0.0,
            ..Duffing::default()
        };
        let energy = |s: [f64; 2]| 0.5 * s[1] * s[1] + 0.5 * s[0] * s[0] + 0.25 * s[0].powi(4);
        let traj = sys.simulate([1.5, 0.0], &vec![0.0; 500], 0.1, 10);
        let e0 = energy(traj[0]);
        for s in &traj {
            assert!(
                (energy(*s) - e0).abs() < 1e-8 * e0,
                "{} vs {e0}",
                energy(*s)
            );
        }
    }

    #[test]
    fn linear_case_matches_the_analytic_damped_oscillation() {
        // β = 0: x(t) = e^{−δt/2} cos(ω_d t) + (δ/2ω_d) e^{−δt/2} sin(ω_d t), ω_d = √(α − δ²/4).
        let sys = Duffing {
            alpha: 4.0,
            beta: 0.0,
            delta: 0.4,
            gamma: 1.0,
        };
        let wd = (4.0f64 - 0.04).sqrt();
        let traj = sys.simulate([1.0, 0.0], &vec![0.0; 200], 0.05, 20);
        for (k, s) in traj.iter().enumerate() {
            let t = k as f64 * 0.05;
            let e = (-0.2 * t).exp();
            let x = e * ((wd * t).cos() + 0.2 / wd * (wd * t).sin());
            assert!((s[0] - x).abs() < 1e-9, "t = {t}: {} vs {x}", s[0]);
        }
    }

    #[test]
    fn dataset_is_seeded_and_noise_has_the_requested_level() {
        let sys = Duffing::default();
        let a = duffing_dataset(&sys, 3, 400, 0.1, 5);
        let b = duffing_dataset(&sys, 3, 400, 0.1, 5);
        assert_eq!(a, b);
        let (mut s2, mut n) = (0.0, 0.0);
        for (y, x) in a.outputs.iter().zip(&a.clean) {
            for (p, q) in y.iter().zip(x) {
                s2 += (p - q) * (p - q);
                n += 1.0;
            }
        }
        let std = (s2 / n).sqrt();
        assert!((std - 0.1).abs() < 0.01, "noise std {std}");
        let amp = a.clean[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(amp > 0.3 && amp < 5.0, "response amplitude {amp}");
    }
}
