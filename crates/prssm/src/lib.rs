//! # flapssm-prssm — a generic PR-SSM engine
//!
//! Probabilistic recurrent state-space model (Doerr et al., ICML 2018):
//!
//! ```text
//! x_{t+1} = x_t + f(x_t, u_t) + ω_t,   ω_t ~ N(0, diag(σ_x²))
//! y_t     = C x_t + ε_t,               C = [I 0],  ε_t ~ N(0, diag(σ_y²))
//! ```
//!
//! with `f` one sparse GP per latent dimension sharing the inducing inputs `Z`, trained by
//! maximizing a particle-sampled ELBO with exact reverse-mode gradients. The engine knows
//! nothing about wings: `D_u` inputs, `D_y` outputs, `D_x ≥ D_y` latent states.
//!
//! ## Engine API (for the trainer and the CLI)
//!
//! - [`ModelConfig`] (sizes, [`KernelKind`], [`CovarianceStructure`], [`Parametrization`],
//!   jitters, `shared_draws`), [`Params`] (constrained values) ↔ flat unconstrained vector
//!   ([`Params::unconstrained`], [`Params::from_unconstrained`], [`ParamLayout`]).
//! - [`Elbo::new`]`(config, `[`TrainingData`]`, `[`ElboOptions`]`)` implements [`Objective`]
//!   (initial state from [`InitialStateMode`]); [`Elbo::evaluate`] takes per-window initial
//!   states `N(m₀, diag s₀²)` ([`InitialStates`], row-major `B × D_x`) and returns
//!   `∂loss/∂m₀`, `∂loss/∂s₀` ([`InitialStateGrads`]) with the parameter gradient.
//!   [`Elbo::with_precision`]`(`[`Precision::Mixed`]`)` forms the large products in `f32`
//!   ([`precision`]).
//! - [`predict::predict`] / [`predict::predict_with_draws`]: open-loop particle simulation
//!   ([`predict::Prediction`]); [`stream::StreamPredictor`]: one input sample at a time, no
//!   allocation per step. Both advance the particles with one step,
//!   [`step::ParticleStep`], in `f64` or `f32` ([`step::StepFloat`]).
//! - [`PrssmModel`]: config + params + normalization + training settings; JSON file
//!   ([`PrssmModel::save`], [`PrssmModel::load`]); [`published::import_published`]; prediction
//!   in physical units from the model's initial-state rule ([`PrssmModel::predict_sequence`],
//!   over [`predict::predict_standardized`]; [`Normalization::of_sequences`] for the statistics).
//! - [`sensitivity::InputSensitivity`]: the open-loop prediction and the exact gradient of any
//!   scalar of its output moments with respect to the inputs (reverse mode through the
//!   particles with their draws held fixed), for choosing inputs with the model.
//! - [`regression`]: sparse GP regression of a static map with the same kernels and k-means
//!   inducing inputs (the static nonlinear baseline's engine).
#![warn(missing_docs)]

#[cfg(feature = "bench")]
pub mod bench;
pub mod conditional;
pub mod elbo;
pub mod io;
pub mod kernel;
pub mod kl;
pub mod linalg;
pub mod model;
pub mod objective;
pub mod params;
pub mod precision;
pub mod predict;
pub mod published;
pub mod regression;
pub mod sensitivity;
pub mod step;
pub mod stream;
mod tape;
pub mod train;

pub use elbo::{
    Elbo, ElboError, ElboOptions, InitialStateGrads, InitialStateMode, InitialStates, LossParts,
    LossScaling, Sequence, SequenceView, TrainingData,
};
pub use io::ModelFileError;
pub use kernel::KernelKind;
pub use model::{Normalization, PrssmModel};
pub use objective::{Objective, ObjectiveError, Window};
pub use params::{
    ConfigError, CovarianceStructure, ModelConfig, ParamGrads, ParamInit, ParamLayout,
    Parametrization, Params,
};
pub use precision::Precision;
