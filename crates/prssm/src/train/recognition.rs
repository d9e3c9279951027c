//! Recognition model for the initial latent state: a small map from the first `k` steps of
//! `(u, y)` of a window to a Gaussian `N(m₀, diag(s₀²))`.
//!
//! The input is the flattened window `z = [u_0, y_0, u_1, y_1, …, u_{k−1}, y_{k−1}]`
//! (length `d_z = k · (D_u + D_y)`, standardized units). With `H` hidden units:
//!
//! ```text
//! h  = tanh(W₁ z + b₁)                (H;  W₁: H × d_z)      — skipped when H = 0 (h = z)
//! m₀ = W_m h + b_m                    (D_x; W_m: D_x × H')
//! s₀ = softplus(W_s h + b_s) + s_min  (D_x; W_s: D_x × H')
//! ```
//!
//! `H' = H` (or `d_z` for the linear map, `H = 0`). Parameters are flat, row-major, in the
//! order `W₁, b₁, W_m, b_m, W_s, b_s`. [`Recognition::backward`] chains `∂L/∂m₀`, `∂L/∂s₀`
//! (from the engine) to the parameters exactly.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Lower bound `s_min` added to the recognized standard deviation.
pub const MIN_STD: f64 = 1e-6;

/// Architecture of the recognition model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RecognitionConfig {
    /// Number of leading steps `k` of `(u, y)` read (≥ 1; Doerr et al.: 16).
    pub steps: usize,
    /// Hidden units `H` (0 = linear map).
    pub hidden: usize,
    /// Initial `s₀` of every latent dimension (> `s_min`).
    pub init_std: f64,
}

impl Default for RecognitionConfig {
    /// 16 steps, 32 tanh units, `s₀ = 0.1` initially.
    fn default() -> Self {
        Self {
            steps: 16,
            hidden: 32,
            init_std: 0.1,
        }
    }
}

/// A recognition model of fixed dimensions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recognition {
    /// Architecture.
    pub config: RecognitionConfig,
    /// Input dimension `D_u`.
    pub d_u: usize,
    /// Output dimension `D_y`.
    pub d_y: usize,
    /// Latent dimension `D_x`.
    pub d_x: usize,
}

/// Per-window intermediate values of [`Recognition::forward`], needed by the backward pass.
#[derive(Debug, Clone, Default)]
pub struct RecognitionWorkspace {
    /// Hidden activations `h` (H).
    pub hidden: Vec<f64>,
    /// Pre-softplus `a_s = W_s h + b_s` (D_x).
    pub pre_std: Vec<f64>,
    /// Back-propagated `∂L/∂h` (H).
    pub grad_hidden: Vec<f64>,
}

fn softplus(a: f64) -> f64 {
    if a > 30.0 { a } else { a.exp().ln_1p() }
}

fn sigmoid(a: f64) -> f64 {
    1.0 / (1.0 + (-a).exp())
}

impl Recognition {
    /// Model for `d_u` inputs, `d_y` outputs and `d_x` latent states.
    pub fn new(config: RecognitionConfig, d_u: usize, d_y: usize, d_x: usize) -> Self {
        Self {
            config,
            d_u,
            d_y,
            d_x,
        }
    }

    /// Length of the flattened input window `d_z = k (D_u + D_y)`.
    pub fn input_len(&self) -> usize {
        self.config.steps * (self.d_u + self.d_y)
    }

    fn width(&self) -> usize {
        if self.config.hidden == 0 {
            self.input_len()
        } else {
            self.config.hidden
        }
    }

    fn n_first_layer(&self) -> usize {
        match self.config.hidden {
            0 => 0,
            h => h * (self.input_len() + 1),
        }
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.n_first_layer() + 2 * self.d_x * (self.width() + 1)
    }

    /// Workspace sized for this model.
    pub fn workspace(&self) -> RecognitionWorkspace {
        RecognitionWorkspace {
            hidden: vec![0.0; self.width()],
            pre_std: vec![0.0; self.d_x],
            grad_hidden: vec![0.0; self.width()],
        }
    }

