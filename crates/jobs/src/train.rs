//! PR-SSM training on a dataset's training trajectories: the settings (a preset with overrides)
//! and the job.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use flapssm_prssm::train::fit::{FitError, FitOutcome, FitSpec, ObjectiveForm, fit};

pub use crate::presets::Preset;
use flapssm_prssm::train::{
    BestBy, Budget, Checkpoint, InducingInit, LrSchedule, TrainEvent, TrainHooks,
};
use flapssm_prssm::{Precision, PrssmModel, SequenceView};
use flapssm_wing::dataset::{Trajectory, ValidDataset};
use serde::{Deserialize, Serialize};

use crate::adapters::trajectory_sequence;
use crate::curve::CurveRecorder;
use crate::error::{JobError, Result};
use crate::progress::Progress;

/// PR-SSM training settings shared by the sweeps and the demo: a preset with overrides.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingOptions {
    /// Named preset (paper: D_x 12, M 100, 30 particles, batch 16, lr 0.03, 1000 epochs;
    /// paper-fast; sysid).
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
    /// How the best model is chosen: by RMSE (validation, else training rollouts) or, as the
    /// published code, by the lowest epoch-mean training loss.
    #[serde(default)]
    pub best_by: BestBy,
    /// The training objective: the standard ELBO or the published code's (both quirks).
    #[serde(default)]
    pub objective: ObjectiveForm,
    /// How the inducing inputs and `q(u)` means start (the preset's when `None`).
    #[serde(default)]
    pub inducing_init: Option<InducingInit>,
    /// Early stopping: end when this many evaluated epochs in a row bring no new best model.
    #[serde(default)]
    pub patience: Option<u64>,
    /// Arithmetic of the ELBO's large products (f64, the reference, or mixed; the preset's
    /// when `None`).
    #[serde(default)]
    pub precision: Option<Precision>,
    /// Windows per parallel task of the ELBO (the preset's 4 when `None`): a minibatch of `B`
    /// windows keeps at most `⌈B / n⌉` threads busy.
    #[serde(default)]
    pub windows_per_task: Option<usize>,
    /// Initial lengthscale of every GP input, standardized units (the preset's when `None`: 2
    /// as published, 10 for paper-fast).
    #[serde(default)]
    pub lengthscale_init: Option<f64>,
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
            best_by: BestBy::Rmse,
            objective: ObjectiveForm::Standard,
            inducing_init: None,
            patience: None,
            precision: None,
            windows_per_task: None,
            lengthscale_init: None,
            checkpoint_every: 10,
        }
    }
}

impl TrainingOptions {
    /// Every option by name, as the Python keywords and (with `-` for `_`) the command line's
    /// flags spell it: the one schema both front ends map onto.
    pub const NAMES: [&'static str; 20] = [
        "preset",
        "dx",
        "inducing",
        "particles",
        "epochs",
        "iterations",
        "batch",
        "lr",
        "schedule",
        "eval_every",
        "seed",
        "val_fraction",
        "best_by",
        "objective",
        "inducing_init",
        "patience",
        "precision",
        "windows_per_task",
        "lengthscale_init",
        "checkpoint_every",
    ];

