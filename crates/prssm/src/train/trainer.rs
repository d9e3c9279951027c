//! The training loop: Adam on minibatches of windows of any [`Objective`], with evaluation,
//! best-model tracking, divergence recovery, checkpoints and interruption.
//!
//! Step `t` (0-based, global) belongs to epoch `e = ⌊t / B⌋`, minibatch `b = t mod B`
//! (`B` minibatches per epoch). Its windows come from the `(seed, e)` shuffle and the
//! objective's draws from `derive_seed(seed, 2, t)`; the learning rate is
//! `η_t = lr · s(t) · λ` with the schedule factor `s` and the divergence scale `λ`.
//!
//! A step is **rejected** when the objective reports a non-finite value or a non-positive-
//! definite matrix, when loss or gradient are not finite, or when the loss exceeds the running
//! average `L̄` by more than `loss_jump · (|L̄| + 1)` *and* the loss `L'` of the same minibatch
//! and draws at the parameters before the last step by more than `loss_jump · (|L'| + 1)`
//! (so a merely hard minibatch is not mistaken for divergence). Then the previous update is undone,
//! `λ ← λ · lr_factor`, the previous update is redone with the smaller rate and the same
//! minibatch is evaluated again; a [`TrainEvent::Rejected`] explains it. After
//! `max_retries` consecutive rejections training stops with [`TrainError::Diverged`].

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use super::adam::{Adam, AdamParams};
use super::batches::{BatchError, BatchPlan, WindowSpec, derive_seed};
use super::checkpoint::{
    BestModel, CHECKPOINT_VERSION, Checkpoint, CheckpointError, EpochRecord, PrevStep, TrainState,
};
use super::schedule::{LrSchedule, ScheduleError};
use crate::{Objective, ObjectiveError, Window};

/// Seed stream of the objective's draws.
const OBJECTIVE_STREAM: u64 = 2;

/// How long to train.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", content = "n", rename_all = "snake_case")]
pub enum Budget {
    /// Whole passes over all windows.
    Epochs(u64),
    /// Optimizer steps (the last epoch may be partial).
    Iterations(u64),
}

/// Divergence detection and recovery.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DivergenceGuard {
    /// Factor applied to the learning-rate scale after a rejected step, in (0, 1).
    pub lr_factor: f64,
    /// Consecutive rejections tolerated before giving up.
    pub max_retries: u32,
    /// Reject a loss above `L̄ + loss_jump · (|L̄| + 1)` (running average `L̄`) that is also
    /// above `L' + loss_jump · (|L'| + 1)` (same batch before the last step); `None` checks
    /// only finiteness.
    pub loss_jump: Option<f64>,
}

impl Default for DivergenceGuard {
    /// Halve the rate, up to 10 retries, reject a loss jump above 10 × the running loss.
    fn default() -> Self {
        Self {
            lr_factor: 0.5,
            max_retries: 10,
            loss_jump: Some(10.0),
        }
    }
}

/// Which evaluated epoch's parameters a run keeps as its best model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BestBy {
    /// The lowest validation RMSE, else the evaluator's training RMSE, else the lowest
    /// epoch-mean loss.
    #[default]
    Rmse,
    /// The lowest epoch-mean training loss (the mean minibatch −ELBO of the epoch), as the
    /// published code keeps `best.ckpt`.
    TrainingLoss,
}

impl std::str::FromStr for BestBy {
    type Err = String;
    /// `rmse` or `training-loss` (the command line's and the bindings' spelling).
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rmse" => Ok(BestBy::Rmse),
            "training-loss" => Ok(BestBy::TrainingLoss),
            _ => Err(format!(
                "unknown rule {s:?} (expected rmse or training-loss)"
            )),
        }
    }
}

