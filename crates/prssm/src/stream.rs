//! Streaming prediction: one input sample in, the output's predictive mean and variance out,
//! with no allocation per step, in `f64` or `f32` (`StreamPredictor<f32>`: the particles, the
//! kernel, the products and the moments in single precision, for flight computers whose FPU
//! has no fast double precision; the factorization still done once in `f64`).
//!
//! At call `t` the predictor reports the moments of `y_t` from the particles `x_t`
//! (mean over particles; variance over particles divided by `P`, plus `σ_y²`, as
//! [`predict`](crate::predict::predict)) and then advances the particles with `u_t`:
//! `x_{t+1} = x_t + μ(x_t, u_t) + √(σ²(x_t, u_t) + σ_x² + δ_t) ⊙ ε_t`. Feeding `u_0, u_1, …`
//! reproduces the batch prediction exactly, draw for draw, for the same seed: both advance
//! the particles with [`ParticleStep`]; the initial draws `ε₀` (`P × D_x`) come first from
//! `ChaCha8Rng::seed_from_u64(seed)`, then one block of `P × D_x` per step (`f64` normals in
//! either precision). The difference of the `f32` stream from the `f64` one is measured by the
//! tests and `docs/c-api.md`.
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

use crate::model::PrssmModel;
use crate::objective::ObjectiveError;
use crate::step::{ParticleStep, StepFloat, rounded};

/// A particle predictor advanced one input sample at a time, in `T` (see the module docs).
#[derive(Debug, Clone)]
pub struct StreamPredictor<T: StepFloat = f64> {
    step: ParticleStep<T>,
    rng: ChaCha8Rng,
    /// Particles, `P × D_x` row-major (particle-major).
    x: Vec<T>,
    eps: Vec<f64>,
    u_z: Vec<T>,
    out_mean: Vec<T>,
    out_var: Vec<T>,
    obs_noise_var: Vec<T>,
    /// `(input mean, input std, output mean, output std)`.
    norm: Option<[Vec<T>; 4]>,
    dx: usize,
    dy: usize,
    du: usize,
    mean_only: bool,
    seed: u64,
    /// The initial state `N(init_mean, diag init_std²)`, for [`Self::reset`].
    init_mean: Vec<f64>,
    init_std: Vec<f64>,
}

impl<T: StepFloat> StreamPredictor<T> {
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
        let step = ParticleStep::new(&model.config, &model.params, particles)?;
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
        let step = ParticleStep::new(&model.config, &model.params, 1)?;
        let init = (init_mean.to_vec(), vec![0.0; dx]);
        Ok(Self::assemble(model, step, 1, 0, init, true))
    }

    fn assemble(
        model: &PrssmModel,
        step: ParticleStep<T>,
        particles: usize,
        seed: u64,
        (init_mean, init_std): (Vec<f64>, Vec<f64>),
        mean_only: bool,
    ) -> Self {
        let c = &model.config;
        let n = particles * c.n_state;
        let zero = T::of(0.0);
        let norm = model.normalization.as_ref().map(|n| {
            [
                rounded(&n.input_mean),
                rounded(&n.input_std),
                rounded(&n.output_mean),
                rounded(&n.output_std),
            ]
        });
        let mut stream = Self {
            step,
            rng: ChaCha8Rng::seed_from_u64(seed),
            eps: vec![0.0; n],
            x: vec![zero; n],
            u_z: vec![zero; c.n_input],
            out_mean: vec![zero; c.n_output],
            out_var: vec![zero; c.n_output],
            obs_noise_var: rounded(&model.params.obs_noise_var),
            norm,
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
                *x = T::of(m + s * e);
            }
        }
    }

    /// Current particles, `P × D_x` row-major (standardized latent units).
    pub fn particles(&self) -> &[T] {
        &self.x
    }

    /// Reports the moments of `y_t` (mean and variance, `D_y` each) and advances the
    /// particles with the input `u_t` (`D_u`). Allocates nothing.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] when `u` does not have `D_u` values;
    /// [`ObjectiveError::NonFinite`] for a non-finite input.
    pub fn step(&mut self, u: &[T]) -> Result<(&[T], &[T]), ObjectiveError> {
        if u.len() != self.du {
            return Err(ObjectiveError::Shape(format!(
                "input has {} values, expected {}",
                u.len(),
                self.du
            )));
        }
        if u.iter().any(|v| !v.to_f64().is_finite()) {
            return Err(ObjectiveError::NonFinite { what: "input" });
        }
        self.moments();
        match &self.norm {
            Some([im, is, _, _]) => {
                for (i, (z, &v)) in self.u_z.iter_mut().zip(u).enumerate() {
                    *z = (v - im[i]) / is[i];
                }
            }
            None => self.u_z.copy_from_slice(u),
        }
        if !self.mean_only {
            self.step.draw(&mut self.rng, &mut self.eps);
        }
        self.step.step(&mut self.x, &self.u_z, &self.eps);
        Ok((&self.out_mean, &self.out_var))
    }

    /// Particle mean and variance (divided by `P`) of the outputs, plus `σ_y²`, in the
    /// model's output units: means `m · std + mean`, variances `v · std²`.
    fn moments(&mut self) {
        let (dx, dy) = (self.dx, self.dy);
        let p = T::of((self.x.len() / dx) as f64);
        for dd in 0..dy {
            let mean = self.x.chunks_exact(dx).map(|c| c[dd]).sum::<T>() / p;
            let var = self
                .x
                .chunks_exact(dx)
                .map(|c| (c[dd] - mean) * (c[dd] - mean))
                .sum::<T>()
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
}