    /// Initial parameters: `W₁ ~ N(0, 1/d_z)`, `W_m ~ N(0, 0.01²/H')`, `W_s = 0`,
    /// `b_s = softplus⁻¹(init_std − s_min)`, other biases 0.
    pub fn init_params(&self, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut p = vec![0.0; self.n_params()];
        let (dz, w, dx) = (self.input_len(), self.width(), self.d_x);
        let n1 = self.n_first_layer();
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        if self.config.hidden > 0 {
            let scale = 1.0 / (dz as f64).sqrt();
            for v in &mut p[..self.config.hidden * dz] {
                *v = scale * normal();
            }
        }
        let wm = n1;
        let scale = 0.01 / (w as f64).sqrt();
        for v in &mut p[wm..wm + dx * w] {
            *v = scale * normal();
        }
        let bs = n1 + 2 * dx * w + dx;
        let target = (self.config.init_std - MIN_STD).max(1e-12);
        let inv_softplus = if target > 30.0 {
            target
        } else {
            target.exp_m1().ln()
        };
        for v in &mut p[bs..bs + dx] {
            *v = inv_softplus;
        }
        p
    }

    /// Computes `m₀` and `s₀` (length D_x each) from the flattened window `z` (length `d_z`).
    /// Allocates nothing; `ws` keeps what [`Self::backward`] needs.
    pub fn forward(
        &self,
        params: &[f64],
        z: &[f64],
        ws: &mut RecognitionWorkspace,
        mean: &mut [f64],
        std: &mut [f64],
    ) {
        let (dz, w, dx) = (self.input_len(), self.width(), self.d_x);
        let h_units = self.config.hidden;
        let n1 = self.n_first_layer();
        if h_units == 0 {
            ws.hidden.copy_from_slice(&z[..dz]);
        } else {
            let (w1, b1) = params[..n1].split_at(h_units * dz);
            for j in 0..h_units {
                let row = &w1[j * dz..(j + 1) * dz];
                let a: f64 = b1[j] + row.iter().zip(z).map(|(a, b)| a * b).sum::<f64>();
                ws.hidden[j] = a.tanh();
            }
        }
        let rest = &params[n1..];
        let (wm, rest) = rest.split_at(dx * w);
        let (bm, rest) = rest.split_at(dx);
        let (ws_w, bs) = rest.split_at(dx * w);
        for i in 0..dx {
            let h = &ws.hidden;
            mean[i] = bm[i]
                + wm[i * w..(i + 1) * w]
                    .iter()
                    .zip(h)
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            let a = bs[i]
                + ws_w[i * w..(i + 1) * w]
                    .iter()
                    .zip(h)
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            ws.pre_std[i] = a;
            std[i] = softplus(a) + MIN_STD;
        }
    }

    /// Adds `∂L/∂params` to `grad` given `∂L/∂m₀` and `∂L/∂s₀` of the window `z` whose forward
    /// pass left `ws`. Allocates nothing.
    pub fn backward(
        &self,
        params: &[f64],
        z: &[f64],
        ws: &mut RecognitionWorkspace,
        grad_mean: &[f64],
        grad_std: &[f64],
        grad: &mut [f64],
    ) {
        let (dz, w, dx) = (self.input_len(), self.width(), self.d_x);
        let h_units = self.config.hidden;
        let n1 = self.n_first_layer();
        ws.grad_hidden.fill(0.0);
        {
            let grest = &mut grad[n1..];
            let (gwm, grest) = grest.split_at_mut(dx * w);
            let (gbm, grest) = grest.split_at_mut(dx);
            let (gws, gbs) = grest.split_at_mut(dx * w);
            let prest = &params[n1..];
            let wm = &prest[..dx * w];
            let wsw = &prest[dx * w + dx..2 * dx * w + dx];
            for i in 0..dx {
                let gm = grad_mean[i];
                let ga = grad_std[i] * sigmoid(ws.pre_std[i]);
                gbm[i] += gm;
                gbs[i] += ga;
                for k in 0..w {
                    let h = ws.hidden[k];
                    gwm[i * w + k] += gm * h;
                    gws[i * w + k] += ga * h;
                    ws.grad_hidden[k] += gm * wm[i * w + k] + ga * wsw[i * w + k];
                }
            }
        }
        if h_units > 0 {
            let (gw1, gb1) = grad[..n1].split_at_mut(h_units * dz);
            for j in 0..h_units {
                let h = ws.hidden[j];
                let ga = ws.grad_hidden[j] * (1.0 - h * h);
                gb1[j] += ga;
                for (g, &zk) in gw1[j * dz..(j + 1) * dz].iter_mut().zip(&z[..dz]) {
                    *g += ga * zk;
                }
            }
        }
    }