/// Configuration of a training run (all of it is stored in checkpoints).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    /// Training length.
    pub budget: Budget,
    /// How sequences are cut into windows.
    pub windows: WindowSpec,
    /// Windows per minibatch.
    pub batch_size: usize,
    /// Base learning rate `lr` (> 0).
    pub lr: f64,
    /// Learning-rate schedule.
    pub schedule: LrSchedule,
    /// Adam hyper-parameters.
    pub adam: AdamParams,
    /// Seed of shuffles and objective draws.
    pub seed: u64,
    /// Evaluate (and track the best model) every this many epochs (≥ 1), and after the last step.
    pub eval_every: u64,
    /// Write a checkpoint every this many epochs (0 = never; interruption always writes one
    /// when a path is given).
    pub checkpoint_every: u64,
    /// Divergence handling.
    pub divergence: DivergenceGuard,
    /// How the best model is chosen among the evaluated epochs.
    #[serde(default)]
    pub best_by: BestBy,
    /// Early stopping: end the run when this many evaluated epochs in a row brought no new
    /// best model (`None`: run the whole budget).
    #[serde(default)]
    pub patience: Option<u64>,
    /// What else defines the run (e.g. the model specification and a fingerprint of the
    /// training data); compared like every other field when resuming. `null` if unused.
    #[serde(default)]
    pub run_context: serde_json::Value,
}

impl Default for TrainConfig {
    /// 100 epochs of whole sequences, batch 16, Adam lr 0.01, constant rate, seed 0.
    fn default() -> Self {
        Self {
            budget: Budget::Epochs(100),
            windows: WindowSpec::WholeSequences,
            batch_size: 16,
            lr: 0.01,
            schedule: LrSchedule::Constant,
            adam: AdamParams::default(),
            seed: 0,
            eval_every: 1,
            checkpoint_every: 0,
            divergence: DivergenceGuard::default(),
            best_by: BestBy::default(),
            patience: None,
            run_context: serde_json::Value::Null,
        }
    }
}

/// Metrics an evaluator returns for the current parameters (lower is better).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Evaluation {
    /// RMSE on the training sequences.
    pub train_rmse: Option<f64>,
    /// RMSE on the validation sequences (used to select the best model when present).
    pub val_rmse: Option<f64>,
}

/// Progress reported to the caller.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TrainEvent<'a> {
    /// An accepted optimizer step.
    Step {
        /// Global step index.
        step: u64,
        /// Total steps of the run.
        total_steps: u64,
        /// Epoch index.
        epoch: u64,
        /// Minibatch loss.
        loss: f64,
        /// Effective learning rate used.
        lr: f64,
    },
    /// An evaluated epoch.
    Epoch(&'a EpochRecord),
    /// A rejected step (divergence): what happened and what was done.
    Rejected {
        /// Global step index.
        step: u64,
        /// Human-readable reason.
        reason: String,
        /// New learning-rate scale `λ`.
        lr_scale: f64,
        /// Consecutive rejection count.
        retry: u32,
    },
    /// A checkpoint was written.
    Checkpoint {
        /// File.
        path: &'a std::path::Path,
        /// Steps done.
        step: u64,
    },
    /// A checkpoint was accepted for resuming (its configuration matches this run's, the
    /// budget aside); emitted once, before the first step.
    Resumed {
        /// Steps done in the checkpoint.
        step: u64,
        /// The checkpoint's configuration (its budget may be smaller than this run's).
        checkpoint: &'a TrainConfig,
    },
    /// Training stopped early on request; the state was checkpointed if a path was given.
    Interrupted {
        /// Steps done.
        step: u64,
    },
}

/// Why training failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TrainError {
    /// Invalid configuration.
    #[error("training config: {field} = {value} ({why})")]
    Config {
        /// Field name.
        field: &'static str,
        /// Value, formatted.
        value: String,
        /// Requirement.
        why: &'static str,
    },
    /// Invalid schedule.
    #[error(transparent)]
    Schedule(#[from] ScheduleError),
    /// Windows could not be formed.
    #[error(transparent)]
    Batches(#[from] BatchError),
    /// Initial parameter vector has the wrong length.
    #[error("initial parameters: {found} values, the objective has {expected}")]
    ParamCount {
        /// Values given.
        found: usize,
        /// Values expected.
        expected: usize,
    },
    /// The objective failed for a reason a smaller step cannot fix.
    #[error("objective at step {step}: {source}")]
    Objective {
        /// Step index.
        step: u64,
        /// Cause.
        source: ObjectiveError,
    },
    /// The loss at the initial parameters is not usable (nothing to roll back to).
    #[error("step {step}: {reason} at the initial parameters; nothing to roll back to")]
    BadStart {
        /// Step index.
        step: u64,
        /// What was wrong.
        reason: String,
    },
    /// Too many consecutive rejected steps.
    #[error(
        "training diverged at step {step}: {retries} consecutive rejected steps, learning-rate scale {lr_scale:e}; last: {reason}"
    )]
    Diverged {
        /// Step index.
        step: u64,
        /// Consecutive rejections.
        retries: u32,
        /// Final learning-rate scale.
        lr_scale: f64,
        /// Last reason.
        reason: String,
    },
    /// The evaluator failed.
    #[error("evaluation after epoch {epoch}: {message}")]
    Evaluation {
        /// Epoch index.
        epoch: u64,
        /// Evaluator's message.
        message: String,
    },
    /// The checkpoint to resume from belongs to a different run.
    #[error("resume: checkpoint {field} differs from this run ({why})")]
    ResumeMismatch {
        /// Differing field.
        field: String,
        /// Detail.
        why: String,
    },
    /// Checkpoint I/O.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
}

