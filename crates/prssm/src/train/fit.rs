//! Fitting a PR-SSM to raw sequences: presets, standardization, validation metrics, the
//! training loop and the resulting [`PrssmModel`]s (best and last). Prediction with the
//! model's initial-state rule is [`PrssmModel::predict_sequence`].
//!
//! [`FitSpec::new`] starts from the settings of Bayiz & Cheng's published run (whole
//! sequences in minibatches of 16, 30 particles, Adam at 0.03 for 1000 epochs, zero initial
//! state with 20 % burn-in); the application's named presets (`flapssm_jobs::presets`) are
//! built on it.
//!
//! Inputs and outputs are standardized with the training mean and standard deviation
//! (ddof 0; a constant channel gets std 1), stored in the model. Reported RMSEs
//! ([`Evaluation`]) are open-loop (from the initial-state rule), in standardized units,
//! averaged over output channels, over the steps after the burn-in, on at most
//! `eval_max_sequences` training sequences and all validation sequences.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::batches::{BatchPlan, WindowSpec, derive_seed};
use super::checkpoint::Checkpoint;
use super::inducing::{InducingInit, kmeans_start};
use super::initial::{InitialStateModel, InitialStateSpec, RecognizedElbo};
use super::recognition::Recognition;
use super::schedule::LrSchedule;
use super::trainer::{
    Budget, Evaluation, TrainConfig, TrainError, TrainHooks, TrainOutcome, train,
};
use crate::elbo::{
    Elbo, ElboError, ElboOptions, InitialStateMode, LossScaling, Sequence, SequenceView,
    TrainingData, sequence_lengths,
};
use crate::model::{Normalization, PrssmModel};
use crate::params::{ConfigError, ModelConfig, ParamInit, Params};
use crate::precision::Precision;
use crate::predict::{self, Prediction};
use crate::{Objective, ObjectiveError};

/// Which training objective a fit minimizes.
///
/// | form | likelihood scale `s` | noise draws |
/// |---|---|---|
/// | `Standard` | `N_windows / (batch · particles)`: an unbiased minibatch −ELBO | independent per latent dim |
/// | `PublishedCode` | 1: summed over batch, time and particles, one KL per minibatch | one draw per particle and step, shared by all latent dims |
///
/// `PublishedCode` reproduces the authors' TensorFlow objective (notes §1) so that their run
/// can be repeated exactly; its KL weight against the likelihood changes with the particle
/// count and batch size, and its shared draws correlate the latent dims' noise.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveForm {
    /// The correct minibatch ELBO with independent draws.
    #[default]
    Standard,
    /// The published code's objective and sampling (both quirks).
    PublishedCode,
}

impl std::str::FromStr for ObjectiveForm {
    type Err = String;
    /// `standard` or `published-code` (the command line's and the bindings' spelling).
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "standard" => Ok(ObjectiveForm::Standard),
            "published-code" => Ok(ObjectiveForm::PublishedCode),
            _ => Err(format!(
                "unknown form {s:?} (expected standard or published-code)"
            )),
        }
    }
}

/// Everything that defines a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSpec {
    /// Model structure (sizes, kernel, …).
    pub model: ModelConfig,
    /// Initial parameter values.
    pub init: ParamInit,
    /// Particles per window in the ELBO.
    pub particles: usize,
    /// Fraction of each window excluded from the likelihood.
    pub burn_in_fraction: f64,
    /// Initial-state rule.
    pub initial_state: InitialStateSpec,
    /// Optimizer, minibatches, budget, seed, checkpoints.
    pub train: TrainConfig,
    /// Particles of the evaluation rollouts.
    pub eval_particles: usize,
    /// At most this many training sequences are evaluated each epoch.
    pub eval_max_sequences: usize,
    /// The objective's form (older specs: standard).
    #[serde(default)]
    pub objective: ObjectiveForm,
    /// How `Z` and the `q(u)` means start (older specs: uniform).
    #[serde(default)]
    pub inducing_init: InducingInit,
    /// Arithmetic of the ELBO's large products (older specs: f64; [`crate::precision`]).
    #[serde(default)]
    pub precision: Precision,
    /// Windows batched into one parallel task of the ELBO ([`ElboOptions::windows_per_task`];
    /// older specs: 4). A minibatch of `B` windows runs as `⌈B / n⌉` tasks, so at most that
    /// many threads work on it; the result does not depend on the thread count, and on `n`
    /// only through the order of floating-point sums.
    #[serde(default = "default_windows_per_task")]
    pub windows_per_task: usize,
}