    /// Writes the flattened window `z = [u_t, y_t]_{t = start..start+k}` of a sequence with
    /// row-major inputs `u` (T × D_u) and outputs `y` (T × D_y) into `z` (length `d_z`).
    /// Returns `false` (leaving `z` untouched) when fewer than `k` steps follow `start`.
    pub fn gather(&self, u: &[f64], y: &[f64], start: usize, z: &mut [f64]) -> bool {
        let (du, dy, k) = (self.d_u, self.d_y, self.config.steps);
        let n_steps = u.len().checked_div(du).unwrap_or(y.len() / dy.max(1));
        if start + k > n_steps || (start + k) * dy > y.len() {
            return false;
        }
        for t in 0..k {
            let row = &mut z[t * (du + dy)..(t + 1) * (du + dy)];
            row[..du].copy_from_slice(&u[(start + t) * du..(start + t + 1) * du]);
            row[du..].copy_from_slice(&y[(start + t) * dy..(start + t + 1) * dy]);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L = Σ_i c_i m₀_i + d_i s₀_i², checked against central differences.
    fn fd_check(config: RecognitionConfig) {
        let rec = Recognition::new(config, 2, 1, 3);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut p = rec.init_params(3);
        for v in &mut p {
            *v += 0.3 * Distribution::<f64>::sample(&StandardNormal, &mut rng);
        }
        let z: Vec<f64> = (0..rec.input_len())
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        let c = [0.7, -1.3, 0.4];
        let d = [1.1, 0.5, -0.8];
        let mut ws = rec.workspace();
        let (mut m, mut s) = (vec![0.0; 3], vec![0.0; 3]);
        let mut loss = |p: &[f64], ws: &mut RecognitionWorkspace| {
            rec.forward(p, &z, ws, &mut m, &mut s);
            (0..3)
                .map(|i| c[i] * m[i] + d[i] * s[i] * s[i])
                .sum::<f64>()
        };
        loss(&p, &mut ws);
        let mut m0 = vec![0.0; 3];
        let mut s0 = vec![0.0; 3];
        rec.forward(&p, &z, &mut ws, &mut m0, &mut s0);
        let gs: Vec<f64> = (0..3).map(|i| 2.0 * d[i] * s0[i]).collect();
        let mut g = vec![0.0; rec.n_params()];
        rec.backward(&p, &z, &mut ws, &c, &gs, &mut g);
        let h = 1e-6;
        let mut ws2 = rec.workspace();
        for i in 0..p.len() {
            let mut pp = p.clone();
            pp[i] += h;
            let lp = loss(&pp, &mut ws2);
            pp[i] -= 2.0 * h;
            let lm = loss(&pp, &mut ws2);
            let fd = (lp - lm) / (2.0 * h);
            assert!(
                (fd - g[i]).abs() < 1e-7 * (1.0 + fd.abs()),
                "param {i}: fd {fd} vs exact {}",
                g[i]
            );
        }
    }

    #[test]
    fn mlp_gradient_matches_finite_differences() {
        fd_check(RecognitionConfig {
            steps: 3,
            hidden: 5,
            init_std: 0.2,
        });
    }

    #[test]
    fn linear_gradient_matches_finite_differences() {
        fd_check(RecognitionConfig {
            steps: 4,
            hidden: 0,
            init_std: 0.05,
        });
    }

    #[test]
    fn initial_std_and_gather_layout() {
        let rec = Recognition::new(
            RecognitionConfig {
                steps: 2,
                hidden: 4,
                init_std: 0.25,
            },
            1,
            2,
            3,
        );
        let p = rec.init_params(1);
        let mut ws = rec.workspace();
        let (mut m, mut s) = ([0.0; 3], [0.0; 3]);
        let u = [10.0, 11.0, 12.0];
        let y = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let mut z = [0.0; 6];
        assert!(rec.gather(&u, &y, 1, &mut z));
        assert_eq!(z, [11.0, 2.0, 3.0, 12.0, 4.0, 5.0]);
        assert!(!rec.gather(&u, &y, 2, &mut z));
        rec.forward(&p, &z, &mut ws, &mut m, &mut s);
        for v in s {
            assert!((v - 0.25).abs() < 1e-12);
        }
    }
}
