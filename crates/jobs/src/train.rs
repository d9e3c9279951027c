//! PR-SSM training on a dataset's training trajectories: the settings (a preset with overrides)
//! and the job.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use flapssm_data::Trajectory;
use flapssm_prssm::Sequence;
use flapssm_prssm::train::fit::{FitOutcome, FitSpec, Preset, fit};
use flapssm_prssm::train::{Budget, Checkpoint, LrSchedule, TrainEvent, TrainHooks};
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result};
use crate::predict::trajectory_sequence;
use crate::progress::Progress;

/// PR-SSM training settings shared by the sweeps and the demo: a preset with overrides.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingOptions {
    /// Named preset (paper: D_x 12, M 100, 30 particles, batch 16, lr 0.03, 1000 epochs).
    pub preset: Preset,
    /// Latent dimension D_x.
    pub dx: Option<usize>,
    /// Inducing points M.
    pub inducing: Option<usize>,
    /// Particles per window (also used for the per-epoch evaluation rollouts).
    pub particles: Option<usize>,
    /// Epochs.
    pub epochs: Option<u64>,
    /// Optimizer steps (instead of epochs; wins over `epochs` when both are given).
    pub iterations: Option<u64>,
    /// Windows per minibatch.
    pub batch: Option<usize>,
    /// Adam learning rate.
    pub lr: Option<f64>,
    /// Learning-rate schedule.
    pub schedule: Option<LrSchedule>,
    /// Evaluate (best-model tracking) every this many epochs.
    pub eval_every: Option<u64>,
    /// Seed of initialization, shuffles and draws.
    pub seed: u64,
    /// Fraction of the training trajectories (the last ones) held out for best-model selection.
    pub val_fraction: f64,
    /// Checkpoint every this many epochs (0: only when interrupted).
    pub checkpoint_every: u64,
}

impl Default for TrainingOptions {
    /// The paper preset, no overrides, seed 0, 10 % validation, checkpoint every 10 epochs.
    fn default() -> Self {
        Self {
            preset: Preset::Paper,
            dx: None,
            inducing: None,
            particles: None,
            epochs: None,
            iterations: None,
            batch: None,
            lr: None,
            schedule: None,
            eval_every: None,
            seed: 0,
            val_fraction: 0.1,
            checkpoint_every: 10,
        }
    }
}

impl TrainingOptions {
    /// The fit specification for 7 inputs and 5 outputs.
    pub fn spec(&self) -> FitSpec {
        let mut spec = FitSpec::preset(self.preset, 7, 5);
        if let Some(v) = self.dx {
            spec.model.n_state = v;
        }
        if let Some(v) = self.inducing {
            spec.model.n_inducing = v;
        }
        if let Some(v) = self.particles {
            spec.particles = v;
            spec.eval_particles = v;
        }
        if let Some(v) = self.epochs {
            spec.train.budget = Budget::Epochs(v);
        }
        if let Some(v) = self.iterations {
            spec.train.budget = Budget::Iterations(v);
        }
        if let Some(v) = self.batch {
            spec.train.batch_size = v;
        }
        if let Some(v) = self.lr {
            spec.train.lr = v;
        }
        if let Some(v) = self.schedule {
            spec.train.schedule = v;
        }
        if let Some(v) = self.eval_every {
            spec.train.eval_every = v;
        }
        spec.train.seed = self.seed;
        spec.train.checkpoint_every = self.checkpoint_every;
        spec
    }

    /// Splits training trajectories into (fit, validation): the last
    /// `round(n · val_fraction)` (at most `n − 1`) validate.
    ///
    /// # Errors
    /// [`JobError::Mismatch`] for a fraction outside [0, 1) or no trajectory.
    pub fn split<'a>(
        &self,
        train: &'a [Trajectory],
    ) -> Result<(&'a [Trajectory], &'a [Trajectory])> {
        if !(0.0..1.0).contains(&self.val_fraction) || train.is_empty() {
            return Err(JobError::Mismatch {
                what: "training split".into(),
                expected: "val_fraction in [0, 1) and at least one training trajectory".into(),
                found: format!("{} of {} trajectories", self.val_fraction, train.len()),
            });
        }
        let n_val =
            ((train.len() as f64 * self.val_fraction).round() as usize).min(train.len() - 1);
        Ok(train.split_at(train.len() - n_val))
    }
}

