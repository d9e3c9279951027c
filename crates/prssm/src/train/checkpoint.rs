//! Resumable training checkpoints: the complete mutable state of a run as JSON.
//!
//! A checkpoint holds the parameters, Adam moments and step count, the previous step (for
//! rollback after a rejected step), the learning-rate scale, the loss averages, the best
//! model and the history. Shuffles and objective draws are pure functions of `(seed, step)`,
//! so the step counter is the whole RNG state. Floats round-trip exactly (serde_json with
//! `float_roundtrip`), which makes a resumed run bit-identical to an uninterrupted one.
//! Files are written atomically (temporary file + rename).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::adam::Adam;
use super::trainer::TrainConfig;

/// Current checkpoint format version.
pub const CHECKPOINT_VERSION: u32 = 1;

/// The accepted step before the current parameters, kept to roll back a rejected step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrevStep {
    /// Parameters before the step.
    pub params: Vec<f64>,
    /// Adam state before the step.
    pub adam: Adam,
    /// Gradient the step used.
    pub grad: Vec<f64>,
    /// Schedule learning rate of the step (before the divergence scale).
    pub lr: f64,
}

/// The best model seen so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestModel {
    /// Its parameters.
    pub params: Vec<f64>,
    /// Its score (by [`super::BestBy`]: validation RMSE, else training RMSE, else mean epoch
    /// loss; or the mean epoch loss; lower is better).
    pub score: f64,
    /// Epoch (0-based) after which it was recorded.
    pub epoch: u64,
}

/// Summary of one evaluated epoch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// Epoch index (0-based).
    pub epoch: u64,
    /// Global optimizer steps done at the end of the epoch.
    pub step: u64,
    /// Mean minibatch loss over the epoch.
    pub mean_loss: f64,
    /// Training RMSE from the evaluator, if any.
    pub train_rmse: Option<f64>,
    /// Validation RMSE from the evaluator, if any.
    pub val_rmse: Option<f64>,
    /// Effective learning rate of the last step.
    pub lr: f64,
    /// Whether this epoch produced a new best model.
    pub is_best: bool,
}

/// Complete mutable state of a training run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainState {
    /// Optimizer steps done (the next step's index).
    pub step: u64,
    /// Current parameters.
    pub params: Vec<f64>,
    /// Adam state.
    pub adam: Adam,
    /// Previous accepted step, for rollback.
    pub prev: Option<PrevStep>,
    /// Learning-rate multiplier, reduced after each rejected step (starts at 1).
    pub lr_scale: f64,
    /// Exponential moving average of accepted minibatch losses (weight 0.1 on the newest).
    pub ema_loss: Option<f64>,
    /// Number of rejected steps so far.
    pub rejected: u64,
    /// Sum of minibatch losses in the current epoch.
    pub epoch_loss_sum: f64,
    /// Minibatches in the current epoch so far.
    pub epoch_batches: u64,
    /// Best model so far.
    pub best: Option<BestModel>,
    /// One record per evaluated epoch.
    pub history: Vec<EpochRecord>,
}

/// A checkpoint file: format version, the run's configuration and its state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`CHECKPOINT_VERSION`].
    pub format_version: u32,
    /// Configuration of the run (a resumed run must use the same).
    pub config: TrainConfig,
    /// State.
    pub state: TrainState,
}

/// Why a checkpoint could not be written or read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    /// File system error.
    #[error("checkpoint {path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// The file is not a valid checkpoint.
    #[error("checkpoint {path}: invalid JSON: {source}")]
    Parse {
        /// File.
        path: PathBuf,
        /// Cause (with line and column).
        source: serde_json::Error,
    },
    /// Written by an incompatible version.
    #[error("checkpoint {path}: format version {found}, expected {expected}")]
    Version {
        /// File.
        path: PathBuf,
        /// Version in the file.
        found: u32,
        /// Supported version.
        expected: u32,
    },
}

impl Checkpoint {
    /// Writes the checkpoint atomically to `path`.
    ///
    /// # Errors
    /// [`CheckpointError::Io`] naming the file.
    pub fn save(&self, path: &Path) -> Result<(), CheckpointError> {
        let io = |source| CheckpointError::Io {
            path: path.to_path_buf(),
            source,
        };
        let bytes = serde_json::to_vec(self).map_err(|e| io(std::io::Error::other(e)))?;
        flapssm_data::atomic::write_bytes_atomic(path, &bytes).map_err(io)
    }

    /// Reads a checkpoint.
    ///
    /// # Errors
    /// [`CheckpointError`] naming the file, the JSON position or the version.
    pub fn load(path: &Path) -> Result<Self, CheckpointError> {
        let bytes = std::fs::read(path).map_err(|source| CheckpointError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let ck: Checkpoint =
            serde_json::from_slice(&bytes).map_err(|source| CheckpointError::Parse {
                path: path.to_path_buf(),
                source,
            })?;
        if ck.format_version != CHECKPOINT_VERSION {
            return Err(CheckpointError::Version {
                path: path.to_path_buf(),
                found: ck.format_version,
                expected: CHECKPOINT_VERSION,
            });
        }
        Ok(ck)
    }
}
