//! Sensitivity of an open-loop prediction to its inputs: `∂J/∂u_t` for any scalar `J` of the
//! predicted output moments, by reverse mode through the particles with their draws held
//! fixed (the reparametrized simulation of [`crate::predict`]).
//!
//! The forward pass is [`crate::predict::predict`]'s simulation, with the same draws from the
//! same seed, on the sparse-GP conditional ([`ConditionalWorkspace`]):
//!
//! ```text
//! x_{t+1} = x_t + μ(x_t, u_t) + s_t ⊙ ε_t,   s_t = √(σ²(x_t, u_t) + σ_x² + δ)
//! m_t = (1/P) Σ_p x_{p,t}[..D_y],   v_t = (1/P) Σ_p (x_{p,t} − m_t)² + σ_y²
//! ```
//!
//! Given `m̄_t = ∂J/∂m_t` and `v̄_t = ∂J/∂v_t` (`T × D_y`), the reverse pass runs backwards in
//! time: `x̄_{p,t} += m̄_t/P + 2 v̄_t (x_{p,t} − m_t)/P`, then through each step with
//! `μ̄ = x̄_{t+1}`, `σ̄² = x̄_{t+1} ⊙ ε_t / (2 s_t)` into the conditional's adjoint of its
//! inputs `[x; u]` ([`ConditionalWorkspace::backward_all_inputs`]): the state rows carry on
//! to `x̄_t`, the input rows summed over particles give `ū_t`. Each step's conditional is
//! recomputed from the kept particles rather than taped, so memory is `O(T · P · D_x)` and a
//! gradient costs about two predictions. The result is the exact gradient of the
//! finite-particle prediction (a common-random-numbers estimate of the gradient of the
//! predictive moments), which is what an optimizer of that prediction needs.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::conditional::{ConditionalGrads, ConditionalWorkspace, Posterior};
use crate::model::{Normalization, PrssmModel};
use crate::objective::ObjectiveError;
use crate::params::{ModelConfig, Params};
use crate::predict::{Prediction, draw_initial, empty_prediction, moments, prediction_posterior};
use crate::step::StepDraws;

/// A predictor that also differentiates its prediction with respect to the inputs. Buffers
/// are sized on the first prediction and reused for sequences of the same length.
#[derive(Debug, Clone)]
pub struct InputSensitivity {
    config: ModelConfig,
    params: Params,
    normalization: Option<Normalization>,
    post: Posterior,
    ws: ConditionalWorkspace,
    grads: ConditionalGrads,
    particles: usize,
    /// Standardized inputs of the last prediction, `T × D_u`.
    inputs: Vec<f64>,
    /// Every particle, `T × P × D_x`.
    xs: Vec<f64>,
    /// The step draws, `(T − 1) × P × D_x`.
    eps: Vec<f64>,
    /// The last prediction in standardized units.
    pred: Option<Prediction>,
    xbar: Vec<f64>,
    xbar_all: Vec<f64>,
    mean_bar: Vec<f64>,
    var_bar: Vec<f64>,
}

/// The conditional at the particles `x` (`P × D_x`) and the standardized input of step `t`
/// of `inputs` (`T × D_u`) into the workspace's `mean`, `var`. Allocates nothing.
fn conditional_at(
    ws: &mut ConditionalWorkspace,
    post: &Posterior,
    x: &[f64],
    inputs: &[f64],
    t: usize,
) {
    let (dx, d) = (post.dx, post.d);
    let du = d - dx;
    let n = x.len() / dx;
    let u = &inputs[t * du..(t + 1) * du];
    for (col, xp) in ws.input[..d * n]
        .chunks_exact_mut(d)
        .zip(x.chunks_exact(dx))
    {
        col[..dx].copy_from_slice(xp);
        col[dx..].copy_from_slice(u);
    }
    ws.forward(post, n);
}