/// Trains a PR-SSM on `train` (split by [`TrainingOptions::split`]), reporting steps to
/// `progress` (`set(step, total)`, one line per evaluated epoch), checkpointing to
/// `checkpoint` and resuming from `resume`. Polls `stop` before every step.
///
/// # Errors
/// [`JobError::Prssm`] for a failed fit, [`JobError::Interrupted`] when stopped.
pub fn train_prssm(
    train: &[Trajectory],
    opts: &TrainingOptions,
    checkpoint: Option<&Path>,
    resume: Option<Checkpoint>,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<FitOutcome> {
    let (fit_set, val_set) = opts.split(train)?;
    let fit_seqs: Vec<Sequence> = fit_set.iter().map(trajectory_sequence).collect();
    let val_seqs: Vec<Sequence> = val_set.iter().map(trajectory_sequence).collect();
    let spec = opts.spec();
    let mut on_event = |e: &TrainEvent<'_>| match e {
        TrainEvent::Step {
            step,
            total_steps,
            epoch,
            loss,
            ..
        } => {
            progress.set(step + 1, *total_steps);
            progress.message(&format!("epoch {epoch} loss {loss:.3e}"));
        }
        TrainEvent::Epoch(r) => {
            let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
            progress.println(&format!(
                "epoch {:>4}: -ELBO {:.4e}  train RMSE {}  val RMSE {}{}",
                r.epoch,
                r.mean_loss,
                f(r.train_rmse),
                f(r.val_rmse),
                if r.is_best { "  (best)" } else { "" }
            ));
        }
        TrainEvent::Rejected { step, reason, .. } => {
            progress.println(&format!("step {step} rejected ({reason}); retried"));
        }
        _ => {}
    };
    let out = fit(
        &spec,
        &fit_seqs,
        &val_seqs,
        TrainHooks {
            evaluate: None,
            progress: Some(&mut on_event),
            stop,
            checkpoint: checkpoint.map(Path::to_path_buf),
        },
        resume,
    )
    .map_err(|source| JobError::Prssm {
        what: "training".into(),
        source,
    })?;
    if out.outcome.interrupted {
        return Err(JobError::Interrupted {
            step: out.outcome.state.step,
            checkpoint: checkpoint.map(Path::to_path_buf).unwrap_or_default(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_data::Dataset;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

    fn tiny_dataset() -> Dataset {
        let mut cfg = SimulationConfig::default();
        cfg.trajectories.n_trajectories = 6;
        cfg.trajectories.n_train = 4;
        cfg.trajectories.seed = 3;
        simulate_dataset(&cfg, &|| {}).unwrap()
    }

    #[test]
    fn validation_split_follows_the_fraction() {
        let ds = tiny_dataset();
        let t = &ds.trajectories[..5];
        let split = |f: f64| {
            let o = TrainingOptions {
                val_fraction: f,
                ..TrainingOptions::default()
            };
            o.split(t).map(|(a, b)| (a.len(), b.len()))
        };
        assert_eq!(split(0.0).unwrap(), (5, 0));
        assert_eq!(split(0.2).unwrap(), (4, 1));
        assert_eq!(split(0.5).unwrap(), (2, 3)); // round(2.5) = 3
        assert_eq!(split(0.99).unwrap(), (1, 4)); // at least one trajectory is fitted
        assert!(split(1.0).is_err() && split(-0.1).is_err());
    }

    #[test]
    fn overrides_reach_the_fit_spec() {
        let o = TrainingOptions {
            dx: Some(6),
            inducing: Some(9),
            particles: Some(4),
            epochs: Some(7),
            batch: Some(2),
            lr: Some(0.2),
            seed: 11,
            ..TrainingOptions::default()
        };
        let s = o.spec();
        assert_eq!((s.model.n_state, s.model.n_inducing), (6, 9));
        assert_eq!((s.particles, s.eval_particles), (4, 4));
        assert_eq!(s.train.budget, Budget::Epochs(7));
        assert_eq!((s.train.batch_size, s.train.lr, s.train.seed), (2, 0.2, 11));
        // No override: the paper preset.
        let p = TrainingOptions::default().spec();
        assert_eq!(p, {
            let mut f = FitSpec::preset(Preset::Paper, 7, 5);
            f.train.checkpoint_every = 10;
            f
        });
    }
}