/// [`FitSpec::windows_per_task`] of the presets and of specs written before it existed.
pub const DEFAULT_WINDOWS_PER_TASK: usize = 4;

fn default_windows_per_task() -> usize {
    DEFAULT_WINDOWS_PER_TASK
}

impl FitSpec {
    /// A fit of `model` with the settings of the published run: initial parameters
    /// [`ParamInit::default`], 30 particles (training and evaluation), 20 % burn-in, zero
    /// initial state, whole sequences in minibatches of 16, Adam at a constant 0.03 for 1000
    /// epochs, 16 training sequences evaluated per epoch, the standard objective, uniform
    /// inducing inputs, `f64`, [`DEFAULT_WINDOWS_PER_TASK`] windows per task.
    pub fn new(model: ModelConfig) -> Self {
        Self {
            model,
            init: ParamInit::default(),
            particles: 30,
            burn_in_fraction: 0.2,
            initial_state: InitialStateSpec::Zeros,
            train: TrainConfig {
                budget: Budget::Epochs(1000),
                windows: WindowSpec::WholeSequences,
                batch_size: 16,
                lr: 0.03,
                schedule: LrSchedule::Constant,
                ..TrainConfig::default()
            },
            eval_particles: 30,
            eval_max_sequences: 16,
            objective: ObjectiveForm::Standard,
            inducing_init: InducingInit::Uniform,
            precision: Precision::F64,
            windows_per_task: DEFAULT_WINDOWS_PER_TASK,
        }
    }

    /// This spec with the objective `form`; [`ObjectiveForm::PublishedCode`] also switches the
    /// model to the published sampling ([`ModelConfig::published_compat`]); `Standard` to
    /// [`ModelConfig::standard_sampling`].
    pub fn with_objective(mut self, form: ObjectiveForm) -> Self {
        self.objective = form;
        self.model = match form {
            ObjectiveForm::PublishedCode => self.model.published_compat(),
            ObjectiveForm::Standard => self.model.standard_sampling(),
        };
        self
    }

    /// Checks that the model's sampling agrees with the objective's form.
    ///
    /// # Errors
    /// [`ConfigError`] on `shared_draws` when they disagree.
    pub fn check_objective(&self) -> Result<(), ConfigError> {
        let published = self.objective == ObjectiveForm::PublishedCode;
        if self.model.shared_draws != published {
            return Err(ConfigError {
                field: "shared_draws",
                message: format!(
                    "is {} but the objective is {:?}; use FitSpec::with_objective",
                    self.model.shared_draws, self.objective
                ),
            });
        }
        Ok(())
    }
}