    /// Sets the option `name` ([`Self::NAMES`]) from `value` spelled as on the command line
    /// (`paper-fast`, `cosine:0.1`, `training-loss`, `mixed`, numbers). Ranges are
    /// [`Self::check`]'s.
    ///
    /// # Errors
    /// [`JobError::Setting`] for an unknown name or a value that does not parse.
    pub fn set(&mut self, name: &str, value: &str) -> Result<()> {
        fn parse<T: std::str::FromStr>(name: &str, value: &str, what: &str) -> Result<T> {
            value.parse().map_err(|_| JobError::Setting {
                name: name.into(),
                value: value.into(),
                expected: format!("must be {what}"),
            })
        }
        fn named<T: std::str::FromStr<Err = String>>(name: &str, value: &str) -> Result<T> {
            value.parse().map_err(|e: String| JobError::Setting {
                name: name.into(),
                value: value.into(),
                expected: e,
            })
        }
        let whole = "a whole number";
        let real = "a number";
        match name {
            "preset" => self.preset = named(name, value)?,
            "dx" => self.dx = Some(parse(name, value, whole)?),
            "inducing" => self.inducing = Some(parse(name, value, whole)?),
            "particles" => self.particles = Some(parse(name, value, whole)?),
            "epochs" => self.epochs = Some(parse(name, value, whole)?),
            "iterations" => self.iterations = Some(parse(name, value, whole)?),
            "batch" => self.batch = Some(parse(name, value, whole)?),
            "lr" => self.lr = Some(parse(name, value, real)?),
            "schedule" => self.schedule = Some(named(name, value)?),
            "eval_every" => self.eval_every = Some(parse(name, value, whole)?),
            "seed" => self.seed = parse(name, value, whole)?,
            "val_fraction" => self.val_fraction = parse(name, value, real)?,
            "best_by" => self.best_by = named(name, value)?,
            "objective" => self.objective = named(name, value)?,
            "inducing_init" => self.inducing_init = Some(named(name, value)?),
            "patience" => self.patience = Some(parse(name, value, whole)?),
            "precision" => self.precision = Some(named(name, value)?),
            "windows_per_task" => self.windows_per_task = Some(parse(name, value, whole)?),
            "lengthscale_init" => self.lengthscale_init = Some(parse(name, value, real)?),
            "checkpoint_every" => self.checkpoint_every = parse(name, value, whole)?,
            _ => {
                return Err(JobError::Setting {
                    name: name.into(),
                    value: value.into(),
                    expected: format!("an option of training: one of {}", Self::NAMES.join(", ")),
                });
            }
        }
        Ok(())
    }

    /// The fit specification for 7 inputs and 5 outputs (unchecked; [`Self::check`] checks it).
    pub fn spec(&self) -> FitSpec {
        let mut spec = self.preset.fit_spec(7, 5);
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
        if let Some(v) = self.inducing_init {
            spec.inducing_init = v;
        }
        if self.patience.is_some() {
            spec.train.patience = self.patience;
        }
        if let Some(p) = self.precision {
            spec.precision = p;
        }
        if let Some(v) = self.windows_per_task {
            spec.windows_per_task = v;
        }
        if let Some(v) = self.lengthscale_init {
            spec.init.lengthscale = v;
        }
        spec.train.seed = self.seed;
        spec.train.checkpoint_every = self.checkpoint_every;
        spec.train.best_by = self.best_by;
        spec.with_objective(self.objective)
    }

    /// Checks every setting once, before any work, and returns the validated plan.
    ///
    /// # Errors
    /// [`JobError::Setting`] naming the setting in the user's words (`dx`, `particles`,
    /// `val_fraction`, …) with the range it must be in.
    pub fn check(&self) -> Result<TrainingPlan> {
        let bad = |name: &str, value: String, expected: &str| {
            Err(JobError::Setting {
                name: name.into(),
                value,
                expected: expected.into(),
            })
        };
        if !(0.0..1.0).contains(&self.val_fraction) {
            return bad(
                "val_fraction",
                self.val_fraction.to_string(),
                "must be in [0, 1)",
            );
        }
        for (name, v) in [
            ("dx", self.dx),
            ("inducing", self.inducing),
            ("particles", self.particles),
            ("batch", self.batch),
            ("windows_per_task", self.windows_per_task),
        ] {
            if v == Some(0) {
                return bad(name, "0".into(), "must be at least 1");
            }
        }
        for (name, v) in [
            ("epochs", self.epochs),
            ("iterations", self.iterations),
            ("eval_every", self.eval_every),
            ("patience", self.patience),
        ] {
            if v == Some(0) {
                return bad(name, "0".into(), "must be at least 1");
            }
        }
        if let Some(lr) = self.lr
            && !(lr > 0.0 && lr.is_finite())
        {
            return bad("lr", lr.to_string(), "must be positive and finite");
        }
        if let Some(l) = self.lengthscale_init
            && !(l > 0.0 && l.is_finite())
        {
            return bad(
                "lengthscale_init",
                l.to_string(),
                "must be positive and finite",
            );
        }
        let spec = self.spec();
        let m = &spec.model;
        if m.n_state < m.n_output {
            return bad(
                "dx",
                m.n_state.to_string(),
                &format!(
                    "must be at least {}: the first {} latent states are the model's outputs",
                    m.n_output, m.n_output
                ),
            );
        }
        // What the flags cannot reach (jitters, Adam and divergence settings): the engine's own
        // checks, naming its fields.
        let engine = |source: FitError| JobError::Prssm {
            what: "training settings".into(),
            source,
        };
        m.check().map_err(|e| engine(e.into()))?;
        spec.train.check().map_err(|e| engine(e.into()))?;
        Ok(TrainingPlan {
            spec,
            val_fraction: self.val_fraction,
        })
    }
}