/// Result of a (possibly interrupted) run.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOutcome {
    /// Final state: last parameters, best model, history, Adam state.
    pub state: TrainState,
    /// Total steps of the configured run.
    pub total_steps: u64,
    /// Whether the run stopped early on request.
    pub interrupted: bool,
    /// Whether the run ended before its budget because the best model had not improved for
    /// [`TrainConfig::patience`] evaluated epochs.
    pub early_stopped: bool,
}

impl TrainOutcome {
    /// Parameters after the last step.
    pub fn last_params(&self) -> &[f64] {
        &self.state.params
    }

    /// Parameters of the best evaluated model (the last ones if none was evaluated).
    pub fn best_params(&self) -> &[f64] {
        self.state
            .best
            .as_ref()
            .map_or(&self.state.params, |b| &b.params)
    }
}

/// Computes metrics of flat parameters (see [`TrainHooks::evaluate`]).
pub type Evaluator<'a> = dyn FnMut(&[f64]) -> Result<Evaluation, String> + 'a;

/// Receives progress events.
pub type ProgressFn<'a> = dyn FnMut(&TrainEvent<'_>) + 'a;

/// Callbacks and options of a run that are not part of its configuration.
#[derive(Default)]
pub struct TrainHooks<'a> {
    /// Computes metrics of the given parameters at evaluated epochs (must be deterministic
    /// for reproducible best-model selection).
    pub evaluate: Option<&'a mut Evaluator<'a>>,
    /// Receives progress events.
    pub progress: Option<&'a mut ProgressFn<'a>>,
    /// Polled before every step; when set, the run checkpoints and returns.
    pub stop: Option<&'a AtomicBool>,
    /// Checkpoint file.
    pub checkpoint: Option<PathBuf>,
}

impl TrainConfig {
    /// Checks the configuration.
    ///
    /// # Errors
    /// [`TrainError::Config`] or [`TrainError::Schedule`] naming the field.
    pub fn check(&self) -> Result<(), TrainError> {
        let bad = |field, value: String, why| Err(TrainError::Config { field, value, why });
        if !(self.lr > 0.0 && self.lr.is_finite()) {
            return bad("lr", self.lr.to_string(), "must be positive and finite");
        }
        if self.eval_every == 0 {
            return bad("eval_every", "0".into(), "must be at least 1");
        }
        if self.patience == Some(0) {
            return bad("patience", "0".into(), "must be at least 1 evaluated epoch");
        }
        match self.budget {
            Budget::Epochs(0) | Budget::Iterations(0) => {
                return bad("budget", "0".into(), "must be at least 1");
            }
            _ => {}
        }
        let g = self.divergence;
        if !(g.lr_factor > 0.0 && g.lr_factor < 1.0) {
            return bad(
                "divergence.lr_factor",
                g.lr_factor.to_string(),
                "must be in (0, 1)",
            );
        }
        if let Some(j) = g.loss_jump
            && (j.is_nan() || j <= 0.0)
        {
            return bad("divergence.loss_jump", j.to_string(), "must be positive");
        }
        let a = self.adam;
        if !(0.0..1.0).contains(&a.beta1)
            || !(0.0..1.0).contains(&a.beta2)
            || a.eps.is_nan()
            || a.eps < 0.0
        {
            return bad("adam", format!("{a:?}"), "betas in [0, 1), eps >= 0");
        }
        self.schedule.check()?;
        Ok(())
    }

    /// Total optimizer steps for `batches_per_epoch` minibatches per epoch.
    pub fn total_steps(&self, batches_per_epoch: usize) -> u64 {
        match self.budget {
            Budget::Epochs(n) => n * batches_per_epoch as u64,
            Budget::Iterations(n) => n,
        }
    }
}

