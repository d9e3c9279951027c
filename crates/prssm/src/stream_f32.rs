//! Single-precision streaming prediction, for flight computers whose FPU has no (fast) double
//! precision: the particles, the kernel, the products and the moments in `f32`; the model's
//! factorization (`K_mm`, `G = (K_mm + jitter·I)⁻¹` or `L⁻¹`, `mᵀG`) done once in `f64` by
//! [`Posterior::new`](crate::conditional::Posterior::new) and rounded.
//!
//! The step is [`crate::stream::StreamPredictor`]'s with the same draws (the `f64` standard
//! normals of the same seed, rounded): per particle `c`, `z = [x_c; u] / ℓ`,
//! `k_m = σ_f² g(‖z − z̃_m‖²)`, `[w; μ] = [G; mᵀG] k`,
//! `σ²_d = σ_f² − wᵀh + Σ_m S_{md} w_m²` (diagonal `S`; `‖L_dᵀw‖²` for full `S`), then
//! `x_c += μ + √(max(σ², 0) + σ_x² + δ) ⊙ ε` (the `max` guards the cancellation of `f32`).
//! The product `[G; mᵀG] K` of all particles at once by faer's `f32` GEMM; the other loops run
//! over contiguous rows with independent accumulator lanes and a branch-free `exp`, so that
//! the compiler vectorizes them; no allocation per step.
//! The difference from the `f64` stream is measured by the tests and `docs/c-api.md`.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::kernel::{KernelKind, exp_f32 as exp};
use crate::model::PrssmModel;
use crate::objective::ObjectiveError;
use crate::params::CovarianceStructure;
use crate::predict::{StepDraws, prediction_posterior};

/// A streaming predictor in single precision (see the module docs).
#[derive(Debug, Clone)]
pub struct StreamPredictorF32 {
    kind: KernelKind,
    variance: f32,
    tau_jitter: f32,
    m: usize,
    d: usize,
    dx: usize,
    du: usize,
    dy: usize,
    /// `1/ℓ` (`D`).
    inv_len: Vec<f32>,
    /// Scaled inducing inputs, dimension-major `D·M`.
    zt: Vec<f32>,
    /// `[G; mᵀG]` column-major `(M + D_x) × M`.
    g_mean: Vec<f32>,
    /// Diagonal `S`: row-major `D_x × M` (the diagonal of `S_d` in row `d`); full: `D_x`
    /// column-major `M × M` factors `L_d`.
    q_cov: Vec<f32>,
    full: bool,
    whitened: bool,
    /// `σ_x² + δ` (`D_x`).
    step_var: Vec<f32>,
    obs_noise_var: Vec<f32>,
    /// `(input mean, input std, output mean, output std)`.
    norm: Option<[Vec<f32>; 4]>,
    draws: StepDraws,
    seed: u64,
    rng: ChaCha8Rng,
    /// Particles, `P × D_x` row-major.
    x: Vec<f32>,
    eps: Vec<f64>,
    z: Vec<f32>,
    k: Vec<f32>,
    wm: Vec<f32>,
    w2: Vec<f32>,
    lw: Vec<f32>,
    u_z: Vec<f32>,
    out_mean: Vec<f32>,
    out_var: Vec<f32>,
}

fn round(v: &[f64]) -> Vec<f32> {
    v.iter().map(|&x| x as f32).collect()
}