/// Buffer `v` resized to `n` values (a no-op when it already has them).
fn sized(v: &mut Vec<f64>, n: usize) -> &mut [f64] {
    v.resize(n, 0.0);
    &mut v[..n]
}

impl InputSensitivity {
    /// A sensitivity of the model in standardized units (inputs and outputs as in training).
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] for invalid settings or zero particles; a `K_mm` that does
    /// not factorize.
    pub fn new(
        config: &ModelConfig,
        params: &Params,
        particles: usize,
    ) -> Result<Self, ObjectiveError> {
        let post = prediction_posterior(config, params, particles)?;
        let mut ws = ConditionalWorkspace::new(&post, particles);
        ws.set_input_group(particles);
        Ok(Self {
            config: config.clone(),
            params: params.clone(),
            normalization: None,
            grads: ConditionalGrads::zeros(&post),
            post,
            ws,
            particles,
            inputs: Vec::new(),
            xs: Vec::new(),
            eps: Vec::new(),
            pred: None,
            xbar: vec![0.0; particles * config.n_state],
            xbar_all: vec![0.0; particles * config.n_gp_input()],
            mean_bar: vec![0.0; particles * config.n_state],
            var_bar: vec![0.0; particles * config.n_state],
        })
    }

    /// A sensitivity of `model` in its physical units: inputs and output moments as
    /// [`PrssmModel::predict_inputs`] takes and gives them, gradients per physical unit.
    ///
    /// # Errors
    /// As [`Self::new`], and an invalid model ([`PrssmModel::check`]).
    pub fn for_model(model: &PrssmModel, particles: usize) -> Result<Self, ObjectiveError> {
        model
            .check()
            .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
        let mut s = Self::new(&model.config, &model.params, particles)?;
        s.normalization = model.normalization.clone();
        Ok(s)
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.particles
    }

    /// Open-loop prediction from `N(init_mean, diag init_std²)` (standardized latent units)
    /// under `inputs` (row-major `T × D_u`, the model's units), with the draws of
    /// [`crate::predict::predict`] from `seed`: the same moments up to rounding. Output moments
    /// in the model's units; the particles are kept for [`Self::input_gradient`].
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] when the inputs are not `T × D_u` with `T ≥ 1` or the initial
    /// state has not `D_x` values.
    pub fn predict(
        &mut self,
        inputs: &[f64],
        (init_mean, init_std): (&[f64], &[f64]),
        seed: u64,
    ) -> Result<Prediction, ObjectiveError> {
        let (dx, du, dy) = (
            self.config.n_state,
            self.config.n_input,
            self.config.n_output,
        );
        if du == 0 || inputs.is_empty() || inputs.len() % du != 0 {
            return Err(ObjectiveError::Shape(format!(
                "{} input values are not a T × {du} array with T ≥ 1",
                inputs.len()
            )));
        }
        if init_mean.len() != dx || init_std.len() != dx {
            return Err(ObjectiveError::Shape(format!(
                "initial state must have {dx} means and {dx} stds"
            )));
        }
        let (t_n, np) = (inputs.len() / du, self.particles);
        let step = np * dx;
        let z = sized(&mut self.inputs, inputs.len());
        match &self.normalization {
            Some(n) => n.standardize_inputs_into(inputs, z),
            None => z.copy_from_slice(inputs),
        }
        let xs = sized(&mut self.xs, t_n * step);
        let eps = sized(&mut self.eps, (t_n - 1) * step);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        draw_initial(&mut rng, init_mean, init_std, &mut xs[..step]);
        let draws = StepDraws {
            dx,
            shared: self.config.shared_draws,
        };
        let (vx, vy) = (&self.params.process_noise_var, &self.params.obs_noise_var);
        let mut pred = empty_prediction(t_n, dx, dy);
        moments(&xs[..step], dx, dy, vx, vy, &mut pred, 0);
        for t in 0..t_n - 1 {
            draws.fill(&mut rng, &mut eps[t * step..(t + 1) * step]);
            let (done, next) = xs.split_at_mut((t + 1) * step);
            let cur = &done[t * step..];
            conditional_at(&mut self.ws, &self.post, cur, &self.inputs, t);
            let next = &mut next[..step];
            let e = &eps[t * step..(t + 1) * step];
            for i in 0..step {
                let sd = (self.ws.var[i] + vx[i % dx] + self.config.transition_jitter).sqrt();
                next[i] = cur[i] + self.ws.mean[i] + sd * e[i];
            }
            moments(next, dx, dy, vx, vy, &mut pred, t + 1);
        }
        let mut out = pred.clone();
        self.pred = Some(pred);
        if let Some(n) = &self.normalization {
            n.outputs_to_physical(&mut out.output_mean, &mut out.output_var);
        }
        Ok(out)
    }

    /// The outputs of every particle of the last [`Self::predict`], `T × P × D_y` row-major,
    /// in the model's units (without the observation noise `σ_y²` that the output variances
    /// include), into `out` (resized).
    pub fn particle_outputs_into(&self, out: &mut Vec<f64>) {
        let (dx, dy) = (self.config.n_state, self.config.n_output);
        let rows = self.xs.len() / dx.max(1);
        out.resize(rows * dy, 0.0);
        for (o, x) in out.chunks_exact_mut(dy).zip(self.xs.chunks_exact(dx)) {
            o.copy_from_slice(&x[..dy]);
            if let Some(n) = &self.normalization {
                for (k, v) in o.iter_mut().enumerate() {
                    *v = *v * n.output_std[k] + n.output_mean[k];
                }
            }
        }
    }

    /// The observation-noise variances `σ_y²` in the model's output units (`D_y`).
    pub fn observation_variance(&self) -> Vec<f64> {
        let s = self.normalization.as_ref().map(|n| &n.output_std);
        (0..self.config.n_output)
            .map(|k| self.params.obs_noise_var[k] * s.map_or(1.0, |s| s[k] * s[k]))
            .collect()
    }

    /// `∂J/∂u` (row-major `T × D_u`, into `input_grad`, per unit of the model's inputs) of a
    /// scalar `J` of the last [`Self::predict`]'s output moments, given `output_mean_grad =
    /// ∂J/∂(output means)` and `output_var_grad = ∂J/∂(output variances)` (each `T × D_y`,
    /// per unit of the model's outputs). The draws stay those of the prediction.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] before any prediction or on arrays of other shapes.
    pub fn input_gradient(
        &mut self,
        output_mean_grad: &[f64],
        output_var_grad: &[f64],
        input_grad: &mut [f64],
    ) -> Result<(), ObjectiveError> {
        let (dx, du, dy) = (
            self.config.n_state,
            self.config.n_input,
            self.config.n_output,
        );
        let Some(pred) = self.pred.take() else {
            return Err(ObjectiveError::Shape(
                "input_gradient needs a prediction first".into(),
            ));
        };
        let t_n = pred.output_mean.len() / dy.max(1);
        if output_mean_grad.len() != t_n * dy
            || output_var_grad.len() != t_n * dy
            || input_grad.len() != t_n * du
        {
            self.pred = Some(pred);
            return Err(ObjectiveError::Shape(format!(
                "gradients of the moments must be {t_n} × {dy} and of the inputs {t_n} × {du}"
            )));
        }
        let (np, d) = (self.particles, self.post.d);
        let (step, pf) = (np * dx, np as f64);
        let (ostd, istd) = match &self.normalization {
            Some(n) => (n.output_std.clone(), n.input_std.clone()),
            None => (vec![1.0; dy], vec![1.0; du]),
        };
        let vx = self.params.process_noise_var.clone();
        let jitter = self.config.transition_jitter;
        input_grad.fill(0.0);
        let mut xbar = std::mem::take(&mut self.xbar);
        xbar.fill(0.0);
        for t in (0..t_n).rev() {
            let x = &self.xs[t * step..(t + 1) * step];
            let m = &pred.latent_mean[t * dx..(t + 1) * dx];
            for (xb, xp) in xbar.chunks_exact_mut(dx).zip(x.chunks_exact(dx)) {
                for k in 0..dy {
                    let mb = output_mean_grad[t * dy + k] * ostd[k];
                    let vb = output_var_grad[t * dy + k] * ostd[k] * ostd[k];
                    xb[k] += (mb + 2.0 * vb * (xp[k] - m[k])) / pf;
                }
            }
            if t == 0 {
                break;
            }
            let prev = &self.xs[(t - 1) * step..t * step];
            conditional_at(&mut self.ws, &self.post, prev, &self.inputs, t - 1);
            let e = &self.eps[(t - 1) * step..t * step];
            for i in 0..step {
                let sd = (self.ws.var[i] + vx[i % dx] + jitter).sqrt();
                self.mean_bar[i] = xbar[i];
                self.var_bar[i] = xbar[i] * e[i] / (2.0 * sd);
            }
            self.xbar_all.fill(0.0);
            self.ws.backward_all_inputs(
                &self.post,
                np,
                &self.mean_bar,
                &self.var_bar,
                &mut self.grads,
                &mut self.xbar_all,
            );
            let ub = &mut input_grad[(t - 1) * du..t * du];
            for (xb, col) in xbar.chunks_exact_mut(dx).zip(self.xbar_all.chunks_exact(d)) {
                xb.iter_mut().zip(&col[..dx]).for_each(|(a, b)| *a += b);
                ub.iter_mut().zip(&col[dx..]).for_each(|(a, b)| *a += b);
            }
        }
        input_grad
            .chunks_exact_mut(du)
            .for_each(|row| row.iter_mut().zip(&istd).for_each(|(g, s)| *g /= s));
        self.xbar = xbar;
        self.pred = Some(pred);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::KernelKind;
    use crate::params::{CovarianceStructure, ParamInit, Parametrization};
    use crate::predict::predict;
    use rand::{Rng, SeedableRng};

    fn model(kernel: KernelKind, cov: CovarianceStructure, whitened: bool) -> PrssmModel {
        let (m, dx, dy, du) = (7, 4, 2, 3);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut config = ModelConfig::new(dx, dy, du, m);
        config.kernel = kernel;
        config.covariance = cov;
        config.kmm_jitter = 1e-6;
        config.transition_jitter = 1e-4;
        if whitened {
            config.parametrization = Parametrization::Whitened;
        }
        let mut p = Params::init(&config, &ParamInit::default(), 3);
        p.q_mean
            .iter_mut()
            .for_each(|v| *v = rng.random_range(-0.5..0.5));
        p.q_cov
            .iter_mut()
            .for_each(|v| *v = rng.random_range(0.05..0.3));
        if cov == CovarianceStructure::Full {
            for (idx, v) in p.q_cov.iter_mut().enumerate() {
                if idx % m < (idx / m) % m {
                    *v = 0.0;
                }
            }
        }
        p.lengthscales.iter_mut().for_each(|l| *l = 1.3);
        PrssmModel {
            config,
            params: p,
            normalization: Some(Normalization {
                input_mean: vec![0.3, -1.0, 2.0],
                input_std: vec![2.0, 0.5, 1.5],
                output_mean: vec![1.0, -2.0],
                output_std: vec![3.0, 0.7],
            }),
            training: serde_json::Value::Null,
        }
    }

    /// The forward pass is `predict`'s simulation: the same draws, the same moments.
    #[test]
    fn prediction_is_predicts() {
        let m = model(KernelKind::Matern32, CovarianceStructure::Diagonal, false);
        let t_n = 12;
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let u: Vec<f64> = (0..t_n * 3).map(|_| rng.random_range(-2.0..2.0)).collect();
        let (m0, s0) = (vec![0.1; 4], vec![0.2; 4]);
        let mut s = InputSensitivity::for_model(&m, 6).unwrap();
        let got = s.predict(&u, (&m0, &s0), 9).unwrap();
        let z = m.normalization.as_ref().unwrap().standardize_inputs(&u);
        let mut want = predict(&m.config, &m.params, &z, &m0, &s0, 6, 9).unwrap();
        let n = m.normalization.as_ref().unwrap();
        n.outputs_to_physical(&mut want.output_mean, &mut want.output_var);
        for (a, b) in got
            .output_mean
            .iter()
            .chain(&got.output_var)
            .zip(want.output_mean.iter().chain(&want.output_var))
        {
            assert!((a - b).abs() <= 1e-9 * (1.0 + b.abs()), "{a} vs {b}");
        }
    }

    /// `∂J/∂u` against central differences of the same prediction (same draws), for
    /// `J = Σ a ⊙ mean + b ⊙ var`, on both kernels, covariance structures and parametrizations.
    #[test]
    fn input_gradient_matches_central_differences() {
        let (t_n, du, dy) = (9, 3, 2);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let u: Vec<f64> = (0..t_n * du).map(|_| rng.random_range(-2.0..2.0)).collect();
        let a: Vec<f64> = (0..t_n * dy).map(|_| rng.random_range(-1.0..1.0)).collect();
        let b: Vec<f64> = (0..t_n * dy).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (m0, s0) = (vec![0.0; 4], vec![0.3; 4]);
        for kernel in [KernelKind::Matern32, KernelKind::SquaredExponential] {
            for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
                for whitened in [false, true] {
                    let m = model(kernel, cov, whitened);
                    let mut s = InputSensitivity::for_model(&m, 5).unwrap();
                    let j = |s: &mut InputSensitivity, u: &[f64]| {
                        let p = s.predict(u, (&m0, &s0), 3).unwrap();
                        let mean: f64 = p.output_mean.iter().zip(&a).map(|(x, w)| x * w).sum();
                        let var: f64 = p.output_var.iter().zip(&b).map(|(x, w)| x * w).sum();
                        mean + var
                    };
                    j(&mut s, &u);
                    let mut g = vec![0.0; t_n * du];
                    s.input_gradient(&a, &b, &mut g).unwrap();
                    let h = 1e-5;
                    let mut worst: f64 = 0.0;
                    let scale = g.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                    for i in 0..u.len() {
                        let mut up = u.clone();
                        up[i] += h;
                        let fp = j(&mut s, &up);
                        up[i] -= 2.0 * h;
                        let fm = j(&mut s, &up);
                        let fd = (fp - fm) / (2.0 * h);
                        worst = worst.max((fd - g[i]).abs() / scale);
                    }
                    assert!(
                        scale > 1e-3,
                        "{kernel:?} {cov:?} {whitened}: gradient vanishes"
                    );
                    assert!(worst < 1e-6, "{kernel:?} {cov:?} {whitened}: {worst:e}");
                    // The last step's input moves nothing.
                    assert!(g[(t_n - 1) * du..].iter().all(|v| *v == 0.0));
                }
            }
        }
    }

    #[test]
    fn gradient_before_prediction_or_of_other_shapes_is_refused() {
        let m = model(KernelKind::Matern32, CovarianceStructure::Diagonal, false);
        let mut s = InputSensitivity::for_model(&m, 4).unwrap();
        let mut g = vec![0.0; 6];
        assert!(s.input_gradient(&[0.0; 4], &[0.0; 4], &mut g).is_err());
        s.predict(&[0.0; 6], (&[0.0; 4], &[0.0; 4]), 1).unwrap();
        assert!(s.input_gradient(&[0.0; 3], &[0.0; 4], &mut g).is_err());
        assert!(s.input_gradient(&[0.0; 4], &[0.0; 4], &mut g).is_ok());
        assert!(s.predict(&[0.0; 5], (&[0.0; 4], &[0.0; 4]), 1).is_err());
    }
}
