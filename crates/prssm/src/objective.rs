//! The contract between models and the trainer: a differentiable loss over a flat vector of
//! unconstrained parameters, evaluated on a minibatch of sequence windows.

/// A window of one training sequence: steps `start .. start + len` of sequence `sequence`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Window {
    /// Index of the sequence in the training data.
    pub sequence: usize,
    /// First time step of the window.
    pub start: usize,
    /// Number of time steps.
    pub len: usize,
}

/// Why a loss evaluation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ObjectiveError {
    /// A matrix that must be symmetric positive definite was not (e.g. `K_mm` with too little
    /// jitter).
    #[error("{what} is not positive definite (pivot {index})")]
    NotPositiveDefinite {
        /// Which matrix.
        what: &'static str,
        /// Index of the failing pivot.
        index: usize,
    },
    /// The loss or its gradient is NaN or infinite.
    #[error("non-finite {what}")]
    NonFinite {
        /// "loss" or "gradient".
        what: &'static str,
    },
    /// A window or parameter vector does not fit the data or model.
    #[error("shape mismatch: {0}")]
    Shape(String),
}

/// A loss to minimize (e.g. the negative ELBO) with its exact gradient.
///
/// Implementations hold their training data; `params` is the flat vector of unconstrained
/// parameters (positive quantities through softplus or log). All randomness of one evaluation
/// is derived from `seed`, so an evaluation is reproducible.
pub trait Objective: Sync {
    /// Number of unconstrained parameters.
    fn n_params(&self) -> usize;

    /// Evaluates the loss on `batch` and writes `∂loss/∂params` into `grad`
    /// (`grad.len() == n_params()`, overwritten, not accumulated).
    ///
    /// # Errors
    /// [`ObjectiveError`] when the evaluation is not possible or not finite.
    fn loss_and_grad(
        &self,
        params: &[f64],
        batch: &[Window],
        seed: u64,
        grad: &mut [f64],
    ) -> Result<f64, ObjectiveError>;
}