impl StreamPredictorF32 {
    /// A predictor with `particles` particles started from `x₀ = 0`, draws seeded by `seed`
    /// (the same draws as [`crate::stream::StreamPredictor::new`] with zero initial state).
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] for zero particles or invalid parameters; a `K_mm` that does
    /// not factorize.
    pub fn new(model: &PrssmModel, particles: usize, seed: u64) -> Result<Self, ObjectiveError> {
        let (config, params) = (&model.config, &model.params);
        let post = prediction_posterior(config, params, particles)?;
        let (m, d, dx) = (post.m, post.d, post.dx);
        let r = m + dx;
        let full = post.cov == CovarianceStructure::Full;
        let q_cov = if full {
            round(&post.q_cov)
        } else {
            let mut t = vec![0.0f32; dx * m];
            for i in 0..m {
                for dd in 0..dx {
                    t[dd * m + i] = post.q_cov[i * dx + dd] as f32;
                }
            }
            t
        };
        let step_var = params
            .process_noise_var
            .iter()
            .map(|v| (v + config.transition_jitter) as f32)
            .collect();
        let norm = model.normalization.as_ref().map(|n| {
            [
                round(&n.input_mean),
                round(&n.input_std),
                round(&n.output_mean),
                round(&n.output_std),
            ]
        });
        let mut stream = Self {
            kind: post.kind,
            variance: post.variance as f32,
            tau_jitter: post.tau_jitter as f32,
            m,
            d,
            dx,
            du: config.n_input,
            dy: config.n_output,
            inv_len: round(&post.inv_len),
            zt: round(&post.zt),
            g_mean: round(&post.g_mean),
            q_cov,
            full,
            whitened: post.whitened,
            step_var,
            obs_noise_var: round(&params.obs_noise_var),
            norm,
            draws: StepDraws {
                dx,
                shared: config.shared_draws,
            },
            seed,
            rng: ChaCha8Rng::seed_from_u64(seed),
            x: vec![0.0; particles * dx],
            eps: vec![0.0; particles * dx],
            z: vec![0.0; d],
            k: vec![0.0; m * particles],
            wm: vec![0.0; r * particles],
            w2: vec![0.0; m],
            lw: vec![0.0; m],
            u_z: vec![0.0; config.n_input],
            out_mean: vec![0.0; config.n_output],
            out_var: vec![0.0; config.n_output],
        };
        stream.reset();
        Ok(stream)
    }

    /// Starts again from `x₀ = 0` with the seed's first draws. Allocates nothing.
    pub fn reset(&mut self) {
        self.rng = ChaCha8Rng::seed_from_u64(self.seed);
        // The initial state N(0, 0): the draws are consumed as in the f64 stream.
        for x in self.x.iter_mut() {
            let _: f64 = StandardNormal.sample(&mut self.rng);
            *x = 0.0;
        }
    }

    /// Reports the moments of `y_t` (mean, variance; `D_y` each) and advances the particles
    /// with `u_t` (`D_u` values, the model's units). Allocates nothing.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] for a wrong count; [`ObjectiveError::NonFinite`] for a
    /// non-finite input.
    pub fn step(&mut self, u: &[f32]) -> Result<(&[f32], &[f32]), ObjectiveError> {
        if u.len() != self.du {
            return Err(ObjectiveError::Shape(format!(
                "input has {} values, expected {}",
                u.len(),
                self.du
            )));
        }
        if u.iter().any(|v| !v.is_finite()) {
            return Err(ObjectiveError::NonFinite { what: "input" });
        }
        self.moments();
        match &self.norm {
            Some([im, is, _, _]) => {
                for (i, (z, v)) in self.u_z.iter_mut().zip(u).enumerate() {
                    *z = (v - im[i]) / is[i];
                }
            }
            None => self.u_z.copy_from_slice(u),
        }
        self.draws.fill(&mut self.rng, &mut self.eps);
        let (m, r, p) = (self.m, self.m + self.dx, self.x.len() / self.dx);
        for c in 0..p {
            self.kernel(c);
        }
        matmul(
            MatMut::from_column_major_slice_mut(&mut self.wm, r, p),
            Accum::Replace,
            MatRef::from_column_major_slice(&self.g_mean, r, m),
            MatRef::from_column_major_slice(&self.k, m, p),
            1.0f32,
            Par::Seq,
        );
        for c in 0..p {
            self.advance(c);
        }
        Ok((&self.out_mean, &self.out_var))
    }

    /// Particle mean and variance (divided by `P`) of the outputs, plus `σ_y²`, in the
    /// model's output units.
    fn moments(&mut self) {
        let (dx, dy) = (self.dx, self.dy);
        let p = (self.x.len() / dx) as f32;
        for dd in 0..dy {
            let mean = self.x.chunks_exact(dx).map(|c| c[dd]).sum::<f32>() / p;
            let var = self
                .x
                .chunks_exact(dx)
                .map(|c| (c[dd] - mean) * (c[dd] - mean))
                .sum::<f32>()
                / p;
            self.out_mean[dd] = mean;
            self.out_var[dd] = var + self.obs_noise_var[dd];
        }
        if let Some([_, _, om, os]) = &self.norm {
            for dd in 0..dy {
                self.out_mean[dd] = self.out_mean[dd] * os[dd] + om[dd];
                self.out_var[dd] *= os[dd] * os[dd];
            }
        }
    }

    /// Column `c` of `K` (`M × P`): the kernel between particle `c`'s `[x; u]` and the
    /// inducing inputs.
    fn kernel(&mut self, c: usize) {
        let (m, d, dx) = (self.m, self.d, self.dx);
        let x = &self.x[c * dx..(c + 1) * dx];
        for (j, z) in self.z.iter_mut().enumerate() {
            let v = if j < dx { x[j] } else { self.u_z[j - dx] };
            *z = v * self.inv_len[j];
        }
        let k = &mut self.k[c * m..(c + 1) * m];
        k.fill(0.0);
        for j in 0..d {
            let zj = self.z[j];
            for (k, &t) in k.iter_mut().zip(&self.zt[j * m..(j + 1) * m]) {
                *k += (t - zj) * (t - zj);
            }
        }
        let (var_f, jit) = (self.variance, self.tau_jitter);
        match self.kind {
            KernelKind::Matern32 => k.iter_mut().for_each(|k| {
                let r = (3.0 * (*k + jit)).sqrt();
                *k = var_f * (1.0 + r) * exp(-r);
            }),
            KernelKind::SquaredExponential => {
                k.iter_mut().for_each(|k| *k = var_f * exp(-0.5 * *k))
            }
        }
    }

    /// Advances particle `c` from column `c` of `[W; μ]` (see the module docs).
    fn advance(&mut self, c: usize) {
        let (m, dx) = (self.m, self.dx);
        let r = m + dx;
        let x = &mut self.x[c * dx..(c + 1) * dx];
        let (w, mu) = self.wm[c * r..(c + 1) * r].split_at(m);
        let h = if self.whitened {
            w
        } else {
            &self.k[c * m..(c + 1) * m]
        };
        let base = self.variance - dot(w, h);
        if !self.full {
            self.w2.iter_mut().zip(w).for_each(|(a, &b)| *a = b * b);
        }
        let eps = &self.eps[c * dx..(c + 1) * dx];
        for dd in 0..dx {
            let quad = if self.full {
                let ld = &self.q_cov[dd * m * m..(dd + 1) * m * m];
                for (i, l) in self.lw.iter_mut().enumerate() {
                    *l = dot(&ld[i * m..(i + 1) * m], w);
                }
                dot(&self.lw, &self.lw)
            } else {
                dot(&self.q_cov[dd * m..(dd + 1) * m], &self.w2)
            };
            let var = (base + quad).max(0.0);
            x[dd] += mu[dd] + (var + self.step_var[dd]).sqrt() * eps[dd] as f32;
        }
    }
}

/// `Σ aᵢbᵢ` in 16 independent lanes (vectorizable; the lanes are summed at the end).
#[inline(always)]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    const L: usize = 16;
    let mut acc = [0.0f32; L];
    let (ac, bc) = (a.chunks_exact(L), b.chunks_exact(L));
    let tail: f32 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for l in 0..L {
            acc[l] += x[l] * y[l];
        }
    }
    acc.iter().sum::<f32>() + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_equals_the_plain_sum() {
        let a: Vec<f32> = (0..37).map(|i| (i as f32 * 0.37).sin()).collect();
        let b: Vec<f32> = (0..37).map(|i| (i as f32 * 0.11).cos()).collect();
        let plain: f64 = a
            .iter()
            .zip(&b)
            .map(|(x, y)| f64::from(*x) * f64::from(*y))
            .sum();
        assert!((f64::from(dot(&a, &b)) - plain).abs() < 1e-5);
    }
}
