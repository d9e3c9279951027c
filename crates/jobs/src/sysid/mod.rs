//! The system-identification protocol of Doerr et al. (2018) on one recorded input/output
//! table: fit a PR-SSM on the first part, simulate the rest open loop, score it.
//!
//! Protocol ([`SysidSpec::reference`], `docs/sysid.md`):
//!
//! 1. Split the `T` samples at `n_train = ⌊split · T⌋`: train `0..n_train`, test `n_train..T`.
//! 2. Fit the `sysid` preset of [`FitSpec`] (z-scoring with training statistics, ddof 0;
//!    windows of 50 at stride 1, batch 10, `D_x = 4`, `M = 20`, SE-ARD, 50 particles,
//!    Adam lr 0.1, 3000 iterations, recognition of `x₀` from the first 16 steps) `R` times
//!    per seed ([`SysidSpec::restarts`], in parallel; `R = 1` in the reference protocol).
//! 3. Predict the whole test part open loop, the initial state recognized from its first 16
//!    steps of `(u, y)`, combine the restarts ([`Combine`]; [`mixture`]) and score every
//!    test step:
//!
//! ```text
//! RMSE_raw = sqrt( 1/(T_test·D_y) Σ_t Σ_j (y_tj − m_tj)² )                     (raw units)
//! NLL      = 1/(T_test·D_y) Σ_t Σ_j [ ½ ln(2π v_tj) + (y_tj − m_tj)² / (2 v_tj) ]
//! ```
//!
//! with the predictive mean `m` and variance `v` (particle variance + `σ_y²`); the NLL is in
//! standardized units (`y`, `m`, `v` divided by the training std, so it is comparable across
//! data sets), per sample and output.

use flapssm_data::table::TableError;
use flapssm_prssm::train::Budget;
use flapssm_prssm::train::fit::{FitError, FitSpec};

use crate::presets::Preset;
use serde::{Deserialize, Serialize};

mod figure;
mod record;
mod run;
mod score;

pub use figure::plot_test_prediction;
pub use flapssm_analysis::scores::{MeanStd, Scores, score};
pub use record::IoRecord;
pub use run::{RestartRun, SeedRun, SysidReport, TestTrace, run};
pub use score::mixture;

/// Fewest training samples the protocol accepts.
pub const MIN_TRAIN_SAMPLES: usize = 100;

/// Why the protocol could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SysidError {
    /// The table could not be read or a column does not exist.
    #[error(transparent)]
    Table(#[from] TableError),
    /// A setting is out of range.
    #[error("{field} = {value}: {why}")]
    Setting {
        /// Option name.
        field: &'static str,
        /// Value, formatted.
        value: String,
        /// Requirement.
        why: String,
    },
    /// The split leaves too few samples on one side.
    #[error(
        "split {split} of {n_samples} samples leaves {n_train} training and {n_test} test samples; need at least {min_train} training and {min_test} test samples"
    )]
    Split {
        /// The split fraction.
        split: f64,
        /// Samples in the table.
        n_samples: usize,
        /// Training samples.
        n_train: usize,
        /// Test samples.
        n_test: usize,
        /// Minimum of training samples.
        min_train: usize,
        /// Minimum of test samples.
        min_test: usize,
    },
    /// Fitting or predicting failed.
    #[error("run with seed {seed} failed")]
    Fit {
        /// Seed of the failed run.
        seed: u64,
        /// Cause.
        source: FitError,
    },
}

/// How the restarts of one seed are turned into one prediction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Combine {
    /// Equal-weight mixture of the `R` restarts' predictive distributions, moment-matched:
    /// `m = (1/R) Σ_r m_r`, `v = (1/R) Σ_r (v_r + m_r²) − m²`. Its RMSE is never above the
    /// mean RMSE of the restarts (convexity of the squared error).
    Ensemble,
    /// The restart with the lowest open-loop RMSE on the training part (standardized units;
    /// `x₀` recognized from its first steps, as at test time).
    Select,
    /// Like [`Combine::Ensemble`] over `2R` members: the selected (best) and the last
    /// parameters of every restart (a snapshot ensemble).
    Snapshots,
}