/// Training settings checked by [`TrainingOptions::check`]: the fit specification and the
/// validation hold-out.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainingPlan {
    spec: FitSpec,
    val_fraction: f64,
}

impl TrainingPlan {
    /// The fit specification.
    pub fn spec(&self) -> &FitSpec {
        &self.spec
    }

    /// Fraction of the training trajectories held out for best-model selection.
    pub fn val_fraction(&self) -> f64 {
        self.val_fraction
    }

    /// Splits training trajectories into (fit, validation): the last
    /// `round(n · val_fraction)` (at most `n − 1`) validate.
    ///
    /// # Errors
    /// [`JobError::Dataset`] when there is no training trajectory.
    pub fn split<'a>(
        &self,
        train: &'a [Trajectory],
    ) -> Result<(&'a [Trajectory], &'a [Trajectory])> {
        if train.is_empty() {
            return Err(flapssm_wing::dataset::DatasetError::NoTrainingData { n_train: 0 }.into());
        }
        let n_val =
            ((train.len() as f64 * self.val_fraction).round() as usize).min(train.len() - 1);
        Ok(train.split_at(train.len() - n_val))
    }

    /// One line for `train`: the fit / validation split of `train`, sizes and budget.
    ///
    /// # Errors
    /// [`JobError::Dataset`] when there is no training trajectory.
    pub fn describe(&self, train: &[Trajectory]) -> Result<String> {
        let (fit, val) = self.split(train)?;
        let s = &self.spec;
        Ok(format!(
            "{} training / {} validation trajectories; D_x {}, M {}, {} particles, {}",
            fit.len(),
            val.len(),
            s.model.n_state,
            s.model.n_inducing,
            s.particles,
            budget_text(&s.train.budget)
        ))
    }
}

