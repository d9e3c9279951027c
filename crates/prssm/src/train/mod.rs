//! Training of any [`Objective`](crate::Objective): minibatches of windows, Adam with a
//! learning-rate schedule, best-model tracking, divergence recovery, resumable checkpoints
//! and a recognition model for initial states.
//!
//! - [`schedule`]: learning-rate schedules.
//! - [`adam`]: the Adam optimizer.
//! - [`batches`]: windows, shuffled minibatches and seed derivation.
//! - [`checkpoint`]: the complete run state, saved atomically.
//! - [`inducing`]: uniform or k-means starting values of the inducing inputs and `q(u)` means.
//! - [`initial`]: initial-state rules and the ELBO with a recognition model.
//! - [`fit`](mod@fit): fitting a PR-SSM to raw sequences.
//! - [`recognition`]: the recognition model `(u, y)_{0..k} ↦ N(m₀, diag(s₀²))`.
//! - [`trainer`]: the training loop [`train`].

pub mod adam;
pub mod batches;
pub mod checkpoint;
pub mod fit;
pub mod inducing;
pub mod initial;
pub mod recognition;
pub mod schedule;
pub mod trainer;

pub use adam::{Adam, AdamParams};
pub use batches::{BatchError, BatchPlan, WindowSpec, derive_seed};
pub use checkpoint::{BestModel, Checkpoint, CheckpointError, EpochRecord, TrainState};
pub use fit::{FitError, FitOutcome, FitSpec, TrainingRecord, fit};
pub use inducing::InducingInit;
pub use initial::{InitialStateModel, InitialStateSpec, RecognizedElbo};
pub use recognition::{Recognition, RecognitionConfig};
pub use schedule::LrSchedule;
pub use trainer::{
    BestBy, Budget, DivergenceGuard, Evaluation, TrainConfig, TrainError, TrainEvent, TrainHooks,
    TrainOutcome, train,
};
