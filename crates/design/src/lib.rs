//! # flapssm-design — wing kinematics chosen with a learned load model
//!
//! The inverse of prediction: which wing motion gives the loads wanted? A design is a set of
//! harmonic kinematics ([`flapssm_wing::trajectories::harmonic::HarmonicKinematics`]) under
//! limits, chosen to meet a [`Target`] — cycle-mean stroke-frame loads (lift, thrust, side
//! force, moments about the stroke axis) or a wing-frame load history — optionally with the
//! least aerodynamic power, by minimizing
//!
//! ```text
//! J(θ) = fit(θ) + κ · mean_t Σ_k v_k(t)/σ_k² + w_P · P̄/σ_P + μ · Σ_t Σ_c max(0, |s_c(t)|/s̄_c − 1)²
//! ```
//!
//! over the kinematic parameters `θ` with Adam from several starts ([`optimize::design`]).
//! `v_k` are the design model's predictive variances of the wing-frame outputs (the robust
//! term keeps a PR-SSM design where the model knows the physics), `σ_k` the outputs' scales,
//! `s̄` the kinematic limits. The gradient through a PR-SSM is exact: the engine's
//! [`flapssm_prssm::sensitivity::InputSensitivity`] gives `∂J/∂u`, the wing crate's
//! [`flapssm_wing::input_jacobian`] and [`flapssm_wing::stroke_loads`] carry it to the Euler
//! states, and the states are linear in `θ`. Models without input gradients (the LRQSM, the
//! quasi-steady wing) are differentiated by central differences of `J`.
//!
//! [`control`] closes the loop cycle by cycle: a receding-horizon choice of the next stroke's
//! amplitude from the loads measured so far, with the streaming model's state.
#![warn(missing_docs)]

pub mod control;
pub mod error;
pub mod model;
pub mod objective;
pub mod optimize;
pub mod problem;

pub use error::DesignError;
pub use model::{DesignModel, LrqsmDesign, PrssmDesign, QuasiSteadyDesign};
pub use objective::{Evaluation, Objective};
pub use optimize::{Design, OptimizerSettings, design};
pub use problem::{DesignGrid, DesignProblem, Target};