/// Settings of the protocol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SysidSpec {
    /// Fraction of the samples (the first ones) used for training, in (0, 1).
    pub split: f64,
    /// Seeds `0..seeds` (one fit each; the seed replaces `fit.train.seed`).
    pub seeds: u64,
    /// Independent fits per seed (≥ 1), run in parallel. Restart 0 uses the seed itself,
    /// restart `r ≥ 1` the training seed `derive_seed(seed, 41, r)`.
    #[serde(default = "one_restart")]
    pub restarts: usize,
    /// How the restarts are combined (irrelevant for one restart).
    #[serde(default = "ensemble")]
    pub combine: Combine,
    /// Particles of the test-time prediction (per restart).
    pub predict_particles: usize,
    /// The fit (model sizes must match the record's `D_u`, `D_y`).
    pub fit: FitSpec,
}

fn one_restart() -> usize {
    1
}

fn ensemble() -> Combine {
    Combine::Ensemble
}

impl SysidSpec {
    /// The reference protocol for `n_input` inputs and `n_output` outputs: split 0.5, 3 seeds,
    /// the `sysid` preset (3000 iterations), 50 prediction particles.
    pub fn reference(n_input: usize, n_output: usize) -> Self {
        Self {
            split: 0.5,
            seeds: 3,
            restarts: 1,
            combine: Combine::Ensemble,
            predict_particles: 50,
            fit: Preset::Sysid.fit_spec(n_input, n_output),
        }
    }

    /// Sets the optimizer steps per fit.
    pub fn with_iterations(mut self, iterations: u64) -> Self {
        self.fit.train.budget = Budget::Iterations(iterations);
        self
    }

    fn check(&self, n_input: usize, n_output: usize) -> Result<(), SysidError> {
        let bad = |field, value: String, why: &str| {
            Err(SysidError::Setting {
                field,
                value,
                why: why.into(),
            })
        };
        if !(self.split > 0.0 && self.split < 1.0) {
            return bad("split", self.split.to_string(), "must be in (0, 1)");
        }
        if self.seeds == 0 {
            return bad("seeds", "0".into(), "must be ≥ 1");
        }
        if matches!(
            self.fit.train.budget,
            Budget::Iterations(0) | Budget::Epochs(0)
        ) {
            return bad("iterations", "0".into(), "must be ≥ 1");
        }
        if self.restarts == 0 {
            return bad("restarts", "0".into(), "must be ≥ 1");
        }
        if self.predict_particles == 0 {
            return bad("predict_particles", "0".into(), "must be ≥ 1");
        }
        let m = &self.fit.model;
        if (m.n_input, m.n_output) != (n_input, n_output) {
            return bad(
                "fit.model (n_input, n_output)",
                format!("({}, {})", m.n_input, m.n_output),
                &format!("the record has {n_input} inputs and {n_output} outputs"),
            );
        }
        Ok(())
    }
}

/// Training/test sample counts for `n` samples, checked.
///
/// # Errors
/// [`SysidError::Split`] when fewer than [`MIN_TRAIN_SAMPLES`] training samples or fewer test
/// samples than the recognition window remain.
pub fn split_counts(split: f64, n: usize, min_test: usize) -> Result<(usize, usize), SysidError> {
    let n_train = ((split * n as f64).floor() as usize).min(n);
    let n_test = n - n_train;
    if n_train < MIN_TRAIN_SAMPLES || n_test < min_test {
        return Err(SysidError::Split {
            split,
            n_samples: n,
            n_train,
            n_test,
            min_train: MIN_TRAIN_SAMPLES,
            min_test,
        });
    }
    Ok((n_train, n_test))
}
