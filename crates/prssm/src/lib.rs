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
#![warn(missing_docs)]

pub mod objective;

pub use objective::{Objective, ObjectiveError, Window};
