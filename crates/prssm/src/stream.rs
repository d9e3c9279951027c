//! Streaming prediction: one input sample in, the output's predictive mean and variance out,
//! with no allocation per step.
//!
//! At call `t` the predictor reports the moments of `y_t` from the particles `x_t`
//! (mean over particles; variance over particles divided by `P`, plus `σ_y²`, as
//! [`predict`](crate::predict::predict)) and then advances the particles with `u_t`:
//! `x_{t+1} = x_t + μ(x_t, u_t) + √(σ²(x_t, u_t) + σ_x² + δ_t) ⊙ ε_t`. Feeding `u_0, u_1, …`
//! reproduces the batch prediction exactly, draw for draw, for the same seed: the initial
//! draws `ε₀` (`P × D_x`) come first from `ChaCha8Rng::seed_from_u64(seed)`, then one block of
//! `P × D_x` per step.
//!
//! Units: with a model normalization, inputs and outputs are raw (physical) units; the
//! initial state `N(m₀, diag s₀²)` is in the model's standardized latent units.
//!
//! ```
//! use flapssm_prssm::params::{ModelConfig, ParamInit, Params};
//! use flapssm_prssm::stream::StreamPredictor;
//! use flapssm_prssm::PrssmModel;
//!
//! let config = ModelConfig::new(4, 1, 1, 10);
//! let params = Params::init(&config, &ParamInit::default(), 1);
//! let model = PrssmModel { config, params, normalization: None, training: serde_json::Value::Null };
//! let mut stream = StreamPredictor::new(&model, 30, &[0.0; 4], &[0.0; 4], 7).unwrap();
//! for t in 0..100 {
//!     let u = [(0.1 * t as f64).sin()];
//!     let (mean, var) = stream.step(&u).unwrap();
//!     assert!(mean[0].is_finite() && var[0] > 0.0);
//! }
//! ```

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::model::{Normalization, PrssmModel};
use crate::objective::ObjectiveError;
use crate::precision::Precision;
use crate::predict::StepPredictor;

/// A particle predictor advanced one input sample at a time (see the module docs).
#[derive(Debug, Clone)]
pub struct StreamPredictor {
    step: StepPredictor,
    rng: ChaCha8Rng,
    /// Particles, `P × D_x` row-major (particle-major).
    x: Vec<f64>,
    eps: Vec<f64>,
    u_z: Vec<f64>,
    out_mean: Vec<f64>,
    out_var: Vec<f64>,
    obs_noise_var: Vec<f64>,
    norm: Option<Normalization>,
    dx: usize,
    dy: usize,
    du: usize,
    mean_only: bool,
    seed: u64,
    /// The initial state `N(init_mean, diag init_std²)`, for [`Self::reset`].
    init_mean: Vec<f64>,
    init_std: Vec<f64>,
}

impl StreamPredictor {
    /// A predictor with `particles` particles started from `N(init_mean, diag init_std²)`
    /// (`D_x` each, standardized latent units), draws seeded by `seed`.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] for wrong lengths or zero particles; factorization errors.
    pub fn new(
        model: &PrssmModel,
        particles: usize,
        init_mean: &[f64],
        init_std: &[f64],
        seed: u64,
    ) -> Result<Self, ObjectiveError> {
        let dx = model.config.n_state;
        if init_mean.len() != dx || init_std.len() != dx {
            return Err(ObjectiveError::Shape(format!(
                "initial state: {} means and {} stds, expected {dx} each",
                init_mean.len(),
                init_std.len()
            )));
        }
        let step = StepPredictor::new(&model.config, &model.params, particles)?;
        let init = (init_mean.to_vec(), init_std.to_vec());
        Ok(Self::assemble(model, step, particles, seed, init, false))
    }