/// What a fit stores in [`PrssmModel::training`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingRecord {
    /// The fit's specification.
    pub spec: FitSpec,
    /// The fitted initial-state rule.
    pub initial_state: InitialStateModel,
    /// Which parameters these are: `"best"` or `"last"`.
    pub which: String,
    /// Epoch of the best model, if any was evaluated.
    pub best_epoch: Option<u64>,
    /// Steps done.
    pub steps: u64,
    /// Rejected (divergent) steps.
    pub rejected_steps: u64,
    /// Per-epoch history.
    pub history: Vec<super::checkpoint::EpochRecord>,
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// Bad training data or options.
    #[error(transparent)]
    Elbo(#[from] ElboError),
    /// Bad configuration.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Training failed.
    #[error(transparent)]
    Train(#[from] TrainError),
    /// Prediction failed.
    #[error(transparent)]
    Objective(#[from] ObjectiveError),
    /// The model file's training record is missing or invalid.
    #[error("model training record: {0}")]
    Record(String),
    /// A prediction from the model's initial-state rule failed.
    #[error(transparent)]
    Prediction(#[from] crate::predict::PredictionError),
}

/// The result of [`fit`].
#[derive(Debug, Clone)]
pub struct FitOutcome {
    /// Model with the best evaluated parameters (the last ones if none was evaluated).
    pub best: PrssmModel,
    /// Model with the parameters after the last step.
    pub last: PrssmModel,
    /// The raw training outcome (state, interruption flag).
    pub outcome: TrainOutcome,
}

fn record(
    spec: &FitSpec,
    initial: InitialStateModel,
    which: &str,
    outcome: &TrainOutcome,
) -> serde_json::Value {
    let r = TrainingRecord {
        spec: spec.clone(),
        initial_state: initial,
        which: which.into(),
        best_epoch: outcome.state.best.as_ref().map(|b| b.epoch),
        steps: outcome.state.step,
        rejected_steps: outcome.state.rejected,
        history: outcome.state.history.clone(),
    };
    serde_json::to_value(r).unwrap_or(serde_json::Value::Null)
}

/// Reads the training record of a model written by [`fit`].
///
/// # Errors
/// [`FitError::Record`] when the model has none or it does not parse.
pub fn training_record(model: &PrssmModel) -> Result<TrainingRecord, FitError> {
    serde_json::from_value(model.training.clone()).map_err(|e| FitError::Record(e.to_string()))
}

/// Fits a PR-SSM to raw training sequences (`train`) with optional validation sequences.
///
/// # Errors
/// [`FitError`] for invalid data, configuration or a failed run.
pub fn fit(
    spec: &FitSpec,
    train_raw: &[SequenceView<'_>],
    val_raw: &[SequenceView<'_>],
    hooks: TrainHooks<'_>,
    resume: Option<Checkpoint>,
) -> Result<FitOutcome, FitError> {
    let cfg = &spec.model;
    cfg.check()?;
    spec.check_objective()?;
    let (du, dy) = (cfg.n_input, cfg.n_output);
    // Validate shapes before computing statistics.
    let lens = sequence_lengths(du, dy, train_raw.iter().copied())?;
    sequence_lengths(du, dy, val_raw.iter().copied())?;
    let norm = Normalization::of_sequences(train_raw, du, dy);
    let train_z: Vec<Sequence> = train_raw
        .iter()
        .map(|s| norm.standardize_sequence(*s))
        .collect();
    let val_z: Vec<Sequence> = val_raw
        .iter()
        .map(|s| norm.standardize_sequence(*s))
        .collect();
    let data = TrainingData::new(du, dy, train_z)?;
    let plan = BatchPlan::new(&lens, spec.train.windows, spec.train.batch_size)
        .map_err(TrainError::from)?;
    let options = ElboOptions {
        particles: spec.particles,
        burn_in_fraction: spec.burn_in_fraction,
        scaling: match spec.objective {
            ObjectiveForm::Standard => LossScaling::Standard {
                n_windows: plan.windows().len() as f64,
            },
            ObjectiveForm::PublishedCode => LossScaling::Published,
        },
        initial_state: match spec.initial_state {
            InitialStateSpec::Outputs => InitialStateMode::Outputs,
            _ => InitialStateMode::Zeros,
        },
        windows_per_task: spec.windows_per_task,
    };
    let elbo = Elbo::new(cfg.clone(), data, options)?.with_precision(spec.precision);
    let train_z = elbo.data().sequences();
    let seed = spec.train.seed;
    let mut start = Params::init(cfg, &spec.init, derive_seed(seed, 3, 0));
    if spec.inducing_init == InducingInit::Kmeans {
        let burn_in = match spec.initial_state {
            InitialStateSpec::Zeros => spec.burn_in_fraction,
            _ => 0.0,
        };
        kmeans_start(cfg, train_z, burn_in, derive_seed(seed, 8, 0), &mut start)?;
    }
    let mut init = start.unconstrained(cfg);
    let recognized = match spec.initial_state {
        InitialStateSpec::Recognition(rc) => Some(RecognizedElbo::new(&elbo, rc)),
        _ => None,
    };
    if let Some(r) = &recognized {
        init.extend(r.recognition().init_params(derive_seed(seed, 4, 0)));
    }
    let n_e = elbo.n_params();
    let recognition: Option<Recognition> = recognized.as_ref().map(|r| r.recognition().clone());
    let initial_of = |flat: &[f64]| InitialStateModel {
        spec: spec.initial_state,
        recognition: recognition.clone(),
        params: flat[n_e..].to_vec(),
    };
    let skip = |len: usize| (spec.burn_in_fraction * len as f64).floor() as usize;
    let eval_seed = derive_seed(seed, 5, 0);
    let evaluate_set = |flat: &[f64], set: &[Sequence]| -> Result<Option<f64>, String> {
        if set.is_empty() {
            return Ok(None);
        }
        let p = Params::from_unconstrained(cfg, &flat[..n_e]).map_err(|e| e.to_string())?;
        let initial = initial_of(flat);
        // The rollouts in parallel (each has its own seed), the sum in sequence order.
        let rollout = |(i, seq): (usize, &Sequence)| {
            predict::predict_standardized(
                cfg,
                &p,
                &initial,
                seq.view(),
                spec.eval_particles,
                derive_seed(eval_seed, 6, i as u64),
            )
            .map_err(|e| format!("sequence {i}: {e}"))
        };
        let preds: Vec<Result<Prediction, String>> =
            set.par_iter().enumerate().map(rollout).collect();
        let (mut s2, mut n) = (0.0, 0.0);
        for (seq, pred) in set.iter().zip(preds) {
            let pred = pred?;
            let t0 = skip(seq.outputs.len() / dy) * dy;
            for (m, y) in pred.output_mean[t0..].iter().zip(&seq.outputs[t0..]) {
                s2 += (m - y) * (m - y);
                n += 1.0;
            }
        }
        Ok(Some((s2 / f64::max(n, 1.0)).sqrt()))
    };
    let n_eval_train = spec.eval_max_sequences.min(train_z.len());
    let mut user_progress = hooks.progress;
    let mut evaluate = |flat: &[f64]| -> Result<Evaluation, String> {
        Ok(Evaluation {
            train_rmse: evaluate_set(flat, &train_z[..n_eval_train])?,
            val_rmse: evaluate_set(flat, &val_z)?,
        })
    };
    let mut forward = |e: &super::trainer::TrainEvent<'_>| {
        if let Some(p) = user_progress.as_mut() {
            p(e);
        }
    };
    let hooks = TrainHooks {
        evaluate: Some(&mut evaluate),
        progress: Some(&mut forward),
        stop: hooks.stop,
        checkpoint: hooks.checkpoint,
    };
    let objective: &dyn Objective = match &recognized {
        Some(r) => r,
        None => &elbo,
    };
    // Everything besides the optimizer settings that defines the run, so that a checkpoint is
    // only resumed with the same model, ELBO options and data.
    let mut train_config = spec.train.clone();
    let mut spec_rest = serde_json::to_value(spec).unwrap_or_default();
    if let Some(obj) = spec_rest.as_object_mut() {
        obj.remove("train");
    }
    train_config.run_context = serde_json::json!({
        "fit": spec_rest,
        "data": { "train": data_fingerprint(train_raw), "validation": data_fingerprint(val_raw) },
    });
    let outcome = train(objective, &lens, &init, &train_config, hooks, resume)?;
    let model_of = |flat: &[f64], which: &str| -> Result<PrssmModel, FitError> {
        Ok(PrssmModel {
            config: cfg.clone(),
            params: Params::from_unconstrained(cfg, &flat[..n_e])?,
            normalization: Some(norm.clone()),
            training: record(spec, initial_of(flat), which, &outcome),
        })
    };
    Ok(FitOutcome {
        best: model_of(outcome.best_params(), "best")?,
        last: model_of(outcome.last_params(), "last")?,
        outcome,
    })
}

/// A fingerprint of raw sequences: count, total length and an FNV-1a hash of every value's bits.
fn data_fingerprint(sequences: &[SequenceView<'_>]) -> serde_json::Value {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut n_values = 0usize;
    for s in sequences {
        for x in s.inputs.iter().chain(s.outputs) {
            for byte in x.to_bits().to_le_bytes() {
                hash = (hash ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
            }
            n_values += 1;
        }
    }
    serde_json::json!({
        "sequences": sequences.len(),
        "values": n_values,
        "fnv1a64": format!("{hash:016x}"),
    })
}