/// Trains a PR-SSM on `train` (split by [`TrainingPlan::split`]), reporting steps to
/// `progress` (`set(step, total)`, one line per evaluated epoch, rejected step, checkpoint),
/// recording evaluated epochs to `curve`, checkpointing to `checkpoint` and resuming from
/// `resume`. Polls `stop` before every step.
///
/// # Errors
/// [`JobError::Prssm`] for a failed fit, [`JobError::Interrupted`] when stopped (the
/// checkpoint is written first).
pub fn train_prssm(
    train: &[Trajectory],
    plan: &TrainingPlan,
    checkpoint: Option<&Path>,
    resume: Option<Checkpoint>,
    curve: Option<&mut CurveRecorder>,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<FitOutcome> {
    let (fit_set, val_set) = plan.split(train)?;
    let s = &plan.spec;
    let longest = train.iter().map(|t| t.inputs.len()).max().unwrap_or(0);
    crate::resources::check_memory(
        "particles",
        s.particles,
        crate::resources::particle_bytes(
            s.particles * s.train.batch_size,
            longest,
            s.model.n_state,
            s.model.n_inducing,
        ),
    )?;
    let fit_seqs: Vec<SequenceView<'_>> = fit_set.iter().map(trajectory_sequence).collect();
    let val_seqs: Vec<SequenceView<'_>> = val_set.iter().map(trajectory_sequence).collect();
    // A learning curve that cannot be written is reported once and dropped; training goes on.
    let mut curve = curve;
    let curve_failed = |curve: &mut Option<&mut CurveRecorder>, e: JobError| {
        progress.println(&format!(
            "warning: learning curve not written ({e}); training continues"
        ));
        *curve = None;
    };
    let mut on_event = |e: &TrainEvent<'_>| match e {
        TrainEvent::Step {
            step,
            total_steps,
            epoch,
            loss,
            lr,
        } => {
            if let Some(Err(e)) = curve.as_mut().map(|c| c.begin()) {
                curve_failed(&mut curve, e);
            }
            progress.set(step + 1, *total_steps);
            progress.message(&format!("epoch {epoch} loss {loss:.4e} lr {lr:.2e}"));
        }
        TrainEvent::Epoch(r) => {
            if let Some(Err(e)) = curve.as_mut().map(|c| c.record(r)) {
                curve_failed(&mut curve, e);
            }
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
        TrainEvent::Rejected {
            step,
            reason,
            lr_scale,
            retry,
        } => progress.println(&format!(
            "warning: step {step} rejected ({reason}); step undone, learning-rate factor now \
             {lr_scale:.3e} (retry {retry})"
        )),
        TrainEvent::Resumed { step, checkpoint } => {
            if let Some(note) = extension_note(checkpoint, &s.train, *step) {
                progress.println(&note);
            }
        }
        TrainEvent::Interrupted { step } => progress.println(&format!(
            "interrupted at step {step}; checkpoint {}",
            checkpoint.map_or("(none)".into(), |p| p.display().to_string())
        )),
        _ => {}
    };
    let out = fit(
        plan.spec(),
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
    if out.outcome.early_stopped {
        progress.println(&format!(
            "stopped early at step {} of {}: no new best model for {} evaluated epochs",
            out.outcome.state.step,
            out.outcome.total_steps,
            s.train.patience.unwrap_or(0)
        ));
    }
    if out.outcome.interrupted {
        return Err(JobError::Interrupted {
            step: out.outcome.state.step,
            checkpoint: checkpoint.map(Path::to_path_buf),
        });
    }
    Ok(out)
}

/// What resuming a checkpoint under a larger budget does (`None` for the same budget): the
/// run continues from `step`, and a schedule that depends on the budget is recomputed over the
/// new one, so the learning rate from `step` on follows the new curve.
fn extension_note(
    old: &flapssm_prssm::train::TrainConfig,
    new: &flapssm_prssm::train::TrainConfig,
    step: u64,
) -> Option<String> {
    use flapssm_prssm::train::LrSchedule;
    if old.budget == new.budget {
        return None;
    }
    let schedule = match new.schedule {
        LrSchedule::Constant => "the constant learning rate continues".to_string(),
        _ => format!(
            "the {:?} schedule is recomputed over the new budget, so the learning rate from here \
             on follows its new curve",
            new.schedule
        ),
    };
    Some(format!(
        "extending the run from {} to {} at step {step}: {schedule}",
        budget_text(&old.budget),
        budget_text(&new.budget)
    ))
}

/// A budget in words: `N epochs` or `N iterations`.
fn budget_text(budget: &Budget) -> String {
    match budget {
        Budget::Epochs(n) => format!("{n} epochs"),
        Budget::Iterations(n) => format!("{n} iterations"),
    }
}

/// Reads the checkpoint at `path` to resume a run from.
///
/// # Errors
/// [`JobError::Io`] naming the file, with the checkpoint's own error (missing, invalid JSON,
/// another format version).
pub(crate) fn load_checkpoint(path: &Path) -> Result<Checkpoint> {
    Checkpoint::load(path).map_err(|e| JobError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(format!("resuming: {e}")),
    })
}

/// The files of a training run: the best model, the last model and the checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainFiles {
    /// Best model (by validation RMSE, or training loss without validation).
    pub model: PathBuf,
    /// Model after the last step.
    pub last: PathBuf,
    /// Checkpoint (written every `checkpoint_every` epochs and when stopped).
    pub checkpoint: PathBuf,
    /// Learning curve, one row per evaluated epoch with its wall time ([`crate::curve`]).
    pub curve: PathBuf,
}