    /// A single trajectory propagated without noise from `init_mean` (`ε = 0`, one particle):
    /// the cheapest predictor; its variance is `σ_y²` only (no uncertainty propagation).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn mean_propagated(model: &PrssmModel, init_mean: &[f64]) -> Result<Self, ObjectiveError> {
        let dx = model.config.n_state;
        if init_mean.len() != dx {
            return Err(ObjectiveError::Shape(format!(
                "initial state: {} means, expected {dx}",
                init_mean.len()
            )));
        }
        let step = StepPredictor::new(&model.config, &model.params, 1)?;
        let init = (init_mean.to_vec(), vec![0.0; dx]);
        Ok(Self::assemble(model, step, 1, 0, init, true))
    }

    /// This predictor with its conditional's large products in `precision`
    /// ([`StepPredictor::with_precision`]); the draws are unchanged.
    pub fn with_precision(mut self, precision: Precision) -> Self {
        self.step = self.step.with_precision(precision);
        self
    }

    fn assemble(
        model: &PrssmModel,
        step: StepPredictor,
        particles: usize,
        seed: u64,
        (init_mean, init_std): (Vec<f64>, Vec<f64>),
        mean_only: bool,
    ) -> Self {
        let c = &model.config;
        let n = particles * c.n_state;
        let mut stream = Self {
            step,
            rng: ChaCha8Rng::seed_from_u64(seed),
            eps: vec![0.0; n],
            x: vec![0.0; n],
            u_z: vec![0.0; c.n_input],
            out_mean: vec![0.0; c.n_output],
            out_var: vec![0.0; c.n_output],
            obs_noise_var: model.params.obs_noise_var.clone(),
            norm: model.normalization.clone(),
            dx: c.n_state,
            dy: c.n_output,
            du: c.n_input,
            mean_only,
            seed,
            init_mean,
            init_std,
        };
        stream.reset();
        stream
    }

    /// Starts again from the initial state with the first draws of the seed: the next
    /// [`Self::step`]s repeat those since creation exactly. Allocates nothing.
    pub fn reset(&mut self) {
        self.rng = ChaCha8Rng::seed_from_u64(self.seed);
        for c in self.x.chunks_exact_mut(self.dx) {
            for ((x, &m), &s) in c.iter_mut().zip(&self.init_mean).zip(&self.init_std) {
                let e: f64 = if self.mean_only {
                    0.0
                } else {
                    StandardNormal.sample(&mut self.rng)
                };
                *x = m + s * e;
            }
        }
    }

    /// Current particles, `P × D_x` row-major (standardized latent units).
    pub fn particles(&self) -> &[f64] {
        &self.x
    }

    /// Reports the moments of `y_t` (mean and variance, `D_y` each) and advances the
    /// particles with the input `u_t` (`D_u`). Allocates nothing.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] when `u` does not have `D_u` values;
    /// [`ObjectiveError::NonFinite`] for a non-finite input.
    pub fn step(&mut self, u: &[f64]) -> Result<(&[f64], &[f64]), ObjectiveError> {
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
        let (dx, dy) = (self.dx, self.dy);
        let p = (self.x.len() / dx) as f64;
        for dd in 0..dy {
            let mean = self.x.chunks_exact(dx).map(|c| c[dd]).sum::<f64>() / p;
            let var = self
                .x
                .chunks_exact(dx)
                .map(|c| (c[dd] - mean).powi(2))
                .sum::<f64>()
                / p;
            self.out_mean[dd] = mean;
            self.out_var[dd] = var + self.obs_noise_var[dd];
        }
        match &self.norm {
            Some(n) => {
                n.standardize_inputs_into(u, &mut self.u_z);
                n.outputs_to_physical(&mut self.out_mean, &mut self.out_var);
            }
            None => self.u_z.copy_from_slice(u),
        }
        if !self.mean_only {
            self.step.draw(&mut self.rng, &mut self.eps);
        }
        self.step.step(&mut self.x, &self.u_z, &self.eps);
        Ok((&self.out_mean, &self.out_var))
    }
}