/// First differing top-level field of two configurations.
fn config_difference(a: &TrainConfig, b: &TrainConfig) -> Option<(String, String)> {
    let (va, vb) = (serde_json::to_value(a).ok()?, serde_json::to_value(b).ok()?);
    json_difference("", &va, &vb)
}

/// The first leaf where two JSON values differ, as (dotted path, "checkpoint X, now Y").
fn json_difference(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
) -> Option<(String, String)> {
    use serde_json::Value;
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match (a, b) {
        (Value::Object(oa), Value::Object(ob)) => {
            let keys: std::collections::BTreeSet<&String> = oa.keys().chain(ob.keys()).collect();
            keys.into_iter().find_map(|k| {
                let null = Value::Null;
                json_difference(
                    &join(k),
                    oa.get(k).unwrap_or(&null),
                    ob.get(k).unwrap_or(&null),
                )
            })
        }
        (Value::Array(xa), Value::Array(xb)) if xa.len() == xb.len() => xa
            .iter()
            .zip(xb)
            .enumerate()
            .find_map(|(i, (x, y))| json_difference(&join(&i.to_string()), x, y)),
        _ => (a != b).then(|| {
            let field = if path.is_empty() { "config" } else { path };
            (field.to_string(), format!("checkpoint {a}, now {b}"))
        }),
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The state a run starts from: the checkpoint's (checked against `config`; returned with the
/// checkpoint's configuration) or a fresh one at `init`.
fn start_state(
    resume: Option<Checkpoint>,
    init: &[f64],
    config: &TrainConfig,
    n: usize,
    total_steps: u64,
) -> Result<(TrainState, Option<TrainConfig>), TrainError> {
    Ok(match resume {
        Some(ck) => {
            // Only the budget may grow (the run is then extended from where it stopped) and the
            // checkpoint interval change: neither touches the arithmetic of a step.
            let same_budget = TrainConfig {
                budget: config.budget,
                checkpoint_every: config.checkpoint_every,
                ..ck.config.clone()
            };
            if let Some((field, why)) = config_difference(&same_budget, config) {
                return Err(TrainError::ResumeMismatch { field, why });
            }
            if ck.state.step > total_steps {
                return Err(TrainError::ResumeMismatch {
                    field: "budget".into(),
                    why: format!(
                        "the checkpoint is at step {}, past this run's {total_steps} steps",
                        ck.state.step
                    ),
                });
            }
            if ck.state.params.len() != n {
                return Err(TrainError::ResumeMismatch {
                    field: "params".into(),
                    why: format!("{} values, the objective has {n}", ck.state.params.len()),
                });
            }
            (ck.state, Some(ck.config))
        }
        None => {
            if init.len() != n {
                return Err(TrainError::ParamCount {
                    found: init.len(),
                    expected: n,
                });
            }
            (
                TrainState {
                    step: 0,
                    params: init.to_vec(),
                    adam: Adam::new(n, config.adam),
                    prev: None,
                    lr_scale: 1.0,
                    ema_loss: None,
                    rejected: 0,
                    epoch_loss_sum: 0.0,
                    epoch_batches: 0,
                    best: None,
                    history: Vec::new(),
                },
                None,
            )
        }
    })
}

/// The loss and gradient (into `grad`) of step `t` on `batch`, once accepted: a non-finite loss
/// or gradient, or a jump of the loss that the previous parameters do not share on the same
/// batch and draws, rejects the last step (its parameters restored, the rate scaled down by
/// the divergence guard, the step retaken) up to `max_retries` times.
#[allow(clippy::too_many_arguments)]
fn accepted_loss<O: Objective + ?Sized>(
    objective: &O,
    state: &mut TrainState,
    config: &TrainConfig,
    batch: &[Window],
    seed: u64,
    t: u64,
    grad: &mut [f64],
    scratch: &mut [f64],
    emit: &mut dyn FnMut(&TrainEvent<'_>),
) -> Result<f64, TrainError> {
    let mut retry = 0u32;
    loop {
        let reason = match objective.loss_and_grad(&state.params, batch, seed, grad) {
            Ok(l) if !l.is_finite() => format!("loss is {l}"),
            Ok(_) if !all_finite(grad) => "gradient is not finite".to_string(),
            Ok(l) => match (state.ema_loss, config.divergence.loss_jump, &state.prev) {
                (Some(avg), Some(jump), Some(prev)) if l > avg + jump * (avg.abs() + 1.0) => {
                    // A hard minibatch or a bad step? Compare on the same batch and draws.
                    match objective.loss_and_grad(&prev.params, batch, seed, scratch) {
                        Ok(l_prev) if l > l_prev + jump * (l_prev.abs() + 1.0) => format!(
                            "loss {l:.6e} jumped above {l_prev:.6e} before the last step \
                             (running loss {avg:.6e})"
                        ),
                        _ => return Ok(l),
                    }
                }
                _ => return Ok(l),
            },
            Err(
                e @ (ObjectiveError::NonFinite { .. } | ObjectiveError::NotPositiveDefinite { .. }),
            ) => e.to_string(),
            Err(source) => return Err(TrainError::Objective { step: t, source }),
        };
        let Some(prev) = state.prev.as_ref() else {
            return Err(TrainError::BadStart { step: t, reason });
        };
        retry += 1;
        if retry > config.divergence.max_retries {
            return Err(TrainError::Diverged {
                step: t,
                retries: retry - 1,
                lr_scale: state.lr_scale,
                reason,
            });
        }
        state.rejected += 1;
        state.lr_scale *= config.divergence.lr_factor;
        state.params.copy_from_slice(&prev.params);
        state.adam.copy_from(&prev.adam);
        state
            .adam
            .step(&mut state.params, &prev.grad, prev.lr * state.lr_scale);
        emit(&TrainEvent::Rejected {
            step: t,
            reason,
            lr_scale: state.lr_scale,
            retry,
        });
    }
}

/// The record of an evaluated epoch: the evaluator's metrics of the current parameters, the
/// epoch's mean loss, and the best model replaced when the score (by `config.best_by`) improves.
fn record_epoch(
    state: &mut TrainState,
    config: &TrainConfig,
    evaluate: Option<&mut &mut Evaluator<'_>>,
    epoch: u64,
    lr: f64,
) -> Result<(), TrainError> {
    let metrics = match evaluate {
        Some(f) => f(&state.params).map_err(|message| TrainError::Evaluation { epoch, message })?,
        None => Evaluation::default(),
    };
    let mean_loss = state.epoch_loss_sum / state.epoch_batches.max(1) as f64;
    let score = match config.best_by {
        BestBy::Rmse => metrics.val_rmse.or(metrics.train_rmse).unwrap_or(mean_loss),
        BestBy::TrainingLoss => mean_loss,
    };
    let is_best = score.is_finite() && state.best.as_ref().is_none_or(|b| score < b.score);
    if is_best {
        state.best = Some(BestModel {
            params: state.params.clone(),
            score,
            epoch,
        });
    }
    state.history.push(EpochRecord {
        epoch,
        step: state.step,
        mean_loss,
        train_rmse: metrics.train_rmse,
        val_rmse: metrics.val_rmse,
        lr,
        is_best,
    });
    Ok(())
}

/// Trains `objective` from `init` (or from `resume`) on sequences of lengths `seq_lens`.
///
/// Returns the final state, also when interrupted through `hooks.stop` (then
/// [`TrainOutcome::interrupted`] is set and a checkpoint was written to `hooks.checkpoint`).
/// A resumed run ends bit-identical to an uninterrupted one with the same configuration.
///
/// # Errors
/// [`TrainError`]: invalid configuration, windows, parameter count or checkpoint; objective
/// failure; divergence that the learning-rate reduction could not cure.
pub fn train<O: Objective + ?Sized>(
    objective: &O,
    seq_lens: &[usize],
    init: &[f64],
    config: &TrainConfig,
    hooks: TrainHooks<'_>,
    resume: Option<Checkpoint>,
) -> Result<TrainOutcome, TrainError> {
    config.check()?;
    let n = objective.n_params();
    let plan = BatchPlan::new(seq_lens, config.windows, config.batch_size)?;
    let bpe = plan.batches_per_epoch() as u64;
    let total_steps = config.total_steps(plan.batches_per_epoch());
    let (mut state, resumed_from) = start_state(resume, init, config, n, total_steps)?;
    let TrainHooks {
        mut evaluate,
        mut progress,
        stop,
        checkpoint,
    } = hooks;
    let mut emit = |ev: &TrainEvent<'_>| {
        if let Some(p) = progress.as_mut() {
            p(ev);
        }
    };
    if let Some(checkpoint) = &resumed_from {
        emit(&TrainEvent::Resumed {
            step: state.step,
            checkpoint,
        });
    }
    let save = |state: &TrainState| -> Result<(), TrainError> {
        if let Some(path) = &checkpoint {
            Checkpoint {
                format_version: CHECKPOINT_VERSION,
                config: config.clone(),
                state: state.clone(),
            }
            .save(path)?;
        }
        Ok(())
    };

    let mut grad = vec![0.0; n];
    let mut scratch = vec![0.0; n];
    let mut order = Vec::new();
    let mut order_epoch = u64::MAX;
    let mut batch: Vec<Window> = Vec::with_capacity(config.batch_size);
    let mut early_stopped = false;
    while state.step < total_steps {
        if config
            .patience
            .is_some_and(|p| patience_exhausted(&state.history, p))
        {
            early_stopped = true;
            break;
        }
        if stop.is_some_and(|s| s.load(Ordering::SeqCst)) {
            save(&state)?;
            if let Some(path) = &checkpoint {
                emit(&TrainEvent::Checkpoint {
                    path,
                    step: state.step,
                });
            }
            emit(&TrainEvent::Interrupted { step: state.step });
            return Ok(TrainOutcome {
                state,
                total_steps,
                interrupted: true,
                early_stopped: false,
            });
        }
        let t = state.step;
        let (epoch, b) = (t / bpe, t % bpe);
        if epoch != order_epoch {
            plan.epoch_order(config.seed, epoch, &mut order);
            order_epoch = epoch;
        }
        plan.batch_into(&order, b as usize, &mut batch);
        let seed = derive_seed(config.seed, OBJECTIVE_STREAM, t);
        let lr_sched = config.lr * config.schedule.factor(t, total_steps);

        let loss = accepted_loss(
            objective,
            &mut state,
            config,
            &batch,
            seed,
            t,
            &mut grad,
            &mut scratch,
            &mut emit,
        )?;

        match state.prev.as_mut() {
            Some(p) => {
                p.params.copy_from_slice(&state.params);
                p.adam.copy_from(&state.adam);
                p.grad.copy_from_slice(&grad);
                p.lr = lr_sched;
            }
            None => {
                state.prev = Some(PrevStep {
                    params: state.params.clone(),
                    adam: state.adam.clone(),
                    grad: grad.clone(),
                    lr: lr_sched,
                })
            }
        }
        let lr = lr_sched * state.lr_scale;
        state.adam.step(&mut state.params, &grad, lr);
        state.ema_loss = Some(state.ema_loss.map_or(loss, |a| 0.9 * a + 0.1 * loss));
        state.epoch_loss_sum += loss;
        state.epoch_batches += 1;
        state.step += 1;
        emit(&TrainEvent::Step {
            step: t,
            total_steps,
            epoch,
            loss,
            lr,
        });

        let epoch_end = b + 1 == bpe || state.step == total_steps;
        if epoch_end {
            let evaluated = (epoch + 1) % config.eval_every == 0 || state.step == total_steps;
            if evaluated {
                record_epoch(&mut state, config, evaluate.as_mut(), epoch, lr)?;
                if let Some(rec) = state.history.last() {
                    emit(&TrainEvent::Epoch(rec));
                }
            }
            state.epoch_loss_sum = 0.0;
            state.epoch_batches = 0;
            if config.checkpoint_every > 0 && (epoch + 1) % config.checkpoint_every == 0 {
                save(&state)?;
                if let Some(path) = &checkpoint {
                    emit(&TrainEvent::Checkpoint {
                        path,
                        step: state.step,
                    });
                }
            }
        }
    }
    // The final state, so that a finished run can be extended (resumed with a larger budget).
    save(&state)?;
    Ok(TrainOutcome {
        state,
        total_steps,
        interrupted: false,
        early_stopped,
    })
}

/// Whether the last `patience` evaluated epochs all failed to improve the best model (and
/// at least one epoch did before them).
fn patience_exhausted(history: &[EpochRecord], patience: u64) -> bool {
    let p = patience as usize;
    history.len() > p && history[history.len() - p..].iter().all(|r| !r.is_best)
}