impl TrainFiles {
    /// `model`, `<stem>.last.json` and `<stem>.curve.csv` beside it, and `checkpoint` or
    /// `<stem>.ckpt.json`.
    pub fn beside(model: &Path, checkpoint: Option<PathBuf>) -> Self {
        Self {
            model: model.to_path_buf(),
            last: sibling(model, ".last.json"),
            checkpoint: checkpoint.unwrap_or_else(|| sibling(model, ".ckpt.json")),
            curve: sibling(model, ".curve.csv"),
        }
    }
}

/// `<dir>/<stem><suffix>` next to `path`.
pub(crate) fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    path.with_file_name(format!("{stem}{suffix}"))
}

/// What a finished [`train_dataset`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainSummary {
    /// Optimizer steps done.
    pub steps: u64,
    /// Steps rejected (non-finite or diverging) and retried.
    pub rejected: u64,
    /// Epoch and score (validation RMSE, or training loss) of the best model.
    pub best: Option<(u64, f64)>,
}

/// `flapssm train`: trains on `ds`'s training trajectories and writes the best and the last
/// model to `files` (atomically), checkpointing to `files.checkpoint`; with `resume`, continues
/// bit-identically from that checkpoint.
///
/// # Errors
/// [`JobError::Dataset`] for a dataset without outputs or training trajectories, checkpoint and
/// model-file errors naming the file, [`JobError::Interrupted`] when stopped.
pub fn train_dataset(
    ds: &ValidDataset,
    plan: &TrainingPlan,
    files: &TrainFiles,
    resume: bool,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<TrainSummary> {
    if !ds.has_outputs() {
        return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
    }
    let resume = if resume {
        Some(load_checkpoint(&files.checkpoint)?)
    } else {
        None
    };
    let mut curve = CurveRecorder::new(&files.curve, resume.as_ref().map(|c| c.state.step))?;
    progress.start("train PR-SSM", 0);
    let out = train_prssm(
        ds.train(),
        plan,
        Some(&files.checkpoint),
        resume,
        Some(&mut curve),
        progress,
        stop,
    )?;
    for (m, path) in [(&out.best, &files.model), (&out.last, &files.last)] {
        m.save(path).map_err(|source| JobError::ModelFile {
            path: path.clone(),
            source,
        })?;
    }
    progress.finish(&format!("{} steps", out.outcome.state.step));
    let state = &out.outcome.state;
    Ok(TrainSummary {
        steps: state.step,
        rejected: state.rejected,
        best: state.best.as_ref().map(|b| (b.epoch, b.score)),
    })
}

/// Trains a PR-SSM on the training trajectories of `ds` as [`train_dataset`] does, but writes
/// nothing (no model file, checkpoint or learning curve): the best model, in memory. An
/// interruption loses the run.
///
/// # Errors
/// As [`train_dataset`], without the file errors.
pub fn train_in_memory(
    ds: &ValidDataset,
    plan: &TrainingPlan,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<PrssmModel> {
    if !ds.has_outputs() {
        return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
    }
    progress.start("train PR-SSM", 0);
    let out = train_prssm(ds.train(), plan, None, None, None, progress, stop)?;
    progress.finish(&format!("{} steps", out.outcome.state.step));
    Ok(out.best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_data::tiny_dataset;

    /// [`TrainingOptions::NAMES`] are exactly the fields (so a new field fails here until the
    /// schema, the command line and Python have it), and each name sets its field from the
    /// command line's spelling.
    #[test]
    fn the_option_names_are_the_fields_and_each_sets_its_own() {
        let fields = serde_json::to_value(TrainingOptions::default()).unwrap();
        let mut fields: Vec<&str> = fields
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut names = TrainingOptions::NAMES.to_vec();
        fields.sort_unstable();
        names.sort_unstable();
        assert_eq!(fields, names);
        let values = [
            ("preset", "paper-fast"),
            ("dx", "6"),
            ("inducing", "30"),
            ("particles", "7"),
            ("epochs", "12"),
            ("iterations", "40"),
            ("batch", "3"),
            ("lr", "0.01"),
            ("schedule", "cosine:0.1"),
            ("eval_every", "2"),
            ("seed", "9"),
            ("val_fraction", "0.2"),
            ("best_by", "training-loss"),
            ("objective", "published-code"),
            ("inducing_init", "kmeans"),
            ("patience", "5"),
            ("precision", "mixed"),
            ("windows_per_task", "2"),
            ("lengthscale_init", "3.5"),
            ("checkpoint_every", "0"),
        ];
        assert_eq!(values.len(), TrainingOptions::NAMES.len());
        let default = serde_json::to_value(TrainingOptions::default()).unwrap();
        for (name, value) in values {
            let mut o = TrainingOptions::default();
            o.set(name, value).unwrap();
            let changed = serde_json::to_value(&o).unwrap();
            for key in TrainingOptions::NAMES {
                let moved = changed[key] != default[key];
                assert_eq!(moved, key == name, "setting {name} = {value} moved {key}");
            }
        }
        let e = TrainingOptions::default().set("epoch", "3").unwrap_err();
        assert!(
            e.to_string().contains("epoch") && e.to_string().contains("epochs"),
            "{e}"
        );
        let e = TrainingOptions::default().set("dx", "1.5").unwrap_err();
        assert!(e.to_string().contains("whole number"), "{e}");
        let e = TrainingOptions::default()
            .set("schedule", "linear")
            .unwrap_err();
        assert!(e.to_string().contains("unknown schedule"), "{e}");
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
            o.check()?.split(t).map(|(a, b)| (a.len(), b.len()))
        };
        assert_eq!(split(0.0).unwrap(), (5, 0));
        assert_eq!(split(0.2).unwrap(), (4, 1));
        assert_eq!(split(0.5).unwrap(), (2, 3)); // round(2.5) = 3
        assert_eq!(split(0.99).unwrap(), (1, 4)); // at least one trajectory is fitted
        assert!(split(1.0).is_err() && split(-0.1).is_err());
    }

    #[test]
    fn check_names_the_setting_in_the_users_words() {
        let err = |o: TrainingOptions| o.check().unwrap_err().to_string();
        let e = err(TrainingOptions {
            dx: Some(4),
            ..TrainingOptions::default()
        });
        assert!(
            e.contains("setting dx = 4") && e.contains("at least 5"),
            "{e}"
        );
        let e = err(TrainingOptions {
            particles: Some(0),
            ..TrainingOptions::default()
        });
        assert!(e.contains("setting particles = 0"), "{e}");
        let e = err(TrainingOptions {
            val_fraction: 1.0,
            ..TrainingOptions::default()
        });
        assert!(e.contains("setting val_fraction = 1"), "{e}");
        let e = err(TrainingOptions {
            lr: Some(-1.0),
            ..TrainingOptions::default()
        });
        assert!(e.contains("setting lr = -1: must be positive"), "{e}");
        assert!(
            TrainingOptions {
                dx: Some(5),
                ..TrainingOptions::default()
            }
            .check()
            .is_ok()
        );
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
            let mut f = Preset::Paper.fit_spec(7, 5);
            f.train.checkpoint_every = 10;
            f
        });
    }

    #[test]
    fn objective_option_switches_loss_and_sampling_together() {
        let p = TrainingOptions {
            objective: ObjectiveForm::PublishedCode,
            ..TrainingOptions::default()
        }
        .spec();
        assert_eq!(p.objective, ObjectiveForm::PublishedCode);
        assert!(p.model.shared_draws && p.model.matern_tau_jitter == 1e-8);
        assert!(p.check_objective().is_ok());
        let s = TrainingOptions::default().spec();
        assert_eq!(s.objective, ObjectiveForm::Standard);
        assert!(!s.model.shared_draws && s.model.matern_tau_jitter == 0.0);
        // A spec whose sampling disagrees with its objective is refused, naming the field.
        let mut mixed = s.clone();
        mixed.objective = ObjectiveForm::PublishedCode;
        assert_eq!(mixed.check_objective().unwrap_err().field, "shared_draws");
    }
}
